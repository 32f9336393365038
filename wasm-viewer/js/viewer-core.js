// Casual3dViewer: the JavaScript API of the 3D photo viewer (no custom element;
// see casual3d-viewer.js for <casual3d-viewer>). Loading and decoding run in a
// Web Worker (worker.js); this thread only uploads meshes and draws.
//
// Events (EventTarget; `detail` of a CustomEvent):
//   'progress'   {loadedBytes, totalBytes, level, levels}
//   'level'      {level, levels, width, height, triangles}: a level is shown
//   'firstframe' {timeToFirstFrameMs, bytesBeforeFirstFrame}
//   'load'       {levels, bytes, timeMs}: every level is loaded
//   'error'      {message, fatal}: fatal errors leave nothing to show; others
//                keep the coarser level that is already on screen.

import { Camera, clamp, lookAlong, multiply } from './camera.js';
import { Renderer, DEFAULT_EFFECTS } from './renderer.js';

const DEG = Math.PI / 180;

export const DEFAULT_OPTIONS = Object.freeze({
  maxLevelWidth: 4096,       // Finest level loaded (panorama width, pixels).
  maxTriangles: 2000000,     // Triangle budget per level's mesh (simplified above it).
  maxOffset: 0.3,            // Radius of the ball the eye may move in (m).
  keyRotateDegPerSec: 90,    // Arrow keys.
  keyMoveMPerSec: 0.3,       // W/A/S/D/Q/E head motion.
  dragDegPerPixel: 0.15,     // Scaled by the field of view (divided by 75 deg).
  mouseParallax: true,       // Moving the mouse over the view moves the eye.
});

export class Casual3dViewer extends EventTarget {
  /**
   * @param {HTMLElement} container element that receives the canvas
   * @param {object} options see DEFAULT_OPTIONS
   */
  constructor(container, options = {}) {
    super();
    this.options = { ...DEFAULT_OPTIONS, ...options };
    this.container = container;
    this.canvas = document.createElement('canvas');
    this.canvas.style.cssText = 'display:block;width:100%;height:100%;touch-action:none;outline:none';
    this.canvas.tabIndex = 0;
    container.appendChild(this.canvas);
    this.camera = new Camera({ maxOffset: this.options.maxOffset });
    this.renderer = new Renderer(this.canvas, { xrCompatible: true });
    this.effects = { ...DEFAULT_EFFECTS };
    this.effectsTime = null;          // Fixed effects time (s) or null: real time.
    this.stats = {};
    this._startTime = performance.now();
    this._loadId = 0;
    this._levelShown = false;  // Whether the current load has shown a level.
    this._worker = null;
    this._dirty = true;
    this._frameWaiters = [];
    this._keys = new Set();
    this._mouseOffset = [0, 0];
    this._lastTick = performance.now();
    this._xrSession = null;
    this._resizeObserver = new ResizeObserver(() => this._resize());
    this._resizeObserver.observe(this.canvas);
    this._bindInput();
    this._resize();
    this._raf = requestAnimationFrame((t) => this._tick(t));
  }

  /** Loads a package from the URL of its manifest.json; resolves when the first level is shown. */
  load(url) {
    const id = ++this._loadId;
    const manifestUrl = new URL(url, document.baseURI).href;
    if (!this._worker) {
      this._worker = new Worker(new URL('./worker.js', import.meta.url), { type: 'module' });
      this._worker.onmessage = (e) => this._onWorkerMessage(e.data);
      this._worker.onerror = (e) => {
        e.preventDefault();
        this._emitError(`the decoding worker failed: ${e.message || 'unknown error'}`, !this._levelShown);
      };
    }
    this.stats = { loadStart: performance.now(), url: manifestUrl };
    this._levelShown = false;  // Whether this load has shown a level yet.
    if (this._pending) this._pending.resolve();  // A superseded load settles quietly.
    return new Promise((resolve, reject) => {
      this._pending = { id, resolve, reject };
      this._worker.postMessage({
        type: 'load', id, url: manifestUrl, yawDeg: this.camera.yawDeg,
        maxLevelWidth: this.options.maxLevelWidth, maxTriangles: this.options.maxTriangles,
      });
    });
  }

  /** Sets any of {yawDeg, pitchDeg, fovDeg, position: [x, y, z] metres}. */
  setCamera(camera) {
    this.camera.set(camera);
    this._dirty = true;
    if (this._worker && Number.isFinite(camera?.yawDeg)) {
      this._worker.postMessage({ type: 'view', yawDeg: this.camera.yawDeg });
    }
  }

  getCamera() {
    return this.camera.get();
  }

  resetView() {
    this.camera.reset();
    this._mouseOffset = [0, 0];
    this._dirty = true;
  }

  /** Sets any of the effect fields (renderer.js DEFAULT_EFFECTS). */
  setEffects(effects) {
    Object.assign(this.effects, effects);
    this._dirty = true;
  }

  getEffects() {
    return { ...this.effects };
  }

  /** Freezes the effects' animation at `timeSec` (null: real time). */
  setEffectsTime(timeSec) {
    this.effectsTime = timeSec;
    this._dirty = true;
  }

  /** Resolves after the next frame has been drawn. */
  nextFrame() {
    this._dirty = true;
    return new Promise((resolve) => this._frameWaiters.push(resolve));
  }

  /** Whether immersive VR is offered by this browser and device. */
  async isVRSupported() {
    try {
      return !!(navigator.xr && (await navigator.xr.isSessionSupported('immersive-vr')));
    } catch {
      return false;
    }
  }

  /**
   * Starts an immersive VR session with per-eye stereo rendering; resolves once
   * the session runs. Each eye is drawn with its own projection matrix and eye
   * transform from the headset; the 'local' reference space (its origin where
   * the head was when the session started) is placed at the capture centre,
   * turned so that the headset starts looking where the viewer looked, and the
   * head is kept inside the ball of `maxOffset` metres where the 3D photo holds
   * (both eyes move with it, keeping their baseline).
   */
  async enterVR() {
    if (this._xrSession) return;
    if (!(await this.isVRSupported())) throw new Error('immersive VR is not available on this device');
    const session = await navigator.xr.requestSession('immersive-vr', { optionalFeatures: ['local'] });
    let space;
    try {
      const gl = this.renderer.gl;
      await gl.makeXRCompatible();
      session.updateRenderState({
        baseLayer: new XRWebGLLayer(session, gl),
        depthNear: this.camera.near, depthFar: this.camera.far,
      });
      space = await session.requestReferenceSpace('local');
    } catch (err) {
      await session.end().catch(() => {});
      throw err;
    }
    this._xrSession = session;
    this.stats.xrFrames = 0;
    // Panorama frame from the reference space: a turn about +Y by the viewer's yaw.
    const yaw = this.camera.yawDeg * DEG;
    const c = Math.cos(yaw), s = Math.sin(yaw);
    const localFromWorld = new Float32Array([c, 0, -s, 0, 0, 1, 0, 0, s, 0, c, 0, 0, 0, 0, 1]);
    const toWorld = (p) => [c * p.x - s * p.z, p.y, s * p.x + c * p.z];
    session.addEventListener('end', () => {
      this._xrSession = null;
      this._dirty = true;
      cancelAnimationFrame(this._raf);
      this._raf = requestAnimationFrame((t) => this._tick(t));
    });
    const onFrame = (time, frame) => {
      if (this._xrSession !== session) return;
      session.requestAnimationFrame(onFrame);
      const pose = frame.getViewerPose(space);
      const layer = session.renderState.baseLayer;
      if (!pose || !layer) return;
      // Keep the head inside the parallax ball; the eyes follow it rigidly.
      const head = toWorld(pose.transform.position);
      const len = Math.hypot(...head);
      const scale = len > this.camera.maxOffset ? this.camera.maxOffset / len : 1;
      const shift = head.map((v) => v * scale - v);
      const unshift = new Float32Array([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -shift[0], -shift[1], -shift[2], 1]);
      const localFromPanorama = multiply(localFromWorld, unshift);
      pose.views.forEach((view, i) => {
        const vp = layer.getViewport(view);
        if (!vp) return;
        const eye = toWorld(view.transform.position).map((v, k) => v + shift[k]);
        this.renderer.draw({
          view: multiply(view.transform.inverse.matrix, localFromPanorama), projection: view.projectionMatrix, eye,
          effects: this.effects, timeSec: this._effectsSeconds(),
          viewport: [vp.x, vp.y, vp.width, vp.height], framebuffer: layer.framebuffer, clear: i === 0,
        });
      });
      this.stats.xrFrames += 1;
      const waiters = this._frameWaiters;
      this._frameWaiters = [];
      for (const w of waiters) w();
    };
    session.requestAnimationFrame(onFrame);
  }

  /** Ends the immersive VR session, if any; the page's canvas is drawn again. */
  async exitVR() {
    if (this._xrSession) await this._xrSession.end();
  }

  /** Whether an immersive VR session is running. */
  get inVR() {
    return this._xrSession !== null;
  }

  /** Stops loading and rendering and releases GPU resources. */
  dispose() {
    cancelAnimationFrame(this._raf);
    this._resizeObserver.disconnect();
    this._unbindInput?.();
    if (this._worker) this._worker.terminate();
    this._worker = null;
    this.renderer.dispose();
    this.canvas.remove();
  }

  // --- internals ---------------------------------------------------------------

  _emit(type, detail) {
    this.dispatchEvent(new CustomEvent(type, { detail }));
  }

  _emitError(message, fatal) {
    this.stats.lastError = message;
    this._emit('error', { message, fatal });
    if (this._pending && fatal) {
      this._pending.reject(new Error(message));
      this._pending = null;
    }
  }

  _onWorkerMessage(msg) {
    if (msg.id !== this._loadId) return;  // A superseded load.
    switch (msg.type) {
      case 'progress':
        this.stats.packageBytes = msg.progress.loadedBytes;
        this._emit('progress', msg.progress);
        break;
      case 'level': {
        const t0 = performance.now();
        // Keep the whole scene inside the far plane (near plane unchanged).
        if (msg.depthFarM > 0) this.camera.far = Math.max(this.camera.far, 1.5 * msg.depthFarM);
        try {
          this.renderer.setMesh(msg.mesh, msg.atlas);
        } catch (err) {
          // For example a texture larger than this GPU allows.
          this._emitError(`level ${msg.level} cannot be shown: ${err.message || err}`, !this._levelShown);
          break;
        }
        this._levelShown = true;
        this.stats.level = msg.level;
        this.stats.levels = msg.levels;
        this.stats.triangles = msg.mesh.indices.length / 3;
        this.stats.vertices = msg.mesh.positions.length / 3;
        this.stats.workerMs = (this.stats.workerMs ?? []).concat([msg.timing]);
        this.stats.uploadMs = performance.now() - t0;
        this._dirty = true;
        this._emit('level', {
          level: msg.level, levels: msg.levels, width: msg.width, height: msg.height,
          triangles: this.stats.triangles,
        });
        if (this._pending) {
          this._pending.resolve();
          this._pending = null;
        }
        break;
      }
      case 'done':
        this.stats.loadMs = performance.now() - this.stats.loadStart;
        this._emit('load', { levels: msg.levels, bytes: msg.bytes, timeMs: this.stats.loadMs });
        break;
      case 'error':
        this._emitError(msg.message, !this._levelShown);
        break;
      default:
        break;
    }
  }

  _effectsSeconds() {
    return this.effectsTime ?? (performance.now() - this._startTime) / 1000;
  }

  _resize() {
    const dpr = Math.min(window.devicePixelRatio || 1, 2);
    const w = Math.max(1, Math.round(this.canvas.clientWidth * dpr));
    const h = Math.max(1, Math.round(this.canvas.clientHeight * dpr));
    if (this.canvas.width !== w || this.canvas.height !== h) {
      this.canvas.width = w;
      this.canvas.height = h;
      this._dirty = true;
    }
  }

  _tick(now) {
    if (this._xrSession) return;  // The XR session drives frames.
    this._raf = requestAnimationFrame((t) => this._tick(t));
    const dt = Math.min(0.1, (now - this._lastTick) / 1000);
    this._lastTick = now;
    this._applyKeys(dt);
    const animated = this.effectsTime === null && (this.effects.lighting || this.effects.water);
    if (!this._dirty && !animated) return;
    this._dirty = false;
    const cam = this.camera;
    // Mouse parallax: an extra offset along the view's right and up vectors.
    const eye = [...cam.position];
    if (this.options.mouseParallax && (this._mouseOffset[0] || this._mouseOffset[1])) {
      const yaw = cam.yawDeg * DEG;
      const right = [Math.cos(yaw), 0, Math.sin(yaw)];
      for (let i = 0; i < 3; ++i) eye[i] += right[i] * this._mouseOffset[0] * cam.maxOffset;
      eye[1] += this._mouseOffset[1] * cam.maxOffset * 0.5;
      const len = Math.hypot(...eye);
      if (len > cam.maxOffset) for (let i = 0; i < 3; ++i) eye[i] *= cam.maxOffset / len;
    }
    const aspect = this.canvas.width / this.canvas.height;
    this.renderer.draw({
      view: lookAlong(eye, cam.forward()), projection: cam.projectionMatrix(aspect), eye,
      effects: this.effects, timeSec: this._effectsSeconds(),
    });
    if (this._levelShown && this.stats.timeToFirstFrameMs === undefined) {
      this.stats.timeToFirstFrameMs = now - this.stats.loadStart;
      this.stats.bytesBeforeFirstFrame = this._bytesFetched();
      this._emit('firstframe', {
        timeToFirstFrameMs: this.stats.timeToFirstFrameMs,
        bytesBeforeFirstFrame: this.stats.bytesBeforeFirstFrame,
      });
    }
    const waiters = this._frameWaiters;
    this._frameWaiters = [];
    for (const w of waiters) w();
  }

  // Bytes of the package fetched by the worker so far (reported with progress).
  _bytesFetched() {
    return this.stats.packageBytes ?? 0;
  }

  _applyKeys(dt) {
    if (this._keys.size === 0) return;
    const o = this.options;
    const c = this.camera.get();
    const k = (a) => (this._keys.has(a) ? 1 : 0);
    const yaw = c.yawDeg + (k('ArrowRight') - k('ArrowLeft')) * o.keyRotateDegPerSec * dt;
    const pitch = c.pitchDeg + (k('ArrowUp') - k('ArrowDown')) * o.keyRotateDegPerSec * dt;
    const f = [Math.sin(yaw * DEG), 0, -Math.cos(yaw * DEG)];
    const r = [Math.cos(yaw * DEG), 0, Math.sin(yaw * DEG)];
    const fwd = k('w') - k('s'), side = k('d') - k('a'), up = k('e') - k('q');
    const step = o.keyMoveMPerSec * dt;
    const p = c.position.map((v, i) => v + (f[i] * fwd + r[i] * side) * step + (i === 1 ? up * step : 0));
    this.setCamera({ yawDeg: yaw, pitchDeg: pitch, position: p });
  }

  _bindInput() {
    const canvas = this.canvas;
    const pointers = new Map();
    let pinchStart = null;
    const onDown = (e) => {
      canvas.focus();
      canvas.setPointerCapture(e.pointerId);
      pointers.set(e.pointerId, { x: e.clientX, y: e.clientY });
      if (pointers.size === 2) {
        const [a, b] = [...pointers.values()];
        pinchStart = { dist: Math.hypot(a.x - b.x, a.y - b.y), fov: this.camera.fovDeg };
      }
    };
    const onMove = (e) => {
      const rect = canvas.getBoundingClientRect();
      if (!pointers.has(e.pointerId)) {
        if (this.options.mouseParallax && e.pointerType === 'mouse') {
          this._mouseOffset = [
            clamp(((e.clientX - rect.left) / rect.width) * 2 - 1, -1, 1),
            clamp(1 - ((e.clientY - rect.top) / rect.height) * 2, -1, 1),
          ];
          this._dirty = true;
        }
        return;
      }
      const prev = pointers.get(e.pointerId);
      pointers.set(e.pointerId, { x: e.clientX, y: e.clientY });
      if (pointers.size === 2 && pinchStart) {
        const [a, b] = [...pointers.values()];
        const dist = Math.hypot(a.x - b.x, a.y - b.y);
        this.setCamera({ fovDeg: pinchStart.fov * (pinchStart.dist / Math.max(dist, 1)) });
      } else if (pointers.size === 1) {
        const s = this.options.dragDegPerPixel * (this.camera.fovDeg / 75);
        const c = this.camera.get();
        // Dragging moves the photo with the pointer.
        this.setCamera({ yawDeg: c.yawDeg - (e.clientX - prev.x) * s, pitchDeg: c.pitchDeg + (e.clientY - prev.y) * s });
      }
    };
    const onUp = (e) => {
      pointers.delete(e.pointerId);
      if (pointers.size < 2) pinchStart = null;
    };
    const onWheel = (e) => {
      e.preventDefault();
      this.setCamera({ fovDeg: this.camera.fovDeg * Math.exp(e.deltaY * 0.001) });
    };
    const keys = new Set(['ArrowLeft', 'ArrowRight', 'ArrowUp', 'ArrowDown', 'w', 'a', 's', 'd', 'q', 'e']);
    const onKeyDown = (e) => {
      const key = e.key.length === 1 ? e.key.toLowerCase() : e.key;
      if (keys.has(key)) {
        e.preventDefault();
        this._keys.add(key);
      } else if (key === 'r' || key === 'Home') {
        this.resetView();
      } else if (key === '+' || key === '=') {
        this.setCamera({ fovDeg: this.camera.fovDeg / 1.1 });
      } else if (key === '-') {
        this.setCamera({ fovDeg: this.camera.fovDeg * 1.1 });
      }
    };
    const onKeyUp = (e) => this._keys.delete(e.key.length === 1 ? e.key.toLowerCase() : e.key);
    const onBlur = () => this._keys.clear();
    const onLeave = () => {
      this._mouseOffset = [0, 0];
      this._dirty = true;
    };
    canvas.addEventListener('pointerdown', onDown);
    canvas.addEventListener('pointermove', onMove);
    canvas.addEventListener('pointerup', onUp);
    canvas.addEventListener('pointercancel', onUp);
    canvas.addEventListener('pointerleave', onLeave);
    canvas.addEventListener('wheel', onWheel, { passive: false });
    canvas.addEventListener('keydown', onKeyDown);
    canvas.addEventListener('keyup', onKeyUp);
    canvas.addEventListener('blur', onBlur);
    canvas.addEventListener('dblclick', () => this.resetView());
    this._unbindInput = () => {
      this._stopMotion?.();
    };
  }

  /**
   * Follows the device's orientation (look around) and tilt (parallax) on
   * phones. Must be called from a user gesture where the browser asks for
   * permission (iOS). Resolves false if unavailable or refused.
   */
  async enableDeviceMotion() {
    const D = window.DeviceOrientationEvent;
    if (!D) return false;
    if (typeof D.requestPermission === 'function') {
      try {
        if ((await D.requestPermission()) !== 'granted') return false;
      } catch {
        return false;
      }
    }
    let base = null;
    const onOrientation = (e) => {
      if (e.alpha === null || e.beta === null) return;
      // Device held upright in portrait: beta 90 looks at the horizon; alpha is
      // the compass heading, gamma the sideways tilt.
      const screenAngle = (screen.orientation?.angle ?? 0) * DEG;
      const yaw = -e.alpha;
      const pitch = (e.beta - 90) * Math.cos(screenAngle) + (e.gamma ?? 0) * Math.sin(screenAngle);
      if (!base) base = { yaw: yaw - this.camera.yawDeg };
      this.setCamera({ yawDeg: yaw - base.yaw, pitchDeg: pitch });
      // Tilt sideways moves the eye sideways (motion parallax on a phone).
      const tilt = clamp((e.gamma ?? 0) / 45, -1, 1);
      this._mouseOffset = [tilt, 0];
    };
    window.addEventListener('deviceorientation', onOrientation);
    this._stopMotion = () => window.removeEventListener('deviceorientation', onOrientation);
    return true;
  }
}
