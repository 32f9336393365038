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

import { assertLevelMatchesNative } from './native-comparison.mjs';
import { SOURCE_DIR, loadFormatModule } from './node-support.mjs';
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
      const { triangles } = await assertLevelMatchesNative(format, pkg, level, path.join(dir, `${name}_${level}`));
      assert.ok(triangles > 0);
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
