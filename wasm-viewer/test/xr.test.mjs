// Browser test of the viewer's immersive VR path in Debian's headless Chromium
// (SwiftShader WebGL2), which offers no XR device: a scripted one
// (webxr-mock.mjs) is installed in the page before the viewer loads. The test
// enters VR with the element's VR button, lets the viewer draw XR frames into
// the layer's side-by-side framebuffer, reads both eyes back and checks:
//  - each eye matches the native software renderer's image from that eye's
//    position, orientation and field of view (PSNR >= 30 dB): the viewer uses
//    each view's projection matrix and eye transform;
//  - stereo: the near sphere shifts between the eyes by the disparity a 64 mm
//    baseline gives at its depth, the far wall by much less;
//  - head translation from the pose moves both eyes (motion parallax), and a
//    head outside the 3D photo's 0.3 m ball is brought back to its surface;
//  - ending the session (viewer API or device) returns to canvas rendering.
// Eye images: $CASUAL3D_BINARY_DIR/wasm-viewer/xr-test/*.png.
// Exits 77 (ctest: skipped) when Chromium is not installed.

import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { after, before, test } from 'node:test';
import zlib from 'node:zlib';

import { readCanvas as readViewerCanvas } from './native-comparison.mjs';
import { directionFromYawPitch, lookAlong, multiply, perspective } from '../js/camera.js';
import { BINARY_DIR, DIST_DIR, copyPackageWithView, runTool } from './node-support.mjs';
import { chromiumArgs, chromiumOrSkip, startServer, viewerPage } from './static-server.mjs';
import { installWebXRMock } from './webxr-mock.mjs';

const { chromium, executable: CHROMIUM } = await chromiumOrSkip('the XR browser test');

const DEG = Math.PI / 180;
const W = 640, H = 400;                      // The page's canvas.
const EYE = 400;                             // Each eye's viewport: EYE x EYE pixels.
const XR = { eyeWidth: EYE, eyeHeight: EYE, fovYDeg: 90, ipdM: 0.064 };
const VIEWER_YAW = 10;                       // The viewer's yaw when VR starts (deg).
const HEAD_PITCH = -10;                      // The head looks slightly down (deg).
const MAX_OFFSET = 0.3;                      // The package's viewing volume (m): its manifest's "view".
// The room package (format/testing/test_panoramas.h): the sphere's centre and
// radius, and a point of the back wall (z = -4 m) that no object hides.
const SPHERE_CENTRE = [0.4, -0.3, -1.6];
const SPHERE_RADIUS = 0.6;
const FAR_POINT = [-0.9, 0.6, -4.0];
const OUT = path.join(BINARY_DIR, 'wasm-viewer', 'xr-test');

let tmp, server, browser, page;
let canvasBeforeVR;  // The page's canvas just before entering VR.
let centreLeftColumn;  // The sphere's mean column in the left eye, head at the centre.
const metrics = {};

// --- images -----------------------------------------------------------------

const CRC_TABLE = new Uint32Array(256).map((_, n) => {
  let c = n;
  for (let k = 0; k < 8; ++k) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
  return c >>> 0;
});
function crc32(bytes) {
  let c = 0xffffffff;
  for (const b of bytes) c = CRC_TABLE[(c ^ b) & 0xff] ^ (c >>> 8);
  return (c ^ 0xffffffff) >>> 0;
}

/** Writes an RGB image (top row first) as a PNG. */
function writePng(file, { width, height, data }) {
  const raw = Buffer.alloc((width * 3 + 1) * height);
  for (let y = 0; y < height; ++y) {
    raw[y * (width * 3 + 1)] = 0;  // Filter: none.
    Buffer.from(data.buffer, data.byteOffset + y * width * 3, width * 3).copy(raw, y * (width * 3 + 1) + 1);
  }
  const chunk = (type, body) => {
    const out = Buffer.alloc(12 + body.length);
    out.writeUInt32BE(body.length, 0);
    out.write(type, 4, 'latin1');
    body.copy(out, 8);
    out.writeUInt32BE(crc32(out.subarray(4, 8 + body.length)), 8 + body.length);
    return out;
  };
  const header = Buffer.alloc(13);
  header.writeUInt32BE(width, 0);
  header.writeUInt32BE(height, 4);
  header[8] = 8;  // Bit depth.
  header[9] = 2;  // Colour type: RGB.
  fs.writeFileSync(file, Buffer.concat([
    Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]),
    chunk('IHDR', header), chunk('IDAT', zlib.deflateSync(raw)), chunk('IEND', Buffer.alloc(0)),
  ]));
}

/** One eye's half of the layer's RGBA pixels (bottom row first) as RGB, top row first. */
function eyeImage(layerRgba, eye) {
  const data = new Uint8Array(EYE * EYE * 3);
  const x0 = eye === 'left' ? 0 : EYE;
  for (let y = 0; y < EYE; ++y) {
    const src = (EYE - 1 - y) * 2 * EYE;
    for (let x = 0; x < EYE; ++x) {
      for (let c = 0; c < 3; ++c) data[(y * EYE + x) * 3 + c] = layerRgba[(src + x0 + x) * 4 + c];
    }
  }
  return { width: EYE, height: EYE, data };
}

function readPpm(file) {
  const buf = fs.readFileSync(file);
  const header = buf.subarray(0, 64).toString('latin1').match(/^P6\s+(\d+)\s+(\d+)\s+255\s/);
  assert.ok(header, `${file}: not a binary PPM`);
  return { width: Number(header[1]), height: Number(header[2]), data: buf.subarray(header[0].length) };
}

function psnr(a, b) {
  assert.equal(a.data.length, b.data.length);
  let se = 0;
  for (let i = 0; i < a.data.length; ++i) se += (a.data[i] - b.data[i]) ** 2;
  const mse = se / a.data.length;
  return mse === 0 ? Infinity : 10 * Math.log10((255 * 255) / mse);
}

/** Mean column of the sphere's pixels (red, G < 60; the walls have G >= 75). */
function sphereColumn(img) {
  let sum = 0, n = 0;
  for (let i = 0, p = 0; i < img.data.length; i += 3, ++p) {
    if (img.data[i + 1] < 60 && img.data[i] > 120) {
      sum += p % img.width;
      ++n;
    }
  }
  assert.ok(n > 500, `the sphere covers ${n} pixels`);
  return sum / n;
}

/**
 * Horizontal shift (pixels, sub-pixel) that best maps a (2r+1)^2 patch of `a`
 * centred at (cx, cy) onto `b`: b(x - d, y) ~ a(x, y), found by SAD over
 * integer shifts in [-maxShift, maxShift] refined by a parabola.
 */
function patchShift(a, b, cx, cy, r = 24, maxShift = 24) {
  const cost = (d) => {
    let s = 0;
    for (let y = cy - r; y <= cy + r; ++y) {
      for (let x = cx - r; x <= cx + r; ++x) {
        for (let c = 0; c < 3; ++c) s += Math.abs(a.data[(y * a.width + x) * 3 + c] - b.data[(y * b.width + x - d) * 3 + c]);
      }
    }
    return s;
  };
  const costs = [];
  for (let d = -maxShift; d <= maxShift; ++d) costs.push(cost(d));
  let k = 0;
  for (let i = 1; i < costs.length; ++i) if (costs[i] < costs[k]) k = i;
  let frac = 0;
  if (k > 0 && k < costs.length - 1) {
    const [l, m, r2] = [costs[k - 1], costs[k], costs[k + 1]];
    const den = l - 2 * m + r2;
    if (den > 0) frac = (0.5 * (l - r2)) / den;
  }
  return k - maxShift + frac;
}

// --- geometry of the scripted headset, in the panorama frame ----------------

const RIGHT = [Math.cos(VIEWER_YAW * DEG), 0, Math.sin(VIEWER_YAW * DEG)];  // Head x axis (no roll).

/** Unit quaternion of a head turned down by `pitchDeg` about its x axis. */
function pitchQuaternion(pitchDeg) {
  const h = (pitchDeg * DEG) / 2;
  return { x: Math.sin(h), y: 0, z: 0, w: Math.cos(h) };
}

/** Eye centres in the panorama frame for a head at `head` (metres along RIGHT, after the ball). */
function eyePositions(headAlongRight) {
  return {
    left: RIGHT.map((v) => v * (headAlongRight - XR.ipdM / 2)),
    right: RIGHT.map((v) => v * (headAlongRight + XR.ipdM / 2)),
  };
}

/** Pixel column of a panorama point in an eye's image (the mock's projection). */
function projectColumn(point, eye) {
  const view = lookAlong(eye, directionFromYawPitch(VIEWER_YAW * DEG, HEAD_PITCH * DEG));
  const m = multiply(perspective(XR.fovYDeg, 1, 0.05, 2000), view);
  const clip = [0, 1, 2, 3].map((r) => m[r] * point[0] + m[4 + r] * point[1] + m[8 + r] * point[2] + m[12 + r]);
  return { x: (clip[0] / clip[3] * 0.5 + 0.5) * EYE, y: (0.5 - clip[1] / clip[3] * 0.5) * EYE };
}

// Head positions along RIGHT (m) the test renders references for: the centre,
// 0.1 m to the right, and 0.6 m held on the 0.3 m ball.
const REFERENCE_HEADS = { centre: 0, moved: 0.1, clamped: MAX_OFFSET };
const references = {};

/** Native reference renders of both eyes for every head of REFERENCE_HEADS (one tool run). */
function renderReferences() {
  const names = Object.keys(REFERENCE_HEADS);
  const specs = [];
  for (const name of names) {
    const eyes = eyePositions(REFERENCE_HEADS[name]);
    for (const e of ['left', 'right']) specs.push([VIEWER_YAW, HEAD_PITCH, XR.fovYDeg, ...eyes[e]].join(','));
  }
  runTool('viewer_test_tool', ['render', path.join(tmp, 'room'), '0', String(EYE), String(EYE), path.join(OUT, 'reference'), ...specs]);
  names.forEach((name, k) => {
    const pair = {};
    ['left', 'right'].forEach((e, j) => {
      pair[e] = readPpm(path.join(OUT, `reference_${2 * k + j}.ppm`));
      writePng(path.join(OUT, `${name}_reference_${e}.png`), pair[e]);
    });
    references[name] = pair;
  });
}

// --- page helpers -------------------------------------------------------------

/** Sets the scripted head pose, waits for `frames` XR frames and returns both eyes. */
async function captureEyes(name, headPosition, frames = 3) {
  const b64 = await page.evaluate(async ({ p, q, n }) => {
    const device = window.__xrDevice;
    device.setHeadPose(p, q);
    device.capture = true;
    await device.waitFrames(n);
    device.capture = false;
    const px = device.pixels;
    let s = '';
    for (let i = 0; i < px.length; i += 0x8000) s += String.fromCharCode.apply(null, px.subarray(i, i + 0x8000));
    return btoa(s);
  }, { p: headPosition, q: pitchQuaternion(HEAD_PITCH), n: frames });
  const layer = new Uint8Array(Buffer.from(b64, 'base64'));
  const eyes = { left: eyeImage(layer, 'left'), right: eyeImage(layer, 'right') };
  writePng(path.join(OUT, `${name}_left.png`), eyes.left);
  writePng(path.join(OUT, `${name}_right.png`), eyes.right);
  return eyes;
}

/** The page canvas' RGB pixels (top row first) after the next frame. */
async function readCanvas() {
  const rgba = await readViewerCanvas(page);
  const data = new Uint8Array(W * H * 3);
  for (let y = 0; y < H; ++y) {
    for (let x = 0; x < W; ++x) for (let c = 0; c < 3; ++c) data[(y * W + x) * 3 + c] = rgba[((H - 1 - y) * W + x) * 4 + c];
  }
  return { width: W, height: H, data };
}

const vrButton = () => page.locator('casual3d-viewer [data-action="vr"]');

async function enterWithButton() {
  await vrButton().click();
  await page.waitForFunction(() => {
    const v = document.getElementById('v').viewer;
    return v.inVR && window.__xrDevice.frames >= 2;
  }, null, { timeout: 60000, polling: 50 });
}

before(async () => {
  fs.rmSync(OUT, { recursive: true, force: true });
  fs.mkdirSync(OUT, { recursive: true });
  tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'casual3d-xr-'));
  // The room with view hints (spec/package.md 1.1): the whole sphere and a
  // viewing volume of MAX_OFFSET metres, which holds the head.
  runTool('viewer_test_tool', ['package', 'room', '1024', '512', path.join(tmp, 'room-1.0'), '256', '3']);
  copyPackageWithView(path.join(tmp, 'room-1.0'), path.join(tmp, 'room'), {
    yaw_deg: 0, pitch_deg: 0, fov_deg: 75, content_yaw_deg: [-180, 180], content_pitch_deg: [-90, 90],
    volume_radius: MAX_OFFSET, metric: true,
  });
  renderReferences();
  server = await startServer({ '/viewer/': DIST_DIR, '/pkg/': path.join(tmp, 'room') }, {
    '/xr.html': viewerPage('/pkg/manifest.json', { width: W, height: H, maxLevelWidth: 1024, attributes: 'controls' }),
    '/favicon.ico': '',
  });
  browser = await chromium.launch({ executablePath: CHROMIUM, args: chromiumArgs() });
  page = await browser.newPage({ viewport: { width: W, height: H }, deviceScaleFactor: 1 });
  page.on('pageerror', (e) => console.log(`page error: ${e.message}`));
  page.on('console', (m) => { if (m.type() === 'error') console.log(`console: ${m.text()}`); });
  await page.addInitScript(installWebXRMock, XR);
  await page.goto(`${server.url}/xr.html`);
  await page.waitForFunction(() => window.__events.some((e) => e.type === 'load'), null, { timeout: 120000, polling: 100 });
  await page.evaluate((yaw) => {
    const v = document.getElementById('v').viewer;
    v.setEffectsTime(0);
    v.setCamera({ yawDeg: yaw, pitchDeg: 0, fovDeg: 75, position: [0, 0, 0] });
  }, VIEWER_YAW);
});

after(async () => {
  await browser?.close();
  await server?.close();
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
  console.log(`METRICS ${JSON.stringify(metrics)}`);
});

test('the VR button is offered; a refused session leaves the viewer out of VR', async () => {
  await page.waitForFunction(() => {
    const b = document.getElementById('v').shadowRoot.querySelector('[data-action="vr"]');
    return b && !b.hidden;
  }, null, { timeout: 10000 });
  const refused = await page.evaluate(async () => {
    window.__xrDevice.refuseNext = true;  // The user declines the browser's VR prompt.
    return document.getElementById('v').viewer.enterVR().then(() => 'entered', (e) => e.name);
  });
  assert.equal(refused, 'NotAllowedError');
  assert.equal(await page.evaluate(() => document.getElementById('v').viewer.inVR), false);
  assert.equal(await page.evaluate(() => window.__xrDevice.sessionsStarted), 0);
});

test('stereo: both eyes drawn with their own transform and projection, 64 mm parallax', async () => {
  canvasBeforeVR = await readCanvas();
  writePng(path.join(OUT, 'canvas_before_vr.png'), canvasBeforeVR);
  await enterWithButton();
  const eyes = await captureEyes('centre', { x: 0, y: 0, z: 0 });
  const ref = references.centre;
  metrics.psnrCentreDb = { left: +psnr(eyes.left, ref.left).toFixed(2), right: +psnr(eyes.right, ref.right).toFixed(2) };
  assert.ok(metrics.psnrCentreDb.left >= 30, `left eye PSNR ${metrics.psnrCentreDb.left} dB`);
  assert.ok(metrics.psnrCentreDb.right >= 30, `right eye PSNR ${metrics.psnrCentreDb.right} dB`);

  // Disparity (left column minus right column) of the near sphere and the far wall.
  const e = eyePositions(0);
  const predict = (p) => projectColumn(p, e.left).x - projectColumn(p, e.right).x;
  const near = SPHERE_CENTRE.map((v) => v * (1 - SPHERE_RADIUS / Math.hypot(...SPHERE_CENTRE)));
  metrics.sphereShiftPx = +(sphereColumn(eyes.left) - sphereColumn(eyes.right)).toFixed(2);
  metrics.spherePredictedPx = +predict(SPHERE_CENTRE).toFixed(2);
  metrics.sphereFrontPredictedPx = +predict(near).toFixed(2);
  const far = projectColumn(FAR_POINT, e.left);
  metrics.farWallShiftPx = +patchShift(eyes.left, eyes.right, Math.round(far.x), Math.round(far.y)).toFixed(2);
  metrics.farWallPredictedPx = +predict(FAR_POINT).toFixed(2);
  // The sphere's silhouette lies between its centre's and its front's depths.
  const [lo, hi] = [metrics.spherePredictedPx, metrics.sphereFrontPredictedPx].sort((a, b) => a - b);
  assert.ok(metrics.sphereShiftPx > lo - 1 && metrics.sphereShiftPx < hi + 1,
    `sphere shift ${metrics.sphereShiftPx} px, expected ${lo}..${hi} px`);
  assert.ok(Math.abs(metrics.farWallShiftPx - metrics.farWallPredictedPx) < 1,
    `far wall shift ${metrics.farWallShiftPx} px, expected ${metrics.farWallPredictedPx} px`);
  assert.ok(metrics.sphereShiftPx > metrics.farWallShiftPx + 3, 'near content shifts more than far content');
  centreLeftColumn = sphereColumn(eyes.left);
});

test('head translation moves both eyes (motion parallax), inside the 0.3 m ball', async () => {
  // 0.1 m to the right of the head's start (local x = the panorama's RIGHT).
  const moved = await captureEyes('moved', { x: 0.1, y: 0, z: 0 });
  const ref = references.moved;
  metrics.psnrMovedDb = { left: +psnr(moved.left, ref.left).toFixed(2), right: +psnr(moved.right, ref.right).toFixed(2) };
  assert.ok(metrics.psnrMovedDb.left >= 30 && metrics.psnrMovedDb.right >= 30, JSON.stringify(metrics.psnrMovedDb));
  // Moving right, the near sphere moves left in the image.
  metrics.sphereMotionParallaxPx = +(sphereColumn(moved.left) - centreLeftColumn).toFixed(2);
  assert.ok(metrics.sphereMotionParallaxPx < -5, `the sphere moved ${metrics.sphereMotionParallaxPx} px`);

  // 0.6 m away: the head is held on the ball's surface (0.3 m), eyes 64 mm apart.
  const outside = await captureEyes('outside_ball', { x: 0.6, y: 0, z: 0 });
  const clamped = references.clamped;
  metrics.psnrClampedDb = { left: +psnr(outside.left, clamped.left).toFixed(2), right: +psnr(outside.right, clamped.right).toFixed(2) };
  assert.ok(metrics.psnrClampedDb.left >= 30 && metrics.psnrClampedDb.right >= 30, JSON.stringify(metrics.psnrClampedDb));
});

test('ending the session returns to the canvas', async () => {
  const framesBefore = await page.evaluate(() => window.__xrDevice.frames);
  await page.evaluate(() => document.getElementById('v').viewer.exitVR());
  assert.equal(await page.evaluate(() => document.getElementById('v').viewer.inVR), false);
  const after1 = await readCanvas();
  writePng(path.join(OUT, 'canvas_after_exit.png'), after1);
  metrics.canvasAfterExitIdentical = psnr(after1, canvasBeforeVR) === Infinity;
  assert.ok(metrics.canvasAfterExitIdentical, 'the canvas shows the pre-VR view again');
  metrics.xrFrames = framesBefore;

  // Again, ended by the device this time (the headset taken off).
  await enterWithButton();
  await page.evaluate(() => window.__xrDevice.endSession());
  await page.waitForFunction(() => !document.getElementById('v').viewer.inVR, null, { timeout: 10000 });
  const after2 = await readCanvas();
  assert.equal(psnr(after2, canvasBeforeVR), Infinity);
  // The page still answers input after VR.
  await page.evaluate(() => document.getElementById('v').viewer.setCamera({ yawDeg: 40 }));
  const turned = await readCanvas();
  assert.ok(psnr(turned, canvasBeforeVR) < 25, 'turning the view changes the canvas');
});
