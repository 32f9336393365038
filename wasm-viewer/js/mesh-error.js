// How the viewer bounds its meshes: how far the simplified mesh may stray
// from a package's decoded depth (format/mesh_simplify.h, max_relative_error),
// and how coarse the backdrop's cells are (format/backdrop.h).

/** Relative depth error the viewer allows the simplifier beyond the depth code's own step. */
export const SIMPLIFY_ERROR = 0.01;

/**
 * Relative depth step between neighbouring log-depth codes of a package
 * (spec/package.md Sec. 4.2): exp(ln(far_m / near_m) / (2^bits - 2)) - 1.
 * @param {{bits: number, near_m: number, far_m: number}} depthEncoding the manifest's depth_encoding
 * @returns {number} e.g. 0.0068 for 10 bits and far/near 1000
 */
export function depthCodeStep(depthEncoding) {
  const { bits, near_m: near, far_m: far } = depthEncoding ?? {};
  if (!(Number.isInteger(bits) && bits >= 2 && near > 0 && far > near && Number.isFinite(far))) {
    throw new Error('depth_encoding: expected integer bits and 0 < near_m < far_m (spec/package.md Sec. 4.2)');
  }
  return Math.expm1(Math.log(far / near) / (2 ** bits - 2));
}

/**
 * The simplifier's largest relative error for a package: SIMPLIFY_ERROR
 * beyond one depth code step, at most 0.5 (the simplifier's range). A flat
 * surface decoded from a coarse code is a staircase of one-step terraces;
 * without the step's margin, no block of it fits a thin slab and a 9-bit
 * package's mesh runs over the triangle budget that a 10-bit one meets.
 * @param {{bits: number, near_m: number, far_m: number}} depthEncoding the manifest's depth_encoding
 * @returns {number}
 */
export function simplifyMaxError(depthEncoding) {
  return Math.min(0.5, SIMPLIFY_ERROR + depthCodeStep(depthEncoding));
}

/**
 * The backdrop's cell side for a level: the library's default (0) unless a
 * backdrop over the whole sphere would then exceed a quarter of the triangle
 * budget, in which case the smallest cell that keeps it within.
 */
export function backdropCell(width, height, maxTriangles) {
  const defaultCell = Math.max(1, Math.round(width / 1024));
  const fullSphere = (cell) => 2 * Math.ceil(width / cell) * Math.ceil(height / cell);
  if (!(maxTriangles > 0) || fullSphere(defaultCell) <= maxTriangles / 4) return 0;
  let cell = defaultCell;
  while (fullSphere(cell) > maxTriangles / 4 && cell < 256) ++cell;
  return cell;
}
