#!/usr/bin/python3
"""scale/casual3d_dask.py on a local Dask cluster: a scheduler and two workers
talking over TCP on 127.0.0.1 convert two synthetic captures and a third with
a truncated photo. Checks:
  - each good capture's package (web/, photo.c3d) and master.exr have the
    bytes that `casual3d reconstruct` gives on one machine;
  - a worker killed (SIGKILL) while it runs a dense unit: the scheduler runs
    the unit again on another worker and nothing is lost (no intermediate or
    temporary file left, every output present);
  - the bad capture fails with its unit's message, the batch goes on, the
    driver exits 1 and batch.json says which capture failed and why.
Exits 77 (skipped) when Dask distributed is not installed.

    dask_local_test.py --casual3d build/cli/casual3d --work /tmp/dask-test
"""

import argparse
import filecmp
import json
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
DRIVER = HERE.parent.parent / "scale" / "casual3d_dask.py"


def fail(message):
    print("FAIL: " + message, file=sys.stderr, flush=True)
    sys.exit(1)


def children(pid):
    """Command lines of the processes whose parent is pid."""
    out = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
            ppid = int(stat[stat.rindex(")") + 2:].split()[1])
            if ppid == pid:
                out.append((entry / "cmdline").read_bytes().replace(b"\0", b" ").decode())
        except (OSError, ValueError):
            continue
    return out


def same_tree(a, b):
    """Names of the files that differ or exist on one side only (recursive)."""
    cmp = filecmp.dircmp(a, b)
    bad = [os.path.join(a, n) for n in cmp.left_only + cmp.right_only + cmp.funny_files]
    _, mismatch, errors = filecmp.cmpfiles(a, b, cmp.common_files, shallow=False)
    bad += [os.path.join(a, n) for n in mismatch + errors]
    for sub in cmp.common_dirs:
        bad += same_tree(os.path.join(a, sub), os.path.join(b, sub))
    return bad


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--casual3d", required=True)
    ap.add_argument("--work", required=True)
    args = ap.parse_args()
    try:
        import distributed  # noqa: F401
    except ImportError:
        print("SKIP: Dask distributed is not installed (apt-get install python3-distributed)")
        return 77
    scheduler_cmd = shutil.which("dask-scheduler")
    worker_cmd = shutil.which("dask-worker")
    if not scheduler_cmd or not worker_cmd:
        print("SKIP: dask-scheduler / dask-worker not on PATH")
        return 77
    casual3d = str(Path(args.casual3d).resolve())
    work = Path(args.work).resolve()
    shutil.rmtree(work, ignore_errors=True)
    captures = work / "captures"
    captures.mkdir(parents=True)

    def run(cmd, **kw):
        r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, **kw)
        if r.returncode != 0:
            fail("%s exited %d:\n%s" % (" ".join(map(str, cmd)), r.returncode, r.stdout[-2000:]))
        return r.stdout

    # Two small captures and one whose fourth photo is cut short.
    for name, seed in (("alpha", 3), ("beta", 7)):
        run([casual3d, "synth", "-o", captures / name, "--width", "320", "--photos", "6", "--seed", str(seed),
             "--panorama-width", "256"])
    shutil.copytree(captures / "alpha", captures / "broken")
    photo = captures / "broken" / "images" / "0003.jpg"
    photo.write_bytes(photo.read_bytes()[:2000])

    t0 = time.time()
    for name in ("alpha", "beta"):
        run([casual3d, "reconstruct", captures / name, "-o", work / "reference" / name])
    print("reference: %.0f s" % (time.time() - t0), flush=True)

    # The cluster: a scheduler and workers on 127.0.0.1, one unit at a time each.
    sched_file = work / "scheduler.json"
    procs = []

    def start(cmd, log):
        p = subprocess.Popen(cmd, stdout=open(work / log, "w"), stderr=subprocess.STDOUT)
        procs.append(p)
        return p

    start([scheduler_cmd, "--host", "127.0.0.1", "--port", "0", "--no-dashboard", "--scheduler-file", sched_file],
          "scheduler.log")
    # The scheduler writes its file in place: wait until it parses, not only exists.
    address = None
    for _ in range(300):
        try:
            address = json.loads(sched_file.read_text())["address"]
            break
        except (OSError, ValueError, KeyError):
            time.sleep(0.1)
    if address is None:
        fail("the scheduler wrote no address to %s within 30 s (see scheduler.log)" % sched_file)
    if not address.startswith("tcp://127.0.0.1:"):
        fail("scheduler address %s is not TCP on 127.0.0.1" % address)

    def worker(name):
        return start([worker_cmd, address, "--name", name, "--nthreads", "1", "--no-nanny", "--host", "127.0.0.1",
                      "--no-dashboard", "--memory-limit", "0"], name + ".log")

    w1, _ = worker("w1"), worker("w2")
    killed = {}

    def kill_mid_dense():
        # Once some sweep has finished, kill w1 the moment it runs a dense unit.
        out = work / "out"
        deadline = time.time() + 600
        while time.time() < deadline and w1.poll() is None:
            started = any(out.glob("*/dense/.dense-units/sweep/*.json"))
            running = [c for c in children(w1.pid) if " dense " in c and ("--pass sweep" in c or "--pass depth" in c)]
            if started and running:
                w1.send_signal(signal.SIGKILL)
                killed["unit"] = running[0]
                worker("w3")  # A replacement, so that two workers remain.
                return
            time.sleep(0.02)

    killer = threading.Thread(target=kill_mid_dense, daemon=True)
    killer.start()
    t0 = time.time()
    try:
        r = subprocess.run([sys.executable, DRIVER, "--scheduler", address, "--casual3d", casual3d,
                            "--captures-in", captures, "-o", work / "out", "--photos-per-unit", "2",
                            "--unit-threads", "1"],
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=900)
    finally:
        killer.join(timeout=1)
        for p in reversed(procs):
            if p.poll() is None:
                p.terminate()
        for p in procs:
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()
    print(r.stdout, flush=True)
    print("distributed: %.0f s" % (time.time() - t0), flush=True)

    if "unit" not in killed:
        fail("no worker was killed during a dense unit (the test could not inject the fault)")
    print("killed w1 while it ran: " + killed["unit"], flush=True)
    if r.returncode != 1:
        fail("driver exit status %d, expected 1 (one capture fails)" % r.returncode)
    batch = json.loads((work / "out" / "batch.json").read_text())
    status = {c["name"]: c for c in batch["captures"]}
    if status["broken"]["status"] != "failed":
        fail("the broken capture was not reported as failed: %s" % status["broken"])
    error = status["broken"]["error"]
    if "broken: dense plan" not in error or "0003.jpg: truncated JPEG" not in error:
        fail("the broken capture's message does not name the unit and the photo: " + error)
    for name in ("alpha", "beta"):
        if status[name]["status"] != "converted":
            fail("%s: %s" % (name, status[name]))
        got, ref = work / "out" / name, work / "reference" / name
        diff = same_tree(got / "web", ref / "web")
        for f in ("photo.c3d", "master.exr"):
            if not filecmp.cmp(got / f, ref / f, shallow=False):
                diff.append(str(got / f))
        if diff:
            fail("%s: differs from casual3d reconstruct: %s" % (name, ", ".join(diff)))
        left = [str(p) for p in got.rglob("*") if ".tmp-" in p.name or p.name == ".dense-units"]
        if left:
            fail("%s: intermediate or temporary files left: %s" % (name, ", ".join(left[:5])))
        print("%s: package, photo.c3d and master.exr identical to casual3d reconstruct" % name, flush=True)
    print("PASS", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
