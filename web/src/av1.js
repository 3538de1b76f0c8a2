// AV1 colour (format/SPEC.md §11.1.12) through the browser's own AV1 decoder, WebCodecs
// `VideoDecoder`. One decoder per colour cell, as the native decoder keeps (decoder/src/
// lightfield_decoder.cc, update_cell_av1): within the GOP chunk serving a frame, decoding goes on from
// the frame the cell's decoder last gave when that lies before it (playback: one unit per frame),
// else it restarts at the chunk's key frame (a seek: at most the keyframe interval of units).
// Pictures come back as their 8-bit planes (VideoFrame.copyTo); lightfield.js converts them with
// SPEC's integer formula. Errors are the native decoder's: a unit the decoder refuses, or one
// that gives no picture or more than one, CALF-E301; the picture's checks (CALF-E302) are
// lightfield.js's.
import { E, fail } from './errors.js';

// The codec string of AV1 Main profile, 8 bits (SPEC: every AV1 colour stream is 8-bit 4:2:0);
// the level is advisory to a software decoder.
const CODEC = 'av01.0.04M.08';
// Open decoders kept at most: above it the least recently used one is closed (its cell restarts
// from its chunk's key frame when it is next needed).
const MAX_DECODERS = 96;
// A unit's picture normally arrives at once (optimizeForLatency); when it has not after this
// long, the decoder is flushed, which gives every pending picture (and means the next frame
// restarts from the key frame). Only speed depends on it, never a result.
const WAIT_MS = 1000;

// The AV1 decoder of `codecs.av1` where this JavaScript has WebCodecs with AV1 (a browser), else
// null (node).
export async function webCodecsAv1() {
  const VD = globalThis.VideoDecoder;
  if (typeof VD !== 'function' || typeof globalThis.EncodedVideoChunk !== 'function') return null;
  try {
    const s = await VD.isConfigSupported({ codec: CODEC, optimizeForLatency: true });
    if (!s.supported) return null;
  } catch {
    return null;
  }
  return makeAv1Decoders();
}

// { picture(key, chunk, units, i, what) }: the picture of unit i of GOP chunk `chunk` ({ id,
// firstFrame }) whose temporal units are `units`, for the cell named `key`; resolves to
// { format, width, height, planes: [y, u, v], strides: [y, u, v] } (copies; the VideoFrame is
// closed) or throws CALF-E301. `close()` closes every decoder.
export function makeAv1Decoders() {
  const cells = new Map();  // key -> state, in least recently used order
  const drop = (key) => {
    const s = cells.get(key);
    if (!s) return;
    cells.delete(key);
    if (s.decoder.state !== 'closed') s.decoder.close();
    for (const w of s.waiters.values()) w.reject(null);
  };
  function open(key, chunkId) {
    drop(key);
    while (cells.size >= MAX_DECODERS) drop(cells.keys().next().value);
    const s = { chunkId, next: 0, pictures: new Map(), counts: new Map(), waiters: new Map(), error: null, flushed: false, decoder: null };
    s.decoder = new VideoDecoder({
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
    s.decoder.configure({ codec: CODEC, optimizeForLatency: true });
    cells.set(key, s);
    return s;
  }
  async function picture(key, chunk, units, i, what) {
    let s = cells.get(key);
    if (s) { cells.delete(key); cells.set(key, s); }  // most recently used
    if (!s || s.chunkId !== chunk.id || s.next > i || s.flushed || s.error) s = open(key, chunk.id);
    const ts = chunk.firstFrame + i;
    const bad = (why) => { drop(key); fail(E.av1Decode, `${what} frame ${ts}: ${why}`); };
    for (; s.next <= i; ++s.next) {
      try {
        s.decoder.decode(new EncodedVideoChunk({ type: s.next === 0 ? 'key' : 'delta', timestamp: chunk.firstFrame + s.next, data: units[s.next] }));
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
  return { picture, close: () => { for (const k of [...cells.keys()]) drop(k); } };
}

// A VideoFrame's visible picture as its planes, then the frame closed (I420: Y, U, V; another
// format resolves with no planes, for lightfield.js to refuse).
async function copyFrame(frame) {
  const { width, height } = frame.visibleRect;
  const out = { format: frame.format, width, height, planes: null, strides: null };
  try {
    if (frame.format !== 'I420') return out;
    const buffer = new Uint8Array(frame.allocationSize());
    const layout = await frame.copyTo(buffer);
    out.planes = layout.map((l, k) => buffer.subarray(l.offset, l.offset + l.stride * (k ? Math.ceil(height / 2) : height)));
    out.strides = layout.map((l) => l.stride);
    return out;
  } finally {
    frame.close();
  }
}
