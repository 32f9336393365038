// Shared helpers of the viewer's Node tests: where the build is, loading the
// wasm format module under Node, running native helpers, reading mesh blobs.

import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';

export const SOURCE_DIR = process.env.CASUAL3D_SOURCE_DIR ??
  path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
export const BINARY_DIR = process.env.CASUAL3D_BINARY_DIR ?? path.join(SOURCE_DIR, 'build');
export const DIST_DIR = path.join(BINARY_DIR, 'wasm-viewer', 'dist');
export const TOOLS_DIR = path.join(BINARY_DIR, 'wasm-viewer');

/**
 * The wasm format library (js/format-module.js) instantiated under Node: the
 * threaded build (casual3d-format-mt.wasm) if `threads`, else the
 * single-threaded one.
 */
export async function loadFormatModule({ threads = false } = {}) {
  // The ES6 Emscripten loader expects CommonJS globals under Node.
  globalThis.require ??= createRequire(import.meta.url);
  globalThis.__dirname ??= DIST_DIR;
  const { FormatModule } = await import(pathToFileURL(path.join(DIST_DIR, 'format-module.js')).href);
  const name = threads ? 'casual3d-format-mt.wasm' : 'casual3d-format.wasm';
  const wasmBinary = fs.readFileSync(path.join(DIST_DIR, name));
  return FormatModule.create({ threads, wasmBinary });
}

/** Runs a native helper built in <build>/wasm-viewer; returns stdout. */
export function runTool(name, args) {
  return execFileSync(path.join(TOOLS_DIR, name), args, { encoding: 'utf8' });
}

/** Parses a mesh blob (src/panorama_blob.h) into typed arrays. */
export function parseMeshBlob(bytes) {
  const buf = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
  const magic = Buffer.from(buf, 0, 8).toString('latin1');
  if (magic !== 'C3DMESH1') throw new Error(`not a mesh blob (magic ${JSON.stringify(magic)})`);
  const dv = new DataView(buf);
  const nv = dv.getUint32(8, true), ni = dv.getUint32(12, true);
  let at = 16;
  const take = (Type, n) => {
    const bytesLen = n * Type.BYTES_PER_ELEMENT;
    const out = new Type(buf.slice(at, at + bytesLen));
    at += bytesLen;
    return out;
  };
  const mesh = {
    positions: take(Float32Array, 3 * nv), normals: take(Float32Array, 3 * nv), uvs: take(Float32Array, 2 * nv),
    colors: take(Uint8Array, 3 * nv), indices: take(Uint32Array, ni),
  };
  if (at !== buf.byteLength) throw new Error('mesh blob has trailing bytes');
  return mesh;
}

/** Number of elements whose bytes differ and the largest absolute difference. */
export function compareArrays(a, b) {
  if (a.length !== b.length) return { sameLength: false, differing: Math.max(a.length, b.length), maxAbs: Infinity };
  const ab = new Uint8Array(a.buffer, a.byteOffset, a.byteLength);
  const bb = new Uint8Array(b.buffer, b.byteOffset, b.byteLength);
  let differing = 0, maxAbs = 0;
  const size = a.BYTES_PER_ELEMENT;
  for (let i = 0; i < a.length; ++i) {
    let same = true;
    for (let k = 0; k < size; ++k) if (ab[i * size + k] !== bb[i * size + k]) { same = false; break; }
    if (!same) {
      ++differing;
      maxAbs = Math.max(maxAbs, Math.abs(a[i] - b[i]));
    }
  }
  return { sameLength: true, differing, maxAbs };
}

/**
 * Copies the package folder `from` to `to` and sets its manifest's "view"
 * member (spec/package.md 1.1) to `view`, or removes it (undefined). The
 * manifest is not covered by the package's checksums.
 */
export function copyPackageWithView(from, to, view) {
  fs.cpSync(from, to, { recursive: true });
  const file = path.join(to, 'manifest.json');
  const manifest = JSON.parse(fs.readFileSync(file, 'utf8'));
  if (view === undefined) delete manifest.view;
  else manifest.view = view;
  // A view needs 1.1; a 2.x package keeps its version.
  if (view !== undefined && manifest.version.startsWith('1.')) manifest.version = '1.1';
  fs.writeFileSync(file, JSON.stringify(manifest));
}
