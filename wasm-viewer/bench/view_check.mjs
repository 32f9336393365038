// What a viewer sees of a package, in headless Chromium (SwiftShader): the
// fraction of background pixels (no surface, measured offscreen by the
// renderer) of the default view and of the view after dragging to each limit
// (left, right, up, down, zoom out; the mouse where the drag left it, and
// moved to the centre), with a screenshot of each; and the same
// for the classic viewer (no framing, no limits, black background, a fixed
// 0.3 ball, opening at yaw 0, pitch 0, 75 degrees), also turned 40 degrees
// with the eye moved 0.25 to the side. Prints one JSON line.
//
//   CASUAL3D_BINARY_DIR=build node wasm-viewer/bench/view_check.mjs <package_dir> <out_dir> [width] [height]

import fs from 'node:fs';
import path from 'node:path';

import { chromium } from 'playwright-core';

import { DIST_DIR } from '../test/node-support.mjs';
import { chromiumArgs, startServer, viewerCorePage } from '../test/static-server.mjs';

const [pkg, out] = process.argv.slice(2, 4);
if (!pkg || !out) throw new Error('usage: view_check.mjs <package_dir> <out_dir> [width] [height]');
const W = Number(process.argv[4] ?? 960), H = Number(process.argv[5] ?? 540);
fs.mkdirSync(out, { recursive: true });

const page = (options) => viewerCorePage(options, W, H);

const CLASSIC = { maxOffset: 0.3, keepInContent: false, softBackground: false };
const server = await startServer({ '/viewer/': DIST_DIR, '/pkg/': pkg }, {
  '/now.html': page({}), '/classic.html': page(CLASSIC), '/favicon.ico': '',
}, { isolated: true });
const browser = await chromium.launch({ executablePath: '/usr/bin/chromium', args: chromiumArgs() });
const result = { width: W, height: H };
try {
  const tab = await browser.newPage({ viewport: { width: W, height: H }, deviceScaleFactor: 1 });
  tab.on('console', (m) => { if (m.type() === 'warning' || m.type() === 'error') console.error(m.text()); });
  const open = async (name) => {
    await tab.goto(`${server.url}/${name}.html`);
    await tab.waitForFunction(() => window.loaded, null, { timeout: 600000 });
    await tab.evaluate(() => window.loaded);
  };
  const measure = async (file) => {
    const r = await tab.evaluate(async () => {
      await window.viewer.nextFrame();
      return { background: window.viewer.measureBackground(), camera: window.viewer.getCamera() };
    });
    await tab.screenshot({ path: path.join(out, file) });
    return r;
  };
  // The ease back starts 200 ms after the last input (viewer-core.js) and
  // moves the view once per frame: wait past that, then until the camera
  // stays put for three frames.
  const settle = async () => {
    await tab.waitForTimeout(300);
    let last = '', still = 0;
    for (let i = 0; i < 200 && still < 3; ++i) {
      const c = JSON.stringify(await tab.evaluate(async () => {
        await window.viewer.nextFrame();
        return window.viewer.getCamera();
      }));
      still = c === last ? still + 1 : 0;
      last = c;
    }
  };
  const drag = async (dx, dy) => {
    const x0 = W / 2 - dx / 2, y0 = H / 2 - dy / 2;
    for (let i = 0; i < 3; ++i) {
      await tab.mouse.move(x0, y0);
      await tab.mouse.down();
      await tab.mouse.move(x0 + dx, y0 + dy, { steps: 12 });
      await tab.mouse.up();
    }
  };

  await open('classic');
  await tab.evaluate(() => window.viewer.setCamera({ yawDeg: 0, pitchDeg: 0, fovDeg: 75, position: [0, 0, 0] }));
  result.classicDefault = await measure('classic_default.png');
  await tab.evaluate(() => window.viewer.setCamera({ yawDeg: 40, position: [0.25 * Math.cos(40 * Math.PI / 180), 0, 0.25 * Math.sin(40 * Math.PI / 180)] }));
  result.classicTurned = await measure('classic_turned40_moved025.png');

  await open('now');
  result.hints = await tab.evaluate(() => window.viewer.getViewHints());
  await tab.mouse.move(W / 2, H / 2);
  await settle();
  result.default = await measure('default.png');
  const limits = {
    left: () => drag(0.85 * W, 0), right: () => drag(-0.85 * W, 0), up: () => drag(0, 0.85 * H), down: () => drag(0, -0.85 * H),
    zoomout: async () => { await tab.mouse.move(W / 2, H / 2); for (let i = 0; i < 6; ++i) await tab.mouse.wheel(0, 400); },
  };
  for (const [name, go] of Object.entries(limits)) {
    await tab.evaluate(() => window.viewer.resetView());
    await settle();
    await go();
    await settle();
    // The mouse where the input left it (its parallax included), then back
    // at the centre of the view (the eye at the centre).
    result[name] = await measure(`limit_${name}.png`);
    await tab.mouse.move(W / 2, H / 2);
    result[`${name}Centred`] = await measure(`limit_${name}_centred.png`);
  }
  // Past the content on purpose (limits off): the soft background.
  await tab.evaluate(() => {
    const v = window.viewer;
    const h = v.getViewHints();
    v.options.keepInContent = false;
    v.setCamera({ yawDeg: h.contentYawDeg[0] + 10, pitchDeg: 0, fovDeg: 75 });
  });
  result.pastLeftEdge = await measure('past_left_edge.png');
} finally {
  await browser.close();
  await server.close();
}
const pct = (r) => (r ? Number((100 * r.background).toFixed(3)) : null);
console.log(JSON.stringify({
  backgroundPercent: {
    classicDefault: pct(result.classicDefault), classicTurned40Moved025: pct(result.classicTurned),
    default: pct(result.default), left: pct(result.left), right: pct(result.right), up: pct(result.up),
    down: pct(result.down), zoomout: pct(result.zoomout),
    eyeCentred: Object.fromEntries(['left', 'right', 'up', 'down', 'zoomout'].map((k) => [k, pct(result[`${k}Centred`])])),
    pastLeftEdgeLimitsOff: pct(result.pastLeftEdge),
  },
  result,
}));
