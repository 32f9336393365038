// <casual3d-viewer src="scene/manifest.json"></casual3d-viewer>: the embeddable
// 3D photo viewer (src: a package folder's manifest.json or a .c3d file). One
// script (this module) and one element:
//
//   <script type="module" src="viewer/casual3d-viewer.js"></script>
//   <casual3d-viewer src="manifest.json" controls></casual3d-viewer>
//
// Attributes: src (manifest.json or .c3d URL), controls (show the toolbar), info-open (show the
// info panel at load: the element's children in slot "info", e.g. the capture's advice that
// `casual3d reconstruct` writes into index.html; an Info button toggles it), effects (any of
// "lighting water object", space separated), yaw, pitch, fov (degrees; without
// them a package opens framed on its captured content), max-level-width
// (finest level loaded, pixels).
// Events (bubbling, composed): progress, level, firstframe, load, error; see
// viewer-core.js. Property `viewer` gives the Casual3dViewer (JS API).

import { Casual3dViewer } from './viewer-core.js';
import { EFFECT_BUTTONS } from './effects.js';

export { Casual3dViewer } from './viewer-core.js';
export { setAssetBase } from './assets.js';

const STYLE = `
:host { display: block; position: relative; width: 100%; height: 360px; background: #000; overflow: hidden;
  font: 13px/1.4 system-ui, sans-serif; color: #fff; contain: content; }
.view { position: absolute; inset: 0; }
.progress { position: absolute; left: 0; right: 0; bottom: 0; height: 3px; background: rgba(255,255,255,.15); }
.progress > div { height: 100%; width: 0; background: #4ea1ff; transition: width .15s; }
.progress[hidden] { display: none; }
.status { position: absolute; left: 50%; top: 50%; transform: translate(-50%, -50%); opacity: .8; pointer-events: none; }
.error { position: absolute; left: 8px; right: 8px; top: 8px; padding: 8px 10px; border-radius: 4px;
  background: rgba(160, 20, 20, .9); white-space: pre-wrap; word-break: break-word; }
.error[hidden], .status[hidden], .toolbar[hidden], button[hidden] { display: none; }
.error button { float: right; margin-left: 8px; background: none; border: 0; color: #fff; font-size: 16px; cursor: pointer; }
.toolbar { position: absolute; right: 8px; bottom: 10px; display: flex; gap: 4px; }
.toolbar button { background: rgba(0,0,0,.55); color: #fff; border: 1px solid rgba(255,255,255,.35); border-radius: 4px;
  padding: 3px 8px; cursor: pointer; font: inherit; }
.toolbar button[aria-pressed="true"] { background: rgba(78,161,255,.75); }
.info { position: absolute; left: 8px; top: 8px; max-width: min(32em, calc(100% - 16px)); max-height: calc(100% - 60px);
  overflow: auto; box-sizing: border-box; padding: 10px 30px 4px 12px; border-radius: 4px; background: rgba(0,0,0,.72); }
.info[hidden] { display: none; }
.info > button { position: absolute; right: 6px; top: 4px; background: none; border: 0; color: #fff; font-size: 16px; cursor: pointer; }
`;

export class Casual3dViewerElement extends HTMLElement {
  static get observedAttributes() {
    return ['src', 'controls', 'info-open', 'effects', 'yaw', 'pitch', 'fov'];
  }

  constructor() {
    super();
    const root = this.attachShadow({ mode: 'open' });
    root.innerHTML = `<style>${STYLE}</style>
      <div class="view" part="view"></div>
      <div class="status" part="status" hidden></div>
      <div class="progress" part="progress" hidden><div></div></div>
      <div class="error" part="error" role="alert" hidden><button type="button" aria-label="Dismiss">×</button><span></span></div>
      <div class="info" part="info" role="note" hidden><button type="button" aria-label="Close">×</button><slot name="info"></slot></div>
      <div class="toolbar" part="toolbar" hidden>
        ${EFFECT_BUTTONS.map((e) => `<button type="button" data-effect="${e.name}" aria-pressed="false" title="${e.title}">${e.label}</button>`).join('\n        ')}
        <button type="button" data-action="motion" hidden title="Look around by moving the phone">Motion</button>
        <button type="button" data-action="vr" hidden title="Immersive VR">VR</button>
        <button type="button" data-action="info" hidden aria-pressed="false" title="About this capture">Info</button>
        <button type="button" data-action="reset" title="Reset view (R)">Reset</button>
      </div>`;
    this._els = {
      view: root.querySelector('.view'),
      status: root.querySelector('.status'),
      progress: root.querySelector('.progress'),
      bar: root.querySelector('.progress > div'),
      error: root.querySelector('.error'),
      errorText: root.querySelector('.error span'),
      toolbar: root.querySelector('.toolbar'),
      info: root.querySelector('.info'),
      infoSlot: root.querySelector('slot[name="info"]'),
      infoButton: root.querySelector('[data-action="info"]'),
    };
    this._viewer = null;
  }

  /** The Casual3dViewer behind the element (created when connected). */
  get viewer() {
    return this._viewer;
  }

  get src() {
    return this.getAttribute('src') ?? '';
  }

  set src(value) {
    this.setAttribute('src', value);
  }

  connectedCallback() {
    if (this._viewer) return;
    try {
      const maxLevelWidth = Number(this.getAttribute('max-level-width')) || undefined;
      this._viewer = new Casual3dViewer(this._els.view, maxLevelWidth ? { maxLevelWidth } : {});
    } catch (err) {
      this._showError(err.message || String(err));
      this.dispatchEvent(new CustomEvent('error', { detail: { message: err.message, fatal: true }, bubbles: true, composed: true }));
      return;
    }
    const v = this._viewer;
    for (const type of ['progress', 'level', 'firstframe', 'load', 'error']) {
      v.addEventListener(type, (e) => {
        this._onViewerEvent(type, e.detail);
        this.dispatchEvent(new CustomEvent(type, { detail: e.detail, bubbles: true, composed: true }));
      });
    }
    this._bindToolbar();
    this._applyAttributes();
    this.showInfo(this.hasAttribute('info-open'));
    // After the running script: a page that registered the element in the same
    // script may still call setAssetBase() or set src.
    queueMicrotask(() => {
      if (this._viewer && this.src && !this._loading) this._load();
    });
  }

  disconnectedCallback() {
    this._viewer?.dispose();
    this._viewer = null;
  }

  attributeChangedCallback(name, oldValue, newValue) {
    if (!this._viewer || oldValue === newValue) return;
    if (name === 'src') this._load();
    else if (name === 'info-open') this.showInfo(newValue !== null);
    else this._applyAttributes();
  }

  /** Loads `url` (or the src attribute); resolves when the first level shows. */
  load(url) {
    if (url !== undefined && url !== this.src) {
      this.setAttribute('src', url);  // attributeChangedCallback loads it.
      return this._loading;
    }
    return this._load();
  }

  /** See Casual3dViewer.setCamera. */
  setCamera(camera) {
    this._viewer?.setCamera(camera);
  }

  getCamera() {
    return this._viewer?.getCamera();
  }

  /** Back to the package's framed view. */
  resetView() {
    this._viewer?.resetView();
  }

  /** See Casual3dViewer.getViewHints: null until the first level shows. */
  getViewHints() {
    return this._viewer?.getViewHints() ?? null;
  }

  /** Shows or hides the info panel (the children in slot "info"). */
  showInfo(show = true) {
    this._els.info.hidden = !(show && this._hasInfo());
    this._els.infoButton.setAttribute('aria-pressed', String(!this._els.info.hidden));
  }

  /** The info panel's text while it shows, or '' (for tests and embedding pages). */
  get infoText() {
    if (this._els.info.hidden) return '';
    return this._els.infoSlot.assignedElements().map((e) => e.innerText).join('\n');
  }

  _hasInfo() {
    return this._els.infoSlot.assignedElements().length > 0;
  }

  setEffects(effects) {
    this._viewer?.setEffects(effects);
    this._syncToolbar();
  }

  _load() {
    this._hideError();
    this._els.status.textContent = 'Loading…';
    this._els.status.hidden = false;
    this._els.progress.hidden = false;
    this._els.bar.style.width = '0';
    this._loading = this._viewer.load(this.src).catch(() => {});  // Errors arrive as 'error' events.
    this._applyCamera();  // yaw, pitch, fov replace the package's framed view.
    return this._loading;
  }

  _applyCamera() {
    const num = (n) => (this.hasAttribute(n) ? Number(this.getAttribute(n)) : undefined);
    const camera = { yawDeg: num('yaw'), pitchDeg: num('pitch'), fovDeg: num('fov') };
    if (Object.values(camera).some((v) => v !== undefined)) this._viewer.setCamera(camera);
  }

  _applyAttributes() {
    const v = this._viewer;
    this._els.toolbar.hidden = !this.hasAttribute('controls');
    this._applyCamera();
    if (this.hasAttribute('effects')) {
      const on = new Set((this.getAttribute('effects') || '').split(/\s+/));
      v.setEffects(Object.fromEntries(EFFECT_BUTTONS.map((e) => [e.name, on.has(e.name)])));
    }
    this._syncToolbar();
  }

  _bindToolbar() {
    const root = this.shadowRoot;
    root.querySelector('.error button').addEventListener('click', () => this._hideError());
    for (const b of root.querySelectorAll('[data-effect]')) {
      b.addEventListener('click', () => {
        const name = b.dataset.effect;
        this._viewer.setEffects({ [name]: !this._viewer.getEffects()[name] });
        this._syncToolbar();
      });
    }
    root.querySelector('[data-action="reset"]').addEventListener('click', () => this._viewer.resetView());
    const els = this._els;
    els.infoButton.hidden = !this._hasInfo();
    els.infoSlot.addEventListener('slotchange', () => {
      els.infoButton.hidden = !this._hasInfo();
      this.showInfo(this._hasInfo() && (this.hasAttribute('info-open') || !els.info.hidden));
    });
    els.infoButton.addEventListener('click', () => this.showInfo(els.info.hidden));
    els.info.querySelector('button').addEventListener('click', () => this.showInfo(false));
    const vr = root.querySelector('[data-action="vr"]');
    this._viewer.isVRSupported().then((ok) => { vr.hidden = !ok; });
    vr.addEventListener('click', () => this._viewer.enterVR().catch((err) => this._showError(err.message)));
    const motion = root.querySelector('[data-action="motion"]');
    motion.hidden = !('DeviceOrientationEvent' in window && matchMedia('(pointer: coarse)').matches);
    motion.addEventListener('click', async () => {
      const ok = await this._viewer.enableDeviceMotion();
      motion.setAttribute('aria-pressed', String(ok));
      if (!ok) this._showError('device motion is not available or was not allowed');
    });
  }

  _syncToolbar() {
    if (!this._viewer) return;
    const effects = this._viewer.getEffects();
    for (const b of this.shadowRoot.querySelectorAll('[data-effect]')) {
      b.setAttribute('aria-pressed', String(!!effects[b.dataset.effect]));
    }
  }

  _onViewerEvent(type, detail) {
    const els = this._els;
    if (type === 'progress') {
      const f = detail.totalBytes > 0 ? detail.loadedBytes / detail.totalBytes : 0;
      els.bar.style.width = `${Math.round(100 * Math.min(1, f))}%`;
    } else if (type === 'level') {
      els.status.hidden = true;
    } else if (type === 'load') {
      els.progress.hidden = true;
    } else if (type === 'error') {
      els.status.hidden = true;
      els.progress.hidden = true;
      this._showError(detail.fatal ? detail.message : `${detail.message}\nShowing the coarser level already loaded.`);
    }
  }

  _showError(message) {
    this._els.errorText.textContent = message;
    this._els.error.hidden = false;
  }

  _hideError() {
    this._els.error.hidden = true;
    this._els.errorText.textContent = '';
  }

  /** The error message on display, or '' (for tests and embedding pages). */
  get errorMessage() {
    return this._els.error.hidden ? '' : this._els.errorText.textContent;
  }
}

if (!customElements.get('casual3d-viewer')) customElements.define('casual3d-viewer', Casual3dViewerElement);
