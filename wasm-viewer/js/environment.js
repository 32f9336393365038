// The soft background drawn behind a 3D photo where no surface is (outside
// the captured content, in holes): the coarsest level's front colours,
// spread into the empty parts of the sphere and heavily blurred, as a small
// equirectangular image. The renderer draws it at infinite distance, so the
// view never shows a hard black edge. Plain functions (Node-tested).

/** Size of the environment image (equirectangular, pixels). */
export const ENVIRONMENT_WIDTH = 64;
export const ENVIRONMENT_HEIGHT = 32;
/** Box blur radius (pixels of the environment image) and passes: about a 14-degree Gaussian. */
const BLUR_RADIUS = 2;
const BLUR_PASSES = 3;

/**
 * The environment image of a level: `atlas` its colour atlas ({width, height:
 * 2 * level height, data: RGBA}, front colours in the top half), `presence`
 * its width x height node presence (view-hints.js presenceFromMesh). Returns
 * {width, height, data: RGBA Uint8Array}, alpha 255; all black if no node is
 * present.
 */
export function buildEnvironment(atlas, presence, width = ENVIRONMENT_WIDTH, height = ENVIRONMENT_HEIGHT) {
  const lw = atlas.width, lh = atlas.height / 2;
  // 1. Area-average the present nodes' colours into the small grid.
  const sum = new Float64Array(width * height * 3);
  const weight = new Float64Array(width * height);
  for (let y = 0; y < lh; ++y) {
    const ey = Math.min(height - 1, Math.floor((y * height) / lh));
    for (let x = 0; x < lw; ++x) {
      if (!presence[y * lw + x]) continue;
      const ex = Math.min(width - 1, Math.floor((x * width) / lw));
      const e = ey * width + ex, a = (y * lw + x) * 4;
      for (let c = 0; c < 3; ++c) sum[3 * e + c] += atlas.data[a + c];
      weight[e] += 1;
    }
  }
  const cells = [];
  for (let e = 0; e < width * height; ++e) {
    cells.push(weight[e] > 0 ? [sum[3 * e] / weight[e], sum[3 * e + 1] / weight[e], sum[3 * e + 2] / weight[e]] : null);
  }
  // 2. Fill the empty cells from coarser and coarser averages (push-pull).
  const filled = pushPull(cells, width, height);
  // 3. Blur: separable box filter, wrapping in longitude, clamped in latitude.
  let img = new Float64Array(width * height * 3);
  filled.forEach((v, e) => { img[3 * e] = v[0]; img[3 * e + 1] = v[1]; img[3 * e + 2] = v[2]; });
  for (let pass = 0; pass < BLUR_PASSES; ++pass) {
    img = boxBlur(img, width, height, BLUR_RADIUS, true);
    img = boxBlur(img, width, height, BLUR_RADIUS, false);
  }
  const data = new Uint8Array(width * height * 4);
  for (let e = 0; e < width * height; ++e) {
    for (let c = 0; c < 3; ++c) data[4 * e + c] = Math.round(Math.min(255, Math.max(0, img[3 * e + c])));
    data[4 * e + 3] = 255;
  }
  return { width, height, data };
}

/** Cells (RGB arrays or null) with every null replaced by the mean of its nearest filled neighbourhood. */
function pushPull(cells, width, height) {
  if (cells.every((c) => c === null)) return cells.map(() => [0, 0, 0]);
  if (cells.every((c) => c !== null) || (width === 1 && height === 1)) return cells.map((c) => c ?? [0, 0, 0]);
  const cw = Math.max(1, Math.ceil(width / 2)), ch = Math.max(1, Math.ceil(height / 2));
  const coarse = [];
  for (let y = 0; y < ch; ++y) {
    for (let x = 0; x < cw; ++x) {
      const acc = [0, 0, 0];
      let n = 0;
      for (let dy = 0; dy < 2; ++dy) {
        for (let dx = 0; dx < 2; ++dx) {
          const fx = 2 * x + dx, fy = 2 * y + dy;
          if (fx >= width || fy >= height) continue;
          const c = cells[fy * width + fx];
          if (!c) continue;
          acc[0] += c[0]; acc[1] += c[1]; acc[2] += c[2];
          ++n;
        }
      }
      coarse.push(n > 0 ? acc.map((v) => v / n) : null);
    }
  }
  const coarseFilled = pushPull(coarse, cw, ch);
  return cells.map((c, e) => c ?? coarseFilled[Math.floor(Math.floor(e / width) / 2) * cw + Math.floor((e % width) / 2)]);
}

function boxBlur(img, width, height, radius, horizontal) {
  const out = new Float64Array(img.length);
  const n = 2 * radius + 1;
  for (let y = 0; y < height; ++y) {
    for (let x = 0; x < width; ++x) {
      const acc = [0, 0, 0];
      for (let k = -radius; k <= radius; ++k) {
        const sx = horizontal ? (((x + k) % width) + width) % width : x;
        const sy = horizontal ? y : Math.min(height - 1, Math.max(0, y + k));
        const s = 3 * (sy * width + sx);
        acc[0] += img[s]; acc[1] += img[s + 1]; acc[2] += img[s + 2];
      }
      const d = 3 * (y * width + x);
      out[d] = acc[0] / n; out[d + 1] = acc[1] / n; out[d + 2] = acc[2] / n;
    }
  }
  return out;
}
