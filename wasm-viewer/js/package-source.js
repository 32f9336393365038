// Where a package's files come from (spec/package.md): a package folder on a
// web server (manifest.json and one file per tile image), or the single-file
// container (.c3d, Sec. 8) read in byte ranges: over HTTP with Range requests,
// from a Blob or File, or from bytes in memory. Every source gives the bytes
// of manifest.json and read(path) for the files it names; the package reader
// checks each file's size and SHA-256, so a source only moves bytes.
//
// A .c3d over HTTP costs one request for its header and directory (the first
// 16 KiB, more for a long directory), one for the manifest unless those bytes
// hold it, then one range per file (the files those bytes hold excepted),
// so that the coarsest level shows after a few requests. A server that
// ignores Range (200 instead of 206) sends the whole file, which is then read
// from memory.

/**
 * Runs `task(item)` over `items` with at most `limit` in flight. On the first
 * failure no new task starts; it waits for the running ones to settle (so none
 * touches the reader afterwards) and then throws that failure.
 */
export async function forEachLimited(items, limit, task) {
  let next = 0;
  let failure = null;
  const runners = Array.from({ length: Math.min(limit, items.length) }, async () => {
    while (next < items.length && !failure) {
      try {
        await task(items[next++]);
      } catch (err) {
        failure ??= err;
      }
    }
  });
  await Promise.all(runners);
  if (failure) throw failure;
}

const PREFIX_BYTES = 16 * 1024;
const SINGLE_FILE_MAGIC = [0x89, 0x43, 0x33, 0x44, 0x0d, 0x0a, 0x1a, 0x0a];

/** Whether `bytes` begin with the .c3d magic. */
export function isSingleFile(bytes) {
  return bytes.length >= 8 && SINGLE_FILE_MAGIC.every((b, i) => bytes[i] === b);
}

/** Whether a URL or file name names a .c3d file (by its extension). */
export function hasSingleFileExtension(name) {
  const p = String(name).split(/[?#]/)[0];
  return /\.c3d$/i.test(p);
}

/** The body of a fetch response; `name` prefixes the error messages. */
async function responseBytes(response, name) {
  try {
    return new Uint8Array(await response.arrayBuffer());
  } catch {
    throw new Error(`${name}: the download was interrupted`);
  }
}

async function fetchOrThrow(fetchFn, url, name, init) {
  let response;
  try {
    response = await fetchFn(url, init);
  } catch {
    throw new Error(`${name}: cannot be fetched (network error)`);
  }
  if (!response.ok) throw new Error(`${name}: HTTP ${response.status} ${response.statusText || ''}`.trim());
  return response;
}

/** The whole file at `url` as bytes. */
export async function fetchBytes(url, name, fetchFn = fetch) {
  return responseBytes(await fetchOrThrow(fetchFn, url, name), name);
}

/**
 * A package folder served over HTTP: `url` is its manifest.json. A .c3d
 * behind a URL without the extension is read from the bytes fetched.
 */
export async function openFolderUrl(format, url, { fetch: fetchFn = fetch } = {}) {
  const manifestBytes = await fetchBytes(url, 'manifest.json', fetchFn);
  if (isSingleFile(manifestBytes)) return openSingleFile(format, memoryRanges(manifestBytes));
  return {
    kind: 'folder',
    manifestBytes,
    read: (path) => fetchBytes(new URL(path, url).href, path, fetchFn),
  };
}

/**
 * Byte ranges of bytes in memory: {size, read(offset, length)}.
 */
export function memoryRanges(bytes) {
  return { size: bytes.length, read: async (offset, length) => bytes.subarray(offset, offset + length) };
}

/** Byte ranges of a Blob or File. */
export function blobRanges(blob) {
  return {
    size: blob.size,
    read: async (offset, length) => new Uint8Array(await blob.slice(offset, offset + length).arrayBuffer()),
  };
}

/**
 * Byte ranges of a file over HTTP. The first request asks for the first
 * `prefixBytes`; a 206 answer gives the file's size (Content-Range) and
 * further reads are Range requests, a 200 answer (the server ignores Range)
 * the whole file, read from memory from then on.
 */
export async function httpRanges(url, { fetch: fetchFn = fetch, prefixBytes = PREFIX_BYTES, name = url } = {}) {
  let whole = null;
  let prefix = null;
  let size = 0;
  const rangeOf = (response) => {
    const m = /^bytes (\d+)-(\d+)\/(\d+)$/.exec(response.headers.get('Content-Range') ?? '');
    if (!m) throw new Error(`${name}: a 206 answer without a valid Content-Range`);
    return { start: Number(m[1]), end: Number(m[2]), total: Number(m[3]) };
  };
  const first = await fetchOrThrow(fetchFn, url, name, { headers: { Range: `bytes=0-${prefixBytes - 1}` } });
  if (first.status === 206) {
    const r = rangeOf(first);
    prefix = await responseBytes(first, name);
    if (r.start !== 0 || prefix.length !== r.end + 1) throw new Error(`${name}: the server sent another range than asked for`);
    size = r.total;
  } else {
    whole = await responseBytes(first, name);
    size = whole.length;
  }
  const read = async (offset, length) => {
    if (whole) return whole.subarray(offset, offset + length);
    if (offset + length <= prefix.length) return prefix.subarray(offset, offset + length);
    if (length === 0) return new Uint8Array(0);
    const response = await fetchOrThrow(fetchFn, url, name, {
      headers: { Range: `bytes=${offset}-${offset + length - 1}` },
    });
    if (response.status !== 206) {
      // The server stopped honouring ranges: keep the whole file.
      whole = await responseBytes(response, name);
      return whole.subarray(offset, offset + length);
    }
    const r = rangeOf(response);
    const bytes = await responseBytes(response, name);
    if (r.start !== offset || bytes.length !== length) {
      throw new Error(`${name}: asked for bytes ${offset}-${offset + length - 1}, got ${r.start}-${r.start + bytes.length - 1}`);
    }
    return bytes;
  };
  return { size, read, get rangesHonoured() { return whole === null; } };
}

/**
 * A single-file container read through `ranges` ({size, read(offset,
 * length)}): reads the header and directory (format.singleFileDirectory checks
 * them), then the manifest. read(path) reads one entry.
 */
export async function openSingleFile(format, ranges, name = 'single file') {
  let have = await ranges.read(0, Math.min(ranges.size, PREFIX_BYTES));
  let directory = format.singleFileDirectory(have, ranges.size);
  while (directory.needed) {
    const more = await ranges.read(have.length, directory.needed - have.length);
    const joined = new Uint8Array(have.length + more.length);
    joined.set(have);
    joined.set(more, have.length);
    have = joined;
    directory = format.singleFileDirectory(have, ranges.size);
  }
  const entries = new Map(directory.entries.map((e) => [e.path, e]));
  const read = async (path) => {
    const e = entries.get(path);
    if (!e) throw new Error(`${name}: no entry "${path}"`);
    return ranges.read(e.offset, e.size);
  };
  return { kind: 'single-file', entries: directory.entries, manifestBytes: await read('manifest.json'), read };
}

/**
 * Opens a package by URL: a .c3d (by its extension or, behind another URL, by
 * its first bytes) through HTTP ranges, else a folder's manifest.json.
 */
export async function openUrl(format, url, { fetch: fetchFn = fetch } = {}) {
  if (!hasSingleFileExtension(new URL(url).pathname)) return openFolderUrl(format, url, { fetch: fetchFn });
  const name = decodeURIComponent(new URL(url).pathname.split('/').pop() || 'single file');
  return openSingleFile(format, await httpRanges(url, { fetch: fetchFn, name }), name);
}

/**
 * The source of a .c3d held in memory (ArrayBuffer or typed array) or in a
 * Blob; null for any other input.
 */
export async function openInMemory(format, input) {
  if (input instanceof ArrayBuffer || ArrayBuffer.isView(input)) {
    const bytes = input instanceof ArrayBuffer ? new Uint8Array(input)
      : new Uint8Array(input.buffer, input.byteOffset, input.byteLength);
    return openSingleFile(format, memoryRanges(bytes));
  }
  if (typeof Blob !== 'undefined' && input instanceof Blob) {
    return openSingleFile(format, blobRanges(input), input.name || 'single file');
  }
  return null;
}
