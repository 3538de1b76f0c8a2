// The share of a clip that the streaming plan (web/src/stream.js) fetches for every cell of one
// face of one view along all frames: chunks and stored bytes, against the clip's size.
//
//   node web/tools/plan_share.mjs CLIP.calf [VIEW FACE]      (default view 0, face 4)
import { readFileSync } from 'node:fs';
import { loadCodecs } from '../test/node_codecs.mjs';
import { openClip, bytesSource } from '../src/container.js';
import { openLightfield } from '../src/lightfield.js';
import { planFrame, prefetch, cachedT } from '../src/stream.js';

const [path, view = 0, face = 4] = process.argv.slice(2);
const loaded = await loadCodecs();
if (!loaded.codecs) throw new Error(loaded.missing);
const bytes = new Uint8Array(readFileSync(path));
const clip = await openClip(bytesSource(bytes), loaded.codecs);
const t = clip.tracks.findIndex((x) => x.kind === 1);
const lf = await openLightfield(clip, t);
const needed = Array.from({ length: lf.cells.count }, (_, cell) => ({ view: Number(view), face: Number(face), cell }));
const planned = new Set();
for (let n = 0; n < lf.header.frame_count; ++n) {
  // The t chunks first (as a player does), so that a next keyframe is planned only where t ≠ 0.
  await prefetch(clip, planFrame(lf, n, needed).filter((id) => clip.chunks[id].stream === 4));
  for (const id of planFrame(lf, n, needed, cachedT(lf, n))) planned.add(id);
}
const stored = [...planned].reduce((s, id) => s + clip.chunks[id].storedSize, 0);
const directory = 64 + bytes.length - clip.directoryOffset;
const h = lf.header;
console.log(`${path}: ${h.view_count} views, ${h.face_size}² faces, ${h.frame_count} frames; view ${view} face ${face}, all frames: ` +
  `${planned.size} of ${clip.chunks.length} chunks, ${stored} bytes + ${directory} of header and directory = ` +
  `${(100 * (stored + directory) / bytes.length).toFixed(2)} % of ${bytes.length}`);
