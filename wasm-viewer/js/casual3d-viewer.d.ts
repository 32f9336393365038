// Type declarations of the casual3d web viewer (casual3d-viewer.js and the
// modules it re-exports). Hand-written; keep in step with the JavaScript.

export interface CameraState {
  /** Longitude of the view direction, degrees; 0 looks along -Z, +90 along +X. */
  yawDeg: number;
  /** Latitude of the view direction, degrees in [-89.9, 89.9]; +90 looks up (+Y). */
  pitchDeg: number;
  /** Vertical field of view, degrees (clamped to [minFovDeg, maxFovDeg]). */
  fovDeg: number;
  /** Eye position in metres in the panorama frame, inside the parallax ball. */
  position: [number, number, number];
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
  /** Radius of the ball the eye may move in (metres). Default 0.3. */
  maxOffset?: number;
  keyRotateDegPerSec?: number;
  keyMoveMPerSec?: number;
  dragDegPerPixel?: number;
  /** Mouse position over the view moves the eye (motion parallax). Default true. */
  mouseParallax?: boolean;
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
  setCamera(camera: Partial<CameraState>): void;
  getCamera(): CameraState;
  resetView(): void;
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

/** <casual3d-viewer src="manifest.json" controls effects="lighting water object" yaw pitch fov max-level-width> */
export class Casual3dViewerElement extends HTMLElement {
  readonly viewer: Casual3dViewer | null;
  src: string;
  /** The error message on display, or ''. */
  readonly errorMessage: string;
  load(url?: string): Promise<void>;
  setCamera(camera: Partial<CameraState>): void;
  getCamera(): CameraState | undefined;
  resetView(): void;
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
