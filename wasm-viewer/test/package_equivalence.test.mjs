// The wasm package reader and mesh builder (the browser's path, here with a
// wasm libwebp decoder) give the same mesh as the native reader (libwebp) and
// mesh builder on a synthetic package: positions, normals, uvs and indices
// byte-identical (depth, normals and links are lossless), colours within 2
// levels (the colour images are lossy WebP and the two decoders are different
// builds of libwebp; measured difference printed). Both wasm builds: the
// single-threaded one and the threaded one (casual3d-format-mt), which must
// give the same mesh.

import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { test } from 'node:test';

import { assertLevelMatchesNative } from './native-comparison.mjs';
import { loadFormatModule, runTool } from './node-support.mjs';
import { readPackageLevel } from './node-package.mjs';

const format = await loadFormatModule();
const formatThreaded = await loadFormatModule({ threads: true });
const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'casual3d-pkg-eq-'));
process.on('exit', () => fs.rmSync(dir, { recursive: true, force: true }));
const pkg = path.join(dir, 'pkg');
runTool('viewer_test_tool', ['package', 'test', '1024', '512', pkg, '256', '2']);
// The delivery settings with lossy normals (package version 1.2), whose grey
// images both libwebp builds decode to the same codes.
const delivery = path.join(dir, 'delivery');
runTool('viewer_test_tool', ['package', 'test', '1024', '512', delivery, '256', '2', 'lossy-normals']);

for (const [name, f] of [['single-threaded', format], ['threaded', formatThreaded]]) {
  for (const level of [1, 0]) {
    test(`package level ${level}: wasm reader + mesh (${name}) == native reader + mesh`, async () => {
      const { triangles, colors } = await assertLevelMatchesNative(f, pkg, level, path.join(dir, `native_${name}_${level}`));
      assert.ok(triangles > 1000, `only ${triangles} triangles`);
      console.log(`level ${level}, ${name} (${f.numThreads} threads): ${triangles} triangles; colours differing: ${colors.differing}, largest difference ${colors.maxAbs}`);
    });
  }
}

test('a delivery package with lossy normals: wasm reader + mesh == native reader + mesh', async () => {
  const manifest = JSON.parse(fs.readFileSync(path.join(delivery, 'manifest.json'), 'utf8'));
  assert.equal(manifest.version, '1.2');
  assert.equal(manifest.normal_encoding.type, 'octahedral-lossy');
  for (const level of [0, 1]) {
    const { triangles } = await assertLevelMatchesNative(format, delivery, level, path.join(dir, `native_delivery_${level}`));
    assert.ok(triangles > 1000, `only ${triangles} triangles`);
  }
});

test('the threaded build uses more than one thread where the machine has them', () => {
  assert.equal(format.numThreads, 1);
  const cores = os.availableParallelism?.() ?? os.cpus().length;
  assert.equal(formatThreaded.numThreads, Math.max(1, Math.min(4, cores)));
});

test('the reader gives the depth range and the tile image type of the manifest', () => {
  const bytes = fs.readFileSync(path.join(pkg, 'manifest.json'));
  const manifest = JSON.parse(new TextDecoder().decode(bytes));
  const reader = format.openPackage(bytes);
  try {
    assert.ok(manifest.depth_encoding.far_m > 0);
    assert.equal(reader.depthFarM, manifest.depth_encoding.far_m);
    assert.equal(reader.tileImageType, 'image/webp');
  } finally {
    reader.free();
  }
});

test('a damaged tile is refused with a message naming it', async () => {
  const bad = path.join(dir, 'bad');
  fs.cpSync(pkg, bad, { recursive: true });
  const manifest = JSON.parse(fs.readFileSync(path.join(bad, 'manifest.json'), 'utf8'));
  const file = manifest.levels[1].tiles[0].depth;
  const bytes = fs.readFileSync(path.join(bad, file));
  fs.writeFileSync(path.join(bad, file), bytes.subarray(0, bytes.length - 10));
  await assert.rejects(readPackageLevel(format, bad, 1), new RegExp(file.replace(/\./g, '\\.')));
  await assert.rejects(readPackageLevel(formatThreaded, bad, 1), new RegExp(file.replace(/\./g, '\\.')));
  assert.throws(() => format.openPackage(new TextEncoder().encode('{"format": "casual3d", "version": "9.0"}')), /manifest\.json/);
});
