// casual3d-viewer/format: reads casual3d packages (a folder's manifest.json or
// a .c3d single file) without the viewer element, through the format library
// compiled to WebAssembly: the manifest, each level's two layers as typed
// arrays, its mesh and colour atlas. This module is the browser's (and
// worker's) entry; format-node.js is Node's, with the same API.
//
//   import { openPackage } from 'casual3d-viewer/format';
//   const pkg = await openPackage('photo.c3d');        // URL, Blob or bytes
//   const pano = await pkg.readLevel(pkg.numLevels - 1);  // the coarsest
//   const front = pano.layer(0);                       // {present, rgb, depth, ...}
//   const mesh = pano.mesh();                          // {positions, indices, ...}
//   pano.free();
//   pkg.close();

import { FormatModule } from './format-module.js';
import { assetUrl } from './assets.js';
import { forEachLimited, openInMemory, openUrl } from './package-source.js';
import { decodeImage } from './tile-decoder.js';

export { FormatModule, Panorama, PackageReader } from './format-module.js';
export { setAssetBase } from './assets.js';

const CONCURRENCY = 6;

/**
 * A package open for reading: its manifest, levels and files. Levels are read
 * one at a time (concurrent readLevel calls wait for each other).
 */
export class Casual3dPackage {
  /**
   * @param format a FormatModule
   * @param source {kind, manifestBytes, read(path)} (package-source.js)
   * @param decode (bytes, name, type) => Promise<{width, height, data}> RGBA pixels of a tile
   *   image of MIME type `type` (the reader's tileImageType)
   */
  constructor(format, source, decode) {
    this.format = format;
    this.source = source;
    this.decode = decode;
    this.reader = format.openPackage(source.manifestBytes);
    /** manifest.json as parsed JSON (the reader has checked it). */
    this.manifest = JSON.parse(new TextDecoder().decode(source.manifestBytes));
    this._queue = Promise.resolve();
  }

  /** 'folder' or 'single-file'. */
  get kind() {
    return this.source.kind;
  }

  /** Number of levels; level 0 is the finest, numLevels - 1 the coarsest. */
  get numLevels() {
    return this.reader.numLevels;
  }

  /** Largest depth the package encodes (manifest depth_encoding.far_m), metres. */
  get depthFarM() {
    return this.reader.depthFarM;
  }

  /** MIME type of the tile images ('image/webp' in packages 1.x and 2.x). */
  get tileImageType() {
    return this.reader.tileImageType;
  }

  /** {width, height, tiles: [{x, y, w, h, files: [{kind, path, bytes, sha256, width, height}]}]} */
  levelInfo(level) {
    return this.reader.level(level);
  }

  /**
   * Reads, checks (size and SHA-256 of every file), decodes and validates a
   * level; resolves to its Panorama (free() it when done). Options: `tiles`,
   * the order of the tile indices to read (default: in order); `onFile(bytes,
   * path)`, called after each file is checked (throwing from it stops the
   * read); `concurrency`, files in flight (default 6).
   */
  readLevel(level, { tiles, onFile, concurrency = CONCURRENCY } = {}) {
    const run = this._queue.then(() => this._readLevel(level, tiles, onFile, concurrency));
    this._queue = run.catch(() => {});
    return run;
  }

  async _readLevel(level, tiles, onFile, concurrency) {
    if (!this.reader) throw new Error('the package is closed');
    const info = this.reader.level(level);
    const type = this.reader.tileImageType;
    const jobs = [];
    for (const t of tiles ?? info.tiles.map((_, i) => i)) {
      info.tiles[t].files.forEach((file, kind) => jobs.push({ t, kind, file }));
    }
    await forEachLimited(jobs, concurrency, async ({ t, kind, file }) => {
      const bytes = await this.source.read(file.path);
      this.reader.checkFile(file.path, bytes);
      onFile?.(bytes, file.path);
      const image = await this.decode(bytes, file.path, type);
      if (image.width !== file.width || image.height !== file.height) {
        throw new Error(`${file.path}: ${file.kind} image is ${image.width}x${image.height}, expected ${file.width}x${file.height}`);
      }
      this.reader.addImage(level, t, kind, image.data, image.width, image.height, 4);
    });
    return this.reader.assemble(level);
  }

  /** Frees the reader (the Panoramas read stay valid until freed). */
  close() {
    this.reader?.free();
    this.reader = null;
  }
}

let sharedFormat = null;

/**
 * The format library for the browser entry, created once: `threads` as
 * FormatModule.create (default 'auto': threads on cross-origin isolated pages).
 */
export function createFormat({ threads = 'auto' } = {}) {
  if (threads !== 'auto') return FormatModule.create({ threads, baseUrl: assetUrl('') });
  sharedFormat ??= FormatModule.create({ baseUrl: assetUrl('') }).catch((err) => {
    sharedFormat = null;
    throw err;
  });
  return sharedFormat;
}

/**
 * Opens a package: a URL (string or URL, relative to the document) of a
 * folder's manifest.json or of a .c3d file (read with HTTP range requests),
 * a Blob or File holding a .c3d, or a .c3d's bytes (Uint8Array or
 * ArrayBuffer). Options: `format` (a FormatModule; default: createFormat()),
 * `fetch` (default: the global fetch).
 */
export async function openPackage(input, { format, fetch: fetchFn = globalThis.fetch } = {}) {
  format ??= await createFormat();
  let source = await openInMemory(format, input);
  if (!source) {
    const base = typeof document !== 'undefined' ? document.baseURI : globalThis.location?.href;
    source = await openUrl(format, new URL(String(input), base).href, { fetch: fetchFn });
  }
  return new Casual3dPackage(format, source, decodeImage);
}
