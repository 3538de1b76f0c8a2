// AV1 colour (format/SPEC.md §11.1.12) through one interface, `picture()`, with two back ends:
// the browser's own WebCodecs `VideoDecoder` where it decodes AV1, else libav.js's av1-opus
// variant (libaom's decoder in WebAssembly: node, or a browser without AV1 in WebCodecs, or
// whose WebCodecs does not take the stream's profile: 4:4:4 is AV1's High profile). One
// decoder per colour cell, as the native decoder keeps (decoder/src/lightfield_decoder.cc,
// update_cell_av1): within the GOP chunk serving a frame, decoding goes on from the frame the
// cell's decoder last gave when that lies before it (playback: one unit per frame), else it
// restarts at the chunk's key frame (a seek: at most the keyframe interval of units). Pictures
// come back as their planes (8-bit samples for av1 and av1-444, 16-bit for the 10-bit ones of
// av1hdr and av1hdr-444; 4:2:0 or 4:4:4 as the stream codes them); lightfield.js converts them
// with SPEC's integer formulas. Errors are the native decoder's: a unit the decoder refuses, or one that
// gives no picture or more than one, CALF-E301; the picture's checks (CALF-E302) are
// lightfield.js's.
import { E, fail } from './errors.js';

// The codec strings by bits and chroma: the AV1 Main profile (0) for 4:2:0 (av1, av1hdr), the
// High profile (1) for 4:4:4 (av1-444, av1hdr-444); 8 or 10 bits. The level (04: 3.0) and tier
// are advisory to a software decoder.
const CODEC = { '8/420': 'av01.0.04M.08', '10/420': 'av01.0.04M.10', '8/444': 'av01.1.04M.08', '10/444': 'av01.1.04M.10' };
const config = (bits, chroma444) => `${bits}/${chroma444 ? 444 : 420}`;
// Open decoders kept at most: above it the least recently used one is closed (its cell restarts
// from its chunk's key frame when it is next needed).
const MAX_DECODERS = 96;
// A unit's picture normally arrives at once (optimizeForLatency); when it has not after this
// long, the decoder is flushed, which gives every pending picture (and means the next frame
// restarts from the key frame). Only speed depends on it, never a result.
const WAIT_MS = 1000;

// Whether `api`'s VideoDecoder takes the codec string of `key` (CODEC's keys).
async function takes(api, key) {
  try {
    return (await api.VideoDecoder.isConfigSupported({ codec: CODEC[key], optimizeForLatency: true })).supported === true;
  } catch {
    return false;
  }
}

// The AV1 decoders of `codecs.av1` over `api` ({ VideoDecoder, EncodedVideoChunk }: this
// JavaScript's own WebCodecs by default) when its VideoDecoder takes AV1 (the Main profile,
// 8 bits), else null. A stream of a profile it does not take (4:4:4, the High profile, where
// isConfigSupported says no) goes to `fallback` (wasmAv1's decoders) when given.
export async function webCodecsAv1(api = globalThis, fallback = null) {
  if (typeof api.VideoDecoder !== 'function' || typeof api.EncodedVideoChunk !== 'function') return null;
  if (!(await takes(api, '8/420'))) return null;
  return makeAv1Decoders(api, fallback);
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
    backEnd: async () => 'WebAssembly',
    picture: async (...args) => (loaded = await get()).picture(...args),
    release: (prefix) => loaded?.release(prefix),
    open: () => loaded?.open() ?? 0,
    close: () => loaded?.close(),
  };
}

// libav's pixel formats (AVPixelFormat of the libav.js build: YUV420P, YUV444P, YUV420P10LE,
// YUV444P10LE) of the pictures SPEC allows, by WebCodecs' names.
const LIBAV_FORMATS = { 0: 'I420', 5: 'I444', 62: 'I420P10', 68: 'I444P10' };
// Bytes a sample and whether chroma is halved both ways, by picture format.
const SAMPLE_BYTES = { I420: 1, I420P10: 2, I444: 1, I444P10: 2 };
const HALVED = { I420: true, I420P10: true, I444: false, I444P10: false };

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
  return { picture, backEnd: async () => 'WebAssembly', ...housekeeping(cells, drop) };
}

// A libav.js frame (one byte array, its planes at layout's offsets and strides) as av1.js's
// picture: 8-bit samples for YUV420P and YUV444P, 16-bit for YUV420P10LE and YUV444P10LE;
// another format has no planes.
function libavPicture(f) {
  const format = LIBAV_FORMATS[f.format] ?? `libav pixel format ${f.format}`;
  const crop = f.crop ?? { left: 0, right: 0, top: 0, bottom: 0 };
  const width = f.width - crop.left - crop.right, height = f.height - crop.top - crop.bottom;
  const out = { format, width, height, planes: null, strides: null };
  const bytes = SAMPLE_BYTES[format];
  if (!bytes || crop.left || crop.top) return out;
  out.planes = f.layout.slice(0, 3).map((l, k) => {
    const n = l.stride * (k && HALVED[format] ? Math.ceil(f.height / 2) : f.height);
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

// { picture(key, chunk, units, i, what, bits, chroma444) }: the picture of unit i of GOP chunk
// `chunk` ({ id, firstFrame }) whose temporal units are `units`, for the cell named `key`, from a
// stream of `bits` (8 or 10) per sample, 4:4:4 (the High profile) when `chroma444`, else 4:2:0;
// resolves to { format, width, height, planes: [y, u, v], strides: [y, u, v] } (copies, in
// samples; the VideoFrame is closed) or throws CALF-E301. `backEnd(bits, chroma444)` resolves to
// 'WebCodecs' where VideoDecoder.isConfigSupported takes the profile's codec string, else to
// `fallback`'s ('WebAssembly'), which then decodes those streams, else to null. `release`,
// `close` and `open` below (housekeeping), over both.
export function makeAv1Decoders(api = globalThis, fallback = null) {
  const supported = new Map();  // CODEC key -> Promise<boolean>
  const own = (key) => {
    if (!supported.has(key)) supported.set(key, takes(api, key));
    return supported.get(key);
  };
  async function backEnd(bits, chroma444) {
    if (await own(config(bits, chroma444))) return 'WebCodecs';
    return fallback ? fallback.backEnd(bits, chroma444) : null;
  }
  const cells = new Map();  // key -> state, in least recently used order
  const drop = (key) => {
    const s = cells.get(key);
    if (!s) return;
    cells.delete(key);
    if (s.decoder.state !== 'closed') s.decoder.close();
    for (const w of s.waiters.values()) w.reject(null);
  };
  function open(key, chunkId, codec) {
    drop(key);
    while (cells.size >= MAX_DECODERS) drop(cells.keys().next().value);
    const s = { chunkId, codec, next: 0, pictures: new Map(), counts: new Map(), waiters: new Map(), error: null, flushed: false, decoder: null };
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
    s.decoder.configure({ codec: CODEC[codec], optimizeForLatency: true });
    cells.set(key, s);
    return s;
  }
  async function picture(key, chunk, units, i, what, bits = 8, chroma444 = false) {
    const codec = config(bits, chroma444);
    if (!(await own(codec))) {
      if (!fallback) fail(E.lightfieldFormat, `${what}: no AV1 decoder here for ${PROFILE[codec]}: VideoDecoder does not take ${CODEC[codec]}`);
      return fallback.picture(key, chunk, units, i, what, bits, chroma444);
    }
    let s = cells.get(key);
    if (s) { cells.delete(key); cells.set(key, s); }  // most recently used
    if (!s || s.chunkId !== chunk.id || s.codec !== codec || s.next > i || s.flushed || s.error) s = open(key, chunk.id, codec);
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
  return { picture, backEnd, ...housekeeping(cells, drop, fallback) };
}

// The profiles by CODEC key, as lines name them.
export const PROFILE = { '8/420': 'the Main profile, 8-bit 4:2:0', '10/420': 'the Main profile, 10-bit 4:2:0',
  '8/444': 'the High profile, 8-bit 4:4:4', '10/444': 'the High profile, 10-bit 4:4:4' };

// The decoders' housekeeping: `release(prefix)` closes the decoders of the cells whose keys
// start with it (a track that is closed: lightfield.js's closeLightfield), `close()` every one,
// `open()` counts those open; each also over `fallback`'s.
function housekeeping(cells, drop, fallback = null) {
  return {
    release: (prefix) => { for (const k of [...cells.keys()]) if (k.startsWith(prefix)) drop(k); fallback?.release(prefix); },
    close: () => { for (const k of [...cells.keys()]) drop(k); fallback?.close(); },
    open: () => cells.size + (fallback?.open() ?? 0),
  };
}

// A VideoFrame's visible picture as its planes, then the frame closed (I420, I444: Y, U, V of
// 8-bit samples; I420P10, I444P10: of 16-bit little-endian samples, as Uint16Arrays; another
// format resolves with no planes, for lightfield.js to refuse).
async function copyFrame(frame) {
  const { width, height } = frame.visibleRect;
  const out = { format: frame.format, width, height, planes: null, strides: null };
  try {
    const bytes = SAMPLE_BYTES[frame.format];
    if (!bytes) return out;
    const buffer = new Uint8Array(frame.allocationSize());
    const layout = await frame.copyTo(buffer);
    const rows = (k) => (k && HALVED[frame.format] ? Math.ceil(height / 2) : height);
    out.planes = layout.map((l, k) => samples(buffer.slice(l.offset, l.offset + l.stride * rows(k)), bytes));
    out.strides = layout.map((l) => l.stride / bytes);
    return out;
  } finally {
    frame.close();
  }
}
