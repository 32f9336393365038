// The page's script, bundled by esbuild (build.mjs) with the viewer from npm.
// One import registers <casual3d-viewer>; the worker and the wasm files are
// served from casual3d/ next to the bundle (build.mjs copies them there).
import { setAssetBase } from 'casual3d-viewer';

setAssetBase(new URL('casual3d/', import.meta.url));

const viewer = document.querySelector('casual3d-viewer');
// ?src=... shows another package (a folder's manifest.json or a .c3d file).
const src = new URLSearchParams(location.search).get('src');
if (src) viewer.setAttribute('src', src);
viewer.addEventListener('firstframe', (e) => {
  document.querySelector('#status').textContent = `first frame after ${Math.round(e.detail.timeToFirstFrameMs)} ms`;
});
viewer.addEventListener('load', (e) => {
  document.querySelector('#status').textContent = `${e.detail.levels} levels, ${e.detail.bytes} bytes`;
});
