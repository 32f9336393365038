// Effect "water": a transparent rippling water surface rising and falling
// through the scene, tested against the photo's depth but not written to it.
// An effect module (effects.js).

const FRAGMENT_SHADER = `#version 300 es
precision highp float;
in vec3 vPosition;
in vec3 vNormal;
in vec2 vUv;
uniform float uTime;
uniform vec3 uEye;
out vec4 fragColor;
void main() {
  // Small moving ripples and a Fresnel-like rise of opacity at grazing angles.
  vec2 p = vPosition.xz;
  float ripple = 0.5 + 0.25 * sin(p.x * 3.1 + uTime * 1.7) + 0.25 * sin(p.y * 2.3 - uTime * 1.3);
  vec3 toEye = normalize(uEye - vPosition);
  float grazing = 1.0 - abs(toEye.y);
  vec3 color = mix(vec3(0.05, 0.22, 0.35), vec3(0.35, 0.6, 0.75), ripple * 0.6 + grazing * 0.4);
  fragColor = vec4(color, 0.55 + 0.35 * grazing);
}`;

const HALF_EXTENT = 1000;  // Plane half-extent (m); far beyond any scene.

export default {
  name: 'water',
  label: 'Water',
  title: 'Rising water',
  defaults: {
    water: false,
    waterMinY: -1.6,  // Lowest water level (m, panorama Y).
    waterMaxY: -0.4,  // Highest water level (m).
  },

  /** @param ctx {gl, program(fragmentSource), upload(geometry), lighting} */
  init(ctx) {
    const r = HALF_EXTENT;
    return {
      program: ctx.program(FRAGMENT_SHADER),
      plane: ctx.upload({
        positions: new Float32Array([-r, 0, -r, r, 0, -r, r, 0, r, -r, 0, r]),
        normals: new Float32Array([0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0]),
        indices: new Uint32Array([0, 2, 1, 0, 3, 2]),
      }),
    };
  },

  /** @param ctx {gl, effects, eye, timeSec, setCommon(program, lightCount, model)} */
  draw(state, ctx) {
    const { gl, effects, timeSec } = ctx;
    const lo = effects.waterMinY ?? this.defaults.waterMinY;
    const hi = effects.waterMaxY ?? this.defaults.waterMaxY;
    const level = lo + (hi - lo) * (0.5 - 0.5 * Math.cos(timeSec * 0.4));
    gl.useProgram(state.program.program);
    ctx.setCommon(state.program, 0, new Float32Array([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, level, 0, 1]));
    gl.uniform1f(state.program.uniforms.uTime, timeSec);
    gl.enable(gl.BLEND);
    gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA);
    gl.depthMask(false);  // Transparent: tested against the photo's depth, not written.
    gl.bindVertexArray(state.plane.vao);
    gl.drawElements(gl.TRIANGLES, state.plane.count, gl.UNSIGNED_INT, 0);
    gl.depthMask(true);
    gl.disable(gl.BLEND);
  },

  /** @param ctx {gl, release(geometry)} */
  dispose(state, ctx) {
    ctx.release(state.plane);
    ctx.gl.deleteProgram(state.program.program);
  },
};
