// Node tests of the viewer's effect modules (js/effects.js): each module keeps
// the contract the renderer relies on, the effects state is the union of
// their defaults, and drawing leaves the WebGL state as it found it (blending
// off, depth writes on), checked on a recording stand-in for the context.
//
//   node --test wasm-viewer/test/effects.test.mjs

import assert from 'node:assert/strict';
import { test } from 'node:test';

import { EFFECTS, EFFECT_BUTTONS } from '../js/effects.js';
import { DEFAULT_EFFECTS } from '../js/renderer.js';

/** A stand-in WebGL2 context: constants are their names, calls are recorded. */
function recordingGl() {
  const calls = [];
  const state = { blend: false, depthMask: true };
  const gl = new Proxy({}, {
    get(_, key) {
      if (typeof key !== 'string') return undefined;
      if (/^[A-Z_0-9]+$/.test(key)) return key;
      if (key === 'calls') return calls;
      if (key === 'state') return state;
      return (...args) => {
        calls.push([key, ...args]);
        if (key === 'enable' && args[0] === 'BLEND') state.blend = true;
        if (key === 'disable' && args[0] === 'BLEND') state.blend = false;
        if (key === 'depthMask') state.depthMask = args[0];
        return {};
      };
    },
  });
  return gl;
}

test('every effect module has a unique name, a toolbar label and title, and the hooks', () => {
  const names = new Set();
  for (const e of EFFECTS) {
    assert.equal(typeof e.name, 'string');
    assert.ok(/^[a-z]+$/.test(e.name), e.name);
    assert.ok(!names.has(e.name), `two modules named ${e.name}`);
    names.add(e.name);
    assert.ok(e.label && e.title, `${e.name}: label and title`);
    assert.equal(e.defaults[e.name], false, `${e.name}: off by default`);
    for (const hook of ['init', 'draw', 'dispose']) assert.equal(typeof e[hook], 'function', `${e.name}.${hook}`);
  }
  assert.deepEqual(EFFECT_BUTTONS.map((b) => b.name), ['lighting', ...EFFECTS.map((e) => e.name)]);
});

test('the effects state is the lighting plus the union of the modules\' defaults, each field owned once', () => {
  const owner = new Map([['lighting', 'renderer']]);
  for (const e of EFFECTS) {
    for (const key of Object.keys(e.defaults)) {
      assert.ok(!owner.has(key), `${key} belongs to ${owner.get(key)} and ${e.name}`);
      owner.set(key, e.name);
    }
  }
  assert.deepEqual(Object.keys(DEFAULT_EFFECTS).sort(), [...owner.keys()].sort());
  assert.equal(DEFAULT_EFFECTS.lighting, false);
  assert.ok(Object.isFrozen(DEFAULT_EFFECTS));
});

test('init, draw and dispose of each module on a recording context', () => {
  for (const e of EFFECTS) {
    const gl = recordingGl();
    const made = { programs: [], uploads: [], released: [] };
    const state = e.init({
      gl,
      program: (fs) => {
        assert.ok(fs.startsWith('#version 300 es'), `${e.name}: a GLSL ES 3.00 fragment shader`);
        const p = { program: {}, uniforms: new Proxy({}, { get: (_, k) => `loc:${String(k)}` }) };
        made.programs.push(p);
        return p;
      },
      upload: (g) => {
        assert.equal(g.positions.length % 3, 0);
        assert.equal(g.normals.length, g.positions.length);
        assert.ok(g.indices.length > 0 && g.indices.length % 3 === 0);
        for (const i of g.indices) assert.ok(i < g.positions.length / 3);
        const geometry = { vao: {}, count: g.indices.length };
        made.uploads.push(geometry);
        return geometry;
      },
      lighting: 'vec3 shade(vec3 a, vec3 p, vec3 n) { return a; }',
    });
    assert.equal(made.programs.length, 1, `${e.name}: one program`);
    let common = 0;
    e.draw(state, {
      gl, effects: { ...DEFAULT_EFFECTS, [e.name]: true }, eye: [0, 0, 0], timeSec: 1.5,
      setCommon: (p) => { assert.equal(p, made.programs[0]); ++common; },
    });
    assert.equal(common, 1, `${e.name}: the shared uniforms are set once`);
    const draws = gl.calls.filter((c) => c[0] === 'drawElements');
    assert.ok(draws.length >= 1, `${e.name}: draws`);
    assert.equal(gl.state.blend, false, `${e.name}: blending left on`);
    assert.equal(gl.state.depthMask, true, `${e.name}: depth writes left off`);
    e.dispose(state, { gl, release: (g) => made.released.push(g) });
    assert.deepEqual(made.released, made.uploads, `${e.name}: every upload released`);
  }
});
