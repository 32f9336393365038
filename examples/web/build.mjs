// Bundles src/main.js with esbuild into dist/app.js and copies the viewer's
// runtime files (its worker and the wasm format library, which a bundle cannot
// inline) to dist/casual3d/.
import * as esbuild from 'esbuild';
import fs from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';

await esbuild.build({
  entryPoints: ['src/main.js'],
  bundle: true,
  format: 'esm',
  target: 'es2022',
  minify: true,
  outfile: 'dist/app.js',
  logLevel: 'warning',
});

const viewerDist = path.dirname(createRequire(import.meta.url).resolve('casual3d-viewer'));
fs.mkdirSync('dist/casual3d', { recursive: true });
for (const f of fs.readdirSync(viewerDist)) {
  if (/\.(js|wasm)$/.test(f)) fs.copyFileSync(path.join(viewerDist, f), path.join('dist/casual3d', f));
}
console.log(`dist/app.js: ${fs.statSync('dist/app.js').size} bytes; viewer runtime in dist/casual3d/`);
