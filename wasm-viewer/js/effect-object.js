// Effect "object": a small lit cube inserted into the scene, hidden by the
// photo's nearer geometry (the depth test against the mesh). An effect module
// (effects.js): name, toolbar label and title, defaults (the fields it
// adds to the viewer's effects state), init, draw and dispose.

/** A cube of edge `size` centred at the origin: positions, normals, indices. */
function cubeGeometry(size) {
  const h = size / 2;
  const faces = [
    [[1, 0, 0], [0, 1, 0], [0, 0, 1]], [[-1, 0, 0], [0, 1, 0], [0, 0, -1]],
    [[0, 1, 0], [0, 0, 1], [1, 0, 0]], [[0, -1, 0], [0, 0, -1], [1, 0, 0]],
    [[0, 0, 1], [1, 0, 0], [0, 1, 0]], [[0, 0, -1], [-1, 0, 0], [0, 1, 0]],
  ];
  const positions = [], normals = [], indices = [];
  for (const [n, a, b] of faces) {
    const base = positions.length / 3;
    for (const [s, t] of [[-1, -1], [1, -1], [1, 1], [-1, 1]]) {
      for (let k = 0; k < 3; ++k) positions.push((n[k] + s * a[k] + t * b[k]) * h);
      normals.push(...n);
    }
    indices.push(base, base + 1, base + 2, base, base + 2, base + 3);
  }
  return { positions: new Float32Array(positions), normals: new Float32Array(normals), indices: new Uint32Array(indices) };
}

// The fragment shader; `lighting` is the renderer's shared shade() code.
function fragmentShader(lighting) {
  return `#version 300 es
precision highp float;
in vec3 vPosition;
in vec3 vNormal;
in vec2 vUv;
uniform vec3 uColor;
${lighting}
out vec4 fragColor;
void main() {
  fragColor = vec4(shade(uColor, vPosition, vNormal), 1.0);
}`;
}

export default {
  name: 'object',
  label: 'Object',
  title: 'Inserted object',
  defaults: {
    object: false,
    objectPosition: [0.6, -0.4, -2.5],  // Centre (m, panorama frame).
    objectSize: 0.3,                    // Cube edge (m).
  },

  /** @param ctx {gl, program(fragmentSource), upload(geometry), lighting} */
  init(ctx) {
    return { program: ctx.program(fragmentShader(ctx.lighting)), cube: ctx.upload(cubeGeometry(1)) };
  },

  /** @param ctx {gl, effects, eye, timeSec, setCommon(program, lightCount, model)} */
  draw(state, ctx) {
    const { gl, effects, eye } = ctx;
    const p = state.program;
    gl.useProgram(p.program);
    const s = effects.objectSize ?? this.defaults.objectSize;
    const [ox, oy, oz] = effects.objectPosition ?? this.defaults.objectPosition;
    ctx.setCommon(p, 2, new Float32Array([s, 0, 0, 0, 0, s, 0, 0, 0, 0, s, 0, ox, oy, oz, 1]));
    if (!effects.lighting) {
      // Without the moving lights the object gets a fixed key light above the eye.
      gl.uniform3fv(p.uniforms.uLightPosition, new Float32Array([eye[0] + 1, eye[1] + 2, eye[2] + 1, ...new Array(9).fill(0)]));
      gl.uniform3fv(p.uniforms.uLightColor, new Float32Array([1.3, 1.3, 1.3, ...new Array(9).fill(0)]));
      gl.uniform1i(p.uniforms.uLightCount, 1);
    }
    gl.uniform1f(p.uniforms.uAmbient, 0.35);
    gl.uniform3fv(p.uniforms.uColor, [0.95, 0.75, 0.1]);
    gl.bindVertexArray(state.cube.vao);
    gl.drawElements(gl.TRIANGLES, state.cube.count, gl.UNSIGNED_INT, 0);
  },

  /** @param ctx {gl, release(geometry)} */
  dispose(state, ctx) {
    ctx.release(state.cube);
    ctx.gl.deleteProgram(state.program.program);
  },
};
