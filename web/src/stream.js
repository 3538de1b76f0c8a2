// Streaming a clip over HTTP (docs/WEB.md): the header and directory with two range requests,
// then only the chunks a frame needs, found from the chunk index alone (format/SPEC.md §11.1.2),
// fetched as few coalesced byte ranges and kept in a cache so that no chunk is fetched twice.
import { STREAM } from './lightfield.js';
import { decodeStored } from './container.js';


// A source over HTTP range requests. When the server answers a range request with the whole
// body (200 instead of 206), the source keeps the body and serves every read from it; `notice`
// then holds one line saying so.
// `stats.ranges` lists each request's [start, end) (the whole file for a server without range
// support), for chunkFetchCounts.
export async function httpSource(url, { fetch: fetchImpl = fetch } = {}) {
  const stats = { requests: 0, bytes: 0, ranges: [] };
  let whole = null, notice = null;
  const get = async (start, end) => {
    ++stats.requests;
    const r = await fetchImpl(url, { headers: { Range: `bytes=${start}-${end - 1}` } });
    if (r.status !== 206 && r.status !== 200) throw new Error(`${url}: HTTP ${r.status}`);
    const body = new Uint8Array(await r.arrayBuffer());
    stats.bytes += body.length;
    stats.ranges.push(r.status === 206 ? [start, start + body.length] : [0, body.length]);
    return { r, body };
  };
  const first = await get(0, 64);
  let size;
  if (first.r.status === 200) {
    whole = first.body;
    size = whole.length;
    notice = `the server ignores range requests: downloaded the whole clip (${size} bytes)`;
  } else {
    const m = /\/(\d+)$/.exec(first.r.headers.get('content-range') ?? '');
    if (!m) throw new Error(`${url}: a 206 answer without the file size in Content-Range`);
    size = Number(m[1]);
  }
  const head = first.body;
  return {
    size, stats, url,
    get notice() { return notice; },
    async read(offset, length) {
      if (whole) return whole.subarray(offset, offset + length);
      if (offset === 0 && length <= head.length) return head.subarray(0, length);
      if (length === 0) return new Uint8Array(0);
      return (await get(offset, offset + length)).body;
    },
  };
}

// The chunk ids lightfield track `lf` needs for frame n of the regions `needed` ([{view, face,
// cell}] or [{view, face, tile}]): per cell its t chunk and the colour chunk of keyframe k_m (the
// one whose frames hold n) and of the next keyframe, which is needed only when t[n] ≠ 0
// (`tValue(view, face, cell)` gives t[n] when the t chunk is at hand, else undefined and the next
// keyframe is planned), and the depth regions overlapping the cell (not with `{ cellTiles: false }`,
// for a caller that names its tiles); per depth region (named, or
// overlapping a cell) the depth chunk whose frames hold n, the material chunk for a view with
// material (not with `{ material: false }`), and with `{ coverage: true }` in a track with
// coverage, the coverage chunk whose frames hold n (§11.1.11; not planned otherwise).
export function planFrame(lf, n, needed, tValue = () => undefined, { coverage = false, material = true, cellTiles = true } = {}) {
  const ids = new Set();
  const list = (stream, v, f, r) => lf.byKey.get(`${stream}/${v}/${f}/${r}`) ?? [];
  const holding = (chunks) => chunks.find((c) => c.firstFrame <= n && n < c.firstFrame + c.frameCount);
  for (const { view, face, cell, tile } of needed) {
    if (!lf.views[view]) continue;
    const streams = material && lf.views[view].hasMaterial ? [STREAM.depth, STREAM.material] : [STREAM.depth];
    if (coverage && lf.hasCoverage) streams.push(STREAM.coverage);
    const addTile = (r) => {
      for (const s of streams) {
        const c = holding(list(s, view, face, r));
        if (c) ids.add(c.id);
      }
    };
    if (tile !== undefined) {
      addTile(tile);
      continue;
    }
    for (const c of list(STREAM.t, view, face, cell)) ids.add(c.id);
    const colour = list(STREAM.colour, view, face, cell);
    const key = holding(colour);
    if (key) {
      ids.add(key.id);
      // AV1 colour (§11.1.12): the GOP chunk holding n is all a frame needs.
      const t = lf.av1 ? 0 : tValue(view, face, cell);
      const next = colour.find((c) => c.firstFrame === key.firstFrame + key.frameCount);
      if (next && t !== 0) ids.add(next.id);
    }
    if (!cellTiles) continue;
    const rect = lf.cells.rect(cell), side = lf.tiles.side, per = lf.tiles.per;
    for (let j = Math.floor(rect.y / side); j <= Math.floor((rect.y + rect.h - 1) / side); ++j) {
      for (let i = Math.floor(rect.x / side); i <= Math.floor((rect.x + rect.w - 1) / side); ++i) addTile(j * per + i);
    }
  }
  return [...ids].sort((a, b) => a - b);
}

// Byte ranges covering the chunks `ids` (sorted), neighbours in the file merged when the gap
// between them is at most `gap` bytes: [{start, end, ids}].
export function byteRanges(clip, ids, gap = 0) {
  const ranges = [];
  for (const id of ids) {
    const c = clip.chunks[id];
    const last = ranges[ranges.length - 1];
    if (last && c.offset - last.end <= gap) {
      last.end = c.offset + c.storedSize;
      last.ids.push(id);
    } else {
      ranges.push({ start: c.offset, end: c.offset + c.storedSize, ids: [id] });
    }
  }
  return ranges;
}

// Fetches the chunks `ids` that are neither cached nor being fetched (one request per coalesced
// range), checks each one's hash, decompresses it and caches its raw bytes in clip.chunkCache,
// which container.readChunk consults first; waits for those another call is fetching, so that
// overlapping calls (a prefetch running while a frame asks) never request a chunk twice.
// Returns the ids it fetched itself.
export async function prefetch(clip, ids, { gap = 0 } = {}) {
  clip.chunkCache ??= new Map();
  clip.chunkPending ??= new Map();
  const others = new Set(), missing = [];
  for (const id of ids) {
    if (clip.chunkCache.has(id)) continue;
    if (clip.chunkPending.has(id)) others.add(clip.chunkPending.get(id));
    else missing.push(id);
  }
  const run = (async () => {
    for (const r of byteRanges(clip, missing, gap)) {
      const bytes = await clip.source.read(r.start, r.end - r.start);
      for (const id of r.ids) {
        const c = clip.chunks[id];
        const stored = bytes.subarray(c.offset - r.start, c.offset - r.start + c.storedSize);
        clip.chunkCache.set(id, await decodeStored(clip, c, stored));
      }
    }
  })();
  for (const id of missing) clip.chunkPending.set(id, run);
  try {
    await run;
  } finally {
    for (const id of missing) clip.chunkPending.delete(id);
  }
  await Promise.all(others);
  return missing;
}

// How many requests of `source` (an httpSource) covered each chunk: Map id -> count, chunks
// never fetched left out.
export function chunkFetchCounts(clip, source) {
  const counts = new Map();
  const byOffset = clip.chunks.slice().sort((a, b) => a.offset - b.offset);
  for (const [start, end] of source.stats.ranges) {
    let lo = 0, hi = byOffset.length;
    while (lo < hi) { const mid = (lo + hi) >> 1; if (byOffset[mid].offset < start) lo = mid + 1; else hi = mid; }
    for (let i = lo; i < byOffset.length && byOffset[i].offset + byOffset[i].storedSize <= end; ++i) {
      counts.set(byOffset[i].id, (counts.get(byOffset[i].id) ?? 0) + 1);
    }
  }
  return counts;
}

// Drops cached chunks, the least recently cached or used first (touchChunk), until the cache
// holds at most maxBytes raw bytes; the ids in `keep` stay. Returns how many it dropped.
export function trimCache(clip, maxBytes, keep = new Set()) {
  const cache = clip.chunkCache;
  if (!cache) return 0;
  let total = 0;
  for (const raw of cache.values()) total += raw.length;
  let dropped = 0;
  for (const [id, raw] of cache) {
    if (total <= maxBytes) break;
    if (keep.has(id)) continue;
    cache.delete(id);
    total -= raw.length;
    ++dropped;
  }
  return dropped;
}

// Marks a cached chunk as just used (trimCache drops it last).
export function touchChunk(clip, id) {
  const raw = clip.chunkCache?.get(id);
  if (raw) { clip.chunkCache.delete(id); clip.chunkCache.set(id, raw); }
}


// The overlay's rate: bytes fetched per second over about the last second, against what playing
// the whole clip takes (its size over its duration, `seconds`). Returns () => the text.
export function rateMeter(source, seconds) {
  const samples = [];
  const kib = (x) => `${(x / 1024).toFixed(1)} KiB/s`;
  return () => {
    const now = performance.now();
    samples.push({ now, bytes: source.stats.bytes });
    while (samples.length > 2 && now - samples[1].now >= 1000) samples.shift();
    const span = (now - samples[0].now) / 1000;
    const rate = span > 0 ? (source.stats.bytes - samples[0].bytes) / span : 0;
    return `${kib(rate)} fetched against the clip's ${kib(source.size / seconds)}`;
  };
}

// The overlay's part on bytes: fetched, their share of the clip, requests, and rate() (a
// rateMeter's); for a local file (source.local), its size.
export function fetched(source, rate) {
  if (source.local) return `a local file of ${source.size} bytes`;
  return `${source.stats.bytes} of ${source.size} bytes fetched (${(100 * source.stats.bytes / source.size).toFixed(1)} %, ` +
    `${source.stats.requests} requests), ${rate()}`;
}

// tValue for planFrame from the t chunks already in clip.chunkCache (SPEC §11.1.4).
export function cachedT(lf, n) {
  return (view, face, cell) => {
    const c = (lf.byKey.get(`${STREAM.t}/${view}/${face}/${cell}`) ?? [])[0];
    const raw = c && lf.clip.chunkCache?.get(c.id);
    if (!raw || raw.length < 4) return undefined;
    const nk = raw[0] | (raw[1] << 8) | (raw[2] << 16) | (raw[3] << 24);
    return raw[4 + 4 * nk + n];
  };
}
