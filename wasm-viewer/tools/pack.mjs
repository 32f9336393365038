// Makes the npm package of the viewer: stages package.json, README.md and the
// built viewer (<build>/wasm-viewer/dist: the JavaScript, both wasm builds and
// the type declarations) into a folder, then runs `npm pack` there.
//
//   node wasm-viewer/tools/pack.mjs --dist <build>/wasm-viewer/dist --out <dir>
//
// Writes <dir>/casual3d-viewer-<version>.tgz and prints its path. The build
// target `wasm_viewer_npm` runs it (tarball in <build>/wasm-viewer/npm/).

import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const SOURCE = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');

/** The files of dist/ that the package ships: the viewer's runtime and its types. */
export const PACKAGE_FILE = /\.(js|cjs|wasm|d\.ts)$/;

/**
 * Stages the package from `dist` into `<out>/package` and packs it into
 * `out`; returns the tarball's path.
 */
export function pack(dist, out) {
  const required = ['casual3d-viewer.js', 'format.js', 'format-node.js', 'casual3d-format.wasm', 'casual3d-format-mt.wasm'];
  for (const f of required) {
    if (!fs.existsSync(path.join(dist, f))) throw new Error(`${path.join(dist, f)} is missing; build the target wasm_viewer first`);
  }
  const stage = path.join(out, 'package');
  fs.rmSync(stage, { recursive: true, force: true });
  fs.mkdirSync(path.join(stage, 'dist'), { recursive: true });
  // What is published: no scripts or tools of this repository.
  const manifest = JSON.parse(fs.readFileSync(path.join(SOURCE, 'package.json'), 'utf8'));
  delete manifest.scripts;
  delete manifest.devDependencies;
  fs.writeFileSync(path.join(stage, 'package.json'), `${JSON.stringify(manifest, null, 2)}\n`);
  fs.copyFileSync(path.join(SOURCE, 'README.md'), path.join(stage, 'README.md'));
  fs.copyFileSync(path.join(SOURCE, '..', 'LICENSE'), path.join(stage, 'LICENSE'));
  for (const f of fs.readdirSync(dist).sort()) {
    if (PACKAGE_FILE.test(f) && fs.statSync(path.join(dist, f)).isFile()) {
      fs.copyFileSync(path.join(dist, f), path.join(stage, 'dist', f));
    }
  }
  const result = JSON.parse(execFileSync('npm', ['pack', '--json', '--pack-destination', path.resolve(out)], {
    cwd: stage, encoding: 'utf8', stdio: ['ignore', 'pipe', 'inherit'],
  }));
  return path.join(path.resolve(out), result[0].filename);
}

if (process.argv[1] === fileURLToPath(import.meta.url)) {
  const arg = (name) => {
    const i = process.argv.indexOf(name);
    if (i < 0 || !process.argv[i + 1]) {
      console.error('usage: node wasm-viewer/tools/pack.mjs --dist <build>/wasm-viewer/dist --out <dir>');
      process.exit(2);
    }
    return process.argv[i + 1];
  };
  try {
    console.log(pack(arg('--dist'), arg('--out')));
  } catch (err) {
    console.error(`pack: ${err.message}`);
    process.exit(1);
  }
}
