// JavaScript face of the format library compiled to WebAssembly
// (casual3d-format.wasm, src/binding.cc). Works in browsers, workers and Node.
// Two builds of it exist: casual3d-format-mt.{js,wasm} shares the per-pixel
// loops among threads (WebAssembly threads on shared memory, which browsers
// allow only on cross-origin isolated pages, served with the headers
// Cross-Origin-Opener-Policy: same-origin and Cross-Origin-Embedder-Policy:
// require-corp), casual3d-format.{js,wasm} runs on one thread anywhere. Both
// give the same results.
//
//   const format = await FormatModule.create();            // browser / worker
//   const format = await FormatModule.create({ threads, wasmBinary }); // Node: the bytes of that build
//   const pano = format.parsePanoramaBlob(bytes);
//   const mesh = format.buildMesh(pano, { maxTriangles: 0 });  // copies out
//   pano.free();
//
// Every failure throws an Error with the library's message.

/**
 * A module whose one function uses a SIMD instruction (i8x16.popcnt): it
 * validates exactly where WebAssembly SIMD, which the format module is built
 * with, is available.
 */
const SIMD_PROBE = new Uint8Array([
  0, 97, 115, 109, 1, 0, 0, 0, 1, 5, 1, 96, 0, 1, 123, 3, 2, 1, 0, 10, 10, 1, 8, 0, 65, 0, 253, 15,
  253, 98, 11,
]);

/**
 * The heap's current bytes. The threaded build's memory is shared and may grow
 * on another thread, which leaves the module's HEAPU8 view stale; its
 * wasmMemory always has the current buffer.
 */
function heapU8(module) {
  return module.wasmMemory ? new Uint8Array(module.wasmMemory.buffer) : module.HEAPU8;
}

/** Copies `count` elements of a typed-array type out of the wasm heap. */
function copyOut(module, Type, ptr, count) {
  if (count === 0) return new Type(0);
  const view = new Type(heapU8(module).buffer, ptr, count);
  return view.slice();
}

/** Whether this context may use the threaded build (shared memory is available). */
export function threadsAvailable() {
  if (typeof SharedArrayBuffer !== 'function') return false;
  // Browsers define crossOriginIsolated; Node does not and always shares memory.
  return typeof crossOriginIsolated === 'undefined' || crossOriginIsolated === true;
}

export class FormatModule {
  constructor(module) {
    this.m = module;
    // A heap buffer reused for the bytes and pixels handed in (tile after tile
    // of the same size), instead of an allocation per call.
    this._scratchPtr = 0;
    this._scratchSize = 0;
  }

  /**
   * Instantiates the wasm module. `threads`: true for the threaded build,
   * false for the single-threaded one, 'auto' (the default) for the threaded
   * one where threadsAvailable(), falling back to the single-threaded one if
   * the threaded one fails to start. `baseUrl`: the folder holding
   * casual3d-format*.{js,wasm} (default: this module's folder). Other options
   * go to the Emscripten factory (a `wasmBinary` must be the bytes of the
   * build that is chosen).
   */
  static async create({ threads = 'auto', baseUrl = import.meta.url, ...options } = {}) {
    if (!WebAssembly.validate(SIMD_PROBE)) {
      throw new Error('this browser lacks WebAssembly SIMD, which the viewer needs ' +
                      '(Chrome or Edge 91, Firefox 89, Safari 16.4 or later)');
    }
    const useThreads = threads === 'auto' ? threadsAvailable() : threads === true;
    let module;
    if (useThreads) {
      try {
        const { default: factory } = await import(/* @vite-ignore */ new URL('casual3d-format-mt.js', baseUrl).href);
        // A copy: the factory writes its module into the object it is given,
        // which the fallback below must not inherit.
        module = await factory({ ...options });
      } catch (err) {
        // Shared memory reserves its 4 GB maximum up front, which a device
        // short of address space may refuse: fall back to one thread.
        if (threads !== 'auto') throw err;
      }
    }
    if (!module) {
      const { default: factory } = await import(/* @vite-ignore */ new URL('casual3d-format.js', baseUrl).href);
      module = await factory(options);
    }
    // Under Node the threaded build's workers would keep the process alive
    // after its last task; browsers' Workers have no unref.
    const pthreads = module.PThread;
    if (pthreads) {
      for (const w of [...(pthreads.unusedWorkers ?? []), ...(pthreads.runningWorkers ?? [])]) w.unref?.();
    }
    return new FormatModule(module);
  }

  /** Threads the library's loops use: 1 for the single-threaded build. */
  get numThreads() {
    return this.m._c3d_num_threads();
  }

  /** The library's last error; `what` prefixes messages that do not name their input. */
  _error(what) {
    const message = this.m.UTF8ToString(this.m._c3d_last_error());
    return new Error(what ? `${what}: ${message}` : message);
  }

  /** Copies bytes into a fresh heap allocation; the caller frees the pointer. */
  _copyIn(bytes) {
    const ptr = this.m._malloc(Math.max(1, bytes.length));
    if (!ptr) throw new Error(`out of memory for ${bytes.length} bytes`);
    heapU8(this.m).set(bytes, ptr);
    return ptr;
  }

  /**
   * Copies bytes into the scratch buffer and returns its pointer, valid until
   * the next call (for library calls that do not keep the pointer).
   */
  _copyToScratch(bytes) {
    if (bytes.length > this._scratchSize) {
      if (this._scratchPtr) this.m._free(this._scratchPtr);
      this._scratchPtr = 0;
      this._scratchSize = 0;
      const size = Math.max(bytes.length, 1 << 20);
      const ptr = this.m._malloc(size);
      if (!ptr) throw new Error(`out of memory for ${bytes.length} bytes`);
      this._scratchPtr = ptr;
      this._scratchSize = size;
    }
    heapU8(this.m).set(bytes, this._scratchPtr);
    return this._scratchPtr;
  }

  _string(s) {
    const n = this.m.lengthBytesUTF8(s) + 1;
    const ptr = this.m._malloc(n);
    this.m.stringToUTF8(s, ptr, n);
    return ptr;
  }

  /** A Panorama from a panorama blob (src/panorama_blob.h). */
  parsePanoramaBlob(bytes) {
    const ptr = this._copyIn(bytes);
    try {
      const p = this.m._c3d_panorama_parse_blob(ptr, bytes.length);
      if (!p) throw this._error('panorama blob');
      return new Panorama(this, p);
    } finally {
      this.m._free(ptr);
    }
  }

  /**
   * Builds the mesh of a panorama. maxTriangles 0: the full mesh of spec/mesh.md
   * (or, with maxRelativeError > 0, simplified as far as that relative depth
   * error allows); > 0: simplified to that budget with the largest relative
   * depth error maxRelativeError (0: the library's default). Returns plain typed arrays:
   * {positions, normals, uvs, colors, indices, maxRelativeError}.
   */
  buildMesh(pano, { maxTriangles = 0, maxRelativeError = 0 } = {}) {
    const handle = this.m._c3d_build_mesh(pano.ptr, maxTriangles, maxRelativeError);
    if (!handle) throw this._error('mesh');
    return this._takeMesh(handle);
  }

  /**
   * Builds the backdrop of a panorama (format/backdrop.h): a coarse hole-free
   * surface behind every node, drawn with the mesh so that its tears show the
   * background instead of nothing. cellPx: cell side in pixels, 0 for the
   * library's default. Returns the arrays of buildMesh (maxRelativeError 0).
   */
  buildBackdrop(pano, { cellPx = 0 } = {}) {
    const handle = this.m._c3d_build_backdrop(pano.ptr, cellPx);
    if (!handle) throw this._error('backdrop');
    return this._takeMesh(handle);
  }

  /** Copies a native mesh's arrays out and frees it. */
  _takeMesh(handle) {
    const m = this.m;
    try {
      const nv = m._c3d_mesh_num_vertices(handle);
      const ni = m._c3d_mesh_num_indices(handle);
      return {
        positions: copyOut(m, Float32Array, m._c3d_mesh_positions(handle), nv * 3),
        normals: copyOut(m, Float32Array, m._c3d_mesh_normals(handle), nv * 3),
        uvs: copyOut(m, Float32Array, m._c3d_mesh_uvs(handle), nv * 2),
        colors: copyOut(m, Uint8Array, m._c3d_mesh_colors(handle), nv * 3),
        indices: copyOut(m, Uint32Array, m._c3d_mesh_indices(handle), ni),
        maxRelativeError: m._c3d_mesh_max_error(handle),
      };
    } finally {
      m._c3d_mesh_free(handle);
    }
  }

  /**
   * The directory of a single-file container (.c3d, spec/package.md Sec. 8) of
   * `totalSize` bytes from its first bytes `prefix`: {entries: [{path, offset,
   * size}]} once the prefix holds the whole directory, else {needed}: how many
   * bytes from the start to supply next. Throws on an invalid container.
   */
  singleFileDirectory(prefix, totalSize) {
    const m = this.m;
    const out = m._malloc(8);
    try {
      const p = m._c3d_single_file_directory(this._copyToScratch(prefix), prefix.length, totalSize, out);
      const needed = new Float64Array(heapU8(m).buffer, out, 1)[0];
      if (p) return { entries: JSON.parse(m.UTF8ToString(p)) };
      if (needed > 0) return { needed };
      throw this._error();
    } finally {
      m._free(out);
    }
  }

  /** Opens a package from the bytes of its manifest.json. */
  openPackage(manifestBytes) {
    const ptr = this._copyIn(manifestBytes);
    try {
      const r = this.m._c3d_reader_open(ptr, manifestBytes.length);
      if (!r) throw this._error();
      return new PackageReader(this, r);
    } finally {
      this.m._free(ptr);
    }
  }
}

/** A two-layer panorama living in the wasm heap. Call free() when done. */
export class Panorama {
  constructor(format, ptr) {
    this.format = format;
    this.ptr = ptr;
  }

  get width() {
    return this.format.m._c3d_panorama_width(this.ptr);
  }

  get height() {
    return this.format.m._c3d_panorama_height(this.ptr);
  }

  /** Throws if TwoLayerPanorama::Validate() fails. */
  validate() {
    if (!this.format.m._c3d_panorama_validate(this.ptr)) throw this.format._error('panorama');
  }

  /**
   * The colour atlas of format/color_atlas.h (front colours above back colours, each half
   * filled from the other layer where its node is absent; the mesh's uvs rely on that):
   * {width, height: 2 * panorama height, data: RGBA Uint8Array}.
   */
  atlas() {
    const m = this.format.m;
    const w = this.width, h = this.height;
    const ptr = m._c3d_panorama_atlas_rgba(this.ptr);
    return { width: w, height: 2 * h, data: copyOut(m, Uint8Array, ptr, w * h * 2 * 4) };
  }

  /**
   * The nodes of layer 0 (front) or 1 (back), copied out: {present, rgb,
   * depth (metres), normal, label, links}, row-major, width * height elements
   * (times 3 for rgb and normal), absent nodes zero (spec/data-model.md).
   */
  layer(layer) {
    const m = this.format.m;
    const n = this.width * this.height;
    const field = (index, Type, count) => copyOut(m, Type, m._c3d_panorama_layer(this.ptr, layer, index), count);
    if (layer !== 0 && layer !== 1) throw new Error(`layer ${layer}: 0 (front) or 1 (back)`);
    return {
      present: field(0, Uint8Array, n), rgb: field(1, Uint8Array, 3 * n), depth: field(2, Float32Array, n),
      normal: field(3, Float32Array, 3 * n), label: field(4, Uint8Array, n), links: field(5, Uint8Array, n),
    };
  }

  /** FormatModule.buildMesh of this panorama. */
  mesh(options) {
    return this.format.buildMesh(this, options);
  }

  free() {
    if (this.ptr) this.format.m._c3d_panorama_free(this.ptr);
    this.ptr = 0;
  }
}

/** A package being read level by level (format/manifest.h, format/tile_codec.h). */
export class PackageReader {
  constructor(format, ptr) {
    this.format = format;
    this.ptr = ptr;
  }

  /** Number of levels; level 0 is the finest, the last the coarsest. */
  get numLevels() {
    return this.format.m._c3d_reader_num_levels(this.ptr);
  }

  /** Largest depth the package encodes (manifest depth_encoding.far_m), metres. */
  get depthFarM() {
    return this.format.m._c3d_reader_depth_far_m(this.ptr);
  }

  /** MIME type of the tile images ('image/webp' in packages 1.x and 2.x). */
  get tileImageType() {
    return this.format.m.UTF8ToString(this.format.m._c3d_reader_tile_image_type(this.ptr));
  }

  /** {width, height, tiles: [{x, y, w, h, files: [{kind, path, bytes, sha256, width, height}]}]} */
  level(level) {
    const p = this.format.m._c3d_reader_level_json(this.ptr, level);
    if (!p) throw this.format._error();
    return JSON.parse(this.format.m.UTF8ToString(p));
  }

  /** Throws unless `bytes` match the manifest's size and SHA-256 for `path`. */
  checkFile(path, bytes) {
    const f = this.format;
    const sp = f._string(path);
    try {
      const bp = f._copyToScratch(bytes);
      if (!f.m._c3d_reader_check_file(this.ptr, sp, bp, bytes.length)) throw f._error();
    } finally {
      f.m._free(sp);
    }
  }

  /** Adds the decoded pixels (RGB or RGBA rows) of image `kind` (0..3) of a tile. */
  addImage(level, tile, kind, pixels, width, height, channels) {
    const f = this.format;
    if (pixels.length !== width * height * channels) {
      throw new Error(`addImage: ${pixels.length} bytes for ${width}x${height} pixels of ${channels} channels`);
    }
    const ptr = f._copyToScratch(pixels);
    if (!f.m._c3d_reader_add_image(this.ptr, level, tile, kind, ptr, width, height, channels)) {
      throw f._error();
    }
  }

  /** Finishes and validates the level; returns its Panorama (caller frees). */
  assemble(level) {
    const p = this.format.m._c3d_reader_assemble(this.ptr, level);
    if (!p) throw this.format._error();
    return new Panorama(this.format, p);
  }

  free() {
    if (this.ptr) this.format.m._c3d_reader_free(this.ptr);
    this.ptr = 0;
  }
}
