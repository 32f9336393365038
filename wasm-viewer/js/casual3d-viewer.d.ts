// Type declarations of the casual3d web viewer (casual3d-viewer.js and the
// modules it re-exports). Hand-written; keep in step with the JavaScript.

export interface CameraState {
  /** Longitude of the view direction, degrees; 0 looks along -Z, +90 along +X. */
  yawDeg: number;
  /** Latitude of the view direction, degrees in [-89.9, 89.9]; +90 looks up (+Y). */
  pitchDeg: number;
  /** Vertical field of view, degrees (clamped to [minFovDeg, maxFovDeg]). */
  fovDeg: number;
  /**
   * Eye position in the panorama frame, in the unit of the package's depths
   * (metres when ViewHints.metric), inside the viewing volume.
   */
  position: [number, number, number];
}

/**
 * How a package should be looked at (manifest.json "view", spec/package.md
 * 1.1, or derived from its coarsest level when it has none).
 */
export interface ViewHints {
  /** Direction the package opens at: longitude and latitude, degrees. */
  yawDeg: number;
  pitchDeg: number;
  /** Vertical field of view that frames the content, degrees. */
  fovDeg: number;
  /**
   * Longitudes of the captured content [min, max], taken modulo 360 (narrowed
   * to where the coarsest level has surface); [-180, 180]: all around.
   */
  contentYawDeg: [number, number];
  /** Latitudes of the captured content [min, max], degrees. */
  contentPitchDeg: [number, number];
  /** Radius of the viewing volume around the panorama centre, unit of the depths. */
  volumeRadius: number;
  /** Whether the depths are in metres (else the capture's own unit). */
  metric: boolean;
  /** Near depth of the coarsest level (its 10th percentile), unit of the depths. */
  nearDepth: number;
  /** 'package': from the manifest; 'derived': from the coarsest level. */
  source: 'package' | 'derived';
}

export interface Effects {
  /** Moving point lights shading the scene with its normals (sky unlit). */
  lighting: boolean;
  /** A water surface rising and falling through the scene, depth-tested. */
  water: boolean;
  waterMinY: number;
  waterMaxY: number;
  /** A small inserted cube, hidden behind nearer scene geometry. */
  object: boolean;
  objectPosition: [number, number, number];
  objectSize: number;
}

export interface ViewerOptions {
  /** Finest level loaded (panorama width in pixels). Default 4096. */
  maxLevelWidth?: number;
  /** Triangle budget per level's mesh; larger meshes are simplified. Default 2,000,000. */
  maxTriangles?: number;
  /**
   * Radius of the ball the eye may move in (unit of the package's depths).
   * Default null: the package's viewing volume (ViewHints.volumeRadius).
   */
  maxOffset?: number | null;
  keyRotateDegPerSec?: number;
  /** W/A/S/D/Q/E speed in viewing-volume radii per second. Default 1. */
  keyMoveRadiiPerSec?: number;
  dragDegPerPixel?: number;
  /** Mouse position over the view moves the eye (motion parallax, up to the volume). Default true. */
  mouseParallax?: boolean;
  /** Soft limits keep the view on the captured content. Default true. */
  keepInContent?: boolean;
  /** A blurred continuation of the photo where no surface is; false: black. Default true. */
  softBackground?: boolean;
  /** Draw the backdrop behind the mesh (a coarse surface at the background's depth), so that tears show the background. Default true. */
  backdrop?: boolean;
  /** With the backdrop: fragments of mesh triangles that look more than this many times larger from the eye than from the centre (sheets across depth steps) are left out, so that what lies behind shows. 0 draws them all. Default 4. */
  sheetStretch?: number;
}

export interface ProgressDetail { loadedBytes: number; totalBytes: number; level: number; levels: number; }
export interface LevelDetail { level: number; levels: number; width: number; height: number; triangles: number; }
export interface FirstFrameDetail { timeToFirstFrameMs: number; bytesBeforeFirstFrame: number; }
export interface LoadDetail { levels: number; bytes: number; timeMs: number; }
export interface ErrorDetail {
  message: string;
  /** True when nothing could be shown; false when a coarser level stays on screen. */
  fatal: boolean;
}

export interface ViewerEventMap {
  progress: CustomEvent<ProgressDetail>;
  level: CustomEvent<LevelDetail>;
  firstframe: CustomEvent<FirstFrameDetail>;
  load: CustomEvent<LoadDetail>;
  error: CustomEvent<ErrorDetail>;
}

export interface ViewerStats {
  url?: string;
  level?: number;
  levels?: number;
  triangles?: number;
  vertices?: number;
  packageBytes?: number;
  timeToFirstFrameMs?: number;
  bytesBeforeFirstFrame?: number;
  loadMs?: number;
  lastError?: string;
  /** Frames drawn in the current or last immersive VR session. */
  xrFrames?: number;
  /**
   * Per level shown, the worker's times (fetch and decode; assembly, mesh and
   * atlas) and the threads of its wasm build: more than 1 on cross-origin
   * isolated pages, 1 elsewhere.
   */
  workerMs?: { level: number; fetchDecodeMs: number; meshMs: number; threads: number }[];
}

export class Casual3dViewer extends EventTarget {
  constructor(container: HTMLElement, options?: ViewerOptions);
  readonly canvas: HTMLCanvasElement;
  readonly stats: ViewerStats;
  /** Loads a package from its manifest URL; resolves when the first level is shown. */
  load(url: string): Promise<void>;
  /** Held inside the viewing volume and (keepInContent) the content's limits. */
  setCamera(camera: Partial<CameraState>): void;
  getCamera(): CameraState;
  /** Back to the package's framed view, eye at the centre. */
  resetView(): void;
  /** The package's view hints; null until its first level is shown. */
  getViewHints(): ViewHints | null;
  /** Radius of the ball the eye is held in (the package's volume unless options.maxOffset). */
  readonly maxOffset: number;
  /** The eye this frame: the camera's position plus mouse parallax, inside the volume. */
  readonly eyePosition: [number, number, number];
  /** Fraction of the current view's pixels that no surface covers (measured offscreen). */
  measureBackground(): number;
  setEffects(effects: Partial<Effects>): void;
  getEffects(): Effects;
  /** Freezes the effects' animation at a time in seconds (null: real time). */
  setEffectsTime(timeSec: number | null): void;
  /** Resolves after the next frame has been drawn. */
  nextFrame(): Promise<void>;
  isVRSupported(): Promise<boolean>;
  enterVR(): Promise<void>;
  /** Ends the immersive VR session, if any. */
  exitVR(): Promise<void>;
  /** Whether an immersive VR session is running. */
  readonly inVR: boolean;
  /** Call from a user gesture; resolves false when unavailable or refused. */
  enableDeviceMotion(): Promise<boolean>;
  dispose(): void;
  addEventListener<K extends keyof ViewerEventMap>(type: K, listener: (ev: ViewerEventMap[K]) => void,
    options?: boolean | AddEventListenerOptions): void;
  addEventListener(type: string, listener: EventListenerOrEventListenerObject | null,
    options?: boolean | AddEventListenerOptions): void;
}

/** <casual3d-viewer src="manifest.json" controls info-open effects="lighting water object" yaw pitch fov max-level-width>;
 * children with slot="info" fill the info panel. */
export class Casual3dViewerElement extends HTMLElement {
  readonly viewer: Casual3dViewer | null;
  src: string;
  /** The error message on display, or ''. */
  readonly errorMessage: string;
  /** The info panel's text while it shows, or ''. */
  readonly infoText: string;
  /** Shows (default) or hides the info panel; it shows only with children in slot "info". */
  showInfo(show?: boolean): void;
  load(url?: string): Promise<void>;
  setCamera(camera: Partial<CameraState>): void;
  getCamera(): CameraState | undefined;
  resetView(): void;
  getViewHints(): ViewHints | null;
  setEffects(effects: Partial<Effects>): void;
  addEventListener<K extends keyof ViewerEventMap>(type: K, listener: (ev: ViewerEventMap[K]) => void,
    options?: boolean | AddEventListenerOptions): void;
  addEventListener(type: string, listener: EventListenerOrEventListenerObject | null,
    options?: boolean | AddEventListenerOptions): void;
}

declare global {
  interface HTMLElementTagNameMap {
    'casual3d-viewer': Casual3dViewerElement;
  }
}

/**
 * The folder (URL, relative to the page) the viewer's worker and wasm files
 * are served from, for pages that bundle this module; null: beside this module.
 * Call it before the element loads (it loads after the script registering it).
 */
export function setAssetBase(url: string | URL | null): void;
