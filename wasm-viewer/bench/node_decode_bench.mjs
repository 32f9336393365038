// Benchmark: read one level of a package and build its meshes with the wasm
// format library in Node, step by step as the viewer's worker does (WebP
// through the wasm libwebp of @jsquash/webp standing in for the browser's
// decoder). Prints a table of wall and CPU milliseconds per step (the best of
// `repeats` runs; CPU = this process's user + system time, which stays
// meaningful when other jobs share the cores; every step runs on one thread),
// next to those of the first run, then the same numbers as one JSON line.
//
//   CASUAL3D_BINARY_DIR=build node wasm-viewer/bench/node_decode_bench.mjs [package_dir] [repeats] [level] [build]
//
// build: `single` (default), the single-threaded wasm build every page can
// use, or `threaded`, casual3d-format-mt, which shares the format library's
// loops among min(cores, 4) threads (cross-origin isolated pages). CPU ms then
// add up all threads' time, so wall ms is the figure to compare.
//
// Without package_dir it writes the procedural test panorama's package
// (viewer_test_tool package test 4096 2048) to a temporary folder.

import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';

import { loadFormatModule, runTool } from '../test/node-support.mjs';
import { readPackageLevel } from '../test/node-package.mjs';
import { backdropCell, simplifyMaxError } from '../js/mesh-error.js';

const repeats = Number(process.argv[3] ?? 3);
const level = Number(process.argv[4] ?? 0);
const build = process.argv[5] ?? 'single';
if (build !== 'single' && build !== 'threaded') throw new Error(`build ${build}: expected single or threaded`);
const MAX_TRIANGLES = 2000000;  // The viewer's default budget (js/viewer-core.js).
let pkg = process.argv[2];
let tmp = null;
if (!pkg) {
  tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'casual3d-bench-'));
  pkg = path.join(tmp, 'pkg');
  runTool('viewer_test_tool', ['package', 'test', '4096', '2048', pkg]);
}

const cpuNow = () => {
  const u = process.cpuUsage();
  return (u.user + u.system) / 1000;
};
// Runs fn, returning [result, wall ms, CPU ms].
function measure(fn) {
  const t = performance.now(), c = cpuNow();
  const result = fn();
  return [result, performance.now() - t, cpuNow() - c];
}

try {
  const format = await loadFormatModule({ threads: build === 'threaded' });
  const manifest = JSON.parse(fs.readFileSync(path.join(pkg, 'manifest.json'), 'utf8'));
  const best = {};  // step -> {wall, cpu}, each the minimum over repeats.
  // step -> {wall, cpu} of the first run: a fresh page's first level, while
  // V8 still runs much of the wasm in its baseline compiler (Liftoff) and
  // tiers functions up to optimized code as they get hot.
  const first = {};
  const keep = (step, wall, cpu) => {
    const b = (best[step] ??= { wall: Infinity, cpu: Infinity });
    b.wall = Math.min(b.wall, wall);
    b.cpu = Math.min(b.cpu, cpu);
    first[step] ??= { wall, cpu };
  };
  // As the viewer's worker: the simplifier's error beyond the depth code's step.
  const simplifyError = simplifyMaxError(JSON.parse(fs.readFileSync(path.join(pkg, 'manifest.json'), 'utf8')).depth_encoding);
  let full = 0, simplified = 0, bound = 0, backdrop = 0;
  for (let r = 0; r < repeats; ++r) {
    const { pano, timing, cpu } = await readPackageLevel(format, pkg, level);
    for (const k of Object.keys(timing)) keep(k, timing[k], cpu[k]);
    let mesh, wall, c;
    [mesh, wall, c] = measure(() => format.buildMesh(pano, { maxTriangles: MAX_TRIANGLES, maxRelativeError: simplifyError }));
    keep('meshSimplifiedMs', wall, c);
    simplified = mesh.indices.length / 3;
    bound = mesh.maxRelativeError;
    mesh = null;
    [, wall, c] = measure(() => pano.atlas());
    keep('atlasMs', wall, c);
    // As the viewer's worker: the backdrop's cell from the level's size and the budget.
    [mesh, wall, c] = measure(() => format.buildBackdrop(pano, { cellPx: backdropCell(pano.width, pano.height, MAX_TRIANGLES) }));
    keep('backdropMs', wall, c);
    backdrop = mesh.indices.length / 3;
    mesh = null;
    [mesh, wall, c] = measure(() => format.buildMesh(pano));
    keep('meshFullMs', wall, c);
    full = mesh.indices.length / 3;
    mesh = null;
    pano.free();
  }
  const levelBytes = manifest.levels.map((_, l) => manifest.files.filter((f) => f.path.startsWith(`l${l}/`)).reduce((s, f) => s + f.bytes, 0));
  const L = manifest.levels[level];
  const rows = [
    ['read files (fs)', ['readMs']],
    ['SHA-256 check (wasm)', ['checkMs']],
    ['WebP decode (@jsquash/webp)', ['decodeMs']],
    ['tile unpacking: copy in + DecodeTileImage (wasm)', ['addMs']],
    ['assemble: FinishDecodedPanorama + Validate (wasm)', ['finishMs']],
    [`simplified mesh, ${MAX_TRIANGLES / 1e6} M budget, copied out (${simplified} triangles)`, ['meshSimplifiedMs']],
    ['colour atlas, copied out', ['atlasMs']],
    [`backdrop, copied out (${backdrop} triangles)`, ['backdropMs']],
    [`full mesh, copied out (${full} triangles)`, ['meshFullMs']],
    ['viewer path: check + decode + unpack + assemble + simplified mesh + atlas + backdrop', ['checkMs', 'decodeMs', 'addMs', 'finishMs', 'meshSimplifiedMs', 'atlasMs', 'backdropMs']],
    ['wasm format library only: check + unpack + assemble + simplified mesh', ['checkMs', 'addMs', 'finishMs', 'meshSimplifiedMs']],
    ['wasm format library only, full mesh: check + unpack + assemble + full mesh', ['checkMs', 'addMs', 'finishMs', 'meshFullMs']],
  ];
  const sum = (table, keys, f) => keys.reduce((s, k) => s + table[k][f], 0);
  console.log(`level ${level} of ${pkg}: ${L.width}x${L.height}, ${levelBytes[level]} bytes; ${build} wasm build ` +
              `(${format.numThreads} threads); best of ${repeats}, and the first run`);
  console.log('| step | wall ms | CPU ms | first run: wall ms | CPU ms |\n|---|---|---|---|---|');
  for (const [name, keys] of rows) {
    const cells = [best, first].flatMap((t) => [sum(t, keys, 'wall'), sum(t, keys, 'cpu')].map(Math.round));
    console.log(`| ${name} | ${cells.join(' | ')} |`);
  }
  console.log(JSON.stringify({
    package: { width: manifest.width, height: manifest.height, levels: manifest.levels.length, levelBytes },
    level,
    build,
    threads: format.numThreads,
    ms: Object.fromEntries(Object.entries(best).map(([k, v]) => [k, { wall: Math.round(v.wall), cpu: Math.round(v.cpu) }])),
    firstRunMs: Object.fromEntries(Object.entries(first).map(([k, v]) => [k, { wall: Math.round(v.wall), cpu: Math.round(v.cpu) }])),
    triangles: { full, simplified, backdrop, relativeErrorBound: bound },
    repeats,
  }));
} finally {
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
}
