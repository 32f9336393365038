// The viewer's decoding worker: fetches a package (a folder's manifest.json or
// a .c3d file, read in HTTP ranges; package-source.js) level by level (coarsest
// first), checks every file against the manifest's size and SHA-256, decodes
// tile images with the browser's decoder, assembles and validates each level's
// two-layer panorama and builds its mesh with the wasm format library, then
// hands the mesh and colour atlas to the main thread (transferred, not copied).
//
// Within a level, the tiles nearest the current view direction are fetched
// first (the page reports the view with 'view' messages).
//
// With the first (coarsest) level shown it sends the view hints
// (view-hints.js): the manifest's "view" member if valid, else hints derived
// from that level, with the content narrowed to where that level has nodes;
// and the soft background image (environment.js) built from that level.
//
// Finer levels are fetched once the page has drawn the first one (it says so
// with 'shown'), so that nothing competes with the first frame.
//
// Messages in:  {type: 'load', id, url, yawDeg, maxLevelWidth, maxTriangles, backdrop}
//               {type: 'view', yawDeg}
//               {type: 'shown', id}   (the first level of load `id` is on screen)
// Messages out: {type: 'progress', id, progress: {loadedBytes, totalBytes, level, levels}}
//               {type: 'level', id, level, levels, width, height, mesh, atlas, timing,
//                view?: {hints, warning, environment}}   (first level only)
//               {type: 'error', id, message}
//               {type: 'done', id, levels, bytes}

import { FormatModule } from './format-module.js';
import { Casual3dPackage } from './format.js';
import { openUrl } from './package-source.js';
import { backdropCell, simplifyMaxError } from './mesh-error.js';
import { decodeImage } from './tile-decoder.js';
import { buildEnvironment } from './environment.js';
import { deriveViewHints, narrowContent, parseViewHints, presenceFromMesh } from './view-hints.js';

const FETCH_CONCURRENCY = 6;
let formatPromise = null;
let currentId = 0;
let viewYawDeg = 0;
let shownId = -1;
let shownWaiter = null;

/** Resolves once load `id`'s first level is on screen, or a newer load began. */
function firstLevelShown(id) {
  if (shownId === id) return Promise.resolve();
  return new Promise((resolve) => { shownWaiter = resolve; });
}

function wakeShownWaiter() {
  shownWaiter?.();
  shownWaiter = null;
}

class Superseded extends Error {}

self.onmessage = (e) => {
  const msg = e.data;
  if (msg.type === 'view') {
    viewYawDeg = msg.yawDeg;
    return;
  }
  if (msg.type === 'shown') {
    if (msg.id === currentId) {
      shownId = msg.id;
      wakeShownWaiter();
    }
    return;
  }
  if (msg.type !== 'load') return;
  currentId = msg.id;
  wakeShownWaiter();  // The previous load, waiting, sees that it is superseded.
  viewYawDeg = msg.yawDeg ?? 0;
  load(msg).catch((err) => {
    if (err instanceof Superseded) return;
    self.postMessage({ type: 'error', id: msg.id, message: err.message || String(err) });
  });
};

async function load({ id, url, maxLevelWidth, maxTriangles, backdrop: withBackdrop = true }) {
  const check = () => {
    if (id !== currentId) throw new Superseded();
  };
  if (!formatPromise) {
    formatPromise = FormatModule.create().catch((err) => {
      formatPromise = null;
      throw new Error(`the viewer's WebAssembly module failed to load: ${err.message || err}`);
    });
  }
  const format = await formatPromise;
  check();
  const source = await openUrl(format, url);
  check();
  const { manifestBytes } = source;
  const pkg = new Casual3dPackage(format, source, decodeImage);
  const reader = pkg.reader;
  // The reader accepted the bytes, so they are JSON; the optional "view"
  // member is checked here (a bad one is ignored with a warning).
  let packageView;
  try {
    packageView = parseViewHints(pkg.manifest.view);
  } catch (err) {
    packageView = { hints: null, warning: `manifest.json: "view" ignored: ${err.message || err}` };
  }
  // The farthest depth of the panorama (the package's depth code range), so
  // that the camera's far plane never clips the scene: a model in COLMAP
  // units can lie thousands of units away.
  const depthFarM = reader.depthFarM;
  // The reader accepted depth_encoding, so it is in range.
  const simplifyError = simplifyMaxError(pkg.manifest.depth_encoding);
  try {
    const numLevels = reader.numLevels;
    // Coarsest first; finer levels while they fit maxLevelWidth.
    const chosen = [];
    for (let l = numLevels - 1; l >= 0; --l) {
      const info = reader.level(l);
      if (chosen.length > 0 && info.width > maxLevelWidth) break;
      chosen.push({ level: l, info });
    }
    const totalBytes = manifestBytes.length +
      chosen.reduce((s, c) => s + c.info.tiles.reduce((t, tile) => t + tile.files.reduce((u, f) => u + f.bytes, 0), 0), 0);
    let loadedBytes = manifestBytes.length;
    let shown = 0;
    let lastProgress = 0;
    const progress = (level, force) => {
      const now = performance.now();
      if (!force && now - lastProgress < 50) return;
      lastProgress = now;
      self.postMessage({ type: 'progress', id, progress: { loadedBytes, totalBytes, level, levels: numLevels } });
    };
    progress(chosen[0].level, true);

    for (const { level, info } of chosen) {
      if (shown === 1) {
        await firstLevelShown(id);
        check();
      }
      const timing = { level, fetchDecodeMs: 0, meshMs: 0, threads: format.numThreads };
      const t0 = performance.now();
      try {
        // Tiles in view first: order by the longitude distance of the tile's
        // centre column from the view direction (format/equirect.h).
        const away = (tile) => {
          const lonDeg = ((tile.x + tile.w / 2) / info.width - 0.5) * 360;
          const d = Math.abs(lonDeg - viewYawDeg) % 360;
          return Math.min(d, 360 - d);
        };
        const order = info.tiles.map((tile, t) => t).sort((a, b) => away(info.tiles[a]) - away(info.tiles[b]) || a - b);
        // Fetch and check in parallel; decode in order of arrival. The reader
        // accepts images in any order.
        const pano = await pkg.readLevel(level, {
          tiles: order,
          concurrency: FETCH_CONCURRENCY,
          onFile: (bytes) => {
            check();
            loadedBytes += bytes.length;
            progress(level, false);
          },
        });
        timing.fetchDecodeMs = performance.now() - t0;
        const t1 = performance.now();
        let mesh, backdrop, atlas;
        try {
          // The full mesh has about 2 triangles per node; simplify above the budget.
          const fullEstimate = 2 * info.width * info.height;
          mesh = format.buildMesh(pano, fullEstimate > maxTriangles
            ? { maxTriangles, maxRelativeError: simplifyError }
            : { maxTriangles: 0 });
          if (withBackdrop) backdrop = format.buildBackdrop(pano, { cellPx: backdropCell(info.width, info.height, maxTriangles) });
          atlas = pano.atlas();
        } finally {
          pano.free();
        }
        timing.meshMs = performance.now() - t1;
        check();
        const view = shown === 0 ? viewOfLevel(packageView, mesh, atlas, info.width, info.height) : undefined;
        if (backdrop) mesh = appendMesh(mesh, backdrop);
        progress(level, true);
        const transfer = [mesh.positions.buffer, mesh.normals.buffer, mesh.uvs.buffer, mesh.indices.buffer, atlas.data.buffer];
        if (mesh.colors && backdrop) transfer.push(mesh.colors.buffer);
        if (view) transfer.push(view.environment.data.buffer);
        self.postMessage(
          {
            type: 'level', id, level, levels: numLevels, width: info.width, height: info.height, depthFarM,
            mesh: {
              positions: mesh.positions, normals: mesh.normals, uvs: mesh.uvs, indices: mesh.indices,
              colors: backdrop ? mesh.colors : undefined,
            },
            atlas, timing, view,
          },
          transfer,
        );
        ++shown;
      } catch (err) {
        if (err instanceof Superseded) throw err;
        // Keep what is on screen; report and stop refining (finer levels would
        // be refused by the same damage or cost more to fetch).
        self.postMessage({ type: 'error', id, message: err.message || String(err) });
        break;
      }
    }
    if (shown > 0) self.postMessage({ type: 'done', id, levels: shown, bytes: loadedBytes });
  } finally {
    pkg.close();
  }
}

/**
 * The arrays of mesh `a` followed by those of backdrop `b` (b's indices
 * offset), with per-vertex RGBA colours: alpha 255 marks the backdrop's
 * vertices, drawn in their own colour; 0 the mesh's, textured from the atlas.
 */
function appendMesh(a, b) {
  const cat = (Type, x, y) => {
    const out = new Type(x.length + y.length);
    out.set(x);
    out.set(y, x.length);
    return out;
  };
  const indices = cat(Uint32Array, a.indices, b.indices);
  const offset = a.positions.length / 3;
  for (let i = a.indices.length; i < indices.length; ++i) indices[i] += offset;
  const nb = b.positions.length / 3;
  const colors = new Uint8Array(4 * (offset + nb));
  for (let v = 0; v < nb; ++v) {
    const o = 4 * (offset + v);
    colors[o] = b.colors[3 * v];
    colors[o + 1] = b.colors[3 * v + 1];
    colors[o + 2] = b.colors[3 * v + 2];
    colors[o + 3] = 255;
  }
  return {
    positions: cat(Float32Array, a.positions, b.positions),
    normals: cat(Float32Array, a.normals, b.normals),
    uvs: cat(Float32Array, a.uvs, b.uvs),
    colors,
    indices,
  };
}

/**
 * The view hints and soft background of the first level shown: the package's
 * hints (narrowed to the level's content) or, without valid ones, hints
 * derived from the level (view-hints.js).
 */
function viewOfLevel(packageView, mesh, atlas, width, height) {
  const { presence, depths } = presenceFromMesh(mesh, width, height);
  const measured = deriveViewHints({ presence, depths, width, height });
  const hints = packageView.hints ? narrowContent(packageView.hints, measured) : measured;
  return { hints, warning: packageView.warning, environment: buildEnvironment(atlas, presence) };
}
