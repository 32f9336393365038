// The npm package as a web project gets it:
//  - tools/pack.mjs stages the built viewer and runs `npm pack`; the tarball
//    holds the element, both wasm builds, the types, README and package.json
//    (version = the project's), and no test files, repository tools or paths
//    of this machine;
//  - a copy of examples/web installs it from the tarball (offline, with
//    esbuild from npm's cache) and bundles its page with esbuild;
//  - casual3d-viewer/format, imported by name in that project under Node,
//    reads every spec vector (folder and .c3d) with the figures of
//    spec/vectors/expected.json, and the example script runs;
//  - in headless Chromium the bundled page and the plain <script type=module>
//    page show a .c3d like the native renderer (PSNR >= 30 dB).
// The browser part is skipped with a message without Chromium.

import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { after, before, test } from 'node:test';

import { pack } from '../tools/pack.mjs';
import { psnr, readCanvas, readPpm } from './native-comparison.mjs';
import { BINARY_DIR, DIST_DIR, SOURCE_DIR, runTool } from './node-support.mjs';
import { chromiumArgs, startServer } from './static-server.mjs';

const VECTORS = path.join(SOURCE_DIR, 'spec', 'vectors');
const OUT = path.join(BINARY_DIR, 'wasm-viewer', 'npm-test');
const W = 480, H = 320;
const CAMERA = { yawDeg: 10, pitchDeg: -10, fovDeg: 75, position: [0, 0, 0] };
let tmp, tarball, app;

before(() => {
  tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'casual3d-npm-'));
  fs.mkdirSync(OUT, { recursive: true });
});

after(() => {
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
});

test('npm pack: the element, both wasm builds, types, README; no tests, tools or build paths', () => {
  tarball = pack(DIST_DIR, path.join(tmp, 'pack'));
  const pkgJson = JSON.parse(fs.readFileSync(path.join(SOURCE_DIR, 'wasm-viewer', 'package.json'), 'utf8'));
  assert.equal(path.basename(tarball), `casual3d-viewer-${pkgJson.version}.tgz`);
  const files = execFileSync('tar', ['-tzf', tarball], { encoding: 'utf8' }).trim().split('\n').sort();
  for (const f of ['package.json', 'README.md', 'LICENSE', 'dist/casual3d-viewer.js', 'dist/casual3d-viewer.d.ts', 'dist/format.js',
    'dist/format-node.js', 'dist/format.d.ts', 'dist/worker.js', 'dist/casual3d-format.js', 'dist/casual3d-format.wasm',
    'dist/casual3d-format-mt.js', 'dist/casual3d-format-mt.wasm', 'dist/casual3d-format-mt.worker.js']) {
    assert.ok(files.includes(`package/${f}`), `${f} is in the tarball`);
  }
  for (const f of files) {
    assert.ok(f.startsWith('package/'), f);
    assert.doesNotMatch(f, /(^|\/)(test|tests|tools|bench|src|node_modules)\/|\.test\.|\.mjs$|\.cc$|\.ts$(?<!\.d\.ts)/, `${f} does not belong in the package`);
  }
  // No path of this machine inside any file (wasm included).
  const unpacked = path.join(tmp, 'unpacked');
  fs.mkdirSync(unpacked);
  execFileSync('tar', ['-xzf', tarball, '-C', unpacked]);
  const machinePaths = [SOURCE_DIR, BINARY_DIR, path.resolve(DIST_DIR), tmp, os.homedir()].filter((p) => p.length > 1);
  for (const f of files) {
    const bytes = fs.readFileSync(path.join(unpacked, f)).toString('latin1');
    for (const p of machinePaths) assert.ok(!bytes.includes(p), `${f} holds the path ${p}`);
  }
  const published = JSON.parse(fs.readFileSync(path.join(unpacked, 'package', 'package.json'), 'utf8'));
  assert.equal(published.private, undefined);
  assert.ok(published.license);
  assert.deepEqual(Object.keys(published.exports).sort(), ['.', './format', './package.json']);
  assert.equal(published.exports['./format'].node, './dist/format-node.js');
  assert.equal(published.scripts, undefined);
  console.log(`tarball: ${path.basename(tarball)}, ${fs.statSync(tarball).size} bytes, ${files.length} files`);
});

test('a web project installs the tarball offline and bundles its page with esbuild', () => {
  assert.ok(tarball, 'packed');
  app = path.join(tmp, 'app');
  fs.cpSync(path.join(SOURCE_DIR, 'examples', 'web'), app, {
    recursive: true, filter: (f) => !/(node_modules|dist)$/.test(f),
  });
  // A lock file with the versions this repository pins (wasm-viewer/
  // package-lock.json) for the project's other packages, with their tarballs'
  // addresses, so that npm installs them from its cache (filled by `npm ci`
  // in wasm-viewer/) without asking the registry.
  const pinned = JSON.parse(fs.readFileSync(path.join(SOURCE_DIR, 'wasm-viewer', 'package-lock.json'), 'utf8'));
  const appJson = JSON.parse(fs.readFileSync(path.join(app, 'package.json'), 'utf8'));
  const packages = { '': { name: appJson.name, devDependencies: appJson.devDependencies } };
  for (const [key, entry] of Object.entries(pinned.packages)) {
    const name = key.replace(/^node_modules\//, '');
    if (!/^(esbuild|@esbuild\/|@jsquash\/webp|wasm-feature-detect)/.test(name)) continue;
    packages[key] = { ...entry, resolved: `https://registry.npmjs.org/${name}/-/${name.split('/').pop()}-${entry.version}.tgz` };
  }
  fs.writeFileSync(path.join(app, 'package-lock.json'), JSON.stringify({ name: appJson.name, lockfileVersion: 3, requires: true, packages }));
  delete appJson.dependencies['casual3d-viewer'];
  fs.writeFileSync(path.join(app, 'package.json'), JSON.stringify(appJson, null, 2));
  try {
    execFileSync('npm', ['install', tarball, '--offline', '--no-audit', '--no-fund', '--loglevel=error'],
      { cwd: app, encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });
  } catch (err) {
    assert.fail(`npm install --offline failed (esbuild and @jsquash/webp come from npm's cache, which \`npm ci\` in ` +
      `wasm-viewer/ fills):\n${err.stderr}`);
  }
  const installed = JSON.parse(fs.readFileSync(path.join(app, 'node_modules', 'casual3d-viewer', 'package.json'), 'utf8'));
  assert.equal(installed.version, path.basename(tarball).match(/-(\d+\.\d+\.\d+.*)\.tgz$/)[1]);
  const out = execFileSync('npm', ['run', '--silent', 'build'], { cwd: app, encoding: 'utf8' });
  assert.match(out, /dist\/app\.js: \d+ bytes/);
  const bundle = fs.readFileSync(path.join(app, 'dist', 'app.js'), 'utf8');
  assert.match(bundle, /casual3d-viewer/, 'the element is in the bundle');
  for (const f of ['worker.js', 'format-module.js', 'casual3d-format.wasm', 'casual3d-format-mt.wasm']) {
    assert.ok(fs.existsSync(path.join(app, 'dist', 'casual3d', f)), `dist/casual3d/${f}`);
  }
});

/** Sums of spec/package.md Sec. 9 over one level read with casual3d-viewer/format. */
const FIGURES_SCRIPT = `
import { createHash } from 'node:crypto';
import { openPackage, createFormat } from 'casual3d-viewer/format';
const [input, threads] = process.argv.slice(2);
const pkg = await openPackage(input, { format: await createFormat({ threads: threads === 'mt' }) });
const levels = [];
for (let level = 0; level < pkg.numLevels; ++level) {
  const pano = await pkg.readLevel(level);
  const n = pano.width * pano.height;
  const f = { width: pano.width, height: pano.height, present: [], rgb_sum: [], depth_sum_m: [], normal_sum: [] };
  const graph = createHash('sha256');
  for (const l of [0, 1]) {
    const layer = pano.layer(l);
    let present = 0, rgb = 0, depth = 0;
    const normal = [0, 0, 0];
    for (let i = 0; i < n; ++i) {
      if (!layer.present[i]) continue;
      ++present;
      rgb += layer.rgb[3 * i] + layer.rgb[3 * i + 1] + layer.rgb[3 * i + 2];
      depth += layer.depth[i];
      for (let c = 0; c < 3; ++c) normal[c] += layer.normal[3 * i + c];
    }
    f.present.push(present); f.rgb_sum.push(rgb); f.depth_sum_m.push(depth); f.normal_sum.push(normal);
    graph.update(layer.present); graph.update(layer.label); graph.update(layer.links);
  }
  f.graph_sha256 = graph.digest('hex');
  const meshSha = (m) => {
    const h = createHash('sha256');
    for (const a of [m.positions, m.normals, m.uvs, m.indices]) h.update(new Uint8Array(a.buffer, a.byteOffset, a.byteLength));
    return { vertices: m.positions.length / 3, triangles: m.indices.length / 3, sha256: h.digest('hex') };
  };
  f.mesh = { full: meshSha(pano.mesh()), simplified: [0.01, 0.05].map((e) => meshSha(pano.mesh({ maxRelativeError: e }))) };
  pano.free();
  levels.push(f);
}
pkg.close();
console.log(JSON.stringify({ kind: pkg.kind, levels }));
`;

test('casual3d-viewer/format in Node reads the spec vectors with the expected figures', () => {
  assert.ok(app, 'installed');
  fs.writeFileSync(path.join(app, 'figures.mjs'), FIGURES_SCRIPT);
  const expected = JSON.parse(fs.readFileSync(path.join(VECTORS, 'expected.json'), 'utf8'));
  assert.ok(Object.keys(expected).length >= 2);
  for (const [name, levels] of Object.entries(expected)) {
    for (const [input, kind, threads] of [[path.join(VECTORS, name), 'folder', 'st'], [path.join(VECTORS, `${name}.c3d`), 'single-file', 'mt']]) {
      const got = JSON.parse(execFileSync('node', ['figures.mjs', input, threads], { cwd: app, encoding: 'utf8' }));
      const what = `${path.basename(input)}`;
      assert.equal(got.kind, kind, what);
      assert.equal(got.levels.length, levels.length, `${what}: levels`);
      levels.forEach((e, level) => {
        const g = got.levels[level];
        const at = `${what} level ${level}`;
        assert.deepEqual([g.width, g.height], [e.width, e.height], at);
        assert.deepEqual(g.present, e.present, `${at}: present`);
        assert.deepEqual(g.rgb_sum, e.rgb_sum, `${at}: rgb_sum`);
        for (const l of [0, 1]) {
          const tolerance = 1e-6 * Math.max(1, Math.abs(e.depth_sum_m[l]));
          assert.ok(Math.abs(g.depth_sum_m[l] - e.depth_sum_m[l]) <= tolerance, `${at}: depth_sum_m ${g.depth_sum_m[l]} vs ${e.depth_sum_m[l]}`);
          for (let c = 0; c < 3; ++c) assert.ok(Math.abs(g.normal_sum[l][c] - e.normal_sum[l][c]) <= 1e-3, `${at}: normal_sum`);
        }
        assert.equal(g.graph_sha256, e.graph_sha256, `${at}: graph_sha256`);
        if (e.mesh) {
          assert.deepEqual(g.mesh.full, e.mesh.full, `${at}: full mesh`);
          e.mesh.simplified.forEach((s, k) => {
            const { max_relative_error: _, ...counts } = s;
            assert.deepEqual(g.mesh.simplified[k], counts, `${at}: simplified mesh ${s.max_relative_error}`);
          });
        }
      });
    }
  }
  const example = execFileSync('node', ['read-package.mjs', path.join(VECTORS, 'two-layer-64x32.c3d')], { cwd: app, encoding: 'utf8' });
  assert.match(example, /single-file, 2 levels/);
  assert.match(example, /level 0 \(64x32\) front: 2048 nodes, depth/);
  assert.match(example, /level 1 mesh: \d+ vertices, \d+ triangles/);
});

test('both pages show a .c3d in headless Chromium like the native renderer', async (t) => {
  assert.ok(app, 'installed');
  const executable = process.env.CASUAL3D_CHROMIUM ?? '/usr/bin/chromium';
  if (!fs.existsSync(executable)) return t.skip(`SKIP: ${executable} is not installed (apt-get install chromium)`);
  const { chromium } = await import('playwright-core');
  // A package and the native renderer's image of it.
  const folder = path.join(tmp, 'room');
  runTool('viewer_test_tool', ['package', 'room', '512', '256', folder, '128', '2']);
  runTool('viewer_test_tool', ['single-file', folder, path.join(app, 'photo.c3d')]);
  runTool('viewer_test_tool', ['render', folder, '0', String(W), String(H), path.join(OUT, 'reference'),
    [CAMERA.yawDeg, CAMERA.pitchDeg, CAMERA.fovDeg, ...CAMERA.position].join(',')]);
  const reference = readPpm(path.join(OUT, 'reference_0.ppm'));
  const server = await startServer({ '/': app }, { '/favicon.ico': '' }, { isolated: true });
  const browser = await chromium.launch({ executablePath: executable, args: chromiumArgs() });
  try {
    for (const pageName of ['index.html', 'plain.html']) {
      const page = await browser.newPage({ viewport: { width: W, height: H }, deviceScaleFactor: 1 });
      page.on('pageerror', (e) => console.log(`${pageName}: page error: ${e.message}`));
      page.on('console', (m) => { if (m.type() === 'error') console.log(`${pageName}: console: ${m.text()}`); });
      // The example's own page, with the viewer sized like the reference.
      await page.addInitScript(`document.addEventListener('DOMContentLoaded', () => {
        const s = document.createElement('style');
        s.textContent = 'body{margin:0} casual3d-viewer{width:${W}px;height:${H}px} p{display:none}';
        document.head.append(s);
        document.querySelector('casual3d-viewer').id = 'v';
      });`);
      await page.goto(`${server.url}/${pageName}`);
      await page.waitForFunction(() => {
        const v = document.querySelector('casual3d-viewer')?.viewer;
        return v && (v.stats.loadMs !== undefined || document.querySelector('casual3d-viewer').errorMessage);
      }, null, { timeout: 120000, polling: 200 });
      const state = await page.evaluate(() => {
        const el = document.querySelector('casual3d-viewer');
        return { error: el.errorMessage, level: el.viewer.stats.level };
      });
      assert.equal(state.error, '', pageName);
      assert.equal(state.level, 0, `${pageName}: the finest level shows`);
      await page.evaluate((c) => document.getElementById('v').setCamera(c), CAMERA);
      const db = psnr(await readCanvas(page), reference.data, W, H);
      await page.screenshot({ path: path.join(OUT, pageName.replace('.html', '.png')) });
      console.log(`${pageName}: PSNR ${db.toFixed(2)} dB against the native renderer`);
      assert.ok(db >= 30, `${pageName}: PSNR ${db.toFixed(2)} dB < 30 dB`);
      await page.close();
    }
    // The bundled page fetched the viewer's runtime from dist/casual3d/, the plain one from node_modules/.
    const paths = server.log.map((r) => r.path);
    assert.ok(paths.includes('/dist/casual3d/worker.js'));
    assert.ok(paths.includes('/node_modules/casual3d-viewer/dist/worker.js'));
    assert.ok(server.log.filter((r) => r.path === '/photo.c3d').every((r) => r.status === 206));
  } finally {
    await browser.close();
    await server.close();
  }
});
