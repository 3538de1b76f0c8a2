// The tiles kind (format/SPEC.md §11.2): layered quads textured from one RGBA atlas. openTiles
// checks the header and the chunk keys (§11.2.5), reads the index chunk (§11.2.2); quads() and
// atlas() decode on demand (§11.2.3, §11.2.4); tilesHashes gives §11.2.6's conformance lines.
import { E, fail } from './errors.js';
import { readChunk } from './container.js';
import { decodeBc7 } from './bc.js';

const STREAM = { index: 0, atlas: 1, quads: 2 };
const MAX_TILES = 4194304, MAX_BAND = 16384, MAX_COORD = 1e12;

// Word i of n 32-bit words stored as byte planes (byte 0 of every word, then byte 1, …).
export function fromBytePlanes(raw, at, n) {
  const w = new Uint32Array(n);
  for (let i = 0; i < n; ++i) {
    w[i] = (raw[at + i] | (raw[at + n + i] << 8) | (raw[at + 2 * n + i] << 16) | (raw[at + 3 * n + i] << 24)) >>> 0;
  }
  return w;
}

// The track's header checks, chunk keys and index; throws the first problem.
export async function openTiles(clip, t) {
  const track = clip.tracks[t];
  if (!track || track.kind !== 2) fail('CALF-E001', `track ${t} is not a tiles track`);
  const h = track.header;
  if (h.frame_count !== 1) fail(E.tilesUnsupported, `track ${t}: frame_count ${h.frame_count}, layout 1 holds one frame`);
  if (h.flags !== 0) fail(E.tilesUnsupported, `track ${t}: header flags ${h.flags}`);
  if (h.atlas_format !== 8 && h.atlas_format !== 1) fail(E.tilesUnsupported, `track ${t}: atlas_format ${h.atlas_format}`);
  if (h.tile_count > MAX_TILES) fail(E.tilesLimit, `track ${t}: ${h.tile_count} tiles`);
  let index = null, quads = null;
  const bands = new Map();
  for (const c of clip.chunks) {
    if (c.track !== t || c.stream > 2) continue;
    const what = `track ${t} chunk ${c.id}`;
    if (c.view || c.face || c.layer || c.firstFrame || c.frameCount || (c.stream !== STREAM.atlas && c.region)) {
      fail(E.tilesChunk, `${what}: keys other than stream and region`);
    }
    if (c.stream === STREAM.index) { if (index) fail(E.tilesChunk, `${what}: a second index chunk`); index = c; }
    else if (c.stream === STREAM.quads) { if (quads) fail(E.tilesChunk, `${what}: a second quads chunk`); quads = c; }
    else bands.set(c.region, bands.has(c.region) ? null : c);
  }
  if (!index) return null;  // no representation (§11.2.6): readers skip it
  if (!quads) fail(E.tilesChunk, `track ${t}: no quads chunk`);
  const ix = parseIndex(await readChunk(clip, index.id), `track ${t} index`);
  const bandCount = Math.ceil(h.atlas_height / ix.bandRows);
  for (const [b, c] of bands) {
    if (c === null) fail(E.tilesChunk, `track ${t}: band ${b} twice`);
    if (b >= bandCount) fail(E.tilesChunk, `track ${t}: band ${b} of ${bandCount}`);
  }
  if (Number(quads.rawSize) !== 96 * h.tile_count) fail(E.tilesChunk, `track ${t}: quads chunk of ${quads.rawSize} bytes`);
  const W = h.atlas_width, H = h.atlas_height;
  const bandChunks = [];
  for (let b = 0; b < bandCount; ++b) {
    const c = bands.get(b);
    if (!c) fail(E.tilesChunk, `track ${t}: band ${b} missing`);
    const rows = Math.min(ix.bandRows, H - b * ix.bandRows);
    const size = h.atlas_format === 1 ? 4 * W * rows : 16 * Math.ceil(W / 4) * Math.ceil(rows / 4);
    if (Number(c.rawSize) !== size) fail(E.tilesChunk, `track ${t}: band ${b} of ${c.rawSize} bytes, expected ${size}`);
    bandChunks.push(c);
  }
  return { clip, track: t, header: h, index: ix, quadsChunk: quads, bandChunks,
    quads: () => decodeQuads(clip, quads, h.tile_count, `track ${t}`),
    atlas: () => decodeAtlas(clip, bandChunks, h, ix.bandRows),
    atlasBlocks: () => atlasBlocks(clip, bandChunks, h) };
}

function parseIndex(raw, what) {
  const v = new DataView(raw.buffer, raw.byteOffset, raw.byteLength);
  if (raw.length < 4) fail(E.tilesChunk, `${what}: ${raw.length} bytes`);
  const version = v.getUint32(0, true);
  if (version !== 1) fail(E.tilesUnsupported, `${what}: layout version ${version}`);
  if (raw.length < 60) fail(E.tilesChunk, `${what}: ${raw.length} bytes, expected 60`);
  const min = [], max = [];
  for (let i = 0; i < 6; ++i) {
    const x = v.getFloat64(8 + 8 * i, true);
    if (!Number.isFinite(x)) fail(E.tilesValue, `${what}: view region coordinate ${i} not finite`);
    (i < 3 ? min : max).push(x);
  }
  const bandRows = v.getUint32(56, true);
  if (bandRows > MAX_BAND) fail(E.tilesLimit, `${what}: band_rows ${bandRows}`);
  if (raw.length !== 60) fail(E.tilesChunk, `${what}: ${raw.length} bytes, expected 60`);
  const flags = v.getUint32(4, true);
  if (flags !== 0) fail(E.tilesUnsupported, `${what}: flags ${flags}`);
  if (bandRows < 4 || bandRows % 4) fail(E.tilesValue, `${what}: band_rows ${bandRows}`);
  for (let a = 0; a < 3; ++a) {
    if (!(min[a] <= max[a]) || Math.abs(min[a]) > MAX_COORD || Math.abs(max[a]) > MAX_COORD) {
      fail(E.tilesValue, `${what}: view region axis ${a}`);
    }
  }
  return { viewMin: min, viewMax: max, bandRows };
}

// §11.2.3: the 24n words of the tiles (tile, corner, field x y z U V W) as a Float32Array.
async function decodeQuads(clip, c, n, what) {
  const raw = await readChunk(clip, c.id);
  const res = fromBytePlanes(raw, 0, 24 * n);
  const words = new Uint32Array(24 * n);
  for (let t = 0; t < n; ++t) {
    for (let w = 0; w < 24; ++w) {
      const pred = w < 6 ? (t ? words[24 * (t - 1) + w] : 0) : words[24 * t + (w % 6)];
      words[24 * t + w] = (res[w * n + t] + pred) >>> 0;
    }
  }
  const f = new Float32Array(words.buffer);
  for (let t = 0; t < n; ++t) {
    for (let k = 0; k < 4; ++k) {
      const q = f.subarray(24 * t + 6 * k, 24 * t + 6 * k + 6);
      const at = `${what}: tile ${t} corner ${k}`;
      for (let i = 0; i < 3; ++i) {
        if (!Number.isFinite(q[i]) || Math.abs(q[i]) > MAX_COORD) fail(E.tilesValue, `${at} position ${'xyz'[i]}`);
      }
      if (!Number.isFinite(q[5]) || !(q[5] > 0)) fail(E.tilesValue, `${at} W`);
      if (!(q[3] >= 0 && q[3] <= q[5])) fail(E.tilesValue, `${at} U`);
      if (!(q[4] >= 0 && q[4] <= q[5])) fail(E.tilesValue, `${at} V`);
    }
  }
  return f;
}

// §11.2.4: the W × H RGBA8 texels (premultiplied), rows from the top.
async function decodeAtlas(clip, bands, h, R) {
  const W = h.atlas_width, H = h.atlas_height;
  const out = new Uint8Array(4 * W * H);
  const texels = new Uint8Array(64);
  for (let b = 0; b < bands.length; ++b) {
    const raw = await readChunk(clip, bands[b].id);
    const r0 = b * R, rows = Math.min(R, H - r0);
    if (h.atlas_format === 1) { out.set(raw, 4 * W * r0); continue; }
    const bw = Math.ceil(W / 4);
    for (let by = 0; by < Math.ceil(rows / 4); ++by) {
      for (let bx = 0; bx < bw; ++bx) {
        decodeBc7(raw, 16 * (by * bw + bx), texels);
        for (let y = 0; y < 4; ++y) {
          const row = r0 + 4 * by + y;
          if (4 * by + y >= rows) break;
          for (let x = 0; x < 4 && 4 * bx + x < W; ++x) {
            out.set(texels.subarray(4 * (4 * y + x), 4 * (4 * y + x) + 4), 4 * (row * W + 4 * bx + x));
          }
        }
      }
    }
  }
  return out;
}

// The BC7 blocks of the whole atlas (bands are whole block rows), for a compressed upload.
async function atlasBlocks(clip, bands, h) {
  if (h.atlas_format !== 8) return null;
  const parts = [];
  for (const c of bands) parts.push(await readChunk(clip, c.id));
  const out = new Uint8Array(parts.reduce((s, p) => s + p.length, 0));
  let o = 0;
  for (const p of parts) { out.set(p, o); o += p.length; }
  return out;
}

const hex = (x) => x.toString(16).padStart(16, '0');

// §11.2.6: the two lines calf-verify --decode prints for tiles track t (none when it has no index).
export async function tilesLines(clip, t) {
  const tl = await openTiles(clip, t);
  if (!tl) return [];
  const n = tl.header.tile_count;
  const q = await tl.quads();
  const qb = new Uint8Array(4 + 48 + 96 * n);
  const v = new DataView(qb.buffer);
  v.setUint32(0, n, true);
  [...tl.index.viewMin, ...tl.index.viewMax].forEach((x, i) => v.setFloat64(4 + 8 * i, x, true));
  qb.set(new Uint8Array(q.buffer, q.byteOffset, q.byteLength), 52);
  const atlas = await tl.atlas();
  const ab = new Uint8Array(8 + atlas.length);
  const av = new DataView(ab.buffer);
  av.setUint32(0, tl.header.atlas_width, true);
  av.setUint32(4, tl.header.atlas_height, true);
  ab.set(atlas, 8);
  return [`track ${t} tiles quads ${hex(clip.codecs.xxh3(qb))}`, `track ${t} tiles atlas ${hex(clip.codecs.xxh3(ab))}`];
}
