// The wasm mesh builder, simplifier and backdrop give the same meshes as the native ones:
// byte-identical vertices (positions, normals, uvs, colours) and indices. Native meshes come
// from viewer_mesh_dump (tools/mesh_dump.cc), which also writes the panorama
// blob the wasm side builds from, so both start from identical bytes. Both wasm
// builds are checked: the single-threaded one and the threaded one.
//
//   node --test wasm-viewer/test/mesh_equivalence.test.mjs   (env CASUAL3D_BINARY_DIR)

import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { test } from 'node:test';
import { pathToFileURL } from 'node:url';

import { DIST_DIR, compareArrays, loadFormatModule, parseMeshBlob, runTool } from './node-support.mjs';

const CASES = [
  ['room', 64, 32],          // Depth edges and a back layer behind the sphere.
  ['room', 257, 130],        // Odd width: seam column handling.
  ['room-nosphere', 96, 48], // Fully linked, front only.
  ['sphere', 128, 64],       // Poles and the seam on a closed surface.
  ['test', 200, 100],        // Sky (zero normals), a near object, back-layer ring.
  ['room', 1024, 512],       // A realistic size.
];

const format = await loadFormatModule();
const formatThreaded = await loadFormatModule({ threads: true });
const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'casual3d-mesh-eq-'));
process.on('exit', () => fs.rmSync(dir, { recursive: true, force: true }));

for (const [kind, w, h] of CASES) {
  test(`wasm mesh == native mesh: ${kind} ${w}x${h}`, () => {
    const info = JSON.parse(runTool('viewer_mesh_dump', [kind, String(w), String(h), dir]));
    const base = path.join(dir, `${kind}_${w}x${h}`);
    const native = parseMeshBlob(fs.readFileSync(`${base}.mesh`));
    const nativeSimplified = parseMeshBlob(fs.readFileSync(`${base}.smesh`));
    const nativeBackdrop = parseMeshBlob(fs.readFileSync(`${base}.bmesh`));
    const meshes = (f) => {
      const pano = f.parsePanoramaBlob(fs.readFileSync(`${base}.pano`));
      try {
        pano.validate();
        return [f.buildMesh(pano), f.buildMesh(pano, { maxTriangles: info.budget }), f.buildBackdrop(pano)];
      } finally {
        pano.free();
      }
    };
    const [wasm, wasmSimplified, wasmBackdrop] = meshes(format);
    const [threaded, threadedSimplified, threadedBackdrop] = meshes(formatThreaded);
    assert.ok(nativeBackdrop.indices.length > 0, 'the native backdrop has triangles');
    assert.ok(native.indices.length > 0, 'the native mesh has triangles');
    assert.ok(nativeSimplified.indices.length < native.indices.length, 'simplification removed triangles');
    for (const [name, a, b] of [['full', wasm, native], ['simplified', wasmSimplified, nativeSimplified],
      ['full, threaded', threaded, native], ['simplified, threaded', threadedSimplified, nativeSimplified],
      ['backdrop', wasmBackdrop, nativeBackdrop], ['backdrop, threaded', threadedBackdrop, nativeBackdrop]]) {
      for (const field of ['positions', 'normals', 'uvs', 'colors', 'indices']) {
        const r = compareArrays(a[field], b[field]);
        assert.ok(r.sameLength, `${name} ${field}: ${a[field].length} (wasm) vs ${b[field].length} (native) elements`);
        assert.equal(r.differing, 0, `${name} ${field}: ${r.differing} elements differ, largest difference ${r.maxAbs}`);
      }
    }
  });
}

test('with threads "auto", a device that refuses shared memory gets the single-threaded build', async () => {
  const { FormatModule } = await import(pathToFileURL(path.join(DIST_DIR, 'format-module.js')).href);
  const wasmBinary = fs.readFileSync(path.join(DIST_DIR, 'casual3d-format.wasm'));
  const Memory = WebAssembly.Memory;
  WebAssembly.Memory = function (descriptor) {
    if (descriptor?.shared) throw new RangeError('could not allocate memory');
    return new Memory(descriptor);
  };
  try {
    const f = await FormatModule.create({ threads: 'auto', wasmBinary });
    assert.equal(f.numThreads, 1);
    await assert.rejects(FormatModule.create({ threads: true }), /could not allocate memory/);
  } finally {
    WebAssembly.Memory = Memory;
  }
});

test('wasm panorama blob parser refuses damaged input', () => {
  assert.throws(() => format.parsePanoramaBlob(new Uint8Array([1, 2, 3])), /bad magic/);
  runTool('viewer_mesh_dump', ['room', '16', '8', dir]);
  const bytes = fs.readFileSync(path.join(dir, 'room_16x8.pano'));
  assert.throws(() => format.parsePanoramaBlob(bytes.subarray(0, bytes.length - 5)), /truncated/);
  const huge = Buffer.from(bytes);
  huge.writeUInt32LE(1 << 20, 8);
  assert.throws(() => format.parsePanoramaBlob(huge), /beyond the limit/);
});

test('a browser without WebAssembly SIMD gets a message naming it', async () => {
  const validate = WebAssembly.validate;
  // Such a browser refuses every module with a SIMD instruction.
  WebAssembly.validate = (bytes) => !Array.from(bytes).includes(253) && validate(bytes);
  try {
    await assert.rejects(loadFormatModule(), /lacks WebAssembly SIMD.*Safari 16\.4/);
  } finally {
    WebAssembly.validate = validate;
  }
  assert.ok(await loadFormatModule(), 'loads again with SIMD');
});
