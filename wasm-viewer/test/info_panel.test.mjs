// Browser test of the viewer's info panel (headless Chromium, SwiftShader):
// the page `casual3d reconstruct` writes puts the capture's advice in the
// element's slot "info" and, when it warns, the info-open attribute
// (cli/viewer_assets.cc). With them the panel shows the advice over the 3D
// photo at load, the Info button toggles it and × closes it; without slotted
// content there is neither panel nor button. Screenshots go to
// $CASUAL3D_BINARY_DIR/wasm-viewer/info-panel-test/.
// Exits 77 (ctest: skipped) when Chromium is not installed.

import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { after, before, test } from 'node:test';

import { BINARY_DIR, DIST_DIR, runTool } from './node-support.mjs';
import { chromiumArgs, chromiumOrSkip, startServer } from './static-server.mjs';

const { chromium, executable: CHROMIUM } = await chromiumOrSkip('the info panel test');

const OUT = path.join(BINARY_DIR, 'wasm-viewer', 'info-panel-test');
const WARNING = 'The camera moved 1.84 m around the subject; 3D photos are taken from one spot: stand still and turn.';

// As cli/viewer_assets.cc writes it.
const page = (attributes, info) => `<!DOCTYPE html><html lang="en"><head><meta charset="utf-8">
<script type="module" src="/viewer/casual3d-viewer.js"></script>
<style>html,body{margin:0;height:100%;background:#000}casual3d-viewer{display:block;width:100%;height:100%}
casual3d-viewer h2{font-size:14px;margin:0 0 6px}casual3d-viewer p{margin:0 0 6px}casual3d-viewer .warning{color:#ffd166}</style>
</head><body><casual3d-viewer src="/pkg/manifest.json" controls ${attributes}>${info}</casual3d-viewer></body></html>`;

const ADVICE = `<div slot="info">
<h2>About this capture</h2>
<p>The camera moved 1.84 m; the nearest objects were 0.84 m away; the photos see 18% of the sphere around them.</p>
<p class="warning">${WARNING}</p>
</div>`;

let tmp, server, browser, tab;

before(async () => {
  fs.mkdirSync(OUT, { recursive: true });
  tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'casual3d-info-'));
  const pkg = path.join(tmp, 'room');
  runTool('viewer_test_tool', ['package', 'room', '1024', '512', pkg, '256', '2']);
  server = await startServer({ '/viewer/': DIST_DIR, '/pkg/': pkg }, {
    '/warned.html': page('info-open', ADVICE),
    '/quiet.html': page('', ADVICE.replace(/<p class="warning">.*<\/p>\n/, '')),
    '/plain.html': page('', ''),
    '/favicon.ico': '',
  });
  browser = await chromium.launch({ executablePath: CHROMIUM, args: chromiumArgs() });
  tab = await browser.newPage({ viewport: { width: 800, height: 450 }, deviceScaleFactor: 1 });
});

after(async () => {
  await browser?.close();
  await server?.close();
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
});

async function open(name) {
  await tab.goto(`${server.url}/${name}.html`);
  await tab.waitForFunction(() => {
    const v = document.querySelector('casual3d-viewer');
    return v && v.viewer && v.shadowRoot.querySelector('.status').hidden;
  }, null, { timeout: 120000, polling: 100 });
}

const state = () => tab.evaluate(() => {
  const v = document.querySelector('casual3d-viewer');
  const button = v.shadowRoot.querySelector('[data-action="info"]');
  const panel = v.shadowRoot.querySelector('.info');
  const box = panel.getBoundingClientRect();
  return {
    text: v.infoText, button: !button.hidden, pressed: button.getAttribute('aria-pressed'),
    panel: !panel.hidden, width: box.width, height: box.height,
  };
});

test('a warned capture shows its advice at load; Info and × toggle it', async () => {
  await open('warned');
  let s = await state();
  assert.ok(s.panel && s.button, JSON.stringify(s));
  assert.equal(s.pressed, 'true');
  assert.match(s.text, /About this capture/);
  assert.ok(s.text.includes(WARNING), s.text);
  // A panel beside the photo, not over all of it.
  assert.ok(s.width > 200 && s.width < 0.7 * 800 && s.height < 0.8 * 450, JSON.stringify(s));
  await tab.screenshot({ path: path.join(OUT, 'warned.png') });
  await tab.evaluate(() => document.querySelector('casual3d-viewer').shadowRoot.querySelector('.info > button').click());
  s = await state();
  assert.ok(!s.panel && s.button && s.text === '' && s.pressed === 'false', JSON.stringify(s));
  await tab.screenshot({ path: path.join(OUT, 'closed.png') });
  await tab.evaluate(() => document.querySelector('casual3d-viewer').shadowRoot.querySelector('[data-action="info"]').click());
  s = await state();
  assert.ok(s.panel && s.text.includes(WARNING), JSON.stringify(s));
});

test('a capture without warnings keeps the panel closed behind its Info button', async () => {
  await open('quiet');
  let s = await state();
  assert.ok(!s.panel && s.button, JSON.stringify(s));
  await tab.evaluate(() => document.querySelector('casual3d-viewer').showInfo());
  s = await state();
  assert.ok(s.panel && /The camera moved 1.84 m/.test(s.text) && !s.text.includes(WARNING), s.text);
});

test('without slotted content there is no panel and no Info button', async () => {
  await open('plain');
  await tab.evaluate(() => document.querySelector('casual3d-viewer').showInfo());
  const s = await state();
  assert.ok(!s.panel && !s.button && s.text === '', JSON.stringify(s));
});
