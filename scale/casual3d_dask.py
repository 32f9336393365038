#!/usr/bin/python3
"""Converts captures to 3D photos on a Dask distributed cluster.

    casual3d_dask.py --scheduler tcp://HOST:8786 CAPTURE... -o OUT
    casual3d_dask.py --scheduler-file sched.json --captures-in DIR -o OUT

Each capture (a folder of photos, a video or a COLMAP workspace) becomes
OUT/<name>/web/ (the package), OUT/<name>/photo.c3d and OUT/<name>/master.exr,
with the same bytes as `casual3d reconstruct` on one machine gives. Its work
is split into units that the scheduler spreads over the workers:

    sparse    casual3d reconstruct CAPTURE -o OUT/<name> --to sparse
    plan      casual3d dense WS -o OUT/<name>/dense --pass plan     (the photos, in the order to sweep them)
    sweep     casual3d dense ... --pass sweep --photos LIST         (one unit per group of photos)
    depth     casual3d dense ... --pass depth --photos LIST         (after the sweeps it reads; first
                                                                     when ready, freeing cost caches)
    finish    casual3d dense ... --pass finish
    panorama  casual3d panorama WS --depth OUT/<name>/dense -o OUT/<name>/panorama
    encode    casual3d encode OUT/<name>/panorama/master.exr -o OUT/<name>/web --single-file ...

OUT must be a folder every worker sees at the same path (NFS, CephFS, a
Kubernetes volume). A unit whose worker dies is run again on another worker
by the scheduler; a unit that fails is retried --retries times; either way
the units' outputs are written atomically and a rerun skips what is done, so
the result is the same. A capture whose unit keeps failing is reported with
the unit's message and the others go on. Exit status: 0 when every capture
was converted, 1 when some failed (OUT/batch.json lists them), 2 on bad
arguments. See docs/SCALE.md.
"""

import argparse
import ctypes
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path


class UnitFailed(Exception):
    """A casual3d command that exited non-zero; the message is its error line."""


def _end_with_parent():
    # PR_SET_PDEATHSIG: the unit's process is killed when the worker that
    # started it dies, so a retried unit never races an orphan of itself.
    ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)


def run_unit(casual3d, args, label, *after):
    """Runs `casual3d args` on a worker; `after` only orders the unit after others."""
    del after
    proc = subprocess.run([casual3d] + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                          preexec_fn=_end_with_parent, check=False)
    if proc.returncode != 0:
        lines = [line for line in proc.stderr.splitlines() if line.strip()]
        reason = lines[-1] if lines else "exit status %d" % proc.returncode
        if reason.startswith("casual3d: error: "):
            reason = reason[len("casual3d: error: "):]
        raise UnitFailed("%s: %s" % (label, reason))
    return proc.stdout


def run_into_folder(casual3d, args, label, folder, *after):
    """Runs a command that writes `folder` into a temporary sibling, then renames it."""
    del after
    folder = Path(folder)
    tmp = folder.with_name("%s.tmp-%d" % (folder.name, os.getpid()))
    shutil.rmtree(tmp, ignore_errors=True)
    run_unit(casual3d, [a.replace("{OUT}", str(tmp)) for a in args], label)
    shutil.rmtree(folder, ignore_errors=True)
    os.replace(tmp, folder)
    return str(folder)


def dense_groups(plan_output, per_unit):
    """The plan unit's lines (index, name, the sweeps its depth unit reads;
    in the order to sweep) as groups of per_unit photos along that order, and
    per group the indices of the groups whose sweeps its depth unit reads."""
    rows = []
    for line in plan_output.splitlines():
        if line.strip():
            index, rest = line.split("\t", 1)
            needs = rest.rsplit("\t", 1)[1]  # The name between may hold anything.
            rows.append((int(index), [int(j) for j in needs.split(",")]))
    groups = [rows[a:a + per_unit] for a in range(0, len(rows), per_unit)]
    group_of = {i: g for g, group in enumerate(groups) for i, _ in group}
    reads = [sorted({group_of[j] for _, needs in group for j in needs}) for group in groups]
    return [[i for i, _ in group] for group in groups], reads


def photo_list(photos):
    """--photos value: indices, runs of three or more as a-b."""
    out, k = [], 0
    while k < len(photos):
        e = k
        while e + 1 < len(photos) and photos[e + 1] == photos[e] + 1:
            e += 1
        out.append("%d-%d" % (photos[k], photos[e]) if e - k >= 2 else ",".join(str(p) for p in photos[k:e + 1]))
        k = e + 1
    return ",".join(out)


class Capture:
    """One capture's paths and its units' futures."""

    def __init__(self, source, out_root):
        self.source = Path(source)
        self.name = self.source.stem if self.source.is_file() else self.source.name
        self.root = Path(out_root) / self.name
        self.workspace = self.root / "work" / "sparse"
        self.dense = self.root / "dense"
        self.panorama = self.root / "panorama"
        self.web = self.root / "web"
        self.final = None  # The future whose success means the capture is done.
        self.error = None

    def dense_args(self, cfg, *rest):
        args = ["dense", str(self.workspace), "-o", str(self.dense), "--threads", str(cfg.unit_threads)]
        return args + cfg.dense_options + list(rest)


def submit_start(client, cfg, cap):
    """Sparse and plan units (or nothing when the capture is already done)."""
    if cap.web.is_dir() and (cap.root / "photo.c3d").is_file():
        return None
    submit = lambda fn, *a, key: client.submit(fn, *a, key=key, retries=cfg.retries, pure=False)
    sparse = submit(run_unit, cfg.casual3d,
                    ["reconstruct", str(cap.source), "-o", str(cap.root), "--to", "sparse",
                     "--threads", str(cfg.unit_threads)] + cfg.sparse_options,
                    "%s: sparse" % cap.name, key="sparse-%s" % cap.name)
    return submit(run_unit, cfg.casual3d, cap.dense_args(cfg, "--pass", "plan"), "%s: dense plan" % cap.name,
                  sparse, key="plan-%s" % cap.name)


def submit_rest(client, cfg, cap, plan_output):
    """The dense units, panorama and encode, once the plan has listed the photos."""
    submit = lambda fn, *a, key, priority=0: client.submit(fn, *a, key=key, retries=cfg.retries, pure=False,
                                                           priority=priority)
    done = None
    if not (cap.dense / "dense.json").is_file():
        # Sweeps in the plan's order, each depth unit submitted once the
        # sweeps it reads are, at a higher priority: it runs as soon as they
        # are done and deletes its photos' cost caches (about 1 GB each at
        # 4096x2048), so the disk holds a few groups' caches, not the capture's.
        groups, reads = dense_groups(plan_output, cfg.photos_per_unit)
        sweeps, depths = [], []
        for g, photos in enumerate(groups):
            listed = photo_list(photos)
            sweeps.append(submit(run_unit, cfg.casual3d, cap.dense_args(cfg, "--pass", "sweep", "--photos", listed),
                                 "%s: dense sweep of photos %s" % (cap.name, listed),
                                 key="sweep-%s-%d" % (cap.name, g)))
            for h in range(len(depths), len(groups)):
                if max(reads[h]) > g:
                    break
                listed_h = photo_list(groups[h])
                depths.append(submit(run_unit, cfg.casual3d,
                                     cap.dense_args(cfg, "--pass", "depth", "--photos", listed_h),
                                     "%s: dense depth of photos %s" % (cap.name, listed_h),
                                     *[sweeps[k] for k in reads[h]], key="depth-%s-%d" % (cap.name, h), priority=1))
        done = submit(run_unit, cfg.casual3d, cap.dense_args(cfg, "--pass", "finish"), "%s: dense finish" % cap.name,
                      *depths, key="finish-%s" % cap.name)
    if not (cap.panorama / "master.exr").is_file():
        done = submit(run_into_folder, cfg.casual3d,
                      ["panorama", str(cap.workspace), "--depth", str(cap.dense), "-o", "{OUT}",
                       "--threads", str(cfg.unit_threads)] + cfg.panorama_options,
                      "%s: panorama" % cap.name, str(cap.panorama), *([done] if done else []),
                      key="panorama-%s" % cap.name)
    single = cap.root / "photo.c3d"
    encode = ["encode", str(cap.panorama / "master.exr"), "-o", "{OUT}", "--single-file", "{OUT}/photo.c3d",
              "--threads", str(cfg.unit_threads), "--capture", str(cap.workspace),
              "--title", cap.root.name]
    return submit(finish_capture, cfg.casual3d, encode, "%s: encode" % cap.name, str(cap.web), str(single),
                  str(cap.panorama / "master.exr"), str(cap.root / "master.exr"), *([done] if done else []),
                  key="encode-%s" % cap.name)


def finish_capture(casual3d, args, label, web, single, master, master_copy, *after):
    """Encodes into web/ atomically; photo.c3d and master.exr beside it as reconstruct leaves them."""
    run_into_folder(casual3d, args, label, web)
    os.replace(os.path.join(web, "photo.c3d"), single + ".tmp")
    os.replace(single + ".tmp", single)
    shutil.copyfile(master, master_copy + ".tmp")
    os.replace(master_copy + ".tmp", master_copy)
    return web


def message_of(future):
    try:
        exc = future.exception()
    except Exception as e:  # The scheduler gave up on the unit (e.g. KilledWorker).
        exc = e
    return str(exc) or type(exc).__name__


def run_batch(client, cfg, captures):
    from distributed import as_completed

    plans = {}
    for cap in captures:
        f = submit_start(client, cfg, cap)
        if f is None:
            print("%s: already converted" % cap.name, flush=True)
        else:
            plans[f] = cap
    finals = []
    for f in as_completed(list(plans)):
        cap = plans[f]
        if f.status != "finished":
            cap.error = message_of(f)
            print("%s: failed: %s" % (cap.name, cap.error), file=sys.stderr, flush=True)
            continue
        cap.final = submit_rest(client, cfg, cap, f.result())
        finals.append(cap.final)
    for f in as_completed(finals):
        cap = next(c for c in captures if c.final is f)
        if f.status == "finished":
            print("%s: converted into %s" % (cap.name, cap.web), flush=True)
        else:
            cap.error = message_of(f)
            print("%s: failed: %s" % (cap.name, cap.error), file=sys.stderr, flush=True)


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("captures", nargs="*", help="capture folders or videos")
    p.add_argument("--captures-in", help="convert every capture folder or video in this folder")
    p.add_argument("-o", "--out", required=True, help="output folder, shared by every worker")
    where = p.add_mutually_exclusive_group(required=True)
    where.add_argument("--scheduler", help="scheduler address, e.g. tcp://10.0.0.5:8786")
    where.add_argument("--scheduler-file", help="scheduler file written by dask-scheduler --scheduler-file")
    p.add_argument("--casual3d", default=shutil.which("casual3d") or "casual3d",
                   help="the casual3d program, at the same path on every worker (default: from PATH)")
    p.add_argument("--photos-per-unit", type=int, default=4, help="photos per sweep and depth unit (default 4)")
    p.add_argument("--unit-threads", type=int, default=0,
                   help="threads of each unit's process (default 0: all of the worker's cores)")
    p.add_argument("--retries", type=int, default=1, help="reruns of a unit that fails (default 1)")
    p.add_argument("--dense-option", dest="dense_options", action="append", default=[],
                   help="an option for every dense unit, e.g. --dense-option=--depths=128 (repeatable)")
    p.add_argument("--sparse-option", dest="sparse_options", action="append", default=[],
                   help="an option for the sparse unit's casual3d reconstruct (repeatable)")
    p.add_argument("--panorama-option", dest="panorama_options", action="append", default=[],
                   help="an option for the panorama unit (repeatable)")
    cfg = p.parse_args(argv)
    if cfg.photos_per_unit < 1:
        p.error("--photos-per-unit %d: must be at least 1" % cfg.photos_per_unit)
    if cfg.unit_threads < 0:
        p.error("--unit-threads %d: must be 0 (all cores) or more" % cfg.unit_threads)
    sources = [Path(c) for c in cfg.captures]
    if cfg.captures_in:
        folder = Path(cfg.captures_in)
        if not folder.is_dir():
            p.error("--captures-in %s: not a folder" % folder)
        sources += sorted(e for e in folder.iterdir() if not e.name.startswith("."))
    if not sources:
        p.error("no captures: name capture folders or give --captures-in DIR")
    for s in sources:
        if not s.exists():
            p.error("%s: no such capture folder or video" % s)
    names = [Capture(s, cfg.out).name for s in sources]
    dupes = sorted({n for n in names if names.count(n) > 1})
    if dupes:
        p.error("captures named alike would share an output folder: %s; rename them" % ", ".join(dupes))
    cfg.sources = [s.resolve() for s in sources]
    return cfg


def main(argv):
    cfg = parse_args(argv)
    try:
        from distributed import Client
    except ImportError:
        print("casual3d_dask: error: Dask distributed is not installed (Debian: apt-get install "
              "python3-distributed)", file=sys.stderr)
        return 2
    out = Path(cfg.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    captures = [Capture(s, out) for s in cfg.sources]
    start = time.time()
    with Client(address=cfg.scheduler, scheduler_file=cfg.scheduler_file) as client:
        run_batch(client, cfg, captures)
    failed = [c for c in captures if c.error]
    batch = {"seconds": round(time.time() - start, 1),
             "captures": [{"name": c.name, "source": str(c.source),
                           "status": "failed" if c.error else "converted",
                           **({"error": c.error} if c.error else {"web": str(c.web)})} for c in captures]}
    tmp = out / ("batch.json.tmp-%d" % os.getpid())
    tmp.write_text(json.dumps(batch, indent=2) + "\n")
    os.replace(tmp, out / "batch.json")
    print("%d of %d captures converted in %.0f s%s" % (len(captures) - len(failed), len(captures),
                                                      batch["seconds"], "; failed: " + ", ".join(c.name for c in failed)
                                                      if failed else ""), flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
