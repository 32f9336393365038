// Benchmark: the viewer's tile image decoding in headless Chromium, alone.
// Every tile image of one level of a package is decoded one after another by
// the viewer's own decoder (dist/tile-decoder.js: the browser's image decoder
// and a canvas readback), as many rounds as asked; prints, per image kind,
// the best round's milliseconds, and the best and median total, then the same
// as one JSON line. Interleave two viewer builds (CASUAL3D_BINARY_DIR) or two
// packages in one session to compare them: the machine's drift is larger than
// most differences worth measuring.
//
//   CASUAL3D_BINARY_DIR=build node wasm-viewer/bench/browser_decode_bench.mjs package_dir [rounds] [level]

import fs from 'node:fs';
import path from 'node:path';

import { chromium } from 'playwright-core';

import { DIST_DIR } from '../test/node-support.mjs';
import { chromiumArgs, startServer } from '../test/static-server.mjs';

const pkg = process.argv[2];
const rounds = Number(process.argv[3] ?? 5);
const level = Number(process.argv[4] ?? 0);
if (!pkg || !fs.existsSync(path.join(pkg, 'manifest.json'))) {
  console.error('usage: browser_decode_bench.mjs package_dir [rounds] [level]: package_dir must hold manifest.json');
  process.exit(2);
}
if (!Number.isInteger(rounds) || rounds < 1) throw new Error(`rounds ${process.argv[3]}: expected a positive integer`);
const manifest = JSON.parse(fs.readFileSync(path.join(pkg, 'manifest.json'), 'utf8'));
const levelInfo = manifest.levels?.[level];
if (!levelInfo) throw new Error(`level ${level}: the package has ${manifest.levels?.length ?? 0} levels`);
// Tile image files of the level: each tile maps its kinds to file names.
const files = [];
for (const tile of levelInfo.tiles) {
  for (const [kind, name] of Object.entries(tile)) files.push({ kind, name });
}
if (files.length === 0 || files.some((f) => typeof f.name !== 'string')) throw new Error(`level ${level}: no tile image names found in the manifest`);

const page = `<!doctype html><script type=module>
import { decodeImage } from '/viewer/tile-decoder.js';
const files = ${JSON.stringify(files)};
const bytes = [];
for (const f of files) bytes.push(new Uint8Array(await (await fetch('/pkg/' + f.name)).arrayBuffer()));
const results = [];
for (let r = 0; r < ${rounds}; ++r) {
  const byKind = {};
  const t0 = performance.now();
  for (let i = 0; i < files.length; ++i) {
    const s = performance.now();
    await decodeImage(bytes[i], files[i].name, 'image/webp');
    byKind[files[i].kind] = (byKind[files[i].kind] ?? 0) + performance.now() - s;
  }
  results.push({ total: performance.now() - t0, byKind });
}
window.__results = results;
</script>`;

const server = await startServer({ '/viewer/': DIST_DIR, '/pkg/': pkg }, { '/index.html': page, '/favicon.ico': '' });
const browser = await chromium.launch({ executablePath: '/usr/bin/chromium', args: chromiumArgs() });
try {
  const tab = await browser.newPage();
  await tab.goto(`${server.url}/index.html`);
  await tab.waitForFunction(() => window.__results, null, { timeout: 900000 });
  const results = await tab.evaluate(() => window.__results);
  const totals = results.map((r) => r.total).sort((a, b) => a - b);
  const best = results.reduce((a, b) => (b.total < a.total ? b : a));
  console.log(`level ${level} of ${pkg}: ${files.length} images, ${rounds} rounds, one after another`);
  console.log('| kind | ms (best round) |\n|---|---|');
  for (const [kind, ms] of Object.entries(best.byKind)) console.log(`| ${kind} | ${Math.round(ms)} |`);
  console.log(`| all: best / median | ${Math.round(totals[0])} / ${Math.round(totals[Math.floor(totals.length / 2)])} |`);
  console.log(JSON.stringify({
    level, images: files.length, rounds, bestMs: Math.round(totals[0]),
    medianMs: Math.round(totals[Math.floor(totals.length / 2)]),
    byKindMs: Object.fromEntries(Object.entries(best.byKind).map(([k, v]) => [k, Math.round(v)])),
  }));
} finally {
  await browser.close();
  await server.close();
}
