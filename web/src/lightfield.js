// The lightfield track (format/SPEC.md §11.1): the view index, t, colour keyframe and region
// (depth, material, coverage) chunks, decoded on the CPU to the values the conformance hash
// covers (§14): linear binary32 RGB, log-16 depth codes, material codes, coverage.
import { E, CalfError, fail } from './errors.js';
import { readChunk } from './container.js';
import { decodeBc1, decodeBc4, decodeBc6h, decodeBc7 } from './bc.js';

export const FORMAT = { none: 0, rgba8: 1, rgba16f: 2, r16: 3, bc1: 4, bc4: 5, bc5: 6, bc6h: 7, bc7: 8, rg8: 9, r16p: 10, r16pm: 11, av1: 12, av1hdr: 13, av1_444: 14, av1hdr_444: 15 };
// The AV1 colour formats (§11.1.12): bits a sample, 4:4:4 or 4:2:0, and the AV1 profile.
const AV1_FORMATS = {
  [FORMAT.av1]: { name: 'av1', bits: 8, chroma444: false, profile: 'the Main profile' },
  [FORMAT.av1hdr]: { name: 'av1hdr', bits: 10, chroma444: false, profile: 'the Main profile' },
  [FORMAT.av1_444]: { name: 'av1-444', bits: 8, chroma444: true, profile: 'the High profile (4:4:4)' },
  [FORMAT.av1hdr_444]: { name: 'av1hdr-444', bits: 10, chroma444: true, profile: 'the High profile (4:4:4)' },
};
export const STREAM = { index: 0, colour: 1, depth: 2, material: 3, t: 4, coverage: 5 };
const COLOUR_FORMATS = [FORMAT.bc1, FORMAT.bc7, FORMAT.bc6h, FORMAT.rgba8, FORMAT.rgba16f];
const DEPTH_FORMATS = [FORMAT.r16, FORMAT.r16p, FORMAT.r16pm, FORMAT.bc5];
const MATERIAL_FORMATS = [FORMAT.rgba8, FORMAT.bc1];

const bad = (what) => fail(E.lightfieldChunk, what);

// §11.1.1: the regions of side c on a face of side n.
export function faceGrid(n, c) {
  const side = Math.min(c, n);
  const per = Math.ceil(n / side);
  return {
    side, per, count: per * per,
    rect(r) {
      const i = r % per, j = Math.floor(r / per);
      return { x: i * side, y: j * side, w: Math.min(side, n - i * side), h: Math.min(side, n - j * side) };
    },
  };
}

// sRGB byte → linear binary32 (§11.1.5: binary64 arithmetic, rounded once).
export const SRGB = Float32Array.from({ length: 256 }, (_, b) => {
  const c = b / 255;
  return c <= 0.04045 ? c / 12.92 : Math.pow((c + 0.055) / 1.055, 2.4);
});

export function halfToFloat(h) {
  const s = h >> 15, e = (h >> 10) & 31, m = h & 1023;
  let v;
  if (e === 0) v = m * 2 ** -24;
  else if (e === 31) v = m ? NaN : Infinity;
  else v = (1 + m / 1024) * 2 ** (e - 15);
  return s ? -v : v;
}

// §11.1.3
export function parseViewIndex(raw, what, materialFormat) {
  if (raw.length !== 52) bad(`${what}: ${raw.length} bytes, expected 52`);
  const v = new DataView(raw.buffer, raw.byteOffset, 52);
  if (v.getUint32(0, true) !== 1) bad(`${what}: layout version ${v.getUint32(0, true)}`);
  const position = [v.getFloat64(4, true), v.getFloat64(12, true), v.getFloat64(20, true)];
  const zNear = v.getFloat32(28, true), zFar = v.getFloat32(32, true);
  const flags = v.getUint32(36, true), K = v.getUint32(40, true), W = v.getUint32(44, true);
  if (!position.every(Number.isFinite)) bad(`${what}: position not finite`);
  if (!Number.isFinite(zNear) || !Number.isFinite(zFar) || !(zNear > 0 && zNear < zFar)) bad(`${what}: z range ${zNear} … ${zFar}`);
  if (flags & ~3) bad(`${what}: reserved flags 0x${flags.toString(16)}`);
  if (K < 1) bad(`${what}: depth keyframe interval 0`);
  if (W < 1) bad(`${what}: depth window 0`);
  const hasMaterial = (flags & 2) !== 0;
  if (hasMaterial && materialFormat === 0) bad(`${what}: material flagged but the track has none`);
  return { position, zNear, zFar, finite: (flags & 1) !== 0, hasMaterial, K, W, Q: v.getFloat32(48, true) };
}

// §11.1.4
export function parseTimeline(raw, frameCount, what) {
  if (raw.length < 4) bad(`${what}: ${raw.length} bytes`);
  const v = new DataView(raw.buffer, raw.byteOffset, raw.length);
  const nk = v.getUint32(0, true);
  if (nk < 1 || nk > frameCount) bad(`${what}: ${nk} keyframes`);
  if (raw.length !== 4 + 4 * nk + frameCount) bad(`${what}: ${raw.length} bytes, expected ${4 + 4 * nk + frameCount}`);
  const keys = [];
  for (let i = 0; i < nk; ++i) {
    const k = v.getUint32(4 + 4 * i, true);
    if ((i === 0 && k !== 0) || (i > 0 && k <= keys[i - 1]) || k >= frameCount) bad(`${what}: keyframe ${i} is ${k}`);
    keys.push(k);
  }
  return { keys, t: raw.subarray(4 + 4 * nk) };
}

// §11.1.5: a w × h colour keyframe → linear binary32 RGB, texel-interleaved.
export function decodeColour(raw, format, w, h, what) {
  const n = w * h, bw = Math.ceil(w / 4), B = bw * Math.ceil(h / 4);
  const out = new Float32Array(3 * n);
  const want = { [FORMAT.bc1]: 8 * B, [FORMAT.bc7]: 16 * B, [FORMAT.bc6h]: 16 * B, [FORMAT.rgba8]: 4 * n, [FORMAT.rgba16f]: 8 * n }[format];
  if (raw.length !== want) bad(`${what}: ${raw.length} bytes, expected ${want}`);
  const put = (k, blockTexels, stride, toFloat) => {
    const bx = 4 * (k % bw), by = 4 * Math.floor(k / bw);
    for (let j = 0; j < 4; ++j) {
      for (let i = 0; i < 4; ++i) {
        const x = bx + i, y = by + j;
        if (x >= w || y >= h) continue;
        const s = (4 * j + i) * stride, d = 3 * (y * w + x);
        out[d] = toFloat(blockTexels[s]); out[d + 1] = toFloat(blockTexels[s + 1]); out[d + 2] = toFloat(blockTexels[s + 2]);
      }
    }
  };
  const srgb = (b) => SRGB[b];
  if (format === FORMAT.bc1) {
    const block = new Uint8Array(8), texels = new Uint8Array(48);
    for (let k = 0; k < B; ++k) {
      block.set(raw.subarray(4 * k, 4 * k + 4), 0);
      block.set(raw.subarray(4 * B + 4 * k, 4 * B + 4 * k + 4), 4);
      decodeBc1(block, 0, texels);
      put(k, texels, 3, srgb);
    }
  } else if (format === FORMAT.bc7) {
    const texels = new Uint8Array(64);
    for (let k = 0; k < B; ++k) { decodeBc7(raw, 16 * k, texels); put(k, texels, 4, srgb); }
  } else if (format === FORMAT.bc6h) {
    const texels = new Uint16Array(48);
    for (let k = 0; k < B; ++k) { decodeBc6h(raw, 16 * k, texels); put(k, texels, 3, halfToFloat); }
  } else if (format === FORMAT.rgba8) {
    for (let i = 0; i < n; ++i) for (let c = 0; c < 3; ++c) out[3 * i + c] = SRGB[raw[c * n + i]];
  } else {
    for (let i = 0; i < n; ++i) {
      for (let c = 0; c < 3; ++c) {
        const q = 4 * i + c;
        out[3 * i + c] = halfToFloat((raw[q] << 8) | raw[4 * n + q]);
      }
    }
  }
  return out;
}

// A BC1, BC7 or BC6H colour keyframe of a w × h rect as the blocks a GPU takes (8 or 16 bytes a
// block, row by row): BC7 and BC6H are stored so, BC1's endpoints and indices are interleaved
// back (§11.1.5).
export function bcBlocks(raw, format, w, h, what) {
  const B = Math.ceil(w / 4) * Math.ceil(h / 4);
  const size = format === FORMAT.bc1 ? 8 : 16;
  if (raw.length !== size * B) bad(`${what}: ${raw.length} bytes, expected ${size * B}`);
  if (format !== FORMAT.bc1) return raw;
  const out = new Uint8Array(8 * B);
  for (let k = 0; k < B; ++k) {
    out.set(raw.subarray(4 * k, 4 * k + 4), 8 * k);
    out.set(raw.subarray(4 * B + 4 * k, 4 * B + 4 * k + 4), 8 * k + 4);
  }
  return out;
}

// §11.1.12: an AV1 colour (GOP) chunk of `frameCount` frames → its temporal units; a head that
// contradicts the chunk's size or keys is CALF-E067 (as lf::parse_av1_gop).
export function parseAv1Gop(raw, frameCount, what) {
  const bad67 = (why) => fail(E.av1Chunk, `${what}: ${why}`);
  if (raw.length < 4) bad67(`AV1 chunk of ${raw.length} bytes`);
  const v = new DataView(raw.buffer, raw.byteOffset, raw.length);
  const F = v.getUint32(0, true);
  if (F !== frameCount || F === 0) bad67(`AV1 chunk of ${F} frames, its keys say ${frameCount}`);
  const head = 4 + 4 * F;
  if (head > raw.length) bad67(`AV1 chunk of ${raw.length} bytes is shorter than its head of ${head}`);
  const units = [];
  let at = head;
  for (let i = 0; i < F; ++i) {
    const size = v.getUint32(4 + 4 * i, true);
    if (size === 0 || size > raw.length - at) bad67(`temporal unit ${i} of ${size} bytes at offset ${at} of ${raw.length}`);
    units.push(raw.subarray(at, at + size));
    at += size;
  }
  if (at !== raw.length) bad67(`${raw.length - at} bytes after the last temporal unit`);
  return units;
}

// §11.1.12: an AV1 colour chunk → { units, curve }; for av1hdr (`hdr`) the chunk starts with
// its curve, u16 base and u16 shift, checked before the rest (CALF-E067: a chunk under 4 bytes,
// a base above 0x7BFF, a shift above 5), as lf::parse_av1_chunk.
export function parseAv1Chunk(raw, frameCount, hdr, what) {
  if (!hdr) return { units: parseAv1Gop(raw, frameCount, what), curve: null };
  if (raw.length < 4) fail(E.av1Chunk, `${what}: HDR AV1 chunk of ${raw.length} bytes`);
  const base = raw[0] | (raw[1] << 8), shift = raw[2] | (raw[3] << 8);
  if (base > 0x7bff || shift > 5) fail(E.av1Chunk, `${what}: curve base ${base} shift ${shift} (base at most 31743, shift at most 5)`);
  return { units: parseAv1Gop(raw.subarray(4), frameCount, what), curve: { base, shift } };
}

// §11.1.12's normative conversion of one texel: luma y, chroma cb and cr → sRGB-encoded bytes
// (BT.709 full range in 16 fractional bits; >> of a negative value is floor division).
export function av1YcbcrToRgb(y, cb, cr, out, o = 0) {
  const u = cb - 128, v = cr - 128;
  const c = (x) => (x < 0 ? 0 : x > 255 ? 255 : x);
  out[o] = c(y + ((103206 * v + 32768) >> 16));
  out[o + 1] = c(y - ((12276 * u + 30679 * v + 32768) >> 16));
  out[o + 2] = c(y + ((121609 * u + 32768) >> 16));
}

// The layout and bits of the picture formats av1.js gives (WebCodecs' names).
const PICTURE_FORMATS = { I420: ['4:2:0', 8], I420P10: ['4:2:0', 10], I444: ['4:4:4', 8], I444P10: ['4:4:4', 10] };

// A picture that is not of the `bits` and chroma (4:4:4 when `chroma444`, else 4:2:0) the
// track's colour format says, or is smaller than the w × h cell, is CALF-E302, in the native
// decoder's words (decoder/src/colour_av1.cc).
function checkPicture(picture, bits, chroma444, w, h, what) {
  const want = `${chroma444 ? 'I444' : 'I420'}${bits === 10 ? 'P10' : ''}`;
  if (picture.format === want && picture.planes && picture.width >= w && picture.height >= h) return;
  const known = PICTURE_FORMATS[picture.format];
  const has = known ? `${known[0]} picture of ${known[1]} bits` : `picture of format ${picture.format}`;
  fail(E.av1Picture, `${what}: a ${picture.width} x ${picture.height} ${has} for a ${w} x ${h} cell ` +
    `(${bits}-bit ${chroma444 ? '4:4:4' : '4:2:0'} expected by the track's colour format)`);
}

// §11.1.12: the w × h cell of a decoded AV1 picture ({ format, width, height, planes: [Y, U, V],
// strides }, av1.js) → linear binary32 RGB, texel-interleaved, through the sRGB bytes exactly as
// rgba8 (§11.1.5). Chroma is at (x >> 1, y >> 1) of a 4:2:0 picture ('I420', av1) and at (x, y)
// of a 4:4:4 one ('I444', av1-444: `chroma444`); a picture of the other layout or of 10 bits, or
// smaller than the cell, is CALF-E302.
export function av1Colour(picture, w, h, what, chroma444 = false) {
  checkPicture(picture, 8, chroma444, w, h, what);
  const [ys, us, vs] = picture.planes, [ly, lc] = picture.strides;
  const sub = chroma444 ? 0 : 1;
  const out = new Float32Array(3 * w * h), rgb = new Uint8Array(3);
  for (let y = 0; y < h; ++y) {
    for (let x = 0; x < w; ++x) {
      const c = (y >> sub) * lc + (x >> sub);
      av1YcbcrToRgb(ys[y * ly + x], us[c], vs[c], rgb);
      const d = 3 * (y * w + x);
      out[d] = SRGB[rgb[0]]; out[d + 1] = SRGB[rgb[1]]; out[d + 2] = SRGB[rgb[2]];
    }
  }
  return out;
}

// §11.1.12 (av1hdr): one texel's 10-bit codes y, cb, cr → its R, G, B codes (0 … 1023).
export function av1Ycbcr10ToRgb(y, cb, cr, out, o = 0) {
  const u = cb - 512, v = cr - 512;
  const c = (x) => (x < 0 ? 0 : x > 1023 ? 1023 : x);
  out[o] = c(y + ((103206 * v + 32768) >> 16));
  out[o + 1] = c(y - ((12276 * u + 30679 * v + 32768) >> 16));
  out[o + 2] = c(y + ((121609 * u + 32768) >> 16));
}

// §11.1.12 (av1hdr): the binary16 bits that code c stands for on the curve { base, shift }.
export function av1HdrHalfBits(curve, c) {
  return Math.min(curve.base + c * 2 ** curve.shift, 0x7bff);
}

// §11.1.12 (av1hdr): the w × h cell of a decoded 10-bit picture (16-bit samples, av1.js) →
// linear binary32 RGB, texel-interleaved: each code through the chunk's curve to a half float,
// as rgba16f (§11.1.5). Chroma as av1Colour's: 'I420P10' pictures (av1hdr), or 'I444P10' ones
// when `chroma444` (av1hdr-444); another picture, or one smaller than the cell, is CALF-E302.
// Samples are taken modulo 1024, as the native decoder reads them.
export function av1HdrColour(picture, w, h, curve, what, chroma444 = false) {
  checkPicture(picture, 10, chroma444, w, h, what);
  const value = new Float32Array(1024);
  for (let c = 0; c < 1024; ++c) value[c] = halfToFloat(av1HdrHalfBits(curve, c));
  const [ys, us, vs] = picture.planes, [ly, lc] = picture.strides;
  const sub = chroma444 ? 0 : 1;
  const out = new Float32Array(3 * w * h), rgb = new Uint16Array(3);
  for (let y = 0; y < h; ++y) {
    for (let x = 0; x < w; ++x) {
      const c = (y >> sub) * lc + (x >> sub);
      av1Ycbcr10ToRgb(ys[y * ly + x] & 1023, us[c] & 1023, vs[c] & 1023, rgb);
      const d = 3 * (y * w + x);
      out[d] = value[rgb[0]]; out[d + 1] = value[rgb[1]]; out[d + 2] = value[rgb[2]];
    }
  }
  return out;
}

// §11.1.4's binary32 interpolation of keyframes a and b with t (0 < t ≤ 255).
export function interpolate(a, b, t) {
  const f = Math.fround;
  const w = f(t / 255), u = f(1 - w);
  const out = new Float32Array(a.length);
  for (let i = 0; i < a.length; ++i) out[i] = f(f(u * a[i]) + f(w * b[i]));
  return out;
}

// §11.1.6: a region chunk parsed; frames[i] = rectangles of frame i, each with its texel
// values in `values` (depth codes, 3 material bytes a texel, or for kind 'coverage' (§11.1.11)
// 2 values a texel: mask and near count), or for r16pm its residuals and
// change mask (`residuals`, `mask`; none for the keyframe's rectangle).
export function parseRegion(raw, kind, format, tw, th, frameCount, what) {
  const v = new DataView(raw.buffer, raw.byteOffset, raw.length);
  if (raw.length < 4) bad(`${what}: ${raw.length} bytes`);
  const F = v.getUint32(0, true);
  if (F !== frameCount) bad(`${what}: F = ${F}, the chunk serves ${frameCount} frames`);
  if (raw.length < 4 + 4 * F) bad(`${what}: too short for ${F} rectangle counts`);
  const counts = [];
  let total = 0;
  for (let i = 0; i < F; ++i) { counts.push(v.getUint32(4 + 4 * i, true)); total += counts[i]; }
  let p = 4 + 4 * F;
  if (raw.length < p + 8 * total) bad(`${what}: too short for ${total} rectangles`);
  const blocky = format === FORMAT.bc5 || format === FORMAT.bc1;
  const frames = [];
  const rects = [];
  for (let i = 0; i < F; ++i) {
    const list = [];
    const cover = counts[i] > 1 ? new Uint8Array(tw * th) : null;
    for (let r = 0; r < counts[i]; ++r, p += 8) {
      const x = v.getUint16(p, true), y = v.getUint16(p + 2, true), w = v.getUint16(p + 4, true), h = v.getUint16(p + 6, true);
      if (w === 0 || h === 0 || x + w > tw || y + h > th) bad(`${what}: frame ${i} rectangle ${x},${y} ${w}×${h} outside the ${tw}×${th} tile`);
      if (blocky && (x % 4 || y % 4)) bad(`${what}: frame ${i} rectangle at ${x},${y} not on a block`);
      if (cover) {
        for (let yy = y; yy < y + h; ++yy) for (let xx = x; xx < x + w; ++xx) {
          if (cover[yy * tw + xx]) bad(`${what}: frame ${i} rectangles overlap`);
          cover[yy * tw + xx] = 1;
        }
      }
      const rect = { x, y, w, h };
      list.push(rect); rects.push(rect);
    }
    frames.push(list);
  }
  if (F < 1 || counts[0] !== 1 || frames[0][0].x || frames[0][0].y || frames[0][0].w !== tw || frames[0][0].h !== th) {
    bad(`${what}: the keyframe is not one whole-tile rectangle`);
  }
  const payload = raw.subarray(p);
  const T = rects.reduce((s, r) => s + r.w * r.h, 0);
  const B = rects.reduce((s, r) => s + Math.ceil(r.w / 4) * Math.ceil(r.h / 4), 0);
  if (kind === 'coverage') {
    parseCoverage(payload, rects, what);
  } else if (kind === 'depth') {
    if (format === FORMAT.r16 || format === FORMAT.r16p) {
      if (payload.length !== 2 * T) bad(`${what}: payload of ${payload.length} bytes, expected ${2 * T}`);
      let q = 0;
      for (const r of rects) {
        const n = r.w * r.h;
        r.values = new Uint16Array(n);
        for (let k = 0; k < n; ++k, ++q) r.values[k] = (payload[q] << 8) | payload[T + q];
        if (format === FORMAT.r16p) unpredict(r.values, r.w, r.h);
      }
    } else if (format === FORMAT.r16pm) {
      let m = 0, changed = rects[0].w * rects[0].h;
      for (let k = 1; k < rects.length; ++k) {
        const r = rects[k], n = r.w * r.h, M = Math.ceil(n / 8);
        if (m + M > payload.length) bad(`${what}: payload too short for its masks`);
        r.mask = payload.subarray(m, m + M);
        if (n % 8 && (r.mask[M - 1] >> (n % 8))) bad(`${what}: mask of rectangle ${k} has a bit past the rectangle`);
        for (let i = 0; i < n; ++i) changed += (r.mask[i >> 3] >> (i & 7)) & 1;
        m += M;
      }
      if (payload.length !== m + 2 * changed) bad(`${what}: payload of ${payload.length} bytes, expected ${m + 2 * changed}`);
      let q = 0;
      for (const r of rects) {
        const n = r.w * r.h;
        r.residuals = new Uint16Array(n);
        for (let i = 0; i < n; ++i) {
          if (r.mask && !((r.mask[i >> 3] >> (i & 7)) & 1)) continue;
          r.residuals[i] = (payload[m + q] << 8) | payload[m + changed + q];
          ++q;
        }
      }
    } else {  // BC5, block split
      if (payload.length !== 16 * B) bad(`${what}: payload of ${payload.length} bytes, expected ${16 * B}`);
      let k = 0;
      const block = new Uint8Array(16), hi = new Uint8Array(16), lo = new Uint8Array(16);
      for (const r of rects) {
        r.values = new Uint16Array(r.w * r.h);
        const bw = Math.ceil(r.w / 4), bh = Math.ceil(r.h / 4);
        for (let b = 0; b < bw * bh; ++b, ++k) {
          block[0] = payload[4 * k]; block[1] = payload[4 * k + 1]; block[8] = payload[4 * k + 2]; block[9] = payload[4 * k + 3];
          for (let s = 0; s < 6; ++s) { block[2 + s] = payload[4 * B + 12 * k + s]; block[10 + s] = payload[4 * B + 12 * k + 6 + s]; }
          decodeBc4(block, 0, hi); decodeBc4(block, 8, lo);
          const bx = 4 * (b % bw), by = 4 * Math.floor(b / bw);
          for (let t = 0; t < 16; ++t) {
            const x = bx + (t & 3), y = by + (t >> 2);
            if (x < r.w && y < r.h) r.values[y * r.w + x] = hi[t] * 256 + lo[t];
          }
        }
      }
    }
  } else if (format === FORMAT.rgba8) {
    if (payload.length !== 3 * T) bad(`${what}: payload of ${payload.length} bytes, expected ${3 * T}`);
    let q = 0;
    for (const r of rects) {
      const n = r.w * r.h;
      r.values = new Uint8Array(3 * n);
      for (let k = 0; k < n; ++k, ++q) for (let c = 0; c < 3; ++c) r.values[3 * k + c] = payload[c * T + q];
    }
  } else {  // BC1 material, block split
    if (payload.length !== 8 * B) bad(`${what}: payload of ${payload.length} bytes, expected ${8 * B}`);
    let k = 0;
    const block = new Uint8Array(8), texels = new Uint8Array(48);
    for (const r of rects) {
      r.values = new Uint8Array(3 * r.w * r.h);
      const bw = Math.ceil(r.w / 4), bh = Math.ceil(r.h / 4);
      for (let b = 0; b < bw * bh; ++b, ++k) {
        block.set(payload.subarray(4 * k, 4 * k + 4), 0);
        block.set(payload.subarray(4 * B + 4 * k, 4 * B + 4 * k + 4), 4);
        decodeBc1(block, 0, texels);
        const bx = 4 * (b % bw), by = 4 * Math.floor(b / bw);
        for (let t = 0; t < 16; ++t) {
          const x = bx + (t & 3), y = by + (t >> 2);
          if (x < r.w && y < r.h) for (let c = 0; c < 3; ++c) r.values[3 * (y * r.w + x) + c] = texels[3 * t + c];
        }
      }
    }
  }
  return frames;
}

// §11.1.11: the edge bitmaps of every rectangle, then the mask high bytes, mask low bytes and
// near counts of the E edge texels; each rectangle's values get (mask, near) a texel, the
// plain texel (65535, 0) where it is no edge. A bitmap bit past its rectangle or an edge
// texel that breaks its counts is CALF-E065, a payload of another size CALF-E202 (checked
// before the texels, as the reference decoder does).
function parseCoverage(payload, rects, what) {
  const bitmaps = rects.reduce((s, r) => s + Math.ceil(r.w * r.h / 8), 0);
  if (bitmaps > payload.length) bad(`${what}: payload of ${payload.length} bytes, shorter than its ${bitmaps} bytes of edge bitmaps`);
  let m = 0, edges = 0;
  for (let k = 0; k < rects.length; ++k) {
    const r = rects[k], n = r.w * r.h, M = Math.ceil(n / 8);
    r.mask = payload.subarray(m, m + M);
    for (let i = 0; i < n; ++i) edges += (r.mask[i >> 3] >> (i & 7)) & 1;
    if (n % 8 && (r.mask[M - 1] >> (n % 8))) fail(E.coverageChunk, `${what}: edge bitmap of rectangle ${k} has bits set past its ${n} texels`);
    m += M;
  }
  if (payload.length !== m + 3 * edges) bad(`${what}: payload of ${payload.length} bytes, expected ${m + 3 * edges}`);
  let q = 0;
  for (const r of rects) {
    const n = r.w * r.h;
    r.values = new Uint16Array(2 * n);
    for (let i = 0; i < n; ++i) {
      if (!((r.mask[i >> 3] >> (i & 7)) & 1)) { r.values[2 * i] = 0xffff; continue; }
      const mask = (payload[m + q] << 8) | payload[m + edges + q], near = payload[m + 2 * edges + q];
      let pop = 0;
      for (let b = mask; b; b &= b - 1) ++pop;
      if (near > 16 || near + pop > 16 || (mask === 0xffff && near === 0)) {
        fail(E.coverageChunk, `${what}: edge texel ${q} has mask 0x${mask.toString(16).padStart(4, '0')} and near count ${near}` +
          (mask === 0xffff && near === 0 ? ' (a plain texel, not an edge)' : ' (more than 16 cells)'));
      }
      r.values[2 * i] = mask; r.values[2 * i + 1] = near;
      ++q;
    }
    r.mask = null;
  }
}

// §11.1.8: an r16p rectangle's residuals → codes, in place, row-major (each texel predicted
// from its already decoded neighbours in the rectangle). r16pm's rectangles are decoded
// against the tile state instead, in applyRegionFrame.
function unpredict(values, w, h) {
  for (let y = 0; y < h; ++y) for (let x = 0; x < w; ++x) {
    const i = y * w + x;
    values[i] = (predict(values, w, x, y) + unzigzag(values[i])) & 0xffff;
  }
}

function unzigzag(e) { return e & 1 ? -((e + 1) >> 1) : e >> 1; }

// The prediction of texel (x, y) from codes get(x, y) already decoded.
function predictAt(get, x, y) {
  if (x === 0 && y === 0) return 0;
  if (y === 0) return get(x - 1, y);
  if (x === 0) return get(x, y - 1);
  const a = get(x - 1, y), b = get(x, y - 1), c = get(x - 1, y - 1);
  if (a !== 65535 && b !== 65535 && c !== 65535) return (a + b - c) & 0xffff;
  if (c >= Math.max(a, b)) return Math.min(a, b);
  if (c <= Math.min(a, b)) return Math.max(a, b);
  return a + b - c;
}

function predict(values, w, x, y) {
  return predictAt((xx, yy) => values[yy * w + xx], x, y);
}

// Applies frame i's rectangles of a parsed region chunk to a tile state (codes, or 3 bytes a
// texel for material).
export function applyRegionFrame(rects, state, tw, channels) {
  for (const r of rects) {
    if (r.residuals) {  // r16pm: predicted from the tile state as it stands
      const get = (x, y) => state[(r.y + y) * tw + r.x + x];
      for (let y = 0; y < r.h; ++y) for (let x = 0; x < r.w; ++x) {
        const i = y * r.w + x;
        if (r.mask && !((r.mask[i >> 3] >> (i & 7)) & 1)) continue;
        state[(r.y + y) * tw + r.x + x] = (predictAt(get, x, y) + unzigzag(r.residuals[i])) & 0xffff;
      }
      continue;
    }
    for (let y = 0; y < r.h; ++y) {
      for (let x = 0; x < r.w; ++x) {
        for (let c = 0; c < channels; ++c) state[channels * ((r.y + y) * tw + r.x + x) + c] = r.values[channels * (y * r.w + x) + c];
      }
    }
  }
}

let openings = 0;

// Opens lightfield track t of an opened clip: formats, chunk keys, view index chunks.
// Returns the track, with `views[v]` null and `viewProblems[v]` set for a dropped view, and
// `hasCoverage` when it holds any coverage chunk (§11.1.11).
export async function openLightfield(clip, t) {
  const h = clip.tracks[t].header;
  // AV1 colour (§11.1.12) needs an AV1 decoder (codecs.av1: WebCodecs, or its WebAssembly
  // stand-in) that takes the stream's profile (4:4:4 is AV1's High profile); without one the
  // track is refused as by any reader that lacks the format.
  const av1 = AV1_FORMATS[h.colour_format] ?? null;
  if (av1) {
    const named = `track ${t}: colour format ${h.colour_format} (${av1.name})`;
    if (!clip.codecs.av1) fail(E.lightfieldFormat, `${named}: no AV1 decoder here`);
    if ((await clip.codecs.av1.backEnd?.(av1.bits, av1.chroma444)) === null) {
      fail(E.lightfieldFormat, `${named}: no AV1 decoder here for ${av1.profile} (VideoDecoder.isConfigSupported says no, and no WebAssembly decoder)`);
    }
  }
  if (!COLOUR_FORMATS.includes(h.colour_format) && !av1) fail(E.lightfieldFormat, `track ${t}: colour format ${h.colour_format}`);
  if (!DEPTH_FORMATS.includes(h.depth_format)) fail(E.lightfieldFormat, `track ${t}: depth format ${h.depth_format}`);
  if (h.material_format !== 0 && !MATERIAL_FORMATS.includes(h.material_format)) fail(E.lightfieldFormat, `track ${t}: material format ${h.material_format}`);
  const cells = faceGrid(h.face_size, h.cell_size), tiles = faceGrid(h.face_size, h.depth_region_size);
  const byKey = new Map();
  const indexChunks = Array.from({ length: h.view_count }, () => []);
  for (const c of clip.chunks) {
    if (c.track !== t || c.stream > STREAM.coverage) continue;
    if (c.stream === STREAM.index) {
      if (c.view < h.view_count) indexChunks[c.view].push(c);
      continue;
    }
    const regions = c.stream === STREAM.colour || c.stream === STREAM.t ? cells.count : tiles.count;
    if (c.view >= h.view_count || c.face >= 6 || c.region >= regions) {
      bad(`track ${t} chunk ${c.id}: view ${c.view} face ${c.face} region ${c.region} outside the track`);
    }
    const key = `${c.stream}/${c.view}/${c.face}/${c.region}`;
    if (!byKey.has(key)) byKey.set(key, []);
    const list = byKey.get(key);
    if (list.some((o) => o.firstFrame === c.firstFrame)) bad(`track ${t} chunk ${c.id}: a second chunk of ${key} at frame ${c.firstFrame}`);
    list.push(c);
  }
  const views = [], viewProblems = [];
  for (let v = 0; v < h.view_count; ++v) {
    const what = `track ${t} view ${v} index`;
    try {
      if (indexChunks[v].length !== 1) bad(`${what}: ${indexChunks[v].length} index chunks, expected 1`);
      views.push(parseViewIndex(await readChunk(clip, indexChunks[v][0].id), what, h.material_format));
      viewProblems.push(null);
    } catch (e) {
      if (!(e instanceof CalfError)) throw e;
      views.push(null);
      viewProblems.push(e);
    }
  }
  if (views.every((x) => x === null)) throw viewProblems[0];
  const hasCoverage = clip.chunks.some((c) => c.track === t && c.stream === STREAM.coverage);
  // `opened` names this opening in the AV1 decoders' cell keys (codecs.av1 may serve several).
  return { clip, track: t, header: h, cells, tiles, byKey, views, viewProblems, hasCoverage, av1: av1 !== null, av1Format: av1, opened: ++openings };
}

// Decodes every frame of one face of one view in order; calls onFrame(n, colour, depth,
// material, coverage) with the face's arrays (reused between frames). With `only` ({ cells,
// tiles }: Sets of colour cell and depth region indices) the other regions are neither read nor
// written. Coverage (§11.1.11; mask and near count a texel) is decoded only with
// `{ coverage: true }` in a track with coverage, else it is null and no coverage chunk is read.
// Frames are decoded in order, so a region chunk is read once and its P-frames applied as
// they come. `{ from, to }` decodes frames from … to − 1 only (onFrame is called for those): a
// region chunk holding `from` is applied from its own first frame (§11.1.2), and no chunk of an
// earlier frame is read. `{ material: false }` neither reads nor decodes material (null).
export async function decodeFaceFrames(lf, v, face, onFrame, only = null,
  { coverage: withCoverage = false, material: withMaterial = true, from = 0, to = lf.header.frame_count } = {}) {
  const h = lf.header, N = h.face_size, t = lf.track;
  const view = lf.views[v];
  const colour = new Float32Array(3 * N * N), depth = new Uint16Array(N * N);
  const material = view.hasMaterial && withMaterial ? new Uint8Array(3 * N * N) : null;
  const coverage = withCoverage && lf.hasCoverage ? new Uint16Array(2 * N * N) : null;
  const find = (stream, region) => lf.byKey.get(`${stream}/${v}/${face}/${region}`) ?? [];
  const read = (c) => readChunk(lf.clip, c.id);
  // Colour cells: timelines and a cache of decoded keyframes.
  const cellState = [];
  for (let r = 0; r < lf.cells.count; ++r) {
    if (only && !only.cells.has(r)) {
      cellState.push(null);
      continue;
    }
    const where = `track ${t} view ${v} face ${face} cell ${r}`;
    if (lf.av1) {  // §11.1.12: no t chunks; each frame decoded from the GOP chunk holding it
      cellState.push({ rect: lf.cells.rect(r), where, key: `${lf.opened}/${t}/${v}/${face}/${r}`, chunk: null, units: null });
      continue;
    }
    const tc = find(STREAM.t, r);
    if (tc.length !== 1) bad(`${where}: ${tc.length} t chunks`);
    if (tc[0].frameCount !== h.frame_count) bad(`${where}: t chunk of ${tc[0].frameCount} frames`);
    cellState.push({ rect: lf.cells.rect(r), where, timeline: parseTimeline(await read(tc[0]), h.frame_count, `${where} t`), keys: new Map() });
  }
  const tileState = (stream, channels) => Array.from({ length: lf.tiles.count }, (_, r) => r).filter((r) => !only || only.tiles.has(r)).map((r) => {
    const rect = lf.tiles.rect(r);
    return { r, rect, chunk: null, frames: null, state: new (channels === 3 ? Uint8Array : Uint16Array)(channels * rect.w * rect.h), stream, channels };
  });
  const depthTiles = tileState(STREAM.depth, 1);
  const materialTiles = material ? tileState(STREAM.material, 3) : [];
  const coverageTiles = coverage ? tileState(STREAM.coverage, 2) : [];
  const KIND = { [STREAM.depth]: 'depth', [STREAM.material]: 'material', [STREAM.coverage]: 'coverage' };
  const FORMATS = { [STREAM.depth]: h.depth_format, [STREAM.material]: h.material_format, [STREAM.coverage]: 0 };
  const lossless = h.depth_format !== FORMAT.bc5;
  for (let n = from; n < to; ++n) {
    for (let r = 0; r < cellState.length; ++r) {
      const cell = cellState[r];
      if (!cell) continue;
      if (lf.av1) {
        await av1Cell(lf, cell, find(STREAM.colour, r), n, colour, N);
        continue;
      }
      const { keys, t: tv } = cell.timeline;
      let m = 0;
      while (m + 1 < keys.length && keys[m + 1] <= n) ++m;
      const get = async (k) => {
        if (!cell.keys.has(k)) {
          const c = find(STREAM.colour, r).find((x) => x.firstFrame === k);
          if (!c) bad(`${cell.where}: no colour chunk for keyframe ${k}`);
          cell.keys.set(k, decodeColour(await read(c), h.colour_format, cell.rect.w, cell.rect.h, `${cell.where} keyframe ${k}`));
        }
        return cell.keys.get(k);
      };
      let values = await get(keys[m]);
      if (m + 1 < keys.length && tv[n] !== 0) values = interpolate(values, await get(keys[m + 1]), tv[n]);
      for (const k of [...cell.keys.keys()]) if (k < keys[m]) cell.keys.delete(k);
      const { x: cx, y: cy, w: cw, h: ch } = cell.rect;
      for (let y = 0; y < ch; ++y) colour.set(values.subarray(3 * y * cw, 3 * (y + 1) * cw), 3 * ((cy + y) * N + cx));
    }
    for (const tile of [...depthTiles, ...materialTiles, ...coverageTiles]) {
      const kind = KIND[tile.stream];
      const where = `track ${t} view ${v} face ${face} ${kind} tile ${tile.r}`;
      if (!tile.chunk || n >= tile.chunk.firstFrame + tile.chunk.frameCount) {
        const c = find(tile.stream, tile.r).find((x) => x.firstFrame <= n && n < x.firstFrame + x.frameCount);
        if (!c) bad(`${where}: no chunk for frame ${n}`);
        tile.chunk = c;
        tile.frames = parseRegion(await read(c), kind, FORMATS[tile.stream],
          tile.rect.w, tile.rect.h, c.frameCount, `${where} frames ${c.firstFrame}+${c.frameCount}`);
        if (n !== c.firstFrame && n !== from) bad(`${where}: frame ${n} inside a chunk not decoded from its start`);
        for (let j = c.firstFrame; j < n; ++j) applyRegionFrame(tile.frames[j - c.firstFrame], tile.state, tile.rect.w, tile.channels);
      }
      applyRegionFrame(tile.frames[n - tile.chunk.firstFrame], tile.state, tile.rect.w, tile.channels);
      const dst = { depth, material, coverage }[kind], ch = tile.channels, { x: tx, y: ty, w: tw, h: th } = tile.rect;
      for (let y = 0; y < th; ++y) dst.set(tile.state.subarray(ch * y * tw, ch * (y + 1) * tw), ch * ((ty + y) * N + tx));
    }
    // §11.1.11: with lossless depth, a sky texel has no cell farther than it.
    if (coverage && lossless) {
      for (let i = 0; i < N * N; ++i) {
        if (depth[i] !== 65535) continue;
        const mask = coverage[2 * i], near = coverage[2 * i + 1];
        let pop = 0;
        for (let b = mask; b; b &= b - 1) ++pop;
        if (16 - near - pop !== 0) {
          fail(E.coverageDepth, `track ${t} view ${v} face ${face} frame ${n} texel (${i % N}, ${Math.floor(i / N)}): sky depth with coverage mask 0x${mask.toString(16).padStart(4, '0')} and near count ${near}, ${16 - near - pop} cells farther than sky`);
        }
      }
    }
    await onFrame(n, colour, depth, material, coverage);
  }
}

// Closes what an opened track holds beyond its chunks: the AV1 decoders of its cells.
export function closeLightfield(lf) {
  if (lf.av1) lf.clip.codecs.av1?.release(`${lf.opened}/`);
}

// Frame n of an AV1 colour cell into the face's colour: the GOP chunk holding n parsed (after
// its curve for av1hdr and av1hdr-444), its unit decoded by codecs.av1 (one decoder per cell,
// kept across calls, so that frame after frame decodes one unit each), converted by av1Colour or
// av1HdrColour.
async function av1Cell(lf, cell, chunks, n, colour, N) {
  const { bits, chroma444 } = lf.av1Format, hdr = bits === 10;
  if (!cell.chunk || n < cell.chunk.firstFrame || n >= cell.chunk.firstFrame + cell.chunk.frameCount) {
    const c = chunks.find((x) => x.firstFrame <= n && n < x.firstFrame + x.frameCount);
    if (!c) bad(`${cell.where}: no colour chunk for frame ${n}`);
    const what = `${cell.where} colour`;
    const parsed = parseAv1Chunk(await readChunk(lf.clip, c.id), c.frameCount, hdr, what);
    cell.units = parsed.units;
    cell.curve = parsed.curve;
    cell.chunk = c;
  }
  const what = `${cell.where} colour`, { x: cx, y: cy, w: cw, h: ch } = cell.rect;
  const picture = await lf.clip.codecs.av1.picture(cell.key, cell.chunk, cell.units, n - cell.chunk.firstFrame, what, bits, chroma444);
  const values = hdr ? av1HdrColour(picture, cw, ch, cell.curve, what, chroma444) : av1Colour(picture, cw, ch, what, chroma444);
  for (let y = 0; y < ch; ++y) colour.set(values.subarray(3 * y * cw, 3 * (y + 1) * cw), 3 * ((cy + y) * N + cx));
}

// §14: the conformance hash of one decoded face (coverage: a track with coverage's, as
// decodeFaceFrames gives it; null otherwise).
export function faceHash(codecs, colour, depth, material, coverage = null) {
  const parts = [new Uint8Array(colour.buffer, colour.byteOffset, colour.byteLength),
    new Uint8Array(depth.buffer, depth.byteOffset, depth.byteLength)];
  if (material) parts.push(material);
  if (coverage) {
    const n = coverage.length / 2, bytes = new Uint8Array(3 * n);
    for (let i = 0; i < n; ++i) {
      bytes[3 * i] = coverage[2 * i] & 0xff; bytes[3 * i + 1] = coverage[2 * i] >> 8; bytes[3 * i + 2] = coverage[2 * i + 1];
    }
    parts.push(bytes);
  }
  const total = parts.reduce((s, p) => s + p.length, 0);
  const bytes = new Uint8Array(total);
  let o = 0;
  for (const p of parts) { bytes.set(p, o); o += p.length; }
  return codecs.xxh3(bytes).toString(16).padStart(16, '0');
}
