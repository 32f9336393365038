// Benchmark: time to first frame and bytes fetched before it, in headless
// Chromium (SwiftShader) on localhost, for a 4096x2048 package. Prints one
// JSON line.
//
//   CASUAL3D_BINARY_DIR=build node wasm-viewer/bench/browser_bench.mjs [package_dir] [isolated|plain]
// Without package_dir it writes the procedural test panorama's package
// (viewer_test_tool package test 4096 2048) to a temporary folder.

import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';

import { chromium } from 'playwright-core';

import { DIST_DIR, runTool } from '../test/node-support.mjs';
import { chromiumArgs, startServer, viewerPage } from '../test/static-server.mjs';

let pkg = process.argv[2];
const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'casual3d-browser-bench-'));
if (!pkg) {
  pkg = path.join(tmp, 'pkg');
  runTool('viewer_test_tool', ['package', 'test', '4096', '2048', pkg]);
}
// `isolated` (the default, as `casual3d view` serves): cross-origin isolation
// headers, so the worker uses the threaded wasm build; `plain`: none, one thread.
const mode = process.argv[3] ?? 'isolated';
if (mode !== 'isolated' && mode !== 'plain') throw new Error(`mode ${mode}: expected isolated or plain`);
const server = await startServer({ '/viewer/': DIST_DIR, '/pkg/': pkg }, {
  '/index.html': viewerPage('/pkg/manifest.json', { width: 960, height: 540 }),
  '/favicon.ico': '',
}, { isolated: mode === 'isolated' });
const browser = await chromium.launch({ executablePath: '/usr/bin/chromium', args: chromiumArgs() });
try {
  const page = await browser.newPage({ viewport: { width: 960, height: 540 } });
  await page.goto(`${server.url}/index.html`);
  const t0 = server.log[0].t;
  await page.waitForFunction(() => window.__events.some((e) => e.type === 'firstframe'), null, { timeout: 300000 });
  await page.waitForFunction(() => window.__events.some((e) => e.type === 'load' || e.type === 'error'), null, { timeout: 600000 });
  const events = await page.evaluate(() => window.__events);
  const first = events.find((e) => e.type === 'firstframe');
  const beforeFirst = server.log.filter((r) => r.t - t0 <= first.t);
  const levels = events.filter((e) => e.type === 'level').map((e) => ({ level: e.detail.level, atMs: Math.round(e.t), triangles: e.detail.triangles }));
  const stats = await page.evaluate(() => {
    const s = document.getElementById('v').viewer.stats;
    return { workerMs: s.workerMs, error: s.lastError ?? null };
  });
  console.log(JSON.stringify({
    mode,
    timeToFirstFrameMs: Math.round(first.detail.timeToFirstFrameMs),
    pageLoadToFirstFrameMs: Math.round(first.t),
    packageBytesBeforeFirstFrame: first.detail.bytesBeforeFirstFrame,
    allBytesBeforeFirstFrame: beforeFirst.reduce((s, r) => s + r.bytes, 0),
    viewerCodeBytes: beforeFirst.filter((r) => r.path.startsWith('/viewer/')).reduce((s, r) => s + r.bytes, 0),
    levels, workerMs: stats.workerMs, error: stats.error,
    loadMs: Math.round(events.find((e) => e.type === 'load')?.t ?? -1),
  }));
  await page.screenshot({ path: path.join(tmp, 'bench.png') });
} finally {
  await browser.close();
  await server.close();
  fs.rmSync(tmp, { recursive: true, force: true });
}
