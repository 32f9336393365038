// Renders a GLB (as `casual3d export` writes it) with three.js in headless
// Chromium (SwiftShader WebGL2) from the cameras that
// `casual3d evaluate --write-cameras` writes, one PNG per camera (RGBA, alpha
// 0 where nothing was drawn), for `casual3d evaluate --rendered DIR` to score
// against the photos: the exported GLB as a three.js page shows it.
//
//   node wasm-viewer/bench/glb_rephoto.mjs <file.glb> <cameras.json> <out_dir>
//
// three.js as a page would set it up: GLTFLoader (DRACOLoader with three's own
// decoder for Draco files), the default sRGB output, no tone mapping, pixel
// ratio 1, no antialiasing (one sample per pixel centre, as the cameras'
// pixel convention assumes). Prints one JSON line: the images written, the
// mesh's triangles and the render time.

import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

import { chromiumArgs, chromiumOrSkip, startServer } from '../test/static-server.mjs';

const [glb, camerasFile, out] = process.argv.slice(2, 5);
if (!glb || !camerasFile || !out) {
  console.error('usage: glb_rephoto.mjs <file.glb> <cameras.json> <out_dir>');
  process.exit(2);
}
const fail = (message) => { console.error(`glb_rephoto: error: ${message}`); process.exit(1); };
if (!fs.existsSync(glb) || !fs.statSync(glb).isFile()) fail(`${glb}: no such GLB file`);
let cameras;
try {
  cameras = JSON.parse(fs.readFileSync(camerasFile, 'utf8'));
} catch (e) {
  fail(`${camerasFile}: not a readable JSON cameras file (${e.message})`);
}
if (cameras.format !== 'casual3d-rephoto-cameras' || cameras.version !== 1 || !Array.isArray(cameras.cameras)) {
  fail(`${camerasFile}: not a cameras file of \`casual3d evaluate --write-cameras\` (format casual3d-rephoto-cameras, version 1)`);
}
for (const c of cameras.cameras) {
  if (!(c.width > 0 && c.height > 0) || c.view_matrix?.length !== 16 || c.projection_matrix?.length !== 16 ||
      typeof c.image !== 'string' || c.image.includes('/') || c.image.includes('..')) {
    fail(`${camerasFile}: camera ${JSON.stringify(c.name)} is malformed (write it again with casual3d evaluate --write-cameras)`);
  }
}
fs.mkdirSync(out, { recursive: true });

const here = path.dirname(fileURLToPath(import.meta.url));
const three = path.join(here, '..', 'node_modules', 'three');
if (!fs.existsSync(path.join(three, 'package.json'))) fail(`${three}: npm package three is missing; run scripts/setup.sh`);
const { chromium, executable } = await chromiumOrSkip('glb_rephoto.mjs');

const page = `<!DOCTYPE html><html><head><meta charset="utf-8">
<script type="importmap">{"imports": {"three": "/three/build/three.module.js",
  "three/addons/": "/three/examples/jsm/"}}</script></head><body style="margin:0">
<script type="module">
  import * as THREE from 'three';
  import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
  import { DRACOLoader } from 'three/addons/loaders/DRACOLoader.js';
  const renderer = new THREE.WebGLRenderer({ antialias: false, alpha: true, premultipliedAlpha: false,
                                             preserveDrawingBuffer: true });
  renderer.setPixelRatio(1);
  renderer.setClearColor(0x000000, 0);
  document.body.appendChild(renderer.domElement);
  const draco = new DRACOLoader();
  draco.setDecoderPath('/three/examples/jsm/libs/draco/gltf/');
  const loader = new GLTFLoader();
  loader.setDRACOLoader(draco);
  window.ready = loader.loadAsync('/model.glb').then((gltf) => {
    window.scene = gltf.scene;
    let triangles = 0;
    gltf.scene.traverse((o) => {
      if (o.isMesh) triangles += (o.geometry.index ? o.geometry.index.count : o.geometry.attributes.position.count) / 3;
    });
    return triangles;
  });
  window.renderView = (c) => {
    renderer.setSize(c.width, c.height, false);
    const camera = new THREE.Camera();
    camera.matrixAutoUpdate = false;
    camera.matrix.fromArray(c.view_matrix).invert();
    camera.matrixWorldNeedsUpdate = true;  // matrixAutoUpdate off: copy matrix to matrixWorld
    camera.projectionMatrix.fromArray(c.projection_matrix);
    camera.projectionMatrixInverse.copy(camera.projectionMatrix).invert();
    renderer.render(window.scene, camera);
    return renderer.domElement.toDataURL('image/png');
  };
</script></body></html>`;

const server = await startServer({ '/three/': three }, { '/index.html': page, '/favicon.ico': '' });
const glbBytes = fs.readFileSync(glb);
const browser = await chromium.launch({ executablePath: executable, args: chromiumArgs() });
try {
  const tab = await browser.newPage();
  tab.on('console', (m) => { if (m.type() === 'error') console.error(m.text()); });
  tab.on('pageerror', (e) => console.error(e.message));
  await tab.route('**/model.glb', (route) => route.fulfill({ body: glbBytes, contentType: 'model/gltf-binary' }));
  await tab.goto(`${server.url}/index.html`);
  await tab.waitForFunction(() => window.ready, null, { timeout: 600000 });
  const triangles = await tab.evaluate(() => window.ready);
  const t0 = performance.now();
  for (const c of cameras.cameras) {
    const url = await tab.evaluate((cam) => window.renderView(cam), c);
    const file = path.join(out, c.image);
    fs.writeFileSync(`${file}.tmp`, Buffer.from(url.slice(url.indexOf(',') + 1), 'base64'));
    fs.renameSync(`${file}.tmp`, file);
  }
  console.log(JSON.stringify({ images: cameras.cameras.length, triangles,
    seconds_render: +((performance.now() - t0) / 1000).toFixed(2), out }));
} finally {
  await browser.close();
  await server.close();
}
