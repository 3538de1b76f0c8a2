// The page's lightfield player: calf-play's GL render (raymarch.js: the native ray-march shader,
// its view selection and march range) of a clip opened by URL over range requests. A view's
// faces are decoded on the CPU when the view first becomes active, every frame of them, and a
// frame's faces are uploaded when a pose needs that frame.
import { openClip } from './container.js';
import { openLightfield, decodeFaceFrames } from './lightfield.js';
import { httpSource } from './stream.js';
import { makeCodecs } from './codecs.js';
import { makeRaymarcher, selectViews } from './raymarch.js';

// frame_at_time (format/capture/src/eye_path.cc).
export function frameAtTime(seconds, fps, frameCount) {
  if (!(seconds > 0)) return 0;
  return Math.min(Math.floor(seconds * fps + 1e-9), frameCount - 1);
}

// deps: the npm modules ({hashWasm, fzstd, xz}); status(text) shows one line.
export async function openMarchPlayer({ canvas, url, deps, status }) {
  const gl = canvas.getContext('webgl2', { preserveDrawingBuffer: true, antialias: false });
  if (!gl) throw new Error('WebGL2 is not available');
  const codecs = await makeCodecs(deps);
  const source = await httpSource(url);
  if (source.notice) status(source.notice);
  const clip = await openClip(source, codecs);
  const t = clip.tracks.findIndex((x) => x.kind === 1);
  if (t < 0) throw new Error('the clip has no lightfield track this page can play');
  const lf = await openLightfield(clip, t);
  const h = lf.header, N = h.face_size, F = h.frame_count, fps = h.fps_numerator / h.fps_denominator;
  const renderer = makeRaymarcher(gl, { views: lf.views, faceSize: N, cellSize: h.cell_size });
  const decoded = new Map();  // view -> [frame] -> { colour: [6], depth: [6] }
  const uploaded = new Int32Array(lf.views.length).fill(-1);
  const selection = {};
  const stats = { decodeMs: 0, facesDecoded: 0 };
  async function ensureView(v) {
    if (decoded.has(v)) return decoded.get(v);
    const t0 = performance.now();
    const frames = Array.from({ length: F }, () => ({ colour: [], depth: [] }));
    for (let face = 0; face < 6; ++face) {
      await decodeFaceFrames(lf, v, face, (n, colour, depth) => {
        frames[n].colour[face] = colour.slice();
        frames[n].depth[face] = depth.slice();
      });
      ++stats.facesDecoded;
    }
    stats.decodeMs += performance.now() - t0;
    decoded.set(v, frames);
    return frames;
  }
  // camera: { position, forward, up, fovY (radians), width, height }; time in seconds.
  async function renderPose(camera, time) {
    const frame = frameAtTime(time, fps, F);
    const active = selectViews(lf.views, camera.position, selection);
    for (const v of active) {
      const frames = await ensureView(v);
      if (uploaded[v] === frame) continue;
      for (let face = 0; face < 6; ++face) renderer.uploadFace(v, face, frames[frame].colour[face], frames[frame].depth[face]);
      uploaded[v] = frame;
    }
    if (canvas.width !== camera.width || canvas.height !== camera.height) {
      canvas.width = camera.width;
      canvas.height = camera.height;
    }
    const t0 = performance.now();
    renderer.render(camera, active);
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));  // waits for the draw
    const renderMs = performance.now() - t0;
    status(`frame ${frame}: ${active.length} of ${lf.views.length} views, render ${renderMs.toFixed(1)} ms; ` +
      `${stats.facesDecoded} faces decoded (${stats.decodeMs.toFixed(0)} ms), ${source.stats.bytes} of ${source.size} bytes fetched`);
    return { frame, active, renderMs };
  }
  // The canvas as 8-bit RGB rows, top row first (as calf-play's PNG frames).
  function pixels() {
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
  return { gl, lf, renderPose, pixels, stats, fps };
}
