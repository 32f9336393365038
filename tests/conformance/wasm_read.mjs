// The wasm reader's side of tests/conformance_test.cc: reads each package
// given on the command line (a folder or a .c3d file) through the npm
// package's Node format entry as built (<build>/wasm-viewer/dist/format-node.js,
// the single-threaded module, WebP decoded by @jsquash/webp), every level from
// the coarsest, and prints one JSON line per package:
//   {"path", "ok": true, "levels": [{"width", "height", "present": [f, b], "graph_sha256"}]}
//   {"path", "ok": false, "message"}
// Usage: node wasm_read.mjs <dist dir> <package>...
// (run with NODE_PATH=<source>/wasm-viewer/node_modules, where the format
// entry finds @jsquash/webp).

import crypto from 'node:crypto';
import path from 'node:path';
import { pathToFileURL } from 'node:url';

const [dist, ...packages] = process.argv.slice(2);
if (!dist || packages.length === 0) {
  console.error('usage: node wasm_read.mjs <dist dir> <package>...');
  process.exit(2);
}
const { createFormat, openPackage } = await import(pathToFileURL(path.join(dist, 'format-node.js')).href);
const format = await createFormat({ threads: false });

// spec/package.md Sec. 9: SHA-256 of present, label, links of the front
// layer, then of the back layer.
function graphSha256(pano) {
  const hash = crypto.createHash('sha256');
  const present = [];
  for (const l of [0, 1]) {
    const layer = pano.layer(l);
    hash.update(layer.present).update(layer.label).update(layer.links);
    present.push(layer.present.reduce((a, b) => a + b, 0));
  }
  return { present, graph_sha256: hash.digest('hex') };
}

for (const file of packages) {
  let pkg;
  try {
    pkg = await openPackage(file, { format });
    const levels = [];
    for (let level = pkg.numLevels - 1; level >= 0; --level) {
      const pano = await pkg.readLevel(level);
      try {
        levels[level] = { width: pano.width, height: pano.height, ...graphSha256(pano) };
      } finally {
        pano.free();
      }
    }
    console.log(JSON.stringify({ path: file, ok: true, levels }));
  } catch (err) {
    console.log(JSON.stringify({ path: file, ok: false, message: String(err?.message ?? err) }));
  } finally {
    pkg?.close();
  }
}
