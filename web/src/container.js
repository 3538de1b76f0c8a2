// The calf container (format/SPEC.md §2 – §10): open reads the 64-byte header and the
// directory and checks them in §9's order, reporting the first failure with the C++ reader's
// id; readChunk reads one chunk's stored bytes, checks its hash and decompresses it.
//
// A source is { size, read(offset, length) → Promise<Uint8Array> }: bytes in memory
// (bytesSource) or an HTTP resource read with range requests (web/src/http_source.js).
import { E, CalfError, fail } from './errors.js';
import { zstdBound, zstdDecode, lzma2Bound, lzma2Decode } from './codecs.js';

export const IDENTIFIER = [0xab, 0x43, 0x41, 0x4c, 0x46, 0x20, 0x31, 0xbb, 0x0d, 0x0a, 0x1a, 0x0a];
const MAX_CHUNKS = 4194304, MAX_TRACKS = 256, MAX_METADATA = 4096;
const MAX_KEY = 256, MAX_META_BYTES = 1048576, MAX_TRACK_HEADER = 65536, MAX_RAW = 2 ** 30;
export const KIND_NAMES = { 1: 'lightfield', 2: 'tiles', 3: 'surfels', 4: 'mesh' };

export function bytesSource(bytes) {
  return { size: bytes.length, read: async (offset, length) => bytes.subarray(offset, offset + length) };
}

const align16 = (x) => Math.ceil(x / 16) * 16;

// Little-endian field reader over a byte range; `short` is thrown when a field runs past it.
class Fields {
  constructor(bytes, onShort) {
    this.b = bytes;
    this.v = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    this.p = 0;
    this.onShort = onShort;
  }
  need(n, what) { if (this.p + n > this.b.length) this.onShort(what); }
  u16(what) { this.need(2, what); const x = this.v.getUint16(this.p, true); this.p += 2; return x; }
  u32(what) { this.need(4, what); const x = this.v.getUint32(this.p, true); this.p += 4; return x; }
  u64(what) { this.need(8, what); const x = this.v.getBigUint64(this.p, true); this.p += 8; return x; }
  bytes(n, what) { this.need(n, what); const x = this.b.subarray(this.p, this.p + n); this.p += n; return x; }
  left() { return this.b.length - this.p; }
}

// The timing fields every track header starts with (SPEC §11), then the lightfield's (§11.1).
// [name, width, min, max]; a field the blob is too short for or below its minimum is E051,
// above its maximum E049.
const TIMING = [['frame_count', 4, 1, 16777216], ['fps_numerator', 4, 1, null], ['fps_denominator', 4, 1, null]];
const TRACK_HEADERS = {
  1: [...TIMING, ['view_count', 4, 1, 65536], ['face_size', 4, 1, 16384], ['cell_size', 4, 1, 16384],
    ['depth_region_size', 4, 1, 16384], ['colour_format', 2, 0, null], ['depth_format', 2, 0, null],
    ['material_format', 2, 0, null], ['flags', 2, 0, null]],
  2: [...TIMING, ['tile_count', 4, 0, null], ['atlas_width', 4, 1, 16384], ['atlas_height', 4, 1, 16384],
    ['atlas_format', 2, 0, null], ['flags', 2, 0, null]],
  3: [...TIMING, ['object_count', 4, 0, null], ['surfel_count', 8, 0, null], ['flags', 2, 0, null]],
  4: [...TIMING, ['vertex_count', 8, 0, null], ['triangle_count', 8, 0, null], ['segment_count', 4, 0, null],
    ['flags', 2, 0, null]],
};

function decodeTrackHeader(kind, blob, t) {
  const f = new Fields(blob, (what) => fail(E.trackHeader, `track ${t}: header too short for ${what}`));
  const h = {};
  for (const [name, width, min, max] of TRACK_HEADERS[kind]) {
    const v = width === 8 ? f.u64(name) : width === 4 ? f.u32(name) : f.u16(name);
    if (v < min) fail(E.trackHeader, `track ${t}: ${name} ${v} below ${min}`);
    if (max !== null && v > max) fail(E.limit, `track ${t}: ${name} ${v} above ${max}`);
    h[name] = v;
  }
  return h;
}

const utf8 = new TextDecoder('utf-8', { fatal: true });

function compareBytes(a, b) {
  const n = Math.min(a.length, b.length);
  for (let i = 0; i < n; ++i) if (a[i] !== b[i]) return a[i] - b[i];
  return a.length - b.length;
}

// Opens a clip: header and directory only (one or two reads). Returns the clip object that
// readChunk takes.
export async function openClip(source, codecs) {
  const S = source.size;
  const head = await source.read(0, Math.min(S, 64));
  for (let i = 0; i < Math.min(S, 12); ++i) {
    if (head[i] !== IDENTIFIER[i]) fail(E.identifier, 'not a calf file (identifier)');
  }
  if (S < 64) fail(E.truncated, `file of ${S} bytes ends inside the header`);
  const hv = new DataView(head.buffer, head.byteOffset, 64);
  if (codecs.xxh3(head.subarray(0, 56)) !== hv.getBigUint64(56, true)) fail(E.headerChecksum, 'header checksum mismatch');
  const major = hv.getUint16(12, true), minor = hv.getUint16(14, true);
  const required = hv.getUint32(16, true);
  if (major !== 1) fail(E.version, `major version ${major}`);
  if (required & ~1) fail(E.requiredFeature, `unknown required feature bits 0x${(required >>> 0).toString(16)}`);
  const fileSize = hv.getBigUint64(24, true), dirOffset = hv.getBigUint64(32, true), dirSize = hv.getBigUint64(40, true);
  const chunkCount = hv.getUint32(48, true), trackCount = hv.getUint32(52, true);
  if (chunkCount > MAX_CHUNKS) fail(E.limit, `${chunkCount} chunks`);
  if (trackCount > MAX_TRACKS) fail(E.limit, `${trackCount} tracks`);
  if (BigInt(S) < fileSize) fail(E.truncated, `file of ${S} bytes, header declares ${fileSize}`);
  if (BigInt(S) > fileSize) fail(E.fileSize, `file of ${S} bytes, header declares ${fileSize}`);
  const compressed = (required & 1) !== 0;
  const bMin = 4 + 8 * trackCount + 64 * chunkCount;
  const bMax = bMin + 8 * MAX_METADATA + MAX_META_BYTES + MAX_TRACK_HEADER * trackCount;
  const dMin = compressed ? 16 : bMin + 8, dMax = compressed ? 16 + zstdBound(bMax) : bMax + 8;
  if (dirOffset < 64n || dirOffset % 16n !== 0n || dirOffset > fileSize || dirSize !== fileSize - dirOffset ||
      dirSize < BigInt(dMin)) {
    fail(E.directoryRange, `directory of ${dirSize} bytes at ${dirOffset}`);
  }
  if (dirSize > BigInt(dMax)) fail(E.limit, `directory of ${dirSize} bytes`);
  const dOff = Number(dirOffset), dSize = Number(dirSize);
  const dir = await source.read(dOff, dSize);
  const dv = new DataView(dir.buffer, dir.byteOffset, dSize);
  if (codecs.xxh3(dir.subarray(0, dSize - 8)) !== dv.getBigUint64(dSize - 8, true)) {
    fail(E.directoryChecksum, 'directory checksum mismatch');
  }
  let body = dir.subarray(0, dSize - 8);
  if (compressed) {
    const bodySize = dv.getBigUint64(0, true);
    if (bodySize < BigInt(bMin)) fail(E.directoryRange, `compressed directory body of ${bodySize} bytes`);
    if (bodySize > BigInt(bMax)) fail(E.limit, `compressed directory body of ${bodySize} bytes`);
    body = zstdDecode(codecs, dir.subarray(8, dSize - 8), Number(bodySize), 'compressed directory');
  }
  const f = new Fields(body, (what) => fail(E.directoryFormat, `directory ends inside ${what}`));
  const metaCount = f.u32('metadata_count');
  if (metaCount > MAX_METADATA) fail(E.limit, `${metaCount} metadata pairs`);
  const metadata = [];
  let metaBytes = 0, prevKey = null;
  for (let i = 0; i < metaCount; ++i) {
    const kn = f.u32(`metadata key ${i}`);
    if (kn < 1) fail(E.directoryFormat, `metadata key ${i} is empty`);
    if (kn > MAX_KEY) fail(E.limit, `metadata key ${i} of ${kn} bytes`);
    const key = f.bytes(kn, `metadata key ${i}`);
    const vn = f.u32(`metadata value ${i}`);
    if (vn > MAX_META_BYTES) fail(E.limit, `metadata value ${i} of ${vn} bytes`);
    const value = f.bytes(vn, `metadata value ${i}`);
    metaBytes += kn + vn;
    if (metaBytes > MAX_META_BYTES) fail(E.limit, 'metadata above 1 MiB');
    let k, v;
    try { k = utf8.decode(key); v = utf8.decode(value); } catch { fail(E.metadata, `metadata pair ${i} is not UTF-8`); }
    if (key.includes(0)) fail(E.metadata, `metadata key ${i} holds NUL`);
    if (prevKey && compareBytes(key, prevKey) <= 0) fail(E.metadata, `metadata key ${i} out of order`);
    prevKey = key;
    metadata.push([k, v]);
  }
  const tracks = [];
  for (let t = 0; t < trackCount; ++t) {
    const kind = f.u16(`track ${t} kind`);
    if (kind < 1) fail(E.directoryFormat, `track ${t} kind 0`);
    const flags = f.u16(`track ${t} flags`);
    const hn = f.u32(`track ${t} header size`);
    if (hn > MAX_TRACK_HEADER) fail(E.limit, `track ${t} header of ${hn} bytes`);
    const blob = f.bytes(hn, `track ${t} header`);
    const known = kind in TRACK_HEADERS;
    const header = known ? decodeTrackHeader(kind, blob, t) : null;
    if (!known && (flags & 1)) fail(E.trackKind, `track ${t}: unknown required kind ${kind}`);
    tracks.push({ kind, flags, header, blob });
  }
  const chunks = [];
  for (let i = 0; i < chunkCount; ++i) {
    const c = {
      id: i, offset: f.u64('chunk offset'), storedSize: f.u64('chunk stored_size'), rawSize: f.u64('chunk raw_size'),
    };
    if (c.rawSize > BigInt(MAX_RAW)) fail(E.limit, `chunk ${i}: raw_size ${c.rawSize} above 1 GiB`);
    c.hash = f.u64('chunk hash');
    c.compression = f.u16('chunk compression'); c.flags = f.u16('chunk flags');
    c.track = f.u16('chunk track'); c.stream = f.u16('chunk stream');
    c.view = f.u32('chunk view'); c.face = f.u32('chunk face'); c.region = f.u32('chunk region');
    c.layer = f.u32('chunk layer'); c.firstFrame = f.u32('chunk first_frame'); c.frameCount = f.u32('chunk frame_count');
    chunks.push(c);
  }
  if (f.left()) fail(E.directoryFormat, `${f.left()} directory bytes left over`);
  // §7: the chunk checks, one chunk at a time.
  let expected = 64n;
  for (const c of chunks) {
    const i = c.id;
    if (c.track >= trackCount) fail(E.chunkTrack, `chunk ${i} names track ${c.track}`);
    if (c.compression > 2) fail(E.compression, `chunk ${i}: compression ${c.compression}`);
    if (c.flags & 0xff) fail(E.requiredFeature, `chunk ${i}: unknown must-understand flags 0x${c.flags.toString(16)}`);
    const raw = Number(c.rawSize);
    if (c.compression === 0 ? c.storedSize !== c.rawSize
      : c.storedSize > BigInt(c.compression === 1 ? zstdBound(raw) : lzma2Bound(raw))) {
      fail(E.chunkSize, `chunk ${i}: stored ${c.storedSize} bytes for ${c.rawSize} raw`);
    }
    if (c.offset < 64n || c.offset > dirOffset || c.storedSize > dirOffset - c.offset) {
      fail(E.chunkRange, `chunk ${i} outside the chunk area`);
    }
    if (c.offset !== expected) fail(E.chunkLayout, `chunk ${i} at ${c.offset}, canonical ${expected}`);
    expected = BigInt(align16(Number(c.offset + c.storedSize)));
    c.offset = Number(c.offset); c.storedSize = Number(c.storedSize); c.rawSize = raw;
  }
  if (expected !== dirOffset) fail(E.chunkLayout, `chunk area ends at ${expected}, directory at ${dirOffset}`);
  return { source, codecs, version: [major, minor], metadata, tracks, chunks, fileSize: Number(fileSize),
    directoryOffset: dOff };
}

// Chunk i's raw bytes: from clip.chunkCache when a streaming reader put them there (stream.js),
// else one read of its stored bytes, the hash (E058), then §6.3 (E059, E049).
export async function readChunk(clip, i) {
  if (!(i >= 0 && i < clip.chunks.length)) fail(E.chunkId, `chunk ${i} outside the index`);
  const cached = clip.chunkCache?.get(i);
  if (cached) return cached;
  const c = clip.chunks[i];
  const stored = await clip.source.read(c.offset, c.storedSize);
  if (stored.length !== c.storedSize) fail(E.truncated, `chunk ${i}: file ends inside it`);
  return decodeStored(clip, c, stored);
}

// The raw bytes of chunk c from its stored bytes (already read, e.g. by a streaming fetch).
export async function decodeStored(clip, c, stored) {
  const what = `chunk ${c.id}`;
  if (clip.codecs.xxh3(stored) !== c.hash) fail(E.chunkHash, `${what}: stored bytes do not match its hash`);
  if (c.compression === 0) return stored;
  if (c.compression === 1) return zstdDecode(clip.codecs, stored, c.rawSize, what);
  return lzma2Decode(clip.codecs, stored, c.rawSize, what);
}

// Full verification at the container level (SPEC §10): every chunk read, hashed and
// decompressed, then its padding; returns every problem, in order, as CalfErrors.
export async function verifyContainer(clip) {
  const problems = [];
  for (const c of clip.chunks) {
    try {
      await readChunk(clip, c.id);
    } catch (e) {
      if (!(e instanceof CalfError)) throw e;
      problems.push(e);
    }
    const end = c.offset + c.storedSize, pad = align16(end) - end;
    const bytes = await clip.source.read(end, pad);
    for (let k = 0; k < pad; ++k) {
      if (bytes[k] !== 0) problems.push(new CalfError(E.padding, `padding byte at ${end + k} is not zero`));
    }
  }
  return problems;
}
