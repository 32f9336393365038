// Browser test of the sheets the viewer leaves out where it draws the backdrop
// (format/sheet_stretch.h, spec/mesh.md Sec. 8), in Debian's headless
// Chromium: a room whose sphere's outline is linked to the wall behind it
// (viewer_test_tool's room-sheets, sheets across a depth step as the sealing
// makes them), seen from off the centre,
//  - matches the native renderer drawing it as the viewer does (backdrop,
//    sheets left out) with PSNR >= 30 dB, and matches it far better than the
//    viewer drawing every sheet does (the sheets are there and are left out);
//  - from the centre, leaving sheets out changes nothing.
// Exits 77 (ctest: skipped) when Chromium is not installed.

import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { after, before, test } from 'node:test';

import { psnr, readCanvas, readPpm } from './native-comparison.mjs';
import { BINARY_DIR, DIST_DIR, copyPackageWithView, runTool } from './node-support.mjs';
import { chromiumArgs, chromiumOrSkip, startServer, viewerCorePage } from './static-server.mjs';

const { chromium, executable: CHROMIUM } = await chromiumOrSkip('the sheets test');

const W = 480, H = 320;
const OUT = path.join(BINARY_DIR, 'wasm-viewer', 'sheets-test');
// Towards the sphere (centre (0.4, -0.3, -1.6), radius 0.6): from the centre
// and from 0.2 m to the side, inside the 0.3 m viewing volume.
const CENTRE = { yawDeg: 14, pitchDeg: -10, fovDeg: 60, position: [0, 0, 0] };
const SIDE = { ...CENTRE, position: [0.2, 0.05, 0] };
// A backdrop of the library's default cell (maxTriangles would coarsen it).
const OPTIONS = { mouseParallax: false, maxTriangles: 8000000 };

let tmp, server, browser, page;

before(async () => {
  fs.mkdirSync(OUT, { recursive: true });
  tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'casual3d-sheets-'));
  const plain = path.join(tmp, 'plain');
  runTool('viewer_test_tool', ['package', 'room-sheets', '1024', '512', plain, '256', '1']);
  const pkg = path.join(tmp, 'pkg');
  copyPackageWithView(plain, pkg, {
    yaw_deg: 0, pitch_deg: 0, fov_deg: 75, content_yaw_deg: [-180, 180], content_pitch_deg: [-90, 90],
    volume_radius: 0.3, metric: true,
  });
  server = await startServer({ '/viewer/': DIST_DIR, '/pkg/': pkg }, {
    '/hidden.html': viewerCorePage(OPTIONS, W, H),
    '/drawn.html': viewerCorePage({ ...OPTIONS, sheetStretch: 0 }, W, H),
    '/favicon.ico': '',
  }, { isolated: true });
  browser = await chromium.launch({ executablePath: CHROMIUM, args: chromiumArgs() });
  page = await browser.newPage({ viewport: { width: W, height: H }, deviceScaleFactor: 1 });
  page.on('pageerror', (e) => console.log(`page error: ${e.message}`));
  runTool('viewer_test_tool', ['render', '--viewer', pkg, '0', String(W), String(H), path.join(OUT, 'native'),
    ...[CENTRE, SIDE].map((c) => [c.yawDeg, c.pitchDeg, c.fovDeg, ...c.position].join(','))]);
});

after(async () => {
  await browser?.close();
  await server?.close();
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
});

/** The frame (RGBA, bottom row first) of page `name` from `camera`. */
async function frame(name, camera) {
  await page.goto(`${server.url}/${name}.html`);
  await page.waitForFunction(() => window.loaded, null, { timeout: 300000 });
  await page.evaluate(() => window.loaded);
  await page.evaluate(async (c) => {
    window.viewer.setCamera(c);
    await window.viewer.nextFrame();
  }, camera);
  const pixels = await readCanvas(page);
  await page.screenshot({ path: path.join(OUT, `${name}_${camera.position[0] === 0 ? 'centre' : 'side'}.png`) });
  return pixels;
}

/** Pixels whose RGB differs by more than 24 levels in some channel. */
function differing(a, b) {
  let n = 0;
  for (let i = 0; i < a.length; i += 4) {
    if (Math.max(Math.abs(a[i] - b[i]), Math.abs(a[i + 1] - b[i + 1]), Math.abs(a[i + 2] - b[i + 2])) > 24) ++n;
  }
  return n;
}

test('from off the centre the viewer leaves the sheets out as the native renderer does', async () => {
  const native = readPpm(path.join(OUT, 'native_1.ppm'));
  assert.equal(native.width, W);
  const hidden = await frame('hidden', SIDE);
  const drawn = await frame('drawn', SIDE);
  const hiddenDb = psnr(hidden, native.data, W, H), drawnDb = psnr(drawn, native.data, W, H);
  console.log(`side: PSNR against the native renderer ${hiddenDb.toFixed(2)} dB (sheets left out), ` +
    `${drawnDb.toFixed(2)} dB (sheets drawn); ${differing(hidden, drawn)} pixels differ`);
  assert.ok(hiddenDb >= 30, `sheets left out: PSNR ${hiddenDb.toFixed(2)} dB < 30 dB`);
  assert.ok(hiddenDb >= drawnDb + 3, `the sheets barely show: ${hiddenDb.toFixed(2)} vs ${drawnDb.toFixed(2)} dB`);
  assert.ok(differing(hidden, drawn) >= 200, 'leaving the sheets out changed fewer than 200 pixels');
});

test('from the centre nothing is left out', async () => {
  const native = readPpm(path.join(OUT, 'native_0.ppm'));
  const hidden = await frame('hidden', CENTRE);
  const drawn = await frame('drawn', CENTRE);
  assert.equal(differing(hidden, drawn), 0);
  const db = psnr(hidden, native.data, W, H);
  assert.ok(db >= 30, `centre: PSNR ${db.toFixed(2)} dB < 30 dB`);
});
