// AV1 colour (format/SPEC.md §11.1.12) through one interface, `picture()`, with two back ends:
// the browser's own WebCodecs `VideoDecoder` where it decodes AV1, else libav.js's av1-opus
// variant (libaom's decoder in WebAssembly: node, or a browser without AV1 in WebCodecs). One
// decoder per colour cell, as the native decoder keeps (decoder/src/lightfield_decoder.cc,
// update_cell_av1): within the GOP chunk serving a frame, decoding goes on from the frame the
// cell's decoder last gave when that lies before it (playback: one unit per frame), else it
// restarts at the chunk's key frame (a seek: at most the keyframe interval of units). Pictures
// come back as their planes (8-bit samples for av1, 16-bit for av1hdr's 10-bit ones);
// lightfield.js converts them with SPEC's integer formulas. Errors are the native decoder's: a unit the decoder refuses, or one that
// gives no picture or more than one, CALF-E301; the picture's checks (CALF-E302) are
// lightfield.js's.
import { E, fail } from './errors.js';

// The codec strings of AV1 Main profile, 8 bits (av1) and 10 bits (av1hdr), 4:2:0; the level is
// advisory to a software decoder.
const CODEC = { 8: 'av01.0.04M.08', 10: 'av01.0.04M.10' };
// Open decoders kept at most: above it the least recently used one is closed (its cell restarts
// from its chunk's key frame when it is next needed).
const MAX_DECODERS = 96;
// A unit's picture normally arrives at once (optimizeForLatency); when it has not after this
// long, the decoder is flushed, which gives every pending picture (and means the next frame
// restarts from the key frame). Only speed depends on it, never a result.
const WAIT_MS = 1000;

// The AV1 decoders of `codecs.av1` over `api` ({ VideoDecoder, EncodedVideoChunk }: this
// JavaScript's own WebCodecs by default) when its VideoDecoder takes AV1, else null.
export async function webCodecsAv1(api = globalThis) {
  const VD = api.VideoDecoder;
  if (typeof VD !== 'function' || typeof api.EncodedVideoChunk !== 'function') return null;
  try {
    const s = await VD.isConfigSupported({ codec: CODEC[8], optimizeForLatency: true });
    if (!s.supported) return null;
  } catch {
    return null;
  }
  return makeAv1Decoders(api);
}

// The AV1 decoders of `codecs.av1` where WebCodecs has none: libav.js's av1-opus variant (libaom's
// decoder in WebAssembly). `load()` resolves to a libav.js instance; it is called at the first
// picture (so that a page downloads the WebAssembly decoder only when it plays AV1); a load that
// fails is CALF-E203, as for a reader without the format.
export function wasmAv1(load) {
  let decoders = null;
  const get = () => (decoders ??= load().then((libav) => makeLibavDecoders(libav), (e) => {
    decoders = null;
    fail(E.lightfieldFormat, `no AV1 decoder here: the WebAssembly decoder does not load (${e?.message ?? e})`);
  }));
  let loaded = null;
  return {
    picture: async (...args) => (loaded = await get()).picture(...args),
    release: (prefix) => loaded?.release(prefix),
    open: () => loaded?.open() ?? 0,
    close: () => loaded?.close(),
  };
}

// libav's pixel formats of the pictures SPEC allows: 8-bit and 10-bit (little-endian) 4:2:0.
const LIBAV_FORMATS = { 0: 'I420', 62: 'I420P10' };

// makeAv1Decoders' interface over a libav.js instance: one libaom decoder context per cell, fed
// the units in order (each gives its picture at once); the same restarts and errors.
export function makeLibavDecoders(libav) {
  const cells = new Map();  // key -> state, in least recently used order
  let queue = Promise.resolve();  // libav's calls, one at a time
  const drop = (key) => {
    const s = cells.get(key);
    if (!s) return;
    cells.delete(key);
    queue = queue.then(() => libav.ff_free_decoder(s.c, s.pkt, s.frame)).catch(() => {});
  };
  async function open(key, chunkId) {
    drop(key);
    while (cells.size >= MAX_DECODERS) drop(cells.keys().next().value);
    const [, c, pkt, frame] = await libav.ff_init_decoder('libaom-av1');
    const s = { chunkId, next: 0, c, pkt, frame, last: null };
    cells.set(key, s);
    return s;
  }
  async function run(key, chunk, units, i, what) {
    let s = cells.get(key);
    if (s) { cells.delete(key); cells.set(key, s); }  // most recently used
    if (!s) s = await open(key, chunk.id);
    else if (s.chunkId !== chunk.id || s.next > i + 1 || (s.next === i + 1 && !s.last)) {
      // A restart at a key frame (unit 0: a sequence header and a key frame, which refreshes
      // every reference) reuses the cell's context: libaom's set-up costs more than the unit.
      await libav.avcodec_flush_buffers(s.c);
      Object.assign(s, { chunkId: chunk.id, next: 0, last: null });
    }
    if (s.next === i + 1) return s.last;
    for (; s.next <= i; ++s.next) {
      const frame = chunk.firstFrame + s.next;
      const bad = (why) => { drop(key); fail(E.av1Decode, `${what} frame ${frame}: ${why}`); };
      let out;
      try {
        out = await libav.ff_decode_multi(s.c, s.pkt, s.frame, [{ data: units[s.next], pts: frame, ptshi: 0 }]);
      } catch (e) {
        bad(`the temporal unit does not decode (${e?.message ?? e})`);
      }
      if (out.length === 0) bad('the temporal unit gives no picture');
      if (out.length > 1) bad('the temporal unit gives more than one picture');
      s.last = s.next === i ? libavPicture(out[0]) : null;
    }
    return s.last;
  }
  function picture(key, chunk, units, i, what) {
    const p = queue.then(() => run(key, chunk, units, i, what));
    queue = p.catch(() => {});
    return p;
  }
  return { picture, ...housekeeping(cells, drop) };
}

// A libav.js frame (one byte array, its planes at layout's offsets and strides) as av1.js's
// picture: 8-bit samples for YUV420P, 16-bit for YUV420P10LE; another format has no planes.
function libavPicture(f) {
  const format = LIBAV_FORMATS[f.format] ?? `libav pixel format ${f.format}`;
  const crop = f.crop ?? { left: 0, right: 0, top: 0, bottom: 0 };
  const width = f.width - crop.left - crop.right, height = f.height - crop.top - crop.bottom;
  const out = { format, width, height, planes: null, strides: null };
  const bytes = { I420: 1, I420P10: 2 }[format];
  if (!bytes || crop.left || crop.top) return out;
  out.planes = f.layout.slice(0, 3).map((l, k) => {
    const n = l.stride * (k ? Math.ceil(f.height / 2) : f.height);
    return samples(f.data.slice(l.offset, l.offset + n), bytes);
  });
  out.strides = f.layout.slice(0, 3).map((l) => l.stride / bytes);
  return out;
}

// Bytes (a copy of their own) as samples of `bytes` bytes each, little-endian.
function samples(b, bytes) {
  if (bytes === 1) return b;
  if (new Uint8Array(Uint16Array.of(1).buffer)[0] === 1) return new Uint16Array(b.buffer, b.byteOffset, b.length >> 1);
  return Uint16Array.from({ length: b.length >> 1 }, (_, j) => b[2 * j] | (b[2 * j + 1] << 8));
}

// { picture(key, chunk, units, i, what, bits) }: the picture of unit i of GOP chunk `chunk`
// ({ id, firstFrame }) whose temporal units are `units`, for the cell named `key`, from a stream
// of `bits` (8 or 10) per sample; resolves to { format, width, height, planes: [y, u, v],
// strides: [y, u, v] } (copies, in samples; the VideoFrame is closed) or throws CALF-E301.
// `release`, `close` and `open` below (housekeeping).
export function makeAv1Decoders(api = globalThis) {
  const cells = new Map();  // key -> state, in least recently used order
  const drop = (key) => {
    const s = cells.get(key);
    if (!s) return;
    cells.delete(key);
    if (s.decoder.state !== 'closed') s.decoder.close();
    for (const w of s.waiters.values()) w.reject(null);
  };
  function open(key, chunkId, bits) {
    drop(key);
    while (cells.size >= MAX_DECODERS) drop(cells.keys().next().value);
    const s = { chunkId, bits, next: 0, pictures: new Map(), counts: new Map(), waiters: new Map(), error: null, flushed: false, decoder: null };
    s.decoder = new api.VideoDecoder({
      output: (frame) => {
        const ts = frame.timestamp;
        s.counts.set(ts, (s.counts.get(ts) ?? 0) + 1);
        if (s.counts.get(ts) > 1) {
          s.error ??= 'the temporal unit gives more than one picture';
          frame.close();
        } else {
          s.pictures.set(ts, copyFrame(frame).catch(() => null));
        }
        const w = s.waiters.get(ts);
        if (w) w.resolve();
      },
      error: (e) => {
        s.error ??= `the temporal unit does not decode (${e.name}: ${e.message})`;
        for (const w of s.waiters.values()) w.resolve();
      },
    });
    s.decoder.configure({ codec: CODEC[bits], optimizeForLatency: true });
    cells.set(key, s);
    return s;
  }
  async function picture(key, chunk, units, i, what, bits = 8) {
    let s = cells.get(key);
    if (s) { cells.delete(key); cells.set(key, s); }  // most recently used
    if (!s || s.chunkId !== chunk.id || s.bits !== bits || s.next > i || s.flushed || s.error) s = open(key, chunk.id, bits);
    const ts = chunk.firstFrame + i;
    const bad = (why) => { drop(key); fail(E.av1Decode, `${what} frame ${ts}: ${why}`); };
    for (; s.next <= i; ++s.next) {
      try {
        s.decoder.decode(new api.EncodedVideoChunk({ type: s.next === 0 ? 'key' : 'delta', timestamp: chunk.firstFrame + s.next, data: units[s.next] }));
      } catch (e) {
        bad(`the temporal unit does not decode (${e.name}: ${e.message})`);
      }
    }
    if (!s.pictures.has(ts) && !s.error) {
      let timer = null;
      const arrived = new Promise((resolve, reject) => { s.waiters.set(ts, { resolve, reject }); });
      const late = new Promise((resolve) => { timer = setTimeout(() => resolve('late'), WAIT_MS); });
      const why = await Promise.race([arrived, late]).catch(() => 'closed');
      clearTimeout(timer);
      s.waiters.delete(ts);
      if (why === 'closed') bad('the decoder was closed');
      if (why === 'late' && !s.pictures.has(ts) && !s.error) {
        s.flushed = true;
        try { await s.decoder.flush(); } catch (e) { s.error ??= `the temporal unit does not decode (${e.name}: ${e.message})`; }
      }
    }
    if (s.error) bad(s.error);
    if (!s.pictures.has(ts)) bad('the temporal unit gives no picture');
    const p = await s.pictures.get(ts);
    if (!p) bad('the picture could not be read (VideoFrame.copyTo)');
    // A unit before this one that gave no picture shows as a missing timestamp.
    for (let u = chunk.firstFrame; u < ts; ++u) if (!s.counts.has(u) && s.flushed) bad(`unit ${u - chunk.firstFrame} gives no picture`);
    for (const k of [...s.pictures.keys()]) if (k < ts) s.pictures.delete(k);
    return p;
  }
  return { picture, ...housekeeping(cells, drop) };
}

// The decoders' housekeeping: `release(prefix)` closes the decoders of the cells whose keys
// start with it (a track that is closed: lightfield.js's closeLightfield), `close()` every one,
// `open()` counts those open.
function housekeeping(cells, drop) {
  return {
    release: (prefix) => { for (const k of [...cells.keys()]) if (k.startsWith(prefix)) drop(k); },
    close: () => { for (const k of [...cells.keys()]) drop(k); },
    open: () => cells.size,
  };
}

// A VideoFrame's visible picture as its planes, then the frame closed (I420: Y, U, V of 8-bit
// samples; I420P10: of 16-bit little-endian samples, as Uint16Arrays; another format resolves
// with no planes, for lightfield.js to refuse).
async function copyFrame(frame) {
  const { width, height } = frame.visibleRect;
  const out = { format: frame.format, width, height, planes: null, strides: null };
  try {
    const bytes = { I420: 1, I420P10: 2 }[frame.format];
    if (!bytes) return out;
    const buffer = new Uint8Array(frame.allocationSize());
    const layout = await frame.copyTo(buffer);
    out.planes = layout.map((l, k) => samples(buffer.slice(l.offset, l.offset + l.stride * (k ? Math.ceil(height / 2) : height)), bytes));
    out.strides = layout.map((l) => l.stride / bytes);
    return out;
  } finally {
    frame.close();
  }
}
