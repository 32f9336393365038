// casual3d-viewer/format under Node: the API of format.js, reading packages
// from the file system (a folder, its manifest.json or a .c3d file, read in
// ranges with positioned reads) as well as URLs, with the wasm format library
// and wasm decoders of the tile images (@jsquash/webp for WebP) in place of the
// browser's.
//
//   import { openPackage } from 'casual3d-viewer/format';
//   const pkg = await openPackage('photo.c3d');
//   const pano = await pkg.readLevel(0);
//   console.log(pano.width, pano.layer(0).depth);
//   pano.free();
//   pkg.close();

import fs from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';

import { Casual3dPackage } from './format.js';
import { FormatModule } from './format-module.js';
import { isSingleFile, openInMemory, openSingleFile, openUrl } from './package-source.js';

export { Casual3dPackage } from './format.js';
export { FormatModule, Panorama, PackageReader } from './format-module.js';

const HERE = path.dirname(fileURLToPath(import.meta.url));
const require = createRequire(import.meta.url);

// Emscripten's ES6 loader reaches for CommonJS' require and __dirname under Node.
globalThis.require ??= require;
globalThis.__dirname ??= HERE;

const formats = new Map();

/**
 * The format library, created once per `threads`: true (default) for the
 * threaded build (min(cores, 4) threads), false for the single-threaded one.
 */
export function createFormat({ threads = true } = {}) {
  const key = threads === false ? 'st' : 'mt';
  if (!formats.has(key)) {
    const wasmBinary = fs.readFileSync(path.join(HERE, key === 'mt' ? 'casual3d-format-mt.wasm' : 'casual3d-format.wasm'));
    // The threaded build's pthread worker is CommonJS: its .cjs copy.
    const locateFile = (file, prefix) =>
      (file.endsWith('.worker.js') ? path.join(HERE, file.replace(/\.js$/, '.cjs')) : prefix + file);
    const created = FormatModule.create({ threads: key === 'mt', wasmBinary, locateFile });
    created.catch(() => formats.delete(key));
    formats.set(key, created);
  }
  return formats.get(key);
}

let webpDecode = null;

/** Decodes a WebP tile image to RGBA with @jsquash/webp's wasm libwebp. */
async function decodeWebp(bytes, name) {
  if (!webpDecode) {
    globalThis.ImageData ??= class ImageData {
      constructor(data, width, height) {
        this.data = data;
        this.width = width;
        this.height = height;
      }
    };
    const dir = path.dirname(require.resolve('@jsquash/webp/package.json'));
    const { default: decode, init } = await import(pathToFileURL(path.join(dir, 'decode.js')).href);
    await init(await WebAssembly.compile(fs.readFileSync(path.join(dir, 'codec', 'dec', 'webp_dec.wasm'))));
    webpDecode = decode;
  }
  try {
    return await webpDecode(bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength));
  } catch {
    throw new Error(`${name}: not a decodable image (corrupt or truncated file)`);
  }
}

/** Node's tile image decoders, by the MIME type the reader names (tileImageType). */
const DECODERS = { 'image/webp': decodeWebp };

/** Decodes a tile image of MIME type `type` to RGBA. */
async function decodeTile(bytes, name, type) {
  const decode = DECODERS[type];
  if (!decode) throw new Error(`${name}: no decoder for ${type} tile images under Node (known: ${Object.keys(DECODERS).join(', ')})`);
  return decode(bytes, name);
}

/** Byte ranges of a file, read with positioned reads. */
function fileRanges(file) {
  return {
    size: fs.statSync(file).size,
    read: async (offset, length) => {
      const handle = await fs.promises.open(file, 'r');
      try {
        const bytes = new Uint8Array(length);
        const { bytesRead } = await handle.read(bytes, 0, length, offset);
        if (bytesRead !== length) throw new Error(`${file}: ended after ${offset + bytesRead} bytes`);
        return bytes;
      } finally {
        await handle.close();
      }
    },
  };
}

/** A package folder on disk (`dir` holds manifest.json). */
async function openFolder(dir) {
  const manifestBytes = new Uint8Array(await fs.promises.readFile(path.join(dir, 'manifest.json')));
  // The reader has checked every path it hands out (no "..", not absolute).
  return { kind: 'folder', manifestBytes, read: async (p) => new Uint8Array(await fs.promises.readFile(path.join(dir, p))) };
}

/** The source of a package folder, its manifest.json or a .c3d file on disk (a path or file: URL). */
async function openPath(format, input) {
  const file = String(input).startsWith('file:') ? fileURLToPath(String(input)) : String(input);
  const stat = await fs.promises.stat(file).catch(() => {
    throw new Error(`${file}: no such file or folder`);
  });
  if (stat.isDirectory()) return openFolder(file);
  if (path.basename(file) === 'manifest.json') return openFolder(path.dirname(file));
  const ranges = fileRanges(file);
  const head = await ranges.read(0, Math.min(ranges.size, 8));
  if (!isSingleFile(head)) throw new Error(`${file}: neither a package folder, its manifest.json nor a .c3d file`);
  return openSingleFile(format, ranges, path.basename(file));
}

/**
 * Opens a package: a path (or file: URL) of a package folder, its
 * manifest.json or a .c3d file; an http(s) URL as in browsers (.c3d files in
 * range requests); a Blob; or the bytes of a .c3d. Options: `format` (default:
 * createFormat()), `fetch` (for URLs; default: the global fetch).
 */
export async function openPackage(input, { format, fetch: fetchFn = globalThis.fetch } = {}) {
  format ??= await createFormat();
  const source = (await openInMemory(format, input)) ??
    (/^https?:/i.test(String(input)) ? await openUrl(format, String(input), { fetch: fetchFn }) : await openPath(format, input));
  return new Casual3dPackage(format, source, decodeTile);
}
