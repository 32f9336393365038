// View hints of a 3D photo: where it opens (the direction and vertical field
// of view that frame its captured content), the angular extent of that
// content, and its viewing volume (a ball around the panorama centre in which
// the eye may move, in the unit of the package's depths).
//
// A package carries them in the manifest's optional "view" member
// (spec/package.md, version 1.1); parseViewHints checks it. For a package
// without one (version 1.0) the viewer derives them from the coarsest level it
// shows (deriveViewHints): the content is the part of the sphere where that
// level has nodes, the volume a fixed fraction of its near depth (the rule of
// reconstruct/render/derived_view_hints.h, which `casual3d evaluate` uses for
// such packages: 0.06 x the 5th percentile of the front depths). Either way
// the content extent is narrowed to where the coarsest level really has
// surface (narrowContent), so that a view kept inside it shows no void.
//
// Plain functions without DOM or WebGL: used by the worker, the page and the
// Node tests (test/view_hints.test.mjs).
//
// Hints, in the viewer's camelCase (degrees; camera.js conventions):
//   {yawDeg, pitchDeg, fovDeg, contentYawDeg: [min, max], contentPitchDeg:
//    [min, max], volumeRadius, metric, nearDepth, source: 'package'|'derived'}
// contentYawDeg is an interval of longitudes taken modulo 360 with
// min <= max and max - min <= 360 (360: the whole circle); nearDepth is the
// near depth of the coarsest level (NEAR_DEPTH_PERCENTILE of its front
// nodes' depths), or 0 when not known.

/** Fraction of the near depth taken as the viewing volume's radius when the package gives none. */
export const DERIVED_VOLUME_FRACTION = 0.06;
/** Percentile of the front nodes' depths that stands for the scene's near depth. */
export const NEAR_DEPTH_PERCENTILE = 0.05;
/** Field of view (degrees) a derived view opens at, at most (the viewer's classic default). */
export const DERIVED_FOV_DEG = 75;
/**
 * A row or column at the border of the content must have nodes at this
 * fraction of its cells; sparser borders are peeled off (contentBox).
 */
export const BORDER_COVERAGE = 0.97;

const FULL_CIRCLE = 360;
const EPS = 1e-9;

/** Wraps an angle in degrees into [-180, 180). */
export function wrapDeg(a) {
  return ((((a + 180) % 360) + 360) % 360) - 180;
}

/**
 * Checks the manifest's "view" member (spec/package.md 1.1). Returns
 * {hints, warning}: hints null when the member is absent (warning null) or
 * malformed or out of range (warning names the field and the range). Never
 * throws. Every member of the table is required; unknown members are ignored.
 */
export function parseViewHints(view) {
  if (view === undefined) return { hints: null, warning: null };
  const refuse = (why) => ({ hints: null, warning: `manifest.json: "view" ignored: ${why}` });
  if (view === null || typeof view !== 'object' || Array.isArray(view)) return refuse('not an object');
  const problems = [];
  const number = (name, lo, hi, { open = false } = {}) => {
    const v = view[name];
    if (typeof v !== 'number' || !Number.isFinite(v)) {
      problems.push(`${name} is not a finite number`);
      return NaN;
    }
    if ((open ? v <= lo : v < lo) || v > hi) problems.push(`${name} ${v} is outside ${open ? '(' : '['}${lo}, ${hi}]`);
    return v;
  };
  const interval = (name, lo, hi, maxSpan) => {
    const v = view[name];
    if (!Array.isArray(v) || v.length !== 2 || !v.every((x) => typeof x === 'number' && Number.isFinite(x))) {
      problems.push(`${name} is not an array of two finite numbers`);
      return [NaN, NaN];
    }
    if (v[0] < lo || v[1] > hi || v[0] > v[1]) problems.push(`${name} [${v[0]}, ${v[1]}] is not an interval within [${lo}, ${hi}]`);
    else if (v[1] - v[0] > maxSpan) problems.push(`${name} [${v[0]}, ${v[1]}] spans more than ${maxSpan} degrees`);
    return [v[0], v[1]];
  };
  const hints = {
    yawDeg: number('yaw_deg', -180, 180),
    pitchDeg: number('pitch_deg', -90, 90),
    fovDeg: number('fov_deg', 10, 120),
    contentYawDeg: interval('content_yaw_deg', -360, 360, FULL_CIRCLE),
    contentPitchDeg: interval('content_pitch_deg', -90, 90, 180),
    volumeRadius: number('volume_radius', 0, Number.MAX_VALUE, { open: true }),
    metric: false,
    nearDepth: 0,
    source: 'package',
  };
  if (typeof view.metric !== 'boolean') problems.push('metric is not a boolean');
  else hints.metric = view.metric;
  if (problems.length > 0) return refuse(problems.join('; '));
  return { hints, warning: null };
}

/** Whether a longitude interval covers the whole circle. */
export function isFullCircle([lo, hi]) {
  return hi - lo >= FULL_CIRCLE - EPS;
}

/**
 * Node presence of a level's mesh (format/mesh.h vertices, spec/mesh.md
 * Sec. 3): a width x height grid, 1 where the node of either layer has a
 * vertex, and the depths of the vertices in the atlas's front half (the
 * front nodes, and the few back nodes of triangles joining both layers).
 * Seam copies land on column 0.
 */
export function presenceFromMesh(mesh, width, height) {
  const presence = new Uint8Array(width * height);
  const n = mesh.uvs.length / 2;
  const depths = [];
  const p = mesh.positions;
  for (let i = 0; i < n; ++i) {
    const v = mesh.uvs[2 * i + 1] * 2 * height;
    const x = Math.floor(mesh.uvs[2 * i] * width) % width;
    const y = Math.floor(v) % height;
    if (x >= 0 && y >= 0) presence[y * width + x] = 1;
    if (v < height) depths.push(Math.hypot(p[3 * i], p[3 * i + 1], p[3 * i + 2]));
  }
  return { presence, depths: Float32Array.from(depths) };
}

/** The q-quantile (0..1) of `values` (a copy is sorted); 0 for none. */
export function quantile(values, q) {
  if (values.length === 0) return 0;
  const sorted = Float32Array.from(values).sort();
  return sorted[Math.min(sorted.length - 1, Math.max(0, Math.floor(q * (sorted.length - 1))))];
}

/**
 * The captured content of a presence grid (width x height, row 0 the top,
 * equirectangular): the box of longitudes and latitudes that holds every
 * column and row with nodes, its borders then peeled while the sparsest
 * border has nodes at fewer than `coverage` of its cells. Returns
 * {yawDeg: [min, max], pitchDeg: [min, max]} or null when no node is present.
 */
export function contentBox(presence, width, height, coverage = BORDER_COVERAGE) {
  const at = (x, y) => presence[y * width + (x % width)];
  // Longitudes: the complement of the widest run of empty columns.
  const columnHas = new Uint8Array(width);
  for (let y = 0; y < height; ++y) for (let x = 0; x < width; ++x) if (at(x, y)) columnHas[x] = 1;
  if (!columnHas.some((v) => v)) return null;
  let gapStart = -1, gapLength = 0;
  // Scan runs of empty columns over two turns so that a run across the seam counts once.
  for (let x = 0, run = 0; x < 2 * width; ++x) {
    if (columnHas[x % width]) {
      run = 0;
    } else if (++run > gapLength && run <= width) {
      gapLength = run;
      gapStart = x - run + 1;
    }
  }
  let x0 = 0, x1 = width - 1;
  const fullCircle = gapLength === 0;
  if (!fullCircle) {
    x0 = (gapStart + gapLength) % width;
    x1 = x0 + (width - gapLength) - 1;  // May pass width: columns are taken modulo width.
  }
  let y0 = 0, y1 = height - 1;
  const rowHas = (y) => { for (let x = x0; x <= x1; ++x) if (at(x, y)) return true; return false; };
  while (y0 < y1 && !rowHas(y0)) ++y0;
  while (y1 > y0 && !rowHas(y1)) --y1;
  // Peel the sparsest border while it is too sparse.
  const columnFraction = (x) => { let n = 0; for (let y = y0; y <= y1; ++y) n += at(x, y); return n / (y1 - y0 + 1); };
  const rowFraction = (y) => { let n = 0; for (let x = x0; x <= x1; ++x) n += at(x, y); return n / (x1 - x0 + 1); };
  for (;;) {
    const borders = [{ side: 'top', f: rowFraction(y0) }, { side: 'bottom', f: rowFraction(y1) }];
    if (!fullCircle) borders.push({ side: 'left', f: columnFraction(x0) }, { side: 'right', f: columnFraction(x1) });
    const worst = borders.reduce((a, b) => (b.f < a.f ? b : a));
    if (worst.f >= coverage) break;
    if (worst.side === 'top') ++y0;
    else if (worst.side === 'bottom') --y1;
    else if (worst.side === 'left') ++x0;
    else --x1;
    if (y0 > y1 || x0 > x1) return null;
  }
  // Rounded to 1e-6 degrees: grid lines land on round numbers.
  const round = (v) => Math.round(v * 1e6) / 1e6;
  const lon = (x) => round((x / width - 0.5) * 360);
  const lat = (y) => round(90 - (y / height) * 180);
  // Borders inside the grid run through the outer cells' centres, where this
  // level's nodes are: a finer level's content may end there.
  let yaw = fullCircle ? [-180, 180] : [lon(x0 + 0.5), lon(x1 + 0.5)];
  if (yaw[0] >= 180) yaw = [yaw[0] - 360, yaw[1] - 360];
  return { yawDeg: yaw, pitchDeg: [y1 === height - 1 ? -90 : lat(y1 + 0.5), y0 === 0 ? 90 : lat(y0 + 0.5)] };
}

/**
 * The intersection of two longitude intervals (each modulo 360), or null when
 * they do not overlap. Of two overlapping pieces (possible only with very wide
 * intervals) the one nearer b's centre is kept.
 */
export function intersectYaw(a, b) {
  if (isFullCircle(a)) return [...b];
  if (isFullCircle(b)) return [...a];
  const ca = (a[0] + a[1]) / 2, cb = (b[0] + b[1]) / 2;
  const shift = cb - wrapDeg(cb - ca) - ca;  // Moves a by k * 360 next to b.
  const lo = Math.max(a[0] + shift, b[0]), hi = Math.min(a[1] + shift, b[1]);
  if (lo > hi) return null;
  return lo >= 180 ? [lo - 360, hi - 360] : lo < -360 ? [lo + 360, hi + 360] : [lo, hi];
}

/**
 * Hints for a package without a "view" member, from its coarsest level's
 * presence grid and node depths (presenceFromMesh): the content is
 * contentBox's box; the view looks at its centre with the field of view of
 * its height (at most DERIVED_FOV_DEG); the volume radius is
 * DERIVED_VOLUME_FRACTION of the NEAR_DEPTH_PERCENTILE depth; not metric.
 */
export function deriveViewHints({ presence, depths, width, height }) {
  const box = contentBox(presence, width, height) ?? { yawDeg: [-180, 180], pitchDeg: [-90, 90] };
  const nearDepth = quantile(depths, NEAR_DEPTH_PERCENTILE);
  const full = isFullCircle(box.yawDeg);
  const pitchSpan = box.pitchDeg[1] - box.pitchDeg[0];
  return {
    yawDeg: full ? 0 : wrapDeg((box.yawDeg[0] + box.yawDeg[1]) / 2),
    pitchDeg: full && pitchSpan >= 179 ? 0 : (box.pitchDeg[0] + box.pitchDeg[1]) / 2,
    fovDeg: Math.max(10, Math.min(DERIVED_FOV_DEG, pitchSpan)),
    contentYawDeg: box.yawDeg,
    contentPitchDeg: box.pitchDeg,
    volumeRadius: nearDepth > 0 ? DERIVED_VOLUME_FRACTION * nearDepth : 0.1,
    metric: false,
    nearDepth,
    source: 'derived',
  };
}

/**
 * The package's hints with their content narrowed to the coarsest level's
 * measured content (contentBox) and its near depth filled in; `measured`
 * is deriveViewHints' result. Where the two boxes do not overlap the
 * package's box is kept.
 */
export function narrowContent(hints, measured) {
  const yaw = intersectYaw(hints.contentYawDeg, measured.contentYawDeg);
  const lo = Math.max(hints.contentPitchDeg[0], measured.contentPitchDeg[0]);
  const hi = Math.min(hints.contentPitchDeg[1], measured.contentPitchDeg[1]);
  return {
    ...hints,
    contentYawDeg: yaw ?? hints.contentYawDeg,
    contentPitchDeg: yaw && lo <= hi ? [lo, hi] : hints.contentPitchDeg,
    nearDepth: measured.nearDepth,
  };
}
