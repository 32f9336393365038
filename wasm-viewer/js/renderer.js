// WebGL2 renderer of a 3D photo mesh (format/mesh.h) with the effects of the
// paper's Fig. 1 and 11: moving point lights using the normals (nodes with a
// zero normal, the sky, stay unlit), a water surface rising through the scene
// and a small inserted object; both are depth-tested against the photo's mesh,
// so nearer scene geometry hides them correctly.
//
// Texturing: bilinear from the colour atlas (front colour panorama above the
// back one; every triangle's uvs lie in one half, spec/mesh.md Sec. 4.4), no
// mipmaps, no antialiasing: the same sampling as the project's native software
// renderer, so screenshots can be compared with its renders.
//
// Behind the mesh it draws the soft environment (environment.js) at infinite
// distance where one is set: a blurred continuation of the photo's colours
// instead of black where no surface is. `backgroundFraction` measures how
// much of a view no surface covers.

import { invert, multiply } from './camera.js';
import { EFFECTS } from './effects.js';

const SCENE_VS = `#version 300 es
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in vec2 aUv;
layout(location = 3) in vec4 aColor;  // Alpha 1: drawn in this colour (the backdrop), else textured.
uniform mat4 uViewProjection;
uniform mat4 uModel;  // Translation and uniform scale only.
out vec3 vPosition;
out vec3 vNormal;
out vec2 vUv;
out vec4 vColor;
void main() {
  vec4 world = uModel * vec4(aPosition, 1.0);
  vPosition = world.xyz;
  vNormal = aNormal;
  vUv = aUv;
  vColor = aColor;
  gl_Position = uViewProjection * world;
}`;

// Shared lighting: ambient plus point lights with 1/(1 + k d^2) falloff,
// two-sided (the normal is flipped towards the eye).
const LIGHTING = `
uniform int uLightCount;
uniform vec3 uLightPosition[4];
uniform vec3 uLightColor[4];
uniform float uAmbient;
uniform vec3 uEye;
vec3 shade(vec3 albedo, vec3 position, vec3 normal) {
  vec3 n = normalize(normal);
  if (dot(n, uEye - position) < 0.0) n = -n;
  vec3 sum = vec3(uAmbient);
  for (int i = 0; i < 4; ++i) {
    if (i >= uLightCount) break;
    vec3 toLight = uLightPosition[i] - position;
    float d = length(toLight);
    sum += uLightColor[i] * max(dot(n, toLight / d), 0.0) / (1.0 + 0.05 * d * d);
  }
  return albedo * sum;
}`;

const SCENE_FS = `#version 300 es
precision highp float;
in vec3 vPosition;
in vec3 vNormal;
in vec2 vUv;
in vec4 vColor;
uniform sampler2D uAtlas;
uniform float uSheetStretch;  // 0: every fragment of the mesh is drawn.
${LIGHTING}
out vec4 fragColor;
// Whether this fragment's triangle looks more than uSheetStretch times larger
// from the eye than from the panorama's centre (format/sheet_stretch.h: a
// sheet across a depth step): the smaller root l of det(Gu - l Ge) = 0, Gu
// and Ge the Gram matrices of the screen derivatives of the directions from
// the centre and from the eye, below 1 / uSheetStretch^2.
bool hiddenSheet() {
  vec3 u = normalize(vPosition), e = normalize(vPosition - uEye);
  vec3 ux = dFdx(u), uy = dFdy(u), ex = dFdx(e), ey = dFdy(e);
  float gu11 = dot(ux, ux), gu12 = dot(ux, uy), gu22 = dot(uy, uy);
  float ge11 = dot(ex, ex), ge12 = dot(ex, ey), ge22 = dot(ey, ey);
  float a = ge11 * ge22 - ge12 * ge12;
  float b = gu11 * ge22 + gu22 * ge11 - 2.0 * gu12 * ge12;
  float c = gu11 * gu22 - gu12 * gu12;
  float big = b + sqrt(max(b * b - 4.0 * a * c, 0.0));  // 2 a times the larger root; l = 2 c / big.
  return a > 0.0 && big > 2.0 * c * uSheetStretch * uSheetStretch;
}
void main() {
  // The derivatives are taken in uniform control flow (uSheetStretch is a
  // uniform), before the per-triangle test of the backdrop's colour.
  if (uSheetStretch > 0.0) {
    bool sheet = hiddenSheet();
    if (sheet && vColor.a < 0.5) discard;
  }
  vec3 albedo = vColor.a > 0.5 ? vColor.rgb : texture(uAtlas, vUv).rgb;
  vec3 color = albedo;
  // Unlit where the node has no normal (sky): interpolated length drops below 0.5.
  if (uLightCount > 0 && length(vNormal) > 0.5) color = shade(albedo, vPosition, vNormal);
  fragColor = vec4(color, 1.0);
}`;



// The environment: a full-screen triangle at the far plane; each pixel's ray
// (rotation-only inverse view-projection) looks up the equirectangular image
// (format/equirect.h: u = lon / 2 pi + 0.5, v = 0.5 - lat / pi).
const ENVIRONMENT_VS = `#version 300 es
out vec2 vNdc;
void main() {
  vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
  vNdc = p;
  gl_Position = vec4(p, 1.0, 1.0);
}`;

const ENVIRONMENT_FS = `#version 300 es
precision highp float;
in vec2 vNdc;
uniform mat4 uRayFromNdc;
uniform sampler2D uEnvironment;
out vec4 fragColor;
void main() {
  vec4 h = uRayFromNdc * vec4(vNdc, 1.0, 1.0);
  vec3 d = normalize(h.xyz / h.w);
  float lon = atan(d.x, -d.z);
  float lat = asin(clamp(d.y, -1.0, 1.0));
  vec2 uv = vec2(lon / 6.28318530718 + 0.5, 0.5 - lat / 3.14159265359);
  fragColor = vec4(texture(uEnvironment, uv).rgb, 1.0);
}`;

function compile(gl, type, source) {
  const shader = gl.createShader(type);
  gl.shaderSource(shader, source);
  gl.compileShader(shader);
  if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) {
    const log = gl.getShaderInfoLog(shader);
    gl.deleteShader(shader);
    throw new Error(`shader compilation failed: ${log}`);
  }
  return shader;
}

function program(gl, vs, fs) {
  const p = gl.createProgram();
  gl.attachShader(p, compile(gl, gl.VERTEX_SHADER, vs));
  gl.attachShader(p, compile(gl, gl.FRAGMENT_SHADER, fs));
  gl.linkProgram(p);
  if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(`shader link failed: ${gl.getProgramInfoLog(p)}`);
  const uniforms = {};
  const n = gl.getProgramParameter(p, gl.ACTIVE_UNIFORMS);
  for (let i = 0; i < n; ++i) {
    const name = gl.getActiveUniform(p, i).name.replace(/\[0\]$/, '');
    uniforms[name] = gl.getUniformLocation(p, name);
  }
  return { program: p, uniforms };
}


/**
 * Effects state; all optional. `lighting` relights the photo's mesh; the
 * other fields are the effect modules' defaults (effects.js).
 * Positions in metres in the panorama frame.
 */
export const DEFAULT_EFFECTS = Object.freeze(Object.assign(
  { lighting: false },  // Moving point lights using the normals.
  ...EFFECTS.map((e) => e.defaults),
));

export class Renderer {
  /**
   * @param {HTMLCanvasElement|OffscreenCanvas} canvas
   * @param sheetStretch where a backdrop is drawn, fragments of mesh triangles
   *   that look more than this many times larger from the eye than from the
   *   centre are left out (format/sheet_stretch.h); 0 draws them all
   */
  constructor(canvas, { xrCompatible = false, sheetStretch = 4 } = {}) {
    const gl = canvas.getContext('webgl2', {
      antialias: false, depth: true, alpha: false, preserveDrawingBuffer: true, xrCompatible,
    });
    if (!gl) throw new Error('WebGL2 is not available in this browser');
    this.gl = gl;
    this.canvas = canvas;
    this.sheetStretch = sheetStretch;
    this.scene = program(gl, SCENE_VS, SCENE_FS);
    this.environmentProgram = program(gl, ENVIRONMENT_VS, ENVIRONMENT_FS);
    this.environmentVao = gl.createVertexArray();  // No attributes: gl_VertexID.
    this.environment = null;  // Texture, or null: black background.
    this.coverageTarget = null;  // Framebuffer of backgroundFraction.
    this.mesh = null;
    // The effect modules' programs and geometry, made once per context.
    const effectContext = {
      gl, program: (fs) => program(gl, SCENE_VS, fs), upload: (g) => this._upload(g), lighting: LIGHTING,
    };
    this.effects = EFFECTS.map((effect) => ({ effect, state: effect.init(effectContext) }));
    this.texture = null;
  }

  _upload({ positions, normals, uvs, colors, indices }) {
    const gl = this.gl;
    const vao = gl.createVertexArray();
    gl.bindVertexArray(vao);
    const buffers = [];
    const attribute = (location, data, size, type = gl.FLOAT, normalized = false) => {
      const b = gl.createBuffer();
      gl.bindBuffer(gl.ARRAY_BUFFER, b);
      gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
      gl.enableVertexAttribArray(location);
      gl.vertexAttribPointer(location, size, type, normalized, 0, 0);
      buffers.push(b);
    };
    attribute(0, positions, 3);
    attribute(1, normals, 3);
    if (uvs) attribute(2, uvs, 2);
    else gl.vertexAttrib2f(2, 0, 0);
    if (colors) attribute(3, colors, 4, gl.UNSIGNED_BYTE, true);
    else gl.vertexAttrib4f(3, 0, 0, 0, 0);
    const ib = gl.createBuffer();
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ib);
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, indices, gl.STATIC_DRAW);
    buffers.push(ib);
    gl.bindVertexArray(null);
    return { vao, buffers, count: indices.length, hasBackdrop: Boolean(colors) };
  }

  _release(geometry) {
    if (!geometry) return;
    this.gl.deleteVertexArray(geometry.vao);
    for (const b of geometry.buffers) this.gl.deleteBuffer(b);
  }

  /**
   * Replaces the photo's mesh and colour atlas.
   * @param mesh {positions: Float32Array, normals: Float32Array, uvs: Float32Array, indices: Uint32Array, colors?: Uint8Array (RGBA; alpha 255: a backdrop vertex drawn in its colour)}
   * @param atlas {width, height, data: Uint8Array (RGBA)} or an ImageBitmap
   */
  setMesh(mesh, atlas) {
    const gl = this.gl;
    const maxSize = gl.getParameter(gl.MAX_TEXTURE_SIZE);
    if (atlas.width > maxSize || atlas.height > maxSize) {
      throw new Error(`the colour atlas (${atlas.width}x${atlas.height}) exceeds this GPU's texture limit of ${maxSize}`);
    }
    const geometry = this._upload(mesh);
    const texture = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, texture);
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
    gl.pixelStorei(gl.UNPACK_PREMULTIPLY_ALPHA_WEBGL, false);
    gl.pixelStorei(gl.UNPACK_COLORSPACE_CONVERSION_WEBGL, gl.NONE);
    if (atlas.data) {
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, atlas.width, atlas.height, 0, gl.RGBA, gl.UNSIGNED_BYTE, atlas.data);
    } else {
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, gl.RGBA, gl.UNSIGNED_BYTE, atlas);
    }
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.REPEAT);       // Columns wrap at the seam.
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
    this._release(this.mesh);
    if (this.texture) gl.deleteTexture(this.texture);
    this.mesh = geometry;
    this.texture = texture;
  }

  /**
   * Sets the environment drawn behind the mesh ({width, height, data: RGBA},
   * equirectangular) or removes it (null: black).
   */
  setEnvironment(image) {
    const gl = this.gl;
    if (this.environment) gl.deleteTexture(this.environment);
    this.environment = null;
    if (!image) return;
    const texture = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, texture);
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, image.width, image.height, 0, gl.RGBA, gl.UNSIGNED_BYTE, image.data);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.REPEAT);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
    this.environment = texture;
  }

  /**
   * The fraction of the pixels of a view (the arguments of draw, without
   * effects) that no triangle of the mesh covers, at `width` x `height`
   * pixels: drawn offscreen without the environment, alpha 0 where nothing is.
   */
  backgroundFraction({ view, projection, eye }, width, height) {
    const gl = this.gl;
    let t = this.coverageTarget;
    if (!t || t.width !== width || t.height !== height) {
      if (t) {
        gl.deleteFramebuffer(t.framebuffer);
        gl.deleteRenderbuffer(t.color);
        gl.deleteRenderbuffer(t.depth);
      }
      t = { width, height, framebuffer: gl.createFramebuffer(), color: gl.createRenderbuffer(), depth: gl.createRenderbuffer() };
      gl.bindRenderbuffer(gl.RENDERBUFFER, t.color);
      gl.renderbufferStorage(gl.RENDERBUFFER, gl.RGBA8, width, height);
      gl.bindRenderbuffer(gl.RENDERBUFFER, t.depth);
      gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH_COMPONENT24, width, height);
      gl.bindFramebuffer(gl.FRAMEBUFFER, t.framebuffer);
      gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.RENDERBUFFER, t.color);
      gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.RENDERBUFFER, t.depth);
      this.coverageTarget = t;
    }
    this.draw({
      view, projection, eye, effects: { ...DEFAULT_EFFECTS }, viewport: [0, 0, width, height],
      framebuffer: t.framebuffer, clearColor: [0, 0, 0, 0], environment: false,
    });
    const px = new Uint8Array(width * height * 4);
    gl.bindFramebuffer(gl.FRAMEBUFFER, t.framebuffer);
    gl.readPixels(0, 0, width, height, gl.RGBA, gl.UNSIGNED_BYTE, px);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    let empty = 0;
    for (let i = 3; i < px.length; i += 4) if (px[i] === 0) ++empty;
    return empty / (width * height);
  }

  get hasMesh() {
    return this.mesh !== null;
  }

  /** Point lights at time t (s): two coloured lights circling the centre. */
  static lights(timeSec) {
    const a = timeSec * 0.6;
    return {
      positions: [1.5 * Math.cos(a), 0.3, 1.5 * Math.sin(a) - 1.0, -1.2 * Math.cos(a * 1.3), -0.2, -1.2 * Math.sin(a * 1.3) - 1.5],
      colors: [1.6, 1.3, 0.9, 0.7, 0.9, 1.6],
    };
  }

  /**
   * Draws one view. `viewport` [x, y, w, h] in framebuffer pixels; `framebuffer`
   * null for the canvas (WebXR passes its layer's framebuffer).
   */
  draw({
    view, projection, eye, effects = DEFAULT_EFFECTS, timeSec = 0, viewport, framebuffer = null, clear = true,
    clearColor = [0, 0, 0, 1], environment = true,
  }) {
    const gl = this.gl;
    gl.bindFramebuffer(gl.FRAMEBUFFER, framebuffer);
    const [vx, vy, vw, vh] = viewport ?? [0, 0, gl.drawingBufferWidth, gl.drawingBufferHeight];
    gl.viewport(vx, vy, vw, vh);
    if (clear) {
      gl.clearColor(...clearColor);
      gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    }
    if (!this.mesh) return;
    const viewProjection = multiply(projection, view);
    if (environment && this.environment) this._drawEnvironment(view, projection);
    gl.enable(gl.DEPTH_TEST);
    gl.depthFunc(gl.LEQUAL);
    gl.disable(gl.CULL_FACE);  // The two-layer mesh is seen from both sides.
    gl.disable(gl.BLEND);

    const lights = Renderer.lights(timeSec);
    const lightCount = effects.lighting ? 2 : 0;
    const setCommon = (p, count, model = IDENTITY) => {
      gl.uniformMatrix4fv(p.uniforms.uViewProjection, false, viewProjection);
      gl.uniformMatrix4fv(p.uniforms.uModel, false, model);
      if (p.uniforms.uEye) gl.uniform3fv(p.uniforms.uEye, eye);
      if (p.uniforms.uLightCount) {
        gl.uniform1i(p.uniforms.uLightCount, count);
        gl.uniform3fv(p.uniforms.uLightPosition, new Float32Array([...lights.positions, 0, 0, 0, 0, 0, 0]));
        gl.uniform3fv(p.uniforms.uLightColor, new Float32Array([...lights.colors, 0, 0, 0, 0, 0, 0]));
        gl.uniform1f(p.uniforms.uAmbient, count > 0 ? 0.35 : 1.0);
      }
    };

    gl.useProgram(this.scene.program);
    setCommon(this.scene, lightCount);
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D, this.texture);
    gl.uniform1i(this.scene.uniforms.uAtlas, 0);
    // Sheets are left out only where the backdrop stands behind them.
    gl.uniform1f(this.scene.uniforms.uSheetStretch, this.mesh.hasBackdrop ? this.sheetStretch : 0);
    gl.bindVertexArray(this.mesh.vao);
    gl.drawElements(gl.TRIANGLES, this.mesh.count, gl.UNSIGNED_INT, 0);

    const context = { gl, effects, eye, timeSec, setCommon };
    for (const { effect, state } of this.effects) {
      if (effects[effect.name]) effect.draw(state, context);
    }
    gl.bindVertexArray(null);
  }

  _drawEnvironment(view, projection) {
    const gl = this.gl;
    // The view's rotation only: the environment lies at infinite distance.
    const rotation = Float32Array.from(view);
    rotation[12] = rotation[13] = rotation[14] = 0;
    gl.disable(gl.DEPTH_TEST);
    gl.depthMask(false);
    gl.disable(gl.BLEND);
    gl.useProgram(this.environmentProgram.program);
    gl.uniformMatrix4fv(this.environmentProgram.uniforms.uRayFromNdc, false, invert(multiply(projection, rotation)));
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D, this.environment);
    gl.uniform1i(this.environmentProgram.uniforms.uEnvironment, 0);
    gl.bindVertexArray(this.environmentVao);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    gl.depthMask(true);
  }

  dispose() {
    this.setEnvironment(null);
    if (this.coverageTarget) {
      const gl = this.gl;
      gl.deleteFramebuffer(this.coverageTarget.framebuffer);
      gl.deleteRenderbuffer(this.coverageTarget.color);
      gl.deleteRenderbuffer(this.coverageTarget.depth);
      this.coverageTarget = null;
    }
    this._release(this.mesh);
    for (const { effect, state } of this.effects) effect.dispose(state, { gl: this.gl, release: (g) => this._release(g) });
    this.effects = [];
    if (this.texture) this.gl.deleteTexture(this.texture);
    this.mesh = null;
    this.texture = null;
  }
}

const IDENTITY = new Float32Array([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]);
