// The viewer's effects drawn over the photo, one module each, in drawing
// order (transparent ones last). A module is
//   { name, label, title, defaults, init(ctx) -> state, draw(state, ctx), dispose(state, ctx) }
// where `defaults` holds the fields it adds to the effects state (its `name`
// among them, false: off); the renderer (renderer.js) calls init once per
// WebGL context, draw when effects[name] is on, and dispose with the context.
// The toolbar of <casual3d-viewer> shows one button per module (label,
// title), and its `effects` attribute names them. A new effect is one file
// (effect-<name>.js), listed below, and its test.
//
// "lighting" is not a module: it relights the photo's own mesh with its
// normals (the renderer's scene shader), and the modules' objects with it.

import object from './effect-object.js';
import water from './effect-water.js';

export const EFFECTS = Object.freeze([object, water]);

/** Toolbar entries: the lighting first, then every module. */
export const EFFECT_BUTTONS = Object.freeze([
  { name: 'lighting', label: 'Light', title: 'Moving lights' },
  ...EFFECTS.map(({ name, label, title }) => ({ name, label, title })),
]);
