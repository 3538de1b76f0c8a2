// The page's lightfield player: calf-play's GL render (raymarch.js: the native ray-march shader,
// its view selection and march range) of a clip opened by URL over range requests. Only the
// cells and depth regions the pose's eye can see (culling.js, the native decoder's culling) of the
// active views are fetched and decoded, for the pose's frame; the same cells' chunks of the next
// frames are prefetched; a face is uploaded when a pose needs another frame or new cells of it.
// A clip with a coverage stream (SPEC §11.1.11) has its coverage fetched, decoded and uploaded
// with the depth regions, as calf-play's GL renderer reads it whatever its coverage options say.
import { openClip } from './container.js';
import { openLightfield, closeLightfield, decodeFaceFrames, parseTimeline, bcBlocks, STREAM } from './lightfield.js';
import { readChunk } from './container.js';
import { E, fail } from './errors.js';
import { cachedT, chunkFetchCounts, fetched, httpSource, planFrame, prefetch, rateMeter, touchChunk, trimCache } from './stream.js';
import { makeCodecs } from './codecs.js';
import { bcUpload, cpuUpload, makeRaymarcher, marchRange, selectViews, RENDER_DEFAULTS } from './raymarch.js';
import { visibleSets } from './culling.js';
import { openRasterPlayer, rasterTracks } from './raster_player.js';

// How many frames ahead the page fetches (index.html?prefetch=N), and the most raw bytes of
// chunks it keeps cached.
export const PREFETCH_FRAMES = 2;
export const CACHE_BYTES = 256 * 1024 * 1024;

// frame_at_time (capture/src/eye_path.cc).
export function frameAtTime(seconds, fps, frameCount) {
  if (!(seconds > 0)) return 0;
  return Math.min(Math.floor(seconds * fps + 1e-9), frameCount - 1);
}

// deps: the npm modules ({hashWasm, fzstd, xz}); status(text) shows one line.
// The canvas as 8-bit RGB rows, top row first (as calf-play's PNG frames).
export function canvasRgb(gl, canvas) {
  const W = canvas.width, H = canvas.height, px = new Uint8Array(4 * W * H);
  gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE, px);
  const rgb = new Uint8Array(3 * W * H);
  for (let y = 0; y < H; ++y) {
    for (let x = 0; x < W; ++x) {
      const s = 4 * ((H - 1 - y) * W + x), d = 3 * (y * W + x);
      rgb[d] = px[s]; rgb[d + 1] = px[s + 1]; rgb[d + 2] = px[s + 2];
    }
  }
  return rgb;
}

// The texels of decoded coverage (lightfield.js: mask and near count a texel) as the native
// coverage texture holds them (lf::coverage_to_gpu): mask low byte, mask high byte, near count,
// far count (16 − near − the mask's cells).
export function coverageGpuBytes(coverage, out, from, to) {
  for (let i = from; i < to; ++i) {
    const mask = coverage[2 * i], near = coverage[2 * i + 1];
    let pop = 0;
    for (let b = mask; b; b &= b - 1) ++pop;
    out[4 * i] = mask & 255; out[4 * i + 1] = mask >> 8; out[4 * i + 2] = near; out[4 * i + 3] = Math.max(0, 16 - near - pop);
  }
}

// The clip: `url` (read with range requests), or `source` (container.js's bytesSource, e.g. a
// local file's bytes; nothing is fetched). deps.render: the render options (RENDER_DEFAULTS by
// default; index.html's renderOptionsFromParams).
export async function openMarchPlayer({ canvas, url, source: given = null, deps, status }) {
  const gl = canvas.getContext('webgl2', { preserveDrawingBuffer: true, antialias: false });
  if (!gl) throw new Error('WebGL2 is not available');
  const codecs = await makeCodecs(deps);
  const source = given ? { ...given, local: true, stats: { requests: 0, bytes: 0, ranges: [] } } : await httpSource(url);
  if (source.notice) status(source.notice);
  const clip = await openClip(source, codecs);
  const t = clip.tracks.findIndex((x) => x.kind === 1);
  if (t < 0) {
    // No lightfield track: its tiles and mesh tracks, drawn as calf-play's rasterisers draw them.
    const tracks = await rasterTracks(clip);
    if (!tracks.length) fail(E.playbackClip, 'the clip has no lightfield, tiles or mesh track (the kinds this page plays)');
    return openRasterPlayer({ gl, canvas, clip, source, status, tracks });
  }
  const lf = await openLightfield(clip, t);
  const h = lf.header, N = h.face_size, F = h.frame_count, fps = h.fps_numerator / h.fps_denominator;
  // BCn colour goes to the GPU as blocks where the browser takes them (the query string's
  // bc=0 turns it off), else it is decoded to RGBA on the CPU.
  const bc = deps.noBc ? null : bcUpload(gl, h.colour_format, N);
  const cpu = cpuUpload(gl, h.colour_format);
  const withCoverage = lf.hasCoverage;
  const options = { ...(deps.render ?? RENDER_DEFAULTS) };
  const renderer = makeRaymarcher(gl, { views: lf.views, faceSize: N, cellSize: h.cell_size, bc, cpu, options, coverage: withCoverage });
  // The C key's coverage mode (calf-play's window: --coverage's mode, else 3).
  const coverageOn = options.coverage || 3;
  // Prefetch: after a frame's own chunks, those of the next `prefetchFrames` frames (wrapping, as
  // the page loops) for the same cells and tiles, in the background; chunks the cache holds
  // beyond `cacheBytes` raw bytes are dropped, least recently used first.
  const prefetchFrames = Math.max(0, Math.floor(deps.prefetchFrames ?? PREFETCH_FRAMES));
  const cacheBytes = deps.cacheBytes ?? CACHE_BYTES;
  const cellInfo = new Map();  // BCn: `view/face/cell` -> { keys, t, slot: [keyframe in slot 0, 1] }
  // Per view: its faces as uploaded, and per face the cells and tiles decoded at `frame` (the
  // others keep an earlier frame's texels, which this pose's rays do not reach).
  const faces = new Map();
  const selection = {};
  const stats = { decodeMs: 0, fetchMs: 0, cellsDecoded: 0, tilesDecoded: 0, prefetched: 0 };
  const running = new Set();  // prefetches in flight
  const rate = rateMeter(source, F / fps);
  const plan = (needed, n) => planFrame(lf, n, needed, cachedT(lf, n), { material: false, cellTiles: false, coverage: withCoverage });
  // Fetches what frame n of the regions `needed` asks for: t chunks first, so that the next
  // colour keyframe is fetched only where t[n] ≠ 0. Returns the chunk ids of the frame.
  async function fetchFrame(needed, n) {
    let got = await prefetch(lf.clip, plan(needed, n).filter((id) => lf.clip.chunks[id].stream === STREAM.t));
    const ids = plan(needed, n);
    got = got.concat(await prefetch(lf.clip, ids));
    return { ids, got };
  }
  // BCn: per cell of `cells` (view v, face), keyframe m (the one whose frames hold `frame`) in
  // slot m % 2 and the next one in the other slot when t ≠ 0 (docs/DECODER.md), and its value in
  // the cell texture.
  async function uploadBc(v, face, cells, frame, values) {
    for (const r of cells) {
      const key = `${v}/${face}/${r}`;
      if (!cellInfo.has(key)) {
        const tc = lf.byKey.get(`${STREAM.t}/${v}/${face}/${r}`)?.[0];
        const what = `track ${lf.track} view ${v} face ${face} cell ${r} t`;
        if (!tc) fail(E.lightfieldChunk, `${what}: no t chunk`);
        cellInfo.set(key, { ...parseTimeline(await readChunk(lf.clip, tc.id), F, what), slot: [-1, -1] });
      }
      const info = cellInfo.get(key), { keys } = info;
      let m = 0;
      while (m + 1 < keys.length && keys[m + 1] <= frame) ++m;
      const w = m + 1 < keys.length ? info.t[frame] : 0;
      for (const i of w ? [m, m + 1] : [m]) {
        if (info.slot[i % 2] === keys[i]) continue;
        const c = (lf.byKey.get(`${STREAM.colour}/${v}/${face}/${r}`) ?? []).find((x) => x.firstFrame === keys[i]);
        const what = `track ${lf.track} view ${v} face ${face} cell ${r} keyframe ${keys[i]}`;
        if (!c) fail(E.lightfieldChunk, `${what}: no colour chunk`);
        const rect = lf.cells.rect(r);
        renderer.uploadBlocks(v, face, i % 2, rect, bcBlocks(await readChunk(lf.clip, c.id), h.colour_format, rect.w, rect.h, what));
        info.slot[i % 2] = keys[i];
      }
      values[r] = ((m % 2) << 8) | w;
    }
    renderer.uploadCells(v, face, values);
  }
  // Decodes frame n of the cells and tiles of view v that `sets` names and that are not decoded
  // at n yet (their chunks fetched), and uploads the faces that changed.
  async function decodeView(v, sets, n) {
    if (!faces.has(v)) {
      const six = (make) => Array.from({ length: 6 }, make);
      faces.set(v, { frame: -1, colour: six(() => new Float32Array(3 * N * N)), depth: six(() => new Uint16Array(N * N)),
        cells: six(() => new Set()), tiles: six(() => new Set()), values: six(() => new Uint32Array(lf.cells.count)),
        coverage: withCoverage ? six(() => new Uint8Array(4 * N * N)) : null });
    }
    const d = faces.get(v);
    if (d.frame !== n) {
      for (let face = 0; face < 6; ++face) { d.cells[face].clear(); d.tiles[face].clear(); }
      d.frame = n;
    }
    for (let face = 0; face < 6; ++face) {
      const only = { cells: new Set([...sets.cells[face]].filter((r) => !d.cells[face].has(r))),
        tiles: new Set([...sets.tiles[face]].filter((r) => !d.tiles[face].has(r))) };
      if (only.cells.size === 0 && only.tiles.size === 0) continue;
      const t0 = performance.now();
      if (bc) await uploadBc(v, face, only.cells, n, d.values[face]);
      const cpu = { cells: bc ? new Set() : only.cells, tiles: only.tiles };
      if (cpu.cells.size || cpu.tiles.size) {
        await decodeFaceFrames(lf, v, face, (m, colour, depth, material, coverage) => {
          for (const r of cpu.cells) {
            const { x, y, w, h: rh } = lf.cells.rect(r);
            for (let j = y; j < y + rh; ++j) d.colour[face].set(colour.subarray(3 * (j * N + x), 3 * (j * N + x + w)), 3 * (j * N + x));
          }
          for (const r of cpu.tiles) {
            const { x, y, w, h: rh } = lf.tiles.rect(r);
            for (let j = y; j < y + rh; ++j) d.depth[face].set(depth.subarray(j * N + x, j * N + x + w), j * N + x);
            if (coverage) for (let j = y; j < y + rh; ++j) coverageGpuBytes(coverage, d.coverage[face], j * N + x, j * N + x + w);
          }
        }, cpu, { material: false, coverage: withCoverage, from: n, to: n + 1 });
      }
      if (withCoverage && cpu.tiles.size) renderer.uploadCoverage(v, face, d.coverage[face]);
      if (bc) { if (cpu.tiles.size) renderer.uploadDepth(v, face, d.depth[face]); }
      else renderer.uploadFace(v, face, d.colour[face], d.depth[face]);
      stats.decodeMs += performance.now() - t0;
      stats.cellsDecoded += only.cells.size;
      stats.tilesDecoded += only.tiles.size;
      for (const r of only.cells) d.cells[face].add(r);
      for (const r of only.tiles) d.tiles[face].add(r);
    }
  }
  // The view volume: the clip's `view_volume` metadata ("x0 y0 z0 x1 y1 z1") where well formed,
  // else the bounds of the usable views' positions (LightfieldRepresentation).
  const volume = (() => {
    const meta = clip.metadata?.find(([k]) => k === 'view_volume');
    const v = meta ? meta[1].trim().split(/\s+/).map(Number) : [];
    if (v.length === 6 && v.every(Number.isFinite) && v[0] <= v[3] && v[1] <= v[4] && v[2] <= v[5]) return { lo: v.slice(0, 3), hi: v.slice(3) };
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (const view of lf.views) {
      if (!view) continue;
      for (let k = 0; k < 3; ++k) { lo[k] = Math.min(lo[k], view.position[k]); hi[k] = Math.max(hi[k], view.position[k]); }
    }
    return { lo, hi };
  })();
  // Playback::inside_view_volume.
  const inside = (p) => [0, 1, 2].every((k) => p[k] >= volume.lo[k] - 1e-9 && p[k] <= volume.hi[k] + 1e-9);
  const selections = new Map();  // the view selection's incumbents, one set per eye
  // The eye's frustum for culling: a camera with an (asymmetric) projection is culled with the
  // symmetric frustum that holds it.
  function cullCamera(camera) {
    const P = camera.projection;
    if (!P) return camera;
    const tx = (1 + Math.abs(P[8])) / P[0], ty = (1 + Math.abs(P[9])) / P[5];
    return { ...camera, fovY: 2 * Math.atan(ty), width: tx, height: ty };
  }
  // Fetches, decodes and uploads what the pose needs; camera: { position, forward, up, fovY
  // (radians), width, height, projection (optional, a WebGL column-major perspective matrix that
  // replaces fovY) }; time in seconds; eye: which incumbent set the view selection keeps.
  async function prepare(camera, time, eye = 0) {
    const frame = frameAtTime(time, fps, F);
    if (!selections.has(eye)) selections.set(eye, {});
    const active = selectViews(lf.views, camera.position, selections.get(eye));
    const { near, far } = marchRange(lf.views, camera.position);
    const sets = visibleSets(lf, cullCamera(camera), near, far, active);
    let visibleCells = 0;
    const needed = [];
    for (const v of active) {
      const vs = sets.get(v);
      for (let face = 0; face < 6; ++face) {
        visibleCells += vs.cells[face].size;
        for (const cell of vs.cells[face]) needed.push({ view: v, face, cell });
        for (const tile of vs.tiles[face]) needed.push({ view: v, face, tile });
      }
    }
    const tf = performance.now();
    const { ids } = await fetchFrame(needed, frame);
    stats.fetchMs += performance.now() - tf;
    for (const id of ids) touchChunk(lf.clip, id);
    trimCache(lf.clip, cacheBytes, new Set(ids));
    for (const v of active) await decodeView(v, sets.get(v), frame);
    const next = [];
    for (let k = 1; k <= prefetchFrames && k < F; ++k) next.push((frame + k) % F);
    if (next.length) {
      const p = (async () => { for (const n of next) stats.prefetched += (await fetchFrame(needed, n)).got.length; })()
        .catch(() => {})  // a chunk that fails here is fetched again, and reported, when a frame needs it
        .finally(() => running.delete(p));
      running.add(p);
    }
    return { frame, active, visibleCells, totalCells: active.length * 6 * lf.cells.count };
  }
  // Resolves when the prefetches in flight are done.
  const settled = async () => { while (running.size) await Promise.all([...running]); };
  // How many requests fetched each chunk (Map id -> count).
  const fetchCounts = () => chunkFetchCounts(lf.clip, source);
  // Draws a prepared pose (synchronous: a WebXR frame draws inside its callback); target:
  // { framebuffer, viewport: { x, y, width, height } } or the whole canvas.
  function draw(camera, prepared, target) {
    if (!target && (canvas.width !== camera.width || canvas.height !== camera.height)) {
      canvas.width = camera.width;
      canvas.height = camera.height;
    }
    const t0 = performance.now();
    renderer.render(camera, prepared.active, target);
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));  // waits for the draw
    return performance.now() - t0;
  }
  // The overlay line of a drawn pose; position: the viewer's.
  function report(prepared, renderMs, position, eyes = 1) {
    const out = inside(position) ? '' : '; the eye is outside the view volume';
    const cov = withCoverage ? `, coverage ${options.coverage ? `mode ${options.coverage}` : 'off'}` : '';
    status(`frame ${prepared.frame}: ${eyes === 2 ? 'two eyes, ' : ''}${prepared.active.length} of ${lf.views.length} views, ${prepared.visibleCells}/${prepared.totalCells} cells, ` +
      `render ${renderMs.toFixed(1)} ms${cov}; ${stats.cellsDecoded} cells decoded (${stats.decodeMs.toFixed(0)} ms), ` +
      `${fetched(source, rate)}${out}`);
    return !out;
  }
  // One pose into the canvas. An error (a damaged chunk, say) is one line in the overlay and is
  // thrown again; nothing is drawn, so the last good frame stays.
  async function renderPose(camera, time) {
    let prepared;
    try {
      prepared = await prepare(camera, time);
    } catch (e) {
      status(e.message.split('\n')[0]);
      throw e;
    }
    const renderMs = draw(camera, prepared);
    const insideVolume = report(prepared, renderMs, camera.position);
    const { frame, active, visibleCells, totalCells } = prepared;
    return { frame, active, renderMs, insideVolume, colourUpload: bc ? bc.name : cpu.name, visibleCells, totalCells, bytes: source.stats.bytes, size: source.size, requests: source.stats.requests };
  }
  const pixels = () => canvasRgb(gl, canvas);
  const views = lf.views.filter((v) => v);
  const startEye = [0, 1, 2].map((k) => views.reduce((s, v) => s + v.position[k], 0) / views.length);
  // The page calls it when another clip replaces this one: its AV1 decoders are closed.
  const close = () => closeLightfield(lf);
  // The window player's C key: coverage off, or back on at its mode; returns the mode now.
  const toggleCoverage = () => (options.coverage = options.coverage ? 0 : coverageOn);
  return { gl, lf, renderPose, prepare, draw, report, pixels, stats, fps, frameCount: F, startEye, volume, inside,
    prefetchFrames, settled, fetchCounts, source, close, options, hasCoverage: withCoverage, toggleCoverage };
}
