// The conformance hash lines of a clip (format/SPEC.md §14), as `calf-verify --decode` prints
// them, from the page's decoder: shared by web/test/conformance.mjs (node, where AV1 colour goes
// through the WebAssembly decoder) and web/test/av1.mjs (the page in Chromium: WebCodecs and the
// WebAssembly decoder).
import { openClip, bytesSource, readChunk } from './container.js';
import { openLightfield, closeLightfield, decodeFaceFrames, faceHash } from './lightfield.js';
import { tilesLines } from './tiles.js';
import { meshLines } from './mesh.js';
import { CalfError } from './errors.js';

// The lines calf-verify --decode prints for a clip's lightfield tracks, and the problems. With
// `tamper`, every chunk's raw bytes are cached first and tamper(clip) may change them.
export async function decodeLines(bytes, codecs, tamper = null) {
  const clip = await openClip(bytesSource(bytes), codecs);
  if (tamper) clip.chunkCache = new Map();
  for (let i = 0; i < clip.chunks.length; ++i) {  // every hash and scheme
    const raw = await readChunk(clip, i);
    if (tamper) clip.chunkCache.set(i, raw.slice());
  }
  if (tamper) tamper(clip);
  const lines = [], problems = [];
  for (let t = 0; t < clip.tracks.length; ++t) {
    if (clip.tracks[t].kind === 2) lines.push(...await tilesLines(clip, t));
    if (clip.tracks[t].kind === 4) lines.push(...await meshLines(clip, t));
    if (clip.tracks[t].kind !== 1) continue;
    const lf = await openLightfield(clip, t);
    const h = lf.header;
    const hashes = new Map();
    for (let v = 0; v < h.view_count; ++v) {
      if (!lf.views[v]) { problems.push(lf.viewProblems[v].message); continue; }
      for (let f = 0; f < 6; ++f) {
        try {
          await decodeFaceFrames(lf, v, f, (n, colour, depth, material, coverage) => {
            hashes.set(`${n}/${v}/${f}`, faceHash(codecs, colour, depth, material, coverage));
          }, null, { coverage: true });
        } catch (e) {
          if (!(e instanceof CalfError)) throw e;
          problems.push(e.message);
        }
      }
    }
    closeLightfield(lf);
    for (let n = 0; n < h.frame_count; ++n) {
      for (let v = 0; v < h.view_count; ++v) {
        for (let f = 0; f < 6; ++f) {
          const x = hashes.get(`${n}/${v}/${f}`);
          if (x) lines.push(`track ${t} frame ${n} view ${v} face ${f} ${x}`);
        }
      }
    }
  }
  return { lines, problems };
}
