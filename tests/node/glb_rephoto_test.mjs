// The exported GLB as three.js shows it, scored like the package itself:
// a synthetic capture's ground-truth 3D photo is exported (plain and Draco
// GLB), rendered by three.js in headless Chromium from the photos' cameras
// (`casual3d evaluate --write-cameras`, wasm-viewer/bench/glb_rephoto.mjs),
// and `casual3d evaluate --rendered` scores those images. They must come
// within 0.5 dB (whole frame) and 0.01 completeness of the native
// rephotography: a wrong axis, pixel convention, colour space or texture
// orientation in the GLB costs far more. Bad inputs give one-line errors.
//
//   node glb_rephoto_test.mjs --casual3d PROGRAM --work DIR
// Exit code 77 (skip) when Chromium is not installed.

import assert from 'node:assert/strict';
import { execFileSync, spawnSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const args = Object.fromEntries(process.argv.slice(2).reduce((a, v, i, all) => (i % 2 ? a : [...a, [v.slice(2), all[i + 1]]]), []));
if (!args.casual3d || !args.work) throw new Error('usage: glb_rephoto_test.mjs --casual3d PROGRAM --work DIR');
if (!fs.existsSync('/usr/bin/chromium') && !process.env.CASUAL3D_CHROMIUM) {
  console.log('SKIP: chromium is not installed (apt-get install chromium); the GLB rephotography test needs it');
  process.exit(77);
}
const here = path.dirname(fileURLToPath(import.meta.url));
const renderer = path.join(here, '..', '..', 'wasm-viewer', 'bench', 'glb_rephoto.mjs');
const work = path.resolve(args.work);
fs.rmSync(work, { recursive: true, force: true });
fs.mkdirSync(work, { recursive: true });
const run = (program, argv) => execFileSync(program, argv, { cwd: work, encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });
args.casual3d = path.resolve(args.casual3d);
const casual3d = (...argv) => run(args.casual3d, argv);
const wholeFrame = (out) => {
  const m = out.match(/completeness ([0-9.]+), PSNR [0-9.]+ dB, SSIM [0-9.]+ \(whole frame ([0-9.]+) dB/);
  assert.ok(m, `unexpected output of casual3d evaluate:\n${out}`);
  return { completeness: Number(m[1]), psnr: Number(m[2]) };
};

casual3d('synth', '--width', '192', '--photos', '4', '--panorama-width', '1024', '-o', 'capture');
casual3d('encode', 'capture/ground_truth/master.exr', '-o', 'package', '--no-viewer');
const evaluate = ['evaluate', 'capture', 'package', '--width', '192', '--no-viewer-views'];
const native = wholeFrame(casual3d(...evaluate, '--write-cameras', 'cameras.json', '-o', 'native.html',
  '--rephoto-images', 'rephotos'));
const cameras = JSON.parse(fs.readFileSync(path.join(work, 'cameras.json'), 'utf8'));
assert.equal(cameras.cameras.length, 4);
// --rephoto-images: each evaluated photo and its rephotograph as PNG.
const rephotos = fs.readdirSync(path.join(work, 'rephotos')).sort();
assert.equal(rephotos.filter((f) => /^0_.+_render\.png$/.test(f)).length, 4, rephotos.join(' '));
assert.equal(rephotos.filter((f) => /^0_.+_photo\.png$/.test(f)).length, 4, rephotos.join(' '));
console.log(`native: ${JSON.stringify(native)}`);

for (const draco of [false, true]) {
  const name = draco ? 'draco' : 'plain';
  casual3d('export', 'package', '--glb', `${name}.glb`, ...(draco ? ['--draco'] : []));
  const r = spawnSync(process.execPath, [renderer, `${name}.glb`, 'cameras.json', `renders_${name}`], { cwd: work, encoding: 'utf8' });
  assert.equal(r.status, 0, `glb_rephoto.mjs failed:\n${r.stdout}\n${r.stderr}`);
  const three = wholeFrame(casual3d(...evaluate, '--rendered', `renders_${name}`, '-o', `${name}.html`));
  console.log(`three.js ${name}: ${JSON.stringify(three)}`);
  assert.ok(Math.abs(three.psnr - native.psnr) <= 0.5, `${name}: ${three.psnr} dB against ${native.psnr} dB natively`);
  assert.ok(Math.abs(three.completeness - native.completeness) <= 0.01, `${name}: completeness ${three.completeness} against ${native.completeness}`);
}

// A renderer reading the matrices row-major (the classic mistake) is caught.
const transposed = structuredClone(cameras);
for (const c of transposed.cameras) {
  c.view_matrix = c.view_matrix.map((_, i) => c.view_matrix[4 * (i % 4) + Math.floor(i / 4)]);
}
fs.writeFileSync(path.join(work, 'transposed.json'), JSON.stringify(transposed));
const t = spawnSync(process.execPath, [renderer, 'plain.glb', 'transposed.json', 'transposed'], { cwd: work, encoding: 'utf8' });
assert.equal(t.status, 0, t.stderr);
const wrong = wholeFrame(casual3d(...evaluate, '--rendered', 'transposed', '-o', 'transposed.html'));
console.log(`transposed view matrices: ${JSON.stringify(wrong)}`);
assert.ok(wrong.psnr < native.psnr - 3, `renderings with transposed view matrices scored ${wrong.psnr} dB`);

// Bad inputs: one line naming the input, non-zero exit, no report written.
const refuse = (argv, pattern) => {
  const r = spawnSync(args.casual3d, argv, { cwd: work, encoding: 'utf8' });
  assert.notEqual(r.status, 0, `${argv.join(' ')} succeeded`);
  assert.match(r.stderr.trim(), pattern);
  assert.equal(r.stderr.trim().split('\n').length, 1, r.stderr);
};
fs.mkdirSync(path.join(work, 'empty'));
refuse([...evaluate, '--rendered', 'empty', '-o', 'x.html'], /empty\/0000\.png: no rendering of photo 0000\.jpg/);
refuse([...evaluate, '--rendered', 'missing', '-o', 'x.html'], /missing: not a folder/);
refuse([...evaluate.slice(0, 3), 'package', '--write-cameras', 'c.json', '-o', 'x.html'], /--write-cameras: give exactly one 3D photo/);
assert.ok(!fs.existsSync(path.join(work, 'x.html')));
const bad = spawnSync(process.execPath, [renderer, 'plain.glb', 'native.html', 'out'], { cwd: work, encoding: 'utf8' });
assert.equal(bad.status, 1);
assert.match(bad.stderr, /native\.html: not a readable JSON cameras file/);
console.log('glb_rephoto_test: passed');
