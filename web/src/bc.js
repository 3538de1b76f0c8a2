// Block decoders of format/SPEC.md §11.1.10: BC1, BC4 / BC5, BC7 and BC6H (unsigned). Each
// decodes one block (8 or 16 bytes at `src[at]`) into the 16 texels of a 4 × 4 block, texel
// k = 4j + i being column i, row j. Integer arithmetic throughout, with the SPEC's rounding.
import {
  kPartition2, kPartition3, kAnchor2, kAnchor3a, kAnchor3b, kWeights2, kWeights3, kWeights4,
  kBc6hModes, kBc6hFieldText,
} from './bc_tables.js';

const weightsFor = (bits) => (bits === 2 ? kWeights2 : bits === 3 ? kWeights3 : kWeights4);

// Reads a 128-bit block from bit 0 of byte 0 upwards.
class Bits {
  constructor(src, at) { this.src = src; this.at = at; this.pos = 0; }
  take(n) {
    let v = 0;
    for (let k = 0; k < n; ++k, ++this.pos) {
      v |= ((this.src[this.at + (this.pos >> 3)] >> (this.pos & 7)) & 1) << k;
    }
    return v >>> 0;
  }
}

// BC1 → out[3k + c] the R, G, B bytes of texel k; a 3-colour block's index 3 gives (0, 0, 0).
export function decodeBc1(src, at, out) {
  const c0 = src[at] | (src[at + 1] << 8);
  const c1 = src[at + 2] | (src[at + 3] << 8);
  const idx = (src[at + 4] | (src[at + 5] << 8) | (src[at + 6] << 16) | (src[at + 7] << 24)) >>> 0;
  const expand = (c) => {
    const r = c >> 11, g = (c >> 5) & 63, b = c & 31;
    return [(r << 3) | (r >> 2), (g << 2) | (g >> 4), (b << 3) | (b >> 2)];
  };
  const p0 = expand(c0), p1 = expand(c1);
  const pal = [p0, p1, [0, 0, 0], [0, 0, 0]];
  for (let c = 0; c < 3; ++c) {
    if (c0 > c1) {
      pal[2][c] = Math.floor((2 * p0[c] + p1[c]) / 3);
      pal[3][c] = Math.floor((p0[c] + 2 * p1[c]) / 3);
    } else {
      pal[2][c] = (p0[c] + p1[c]) >> 1;
    }
  }
  for (let k = 0; k < 16; ++k) {
    const e = pal[(idx >>> (2 * k)) & 3];
    out[3 * k] = e[0]; out[3 * k + 1] = e[1]; out[3 * k + 2] = e[2];
  }
}

// BC4 → out[k * stride] the level of texel k.
export function decodeBc4(src, at, out, offset = 0, stride = 1) {
  const a = src[at], b = src[at + 1];
  const levels = [a, b, 0, 0, 0, 0, 0, 0];
  if (a > b) {
    for (let i = 2; i < 8; ++i) levels[i] = Math.floor((a * (8 - i) + b * (i - 1)) / 7);
  } else {
    for (let i = 2; i < 6; ++i) levels[i] = Math.floor((a * (6 - i) + b * (i - 1)) / 5);
    levels[6] = 0; levels[7] = 255;
  }
  // 48 index bits: two 24-bit halves so that JavaScript's 32-bit shifts suffice.
  const lo = src[at + 2] | (src[at + 3] << 8) | (src[at + 4] << 16);
  const hi = src[at + 5] | (src[at + 6] << 8) | (src[at + 7] << 16);
  for (let k = 0; k < 16; ++k) {
    const v = k < 8 ? (lo >> (3 * k)) & 7 : (hi >> (3 * (k - 8))) & 7;
    out[offset + k * stride] = levels[v];
  }
}

// BC7 modes: subsets, partition bits, rotation bits, index selection bits, colour bits, alpha
// bits, p-bits (0 none, 1 per subset, 2 per endpoint), index bits, secondary index bits.
const BC7_MODES = [
  [3, 4, 0, 0, 4, 0, 2, 3, 0], [2, 6, 0, 0, 6, 0, 1, 3, 0], [3, 6, 0, 0, 5, 0, 0, 2, 0],
  [2, 6, 0, 0, 7, 0, 2, 2, 0], [1, 0, 2, 1, 5, 6, 0, 2, 3], [1, 0, 2, 0, 7, 8, 0, 2, 2],
  [1, 0, 0, 0, 7, 7, 2, 4, 0], [2, 6, 0, 0, 5, 5, 2, 2, 0],
];

const subsetOf = (subsets, p, i) => (subsets === 1 ? 0 : subsets === 2 ? kPartition2[p][i] : kPartition3[p][i]);
const isAnchor = (subsets, p, i) => i === 0 ||
  (subsets === 2 && i === kAnchor2[p]) || (subsets === 3 && (i === kAnchor3a[p] || i === kAnchor3b[p]));

// BC7 → out[4k + c] the R, G, B, A bytes of texel k.
export function decodeBc7(src, at, out) {
  if (src[at] === 0) { out.fill(0, 0, 64); return; }
  let m = 0;
  while (!((src[at] >> m) & 1)) ++m;
  const [ns, pb, rb, isb, cb, ab, pmode, ib, ib2] = BC7_MODES[m];
  const br = new Bits(src, at);
  br.take(m + 1);
  const part = br.take(pb), rot = br.take(rb), isel = br.take(isb);
  const ne = 2 * ns;
  const ends = Array.from({ length: ne }, () => [0, 0, 0, 255]);
  for (let c = 0; c < 3; ++c) for (let e = 0; e < ne; ++e) ends[e][c] = br.take(cb);
  if (ab) for (let e = 0; e < ne; ++e) ends[e][3] = br.take(ab);
  let pbits = null;
  if (pmode === 2) pbits = Array.from({ length: ne }, () => br.take(1));
  else if (pmode === 1) { const s = Array.from({ length: ns }, () => br.take(1)); pbits = Array.from({ length: ne }, (_, e) => s[e >> 1]); }
  const expand = (x, n) => { x <<= 8 - n; return x | (x >> n); };
  for (let e = 0; e < ne; ++e) {
    for (let c = 0; c < 4; ++c) {
      if (c === 3 && !ab) continue;
      let n = c < 3 ? cb : ab, x = ends[e][c];
      if (pbits) { x = (x << 1) | pbits[e]; ++n; }
      ends[e][c] = expand(x, n);
    }
  }
  const idx1 = new Array(16), idx2 = new Array(16);
  for (let k = 0; k < 16; ++k) idx1[k] = br.take(ib - (isAnchor(ns, part, k) ? 1 : 0));
  if (ib2) for (let k = 0; k < 16; ++k) idx2[k] = br.take(ib2 - (k === 0 ? 1 : 0));
  const w1 = weightsFor(ib), w2 = ib2 ? weightsFor(ib2) : null;
  for (let k = 0; k < 16; ++k) {
    const s = subsetOf(ns, part, k), e0 = ends[2 * s], e1 = ends[2 * s + 1];
    let wc, wa;
    if (!ib2) { wc = wa = w1[idx1[k]]; } else if (isel) { wc = w2[idx2[k]]; wa = w1[idx1[k]]; } else { wc = w1[idx1[k]]; wa = w2[idx2[k]]; }
    const px = [0, 0, 0, 0];
    for (let c = 0; c < 3; ++c) px[c] = ((64 - wc) * e0[c] + wc * e1[c] + 32) >> 6;
    px[3] = ((64 - wa) * e0[3] + wa * e1[3] + 32) >> 6;
    if (rot) { const t = px[3]; px[3] = px[rot - 1]; px[rot - 1] = t; }
    out[4 * k] = px[0]; out[4 * k + 1] = px[1]; out[4 * k + 2] = px[2]; out[4 * k + 3] = px[3];
  }
}

// BC6H's Table.F parsed once: per mode, [variable, bit] per block bit; variable 3e + c is
// endpoint e's channel c (R, G, B), 12 the mode bits, 13 the partition number.
const BC6H_LAYOUTS = kBc6hFieldText.map((text, k) => {
  const fields = [];
  for (const f of text.split(',')) {
    const m = /^([mrgb])(\d?)\[(\d+)(?::(\d+))?\]$/.exec(f);
    const v = m[1] === 'm' ? 12 : 3 * Number(m[2]) + 'rgb'.indexOf(m[1]);
    const a = Number(m[3]), b = m[4] === undefined ? a : Number(m[4]);
    const step = a >= b ? 1 : -1;
    for (let bit = b; ; bit += step) { fields.push([v, bit]); if (bit === a) break; }
  }
  for (let bit = 0; bit < kBc6hModes[k].partitionBits; ++bit) fields.push([13, bit]);
  return fields;
});

const signExtend = (v, bits) => { const m = 1 << (bits - 1); return ((v & ((1 << bits) - 1)) ^ m) - m; };

function unquantize(x, bits) {
  if (bits >= 15) return x;
  if (x === 0) return 0;
  if (x === (1 << bits) - 1) return 0xffff;
  return ((x << 15) + 0x4000) >> (bits - 1);
}

// BC6H_UF16 → out[3k + c] the half-float bits of texel k's R, G, B.
export function decodeBc6h(src, at, out) {
  const low2 = src[at] & 3;
  const value = low2 < 2 ? low2 : src[at] & 31;
  const k = kBc6hModes.findIndex((m) => m.modeValue === value);
  if (k < 0) { out.fill(0, 0, 48); return; }
  const mode = kBc6hModes[k];
  const br = new Bits(src, at);
  const v = new Array(14).fill(0);
  for (const [variable, bit] of BC6H_LAYOUTS[k]) v[variable] |= br.take(1) << bit;
  const regions = mode.partitionBits ? 2 : 1;
  const part = v[13], eb = mode.endpointBits;
  const ep = [[0, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0]];
  for (let c = 0; c < 3; ++c) {
    ep[0][c] = v[c];
    for (let e = 1; e < 2 * regions; ++e) {
      let x = v[3 * e + c];
      if (mode.transformed) x = (ep[0][c] + signExtend(x, mode.deltaBits[c])) & ((1 << eb) - 1);
      ep[e][c] = x;
    }
  }
  for (let e = 0; e < 2 * regions; ++e) for (let c = 0; c < 3; ++c) ep[e][c] = unquantize(ep[e][c], eb);
  const ib = regions === 2 ? 3 : 4;
  const w = weightsFor(ib);
  for (let i = 0; i < 16; ++i) {
    const index = br.take(ib - (isAnchor(regions, part, i) ? 1 : 0));
    const s = subsetOf(regions, part, i);
    for (let c = 0; c < 3; ++c) {
      const x = (ep[2 * s][c] * (64 - w[index]) + ep[2 * s + 1][c] * w[index] + 32) >> 6;
      out[3 * i + c] = (x * 31) >> 6;
    }
  }
}
