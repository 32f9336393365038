// The spec's conformance vectors (spec/vectors/) through the wasm reader and
// mesh builder (the browser's path, WebP via @jsquash/webp): every level of
// every valid vector gives the native reader's and builder's mesh (geometry
// byte-identical, colours within 2 levels of the lossy WebP), and every vector
// under invalid/ is refused with a message.

import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { test } from 'node:test';

import { SOURCE_DIR, compareArrays, loadFormatModule, parseMeshBlob, runTool } from './node-support.mjs';
import { readPackageLevel } from './node-package.mjs';

const VECTORS = path.join(SOURCE_DIR, 'spec', 'vectors');
const format = await loadFormatModule();
const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'casual3d-vectors-'));
process.on('exit', () => fs.rmSync(dir, { recursive: true, force: true }));

const valid = fs.readdirSync(VECTORS).filter((n) => fs.existsSync(path.join(VECTORS, n, 'manifest.json')));
assert.ok(valid.length >= 2, `expected conformance packages in ${VECTORS}`);

for (const name of valid) {
  const pkg = path.join(VECTORS, name);
  const levels = JSON.parse(fs.readFileSync(path.join(pkg, 'manifest.json'), 'utf8')).levels.length;
  for (let level = 0; level < levels; ++level) {
    test(`${name} level ${level}: wasm == native`, async () => {
      const base = path.join(dir, `${name}_${level}`);
      runTool('viewer_test_tool', ['mesh', pkg, String(level), base]);
      const native = parseMeshBlob(fs.readFileSync(`${base}.mesh`));
      const { pano } = await readPackageLevel(format, pkg, level);
      let wasm;
      try {
        wasm = format.buildMesh(pano);
      } finally {
        pano.free();
      }
      assert.ok(native.indices.length > 0);
      for (const field of ['positions', 'normals', 'uvs', 'indices']) {
        const r = compareArrays(wasm[field], native[field]);
        assert.ok(r.sameLength, `${field}: ${wasm[field].length} vs ${native[field].length} elements`);
        assert.equal(r.differing, 0, `${field}: ${r.differing} elements differ (largest ${r.maxAbs})`);
      }
      const colors = compareArrays(wasm.colors, native.colors);
      assert.ok(colors.sameLength && colors.maxAbs <= 2, `colours differ by up to ${colors.maxAbs}`);
    });
  }
}

const invalidDir = path.join(VECTORS, 'invalid');
for (const name of fs.existsSync(invalidDir) ? fs.readdirSync(invalidDir) : []) {
  test(`invalid/${name} is refused`, async () => {
    const pkg = path.join(invalidDir, name);
    const read = async () => {
      const manifest = JSON.parse(fs.readFileSync(path.join(pkg, 'manifest.json'), 'utf8'));
      const n = manifest.levels?.length ?? 1;
      for (let level = n - 1; level >= 0; --level) {
        const { pano } = await readPackageLevel(format, pkg, level);
        pano.free();
      }
    };
    await assert.rejects(read(), (err) => err instanceof Error && err.message.length > 10);
  });
}
