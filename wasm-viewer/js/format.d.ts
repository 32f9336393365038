// Type declarations of casual3d-viewer/format (format.js in browsers and
// workers, format-node.js in Node; the same API). Hand-written; keep in step
// with the JavaScript.

/** The nodes of one layer, row-major, width * height (x3 for rgb and normal); absent nodes are zero. */
export interface Layer {
  /** 1 where the layer has a node. */
  present: Uint8Array;
  /** sRGB colour, 3 bytes per node. */
  rgb: Uint8Array;
  /** Distance from the panorama centre along the ray, metres (the package's unit). */
  depth: Float32Array;
  /** Unit normal in the panorama frame, 3 floats per node, or 0, 0, 0 (unlit). */
  normal: Float32Array;
  /** 0: foreground (F), 1: background (B). */
  label: Uint8Array;
  /** Links to the 4 neighbours, 2 bits each (spec/data-model.md). */
  links: Uint8Array;
}

export interface Mesh {
  positions: Float32Array;
  normals: Float32Array;
  uvs: Float32Array;
  colors: Uint8Array;
  indices: Uint32Array;
  /** The simplifier's bound on the relative depth error (0 for the full mesh). */
  maxRelativeError: number;
}

export interface MeshOptions {
  /** 0 (default): the full mesh of spec/mesh.md; > 0: simplified to this many triangles. */
  maxTriangles?: number;
  /**
   * Largest relative depth error of the simplified mesh (0: the library's
   * default); > 0 with maxTriangles 0: simplified as far as it allows.
   */
  maxRelativeError?: number;
}

/** A two-layer panorama in the wasm heap; free() it when done. */
export class Panorama {
  readonly width: number;
  readonly height: number;
  /** Throws unless the panorama is valid (readLevel already validated it). */
  validate(): void;
  /** Layer 0 (front) or 1 (back), copied out of the wasm heap. */
  layer(layer: 0 | 1): Layer;
  mesh(options?: MeshOptions): Mesh;
  /** The colour atlas the mesh's uvs address: front colours above back colours, RGBA. */
  atlas(): { width: number; height: number; data: Uint8Array };
  free(): void;
}

export interface TileFile {
  kind: 'color' | 'depth' | 'normal' | 'graph';
  path: string;
  bytes: number;
  sha256: string;
  width: number;
  height: number;
}

export interface LevelInfo {
  width: number;
  height: number;
  tiles: { x: number; y: number; w: number; h: number; files: TileFile[] }[];
}

/** The format library compiled to WebAssembly. */
export class FormatModule {
  static create(options?: { threads?: boolean | 'auto'; baseUrl?: string | URL; wasmBinary?: ArrayBuffer | Uint8Array }): Promise<FormatModule>;
  /** Threads the library's loops use (1: the single-threaded build). */
  readonly numThreads: number;
  buildMesh(pano: Panorama, options?: MeshOptions): Mesh;
  /** The backdrop drawn behind the mesh (format/backdrop.h); cellPx 0: the default cell. */
  buildBackdrop(pano: Panorama, options?: { cellPx?: number }): Mesh;
}

export class Casual3dPackage {
  readonly kind: 'folder' | 'single-file';
  /** manifest.json, parsed (checked by the reader). */
  readonly manifest: { format: string; version: string; levels: unknown[]; view?: Record<string, unknown>; [member: string]: unknown };
  /** Level 0 is the finest, numLevels - 1 the coarsest. */
  readonly numLevels: number;
  /** The largest depth the package encodes, metres. */
  readonly depthFarM: number;
  /** MIME type of the tile images ('image/webp' in packages 1.x and 2.x). */
  readonly tileImageType: string;
  levelInfo(level: number): LevelInfo;
  /** Reads, checks (size, SHA-256), decodes and validates a level. */
  readLevel(level: number, options?: {
    tiles?: number[];
    onFile?: (bytes: Uint8Array, path: string) => void;
    concurrency?: number;
  }): Promise<Panorama>;
  close(): void;
}

export interface OpenOptions {
  /** The format library to use (default: one created on first use). */
  format?: FormatModule;
  /** For URLs (default: the global fetch). */
  fetch?: typeof fetch;
}

/**
 * Opens a package: a URL of a folder's manifest.json or of a .c3d file (read
 * with HTTP range requests, the whole file where a server ignores them), a
 * Blob or File, or the bytes of a .c3d; in Node also a path of a package
 * folder, its manifest.json or a .c3d file.
 */
export function openPackage(input: string | URL | Blob | ArrayBuffer | ArrayBufferView, options?: OpenOptions): Promise<Casual3dPackage>;

/** The format library, created once per options (browser default: threads on cross-origin isolated pages). */
export function createFormat(options?: { threads?: boolean | 'auto' }): Promise<FormatModule>;

/** Browsers: the folder the wasm files are served from, for pages that bundle this module. */
export function setAssetBase(url: string | URL | null): void;
