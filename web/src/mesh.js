// The mesh kind (format/SPEC.md §11.4): materials, prototype meshes, objects placing them per
// frame, layout 2's textures. openMesh checks the header and the chunk keys and parses the index
// (§11.4.2, §11.4.7); prototype(p), object(o) and texture(x) decode on demand (§11.4.3 – §11.4.6);
// meshLines gives §11.4.7's conformance lines.
import { E, fail } from './errors.js';
import { readChunk } from './container.js';
import { fromBytePlanes } from './tiles.js';

const STREAM = { index: 0, vertices: 1, triangles: 2, visibility: 3, textures: 4 };
const MAX_COORD = 1e12, NONE = 0xffffffff;
const LIMITS = { materials: 65536, prototypes: 1048576, objects: 16777216, textures: 4096, states: 4096, texels: 16384 };

class Reader {
  constructor(raw, what) {
    this.raw = raw; this.v = new DataView(raw.buffer, raw.byteOffset, raw.byteLength); this.p = 0; this.what = what;
  }
  need(n) { if (this.p + n > this.raw.length) fail(E.meshChunk, `${this.what}: ends early`); }
  u32() { this.need(4); const x = this.v.getUint32(this.p, true); this.p += 4; return x; }
  f32() { this.need(4); const x = this.v.getFloat32(this.p, true); this.p += 4; return x; }
  f64() { this.need(8); const x = this.v.getFloat64(this.p, true); this.p += 8; return x; }
  count(name, limit) {
    const n = this.u32();
    if (n > limit) fail(E.meshLimit, `${this.what}: ${n} ${name}, at most ${limit}`);
    return n;
  }
}

export async function openMesh(clip, t) {
  const track = clip.tracks[t];
  if (!track || track.kind !== 4) fail('CALF-E001', `track ${t} is not a mesh track`);
  const h = track.header;
  if (h.flags & ~1) fail(E.meshUnsupported, `track ${t}: header flags ${h.flags}`);
  let indexChunk = null;
  const byStream = [new Map(), new Map(), new Map(), new Map(), new Map()];
  for (const c of clip.chunks) {
    if (c.track !== t || c.stream > 4) continue;
    const what = `track ${t} chunk ${c.id}`;
    if (c.view || c.face || c.layer || c.firstFrame || c.frameCount || (c.stream === STREAM.index && c.region)) {
      fail(E.meshChunk, `${what}: keys other than stream and region`);
    }
    if (c.stream === STREAM.index) {
      if (indexChunk) fail(E.meshChunk, `${what}: a second index chunk`);
      indexChunk = c;
    } else {
      if (byStream[c.stream].has(c.region)) fail(E.meshChunk, `${what}: a second chunk of stream ${c.stream} region ${c.region}`);
      byStream[c.stream].set(c.region, c);
    }
  }
  if (!indexChunk) return null;  // no representation (§11.4.7): readers skip it
  const ix = parseIndex(await readChunk(clip, indexChunk.id), `track ${t} index`, h.frame_count);
  const P = ix.prototypes.length, O = ix.objects.length, X = ix.textures.length;
  const limitOf = [0, P, P, O, ix.layout === 2 ? X : Infinity];
  for (let s = 1; s <= 4; ++s) {
    if (s === 4 && ix.layout !== 2) continue;
    for (const r of byStream[s].keys()) if (r >= limitOf[s]) fail(E.meshChunk, `track ${t}: stream ${s} region ${r}`);
  }
  const size = (c) => Number(c.rawSize);
  let vertexCount = 0, triangleCount = 0;
  ix.prototypes.forEach((p, i) => {
    const c = byStream[1].get(i);
    const V = p.V, S = p.S;
    const want = 12 * V * (1 + (p.flags & 1) + ((p.flags >> 1) & 1)) + 8 * V * ((p.flags >> 3) & 1) + 4 * S + 12 * V * S;
    if (!c || size(c) !== want) fail(E.meshChunk, `track ${t}: prototype ${i}'s vertices chunk missing or not ${want} bytes`);
    const tc = byStream[2].get(i);
    if (p.trianglesOf === i) {
      const wantT = 12 * p.T + 4 * p.T * ((p.flags >> 2) & 1);
      if (!tc || size(tc) !== wantT) fail(E.meshChunk, `track ${t}: prototype ${i}'s triangles chunk missing or not ${wantT} bytes`);
    } else if (tc) fail(E.meshChunk, `track ${t}: prototype ${i} has a triangles chunk`);
    vertexCount += V;
  });
  ix.objects.forEach((o, i) => {
    const c = byStream[3].get(i);
    if (!c || size(c) < 48 * o.N + (o.flags & 1 ? 0 : 4)) fail(E.meshChunk, `track ${t}: object ${i}'s visibility chunk`);
    triangleCount += o.K;
  });
  if (ix.layout === 2) {
    ix.textures.forEach((x, i) => {
      const c = byStream[4].get(i);
      if (!c || size(c) !== 4 * x.W * x.H) fail(E.meshChunk, `track ${t}: texture ${i}'s chunk`);
    });
  }
  if (BigInt(vertexCount) !== BigInt(h.vertex_count) || BigInt(triangleCount) !== BigInt(h.triangle_count)) {
    fail(E.meshChunk, `track ${t}: header counts do not match the index`);
  }
  const mesh = { clip, track: t, header: h, index: ix, chunks: byStream };
  mesh.prototype = (p) => decodePrototype(mesh, p);
  mesh.object = (o) => decodeObject(mesh, o);
  mesh.texture = (x) => decodeTexture(mesh, x);
  return mesh;
}

function parseIndex(raw, what, frameCount) {
  const r = new Reader(raw, what);
  const layout = r.u32();
  if (layout !== 1 && layout !== 2) fail(E.meshUnsupported, `${what}: layout version ${layout}`);
  const flags = r.u32();
  const viewMin = [r.f64(), r.f64(), r.f64()], viewMax = [r.f64(), r.f64(), r.f64()];
  const materials = [], prototypes = [], objects = [], textures = [];
  const M = r.count('materials', LIMITS.materials);
  for (let i = 0; i < M; ++i) materials.push({ base: [r.f32(), r.f32(), r.f32()], emission: [r.f32(), r.f32(), r.f32()], texture: NONE });
  const P = r.count('prototypes', LIMITS.prototypes);
  for (let i = 0; i < P; ++i) prototypes.push({ V: r.u32(), T: r.u32(), flags: r.u32(), S: r.u32(), trianglesOf: r.u32() });
  const O = r.count('objects', LIMITS.objects);
  for (let i = 0; i < O; ++i) objects.push({ source: r.u32(), prototype: r.u32(), material: r.u32(), N: r.u32(), flags: r.u32(), K: r.u32() });
  if (layout === 2) {
    const X = r.count('textures', LIMITS.textures);
    for (let i = 0; i < X; ++i) textures.push({ W: r.u32(), H: r.u32(), coding: r.u32(), flags: r.u32() });
    for (const m of materials) m.texture = r.u32();
  }
  if (r.p !== raw.length) fail(E.meshChunk, `${what}: ${raw.length - r.p} bytes after the last array`);
  if (flags) fail(E.meshUnsupported, `${what}: flags ${flags}`);
  const protoFlags = layout === 2 ? 15 : 7;
  prototypes.forEach((p, i) => {
    if (p.flags & ~protoFlags) fail(E.meshUnsupported, `${what}: prototype ${i} flags ${p.flags}`);
    if (p.S > LIMITS.states) fail(E.meshLimit, `${what}: prototype ${i} has ${p.S} states`);
  });
  objects.forEach((o, i) => { if (o.flags & ~1) fail(E.meshUnsupported, `${what}: object ${i} flags ${o.flags}`); });
  textures.forEach((x, i) => {
    if (x.coding > 1 || x.flags) fail(E.meshUnsupported, `${what}: texture ${i} coding ${x.coding} flags ${x.flags}`);
    if (!x.W || !x.H) fail(E.meshValue, `${what}: texture ${i} is empty`);
    if (x.W > LIMITS.texels || x.H > LIMITS.texels) fail(E.meshLimit, `${what}: texture ${i} is ${x.W} × ${x.H}`);
  });
  for (let a = 0; a < 6; ++a) {
    const x = a < 3 ? viewMin[a] : viewMax[a - 3];
    if (!Number.isFinite(x)) fail(E.meshValue, `${what}: view region not finite`);
  }
  for (let a = 0; a < 3; ++a) if (!(viewMin[a] <= viewMax[a])) fail(E.meshValue, `${what}: view region axis ${a}`);
  materials.forEach((m, i) => {
    if (!m.base.every((x) => x >= 0 && x <= 1)) fail(E.meshValue, `${what}: material ${i} base colour`);
    if (!m.emission.every((x) => Number.isFinite(x) && x >= 0)) fail(E.meshValue, `${what}: material ${i} emission`);
  });
  prototypes.forEach((p, i) => {
    const q = prototypes[p.trianglesOf];
    if (p.trianglesOf !== i && (p.trianglesOf > i || q.trianglesOf !== p.trianglesOf || q.T !== p.T || ((q.flags ^ p.flags) & 4))) {
      fail(E.meshIndex, `${what}: prototype ${i} draws the triangles of ${p.trianglesOf}`);
    }
  });
  objects.forEach((o, i) => {
    const p = prototypes[o.prototype];
    if (!p || o.material >= M) fail(E.meshIndex, `${what}: object ${i} names prototype ${o.prototype}, material ${o.material}`);
    if (o.N !== 1 && o.N !== frameCount) fail(E.meshIndex, `${what}: object ${i} has ${o.N} transforms`);
    if ((o.flags & 1) ? o.K !== p.T : o.K > p.T) fail(E.meshIndex, `${what}: object ${i} draws ${o.K} triangles`);
  });
  materials.forEach((m, i) => {
    if (m.texture !== NONE && m.texture >= textures.length) fail(E.meshIndex, `${what}: material ${i} names texture ${m.texture}`);
  });
  return { layout, viewMin, viewMax, materials, prototypes, objects, textures };
}

// A vec3 array of V vertices at `at` (component planes, byte planes), predicted by `ref`
// (the same layout's decoded words, vertex-major) when given; returns vertex-major words.
function vec3Array(raw, at, V, ref) {
  const w = fromBytePlanes(raw, at, 3 * V);
  const out = new Uint32Array(3 * V);
  for (let c = 0; c < 3; ++c) for (let i = 0; i < V; ++i) out[3 * i + c] = (w[c * V + i] + (ref ? ref[3 * i + c] : 0)) >>> 0;
  return out;
}

function sequence(raw, at, n) {
  const w = fromBytePlanes(raw, at, n);
  for (let i = 1; i < n; ++i) w[i] = (w[i] + w[i - 1]) >>> 0;
  return w;
}

const asF32 = (u) => new Float32Array(u.buffer, u.byteOffset, u.length);

// §11.4.3 and §11.4.4: prototype p's arrays (Float32Array / Uint32Array, vertex-major).
async function decodePrototype(mesh, p) {
  const cache = (mesh.protoCache ??= new Map());
  if (cache.has(p)) return cache.get(p);
  const ix = mesh.index, pr = ix.prototypes[p], V = pr.V, S = pr.S;
  const what = `track ${mesh.track} prototype ${p}`;
  const raw = await readChunk(mesh.clip, mesh.chunks[1].get(p).id);
  let at = 0;
  const positions = vec3Array(raw, at, V, null); at += 12 * V;
  const normals = pr.flags & 1 ? vec3Array(raw, at, V, null) : null; if (normals) at += 12 * V;
  const colours = pr.flags & 2 ? vec3Array(raw, at, V, null) : null; if (colours) at += 12 * V;
  let uvs = null;
  if (pr.flags & 8) {
    const w = fromBytePlanes(raw, at, 2 * V);
    uvs = new Uint32Array(2 * V);
    for (let c = 0; c < 2; ++c) for (let i = 0; i < V; ++i) uvs[2 * i + c] = w[c * V + i];
    at += 8 * V;
  }
  const times = sequence(raw, at, S); at += 4 * S;
  const states = [];
  for (let k = 0; k < S; ++k) { states.push(vec3Array(raw, at, V, k ? states[k - 1] : positions)); at += 12 * V; }
  const checkCoords = (u, name) => {
    for (const x of asF32(u)) if (!Number.isFinite(x) || Math.abs(x) > MAX_COORD) fail(E.meshValue, `${what}: ${name} not finite or beyond 1e12`);
  };
  checkCoords(positions, 'a position');
  if (normals) {
    const n = asF32(normals);
    for (let i = 0; i < V; ++i) {
      if (![0, 1, 2].every((c) => Number.isFinite(n[3 * i + c])) || (n[3 * i] === 0 && n[3 * i + 1] === 0 && n[3 * i + 2] === 0)) {
        fail(E.meshValue, `${what}: normal ${i}`);
      }
    }
  }
  if (colours && !asF32(colours).every((x) => x >= 0 && x <= 1)) fail(E.meshValue, `${what}: a colour outside [0, 1]`);
  if (uvs && !asF32(uvs).every(Number.isFinite)) fail(E.meshValue, `${what}: a UV not finite`);
  const tf = asF32(times);
  for (let k = 0; k < S; ++k) if (!Number.isFinite(tf[k]) || tf[k] < 0 || (k && !(tf[k] > tf[k - 1]))) fail(E.meshValue, `${what}: state time ${k}`);
  states.forEach((s) => checkCoords(s, 'a state position'));
  // Triangles: p's own chunk or the one of the prototype it draws.
  const q = pr.trianglesOf, qr = ix.prototypes[q];
  const traw = await readChunk(mesh.clip, mesh.chunks[2].get(q).id);
  const indices = sequence(traw, 0, 3 * qr.T);
  for (let i = 0; i < indices.length; ++i) if (indices[i] >= V) fail(E.meshIndex, `${what}: vertex index ${indices[i]} of ${V}`);
  const materials = qr.flags & 4 ? sequence(traw, 12 * qr.T, qr.T) : null;
  if (materials) for (const m of materials) if (m !== NONE && m >= ix.materials.length) fail(E.meshIndex, `${what}: triangle material ${m}`);
  const out = { V, T: qr.T, positions, normals, colours, uvs, times, states, indices, materials };
  cache.set(p, out);
  return out;
}

// §11.4.5: object o's transforms (12N floats, row-major 3 × 4 each) and its triangles (null: all).
async function decodeObject(mesh, o) {
  const ob = mesh.index.objects[o], N = ob.N, T = mesh.index.prototypes[ob.prototype].T;
  const what = `track ${mesh.track} object ${o}`;
  const raw = await readChunk(mesh.clip, mesh.chunks[3].get(o).id);
  const all = (ob.flags & 1) !== 0;
  const w = fromBytePlanes(raw, 0, 12 * N);
  const transforms = new Uint32Array(12 * N);
  for (let e = 0; e < 12; ++e) {
    for (let f = 0; f < N; ++f) transforms[12 * f + e] = (w[e * N + f] + (f ? transforms[12 * (f - 1) + e] : 0)) >>> 0;
  }
  if (!asF32(transforms).every(Number.isFinite)) fail(E.meshValue, `${what}: a transform element not finite`);
  let subset = null;
  if (!all) {
    const v = new DataView(raw.buffer, raw.byteOffset, raw.byteLength);
    const R = v.getUint32(48 * N, true);
    if (raw.length !== 48 * N + 4 + 8 * R) fail(E.meshChunk, `${what}: ${raw.length} bytes for ${R} runs`);
    const gaps = fromBytePlanes(raw, 48 * N + 4, R), lengths = fromBytePlanes(raw, 48 * N + 4 + 4 * R, R);
    subset = new Uint32Array(ob.K);
    let s = 0, k = 0;
    for (let r = 0; r < R; ++r) {
      if (lengths[r] < 1 || (r && gaps[r] < 1)) fail(E.meshIndex, `${what}: run ${r}`);
      s += gaps[r];
      if (s + lengths[r] > T || k + lengths[r] > ob.K) fail(E.meshIndex, `${what}: run ${r} past the triangles`);
      for (let i = 0; i < lengths[r]; ++i) subset[k++] = s + i;
      s += lengths[r];
    }
    if (k !== ob.K) fail(E.meshIndex, `${what}: runs of ${k} triangles, expected ${ob.K}`);
  } else if (raw.length !== 48 * N) fail(E.meshChunk, `${what}: ${raw.length} bytes, expected ${48 * N}`);
  return { prototype: ob.prototype, material: ob.material, all, transforms, subset };
}

// §11.4.6: texture x's RGBA8 texels, rows from the top.
async function decodeTexture(mesh, x) {
  const cache = (mesh.textureCache ??= new Map());
  if (cache.has(x)) return cache.get(x);
  const tx = mesh.index.textures[x], W = tx.W, H = tx.H;
  const raw = await readChunk(mesh.clip, mesh.chunks[4].get(x).id);
  let out;
  if (tx.coding === 1) out = raw.slice();
  else {
    out = new Uint8Array(4 * W * H);
    for (let c = 0; c < 4; ++c) {
      const plane = raw.subarray(c * W * H);
      const at = (px, py) => out[4 * (py * W + px) + c];
      for (let y = 0; y < H; ++y) {
        for (let xx = 0; xx < W; ++xx) {
          let pred;
          if (!xx && !y) pred = 0;
          else if (!y) pred = at(xx - 1, 0);
          else if (!xx) pred = at(0, y - 1);
          else {
            const a = at(xx - 1, y), b = at(xx, y - 1), cc = at(xx - 1, y - 1);
            pred = cc >= Math.max(a, b) ? Math.min(a, b) : cc <= Math.min(a, b) ? Math.max(a, b) : a + b - cc;
          }
          out[4 * (y * W + xx) + c] = (plane[y * W + xx] + pred) & 255;
        }
      }
    }
  }
  const tex = { W, H, texels: out };
  cache.set(x, tex);
  return tex;
}

const hex = (x) => x.toString(16).padStart(16, '0');

function hashWords(codecs, arrays) {
  const n = arrays.reduce((s, a) => s + (a ? a.length : 0), 0);
  const all = new Uint32Array(n);
  let o = 0;
  for (const a of arrays) if (a) { all.set(a, o); o += a.length; }
  return hex(codecs.xxh3(new Uint8Array(all.buffer)));
}

// §11.4.7: the lines calf-verify --decode prints for mesh track t (none when it has no index).
export async function meshLines(clip, t) {
  const mesh = await openMesh(clip, t);
  if (!mesh) return [];
  const lines = [], ix = mesh.index;
  for (let p = 0; p < ix.prototypes.length; ++p) {
    const d = await mesh.prototype(p);
    lines.push(`track ${t} prototype ${p} ${hashWords(clip.codecs, [d.positions, d.normals, d.colours, d.indices, d.materials, d.times, ...d.states, d.uvs])}`);
  }
  for (let o = 0; o < ix.objects.length; ++o) {
    const d = await mesh.object(o);
    lines.push(`track ${t} object ${o} ${hashWords(clip.codecs, [Uint32Array.of(d.prototype, d.material, d.all ? 1 : 0), d.transforms, d.subset])}`);
  }
  for (let x = 0; x < ix.textures.length; ++x) {
    const d = await mesh.texture(x);
    const words = new Uint32Array(2 + d.W * d.H);
    words[0] = d.W; words[1] = d.H;
    new Uint8Array(words.buffer).set(d.texels, 8);
    lines.push(`track ${t} texture ${x} ${hashWords(clip.codecs, [words])}`);
  }
  return lines;
}
