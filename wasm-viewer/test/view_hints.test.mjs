// Node tests of the viewer's plain view logic: the manifest's "view" member
// (view-hints.js parseViewHints), hints derived from a level's presence
// (contentBox, deriveViewHints, narrowContent), the soft limits
// (view-limits.js) and the soft background (environment.js).

import assert from 'node:assert/strict';
import { test } from 'node:test';

import { buildEnvironment } from '../js/environment.js';
import {
  contentBox, deriveViewHints, DERIVED_VOLUME_FRACTION, intersectYaw, narrowContent, parseViewHints, wrapDeg,
} from '../js/view-hints.js';
import {
  clampView, easeFactor, easeView, maxFovDeg, pitchRange, resist, yawHalfExtentDeg,
} from '../js/view-limits.js';

const VIEW = Object.freeze({
  yaw_deg: -12.5, pitch_deg: 3, fov_deg: 62, content_yaw_deg: [-60, 35], content_pitch_deg: [-40, 45],
  volume_radius: 0.12, metric: false,
});

const near = (a, b, tol = 1e-6) => Math.abs(a - b) <= tol;

test('parseViewHints accepts the spec example and maps it to camelCase', () => {
  const { hints, warning } = parseViewHints({ ...VIEW, unknown_member: 1 });
  assert.equal(warning, null);
  assert.deepEqual(hints, {
    yawDeg: -12.5, pitchDeg: 3, fovDeg: 62, contentYawDeg: [-60, 35], contentPitchDeg: [-40, 45],
    volumeRadius: 0.12, metric: false, nearDepth: 0, source: 'package',
  });
  assert.equal(parseViewHints({ ...VIEW, metric: true }).hints.metric, true);
  assert.deepEqual(parseViewHints({ ...VIEW, content_yaw_deg: [-360, 0] }).hints.contentYawDeg, [-360, 0]);
});

test('parseViewHints: an absent member is no hint and no warning', () => {
  assert.deepEqual(parseViewHints(undefined), { hints: null, warning: null });
});

test('parseViewHints ignores malformed or out-of-range members with a warning naming the field', () => {
  const cases = [
    [null, /not an object/],
    [[1, 2], /not an object/],
    ['view', /not an object/],
    [{ ...VIEW, yaw_deg: 181 }, /yaw_deg 181 is outside \[-180, 180\]/],
    [{ ...VIEW, yaw_deg: '10' }, /yaw_deg is not a finite number/],
    [{ ...VIEW, pitch_deg: -90.5 }, /pitch_deg/],
    [{ ...VIEW, fov_deg: 9 }, /fov_deg 9 is outside \[10, 120\]/],
    [{ ...VIEW, fov_deg: 121 }, /fov_deg/],
    [{ ...VIEW, content_yaw_deg: [35, -60] }, /content_yaw_deg \[35, -60\] is not an interval/],
    [{ ...VIEW, content_yaw_deg: [-361, 0] }, /content_yaw_deg/],
    [{ ...VIEW, content_yaw_deg: [-200, 200] }, /spans more than 360/],
    [{ ...VIEW, content_yaw_deg: [0] }, /content_yaw_deg is not an array of two finite numbers/],
    [{ ...VIEW, content_pitch_deg: [-40, 91] }, /content_pitch_deg/],
    [{ ...VIEW, content_pitch_deg: [10, 'x'] }, /content_pitch_deg/],
    [{ ...VIEW, volume_radius: 0 }, /volume_radius 0 is outside \(0,/],
    [{ ...VIEW, volume_radius: -1 }, /volume_radius/],
    [{ ...VIEW, volume_radius: Infinity }, /volume_radius is not a finite number/],
    [{ ...VIEW, metric: 'yes' }, /metric is not a boolean/],
    [{ ...VIEW, metric: undefined }, /metric is not a boolean/],
    [{ pitch_deg: 0 }, /yaw_deg is not a finite number.*fov_deg/],
  ];
  for (const [view, pattern] of cases) {
    const { hints, warning } = parseViewHints(view);
    assert.equal(hints, null, JSON.stringify(view));
    assert.match(warning, /^manifest\.json: "view" ignored: /);
    assert.match(warning, pattern, JSON.stringify(view));
  }
});

/** A presence grid with nodes inside [lon0, lon1] x [lat0, lat1] (degrees), optional holes. */
function grid(width, height, [lon0, lon1], [lat0, lat1], hole = () => false) {
  const p = new Uint8Array(width * height);
  for (let y = 0; y < height; ++y) {
    const lat = 90 - ((y + 0.5) / height) * 180;
    for (let x = 0; x < width; ++x) {
      const lon = ((x + 0.5) / width - 0.5) * 360;
      const inLon = lon0 <= lon1 ? lon >= lon0 && lon <= lon1 : lon >= lon0 || lon <= lon1;
      if (inLon && lat >= lat0 && lat <= lat1 && !hole(x, y)) p[y * width + x] = 1;
    }
  }
  return p;
}

test('contentBox: a rectangle, a rectangle across the seam, the whole sphere, nothing', () => {
  // Borders run through the outermost nodes' centres (half a cell inside).
  const box = contentBox(grid(360, 180, [-60, 35], [-40, 45]), 360, 180);
  assert.deepEqual(box, { yawDeg: [-59.5, 34.5], pitchDeg: [-39.5, 44.5] });
  const seam = contentBox(grid(360, 180, [150, -160], [-10, 20]), 360, 180);
  assert.deepEqual(seam, { yawDeg: [150.5, 199.5], pitchDeg: [-9.5, 19.5] });
  // Content up to a pole reaches it.
  assert.deepEqual(contentBox(grid(360, 180, [-60, 35], [-40, 90]), 360, 180).pitchDeg, [-39.5, 90]);
  assert.deepEqual(contentBox(new Uint8Array(64 * 32).fill(1), 64, 32), { yawDeg: [-180, 180], pitchDeg: [-90, 90] });
  assert.equal(contentBox(new Uint8Array(64 * 32), 64, 32), null);
});

test('contentBox peels sparse, ragged borders down to a well covered box', () => {
  // Content [-60, 35] x [-40, 45] plus a ragged fringe of scattered nodes to
  // the left (every third row) and a few stray nodes far above.
  const p = grid(360, 180, [-60, 35], [-40, 45]);
  for (let y = 45; y < 135; y += 3) for (let x = 100; x < 120; ++x) p[y * 360 + x] = 1;
  p[5 * 360 + 200] = 1;
  const box = contentBox(p, 360, 180);
  assert.ok(box.yawDeg[0] >= -60 && box.yawDeg[0] <= -58.5, JSON.stringify(box));
  assert.deepEqual(box.pitchDeg, [-39.5, 44.5]);
  // Holes inside (tears) within the coverage threshold do not shrink the box.
  const holes = grid(360, 180, [-60, 35], [-40, 45], (x, y) => (x * 7 + y * 13) % 100 === 0);
  assert.deepEqual(contentBox(holes, 360, 180), { yawDeg: [-59.5, 34.5], pitchDeg: [-39.5, 44.5] });
});

test('deriveViewHints frames the content and scales the volume with the near depth', () => {
  const presence = grid(256, 128, [-60, 40], [-30, 50]);
  const depths = Float32Array.from({ length: 1000 }, (_, i) => 2 + i / 100);  // 2 .. 12
  const h = deriveViewHints({ presence, depths, width: 256, height: 128 });
  assert.equal(h.source, 'derived');
  assert.ok(near(h.contentYawDeg[0], -60, 1.5) && near(h.contentYawDeg[1], 40, 1.5), JSON.stringify(h));
  assert.ok(near(h.yawDeg, -10, 1.5) && near(h.pitchDeg, 10, 1.5), JSON.stringify(h));
  assert.ok(h.fovDeg <= 75 && h.fovDeg >= 10);
  assert.ok(near(h.nearDepth, 2.5, 0.02), `near depth ${h.nearDepth}`);
  assert.ok(near(h.volumeRadius, DERIVED_VOLUME_FRACTION * h.nearDepth, 1e-6));
  // Ten times the scale: ten times the volume.
  const far = deriveViewHints({ presence, depths: depths.map((d) => 10 * d), width: 256, height: 128 });
  assert.ok(near(far.volumeRadius, 10 * h.volumeRadius, 1e-4));
  // A full sphere opens like the classic viewer: yaw 0, pitch 0, 75 degrees.
  const full = deriveViewHints({ presence: new Uint8Array(64 * 32).fill(1), depths, width: 64, height: 32 });
  assert.deepEqual([full.yawDeg, full.pitchDeg, full.fovDeg], [0, 0, 75]);
});

test('intersectYaw and narrowContent work modulo 360', () => {
  assert.deepEqual(intersectYaw([-60, 35], [-50, 100]), [-50, 35]);
  assert.deepEqual(intersectYaw([300, 400], [-50, 20]), [-50, 20]);
  assert.deepEqual(intersectYaw([-180, 180], [10, 20]), [10, 20]);
  assert.equal(intersectYaw([0, 10], [100, 120]), null);
  const hints = parseViewHints(VIEW).hints;
  const measured = { contentYawDeg: [-50, 60], contentPitchDeg: [-30, 80], nearDepth: 1.7 };
  const n = narrowContent(hints, measured);
  assert.deepEqual([n.contentYawDeg, n.contentPitchDeg, n.nearDepth], [[-50, 35], [-30, 45], 1.7]);
  assert.deepEqual([n.yawDeg, n.fovDeg, n.volumeRadius], [hints.yawDeg, hints.fovDeg, hints.volumeRadius]);
  // No overlap: the package's box stays.
  const apart = narrowContent(hints, { contentYawDeg: [100, 150], contentPitchDeg: [-30, 80], nearDepth: 1 });
  assert.deepEqual([apart.contentYawDeg, apart.contentPitchDeg], [[-60, 35], [-40, 45]]);
});

const LIMITS = Object.freeze({ yawDeg: [-60, 40], pitchDeg: [-40, 45], marginDeg: 2, minFovDeg: 20, maxFovDeg: 120 });

/** Whether a view's frustum (sampled) stays inside the limits' box. */
function frustumInside({ yawDeg, pitchDeg, fovDeg }, limits, aspect, tol = 0.05) {
  const tv = Math.tan((fovDeg / 2) * Math.PI / 180), th = tv * aspect;
  const p = pitchDeg * Math.PI / 180, yaw = yawDeg * Math.PI / 180;
  for (let i = 0; i <= 20; ++i) {
    for (let j = 0; j <= 20; ++j) {
      if (i !== 0 && i !== 20 && j !== 0 && j !== 20) continue;
      const a = (i / 10 - 1) * th, b = (j / 10 - 1) * tv;
      // Camera ray (a, b, -1) turned up by p, then about +Y by yaw.
      const y = b * Math.cos(p) + Math.sin(p), z0 = b * Math.sin(p) - Math.cos(p);
      const lon = yaw + Math.atan2(a, -z0);
      const lat = Math.atan2(y, Math.hypot(a, z0));
      const lonDeg = wrapDeg(lon * 180 / Math.PI - (limits.yawDeg[0] + limits.yawDeg[1]) / 2);
      const half = (limits.yawDeg[1] - limits.yawDeg[0]) / 2;
      if (Math.abs(lonDeg) > half + tol) return false;
      const latDeg = lat * 180 / Math.PI;
      if (latDeg < limits.pitchDeg[0] - tol || latDeg > limits.pitchDeg[1] + tol) return false;
    }
  }
  return true;
}

test('yawHalfExtentDeg: the horizontal half field of view at the horizon, wider looking up, 180 over a pole', () => {
  assert.ok(near(yawHalfExtentDeg(60, 1, 0), 30, 1e-9));
  assert.ok(near(yawHalfExtentDeg(60, 16 / 9, 0), Math.atan(Math.tan(Math.PI / 6) * 16 / 9) * 180 / Math.PI, 1e-9));
  assert.ok(yawHalfExtentDeg(60, 1.6, 30) > yawHalfExtentDeg(60, 1.6, 0));
  assert.equal(yawHalfExtentDeg(60, 1.6, 70), 180);
  assert.equal(yawHalfExtentDeg(60, 1.6, -70), 180);
});

test('clampView keeps the whole frustum inside the content at every aspect', () => {
  for (const aspect of [0.6, 1, 1.6, 2.4]) {
    for (const fov of [20, 40, 60, 90, 120]) {
      for (const yaw of [-170, -80, -10, 0, 30, 90, 179]) {
        for (const pitch of [-80, -30, 0, 20, 60]) {
          const v = clampView({ yawDeg: yaw, pitchDeg: pitch, fovDeg: fov }, LIMITS, aspect);
          assert.ok(v.fovDeg <= fov + 1e-9 && v.fovDeg >= 20);
          // Inside the box shrunk by the margin (when the view fits at all).
          const shrunk = { yawDeg: [-58, 38], pitchDeg: [-38, 43] };
          if (v.fovDeg > 20 || maxFovDeg(LIMITS, aspect) > 20) {
            assert.ok(frustumInside(v, shrunk, aspect), `aspect ${aspect} fov ${fov} yaw ${yaw} pitch ${pitch}: ${JSON.stringify(v)}`);
          }
          // Already inside: unchanged.
          const again = clampView(v, LIMITS, aspect);
          assert.ok(near(again.yawDeg, v.yawDeg, 1e-9) && near(again.pitchDeg, v.pitchDeg, 1e-9) && near(again.fovDeg, v.fovDeg, 1e-9));
        }
      }
    }
  }
  // A view inside is left alone.
  assert.deepEqual(clampView({ yawDeg: -10, pitchDeg: 2, fovDeg: 40 }, LIMITS, 1.6), { yawDeg: -10, pitchDeg: 2, fovDeg: 40 });
});

test('clampView: content narrower than the view centres it; full spheres limit nothing', () => {
  const narrow = { yawDeg: [10, 30], pitchDeg: [-5, 5], marginDeg: 0, minFovDeg: 20, maxFovDeg: 120 };
  const v = clampView({ yawDeg: 100, pitchDeg: 40, fovDeg: 75 }, narrow, 1.6);
  assert.deepEqual(v, { yawDeg: 20, pitchDeg: 0, fovDeg: 20 });
  const sphere = { yawDeg: [-180, 180], pitchDeg: [-90, 90], marginDeg: 3, minFovDeg: 20, maxFovDeg: 120 };
  assert.deepEqual(clampView({ yawDeg: 170, pitchDeg: 80, fovDeg: 110 }, sphere, 1.6), { yawDeg: 170, pitchDeg: 80, fovDeg: 110 });
  assert.equal(maxFovDeg(sphere, 1.6), 120);
  // All around but not up to the poles (a cylinder): pitch limited, yaw free.
  const band = { yawDeg: [-180, 180], pitchDeg: [-30, 40], marginDeg: 0, minFovDeg: 20, maxFovDeg: 120 };
  const b = clampView({ yawDeg: -175, pitchDeg: 60, fovDeg: 50 }, band, 1.6);
  assert.deepEqual(b, { yawDeg: -175, pitchDeg: 15, fovDeg: 50 });
  assert.deepEqual(pitchRange(band, 50), [-5, 15]);
});

test('resist: free inside, diminishing past a limit, never beyond the range, independent of steps', () => {
  assert.equal(resist(0, 5, -10, 10, 4), 5);
  assert.equal(resist(0, -5, -10, 10, 4), -5);
  const one = resist(8, 10, -10, 10, 4);
  assert.ok(one > 10 && one < 14, String(one));
  let stepped = 8;
  for (let i = 0; i < 100; ++i) stepped = resist(stepped, 0.1, -10, 10, 4);
  assert.ok(near(stepped, one, 1e-9), `${stepped} vs ${one}`);
  assert.ok(resist(10, 1e9, -10, 10, 4) < 14);
  assert.ok(resist(-10, -1e9, -10, 10, 4) > -14);
  assert.equal(resist(13, -2, -10, 10, 4), 11, 'back towards the interval: free');
  assert.ok(resist(0, 1, 5, -5, 2) > 0 && resist(0, 1, 5, -5, 2) < 2, 'an empty interval resists around its centre');
});

test('easeView converges to clampView', () => {
  let view = { yawDeg: 40, pitchDeg: 30, fovDeg: 110 };
  const target = clampView(view, LIMITS, 1.6);
  let settled = false;
  for (let i = 0; i < 200 && !settled; ++i) ({ view, settled } = easeView(view, LIMITS, 1.6, easeFactor(1 / 60)));
  assert.ok(settled);
  assert.deepEqual(view, target);
  assert.ok(easeFactor(0.12) > 0.6 && easeFactor(0.12) < 0.7);
});

test('buildEnvironment continues the border colour into the void and blurs it', () => {
  // A 128 x 64 level: red content on the left half of the front layer, nothing elsewhere.
  const w = 128, h = 64;
  const atlas = { width: w, height: 2 * h, data: new Uint8Array(w * 2 * h * 4) };
  const presence = new Uint8Array(w * h);
  for (let y = 0; y < h; ++y) {
    for (let x = 0; x < w / 2; ++x) {
      presence[y * w + x] = 1;
      atlas.data.set([200, 40, 20, 255], (y * w + x) * 4);
    }
  }
  const env = buildEnvironment(atlas, presence);
  assert.equal(env.data.length, env.width * env.height * 4);
  // No black anywhere: the void is filled with the content's colour.
  for (let i = 0; i < env.data.length; i += 4) {
    assert.ok(Math.abs(env.data[i] - 200) <= 2 && Math.abs(env.data[i + 1] - 40) <= 2, `texel ${i / 4}`);
    assert.equal(env.data[i + 3], 255);
  }
  // Two colours: the boundary between them is blurred over several texels.
  for (let y = 0; y < h; ++y) for (let x = w / 4; x < w / 2; ++x) atlas.data.set([20, 40, 200, 255], (y * w + x) * 4);
  const two = buildEnvironment(atlas, presence);
  const row = 16, red = (x) => two.data[(row * two.width + x) * 4];
  const ramp = [];
  for (let x = 0; x < two.width / 2; ++x) if (red(x) > 30 && red(x) < 190) ramp.push(x);
  assert.ok(ramp.length >= 6, `blurred over ${ramp.length} texels`);
  // Empty input: black, no exception.
  const none = buildEnvironment(atlas, new Uint8Array(w * h));
  assert.ok(none.data.every((v, i) => (i % 4 === 3 ? v === 255 : v === 0)));
});
