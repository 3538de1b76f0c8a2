// Joins the tracks of several clips into one container 1.0 file (format/SPEC.md §2 – §7: plain
// directory, no metadata): the tracks in the order given, each chunk's stored bytes, hash and
// keys copied as they are, its track id renumbered. web.match_raster uses it to make one clip
// with a tiles and a mesh track from calf-encode's two single-track clips.
//
//   node web/tools/join_clips.mjs OUT.calf IN.calf...
import { readFileSync, writeFileSync, renameSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { openClip, bytesSource } from '../src/container.js';
import { loadCodecs } from '../test/node_codecs.mjs';

const IDENTIFIER = [0xab, 0x43, 0x41, 0x4c, 0x46, 0x20, 0x31, 0xbb, 0x0d, 0x0a, 0x1a, 0x0a];
const align16 = (x) => Math.ceil(x / 16) * 16;

// inputs: the files' bytes; codecs: loadCodecs()'s. Returns the joined file's bytes.
export async function joinClips(inputs, codecs) {
  const tracks = [], chunks = [];
  for (const bytes of inputs) {
    const clip = await openClip(bytesSource(bytes), codecs);
    const base = tracks.length;
    tracks.push(...clip.tracks);
    for (const c of clip.chunks) {
      const stored = bytes.subarray(c.offset, c.offset + c.storedSize);
      chunks.push({ ...c, track: base + c.track, stored });
    }
  }
  let at = 64;
  for (const c of chunks) { c.newOffset = at; at = align16(at + c.stored.length); }
  const dirOffset = at;
  const dirSize = 4 + tracks.reduce((s, t) => s + 8 + t.blob.length, 0) + 64 * chunks.length + 8;
  const out = new Uint8Array(dirOffset + dirSize);
  const v = new DataView(out.buffer);
  out.set(IDENTIFIER, 0);
  v.setUint16(12, 1, true);  // version 1.0, no feature bits
  v.setBigUint64(24, BigInt(out.length), true);
  v.setBigUint64(32, BigInt(dirOffset), true);
  v.setBigUint64(40, BigInt(dirSize), true);
  v.setUint32(48, chunks.length, true);
  v.setUint32(52, tracks.length, true);
  v.setBigUint64(56, codecs.xxh3(out.subarray(0, 56)), true);
  for (const c of chunks) out.set(c.stored, c.newOffset);
  let p = dirOffset + 4;  // metadata_count 0
  for (const t of tracks) {
    v.setUint16(p, t.kind, true); v.setUint16(p + 2, t.flags, true); v.setUint32(p + 4, t.blob.length, true);
    out.set(t.blob, p + 8);
    p += 8 + t.blob.length;
  }
  for (const c of chunks) {
    v.setBigUint64(p, BigInt(c.newOffset), true); v.setBigUint64(p + 8, BigInt(c.stored.length), true);
    v.setBigUint64(p + 16, BigInt(c.rawSize), true); v.setBigUint64(p + 24, c.hash, true);
    v.setUint16(p + 32, c.compression, true); v.setUint16(p + 34, c.flags, true);
    v.setUint16(p + 36, c.track, true); v.setUint16(p + 38, c.stream, true);
    [c.view, c.face, c.region, c.layer, c.firstFrame, c.frameCount].forEach((x, k) => v.setUint32(p + 40 + 4 * k, x, true));
    p += 64;
  }
  v.setBigUint64(p, codecs.xxh3(out.subarray(dirOffset, p)), true);
  return out;
}

if (process.argv[1] === fileURLToPath(import.meta.url)) {
  const [outPath, ...inPaths] = process.argv.slice(2);
  const { codecs, missing } = await loadCodecs();
  if (!codecs) { console.error(`join_clips: ${missing}`); process.exit(1); }
  const bytes = await joinClips(inPaths.map((p) => new Uint8Array(readFileSync(p))), codecs);
  writeFileSync(`${outPath}.tmp`, bytes);
  renameSync(`${outPath}.tmp`, outPath);
}
