// Shared checks of the viewer's tests against the native code: one level of a
// package read and meshed by the wasm library (the browser's path, WebP
// through @jsquash/webp) against the native reader and mesh builder
// (viewer_test_tool), and a viewer's frame against the native renderer's image.

import assert from 'node:assert/strict';
import fs from 'node:fs';

import { compareArrays, parseMeshBlob, runTool } from './node-support.mjs';
import { readPackageLevel } from './node-package.mjs';

/**
 * Reads `level` of the package in folder `pkg` with the wasm reader and builds
 * its full mesh; has viewer_test_tool do the same natively (writing
 * `${base}.mesh`). Asserts that positions, normals, uvs and indices are
 * byte-identical (depth, normals and links are stored lossless) and that
 * colours differ by at most `maxColorDifference` levels (the colour images are
 * lossy WebP, decoded by two different builds of libwebp).
 * Returns {triangles, colors: {differing, maxAbs}}.
 */
export async function assertLevelMatchesNative(format, pkg, level, base, { maxColorDifference = 2 } = {}) {
  runTool('viewer_test_tool', ['mesh', pkg, String(level), base]);
  const native = parseMeshBlob(fs.readFileSync(`${base}.mesh`));
  const { pano } = await readPackageLevel(format, pkg, level);
  let wasm;
  try {
    wasm = format.buildMesh(pano);
  } finally {
    pano.free();
  }
  for (const field of ['positions', 'normals', 'uvs', 'indices']) {
    const r = compareArrays(wasm[field], native[field]);
    assert.ok(r.sameLength, `${field}: ${wasm[field].length} (wasm) vs ${native[field].length} (native) elements`);
    assert.equal(r.differing, 0, `${field}: ${r.differing} elements differ (largest ${r.maxAbs})`);
  }
  const colors = compareArrays(wasm.colors, native.colors);
  assert.ok(colors.sameLength, `colors: ${wasm.colors.length} (wasm) vs ${native.colors.length} (native) elements`);
  assert.ok(colors.maxAbs <= maxColorDifference, `colours differ by up to ${colors.maxAbs}`);
  return { triangles: native.indices.length / 3, colors: { differing: colors.differing, maxAbs: colors.maxAbs } };
}

/** A binary PPM (P6) file: {width, height, data: RGB bytes, top row first}. */
export function readPpm(file) {
  const buf = fs.readFileSync(file);
  const header = buf.subarray(0, 64).toString('latin1').match(/^P6\s+(\d+)\s+(\d+)\s+255\s/);
  assert.ok(header, `${file}: not a binary PPM`);
  return { width: Number(header[1]), height: Number(header[2]), data: buf.subarray(header[0].length) };
}

/** PSNR (dB) of WebGL RGBA (bottom row first) against RGB (top row first). */
export function psnr(glRgba, rgb, width, height) {
  let se = 0;
  for (let y = 0; y < height; ++y) {
    const gy = height - 1 - y;
    for (let x = 0; x < width; ++x) {
      for (let c = 0; c < 3; ++c) {
        const d = glRgba[(gy * width + x) * 4 + c] - rgb[(y * width + x) * 3 + c];
        se += d * d;
      }
    }
  }
  const mse = se / (width * height * 3);
  return mse === 0 ? Infinity : 10 * Math.log10((255 * 255) / mse);
}

/**
 * The pixels (RGBA, bottom row first) of the viewer's canvas in `page` after
 * its next frame: window.viewer (a viewer-core page), else element #v's.
 */
export async function readCanvas(page) {
  const b64 = await page.evaluate(async () => {
    const v = window.viewer ?? document.getElementById('v').viewer;
    await v.nextFrame();
    const gl = v.renderer.gl;
    const px = new Uint8Array(gl.drawingBufferWidth * gl.drawingBufferHeight * 4);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.readPixels(0, 0, gl.drawingBufferWidth, gl.drawingBufferHeight, gl.RGBA, gl.UNSIGNED_BYTE, px);
    let s = '';
    for (let i = 0; i < px.length; i += 0x8000) s += String.fromCharCode.apply(null, px.subarray(i, i + 0x8000));
    return btoa(s);
  });
  return new Uint8Array(Buffer.from(b64, 'base64'));
}
