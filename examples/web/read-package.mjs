// Reads a package in Node with casual3d-viewer/format (no browser, no
// element): its levels, the nodes and depths of both layers, and the mesh.
//
//   node read-package.mjs <package folder | manifest.json | photo.c3d | URL>
import { openPackage } from 'casual3d-viewer/format';

const input = process.argv[2];
if (!input) {
  console.error('usage: node read-package.mjs <package folder, manifest.json, .c3d file or URL>');
  process.exit(2);
}
const pkg = await openPackage(input);
console.log(`${input}: ${pkg.kind}, ${pkg.numLevels} levels, casual3d ${pkg.manifest.version} package`);
for (let level = 0; level < pkg.numLevels; ++level) {
  const pano = await pkg.readLevel(level);
  for (const [index, name] of ['front', 'back'].entries()) {
    const { present, depth } = pano.layer(index);
    let nodes = 0, near = Infinity, far = 0;
    for (let i = 0; i < present.length; ++i) {
      if (!present[i]) continue;
      ++nodes;
      near = Math.min(near, depth[i]);
      far = Math.max(far, depth[i]);
    }
    const range = nodes ? `, depth ${near.toFixed(2)}-${far.toFixed(2)} m` : '';
    console.log(`  level ${level} (${pano.width}x${pano.height}) ${name}: ${nodes} nodes${range}`);
  }
  const mesh = pano.mesh();
  console.log(`  level ${level} mesh: ${mesh.positions.length / 3} vertices, ${mesh.indices.length / 3} triangles`);
  pano.free();
}
pkg.close();
