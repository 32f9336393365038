// A scripted WebXR device for browser tests: `installWebXRMock` is passed to
// Playwright's page.addInitScript, so it runs in the page before any of its
// scripts. It provides the parts of the WebXR Device API the viewer uses, with
// the specification's behaviour where it matters to a renderer:
//  - navigator.xr: isSessionSupported, requestSession ('immersive-vr' needs a
//    user gesture and only one immersive session may run);
//  - XRSession: updateRenderState (applied at the start of the next frame),
//    requestReferenceSpace ('local'), requestAnimationFrame /
//    cancelAnimationFrame, end (fires 'end');
//  - XRWebGLLayer: one framebuffer (colour + depth) holding the left and right
//    eye side by side; getViewport(view) returns each eye's half;
//  - XRFrame.getViewerPose: a head pose set by the test, and two XRViews whose
//    eye transforms are the head's, offset by -/+ half the interpupillary
//    distance along the head's x axis, with symmetric perspective projections
//    using the session's depthNear / depthFar. Only valid inside a callback.
// The test drives it through `window.__xrDevice` (setHeadPose, waitFrames,
// pixels, refuseNext, endSession).
// The function must stay self-contained: Playwright serialises its source.

/**
 * @param {{eyeWidth: number, eyeHeight: number, fovYDeg: number, ipdM: number}} config
 */
export function installWebXRMock(config) {
  const { eyeWidth, eyeHeight, fovYDeg, ipdM } = config;

  // Column-major rigid transform from a position and a unit quaternion.
  const rigidMatrix = (p, q) => {
    const { x, y, z, w } = q;
    return new Float32Array([
      1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w), 0,
      2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w), 0,
      2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y), 0,
      p.x, p.y, p.z, 1,
    ]);
  };
  const rotate = (q, v) => {
    const m = rigidMatrix({ x: 0, y: 0, z: 0 }, q);
    return { x: m[0] * v.x + m[4] * v.y + m[8] * v.z, y: m[1] * v.x + m[5] * v.y + m[9] * v.z, z: m[2] * v.x + m[6] * v.y + m[10] * v.z };
  };

  class MockXRRigidTransform {
    constructor(position = {}, orientation = {}) {
      const p = { x: position.x ?? 0, y: position.y ?? 0, z: position.z ?? 0 };
      const o = { x: orientation.x ?? 0, y: orientation.y ?? 0, z: orientation.z ?? 0, w: orientation.w ?? 1 };
      const n = Math.hypot(o.x, o.y, o.z, o.w);
      this.position = new DOMPointReadOnly(p.x, p.y, p.z, 1);
      this.orientation = new DOMPointReadOnly(o.x / n, o.y / n, o.z / n, o.w / n);
      this.matrix = rigidMatrix(this.position, this.orientation);
    }
    get inverse() {
      const q = this.orientation;
      const conj = { x: -q.x, y: -q.y, z: -q.z, w: q.w };
      const p = rotate(conj, this.position);
      return new MockXRRigidTransform({ x: -p.x, y: -p.y, z: -p.z }, conj);
    }
  }

  const perspective = (fovDeg, aspect, near, far) => {
    const f = 1 / Math.tan((fovDeg * Math.PI) / 360);
    const m = new Float32Array(16);
    m[0] = f / aspect;
    m[5] = f;
    m[10] = (far + near) / (near - far);
    m[11] = -1;
    m[14] = (2 * far * near) / (near - far);
    return m;
  };

  const device = {
    head: new MockXRRigidTransform(),
    session: null,
    frames: 0,         // XR frames whose callbacks ran in the current session.
    pixels: null,      // The layer's RGBA pixels after the last frame (bottom row first).
    capture: false,    // Read the layer back after each frame.
    sessionsStarted: 0,
    refuseNext: false,  // Refuse the next requestSession (the user declines the prompt).
    /** Sets the head pose in the 'local' space: position (m) and orientation (unit quaternion). */
    setHeadPose(position, orientation) {
      this.head = new MockXRRigidTransform(position, orientation);
    },
    /** Resolves after `n` more frames of the running session. */
    waitFrames(n) {
      const target = this.frames + n;
      return new Promise((resolve, reject) => {
        const poll = () => {
          if (!this.session) reject(new Error('no XR session'));
          else if (this.frames >= target) resolve();
          else setTimeout(poll, 10);
        };
        poll();
      });
    },
    /** The user leaves VR (for example takes the headset off). */
    endSession() {
      return this.session ? this.session.end() : Promise.resolve();
    },
  };
  window.__xrDevice = device;

  class MockXRReferenceSpace extends EventTarget {
    constructor(type) {
      super();
      this.type = type;
    }
  }

  class MockXRView {
    constructor(eye, head, renderState) {
      this.eye = eye;
      const half = (eye === 'left' ? -0.5 : 0.5) * ipdM;
      const offset = rotate(head.orientation, { x: half, y: 0, z: 0 });
      const p = head.position;
      this.transform = new MockXRRigidTransform({ x: p.x + offset.x, y: p.y + offset.y, z: p.z + offset.z }, head.orientation);
      this.projectionMatrix = perspective(fovYDeg, eyeWidth / eyeHeight, renderState.depthNear, renderState.depthFar);
      this.recommendedViewportScale = null;
    }
  }

  class MockXRFrame {
    constructor(session) {
      this.session = session;
      this._active = true;
    }
    getViewerPose(space) {
      if (!this._active) throw new DOMException('the frame is not active', 'InvalidStateError');
      if (!(space instanceof MockXRReferenceSpace)) throw new TypeError('not an XRSpace');
      const head = device.head;
      const state = this.session.renderState;
      return {
        transform: head,
        emulatedPosition: false,
        views: [new MockXRView('left', head, state), new MockXRView('right', head, state)],
      };
    }
  }

  class MockXRSession extends EventTarget {
    constructor(mode) {
      super();
      this.mode = mode;
      this.visibilityState = 'visible';
      this.environmentBlendMode = 'opaque';
      this.renderState = { baseLayer: null, depthNear: 0.1, depthFar: 1000, inlineVerticalFieldOfView: null };
      this.onend = null;
      this._pending = null;
      this._callbacks = new Map();
      this._nextHandle = 1;
      this._ended = false;
      const tick = (time) => {
        if (this._ended) return;
        window.requestAnimationFrame(tick);
        if (this._pending) {
          this.renderState = { ...this.renderState, ...this._pending };
          this._pending = null;
        }
        const layer = this.renderState.baseLayer;
        if (!layer) return;  // No frames without a layer to draw into.
        const callbacks = [...this._callbacks.values()];
        this._callbacks.clear();
        if (callbacks.length === 0) return;
        const frame = new MockXRFrame(this);
        for (const cb of callbacks) {
          try {
            cb(time, frame);
          } catch (err) {
            setTimeout(() => { throw err; });
          }
        }
        frame._active = false;
        device.frames += 1;
        if (device.capture) device.pixels = layer._readPixels();
      };
      window.requestAnimationFrame(tick);
    }
    updateRenderState(state = {}) {
      if (this._ended) throw new DOMException('the session has ended', 'InvalidStateError');
      if (state.baseLayer && state.baseLayer._session !== this) {
        throw new DOMException('the layer belongs to another session', 'InvalidStateError');
      }
      this._pending = { ...(this._pending ?? {}), ...state };
    }
    requestReferenceSpace(type) {
      if (type !== 'local') {
        return Promise.reject(new DOMException(`reference space ${type} is not supported`, 'NotSupportedError'));
      }
      return Promise.resolve(new MockXRReferenceSpace(type));
    }
    requestAnimationFrame(callback) {
      const handle = this._nextHandle++;
      if (!this._ended) this._callbacks.set(handle, callback);
      return handle;
    }
    cancelAnimationFrame(handle) {
      this._callbacks.delete(handle);
    }
    end() {
      if (this._ended) return Promise.reject(new DOMException('the session has already ended', 'InvalidStateError'));
      this._ended = true;
      this._callbacks.clear();
      if (device.session === this) device.session = null;
      return new Promise((resolve) => {
        setTimeout(() => {
          const event = new Event('end');
          event.session = this;
          this.dispatchEvent(event);
          if (typeof this.onend === 'function') this.onend(event);
          resolve();
        }, 0);
      });
    }
  }

  class MockXRWebGLLayer {
    constructor(session, gl, init = {}) {
      if (!(session instanceof MockXRSession) || session._ended) {
        throw new DOMException('the session is not running', 'InvalidStateError');
      }
      if (!gl.getContextAttributes().xrCompatible && !gl.__xrCompatible) {
        throw new DOMException('the WebGL context is not XR compatible', 'InvalidStateError');
      }
      this._session = session;
      this._gl = gl;
      this.antialias = false;
      this.ignoreDepthValues = false;
      this.framebufferWidth = 2 * eyeWidth;
      this.framebufferHeight = eyeHeight;
      const previous = gl.getParameter(gl.FRAMEBUFFER_BINDING);
      this.framebuffer = gl.createFramebuffer();
      gl.bindFramebuffer(gl.FRAMEBUFFER, this.framebuffer);
      const color = gl.createRenderbuffer();
      gl.bindRenderbuffer(gl.RENDERBUFFER, color);
      gl.renderbufferStorage(gl.RENDERBUFFER, gl.RGBA8, this.framebufferWidth, this.framebufferHeight);
      gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.RENDERBUFFER, color);
      if (init.depth !== false) {
        const depth = gl.createRenderbuffer();
        gl.bindRenderbuffer(gl.RENDERBUFFER, depth);
        gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH24_STENCIL8, this.framebufferWidth, this.framebufferHeight);
        gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_STENCIL_ATTACHMENT, gl.RENDERBUFFER, depth);
      }
      if (gl.checkFramebufferStatus(gl.FRAMEBUFFER) !== gl.FRAMEBUFFER_COMPLETE) {
        throw new DOMException('cannot create the layer framebuffer', 'OperationError');
      }
      // Starts as transparent black, like a fresh XR framebuffer.
      gl.clearColor(0, 0, 0, 0);
      gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT | gl.STENCIL_BUFFER_BIT);
      gl.bindFramebuffer(gl.FRAMEBUFFER, previous);
      gl.bindRenderbuffer(gl.RENDERBUFFER, null);
    }
    getViewport(view) {
      if (!(view instanceof MockXRView)) throw new TypeError('not an XRView');
      return { x: view.eye === 'right' ? eyeWidth : 0, y: 0, width: eyeWidth, height: eyeHeight };
    }
    _readPixels() {
      const gl = this._gl;
      const previous = gl.getParameter(gl.FRAMEBUFFER_BINDING);
      gl.bindFramebuffer(gl.FRAMEBUFFER, this.framebuffer);
      const px = new Uint8Array(this.framebufferWidth * this.framebufferHeight * 4);
      gl.readPixels(0, 0, this.framebufferWidth, this.framebufferHeight, gl.RGBA, gl.UNSIGNED_BYTE, px);
      gl.bindFramebuffer(gl.FRAMEBUFFER, previous);
      return px;
    }
  }

  const xr = new (class MockXRSystem extends EventTarget {
    isSessionSupported(mode) {
      return Promise.resolve(mode === 'immersive-vr' || mode === 'inline');
    }
    requestSession(mode) {
      if (mode !== 'immersive-vr') {
        return Promise.reject(new DOMException(`session mode ${mode} is not supported`, 'NotSupportedError'));
      }
      if (device.refuseNext) {
        device.refuseNext = false;
        return Promise.reject(new DOMException('the user declined immersive VR', 'NotAllowedError'));
      }
      if (!navigator.userActivation?.isActive) {
        return Promise.reject(new DOMException('an immersive session needs a user gesture', 'SecurityError'));
      }
      if (device.session) {
        return Promise.reject(new DOMException('an immersive session is already running', 'InvalidStateError'));
      }
      device.session = new MockXRSession(mode);
      device.frames = 0;
      device.pixels = null;
      device.sessionsStarted += 1;
      return Promise.resolve(device.session);
    }
  })();

  Object.defineProperty(Navigator.prototype, 'xr', { configurable: true, get: () => xr });
  window.XRWebGLLayer = MockXRWebGLLayer;
  window.XRRigidTransform = MockXRRigidTransform;
  for (const Context of [window.WebGLRenderingContext, window.WebGL2RenderingContext]) {
    if (!Context) continue;
    Context.prototype.makeXRCompatible = function makeXRCompatible() {
      this.__xrCompatible = true;
      return Promise.resolve();
    };
  }
}
