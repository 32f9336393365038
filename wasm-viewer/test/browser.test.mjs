// Browser test of the viewer in Debian's headless Chromium (SwiftShader WebGL2),
// driven by playwright-core:
//  - a page with <casual3d-viewer> loads a package served on 127.0.0.1 and
//    reports its first frame (time and bytes fetched before it are printed);
//  - it renders from three camera positions (centre and two parallax offsets);
//    each frame matches the native software renderer's image of the same mesh
//    (reconstruct/render/, via viewer_test_tool) with PSNR >= 30 dB;
//  - effects are geometry-aware: an object behind the near sphere is hidden, one
//    in front of it shows; water covers the floor but not the sphere's top;
//  - a package with a corrupted tile shows the error message, keeps the coarser
//    level on screen and the page stays responsive;
//  - a delivery package (lossy normals, version 1.2) decodes in Chromium to
//    the same normals as under Node (a wasm libwebp) and natively;
//  - the same package as one .c3d file, by URL: read in HTTP range requests,
//    the first frame before any range of the finest level was asked for, the
//    same images; and from a server that ignores ranges (one whole download).
// Screenshots go to $CASUAL3D_BINARY_DIR/wasm-viewer/browser-test/.
// Exits 77 (ctest: skipped) when Chromium is not installed.

import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { after, before, test } from 'node:test';

import { psnr, readCanvas, readPpm } from './native-comparison.mjs';
import { BINARY_DIR, DIST_DIR, copyPackageWithView, loadFormatModule, runTool } from './node-support.mjs';
import { readPackageLevel } from './node-package.mjs';
import { chromiumArgs, chromiumOrSkip, startServer, viewerPage } from './static-server.mjs';

const { chromium, executable: CHROMIUM } = await chromiumOrSkip('the browser test');

const W = 640, H = 400;
const OUT = path.join(BINARY_DIR, 'wasm-viewer', 'browser-test');
const CAMERAS = [
  { yawDeg: 10, pitchDeg: -10, fovDeg: 75, position: [0, 0, 0] },
  { yawDeg: 20, pitchDeg: -5, fovDeg: 60, position: [0.2, 0.05, 0] },
  { yawDeg: -30, pitchDeg: 15, fovDeg: 90, position: [-0.1, -0.1, 0.15] },
];

let tmp, server, browser, page, metrics = {};

/** The canvas' pixels (RGBA, bottom row first) after the next frame. */
const readFrame = () => readCanvas(page);

function waitForEvent(type, timeoutMs = 120000) {
  return page.waitForFunction((t) => window.__events.some((e) => e.type === t), type, { timeout: timeoutMs, polling: 100 });
}

before(async () => {
  fs.mkdirSync(OUT, { recursive: true });
  tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'casual3d-browser-'));
  const good = path.join(tmp, 'room');
  // The room with view hints (spec/package.md 1.1): the whole sphere, a 0.3 m
  // viewing volume, so that the cameras below stay where they are put.
  const plain = path.join(tmp, 'room-1.0');
  metrics.package = JSON.parse(runTool('viewer_test_tool', ['package', 'room', '1024', '512', plain, '256', '3']));
  copyPackageWithView(plain, good, {
    yaw_deg: 0, pitch_deg: 0, fov_deg: 75, content_yaw_deg: [-180, 180], content_pitch_deg: [-90, 90],
    volume_radius: 0.3, metric: true,
  });
  metrics.package.total_bytes += fs.statSync(path.join(good, 'manifest.json')).size - metrics.package.manifest_bytes;
  // A copy whose finest level has one damaged colour tile (bytes flipped mid-file).
  const bad = path.join(tmp, 'bad');
  fs.cpSync(good, bad, { recursive: true });
  const manifest = JSON.parse(fs.readFileSync(path.join(bad, 'manifest.json'), 'utf8'));
  const damaged = manifest.levels[0].tiles[1].color;
  const bytes = fs.readFileSync(path.join(bad, damaged));
  for (let i = 40; i < 80; ++i) bytes[i] ^= 0x5a;
  fs.writeFileSync(path.join(bad, damaged), bytes);
  metrics.damagedFile = damaged;

  // The same package as one file.
  const single = path.join(tmp, 'single');
  fs.mkdirSync(single);
  runTool('viewer_test_tool', ['single-file', good, path.join(single, 'room.c3d')]);

  server = await startServer({ '/viewer/': DIST_DIR, '/pkg/': good, '/bad/': bad, '/single/': single }, {
    '/room.html': viewerPage('/single/room.c3d', { width: W, height: H, maxLevelWidth: 1024 }),
    '/index.html': viewerPage('/pkg/manifest.json', { width: W, height: H, maxLevelWidth: 1024 }),
    '/bad.html': viewerPage('/bad/manifest.json', { width: W, height: H, maxLevelWidth: 1024 }),
    '/missing.html': viewerPage('/nothing-here/manifest.json', { width: W, height: H }),
    '/favicon.ico': '',
  }, { isolated: true });  // As `casual3d view` serves: the viewer may use its threaded build.
  browser = await chromium.launch({ executablePath: CHROMIUM, args: chromiumArgs() });
  page = await browser.newPage({ viewport: { width: W, height: H }, deviceScaleFactor: 1 });
  page.on('pageerror', (e) => console.log(`page error: ${e.message}`));
  page.on('console', (m) => { if (m.type() === 'error') console.log(`console: ${m.text()}`); });
});

after(async () => {
  await browser?.close();
  await server?.close();
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
  console.log(`METRICS ${JSON.stringify(metrics)}`);
});

test('loads a package and reports the first frame', async () => {
  const start = server.log.length;
  await page.goto(`${server.url}/index.html`);
  await waitForEvent('firstframe');
  await waitForEvent('load');
  const events = await page.evaluate(() => window.__events);
  const errors = events.filter((e) => e.type === 'error');
  assert.equal(errors.length, 0, `unexpected errors: ${JSON.stringify(errors)}`);
  const first = events.find((e) => e.type === 'firstframe');
  const levels = events.filter((e) => e.type === 'level').map((e) => e.detail.level);
  assert.deepEqual(levels, [2, 1, 0], 'levels arrive coarsest first');
  const progress = events.filter((e) => e.type === 'progress').map((e) => e.detail);
  assert.ok(progress.length >= 3, 'progress is reported');
  for (let i = 1; i < progress.length; ++i) assert.ok(progress[i].loadedBytes >= progress[i - 1].loadedBytes);
  const last = progress[progress.length - 1];
  assert.equal(last.loadedBytes, last.totalBytes, 'progress ends at 100 %');
  assert.equal(last.totalBytes, metrics.package.total_bytes, 'every file of the package was fetched once');
  const firstT = first.t;
  // Bytes the server sent before the first frame: package files and viewer code.
  const served = server.log.slice(start);
  const t0 = served[0].t;
  const beforeFirst = served.filter((r) => r.t - t0 <= firstT);
  metrics.timeToFirstFrameMs = Math.round(first.detail.timeToFirstFrameMs);
  metrics.packageBytesBeforeFirstFrame = first.detail.bytesBeforeFirstFrame;
  metrics.allBytesBeforeFirstFrame = beforeFirst.reduce((s, r) => s + r.bytes, 0);
  metrics.loadMs = Math.round(events.find((e) => e.type === 'load').t);
  assert.ok(first.detail.bytesBeforeFirstFrame > 0 && first.detail.bytesBeforeFirstFrame <= 300 * 1024,
    `package bytes before the first frame: ${first.detail.bytesBeforeFirstFrame}`);
  await page.screenshot({ path: path.join(OUT, 'loaded.png') });
});

test('the worker decodes with threads on a cross-origin isolated page, on one thread elsewhere', async () => {
  const isolated = await page.evaluate(() => ({
    isolated: window.crossOriginIsolated, cores: navigator.hardwareConcurrency,
    threads: document.getElementById('v').viewer.stats.workerMs.map((t) => t.threads),
  }));
  assert.equal(isolated.isolated, true);
  for (const t of isolated.threads) assert.equal(t, Math.max(1, Math.min(4, isolated.cores)));
  metrics.workerThreads = isolated.threads[0];
  // The same page from a server without the isolation headers.
  const plain = await startServer({ '/viewer/': DIST_DIR, '/pkg/': path.join(tmp, 'room') }, {
    '/index.html': viewerPage('/pkg/manifest.json', { width: W, height: H, maxLevelWidth: 256 }),
    '/favicon.ico': '',
  });
  const other = await browser.newPage({ viewport: { width: W, height: H }, deviceScaleFactor: 1 });
  try {
    await other.goto(`${plain.url}/index.html`);
    await other.waitForFunction(() => (window.__events ?? []).some((e) => e.type === 'load' || e.type === 'error'),
      null, { timeout: 120000 });
    const result = await other.evaluate(() => ({
      isolated: window.crossOriginIsolated,
      errors: window.__events.filter((e) => e.type === 'error'),
      threads: document.getElementById('v').viewer.stats.workerMs.map((t) => t.threads),
    }));
    assert.equal(result.isolated, false);
    assert.deepEqual(result.errors, []);
    assert.ok(result.threads.length > 0 && result.threads.every((t) => t === 1), JSON.stringify(result.threads));
  } finally {
    await other.close();
    await plain.close();
  }
});

test('renders like the native renderer from three cameras (PSNR >= 30 dB)', async () => {
  const specs = CAMERAS.map((c) => [c.yawDeg, c.pitchDeg, c.fovDeg, ...c.position].join(','));
  runTool('viewer_test_tool', ['render', path.join(tmp, 'room'), '0', String(W), String(H), path.join(OUT, 'reference'), ...specs]);
  metrics.psnrDb = [];
  for (let i = 0; i < CAMERAS.length; ++i) {
    await page.evaluate((c) => document.getElementById('v').setCamera(c), CAMERAS[i]);
    const frame = await readFrame();
    await page.screenshot({ path: path.join(OUT, `viewer_${i}.png`) });
    const ref = readPpm(path.join(OUT, `reference_${i}.ppm`));
    assert.equal(ref.width, W);
    const db = psnr(frame, ref.data, W, H);
    metrics.psnrDb.push(Number(db.toFixed(2)));
    assert.ok(db >= 30, `camera ${i}: PSNR ${db.toFixed(2)} dB < 30 dB`);
  }
  // The three views differ (the cameras really moved).
  assert.ok(new Set(metrics.psnrDb).size === CAMERAS.length);
});

test('effects: inserted object and water are occluded by nearer geometry', async () => {
  const setup = async (effects) => {
    await page.evaluate((e) => {
      const v = document.getElementById('v').viewer;
      v.setEffectsTime(0);
      v.setEffects(e);
      v.setCamera({ yawDeg: 14, pitchDeg: -10, fovDeg: 60, position: [0, 0, 0] });
    }, effects);
    return readFrame();
  };
  const none = { lighting: false, water: false, object: false };
  const plain = await setup(none);
  // The room's sphere: centre (0.4, -0.3, -1.6), radius 0.6. A cube right behind
  // it (from the centre) must be invisible; the same cube in front must show.
  const behind = await setup({ ...none, object: true, objectPosition: [0.4, -0.3, -2.6], objectSize: 0.3 });
  const front = await setup({ ...none, object: true, objectPosition: [0.22, -0.165, -0.88], objectSize: 0.15 });
  await page.screenshot({ path: path.join(OUT, 'effect_object.png') });
  const changed = (a, b) => { let n = 0; for (let i = 0; i < a.length; i += 4) if (Math.abs(a[i] - b[i]) + Math.abs(a[i + 1] - b[i + 1]) + Math.abs(a[i + 2] - b[i + 2]) > 6) ++n; return n; };
  metrics.objectBehindChangedPixels = changed(plain, behind);
  metrics.objectFrontChangedPixels = changed(plain, front);
  assert.equal(metrics.objectBehindChangedPixels, 0, 'a cube behind the sphere is hidden');
  assert.ok(metrics.objectFrontChangedPixels > 500, 'a cube in front of the sphere is visible');
  // Water at y = -1.2 m: the floor (y = -1.5) is under water, the sphere (y >= -0.9) is not.
  const water = await setup({ ...none, water: true, waterMinY: -1.2, waterMaxY: -1.2 });
  await page.screenshot({ path: path.join(OUT, 'effect_water.png') });
  const project = await page.evaluate(() => {
    const v = document.getElementById('v').viewer;
    const cam = v.camera;
    const aspect = v.canvas.width / v.canvas.height;
    const view = cam.viewMatrix(), proj = cam.projectionMatrix(aspect);
    const toPixel = (p) => {
      const mv = [0, 1, 2, 3].map((r) => view[r] * p[0] + view[4 + r] * p[1] + view[8 + r] * p[2] + view[12 + r]);
      const c = [0, 1, 2, 3].map((r) => proj[r] * mv[0] + proj[4 + r] * mv[1] + proj[8 + r] * mv[2] + proj[12 + r] * mv[3]);
      return [Math.round((c[0] / c[3] * 0.5 + 0.5) * v.canvas.width), Math.round((c[1] / c[3] * 0.5 + 0.5) * v.canvas.height)];
    };
    return { sphereTop: toPixel([0.4, 0.2, -1.6]), floor: toPixel([0.6, -1.5, -2.4]) };
  });
  const at = (img, [x, y]) => { const i = (y * W + x) * 4; return [img[i], img[i + 1], img[i + 2]]; };
  const diff = (a, b) => Math.abs(a[0] - b[0]) + Math.abs(a[1] - b[1]) + Math.abs(a[2] - b[2]);
  metrics.waterSphereTopDiff = diff(at(plain, project.sphereTop), at(water, project.sphereTop));
  metrics.waterFloorDiff = diff(at(plain, project.floor), at(water, project.floor));
  assert.ok(metrics.waterSphereTopDiff <= 6, 'the sphere above the water is untouched');
  assert.ok(metrics.waterFloorDiff > 30, 'the floor below the water is covered');
  const lit = await setup({ ...none, lighting: true, object: true, water: true, waterMinY: -1.4, waterMaxY: -1.4 });
  await page.screenshot({ path: path.join(OUT, 'effect_all.png') });
  assert.ok(changed(plain, lit) > W * H * 0.2, 'lighting changes the image');
  await setup(none);
});

/** {path, offset, size} of each entry of a .c3d file (spec/package.md Sec. 8). */
function singleFileEntries(file) {
  const b = fs.readFileSync(file);
  const entries = [];
  for (let i = 0, at = 16; i < b.readUInt32LE(12); ++i) {
    const len = b.readUInt16LE(at);
    entries.push({ path: b.toString('utf8', at + 2, at + 2 + len), offset: Number(b.readBigUInt64LE(at + 2 + len)),
      size: Number(b.readBigUInt64LE(at + 10 + len)) });
    at += 18 + len;
  }
  return entries;
}

/** Opens `url` in a new page; resolves to {page, events, firstEpochMs} once the package has loaded. */
async function loadInNewPage(url) {
  const p = await browser.newPage({ viewport: { width: W, height: H }, deviceScaleFactor: 1 });
  p.on('pageerror', (e) => console.log(`page error: ${e.message}`));
  await p.goto(url);
  await p.waitForFunction(() => (window.__events ?? []).some((e) => e.type === 'load' || e.type === 'error'),
    null, { timeout: 120000, polling: 100 });
  const { events, origin } = await p.evaluate(() => ({ events: window.__events, origin: performance.timeOrigin + window.__t0 }));
  const first = events.find((e) => e.type === 'firstframe');
  return { page: p, events, firstEpochMs: first ? origin + first.t : NaN };
}

/** PSNR of the viewer in `p` from camera 0 against the native reference image. */
async function psnrOfCamera0(p) {
  const reference = path.join(OUT, 'reference_single_0.ppm');
  if (!fs.existsSync(reference)) {
    const c = CAMERAS[0];
    runTool('viewer_test_tool', ['render', path.join(tmp, 'room'), '0', String(W), String(H),
      path.join(OUT, 'reference_single'), [c.yawDeg, c.pitchDeg, c.fovDeg, ...c.position].join(',')]);
  }
  await p.evaluate((c) => document.getElementById('v').setCamera(c), CAMERAS[0]);
  return psnr(await readCanvas(p), readPpm(reference).data, W, H);
}

test('a delivery package with lossy normals decodes in Chromium as under Node', async () => {
  const delivery = path.join(tmp, 'delivery');
  runTool('viewer_test_tool', ['package', 'test', '512', '256', delivery, '128', '2', 'lossy-normals']);
  assert.equal(JSON.parse(fs.readFileSync(path.join(delivery, 'manifest.json'), 'utf8')).normal_encoding.type, 'octahedral-lossy');
  // Per layer: present nodes, unlit present nodes and the sums of the normals'
  // components (the images' G codes and alpha, through each decoder).
  const summary = (pano) => [0, 1].map((l) => {
    const { present, normal } = pano.layer(l);
    const s = { present: 0, unlit: 0, sum: [0, 0, 0] };
    for (let i = 0; i < present.length; ++i) {
      if (!present[i]) continue;
      ++s.present;
      if (normal[3 * i] === 0 && normal[3 * i + 1] === 0 && normal[3 * i + 2] === 0) ++s.unlit;
      for (let c = 0; c < 3; ++c) s.sum[c] += normal[3 * i + c];
    }
    return s;
  });
  const format = await loadFormatModule();
  const expected = [];
  for (const level of [0, 1]) {
    const { pano } = await readPackageLevel(format, delivery, level);
    try { expected.push(summary(pano)); } finally { pano.free(); }
  }
  assert.ok(expected[0][0].unlit > 0 && expected[0][0].unlit < expected[0][0].present);
  const served = await startServer({ '/viewer/': DIST_DIR, '/pkg/': delivery }, { '/index.html': '<!doctype html><title>t</title>' });
  const other = await browser.newPage();
  try {
    await other.goto(`${served.url}/index.html`);
    const got = await other.evaluate(async (summarySource) => {
      const summarize = eval(summarySource);
      const { openPackage: open } = await import('/viewer/format.js');
      const pkg = await open('/pkg/manifest.json');
      const out = [];
      for (const level of [0, 1]) {
        const pano = await pkg.readLevel(level);
        try { out.push(summarize(pano)); } finally { pano.free(); }
      }
      pkg.close();
      return out;
    }, summary.toString());
    for (let level = 0; level < 2; ++level) {
      for (let l = 0; l < 2; ++l) {
        const [g, e] = [got[level][l], expected[level][l]];
        assert.equal(g.present, e.present);
        assert.equal(g.unlit, e.unlit, `level ${level} layer ${l}: unlit nodes`);
        for (let c = 0; c < 3; ++c) assert.ok(Math.abs(g.sum[c] - e.sum[c]) < 1e-3 * e.present, `level ${level} layer ${l}: normal sums ${g.sum} vs ${e.sum}`);
      }
    }
  } finally {
    await other.close();
    await served.close();
  }
});

test('a .c3d by URL: range requests, the first frame before the finest level is asked for', async () => {
  const file = path.join(tmp, 'single', 'room.c3d');
  const entries = singleFileEntries(file);
  const start = server.log.length;
  const { page: p, events, firstEpochMs } = await loadInNewPage(`${server.url}/room.html`);
  try {
    const errors = events.filter((e) => e.type === 'error');
    assert.equal(errors.length, 0, `unexpected errors: ${JSON.stringify(errors)}`);
    assert.deepEqual(events.filter((e) => e.type === 'level').map((e) => e.detail.level), [2, 1, 0]);
    const requests = server.log.slice(start).filter((r) => r.path === '/single/room.c3d');
    assert.ok(requests.every((r) => r.status === 206 && r.range), 'every request of the .c3d is a range');
    // The first request reads the header and directory (16 KiB, which may hold
    // the first files' bytes too); every other one reads one file.
    assert.equal(requests[0].range[0], 0);
    assert.ok(requests[0].bytes <= 16 * 1024);
    const fileOf = new Map(entries.map((e) => [e.offset, e.path]));
    const reads = requests.slice(1).map((r) => ({ ...r, file: fileOf.get(r.range[0]) }));
    assert.ok(reads.every((r) => r.file && r.bytes === entries.find((e) => e.path === r.file).size),
      'each range is one file of the container');
    const finest = reads.filter((r) => r.file.startsWith('l0/'));
    assert.ok(finest.length > 0, 'the finest level was read');
    const firstFinest = Math.min(...finest.map((r) => r.epochMs));
    metrics.singleFile = {
      requests: requests.length, bytes: requests.reduce((s, r) => s + r.bytes, 0), fileBytes: fs.statSync(file).size,
      firstFrameBeforeFinestMs: Math.round(firstFinest - firstEpochMs),
      timeToFirstFrameMs: Math.round(events.find((e) => e.type === 'firstframe').detail.timeToFirstFrameMs),
    };
    assert.ok(firstEpochMs < firstFinest,
      `the first frame (${firstEpochMs}) came before the first request of the finest level (${firstFinest})`);
    // Coarse levels first: no range of the finest level before the coarsest was complete.
    const coarsest = reads.filter((r) => r.file.startsWith('l2/'));
    assert.ok(coarsest.length > 0 && Math.max(...coarsest.map((r) => r.epochMs)) < firstFinest);
    // Each file at most once (one straddling the first 16 KiB is read whole).
    assert.equal(new Set(reads.map((r) => r.file)).size, reads.length);
    assert.ok(metrics.singleFile.bytes <= metrics.singleFile.fileBytes + 16 * 1024);
    const db = await psnrOfCamera0(p);
    metrics.singleFile.psnrDb = Number(db.toFixed(2));
    assert.ok(db >= 30, `PSNR ${db.toFixed(2)} dB < 30 dB`);
    await p.screenshot({ path: path.join(OUT, 'single_file.png') });
  } finally {
    await p.close();
  }
});

test('a .c3d from a server that ignores ranges: one whole download', async () => {
  const plain = await startServer({ '/viewer/': DIST_DIR, '/single/': path.join(tmp, 'single') }, {
    '/room.html': viewerPage('/single/room.c3d', { width: W, height: H, maxLevelWidth: 1024 }),
    '/favicon.ico': '',
  }, { isolated: true, ranges: false });
  try {
    const { page: p, events } = await loadInNewPage(`${plain.url}/room.html`);
    try {
      assert.deepEqual(events.filter((e) => e.type === 'error'), []);
      assert.deepEqual(events.filter((e) => e.type === 'level').map((e) => e.detail.level), [2, 1, 0]);
      const requests = plain.log.filter((r) => r.path === '/single/room.c3d');
      assert.deepEqual(requests.map((r) => [r.status, r.bytes]), [[200, fs.statSync(path.join(tmp, 'single', 'room.c3d')).size]]);
      const db = await psnrOfCamera0(p);
      metrics.singleFileNoRanges = { psnrDb: Number(db.toFixed(2)) };
      assert.ok(db >= 30, `PSNR ${db.toFixed(2)} dB < 30 dB`);
    } finally {
      await p.close();
    }
  } finally {
    await plain.close();
  }
});

test('a corrupted tile shows an error, keeps the coarser level and the page responsive', async () => {
  await page.goto(`${server.url}/bad.html`);
  await waitForEvent('error');
  const state = await page.evaluate(async () => {
    const el = document.getElementById('v');
    const t = performance.now();
    await el.viewer.nextFrame();  // Still rendering.
    return {
      message: el.errorMessage, stats: el.viewer.stats, frameMs: performance.now() - t,
      levels: window.__events.filter((e) => e.type === 'level').map((e) => e.detail.level),
    };
  });
  metrics.corruptMessage = state.message;
  assert.match(state.message, new RegExp(metrics.damagedFile.replace(/[.]/g, '\\.')), 'the message names the file');
  assert.match(state.message, /SHA-256 does not match|checksum/);
  assert.deepEqual(state.levels, [2, 1], 'the coarser levels were shown');
  assert.ok(state.frameMs < 5000, `a frame took ${state.frameMs} ms`);
  // The page still answers input: drag to turn the view.
  const before = await page.evaluate(() => document.getElementById('v').getCamera().yawDeg);
  await page.mouse.move(300, 200);
  await page.mouse.down();
  await page.mouse.move(200, 200, { steps: 5 });
  await page.mouse.up();
  const afterYaw = await page.evaluate(() => document.getElementById('v').getCamera().yawDeg);
  assert.ok(afterYaw > before + 5, `dragging turned the view (${before} -> ${afterYaw})`);
  await page.screenshot({ path: path.join(OUT, 'corrupt.png') });
});

test('a missing package shows a fatal error message', async () => {
  await page.goto(`${server.url}/missing.html`);
  await waitForEvent('error');
  const state = await page.evaluate(() => ({
    message: document.getElementById('v').errorMessage,
    error: window.__events.find((e) => e.type === 'error').detail,
  }));
  assert.equal(state.error.fatal, true);
  assert.match(state.message, /^manifest\.json: HTTP 404/);
});

test('`casual3d view` serves a package the browser shows', async (t) => {
  const casual3d = path.join(BINARY_DIR, 'cli', 'casual3d');
  if (!fs.existsSync(casual3d)) return t.skip('casual3d is not built');
  const { spawn } = await import('node:child_process');
  const proc = spawn(casual3d, ['view', path.join(tmp, 'room'), '--port', '0'], { stdio: ['ignore', 'pipe', 'inherit'] });
  try {
    const url = await new Promise((resolve, reject) => {
      let out = '';
      proc.stdout.on('data', (d) => {
        out += d;
        const m = out.match(/http:\/\/127\.0\.0\.1:\d+\//);
        if (m) resolve(m[0]);
      });
      proc.on('exit', (code) => reject(new Error(`casual3d view exited with ${code}`)));
    });
    await page.goto(url);
    await page.waitForFunction(() => {
      const el = document.querySelector('casual3d-viewer');
      return el && el.viewer && el.viewer.stats.loadMs !== undefined;
    }, null, { timeout: 120000, polling: 200 });
    const state = await page.evaluate(() => {
      const el = document.querySelector('casual3d-viewer');
      return { error: el.errorMessage, level: el.viewer.stats.level, triangles: el.viewer.stats.triangles };
    });
    assert.equal(state.error, '');
    assert.equal(state.level, 0);
    assert.ok(state.triangles > 100000);
    await page.screenshot({ path: path.join(OUT, 'casual3d_view.png') });
  } finally {
    proc.kill('SIGINT');
  }
});
