// Decodes a package's tile images with the browser's own image decoder (for the
// MIME type the reader names: WebP in packages 1.x and 2.x) into exact RGBA pixels, off
// the main thread (works in workers).
// createImageBitmap with colour-space conversion and premultiplication off, and
// an OffscreenCanvas 2D readback: the package's images are opaque RGB (alpha is
// ignored by the format), so the readback returns the decoded values unchanged.

// One canvas per image size: a package's images come in two to three sizes
// (w x h graph, w x 2h colour, depth and normal, 2w x 2h lossy normal), and
// resizing a single canvas between them reallocates its backing store.
const contexts = new Map();

function contextFor(width, height) {
  const key = `${width}x${height}`;
  let context = contexts.get(key);
  if (context) {
    context.clearRect(0, 0, width, height);
    return context;
  }
  if (contexts.size >= 4) contexts.clear();
  context = new OffscreenCanvas(width, height).getContext('2d', { willReadFrequently: true, alpha: true });
  if (!context) throw new Error('this browser offers no 2D OffscreenCanvas to read decoded tiles');
  contexts.set(key, context);
  return context;
}

/**
 * @param {Uint8Array} bytes the encoded image
 * @param {string} name used in error messages (the file's path)
 * @param {string} type its MIME type (PackageReader.tileImageType)
 * @returns {Promise<{width: number, height: number, data: Uint8ClampedArray}>} RGBA
 */
export async function decodeImage(bytes, name, type) {
  let bitmap;
  try {
    bitmap = await createImageBitmap(new Blob([bytes], { type }), {
      premultiplyAlpha: 'none', colorSpaceConversion: 'none',
    });
  } catch {
    throw new Error(`${name}: not a decodable image (corrupt or truncated file)`);
  }
  try {
    const { width, height } = bitmap;
    const context = contextFor(width, height);
    context.drawImage(bitmap, 0, 0);
    return { width, height, data: context.getImageData(0, 0, width, height).data };
  } finally {
    bitmap.close();
  }
}
