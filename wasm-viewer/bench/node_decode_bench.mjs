// Benchmark: decode a 4096x2048 package and build its mesh with the wasm format
// library in Node (the viewer's worker path; WebP through the wasm libwebp of
// @jsquash/webp instead of the browser's decoder). Prints one JSON line.
//
//   CASUAL3D_BINARY_DIR=build node wasm-viewer/bench/node_decode_bench.mjs [package_dir] [repeats]
// Wall times (ms) and CPU times (cpuMs: this process's user + system time,
// which stays meaningful when other jobs share the cores; the wasm work is
// single-threaded). Without package_dir it writes the procedural test panorama's package
// (viewer_test_tool package test 4096 2048) to a temporary folder.

import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';

import { loadFormatModule, runTool } from '../test/node-support.mjs';
import { readPackageLevel } from '../test/node-package.mjs';

const repeats = Number(process.argv[3] ?? 3);
let pkg = process.argv[2];
let tmp = null;
if (!pkg) {
  tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'casual3d-bench-'));
  pkg = path.join(tmp, 'pkg');
  runTool('viewer_test_tool', ['package', 'test', '4096', '2048', pkg]);
}
try {
  const format = await loadFormatModule();
  const manifest = JSON.parse(fs.readFileSync(path.join(pkg, 'manifest.json'), 'utf8'));
  const best = {};
  const keep = (k, v) => { best[k] = Math.min(best[k] ?? Infinity, v); };
  let full = 0, simplified = 0, bound = 0;
  const cpu = () => { const u = process.cpuUsage(); return (u.user + u.system) / 1000; };
  for (let r = 0; r < repeats; ++r) {
    let c = cpu();
    const { pano, timing } = await readPackageLevel(format, pkg, 0);
    keep('readAllCpuMs', cpu() - c);
    for (const [k, v] of Object.entries(timing)) keep(k, v);
    let t = performance.now();
    c = cpu();
    const mesh = format.buildMesh(pano);
    keep('meshFullMs', performance.now() - t);
    keep('meshFullCpuMs', cpu() - c);
    full = mesh.indices.length / 3;
    t = performance.now();
    c = cpu();
    const simple = format.buildMesh(pano, { maxTriangles: 2000000 });
    keep('meshSimplifiedMs', performance.now() - t);
    keep('meshSimplifiedCpuMs', cpu() - c);
    simplified = simple.indices.length / 3;
    bound = simple.maxRelativeError;
    t = performance.now();
    pano.atlas();
    keep('atlasMs', performance.now() - t);
    pano.free();
  }
  const decodeOnly = best.readMs + best.checkMs + best.decodeMs;
  const wasmDecode = best.addMs + best.finishMs;
  const levelBytes = manifest.levels.map((_, l) => manifest.files.filter((f) => f.path.startsWith(`l${l}/`)).reduce((s, f) => s + f.bytes, 0));
  console.log(JSON.stringify({
    package: { width: manifest.width, height: manifest.height, levels: manifest.levels.length, levelBytes },
    ms: Object.fromEntries(Object.entries(best).map(([k, v]) => [k, Math.round(v)])),
    wasmTileDecodePlusMeshFullMs: Math.round(wasmDecode + best.meshFullMs),
    wasmTileDecodePlusMeshSimplifiedMs: Math.round(wasmDecode + best.meshSimplifiedMs),
    webpDecodeAndChecksumMs: Math.round(decodeOnly),
    triangles: { full, simplified, relativeErrorBound: bound },
    repeats,
  }));
} finally {
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
}
