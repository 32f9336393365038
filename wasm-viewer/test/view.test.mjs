// Browser test of what a viewer sees of a package (headless Chromium,
// SwiftShader WebGL2, playwright-core), with the packages' view hints
// (manifest.json "view", spec/package.md 1.1) and without them:
//  - a package whose manifest has a "view" opens at its yaw, pitch and field
//    of view, and Reset returns there;
//  - motion (setCamera, keys, mouse parallax) is bounded by each package's
//    viewing volume: the same room with volume radius 0.05 and 0.5;
//  - a partial capture (the room with nodes only in part of the sphere), with
//    hints derived from its coarsest level and with hints from its manifest:
//    the default view and the view after dragging to each limit (left, right,
//    up, down, zoom out) show at most 1% background (pixels no surface
//    covers, measured offscreen by the renderer);
//  - where no surface is, the soft background is drawn, not black;
//  - a malformed "view" is ignored with a console warning.
// Screenshots: $CASUAL3D_BINARY_DIR/wasm-viewer/view-test/. Exits 77
// (ctest: skipped) when Chromium is not installed.

import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { after, before, test } from 'node:test';

import { BINARY_DIR, DIST_DIR, copyPackageWithView, runTool } from './node-support.mjs';
import { chromiumArgs, chromiumOrSkip, startServer, viewerPage } from './static-server.mjs';

const { chromium, executable: CHROMIUM } = await chromiumOrSkip('the view test');

const W = 640, H = 400;
const OUT = path.join(BINARY_DIR, 'wasm-viewer', 'view-test');
const MAX_BACKGROUND = 0.01;
// The partial room (viewer_test_tool room-partial): nodes at longitudes
// [-75, 45] and latitudes [-40, 50].
const PARTIAL_VIEW = {
  yaw_deg: -16, pitch_deg: 4, fov_deg: 55, content_yaw_deg: [-75, 45], content_pitch_deg: [-40, 50],
  volume_radius: 0.2, metric: true,
};
const roomView = (radius) => ({
  yaw_deg: 0, pitch_deg: 0, fov_deg: 75, content_yaw_deg: [-180, 180], content_pitch_deg: [-90, 90],
  volume_radius: radius, metric: true,
});

let tmp, server, browser, page;
const metrics = {};
const warnings = [];

async function open(name) {
  await page.goto(`${server.url}/${name}.html`);
  await page.waitForFunction(() => window.__events.some((e) => e.type === 'load' || e.type === 'error'),
    null, { timeout: 120000, polling: 100 });
  const errors = await page.evaluate(() => window.__events.filter((e) => e.type === 'error'));
  assert.deepEqual(errors, [], `${name}: unexpected errors`);
  await page.evaluate(() => document.getElementById('v').viewer.nextFrame());
}

const viewer = (fn, arg) => page.evaluate(([f, a]) => {
  const v = document.getElementById('v').viewer;
  return new Function('v', 'a', `return (${f})(v, a);`)(v, a);
}, [fn.toString(), arg]);

/**
 * Waits until the camera has stopped moving: past the 200 ms after the last
 * input before the ease back starts (viewer-core.js), then three frames still
 * (the ease moves the view once per frame).
 */
async function settle() {
  await page.waitForTimeout(300);
  let last = null, still = 0;
  for (let i = 0; i < 200; ++i) {
    const c = await viewer(async (v) => { await v.nextFrame(); return v.getCamera(); });
    still = last && ['yawDeg', 'pitchDeg', 'fovDeg'].every((k) => Math.abs(c[k] - last[k]) < 1e-6) ? still + 1 : 0;
    if (still >= 3) return c;
    last = c;
  }
  throw new Error('the view did not settle');
}

async function drag(dx, dy, times = 3) {
  const x0 = W / 2 - dx / 2, y0 = H / 2 - dy / 2;
  for (let i = 0; i < times; ++i) {
    await page.mouse.move(x0, y0);
    await page.mouse.down();
    await page.mouse.move(x0 + dx, y0 + dy, { steps: 12 });
    if (i < times - 1) await page.mouse.up();
  }
  // Still held: the view may pass the limit a little (soft limit).
  const held = await viewer((v) => ({ camera: v.getCamera(), background: v.measureBackground() }));
  await page.mouse.up();
  return held;
}

before(async () => {
  fs.rmSync(OUT, { recursive: true, force: true });
  fs.mkdirSync(OUT, { recursive: true });
  tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'casual3d-view-'));
  const partial = path.join(tmp, 'partial'), room = path.join(tmp, 'room');
  runTool('viewer_test_tool', ['package', 'room-partial', '1024', '512', partial, '256', '3']);
  runTool('viewer_test_tool', ['package', 'room', '1024', '512', room, '256', '3']);
  copyPackageWithView(partial, path.join(tmp, 'hinted'), PARTIAL_VIEW);
  copyPackageWithView(room, path.join(tmp, 'small'), roomView(0.05));
  copyPackageWithView(room, path.join(tmp, 'large'), roomView(0.5));
  copyPackageWithView(room, path.join(tmp, 'malformed'), { ...roomView(0.5), fov_deg: 500 });
  const names = ['partial', 'hinted', 'small', 'large', 'malformed'];
  const pages = { '/favicon.ico': '' };
  for (const n of names) pages[`/${n}.html`] = viewerPage(`/${n}/manifest.json`, { width: W, height: H, maxLevelWidth: 1024 });
  server = await startServer(Object.fromEntries([['/viewer/', DIST_DIR], ...names.map((n) => [`/${n}/`, path.join(tmp, n)])]),
    pages, { isolated: true });
  browser = await chromium.launch({ executablePath: CHROMIUM, args: chromiumArgs() });
  page = await browser.newPage({ viewport: { width: W, height: H }, deviceScaleFactor: 1 });
  page.on('pageerror', (e) => console.log(`page error: ${e.message}`));
  page.on('console', (m) => {
    if (m.type() === 'warning') warnings.push(m.text());
    if (m.type() === 'error') console.log(`console: ${m.text()}`);
  });
});

after(async () => {
  await browser?.close();
  await server?.close();
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
  console.log(`METRICS ${JSON.stringify(metrics)}`);
});

test('a package with a "view" member opens at its yaw, pitch and field of view; Reset returns there', async () => {
  await open('hinted');
  const state = await viewer((v) => ({ camera: v.getCamera(), hints: v.getViewHints(), maxOffset: v.maxOffset }));
  assert.equal(state.hints.source, 'package');
  assert.equal(state.hints.metric, true);
  assert.equal(state.hints.volumeRadius, 0.2);
  assert.equal(state.maxOffset, 0.2);
  assert.ok(Math.abs(state.camera.yawDeg - PARTIAL_VIEW.yaw_deg) < 1e-6, JSON.stringify(state.camera));
  assert.ok(Math.abs(state.camera.pitchDeg - PARTIAL_VIEW.pitch_deg) < 1e-6, JSON.stringify(state.camera));
  assert.ok(Math.abs(state.camera.fovDeg - PARTIAL_VIEW.fov_deg) < 1e-6, JSON.stringify(state.camera));
  assert.deepEqual(state.camera.position, [0, 0, 0]);
  await page.screenshot({ path: path.join(OUT, 'hinted_default.png') });
  await viewer((v) => v.setCamera({ yawDeg: 0, pitchDeg: -10, fovDeg: 40, position: [0.1, 0, 0] }));
  await page.locator('canvas').dblclick({ position: { x: W / 2, y: H / 2 } });  // Reset.
  await page.mouse.move(W / 2, H / 2);
  const reset = await viewer((v) => v.getCamera());
  assert.deepEqual(reset, state.camera);
});

test('motion is bounded by each package\'s viewing volume (radius 0.05 and 0.5)', async () => {
  metrics.motion = {};
  for (const [name, radius] of [['small', 0.05], ['large', 0.5]]) {
    await open(name);
    const hints = await viewer((v) => v.getViewHints());
    assert.equal(hints.volumeRadius, radius);
    // setCamera: held on the ball's surface.
    const set = await viewer((v) => { v.setCamera({ position: [3, 0, 4] }); return v.getCamera().position; });
    assert.ok(Math.abs(Math.hypot(...set) - radius) < 1e-6, `${name}: setCamera gave ${set}`);
    assert.ok(Math.abs(set[0] / set[2] - 0.75) < 1e-6, 'the direction is kept');
    // Keys: D held moves the eye right (one radius per second of frames, so
    // the same number of frames at any scale), up to the ball and no further.
    await viewer((v) => v.setCamera({ position: [0, 0, 0] }));
    await page.mouse.move(W / 2, H / 2);
    await page.locator('canvas').focus();
    await page.keyboard.down('d');
    await page.waitForFunction((r) => Math.hypot(...document.getElementById('v').viewer.getCamera().position) >= r - 1e-9,
      radius, { timeout: 20000, polling: 50 });
    await page.waitForTimeout(300);
    await page.keyboard.up('d');
    const keys = await viewer((v) => v.getCamera().position);
    assert.ok(Math.abs(Math.hypot(...keys) - radius) < 1e-6, `${name}: keys moved the eye to ${keys}`);
    // Mouse parallax: the pointer at a corner moves the eye up to the ball.
    await viewer((v) => v.setCamera({ position: [0, 0, 0] }));
    await page.mouse.move(W - 1, 0);
    const corner = await viewer(async (v) => { await v.nextFrame(); return v.eyePosition; });
    await page.mouse.move(W / 2 + W / 8, H / 2);
    const quarter = await viewer(async (v) => { await v.nextFrame(); return v.eyePosition; });
    assert.ok(Math.abs(Math.hypot(...corner) - radius) < 1e-6, `${name}: parallax eye ${corner}`);
    assert.ok(Math.abs(Math.hypot(...quarter) - radius / 4) < 0.02 * radius, `${name}: parallax eye ${quarter}`);
    metrics.motion[name] = { setCamera: Math.hypot(...set), keys: Math.hypot(...keys), parallax: Math.hypot(...corner) };
    await page.mouse.move(W / 2, H / 2);
  }
  assert.ok(Math.abs(metrics.motion.large.keys / metrics.motion.small.keys - 10) < 1e-6);
});

for (const name of ['partial', 'hinted']) {
  test(`${name} capture: the default view and the view dragged to each limit show at most 1% background`, async () => {
    await open(name);
    const hints = await viewer((v) => v.getViewHints());
    assert.equal(hints.source, name === 'partial' ? 'derived' : 'package');
    const result = { hints };
    await page.mouse.move(W / 2, H / 2);
    const start = await settle();
    result.default = await viewer((v) => v.measureBackground());
    await page.screenshot({ path: path.join(OUT, `${name}_default.png`) });
    const limits = {
      left: () => drag(560, 0), right: () => drag(-560, 0), up: () => drag(0, 360), down: () => drag(0, -360),
      zoomout: async () => {
        await page.mouse.move(W / 2, H / 2);
        for (let i = 0; i < 6; ++i) await page.mouse.wheel(0, 400);
        const held = await viewer((v) => ({ camera: v.getCamera(), background: v.measureBackground() }));
        return held;
      },
    };
    for (const [limit, go] of Object.entries(limits)) {
      await viewer((v) => v.resetView());
      await settle();
      const held = await go();
      const camera = await settle();
      const background = await viewer((v) => v.measureBackground());
      await page.screenshot({ path: path.join(OUT, `${name}_${limit}.png`) });
      result[limit] = { background, held: held.background, camera };
      // The input went past the limit (soft: the held view overshoots it) and
      // the view eased back to the limit, not to where it started.
      const past = (c) => ({ left: start.yawDeg - c.yawDeg, right: c.yawDeg - start.yawDeg,
        up: c.pitchDeg - start.pitchDeg, down: start.pitchDeg - c.pitchDeg, zoomout: c.fovDeg - start.fovDeg }[limit]);
      assert.ok(past(held.camera) > past(camera) + 0.5, `${name} ${limit}: held ${JSON.stringify(held.camera)}, settled ${JSON.stringify(camera)}`);
      assert.ok(past(camera) >= -1e-6, `${name} ${limit}: eased back past the start`);
      assert.ok(background <= MAX_BACKGROUND, `${name} ${limit}: ${(100 * background).toFixed(2)}% background`);
    }
    assert.ok(result.default <= MAX_BACKGROUND, `${name} default view: ${(100 * result.default).toFixed(2)}% background`);
    metrics[name] = result;
    await page.mouse.move(W / 2, H / 2);
  });
}

test('where no surface is, the soft background is drawn instead of black', async () => {
  await open('partial');
  const counts = await viewer(async (v) => {
    v.options.keepInContent = false;
    v.setCamera({ yawDeg: 70, pitchDeg: 0, fovDeg: 75 });
    await v.nextFrame();
    const gl = v.renderer.gl;
    const px = new Uint8Array(gl.drawingBufferWidth * gl.drawingBufferHeight * 4);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.readPixels(0, 0, gl.drawingBufferWidth, gl.drawingBufferHeight, gl.RGBA, gl.UNSIGNED_BYTE, px);
    let black = 0;
    for (let i = 0; i < px.length; i += 4) if (px[i] + px[i + 1] + px[i + 2] < 12) ++black;
    return { background: v.measureBackground(), black: black / (px.length / 4) };
  });
  await page.screenshot({ path: path.join(OUT, 'soft_background.png') });
  metrics.softBackground = counts;
  assert.ok(counts.background > 0.3, `the view looks past the content's edge (${counts.background})`);
  assert.ok(counts.black < 0.01, `${(100 * counts.black).toFixed(2)}% black pixels`);
});

test('a malformed "view" member is refused with a message naming the field, or ignored with a warning', async () => {
  // The format reader (spec/package.md 1.1) refuses an out-of-range member;
  // a reader that lets one through leaves it to the viewer, which ignores it
  // and derives the hints (view-hints.js parseViewHints, tested in Node).
  warnings.length = 0;
  await page.goto(`${server.url}/malformed.html`);
  await page.waitForFunction(() => window.__events.some((e) => e.type === 'load' || e.type === 'error'),
    null, { timeout: 120000, polling: 100 });
  const state = await viewer((v) => ({
    hints: v.getViewHints(), errors: window.__events.filter((e) => e.type === 'error').map((e) => e.detail),
    shown: document.getElementById('v').errorMessage,
  }));
  if (state.errors.length > 0) {
    assert.match(state.errors[0].message, /view\.fov_deg/);
    assert.match(state.shown, /view\.fov_deg/);
    metrics.malformed = 'refused by the reader';
  } else {
    assert.equal(state.hints.source, 'derived');
    assert.ok(warnings.some((w) => /"view" ignored: fov_deg 500 is outside \[10, 120\]/.test(w)), JSON.stringify(warnings));
    metrics.malformed = 'ignored by the viewer';
  }
});
