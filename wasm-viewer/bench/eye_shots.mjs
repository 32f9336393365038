// Screenshots of a package from eyes on the boundary of its viewing volume,
// with the backdrop (format/backdrop.h) and its sheets left out (the viewer's
// default, "with"), with the backdrop and every sheet drawn ("sheets",
// format/sheet_stretch.h) and without the backdrop ("without"), in headless Chromium
// (SwiftShader). Each view looks along the package's view hints; eyes at the
// centre and at the left, right, top and bottom of the volume. Prints one
// JSON line: per view, the fraction of pixels no triangle covers.
//
//   CASUAL3D_BINARY_DIR=build node wasm-viewer/bench/eye_shots.mjs <package_dir> <out_dir> [width] [height]

import fs from 'node:fs';
import path from 'node:path';

import { chromium } from 'playwright-core';

import { DIST_DIR } from '../test/node-support.mjs';
import { chromiumArgs, startServer, viewerCorePage } from '../test/static-server.mjs';

const [pkg, out] = process.argv.slice(2, 4);
if (!pkg || !out) throw new Error('usage: eye_shots.mjs <package_dir> <out_dir> [width] [height]');
if (!fs.existsSync(path.join(pkg, 'manifest.json'))) throw new Error(`${pkg}: no manifest.json (give a package folder)`);
const W = Number(process.argv[4] ?? 960), H = Number(process.argv[5] ?? 540);
fs.mkdirSync(out, { recursive: true });

const page = (options) => viewerCorePage(options, W, H);

const server = await startServer({ '/viewer/': DIST_DIR, '/pkg/': pkg }, {
  '/with.html': page({ mouseParallax: false }), '/without.html': page({ mouseParallax: false, backdrop: false }),
  '/sheets.html': page({ mouseParallax: false, sheetStretch: 0 }),
  '/favicon.ico': '',
}, { isolated: true });
const browser = await chromium.launch({ executablePath: '/usr/bin/chromium', args: chromiumArgs() });
const result = {};
try {
  const tab = await browser.newPage({ viewport: { width: W, height: H }, deviceScaleFactor: 1 });
  for (const name of ['with', 'sheets', 'without']) {
    await tab.goto(`${server.url}/${name}.html`);
    await tab.waitForFunction(() => window.loaded, null, { timeout: 600000 });
    await tab.evaluate(() => window.loaded);
    const hints = await tab.evaluate(() => window.viewer.getViewHints());
    const r = hints.volumeRadius * 0.999, yaw = (hints.yawDeg * Math.PI) / 180;
    const right = [Math.cos(yaw), 0, Math.sin(yaw)];
    const eyes = {
      centre: [0, 0, 0], left: right.map((v) => -r * v), right: right.map((v) => r * v),
      up: [0, r, 0], down: [0, -r, 0],
    };
    result[name] = {};
    for (const [eye, position] of Object.entries(eyes)) {
      result[name][eye] = await tab.evaluate(async ([p, h]) => {
        window.viewer.setCamera({ yawDeg: h.yawDeg, pitchDeg: h.pitchDeg, fovDeg: h.fovDeg, position: p });
        await window.viewer.nextFrame();
        await window.viewer.nextFrame();
        return window.viewer.measureBackground();
      }, [position, hints]);
      await tab.screenshot({ path: path.join(out, `${name}_${eye}.png`) });
    }
  }
} finally {
  await browser.close();
  server.close();
}
console.log(JSON.stringify(result));
