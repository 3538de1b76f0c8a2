// The supercompression and hashing the container needs (format/SPEC.md §1, §6.3), over the
// pinned npm packages: hash-wasm (XXH3-64, XXH64), fzstd (zstd) and xz-decompress (LZMA2, fed
// as a one-block .xz stream built around the chunk's raw LZMA2 stream). The caller passes the
// packages' modules in, so that node (web/test) and the page (an import map) load them their way.
import { E, fail } from './errors.js';
import { webCodecsAv1, wasmAv1 } from './av1.js';

// `av1` (AV1 colour, SPEC §11.1.12; av1.js) is the browser's WebCodecs decoder where it takes AV1
// (unless `av1Wasm` comes with `preferWasm`), else the WebAssembly one over the libav.js instance
// that `av1Wasm()` resolves to, else null (the track is refused with CALF-E203). A stream of a
// profile that WebCodecs does not take (isConfigSupported: the High profile of 4:4:4 colour, as
// a rule) goes to the WebAssembly one where there is one, else its track is refused (CALF-E203).
export async function makeCodecs({ hashWasm, fzstd, xz, av1Wasm = null, preferWasm = false }) {
  const wasm = av1Wasm ? wasmAv1(av1Wasm) : null;
  const h3 = await hashWasm.createXXHash3();
  const h64 = await hashWasm.createXXHash64();
  const digest = (h, bytes) => {
    h.init();
    h.update(bytes);
    return BigInt('0x' + h.digest('hex'));
  };
  return {
    xxh3: (bytes) => digest(h3, bytes),
    xxh64: (bytes) => digest(h64, bytes),
    zstd: (bytes, rawSize) => fzstd.decompress(bytes, new Uint8Array(rawSize)),
    lzma2: (xzBytes) => new Response(new xz.XzReadableStream(new Blob([xzBytes]).stream())).arrayBuffer(),
    av1: (preferWasm && wasm ? null : await webCodecsAv1(globalThis, wasm)) ?? wasm,
  };
}

// ---- zstd (SPEC §6.3): the frame header and block walk are checked here, the blocks decoded
// by fzstd.

const ZSTD_WINDOW_MAX = 2 ** 27;

export function zstdBound(n) {
  return n + Math.floor(n / 256) + (n < 131072 ? Math.floor((131072 - n) / 2048) : 0);
}

// Decodes `stored` (one zstd frame) to exactly rawSize bytes, or throws E059 / E049 in §6.3's
// order.
export function zstdDecode(codecs, stored, rawSize, what) {
  const bad = (why) => fail(E.decompress, `${what}: ${why}`);
  const n = stored.length;
  if (n < 6 || stored[0] !== 0x28 || stored[1] !== 0xb5 || stored[2] !== 0x2f || stored[3] !== 0xfd) {
    bad('not a zstd frame');
  }
  const fhd = stored[4];
  const fcsFlag = fhd >> 6, single = (fhd >> 5) & 1, checksum = (fhd >> 2) & 1, didFlag = fhd & 3;
  if (fhd & 0x08) bad('reserved bit set in the frame header');
  const didSize = [0, 1, 2, 4][didFlag];
  const fcsSize = fcsFlag === 0 ? (single ? 1 : 0) : [0, 2, 4, 8][fcsFlag];
  let p = 5;
  const headerSize = p + (single ? 0 : 1) + didSize + fcsSize;
  if (n < headerSize) bad('frame header truncated');
  let window = null;
  if (!single) {
    const wd = stored[p++];
    const e = wd >> 3, m = wd & 7;
    const base = 2 ** (10 + e);
    window = base + (base / 8) * m;
  }
  let dictId = 0;
  for (let k = 0; k < didSize; ++k) dictId += stored[p + k] * 2 ** (8 * k);
  p += didSize;
  let fcs = null;
  if (fcsSize) {
    fcs = 0;
    for (let k = 0; k < fcsSize; ++k) fcs += stored[p + k] * 2 ** (8 * k);
    if (fcsSize === 2) fcs += 256;
  }
  p += fcsSize;
  if (single) window = fcs;
  if (window > ZSTD_WINDOW_MAX) fail(E.limit, `${what}: zstd window of ${window} bytes above 128 MiB`);
  // Walk the blocks to find the frame's end.
  for (;;) {
    if (p + 3 > n) bad('frame truncated');
    const bh = stored[p] | (stored[p + 1] << 8) | (stored[p + 2] << 16);
    p += 3;
    const last = bh & 1, type = (bh >> 1) & 3, size = bh >>> 3;
    if (type === 3) bad('reserved block type');
    p += type === 1 ? 1 : size;
    if (p > n) bad('frame truncated');
    if (last) break;
  }
  if (checksum) p += 4;
  if (p !== n) bad(p > n ? 'frame truncated' : 'bytes after the frame');
  if (fcs === null || fcs !== rawSize) bad(`frame content size ${fcs} is not the raw size ${rawSize}`);
  if (dictId !== 0) bad('frame needs a dictionary');
  let raw;
  try {
    raw = codecs.zstd(stored, rawSize);
  } catch (e) {
    bad(`zstd: ${e.message}`);
  }
  if (raw.length !== rawSize) bad(`decoded ${raw.length} bytes, expected ${rawSize}`);
  if (checksum) {
    const want = (stored[n - 4] | (stored[n - 3] << 8) | (stored[n - 2] << 16) | (stored[n - 1] << 24)) >>> 0;
    const got = Number(codecs.xxh64(raw) & 0xffffffffn);
    if (want !== got) bad('content checksum mismatch');
  }
  return raw;
}

// ---- LZMA2 (SPEC §6.3)

export function lzma2Bound(n) {
  const x = n + 3 * Math.ceil(n / 65536) + 1;
  return 1 + 92 + 4 * Math.ceil(x / 4);
}

const CRC_TABLE = (() => {
  const t = new Uint32Array(256);
  for (let i = 0; i < 256; ++i) {
    let c = i;
    for (let k = 0; k < 8; ++k) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
    t[i] = c >>> 0;
  }
  return t;
})();

function crc32(bytes) {
  let c = 0xffffffff;
  for (const b of bytes) c = CRC_TABLE[(c ^ b) & 0xff] ^ (c >>> 8);
  return (c ^ 0xffffffff) >>> 0;
}

const le32 = (v) => [v & 0xff, (v >>> 8) & 0xff, (v >>> 16) & 0xff, (v >>> 24) & 0xff];

function varint(v) {
  const out = [];
  while (v >= 0x80) { out.push((v % 128) | 0x80); v = Math.floor(v / 128); }
  out.push(v);
  return out;
}

// One .xz stream (no integrity check) of one block whose filter is LZMA2 with property byte p
// and whose compressed data is `data`.
function xzWrap(p, data, rawSize) {
  const flags = [0x00, 0x00];
  const streamHeader = [0xfd, 0x37, 0x7a, 0x58, 0x5a, 0x00, ...flags, ...le32(crc32(flags))];
  const bh = [0x02, 0x00, 0x21, 0x01, p, 0x00, 0x00, 0x00];
  const blockHeader = [...bh, ...le32(crc32(bh))];
  const blockPad = (4 - (data.length % 4)) % 4;
  const unpadded = blockHeader.length + data.length;
  const index = [0x00, ...varint(1), ...varint(unpadded), ...varint(rawSize)];
  while (index.length % 4) index.push(0);
  const indexFull = [...index, ...le32(crc32(index))];
  const backward = indexFull.length / 4 - 1;
  const fb = [...le32(backward), ...flags];
  const footer = [...le32(crc32(fb)), ...fb, 0x59, 0x5a];
  const head = Uint8Array.from([...streamHeader, ...blockHeader]);
  const tail = Uint8Array.from([...new Array(blockPad).fill(0), ...indexFull, ...footer]);
  const out = new Uint8Array(head.length + data.length + tail.length);
  out.set(head, 0);
  out.set(data, head.length);
  out.set(tail, head.length + data.length);
  return out;
}

export async function lzma2Decode(codecs, stored, rawSize, what) {
  const bad = (why) => fail(E.decompress, `${what}: ${why}`);
  if (stored.length === 0) bad('LZMA2 chunk without a byte');
  const p = stored[0];
  if (p > 40) bad(`LZMA2 property byte ${p}`);
  if (p >= 29) fail(E.limit, `${what}: LZMA2 dictionary above 64 MiB`);
  let raw;
  try {
    raw = new Uint8Array(await codecs.lzma2(xzWrap(p, stored.subarray(1), rawSize)));
  } catch (e) {
    bad(`LZMA2: ${e.message ?? e}`);
  }
  if (raw.length !== rawSize) bad(`decoded ${raw.length} bytes, expected ${rawSize}`);
  return raw;
}
