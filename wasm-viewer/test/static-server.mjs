// A tiny static HTTP server for the viewer's browser tests and benchmarks:
// serves `routes` (URL prefix -> folder) on 127.0.0.1 with the MIME types the
// viewer needs (application/wasm included), single byte ranges (206) unless
// told to ignore them, and logs each request with the bytes it sends.

import fs from 'node:fs';
import http from 'node:http';
import path from 'node:path';

const MIME = {
  '.html': 'text/html; charset=utf-8', '.js': 'text/javascript; charset=utf-8', '.json': 'application/json',
  '.mjs': 'text/javascript; charset=utf-8', '.css': 'text/css', '.wasm': 'application/wasm', '.webp': 'image/webp',
  '.png': 'image/png', '.ts': 'text/plain',
};

/**
 * @param {Record<string, string>} routes e.g. {'/viewer/': distDir, '/pkg/': packageDir}
 * @param {Record<string, string>} pages exact paths served from memory (e.g. '/index.html')
 * @param {{isolated?: boolean, ranges?: boolean}} options isolated: send the cross-origin
 *   isolation headers (COOP same-origin, COEP require-corp) that let the viewer use its
 *   threaded wasm build; ranges (default true): answer a single-range Range header with 206,
 *   else send the whole file (200) as a server without range support does
 * @returns {Promise<{url: string, close: () => Promise<void>,
 *   log: {path: string, status: number, range: [number, number] | null, bytes: number, t: number, epochMs: number}[]}>}
 *   t: performance.now() of this process; epochMs: the same instant in milliseconds since
 *   1970, comparable with a page's performance.timeOrigin + performance.now()
 */
export async function startServer(routes, pages = {}, { isolated = false, ranges = true } = {}) {
  const log = [];
  const server = http.createServer((req, res) => {
    const urlPath = decodeURIComponent(new URL(req.url, 'http://x').pathname);
    const arrived = performance.now();
    const send = (code, type, body, extra = {}, range = null) => {
      const headers = { 'Content-Type': type, 'Content-Length': body.length, 'Cache-Control': 'no-store', ...extra };
      if (isolated) {
        headers['Cross-Origin-Opener-Policy'] = 'same-origin';
        headers['Cross-Origin-Embedder-Policy'] = 'require-corp';
      }
      res.writeHead(code, headers);
      res.end(body);
      log.push({ path: urlPath, status: code, range, bytes: body.length, t: arrived, epochMs: performance.timeOrigin + arrived });
    };
    const sendFile = (file) => {
      const body = fs.readFileSync(file);
      const type = MIME[path.extname(file)] ?? 'application/octet-stream';
      const m = ranges ? /^bytes=(\d*)-(\d*)$/.exec(req.headers.range ?? '') : null;
      if (!m || (m[1] === '' && m[2] === '')) return send(200, type, body);
      const size = body.length;
      const first = m[1] === '' ? Math.max(0, size - Number(m[2])) : Number(m[1]);
      const last = m[1] === '' || m[2] === '' ? size - 1 : Math.min(Number(m[2]), size - 1);
      if (first >= size || last < first) {
        return send(416, 'text/plain', Buffer.from('range not satisfiable'), { 'Content-Range': `bytes */${size}` });
      }
      return send(206, type, body.subarray(first, last + 1), { 'Content-Range': `bytes ${first}-${last}/${size}` },
        [first, last]);
    };
    if (pages[urlPath] !== undefined) return send(200, MIME['.html'], Buffer.from(pages[urlPath]));
    for (const [prefix, dir] of Object.entries(routes)) {
      if (!urlPath.startsWith(prefix)) continue;
      const rel = urlPath.slice(prefix.length);
      if (rel.split('/').some((s) => s === '..')) return send(400, 'text/plain', Buffer.from('bad path'));
      const file = path.join(dir, rel);
      if (!fs.existsSync(file) || !fs.statSync(file).isFile()) break;
      return sendFile(file);
    }
    send(404, 'text/plain', Buffer.from('not found'));
  });
  await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
  const { port } = server.address();
  return {
    url: `http://127.0.0.1:${port}`,
    log,
    close: () => new Promise((resolve) => { server.closeAllConnections?.(); server.close(() => resolve()); }),
  };
}

/**
 * The flags that give headless Chromium WebGL2 on SwiftShader (TOOLCHAIN.md).
 * Playwright itself starts the browser with a fresh, temporary profile (it
 * refuses --user-data-dir in launch()).
 */
export function chromiumArgs() {
  return [
    '--headless=new', '--no-sandbox', '--enable-unsafe-swiftshader', '--use-angle=swiftshader',
    '--disable-background-networking', '--disable-component-update', '--disable-sync', '--no-first-run',
    '--disable-quic',
  ];
}

/**
 * The Chromium binary and playwright-core's `chromium` for a browser test
 * (`what` names it in the messages). Exits 77 (ctest's skip) when the browser
 * is not installed and 1 when playwright-core is missing.
 */
export async function chromiumOrSkip(what) {
  const executable = process.env.CASUAL3D_CHROMIUM ?? '/usr/bin/chromium';
  if (!fs.existsSync(executable)) {
    console.log(`SKIP: ${executable} is not installed (apt-get install chromium); ${what} needs it`);
    process.exit(77);
  }
  try {
    const { chromium } = await import('playwright-core');
    return { chromium, executable };
  } catch {
    console.error('error: the npm package playwright-core is missing; run `npm ci` in wasm-viewer/ (scripts/setup.sh does)');
    process.exit(1);
  }
}

/** A page embedding one viewer element; events are recorded in window.__events. */
export function viewerPage(src, { width = 640, height = 400, maxLevelWidth = 4096, attributes = '' } = {}) {
  return `<!DOCTYPE html><html><head><meta charset="utf-8">
<style>html,body{margin:0;background:#222}casual3d-viewer{width:${width}px;height:${height}px}</style>
<script>
  window.__events = [];
  window.__t0 = performance.now();
  for (const type of ['progress', 'level', 'firstframe', 'load', 'error']) {
    document.addEventListener(type, (e) => {
      if (e.target && e.target.localName === 'casual3d-viewer') {
        window.__events.push({ type, t: performance.now() - window.__t0, detail: e.detail });
      }
    }, true);
  }
</script>
<script type="module" src="/viewer/casual3d-viewer.js"></script>
</head><body><casual3d-viewer id="v" src="${src}" max-level-width="${maxLevelWidth}" ${attributes}></casual3d-viewer></body></html>`;
}

/**
 * A page with one Casual3dViewer (viewer-core.js, no custom element) built
 * with `options` in a width x height box, opening /pkg/manifest.json;
 * window.viewer is the viewer and window.loaded settles once the first level
 * is shown (or loading failed). The browser benchmarks load it.
 */
export function viewerCorePage(options, width, height) {
  return `<!DOCTYPE html><html><head><meta charset="utf-8">
<style>html,body{margin:0}#c{width:${width}px;height:${height}px}</style></head><body><div id="c"></div>
<script type="module">
  import { Casual3dViewer } from '/viewer/viewer-core.js';
  const v = new Casual3dViewer(document.getElementById('c'), ${JSON.stringify(options)});
  window.viewer = v;
  window.loaded = v.load('/pkg/manifest.json').then(() => new Promise((resolve) => {
    v.addEventListener('load', resolve);
    v.addEventListener('error', resolve);
  }));
</script></body></html>`;
}
