// Shared check of the viewer's package tests: one level of a package read and
// meshed by the wasm library (the browser's path, WebP through @jsquash/webp)
// against the native reader and mesh builder (viewer_test_tool).

import assert from 'node:assert/strict';
import fs from 'node:fs';

import { compareArrays, parseMeshBlob, runTool } from './node-support.mjs';
import { readPackageLevel } from './node-package.mjs';

/**
 * Reads `level` of the package in folder `pkg` with the wasm reader and builds
 * its full mesh; has viewer_test_tool do the same natively (writing
 * `${base}.mesh`). Asserts that positions, normals, uvs and indices are
 * byte-identical (depth, normals and links are stored lossless) and that
 * colours differ by at most `maxColourDifference` levels (the colour images are
 * lossy WebP, decoded by two different builds of libwebp).
 * Returns {triangles, colours: {differing, maxAbs}}.
 */
export async function assertLevelMatchesNative(format, pkg, level, base, { maxColourDifference = 2 } = {}) {
  runTool('viewer_test_tool', ['mesh', pkg, String(level), base]);
  const native = parseMeshBlob(fs.readFileSync(`${base}.mesh`));
  const { pano } = await readPackageLevel(format, pkg, level);
  let wasm;
  try {
    wasm = format.buildMesh(pano);
  } finally {
    pano.free();
  }
  for (const field of ['positions', 'normals', 'uvs', 'indices']) {
    const r = compareArrays(wasm[field], native[field]);
    assert.ok(r.sameLength, `${field}: ${wasm[field].length} (wasm) vs ${native[field].length} (native) elements`);
    assert.equal(r.differing, 0, `${field}: ${r.differing} elements differ (largest ${r.maxAbs})`);
  }
  const colours = compareArrays(wasm.colors, native.colors);
  assert.ok(colours.sameLength, `colors: ${wasm.colors.length} (wasm) vs ${native.colors.length} (native) elements`);
  assert.ok(colours.maxAbs <= maxColourDifference, `colours differ by up to ${colours.maxAbs}`);
  return { triangles: native.indices.length / 3, colours: { differing: colours.differing, maxAbs: colours.maxAbs } };
}
