// Camera of the 3D photo viewer and the little matrix maths it needs.
//
// Conventions (the panorama frame of format/equirect.h: +X right, +Y up, -Z
// forward): yaw and pitch are the longitude and latitude of the viewing
// direction, so yaw 0, pitch 0 looks along -Z, yaw +90 deg looks along +X and
// pitch +90 deg looks up (+Y); roll is always 0 (the up vector is +Y). The
// vertical field of view is in degrees. `position` is the eye in the panorama
// frame, in the unit of the package's depths (metres when known); motion
// parallax keeps it inside a ball of radius `maxOffset` around the centre
// (the package's viewing volume, where the photo was captured). Matrices are column-major
// Float32Array(16) as WebGL expects; clip space is OpenGL's (z in [-1, 1]).

const DEG = Math.PI / 180;

/** Unit direction for yaw/pitch in radians (format/equirect.h LonLatToDirection). */
export function directionFromYawPitch(yawRad, pitchRad) {
  const c = Math.cos(pitchRad);
  return [c * Math.sin(yawRad), Math.sin(pitchRad), -c * Math.cos(yawRad)];
}

/** Column-major perspective matrix (OpenGL clip space). */
export function perspective(fovYDeg, aspect, near, far) {
  const f = 1 / Math.tan((fovYDeg * DEG) / 2);
  const m = new Float32Array(16);
  m[0] = f / aspect;
  m[5] = f;
  m[10] = (far + near) / (near - far);
  m[11] = -1;
  m[14] = (2 * far * near) / (near - far);
  return m;
}

/** Column-major view matrix for an eye at `eye` looking along unit `forward`, up +Y. */
export function lookAlong(eye, forward) {
  const [fx, fy, fz] = forward;
  // right = forward x up(0,1,0), normalised; falls back near the poles.
  let rx = -fz, ry = 0, rz = fx;
  let rl = Math.hypot(rx, rz);
  if (rl < 1e-9) { rx = 1; rz = 0; rl = 1; }
  rx /= rl; rz /= rl;
  // up = right x forward
  const ux = ry * fz - rz * fy, uy = rz * fx - rx * fz, uz = rx * fy - ry * fx;
  const m = new Float32Array(16);
  m[0] = rx; m[4] = ry; m[8] = rz;
  m[1] = ux; m[5] = uy; m[9] = uz;
  m[2] = -fx; m[6] = -fy; m[10] = -fz;
  m[12] = -(rx * eye[0] + ry * eye[1] + rz * eye[2]);
  m[13] = -(ux * eye[0] + uy * eye[1] + uz * eye[2]);
  m[14] = fx * eye[0] + fy * eye[1] + fz * eye[2];
  m[15] = 1;
  return m;
}

/** a * b for column-major 4x4 matrices. */
export function multiply(a, b) {
  const m = new Float32Array(16);
  for (let c = 0; c < 4; ++c) {
    for (let r = 0; r < 4; ++r) {
      let s = 0;
      for (let k = 0; k < 4; ++k) s += a[k * 4 + r] * b[c * 4 + k];
      m[c * 4 + r] = s;
    }
  }
  return m;
}

/** Inverse of a column-major 4x4 matrix (cofactors); the identity if singular. */
export function invert(m) {
  const inv = new Float32Array(16);
  inv[0] = m[5] * m[10] * m[15] - m[5] * m[11] * m[14] - m[9] * m[6] * m[15] + m[9] * m[7] * m[14] + m[13] * m[6] * m[11] - m[13] * m[7] * m[10];
  inv[4] = -m[4] * m[10] * m[15] + m[4] * m[11] * m[14] + m[8] * m[6] * m[15] - m[8] * m[7] * m[14] - m[12] * m[6] * m[11] + m[12] * m[7] * m[10];
  inv[8] = m[4] * m[9] * m[15] - m[4] * m[11] * m[13] - m[8] * m[5] * m[15] + m[8] * m[7] * m[13] + m[12] * m[5] * m[11] - m[12] * m[7] * m[9];
  inv[12] = -m[4] * m[9] * m[14] + m[4] * m[10] * m[13] + m[8] * m[5] * m[14] - m[8] * m[6] * m[13] - m[12] * m[5] * m[10] + m[12] * m[6] * m[9];
  inv[1] = -m[1] * m[10] * m[15] + m[1] * m[11] * m[14] + m[9] * m[2] * m[15] - m[9] * m[3] * m[14] - m[13] * m[2] * m[11] + m[13] * m[3] * m[10];
  inv[5] = m[0] * m[10] * m[15] - m[0] * m[11] * m[14] - m[8] * m[2] * m[15] + m[8] * m[3] * m[14] + m[12] * m[2] * m[11] - m[12] * m[3] * m[10];
  inv[9] = -m[0] * m[9] * m[15] + m[0] * m[11] * m[13] + m[8] * m[1] * m[15] - m[8] * m[3] * m[13] - m[12] * m[1] * m[11] + m[12] * m[3] * m[9];
  inv[13] = m[0] * m[9] * m[14] - m[0] * m[10] * m[13] - m[8] * m[1] * m[14] + m[8] * m[2] * m[13] + m[12] * m[1] * m[10] - m[12] * m[2] * m[9];
  inv[2] = m[1] * m[6] * m[15] - m[1] * m[7] * m[14] - m[5] * m[2] * m[15] + m[5] * m[3] * m[14] + m[13] * m[2] * m[7] - m[13] * m[3] * m[6];
  inv[6] = -m[0] * m[6] * m[15] + m[0] * m[7] * m[14] + m[4] * m[2] * m[15] - m[4] * m[3] * m[14] - m[12] * m[2] * m[7] + m[12] * m[3] * m[6];
  inv[10] = m[0] * m[5] * m[15] - m[0] * m[7] * m[13] - m[4] * m[1] * m[15] + m[4] * m[3] * m[13] + m[12] * m[1] * m[7] - m[12] * m[3] * m[5];
  inv[14] = -m[0] * m[5] * m[14] + m[0] * m[6] * m[13] + m[4] * m[1] * m[14] - m[4] * m[2] * m[13] - m[12] * m[1] * m[6] + m[12] * m[2] * m[5];
  inv[3] = -m[1] * m[6] * m[11] + m[1] * m[7] * m[10] + m[5] * m[2] * m[11] - m[5] * m[3] * m[10] - m[9] * m[2] * m[7] + m[9] * m[3] * m[6];
  inv[7] = m[0] * m[6] * m[11] - m[0] * m[7] * m[10] - m[4] * m[2] * m[11] + m[4] * m[3] * m[10] + m[8] * m[2] * m[7] - m[8] * m[3] * m[6];
  inv[11] = -m[0] * m[5] * m[11] + m[0] * m[7] * m[9] + m[4] * m[1] * m[11] - m[4] * m[3] * m[9] - m[8] * m[1] * m[7] + m[8] * m[3] * m[5];
  inv[15] = m[0] * m[5] * m[10] - m[0] * m[6] * m[9] - m[4] * m[1] * m[10] + m[4] * m[2] * m[9] + m[8] * m[1] * m[6] - m[8] * m[2] * m[5];
  const det = m[0] * inv[0] + m[1] * inv[4] + m[2] * inv[8] + m[3] * inv[12];
  if (!det) return new Float32Array([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]);
  for (let i = 0; i < 16; ++i) inv[i] /= det;
  return inv;
}

/** Clamps v into [lo, hi]. */
export function clamp(v, lo, hi) {
  return Math.min(hi, Math.max(lo, v));
}

export const DEFAULT_CAMERA = Object.freeze({
  yawDeg: 0,
  pitchDeg: 0,
  fovDeg: 75,
  position: Object.freeze([0, 0, 0]),
});

/** Mutable camera state with the limits that keep the 3D photo believable. */
export class Camera {
  constructor(options = {}) {
    this.minFovDeg = options.minFovDeg ?? 20;
    this.maxFovDeg = options.maxFovDeg ?? 120;
    this.maxOffset = options.maxOffset ?? 0.3;  // Parallax ball radius, unit of the depths.
    this.near = options.near ?? 0.05;           // Metres.
    this.far = options.far ?? 2000;             // Metres.
    this.reset();
  }

  reset() {
    this.set(DEFAULT_CAMERA);
  }

  /** Sets any of yawDeg, pitchDeg, fovDeg, position; clamps to the limits. */
  set({ yawDeg, pitchDeg, fovDeg, position } = {}) {
    if (Number.isFinite(yawDeg)) this.yawDeg = ((((yawDeg + 180) % 360) + 360) % 360) - 180;
    if (Number.isFinite(pitchDeg)) this.pitchDeg = clamp(pitchDeg, -89.9, 89.9);
    if (Number.isFinite(fovDeg)) this.fovDeg = clamp(fovDeg, this.minFovDeg, this.maxFovDeg);
    if (position && position.length === 3 && position.every(Number.isFinite)) {
      const p = [position[0], position[1], position[2]];
      const len = Math.hypot(p[0], p[1], p[2]);
      if (len > this.maxOffset) for (let i = 0; i < 3; ++i) p[i] *= this.maxOffset / len;
      this.position = p;
    }
  }

  get() {
    return { yawDeg: this.yawDeg, pitchDeg: this.pitchDeg, fovDeg: this.fovDeg, position: [...this.position] };
  }

  forward() {
    return directionFromYawPitch(this.yawDeg * DEG, this.pitchDeg * DEG);
  }

  viewMatrix() {
    return lookAlong(this.position, this.forward());
  }

  projectionMatrix(aspect) {
    return perspective(this.fovDeg, aspect, this.near, this.far);
  }
}
