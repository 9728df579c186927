// Decoding of the protocol's typed arrays: {"dtype":"float32"|"int32","shape":[rows,cols],"data":BASE64}
// (little-endian, row-major). Decoding writes straight into a caller-provided typed array where
// possible, so the per-iterate path allocates nothing.

const LOOKUP = new Uint8Array(256).fill(255);
{
  const alphabet = 'ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/';
  for (let i = 0; i < alphabet.length; i++) LOOKUP[alphabet.charCodeAt(i)] = i;
  // URL-safe variants decode too.
  LOOKUP['-'.charCodeAt(0)] = 62;
  LOOKUP['_'.charCodeAt(0)] = 63;
}

const LITTLE_ENDIAN = new Uint8Array(new Uint32Array([1]).buffer)[0] === 1;

/** Number of bytes the base64 text decodes to. */
export function base64ByteLength(text) {
  let n = text.length;
  let pad = 0;
  while (n > 0 && text.charCodeAt(n - 1) === 61 /* = */) {
    n--;
    pad++;
  }
  if ((n + pad) % 4 !== 0 && pad > 0) throw new Error('base64: bad padding');
  return Math.floor((n * 3) / 4);
}

/**
 * Decodes base64 text into `bytes` (a Uint8Array at least base64ByteLength(text) long).
 * Returns the number of bytes written.
 */
export function decodeBase64Into(text, bytes) {
  const outLen = base64ByteLength(text);
  if (bytes.length < outLen) throw new Error(`base64: target too small (${bytes.length} < ${outLen})`);
  let o = 0;
  let i = 0;
  const full = outLen - (outLen % 3);
  // Full 4-char groups.
  while (o < full) {
    const a = LOOKUP[text.charCodeAt(i)];
    const b = LOOKUP[text.charCodeAt(i + 1)];
    const c = LOOKUP[text.charCodeAt(i + 2)];
    const d = LOOKUP[text.charCodeAt(i + 3)];
    if ((a | b | c | d) & 0xc0) throw new Error('base64: invalid character');
    const v = (a << 18) | (b << 12) | (c << 6) | d;
    bytes[o++] = v >>> 16;
    bytes[o++] = (v >>> 8) & 255;
    bytes[o++] = v & 255;
    i += 4;
  }
  const rest = outLen - full;
  if (rest > 0) {
    const a = LOOKUP[text.charCodeAt(i)];
    const b = LOOKUP[text.charCodeAt(i + 1)];
    const c = rest === 2 ? LOOKUP[text.charCodeAt(i + 2)] : 0;
    if ((a | b | c) & 0xc0) throw new Error('base64: invalid character');
    const v = (a << 18) | (b << 12) | (c << 6);
    bytes[o++] = v >>> 16;
    if (rest === 2) bytes[o++] = (v >>> 8) & 255;
  }
  return outLen;
}

/** Decodes base64 text into a new Uint8Array. */
export function decodeBase64(text) {
  const bytes = new Uint8Array(base64ByteLength(text));
  decodeBase64Into(text, bytes);
  return bytes;
}

/** Encodes bytes (Uint8Array or any typed array) as base64 (used by tests and tools). */
export function encodeBase64(view) {
  const bytes = view instanceof Uint8Array ? view : new Uint8Array(view.buffer, view.byteOffset, view.byteLength);
  const alphabet = 'ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/';
  let out = '';
  let i = 0;
  for (; i + 2 < bytes.length; i += 3) {
    const v = (bytes[i] << 16) | (bytes[i + 1] << 8) | bytes[i + 2];
    out += alphabet[v >>> 18] + alphabet[(v >>> 12) & 63] + alphabet[(v >>> 6) & 63] + alphabet[v & 63];
  }
  if (i + 1 === bytes.length) {
    const v = bytes[i] << 16;
    out += alphabet[v >>> 18] + alphabet[(v >>> 12) & 63] + '==';
  } else if (i + 2 === bytes.length) {
    const v = (bytes[i] << 16) | (bytes[i + 1] << 8);
    out += alphabet[v >>> 18] + alphabet[(v >>> 12) & 63] + alphabet[(v >>> 6) & 63] + '=';
  }
  return out;
}

/** Number of elements (rows × cols) of an encoded array. */
export function elementCount(spec) {
  return spec.shape.reduce((a, b) => a * b, 1);
}

function arrayTypeFor(dtype) {
  if (dtype === 'float32') return Float32Array;
  if (dtype === 'int32') return Int32Array;
  throw new Error(`unsupported dtype ${dtype}`);
}

function byteSwap32(bytes, length) {
  for (let i = 0; i < length; i += 4) {
    const a = bytes[i];
    const b = bytes[i + 1];
    bytes[i] = bytes[i + 3];
    bytes[i + 1] = bytes[i + 2];
    bytes[i + 2] = b;
    bytes[i + 3] = a;
  }
}

/** Decodes an encoded array into a new typed array: {dtype, shape, data}. */
export function decodeArray(spec) {
  const Type = arrayTypeFor(spec.dtype);
  const data = new Type(elementCount(spec));
  decodeArrayInto(spec, data);
  return { dtype: spec.dtype, shape: spec.shape.slice(), data };
}

/**
 * Decodes an encoded array straight into `target` (a Float32Array or Int32Array of exactly
 * rows × cols elements, matching the dtype). Throws when the sizes or types do not match.
 */
export function decodeArrayInto(spec, target) {
  const Type = arrayTypeFor(spec.dtype);
  if (!(target instanceof Type)) throw new Error(`decodeArrayInto: expected a ${Type.name}`);
  const n = elementCount(spec);
  if (target.length !== n) throw new Error(`decodeArrayInto: size ${target.length} ≠ ${n}`);
  const bytes = new Uint8Array(target.buffer, target.byteOffset, n * 4);
  const written = decodeBase64Into(spec.data, bytes);
  if (written !== n * 4) throw new Error(`array data has ${written} bytes, shape needs ${n * 4}`);
  if (!LITTLE_ENDIAN) byteSwap32(bytes, written);
  return target;
}

/** Encodes a typed array as the protocol's array object (for tests and fixtures). */
export function encodeArray(typed, shape) {
  const dtype = typed instanceof Int32Array ? 'int32' : 'float32';
  return { dtype, shape: shape.slice(), data: encodeBase64(typed) };
}
