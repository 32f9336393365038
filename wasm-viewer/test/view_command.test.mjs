// `casual3d view <package> --port 0`: serves the package and the viewer on
// 127.0.0.1 with the right MIME types, never outside the served folders, and
// refuses bad input with one clear line; single byte ranges (206, 416) for
// reading a .c3d file level by level.

import assert from 'node:assert/strict';
import { spawn, spawnSync } from 'node:child_process';
import fs from 'node:fs';
import http from 'node:http';
import os from 'node:os';
import path from 'node:path';
import { after, before, test } from 'node:test';

import { BINARY_DIR } from './node-support.mjs';

const CASUAL3D = path.join(BINARY_DIR, 'cli', 'casual3d');
let tmp, pkg, server, base;

/** Raw GET/HEAD (the path is sent exactly as given, no normalisation). */
function request(rawPath, method = 'GET', headers = {}) {
  const { hostname, port } = new URL(base);
  return new Promise((resolve, reject) => {
    const req = http.request({ hostname, port, path: rawPath, method, headers }, (res) => {
      const chunks = [];
      res.on('data', (c) => chunks.push(c));
      res.on('end', () => resolve({ status: res.statusCode, type: res.headers['content-type'], headers: res.headers, body: Buffer.concat(chunks) }));
    });
    req.on('error', reject);
    req.end();
  });
}

before(async () => {
  tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'casual3d-view-'));
  pkg = path.join(tmp, 'scene');
  fs.mkdirSync(path.join(pkg, 'l0'), { recursive: true });
  fs.writeFileSync(path.join(pkg, 'manifest.json'), '{"format": "casual3d"}\n');
  fs.writeFileSync(path.join(pkg, 'l0', '0-0.color.webp'), Buffer.from('RIFF....WEBPVP8 '));
  fs.writeFileSync(path.join(pkg, 'photo.c3d'), Buffer.from(Array.from({ length: 1000 }, (_, i) => (i * 7) % 256)));
  fs.writeFileSync(path.join(tmp, 'secret.txt'), 'outside the package');
  fs.symlinkSync(path.join(tmp, 'secret.txt'), path.join(pkg, 'link.txt'));
  server = spawn(CASUAL3D, ['view', pkg, '--port', '0'], { stdio: ['ignore', 'pipe', 'pipe'] });
  base = await new Promise((resolve, reject) => {
    let out = '';
    server.stdout.on('data', (d) => {
      out += d;
      const m = out.match(/http:\/\/127\.0\.0\.1:\d+\//);
      if (m) resolve(m[0]);
    });
    server.on('exit', (code) => reject(new Error(`casual3d view exited with ${code}: ${out}`)));
  });
});

after(() => {
  server?.kill('SIGINT');
  if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
});

test('serves the page, the viewer and the package with the right types', async () => {
  const page = await request('/');
  assert.equal(page.status, 200);
  assert.match(page.type, /^text\/html/);
  assert.match(page.body.toString(), /<casual3d-viewer src="manifest.json"/);
  assert.match(page.body.toString(), /src="viewer\/casual3d-viewer.js"/);
  const js = await request('/viewer/casual3d-viewer.js');
  assert.equal(js.status, 200);
  assert.match(js.type, /^text\/javascript/);
  const wasm = await request('/viewer/casual3d-format.wasm');
  assert.equal(wasm.status, 200);
  assert.equal(wasm.type, 'application/wasm');
  assert.deepEqual([...wasm.body.subarray(0, 4)], [0, 0x61, 0x73, 0x6d]);
  // Cross-origin isolated, so that the viewer may use its threaded build.
  assert.equal(page.headers['cross-origin-opener-policy'], 'same-origin');
  assert.equal(page.headers['cross-origin-embedder-policy'], 'require-corp');
  const worker = await request('/viewer/casual3d-format-mt.worker.js');
  assert.equal(worker.status, 200);
  const manifest = await request('/manifest.json?x=1');
  assert.equal(manifest.type, 'application/json');
  assert.equal(manifest.body.toString(), '{"format": "casual3d"}\n');
  const tile = await request('/l0/0-0.color.webp');
  assert.equal(tile.type, 'image/webp');
  const head = await request('/manifest.json', 'HEAD');
  assert.equal(head.status, 200);
  assert.equal(head.body.length, 0);
});

test('never serves outside the package and the viewer', async () => {
  for (const p of ['/../secret.txt', '/%2e%2e/secret.txt', '/l0/..%2f..%2fsecret.txt', '/viewer/../../secret.txt',
    '/l0/%2E%2E/%2E%2E/secret.txt', '/..\\secret.txt', '/%00manifest.json']) {
    const r = await request(p);
    assert.ok(r.status === 400 || r.status === 404, `${p}: status ${r.status}`);
    assert.ok(!r.body.toString().includes('outside the package'), `${p} leaked a file`);
  }
  const link = await request('/link.txt');
  assert.equal(link.status, 404, 'a symbolic link out of the package is not followed');
  assert.equal((await request('/missing.webp')).status, 404);
  assert.equal((await request('/manifest.json', 'POST')).status, 405);
});

test('refuses bad input with one clear line', () => {
  const missing = spawnSync(CASUAL3D, ['view', path.join(tmp, 'nope')], { encoding: 'utf8' });
  assert.equal(missing.status, 1);
  assert.match(missing.stderr, /^casual3d: error: .*nope: not a folder/);
  assert.equal(missing.stderr.trim().split('\n').length, 1);
  const empty = path.join(tmp, 'empty');
  fs.mkdirSync(empty);
  const noManifest = spawnSync(CASUAL3D, ['view', empty], { encoding: 'utf8' });
  assert.equal(noManifest.status, 1);
  assert.match(noManifest.stderr, /empty: no manifest.json/);
  const badPort = spawnSync(CASUAL3D, ['view', pkg, '--port', '70000'], { encoding: 'utf8' });
  assert.equal(badPort.status, 1);
  assert.match(badPort.stderr, /--port 70000/);
});

test('serves single byte ranges: 206 with Content-Range, 416 past the end, 200 otherwise', async () => {
  const whole = fs.readFileSync(path.join(pkg, 'photo.c3d'));
  const full = await request('/photo.c3d');
  assert.equal(full.status, 200);
  assert.equal(full.headers['accept-ranges'], 'bytes');
  assert.deepEqual(full.body, whole);
  for (const [range, first, last] of [['bytes=0-9', 0, 9], ['bytes=990-', 990, 999], ['bytes=-4', 996, 999],
    ['bytes=500-5000', 500, 999], ['bytes=123-123', 123, 123], ['bytes=-5000', 0, 999]]) {
    const r = await request('/photo.c3d', 'GET', { Range: range });
    assert.equal(r.status, 206, range);
    assert.equal(r.headers['content-range'], `bytes ${first}-${last}/1000`, range);
    assert.equal(Number(r.headers['content-length']), last - first + 1, range);
    assert.deepEqual(r.body, whole.subarray(first, last + 1), range);
    assert.equal(r.headers['cross-origin-embedder-policy'], 'require-corp');
  }
  for (const range of ['bytes=1000-', 'bytes=5000-6000', 'bytes=-0']) {
    const r = await request('/photo.c3d', 'GET', { Range: range });
    assert.equal(r.status, 416, range);
    assert.equal(r.headers['content-range'], 'bytes */1000', range);
  }
  // Several ranges, other units and malformed values: the whole file.
  for (const range of ['bytes=0-1,5-6', 'items=0-1', 'bytes=9-3', 'bytes=a-b', 'bytes=']) {
    const r = await request('/photo.c3d', 'GET', { Range: range });
    assert.equal(r.status, 200, range);
    assert.deepEqual(r.body, whole, range);
  }
  const head = await request('/photo.c3d', 'HEAD', { Range: 'bytes=10-19' });
  assert.equal(head.status, 206);
  assert.equal(head.headers['content-range'], 'bytes 10-19/1000');
  assert.equal(head.body.length, 0);
  const viewer = await request('/viewer/casual3d-format.wasm', 'GET', { range: 'bytes=0-3' });
  assert.equal(viewer.status, 206);
  assert.deepEqual([...viewer.body], [0, 0x61, 0x73, 0x6d]);
});
