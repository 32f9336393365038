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
//
// What the viewer shows of a package follows its view hints (view-hints.js;
// the manifest's "view" member, or derived from the coarsest level): it opens
// framed on the captured content, keeps the view on that content with soft
// limits (view-limits.js: input is resisted past a limit and eased back when
// it ends), draws a blurred continuation of the photo behind it where no
// surface is (environment.js), and holds the eye inside the package's viewing
// volume; key speed and mouse parallax scale with that volume.

import { assetUrl } from './assets.js';
import { Camera, clamp, lookAlong, multiply } from './camera.js';
import { Renderer, DEFAULT_EFFECTS } from './renderer.js';
import { wrapDeg } from './view-hints.js';
import {
  clampView, contentCentreYaw, easeFactor, easeView, fittingPitchRange, maxFovDeg, OVERSHOOT_FRACTION, resist,
  yawAllowance,
} from './view-limits.js';

const DEG = Math.PI / 180;
/** Input counts as ongoing this long after its last event (ms): no easing back meanwhile. */
const INPUT_HOLD_MS = 200;
/** Largest margin (degrees) kept inside the content's edges for the eye's parallax. */
const MAX_MARGIN_DEG = 10;

export const DEFAULT_OPTIONS = Object.freeze({
  maxLevelWidth: 4096,       // Finest level loaded (panorama width, pixels).
  maxTriangles: 2000000,     // Triangle budget per level's mesh (simplified above it).
  maxOffset: null,           // Radius of the ball the eye may move in (unit of the depths); null: the package's volume.
  keyRotateDegPerSec: 90,    // Arrow keys.
  keyMoveRadiiPerSec: 1,     // W/A/S/D/Q/E head motion, in viewing-volume radii per second.
  dragDegPerPixel: 0.15,     // Scaled by the field of view (divided by 75 deg).
  mouseParallax: true,       // Moving the mouse over the view moves the eye.
  keepInContent: true,       // Soft limits keep the view on the captured content.
  softBackground: true,      // A blurred continuation of the photo where no surface is (else black).
  backdrop: true,            // Draw the backdrop behind the mesh (format/backdrop.h): tears show the background.
  sheetStretch: 4,           // With the backdrop: leave out sheets stretched more than this from the eye (format/sheet_stretch.h); 0 draws them.
});

/** Radius of the eye's ball before a package's volume is known (unit of the depths). */
const INITIAL_MAX_OFFSET = 0.3;

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
    this.camera = new Camera({ maxOffset: this.options.maxOffset ?? INITIAL_MAX_OFFSET });
    this.renderer = new Renderer(this.canvas, { xrCompatible: true, sheetStretch: this.options.sheetStretch });
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
    this._hints = null;        // View hints of the package shown (view-hints.js).
    this._limits = null;       // Content limits (view-limits.js), with the hints.
    this._cameraSet = false;   // Whether setCamera chose a view since load().
    this._pointers = 0;        // Pointers down on the canvas.
    this._lastInput = -Infinity;  // performance.now() of the last turn or zoom input.
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
      this._worker = new Worker(assetUrl('worker.js'), { type: 'module' });
      this._worker.onmessage = (e) => this._onWorkerMessage(e.data);
      this._worker.onerror = (e) => {
        e.preventDefault();
        this._emitError(`the decoding worker failed: ${e.message || 'unknown error'}`, !this._levelShown);
      };
    }
    this.stats = { loadStart: performance.now(), url: manifestUrl };
    this._levelShown = false;  // Whether this load has shown a level yet.
    this._cameraSet = false;   // The new package opens framed unless setCamera says otherwise.
    if (this._pending) this._pending.resolve();  // A superseded load settles quietly.
    return new Promise((resolve, reject) => {
      this._pending = { id, resolve, reject };
      this._worker.postMessage({
        type: 'load', id, url: manifestUrl, yawDeg: this.camera.yawDeg,
        maxLevelWidth: this.options.maxLevelWidth, maxTriangles: this.options.maxTriangles,
        backdrop: this.options.backdrop,
      });
    });
  }

  /**
   * Sets any of {yawDeg, pitchDeg, fovDeg, position: [x, y, z]} (position in
   * the unit of the package's depths). The position is held inside the
   * viewing volume and, with `keepInContent`, the view inside the content's
   * limits (the nearest view inside them). A view set after load() starts
   * replaces the framed view the package would open at.
   */
  setCamera(camera) {
    if (['yawDeg', 'pitchDeg', 'fovDeg'].some((k) => Number.isFinite(camera?.[k]))) this._cameraSet = true;
    this.camera.set(camera);
    this._clampToLimits();
    this._viewChanged();
  }

  getCamera() {
    return this.camera.get();
  }

  /** Back to the framed view of the package (its view hints) with the eye at the centre. */
  resetView() {
    const h = this._hints;
    this.camera.reset();
    if (h) this.camera.set({ yawDeg: h.yawDeg, pitchDeg: h.pitchDeg, fovDeg: h.fovDeg });
    this._clampToLimits();
    this._mouseOffset = [0, 0];
    this._viewChanged();
  }

  /**
   * The view hints of the package shown (view-hints.js, casual3d-viewer.d.ts
   * ViewHints): from its manifest's "view" member or derived from its coarsest
   * level; null until its first level is shown.
   */
  getViewHints() {
    const h = this._hints;
    return h ? { ...h, contentYawDeg: [...h.contentYawDeg], contentPitchDeg: [...h.contentPitchDeg] } : null;
  }

  /** Radius of the ball the eye is held in (the package's viewing volume unless options.maxOffset). */
  get maxOffset() {
    return this.camera.maxOffset;
  }

  /** The eye this frame: the camera's position plus mouse parallax, inside the volume. */
  get eyePosition() {
    return [...this._currentView().eye];
  }

  /**
   * The fraction of the current view's pixels (mouse parallax included) that
   * no surface of the 3D photo covers, measured offscreen at the canvas size.
   */
  measureBackground() {
    const { view, projection, eye } = this._currentView();
    return this.renderer.backgroundFraction({ view, projection, eye }, this.canvas.width, this.canvas.height);
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
   * head is kept inside the package's viewing volume (the ball of `maxOffset`;
   * one unit of the package's depths per metre of head motion), where the 3D
   * photo holds (both eyes move with it, keeping their baseline).
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
        if (msg.view) this._setViewHints(msg.view);
        // Keep the whole scene inside the far plane (near plane unchanged).
        if (msg.depthFarM > 0) this.camera.far = Math.max(this.camera.far, 1.5 * msg.depthFarM);
        try {
          this.renderer.setMesh(msg.mesh, msg.atlas);
        } catch (err) {
          // For example a texture larger than this GPU allows.
          this._emitError(`level ${msg.level} cannot be shown: ${err.message || err}`, !this._levelShown);
          break;
        }
        // In VR the session draws the frames: the level is on screen now.
        if (!this._levelShown && this._xrSession) this._worker.postMessage({ type: 'shown', id: msg.id });
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

  /** The current view: camera plus mouse parallax (an offset along the view's right and up). */
  _currentView() {
    const cam = this.camera;
    const eye = [...cam.position];
    if (this.options.mouseParallax && (this._mouseOffset[0] || this._mouseOffset[1])) {
      const yaw = cam.yawDeg * DEG;
      const right = [Math.cos(yaw), 0, Math.sin(yaw)];
      for (let i = 0; i < 3; ++i) eye[i] += right[i] * this._mouseOffset[0] * cam.maxOffset;
      eye[1] += this._mouseOffset[1] * cam.maxOffset * 0.5;
      const len = Math.hypot(...eye);
      if (len > cam.maxOffset) for (let i = 0; i < 3; ++i) eye[i] *= cam.maxOffset / len;
    }
    return { view: lookAlong(eye, cam.forward()), projection: cam.projectionMatrix(this._aspect()), eye };
  }

  _aspect() {
    return this.canvas.width / this.canvas.height;
  }

  /** Takes the hints (and background) of a package's first level and frames it. */
  _setViewHints({ hints, warning, environment }) {
    if (warning) console.warn(`casual3d-viewer: ${warning}`);
    this._hints = hints;
    const cam = this.camera;
    cam.maxOffset = this.options.maxOffset ?? hints.volumeRadius;
    // Keep nearby surfaces in front of the near plane in any unit of depth.
    if (hints.nearDepth > 0) cam.near = Math.min(0.05, 0.25 * hints.nearDepth);
    // The content's edges move by up to atan(radius / depth) with the eye.
    const marginDeg = hints.nearDepth > 0
      ? Math.min(MAX_MARGIN_DEG, Math.atan(cam.maxOffset / hints.nearDepth) / DEG) : 0;
    this._limits = {
      yawDeg: hints.contentYawDeg, pitchDeg: hints.contentPitchDeg, marginDeg,
      minFovDeg: cam.minFovDeg, maxFovDeg: cam.maxFovDeg,
    };
    this.renderer.setEnvironment(this.options.softBackground ? environment : null);
    if (!this._cameraSet) {
      cam.set({ yawDeg: hints.yawDeg, pitchDeg: hints.pitchDeg, fovDeg: hints.fovDeg, position: [0, 0, 0] });
    }
    cam.set({ position: cam.position });  // Inside the new volume.
    this._clampToLimits();
    this._viewChanged();
  }

  /** The nearest view inside the content's limits (hard), if limits apply. */
  _clampToLimits() {
    if (!this._limits || !this.options.keepInContent) return;
    this.camera.set(clampView(this.camera, this._limits, this._aspect()));
  }

  _viewChanged() {
    this._dirty = true;
    if (this._worker) this._worker.postMessage({ type: 'view', yawDeg: this.camera.yawDeg });
  }

  /** Turns the view by input (degrees), resisted past the content's limits. */
  _turn(dYawDeg, dPitchDeg) {
    const c = this.camera;
    this._lastInput = performance.now();
    const L = this.options.keepInContent ? this._limits : null;
    if (!L) {
      c.set({ yawDeg: c.yawDeg + dYawDeg, pitchDeg: c.pitchDeg + dPitchDeg });
    } else {
      const range = OVERSHOOT_FRACTION * c.fovDeg;
      const [lo, hi] = fittingPitchRange(L, c.fovDeg, this._aspect());
      const pitch = resist(c.pitchDeg, dPitchDeg, lo, hi, range);
      const allowance = yawAllowance(L, c.fovDeg, this._aspect(), pitch);
      let yaw = c.yawDeg + dYawDeg;
      if (allowance !== Infinity) {
        const centre = contentCentreYaw(L);
        const a = Math.max(0, allowance);
        yaw = centre + resist(wrapDeg(c.yawDeg - centre), dYawDeg, -a, a, range);
      }
      c.set({ yawDeg: yaw, pitchDeg: pitch });
    }
    this._viewChanged();
  }

  /** Zooms to `fovDeg` by input, resisted past the widest view that fits the content. */
  _zoom(fovDeg) {
    const c = this.camera;
    this._lastInput = performance.now();
    const L = this.options.keepInContent ? this._limits : null;
    if (!L) {
      c.set({ fovDeg });
    } else {
      const widest = maxFovDeg(L, this._aspect());
      c.set({ fovDeg: resist(c.fovDeg, fovDeg - c.fovDeg, L.minFovDeg, widest, OVERSHOOT_FRACTION * widest) });
    }
    this._viewChanged();
  }

  /** Eases the view back inside the limits once input has ended. */
  _easeToLimits(now, dt) {
    if (!this._limits || !this.options.keepInContent) return;
    if (this._pointers > 0 || this._keys.size > 0 || now - this._lastInput < INPUT_HOLD_MS) return;
    const { view, settled } = easeView(this.camera, this._limits, this._aspect(), easeFactor(dt));
    const before = this.camera.get();
    this.camera.set(view);
    if (!settled || before.yawDeg !== this.camera.yawDeg || before.pitchDeg !== this.camera.pitchDeg ||
        before.fovDeg !== this.camera.fovDeg) {
      this._dirty = true;
    }
  }

  _tick(now) {
    if (this._xrSession) return;  // The XR session drives frames.
    this._raf = requestAnimationFrame((t) => this._tick(t));
    const dt = Math.min(0.1, (now - this._lastTick) / 1000);
    this._lastTick = now;
    this._applyKeys(dt);
    this._easeToLimits(now, dt);
    const animated = this.effectsTime === null && (this.effects.lighting || this.effects.water);
    if (!this._dirty && !animated) return;
    this._dirty = false;
    const { view, projection, eye } = this._currentView();
    this.renderer.draw({ view, projection, eye, effects: this.effects, timeSec: this._effectsSeconds() });
    if (this._levelShown && this.stats.timeToFirstFrameMs === undefined) {
      this.stats.timeToFirstFrameMs = now - this.stats.loadStart;
      this.stats.bytesBeforeFirstFrame = this._bytesFetched();
      this._emit('firstframe', {
        timeToFirstFrameMs: this.stats.timeToFirstFrameMs,
        bytesBeforeFirstFrame: this.stats.bytesBeforeFirstFrame,
      });
      this._worker?.postMessage({ type: 'shown', id: this._loadId });
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
    const k = (a) => (this._keys.has(a) ? 1 : 0);
    const dYaw = (k('ArrowRight') - k('ArrowLeft')) * o.keyRotateDegPerSec * dt;
    const dPitch = (k('ArrowUp') - k('ArrowDown')) * o.keyRotateDegPerSec * dt;
    if (dYaw || dPitch) this._turn(dYaw, dPitch);
    const c = this.camera.get();
    const yaw = c.yawDeg;
    const f = [Math.sin(yaw * DEG), 0, -Math.cos(yaw * DEG)];
    const r = [Math.cos(yaw * DEG), 0, Math.sin(yaw * DEG)];
    const fwd = k('w') - k('s'), side = k('d') - k('a'), up = k('e') - k('q');
    if (!fwd && !side && !up) return;
    // Speed in radii of the viewing volume per second: the same feel at any scale.
    const step = o.keyMoveRadiiPerSec * this.camera.maxOffset * dt;
    const p = c.position.map((v, i) => v + (f[i] * fwd + r[i] * side) * step + (i === 1 ? up * step : 0));
    this.camera.set({ position: p });
    this._dirty = true;
  }

  _bindInput() {
    const canvas = this.canvas;
    const pointers = new Map();
    let pinchStart = null;
    const onDown = (e) => {
      canvas.focus();
      canvas.setPointerCapture(e.pointerId);
      pointers.set(e.pointerId, { x: e.clientX, y: e.clientY });
      this._pointers = pointers.size;
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
        this._zoom(pinchStart.fov * (pinchStart.dist / Math.max(dist, 1)));
      } else if (pointers.size === 1) {
        const s = this.options.dragDegPerPixel * (this.camera.fovDeg / 75);
        // Dragging moves the photo with the pointer.
        this._turn(-(e.clientX - prev.x) * s, (e.clientY - prev.y) * s);
      }
    };
    const onUp = (e) => {
      pointers.delete(e.pointerId);
      this._pointers = pointers.size;
      if (pointers.size < 2) pinchStart = null;
    };
    const onWheel = (e) => {
      e.preventDefault();
      this._zoom(this.camera.fovDeg * Math.exp(e.deltaY * 0.001));
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
        this._zoom(this.camera.fovDeg / 1.1);
      } else if (key === '-') {
        this._zoom(this.camera.fovDeg * 1.1);
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
      this._turn(wrapDeg(yaw - base.yaw - this.camera.yawDeg), pitch - this.camera.pitchDeg);
      // Tilt sideways moves the eye sideways (motion parallax on a phone).
      const tilt = clamp((e.gamma ?? 0) / 45, -1, 1);
      this._mouseOffset = [tilt, 0];
    };
    window.addEventListener('deviceorientation', onOrientation);
    this._stopMotion = () => window.removeEventListener('deviceorientation', onOrientation);
    return true;
  }
}
