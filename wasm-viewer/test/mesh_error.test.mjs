// Node tests of the simplifier's error the viewer asks for (js/mesh-error.js).

import assert from 'node:assert/strict';
import { test } from 'node:test';

import { depthCodeStep, SIMPLIFY_ERROR, simplifyMaxError } from '../js/mesh-error.js';

const near = (a, b, tol = 1e-9) => Math.abs(a - b) <= tol;

test('depthCodeStep is the depth ratio of neighbouring codes less one (spec Sec. 4.2)', () => {
  // About twice the spec's stated largest error (0.34% for 10 bits, 0.084% for 12, far/near 1000).
  assert.ok(near(depthCodeStep({ type: 'log', bits: 10, near_m: 0.5, far_m: 500 }), 0.0067820, 1e-7));
  assert.ok(near(depthCodeStep({ type: 'log', bits: 12, near_m: 1, far_m: 1000 }), 0.0016887, 1e-7));
  // Decoding codes 1 and 2 of a 9-bit code (Sec. 4.2) gives depths whose ratio is 1 + step.
  const enc = { type: 'log', bits: 9, near_m: 0.3, far_m: 45 };
  const r = Math.log(enc.far_m / enc.near_m);
  const decode = (code) => enc.near_m * Math.exp(((code - 1) / (2 ** enc.bits - 2)) * r);
  assert.ok(near(decode(2) / decode(1) - 1, depthCodeStep(enc), 1e-12));
  assert.ok(near(decode(300) / decode(299) - 1, depthCodeStep(enc), 1e-12));
});

test('simplifyMaxError adds the code step to the viewer\'s 1% and stays within the simplifier\'s range', () => {
  const ten = { type: 'log', bits: 10, near_m: 1, far_m: 1000 };
  assert.equal(SIMPLIFY_ERROR, 0.01);
  assert.ok(near(simplifyMaxError(ten), 0.01 + depthCodeStep(ten)));
  const nine = { type: 'log', bits: 9, near_m: 1, far_m: 1000 };
  assert.ok(simplifyMaxError(nine) > simplifyMaxError(ten));
  assert.equal(simplifyMaxError({ type: 'log', bits: 2, near_m: 1, far_m: 1e9 }), 0.5);
});

test('depthCodeStep refuses a depth_encoding the spec forbids', () => {
  for (const bad of [undefined, {}, { bits: 10, near_m: 1, far_m: 1 }, { bits: 10, near_m: 0, far_m: 5 },
    { bits: 10.5, near_m: 1, far_m: 5 }, { bits: 10, near_m: 1, far_m: Infinity }]) {
    assert.throws(() => depthCodeStep(bad), /depth_encoding/);
  }
});
