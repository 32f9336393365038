// The spec's conformance vectors (spec/vectors/) through the wasm reader and
// mesh builder (the browser's path, WebP via @jsquash/webp): every level of
// every valid vector gives the native reader's and builder's mesh (geometry
// byte-identical, colours within 2 levels of the lossy WebP), and every vector
// under invalid/ (package folders through the tile reader, .c3d files
// through the format entry) is refused for its content, with a message.

import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { test } from 'node:test';
import { pathToFileURL } from 'node:url';

import { assertLevelMatchesNative } from './native-comparison.mjs';
import { DIST_DIR, SOURCE_DIR, loadFormatModule } from './node-support.mjs';
import { readPackageLevel } from './node-package.mjs';

// The format entry of the npm package, as built, laid out as installed: the
// built files with the viewer's npm packages (its WebP decoder) beside them.
const installed = fs.mkdtempSync(path.join(os.tmpdir(), 'casual3d-format-entry-'));
process.on('exit', () => fs.rmSync(installed, { recursive: true, force: true }));
fs.cpSync(DIST_DIR, path.join(installed, 'dist'), { recursive: true });
fs.symlinkSync(path.join(SOURCE_DIR, 'wasm-viewer', 'node_modules'), path.join(installed, 'node_modules'));
const { createFormat, openPackage } = await import(pathToFileURL(path.join(installed, 'dist', 'format-node.js')).href);

let formatEntryModule;
const formatEntry = async () => (formatEntryModule ??= await createFormat({ threads: false }));

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

// The same path reads every valid vector's .c3d, so that a refusal below is
// the invalid vector's own.
const readC3d = async (file) => {
  const opened = await openPackage(file, { format: await formatEntry() });
  for (let level = opened.numLevels - 1; level >= 0; --level) (await opened.readLevel(level)).free?.();
};
for (const name of valid) {
  test(`${name}.c3d reads through the format entry`, async () => {
    await readC3d(path.join(VECTORS, `${name}.c3d`));
  });
}

const invalidDir = path.join(VECTORS, 'invalid');
// What each invalid vector's refusal says (spec/vectors/refusals.json, the
// table tests/conformance_test.cc checks against spec/package.md Sec. 9.1):
// the rule it breaks, not a file the test failed to find.
const REFUSALS = JSON.parse(fs.readFileSync(path.join(VECTORS, 'refusals.json'), 'utf8'));
const refusedFor = (name) => (err) => {
  const words = REFUSALS[name.replace(/\.c3d$/, '')];
  assert.ok(words, `invalid/${name}: spec/vectors/refusals.json lists no refusal for it`);
  assert.ok(err.message.includes(words), `invalid/${name}: refused with "${err.message}", expected "${words}"`);
  return true;
};
for (const name of fs.existsSync(invalidDir) ? fs.readdirSync(invalidDir) : []) {
  test(`invalid/${name} is refused`, async () => {
    const pkg = path.join(invalidDir, name);
    const read = async () => {
      if (name.endsWith('.c3d')) {
        // The single file through the format entry (header, directory, then
        // every level, the coarsest first).
        await readC3d(pkg);
        return;
      }
      const manifest = JSON.parse(fs.readFileSync(path.join(pkg, 'manifest.json'), 'utf8'));
      const n = manifest.levels?.length ?? 1;
      for (let level = n - 1; level >= 0; --level) {
        const { pano } = await readPackageLevel(format, pkg, level);
        pano.free();
      }
    };
    await assert.rejects(read(), refusedFor(name));
  });
}
