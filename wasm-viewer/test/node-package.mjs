// Reads a casual3d package in Node the way the browser worker does, with the
// wasm format library (package reader, mesh builder) and a wasm libwebp
// decoder from npm (@jsquash/webp) standing in for the browser's decoder.

import fs from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';

let webpDecode = null;

/** Loads the wasm WebP decoder once; returns decode(bytes) -> {width, height, data RGBA}. */
export async function loadWebpDecoder() {
  if (webpDecode) return webpDecode;
  globalThis.ImageData ??= class ImageData {
    constructor(data, width, height) {
      this.data = data;
      this.width = width;
      this.height = height;
    }
  };
  const require = createRequire(import.meta.url);
  const dir = path.dirname(require.resolve('@jsquash/webp/package.json'));
  const { default: decode, init } = await import(path.join(dir, 'decode.js'));
  await init(await WebAssembly.compile(fs.readFileSync(path.join(dir, 'codec', 'dec', 'webp_dec.wasm'))));
  webpDecode = async (bytes) => decode(bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength));
  return webpDecode;
}

/** The decoder of tile images of MIME type `type` (the reader's tileImageType). */
async function loadTileDecoder(type) {
  if (type !== 'image/webp') throw new Error(`no Node decoder for ${type} tile images`);
  return loadWebpDecoder();
}

/**
 * Reads `level` of the package in folder `dir` into a wasm Panorama (caller
 * frees). Returns {pano, timing, cpu}: wall and CPU (this process's user +
 * system) milliseconds per step, {readMs, checkMs, decodeMs, addMs, finishMs}:
 * file reads, SHA-256 checks, tile image decoding, tile unpacking, assembly
 * (not counting the manifest and the decoder's loading).
 */
export async function readPackageLevel(format, dir, level) {
  const reader = format.openPackage(fs.readFileSync(path.join(dir, 'manifest.json')));
  try {
    const decode = await loadTileDecoder(reader.tileImageType);
    return await readLevel(reader, decode, dir, level);
  } finally {
    reader.free();
  }
}

async function readLevel(reader, decode, dir, level) {
  const timing = { readMs: 0, checkMs: 0, decodeMs: 0, addMs: 0, finishMs: 0 };
  const cpu = { ...timing };
  const cpuNow = () => {
    const u = process.cpuUsage();
    return (u.user + u.system) / 1000;
  };
  let t = performance.now();
  let c = cpuNow();
  const lap = (key) => {
    const now = performance.now();
    const cNow = cpuNow();
    timing[key] += now - t;
    cpu[key] += cNow - c;
    t = now;
    c = cNow;
  };
  const info = reader.level(level);
  lap('readMs');
  for (let tile = 0; tile < info.tiles.length; ++tile) {
    for (const [kind, file] of info.tiles[tile].files.entries()) {
      const bytes = fs.readFileSync(path.join(dir, file.path));
      lap('readMs');
      reader.checkFile(file.path, bytes);
      lap('checkMs');
      const image = await decode(bytes);
      lap('decodeMs');
      reader.addImage(level, tile, kind, image.data, image.width, image.height, 4);
      lap('addMs');
    }
  }
  const pano = reader.assemble(level);
  lap('finishMs');
  return { pano, timing, cpu };
}
