// Soft limits that keep the view on a 3D photo's captured content.
//
// A view (yaw, pitch, vertical field of view, camera.js conventions) is
// inside the content when its whole frustum lies inside the content's box of
// longitudes and latitudes (view-hints.js), shrunk by a margin for the eye's
// parallax. `clampView` gives the nearest such view (the hard limits). User
// input does not stop dead at them: `resist` lets a move go past a limit by a
// diminishing amount (at most `range`), and the viewer eases the view back
// (`easeFactor`) once the input ends. Plain functions, tested in Node
// (test/view_limits.test.mjs).
//
// Limits: {yawDeg: [min, max] (modulo 360), pitchDeg: [min, max],
//          marginDeg, minFovDeg, maxFovDeg}.

import { isFullCircle, wrapDeg } from './view-hints.js';

const DEG = Math.PI / 180;
/** Pitch the camera never passes (camera.js). */
export const MAX_PITCH_DEG = 89.9;
/** Overshoot past a limit allowed while dragging, as a fraction of the field of view. */
export const OVERSHOOT_FRACTION = 0.08;
/** Time constant (s) of the ease back to the limits after input ends. */
export const EASE_TIME_S = 0.12;

/**
 * Half the longitude extent (degrees) of a view of vertical field of view
 * `fovDeg` and aspect `aspect` (width / height) looking at pitch `pitchDeg`:
 * the largest longitude offset of its frustum's corners from the view
 * direction (the frustum's edges are great-circle arcs, whose longitude is
 * monotonic, so the corners bound it); 180 when the frustum holds a pole.
 */
export function yawHalfExtentDeg(fovDeg, aspect, pitchDeg) {
  const tv = Math.tan((fovDeg / 2) * DEG);
  const th = tv * aspect;
  const p = Math.abs(pitchDeg) * DEG;
  // The corner on the pole's side: camera ray (th, tv, -1) turned up by p.
  const forward = Math.cos(p) - tv * Math.sin(p);
  if (forward <= 0) return 180;
  return Math.atan2(th, forward) / DEG;
}

function reachesTop(limits) {
  return isFullCircle(limits.yawDeg) && limits.pitchDeg[1] >= 90 - 1e-6;
}

function reachesBottom(limits) {
  return isFullCircle(limits.yawDeg) && limits.pitchDeg[0] <= -90 + 1e-6;
}

/** The pitches a view of field of view `fovDeg` may take: [lo, hi] (lo > hi: none). */
export function pitchRange(limits, fovDeg) {
  const v = fovDeg / 2 + limits.marginDeg;
  const lo = reachesBottom(limits) ? -MAX_PITCH_DEG : limits.pitchDeg[0] + v;
  const hi = reachesTop(limits) ? MAX_PITCH_DEG : limits.pitchDeg[1] - v;
  return [lo, hi];
}

/**
 * Half the yaw range (degrees, around the content's centre longitude) a
 * view may take at `pitchDeg`; Infinity for content all around, negative when
 * the view is wider than the content.
 */
export function yawAllowance(limits, fovDeg, aspect, pitchDeg) {
  if (isFullCircle(limits.yawDeg)) return Infinity;
  const half = (limits.yawDeg[1] - limits.yawDeg[0]) / 2;
  return half - yawHalfExtentDeg(fovDeg, aspect, pitchDeg) - limits.marginDeg;
}

/** The centre longitude of the content. */
export function contentCentreYaw(limits) {
  return wrapDeg((limits.yawDeg[0] + limits.yawDeg[1]) / 2);
}

/**
 * The largest field of view (degrees) whose view fits inside the content at
 * this aspect, within [minFovDeg, maxFovDeg]; minFovDeg when even that does
 * not fit (the view is then centred on the content).
 */
export function maxFovDeg(limits, aspect) {
  const fits = (fov) => {
    const [lo, hi] = pitchRange(limits, fov);
    if (lo > hi) return false;
    const pitch = Math.min(hi, Math.max(lo, 0));  // Least yaw extent.
    return yawAllowance(limits, fov, aspect, pitch) >= 0;
  };
  let a = limits.minFovDeg, b = limits.maxFovDeg;
  if (fits(b)) return b;
  if (!fits(a)) return a;
  for (let i = 0; i < 30; ++i) {
    const m = (a + b) / 2;
    if (fits(m)) a = m;
    else b = m;
  }
  return a;
}

/**
 * The pitches at which a view of field of view `fovDeg` fits inside the
 * content: pitchRange, narrowed where the view, wider in longitude away from
 * the horizon (yawHalfExtentDeg), would no longer fit between the content's
 * longitudes. [lo, hi], lo > hi when none.
 */
export function fittingPitchRange(limits, fovDeg, aspect) {
  const [lo, hi] = pitchRange(limits, fovDeg);
  if (isFullCircle(limits.yawDeg) || lo > hi) return [lo, hi];
  const fitsAt = (pitch) => yawAllowance(limits, fovDeg, aspect, pitch) >= 0;
  const least = Math.min(hi, Math.max(lo, 0));  // The pitch of least longitude extent.
  if (!fitsAt(least)) return [lo, hi];  // Fits nowhere: clampView centres it.
  // The extent grows with |pitch|: bisect each side for the last pitch that fits.
  const edge = (end) => {
    if (fitsAt(end)) return end;
    let a = least, b = end;
    for (let i = 0; i < 40; ++i) {
      const m = (a + b) / 2;
      if (fitsAt(m)) a = m;
      else b = m;
    }
    return a;
  };
  return [edge(lo), edge(hi)];
}

/**
 * The nearest view inside the content: the field of view clamped to
 * [minFovDeg, maxFovDeg(limits, aspect)], then the pitch, then the yaw (its
 * range depends on the pitch). Where the content is narrower than the view
 * the view is centred on it.
 */
export function clampView({ yawDeg, pitchDeg, fovDeg }, limits, aspect) {
  const fov = Math.min(maxFovDeg(limits, aspect), Math.max(limits.minFovDeg, fovDeg));
  const [lo, hi] = fittingPitchRange(limits, fov, aspect);
  const pitch = lo > hi
    ? Math.min(MAX_PITCH_DEG, Math.max(-MAX_PITCH_DEG, (limits.pitchDeg[0] + limits.pitchDeg[1]) / 2))
    : Math.min(hi, Math.max(lo, pitchDeg));
  const allowance = yawAllowance(limits, fov, aspect, pitch);
  let yaw = wrapDeg(yawDeg);
  if (allowance !== Infinity) {
    const c = contentCentreYaw(limits);
    const d = wrapDeg(yaw - c);
    yaw = wrapDeg(c + (allowance < 0 ? 0 : Math.min(allowance, Math.max(-allowance, d))));
  }
  return { yawDeg: yaw, pitchDeg: pitch, fovDeg: fov };
}

/**
 * Moves `value` by `delta` against a soft limit [lo, hi] (lo > hi: the point
 * (lo + hi) / 2): inside, freely; past a limit, each further unit moves it by
 * (1 - over / range)^2, so the overshoot `over` approaches `range` and never
 * reaches it. Moves back towards the interval are free. The result does not
 * depend on how the move is split into steps.
 */
export function resist(value, delta, lo, hi, range) {
  if (lo > hi) lo = hi = (lo + hi) / 2;
  if (delta === 0 || !(range > 0)) return value + delta;
  const sign = delta > 0 ? 1 : -1;
  const limit = sign > 0 ? hi : lo;
  const free = Math.max(0, sign * (limit - value));  // Distance to the limit, if inside.
  if (Math.abs(delta) <= free) return value + delta;
  const over0 = Math.max(0, sign * (value - limit));
  const push = Math.abs(delta) - free;
  // d(over)/d(push) = u^2 with u = 1 - over / range  =>  1/u = 1/u0 + push / range.
  const u0 = Math.max(1e-9, 1 - over0 / range);
  const u = 1 / (1 / u0 + push / range);
  return limit + sign * range * (1 - u);
}

/** The fraction of the way to the limits the view eases in `dtSec` seconds. */
export function easeFactor(dtSec, tauSec = EASE_TIME_S) {
  return 1 - Math.exp(-Math.max(0, dtSec) / tauSec);
}

/**
 * One step of the ease back: `view` moved by `factor` of the way to
 * clampView(view) (yaw along the shorter arc). Returns the new view and
 * whether it is (within 1e-3 degrees) inside the limits.
 */
export function easeView(view, limits, aspect, factor) {
  const target = clampView(view, limits, aspect);
  const dYaw = wrapDeg(target.yawDeg - view.yawDeg);
  const dPitch = target.pitchDeg - view.pitchDeg;
  const dFov = target.fovDeg - view.fovDeg;
  if (Math.abs(dYaw) < 1e-3 && Math.abs(dPitch) < 1e-3 && Math.abs(dFov) < 1e-3) return { view: target, settled: true };
  return {
    view: {
      yawDeg: wrapDeg(view.yawDeg + dYaw * factor),
      pitchDeg: view.pitchDeg + dPitch * factor,
      fovDeg: view.fovDeg + dFov * factor,
    },
    settled: false,
  };
}
