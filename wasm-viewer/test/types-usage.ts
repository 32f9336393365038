// Compile-only check of js/casual3d-viewer.d.ts (ctest viewer_types_test runs
// tsc --noEmit --strict on it): typical embedding code must type-check.
import { Casual3dViewer, Casual3dViewerElement, CameraState, ViewHints, setAssetBase } from '../js/casual3d-viewer.js';

export async function embed(container: HTMLElement): Promise<number> {
  setAssetBase('/assets/casual3d/');
  const viewer = new Casual3dViewer(container, { maxLevelWidth: 2048, maxOffset: 0.2 });
  viewer.addEventListener('progress', (e) => console.log(e.detail.loadedBytes / e.detail.totalBytes));
  viewer.addEventListener('error', (e) => console.log(e.detail.fatal, e.detail.message));
  await viewer.load('scene/manifest.json');
  const camera: CameraState = viewer.getCamera();
  viewer.setCamera({ yawDeg: camera.yawDeg + 10, position: [0.1, 0, 0] });
  const hints: ViewHints | null = viewer.getViewHints();
  if (hints) viewer.setCamera({ position: [hints.volumeRadius / 2, 0, 0], fovDeg: hints.fovDeg });
  const void_: number = viewer.measureBackground() + viewer.maxOffset;
  const unbounded = new Casual3dViewer(container, { maxOffset: null, keepInContent: false, softBackground: false });
  unbounded.dispose();
  viewer.setEffects({ lighting: true, water: true, waterMinY: -1.5 });
  await viewer.nextFrame();
  const element: Casual3dViewerElement = document.querySelector('casual3d-viewer')!;
  element.addEventListener('firstframe', (e) => console.log(e.detail.timeToFirstFrameMs));
  element.setCamera({ fovDeg: 60 });
  element.resetView();
  const contentYaw = element.getViewHints()?.contentYawDeg[1] ?? void_;
  return (viewer.stats.triangles ?? 0) + contentYaw;
}

// casual3d-viewer/format: reading without the element.
import { openPackage, createFormat, type Layer, type Mesh } from '../js/format.js';

export async function read(url: string): Promise<number> {
  const pkg = await openPackage(url, { format: await createFormat({ threads: false }) });
  const pano = await pkg.readLevel(pkg.numLevels - 1, { onFile: (bytes, path) => console.log(path, bytes.length) });
  const front: Layer = pano.layer(0);
  const mesh: Mesh = pano.mesh({ maxRelativeError: 0.01 });
  const atlas = pano.atlas();
  pano.free();
  pkg.close();
  return front.depth[0] + mesh.indices.length + atlas.width + pkg.levelInfo(0).tiles[0].files[0].bytes;
}
