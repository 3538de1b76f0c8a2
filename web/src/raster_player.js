// The page's player of a clip's tiles and mesh tracks (drawn by raster.js as calf-play's GL
// rasterisers draw them): every chunk of those tracks is fetched (range requests merged across
// padding, hashes checked) and decoded when the clip opens; renderPose draws one pose. Same
// interface as march_player.js's player, so index.html drives either.
import { openTiles } from './tiles.js';
import { openMesh } from './mesh.js';
import { makeRaster, loadMesh, loadTiles } from './raster.js';
import { fetched, prefetch, rateMeter } from './stream.js';
import { canvasRgb, frameAtTime } from './march_player.js';

// The tracks of kind 2 and 4 with a representation (an index chunk), in clip order, every chunk
// fetched (neighbouring chunks in one range request) and decoded; [] if none.
export async function rasterTracks(clip) {
  const ids = clip.chunks.filter((c) => clip.tracks[c.track].kind === 2 || clip.tracks[c.track].kind === 4).map((c) => c.id);
  await prefetch(clip, ids, { gap: 15 });  // chunks apart by their padding only: one request
  const out = [];
  for (let t = 0; t < clip.tracks.length; ++t) {
    const kind = clip.tracks[t].kind;
    if (kind === 2) { const tl = await openTiles(clip, t); if (tl) out.push({ track: t, ...(await loadTiles(tl)) }); }
    if (kind === 4) { const m = await openMesh(clip, t); if (m) out.push({ track: t, ...(await loadMesh(m)) }); }
  }
  return out;
}

export async function openRasterPlayer({ gl, canvas, clip, source, status, tracks }) {
  const raster = makeRaster(gl);
  // The frame count and rate of the first track, as calf-play's Playback (each track then shows
  // min(frame, its last frame)).
  const F = tracks[0].frameCount, h0 = clip.tracks[tracks[0].track].header;
  const fps = h0.fps_numerator / h0.fps_denominator;
  const rate = rateMeter(source, F / fps);
  // The view region (the tracks' union): where the eye starts and what the overlay checks.
  const volume = { min: [Infinity, Infinity, Infinity], max: [-Infinity, -Infinity, -Infinity] };
  for (const t of tracks) {
    for (let k = 0; k < 3; ++k) {
      volume.min[k] = Math.min(volume.min[k], t.index.viewMin[k]);
      volume.max[k] = Math.max(volume.max[k], t.index.viewMax[k]);
    }
  }
  const inside = (p) => [0, 1, 2].every((k) => p[k] >= volume.min[k] && p[k] <= volume.max[k]);
  const startEye = [0, 1, 2].map((k) => (volume.min[k] + volume.max[k]) / 2);
  async function prepare(camera, time) {
    return { frame: frameAtTime(time, fps, F) };
  }
  let figures = [];
  function draw(camera, prepared, target) {
    if (!target && (canvas.width !== camera.width || canvas.height !== camera.height)) {
      canvas.width = camera.width;
      canvas.height = camera.height;
    }
    const t0 = performance.now();
    figures = raster.render(tracks, camera, prepared.frame, target);
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));  // waits for the draw
    return performance.now() - t0;
  }
  function report(prepared, renderMs, position, eyes = 1) {
    const what = tracks.map((t, i) => (t.kind === 'mesh' ? `mesh: ${figures[i]?.triangles ?? 0} triangles` : `tiles: ${t.n} tiles`)).join(', ');
    const out = inside(position) ? '' : '; the eye is outside the view volume';
    status(`frame ${prepared.frame}: ${eyes === 2 ? 'two eyes, ' : ''}${what}, render ${renderMs.toFixed(1)} ms; ` +
      `${fetched(source, rate)}${out}`);
    return !out;
  }
  async function renderPose(camera, time) {
    const prepared = await prepare(camera, time);
    let renderMs;
    try {
      renderMs = draw(camera, prepared);
    } catch (e) {
      status(e.message.split('\n')[0]);
      throw e;
    }
    const insideVolume = report(prepared, renderMs, camera.position);
    return { frame: prepared.frame, renderMs, insideVolume, tracks: tracks.map((t, i) => ({ kind: t.kind, ...figures[i] })),
      bytes: source.stats.bytes, size: source.size, requests: source.stats.requests };
  }
  const pixels = () => canvasRgb(gl, canvas);
  return { gl, renderPose, prepare, draw, report, pixels, fps, frameCount: F, startEye, volume, inside, floatBlend: raster.floatBlend };
}
