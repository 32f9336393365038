// Where the viewer's runtime files are served: worker.js, format-module.js and
// the wasm builds (casual3d-format*.{js,wasm}). By default the folder of this
// module, which is right when the package's files are served as they are; a
// page that bundles the viewer (esbuild, vite, ...) copies those files to a
// folder of its own and names it with setAssetBase().

let base = null;

/** The folder (URL, relative to the page) holding the viewer's runtime files; null: the default. */
export function setAssetBase(url) {
  if (url == null) {
    base = null;
    return;
  }
  const page = typeof document !== 'undefined' ? document.baseURI : globalThis.location?.href;
  const folder = String(url).endsWith('/') ? String(url) : `${url}/`;
  base = new URL(folder, page).href;
}

/** The URL of runtime file `name`. */
export function assetUrl(name) {
  return new URL(name, base ?? import.meta.url).href;
}
