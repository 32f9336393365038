// Checks GLB files written by `casual3d export` with the tools of the web:
//  - the Khronos glTF validator (npm gltf-validator): no errors, no warnings;
//  - three.js's GLTFLoader, with Draco decoding by draco3d (the decoder that
//    three's DRACOLoader runs in a Web Worker, here called in-process): the
//    scene loads, the mesh has the expected vertex and triangle counts, and the
//    loaded positions match the accessor bounds.
//
// Usage:
//   node gltf_test.mjs --node-modules DIR --plain plain.glb --draco draco.glb
//        [--triangles N]
// DIR holds the npm packages (wasm-viewer/node_modules). N, when given, is the
// number of triangles both files must have. Exit code 0 when every check
// passes (node:test reports each check).

import assert from 'node:assert/strict';
import { resolveObjectURL } from 'node:buffer';
import fs from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';
import { test } from 'node:test';
import { pathToFileURL } from 'node:url';

function parseArgs(argv) {
  const args = {};
  for (let i = 0; i < argv.length; i += 2) {
    const key = argv[i];
    const value = argv[i + 1];
    if (!key.startsWith('--') || value === undefined) {
      throw new Error(`gltf_test.mjs: bad arguments near '${key}' (see the usage at the top)`);
    }
    args[key.slice(2)] = value;
  }
  for (const required of ['node-modules', 'plain', 'draco']) {
    if (!args[required]) throw new Error(`gltf_test.mjs: --${required} is required`);
  }
  return args;
}

const args = parseArgs(process.argv.slice(2));
const nodeModules = path.resolve(args['node-modules']);
for (const pkg of ['three', 'draco3d', 'gltf-validator']) {
  if (!fs.existsSync(path.join(nodeModules, pkg, 'package.json'))) {
    throw new Error(`${nodeModules}: npm package '${pkg}' is missing; run 'npm ci' in wasm-viewer/`);
  }
}
const require = createRequire(path.join(nodeModules, 'noop.js'));
const validator = require('gltf-validator');
const draco3d = require('draco3d');
// three is an ES module; import the files GLTFLoader itself resolves 'three' to,
// so that both share one copy of the library.
const importFile = (rel) => import(pathToFileURL(path.join(nodeModules, rel)).href);
const THREE = await importFile('three/build/three.module.js');
const { GLTFLoader } = await importFile('three/examples/jsm/loaders/GLTFLoader.js');
const { DRACOLoader } = await importFile('three/examples/jsm/loaders/DRACOLoader.js');

// ---------------------------------------------------------------------------
// Draco: DRACOLoader decodes in Web Workers, which Node lacks. This subclass
// keeps DRACOLoader's interface and its geometry construction
// (_createGeometry) but decodes in-process with draco3d's decoder module.

const dracoModule = await draco3d.createDecoderModule({});

class NodeDracoLoader extends DRACOLoader {
  decodeGeometry(buffer, taskConfig) {
    return Promise.resolve().then(() => this._createGeometry(decodeDraco(buffer, taskConfig)));
  }
  preload() {
    return this;
  }
  dispose() {
    return this;
  }
}

function decodeDraco(buffer, taskConfig) {
  const draco = dracoModule;
  const decoder = new draco.Decoder();
  const array = new Int8Array(buffer);
  const mesh = new draco.Mesh();
  try {
    if (decoder.GetEncodedGeometryType(array) !== draco.TRIANGULAR_MESH) {
      throw new Error('Draco buffer is not a triangle mesh');
    }
    const status = decoder.DecodeArrayToMesh(array, array.byteLength, mesh);
    if (!status.ok() || mesh.ptr === 0) throw new Error(`Draco decoding failed: ${status.error_msg()}`);
    const geometry = { index: null, attributes: [] };
    for (const name in taskConfig.attributeIDs) {
      const TypedArray = globalThis[taskConfig.attributeTypes[name]];
      const attribute = taskConfig.useUniqueIDs
        ? decoder.GetAttributeByUniqueId(mesh, taskConfig.attributeIDs[name])
        : decoder.GetAttribute(mesh, decoder.GetAttributeId(mesh, draco[taskConfig.attributeIDs[name]]));
      if (!attribute || attribute.ptr === 0) throw new Error(`Draco attribute ${name} is missing`);
      if (TypedArray !== Float32Array) throw new Error(`unexpected Draco attribute type for ${name}`);
      const count = mesh.num_points();
      const itemSize = attribute.num_components();
      const byteLength = count * itemSize * 4;
      const ptr = draco._malloc(byteLength);
      decoder.GetAttributeDataArrayForAllPoints(mesh, attribute, draco.DT_FLOAT32, byteLength, ptr);
      const values = new Float32Array(draco.HEAPF32.buffer, ptr, count * itemSize).slice();
      draco._free(ptr);
      geometry.attributes.push({ name, count, itemSize, array: values, stride: itemSize });
    }
    const numIndices = mesh.num_faces() * 3;
    const ptr = draco._malloc(numIndices * 4);
    decoder.GetTrianglesUInt32Array(mesh, numIndices * 4, ptr);
    geometry.index = { array: new Uint32Array(draco.HEAPF32.buffer, ptr, numIndices).slice(), itemSize: 1 };
    draco._free(ptr);
    return geometry;
  } finally {
    draco.destroy(mesh);
    draco.destroy(decoder);
  }
}

// ---------------------------------------------------------------------------
// Textures: three's image loaders need a browser (an <img> element or
// createImageBitmap). A GLTFLoader plugin routes texture loading through
// GLTFParser.loadTextureImage (so three still reads the image from the GLB's
// buffer view into a blob: URL and applies the sampler) with a loader that,
// instead of decoding pixels, checks that the blob is a PNG or JPEG of the
// declared type and reads its size from the header.

globalThis.self ??= globalThis;  // GLTFParser reads self.URL.
function imageSize(bytes) {
  const b = bytes;
  if (b.length >= 24 && b[0] === 0x89 && b[1] === 0x50 && b[2] === 0x4e && b[3] === 0x47) {
    const view = new DataView(b.buffer, b.byteOffset, b.byteLength);
    return { mimeType: 'image/png', width: view.getUint32(16), height: view.getUint32(20) };
  }
  if (b.length >= 4 && b[0] === 0xff && b[1] === 0xd8) {
    // Walk the JPEG segments to the first start-of-frame marker.
    let i = 2;
    while (i + 9 < b.length) {
      if (b[i] !== 0xff) throw new Error('JPEG: bad segment marker');
      const marker = b[i + 1];
      const length = (b[i + 2] << 8) | b[i + 3];
      if (marker >= 0xc0 && marker <= 0xcf && marker !== 0xc4 && marker !== 0xc8 && marker !== 0xcc) {
        return { mimeType: 'image/jpeg', height: (b[i + 5] << 8) | b[i + 6], width: (b[i + 7] << 8) | b[i + 8] };
      }
      i += 2 + length;
    }
    throw new Error('JPEG: no frame header');
  }
  throw new Error('texture is neither PNG nor JPEG');
}

class HeaderOnlyImageLoader {
  constructor(seen) {
    this.seen = seen;
  }
  load(url, onLoad, onProgress, onError) {
    const blob = resolveObjectURL(url);
    if (!blob) {
      onError(new Error(`not a blob URL: ${url}`));
      return;
    }
    blob.arrayBuffer().then((buffer) => {
      const info = imageSize(new Uint8Array(buffer));
      assert.equal(info.mimeType, blob.type, 'image bytes do not match the declared mimeType');
      this.seen.push(info);
      onLoad(new THREE.Texture({ width: info.width, height: info.height }));
    }).catch(onError);
  }
}

class HeaderOnlyTexturePlugin {
  constructor(parser, seen) {
    this.name = 'casual3d_header_only_textures';
    this.parser = parser;
    this.loader = new HeaderOnlyImageLoader(seen);
  }
  loadTexture(textureIndex) {
    const source = this.parser.json.textures[textureIndex].source;
    return this.parser.loadTextureImage(textureIndex, source, this.loader);
  }
}

async function loadWithThree(bytes) {
  const loader = new GLTFLoader();
  loader.setDRACOLoader(new NodeDracoLoader());
  const images = [];
  loader.register((parser) => new HeaderOnlyTexturePlugin(parser, images));
  const buffer = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
  const gltf = await loader.parseAsync(buffer, '');
  return { gltf, images };
}

// The JSON chunk of a GLB.
function glbJson(bytes) {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  assert.equal(view.getUint32(0, true), 0x46546c67, 'not a GLB (magic)');
  assert.equal(view.getUint32(4, true), 2, 'GLB version');
  assert.equal(view.getUint32(8, true), bytes.byteLength, 'GLB length field');
  const length = view.getUint32(12, true);
  assert.equal(view.getUint32(16, true), 0x4e4f534a, 'first chunk is not JSON');
  return JSON.parse(new TextDecoder().decode(bytes.subarray(20, 20 + length)));
}

// ---------------------------------------------------------------------------

const files = { plain: fs.readFileSync(args.plain), draco: fs.readFileSync(args.draco) };
const results = {};

for (const [kind, bytes] of Object.entries(files)) {
  test(`${kind}: the Khronos validator finds no errors or warnings`, async () => {
    const report = await validator.validateBytes(new Uint8Array(bytes), { maxIssues: 100 });
    const problems = report.issues.messages.filter((m) => m.severity <= 1);
    assert.equal(report.issues.numErrors, 0, JSON.stringify(problems, null, 1));
    assert.equal(report.issues.numWarnings, 0, JSON.stringify(problems, null, 1));
    // The validator does not decode Draco; it says so (and then cannot see
    // that the Draco buffer view is used). Nothing else may be reported.
    const allowed = kind === 'draco' ? ['UNSUPPORTED_EXTENSION', 'UNUSED_OBJECT'] : [];
    for (const m of report.issues.messages) {
      assert.ok(allowed.includes(m.code), `unexpected validator message: ${JSON.stringify(m)}`);
    }
    assert.equal(report.info.drawCallCount, 1);
    assert.equal(report.info.hasTextures, true);
    if (args.triangles) assert.equal(report.info.totalTriangleCount, Number(args.triangles));
  });

  test(`${kind}: three.js GLTFLoader loads the mesh`, async () => {
    const json = glbJson(bytes);
    const required = json.extensionsRequired ?? [];
    assert.equal(required.includes('KHR_draco_mesh_compression'), kind === 'draco',
      `extensionsRequired: ${JSON.stringify(required)}`);
    const { gltf, images } = await loadWithThree(bytes);
    const meshes = [];
    gltf.scene.traverse((o) => { if (o.isMesh) meshes.push(o); });
    assert.equal(meshes.length, 1, 'one mesh');
    const mesh = meshes[0];
    const geometry = mesh.geometry;
    const prim = json.meshes[0].primitives[0];
    const accessors = json.accessors;

    // Counts: three's geometry against the file's accessors.
    const position = geometry.getAttribute('position');
    assert.ok(position, 'position attribute');
    assert.equal(position.count, accessors[prim.attributes.POSITION].count);
    assert.ok(geometry.getAttribute('uv'), 'uv attribute');
    assert.equal(geometry.getAttribute('uv').count, position.count);
    assert.equal(geometry.getAttribute('normal')?.count, position.count);
    assert.ok(geometry.index, 'indexed geometry');
    assert.equal(geometry.index.count, accessors[prim.indices].count);
    assert.equal(geometry.index.count % 3, 0);
    const triangles = geometry.index.count / 3;
    assert.ok(triangles > 0);
    if (args.triangles) assert.equal(triangles, Number(args.triangles));
    for (let i = 0; i < geometry.index.count; i++) {
      if (geometry.index.getX(i) >= position.count) assert.fail(`index ${i} out of range`);
    }

    // Positions: the bounding box equals the accessor's min and max, and no
    // node transform moves the mesh (glTF and the panorama share their axes).
    geometry.computeBoundingBox();
    const { min, max } = geometry.boundingBox;
    const acc = accessors[prim.attributes.POSITION];
    for (const [k, axis] of ['x', 'y', 'z'].entries()) {
      assert.ok(Math.abs(min[axis] - acc.min[k]) <= 1e-5 * Math.max(1, Math.abs(acc.min[k])), `min.${axis}`);
      assert.ok(Math.abs(max[axis] - acc.max[k]) <= 1e-5 * Math.max(1, Math.abs(acc.max[k])), `max.${axis}`);
    }
    mesh.updateMatrixWorld(true);
    assert.ok(mesh.matrixWorld.equals(new THREE.Matrix4()), 'identity transform');

    // Normals are unit length.
    const normal = geometry.getAttribute('normal');
    let worst = 0;
    for (let i = 0; i < normal.count; i++) {
      const len = Math.hypot(normal.getX(i), normal.getY(i), normal.getZ(i));
      worst = Math.max(worst, Math.abs(len - 1));
    }
    assert.ok(worst < 2e-3, `normal length off by ${worst}`);

    // Material: unlit (MeshBasicMaterial) with the colour texture.
    assert.ok(mesh.material.isMeshBasicMaterial, `material is ${mesh.material.type}`);
    assert.ok(mesh.material.map, 'colour texture');
    assert.equal(mesh.material.map.wrapS, THREE.RepeatWrapping);
    assert.equal(mesh.material.map.wrapT, THREE.ClampToEdgeWrapping);
    assert.equal(images.length, 1);
    assert.ok(images[0].width >= 16 && images[0].height >= 16);
    assert.equal(images[0].height % 2, 0, 'atlas height holds two layers');

    results[kind] = { triangles, vertices: position.count, min: min.toArray(), max: max.toArray() };
  });
}

test('plain and Draco files hold the same mesh', () => {
  const { plain, draco } = results;
  assert.ok(plain && draco, 'both files loaded');
  assert.equal(draco.triangles, plain.triangles);
  // Draco may duplicate a few vertices on non-manifold edges, never drop any.
  assert.ok(draco.vertices >= plain.vertices && draco.vertices <= plain.vertices * 1.05,
    `vertices: plain ${plain.vertices}, Draco ${draco.vertices}`);
  // Bounds agree within the position quantization (14 bits over the largest extent).
  const extent = Math.max(...plain.max.map((v, k) => v - plain.min[k]));
  const tolerance = extent / (1 << 14) * 1.01;
  for (let k = 0; k < 3; k++) {
    assert.ok(Math.abs(draco.min[k] - plain.min[k]) <= tolerance, `min[${k}]`);
    assert.ok(Math.abs(draco.max[k] - plain.max[k]) <= tolerance, `max[${k}]`);
  }
});
