// The streaming reader (web/src/stream.js) against a local server with range requests
// (web/test/range_server.py): the clip opens with two requests; per frame the plan for one
// face's cells fetches only those chunks, never one twice, and they decode to the face's hash
// lines with no other read (coverage chunks only when the plan asks for coverage), and each
// frame decoded alone (`{ from: n, to: n + 1 }`, as the page decodes a pose's frame) gives its
// line too; two prefetches of the same chunks at once request each chunk once (counted in the
// server's log, and by chunkFetchCounts from the reader's own record); a trimmed cache keeps what
// it is told to and fetches only what it dropped; a server without range support gives one
// notice and the whole clip.
//
//   node web/test/streaming.mjs
import { spawn } from 'node:child_process';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { createInterface } from 'node:readline';
import { ROOT, loadCodecs } from './node_codecs.mjs';
import { openClip } from '../src/container.js';
import { openLightfield, decodeFaceFrames, faceHash } from '../src/lightfield.js';
import { httpSource, planFrame, prefetch, cachedT, chunkFetchCounts, trimCache } from '../src/stream.js';

const DIR = join(ROOT, 'tests/conformance/lightfield');
const problems = [];
const check = (ok, what) => { if (!ok) problems.push(what); };

// The server's log: one `GET PATH RANGE BYTES` line a request.
async function startServer(args) {
  const child = spawn('/usr/bin/python3', [join(ROOT, 'web/test/range_server.py'), DIR, ...args], { stdio: ['ignore', 'pipe', 'pipe'] });
  child.log = [];
  createInterface({ input: child.stderr }).on('line', (l) => child.log.push(l));
  const line = await new Promise((resolve, reject) => {
    createInterface({ input: child.stdout }).once('line', resolve);
    child.once('exit', (code) => reject(new Error(`range_server exited with ${code}`)));
  });
  return { child, base: `http://127.0.0.1:${line.split(' ')[1]}` };
}

// Streams the cells of one face frame by frame, then decodes the face from the cache alone.
async function streamFace(codecs, base, name, view, face, coverage = false) {
  const source = await httpSource(`${base}/${name}.calf`);
  const clip = await openClip(source, codecs);
  const openRequests = source.stats.requests;
  const t = clip.tracks.findIndex((x) => x.kind === 1);
  const lf = await openLightfield(clip, t);
  const needed = Array.from({ length: lf.cells.count }, (_, cell) => ({ view, face, cell }));
  const fetched = new Set();
  let twice = 0;
  for (let n = 0; n < lf.header.frame_count; ++n) {
    // t chunks first, so that the plan knows whether the next keyframe is needed.
    const ids = planFrame(lf, n, needed, cachedT(lf, n), { coverage });
    for (const id of await prefetch(clip, ids.filter((id) => clip.chunks[id].stream === 4))) twice += fetched.has(id) ? 1 : (fetched.add(id), 0);
    const plan = planFrame(lf, n, needed, cachedT(lf, n), { coverage });
    const plain = planFrame(lf, n, needed, cachedT(lf, n));
    check(!plain.some((id) => clip.chunks[id].stream === 5), `${name} frame ${n}: a plan without coverage holds a coverage chunk`);
    if (coverage) check(plan.some((id) => clip.chunks[id].stream === 5), `${name} frame ${n}: a plan with coverage holds no coverage chunk`);
    for (const id of await prefetch(clip, plan)) twice += fetched.has(id) ? 1 : (fetched.add(id), 0);
  }
  const bytes = source.stats.bytes;
  clip.source = { size: source.size, read: async (o, l) => { throw new Error(`read of ${l} bytes at ${o} after streaming`); } };
  const lines = [];
  try {
    await decodeFaceFrames(lf, view, face, (n, c, d, m, cov) => {
      lines.push(`track ${t} frame ${n} view ${view} face ${face} ${faceHash(codecs, c, d, m, cov)}`);
    }, null, { coverage });
  } catch (e) {
    problems.push(`${name}: ${e.message}`);
  }
  const want = readFileSync(join(DIR, `${name}.hashes`), 'utf8').split('\n').filter((l) => l.includes(` view ${view} face ${face} `));
  check(lines.join('\n') === want.join('\n'), `${name} view ${view} face ${face}: streamed decode differs from the .hashes lines`);
  // Each frame alone, from the cache.
  for (let n = 0; n < lf.header.frame_count; ++n) {
    const alone = [];
    try {
      await decodeFaceFrames(lf, view, face, (m, c, d, mat, cov) => {
        alone.push(`track ${t} frame ${m} view ${view} face ${face} ${faceHash(codecs, c, d, mat, cov)}`);
      }, null, { coverage, from: n, to: n + 1 });
    } catch (e) {
      problems.push(`${name} frame ${n} alone: ${e.message}`);
    }
    check(alone.length === 1 && alone[0] === want[n], `${name} view ${view} face ${face} frame ${n} decoded alone: '${alone}' against '${want[n]}'`);
  }
  check(openRequests <= 2, `${name}: ${openRequests} requests to open`);
  check(twice === 0, `${name}: ${twice} chunks fetched twice`);
  check(bytes < source.size, `${name}: fetched ${bytes} of ${source.size} bytes`);
  console.log(`${name} view ${view} face ${face}: ${openRequests} requests to open, ${source.stats.requests} in all, ` +
    `${bytes} of ${source.size} bytes (${(100 * bytes / source.size).toFixed(1)} %; header and directory ${64 + source.size - clip.directoryOffset}), ` +
    `${fetched.size} of ${clip.chunks.length} chunks, ${lines.length} frames as .hashes`);
  return source;
}

const loaded = await loadCodecs();
if (!loaded.codecs) {
  console.log(`web streaming: skipped: ${loaded.missing}`);
  process.exit(process.env.CI === 'true' ? 1 : 77);
}
const { codecs } = loaded;
const ranged = await startServer([]);
const plain = await startServer(['--no-range']);
try {
  await streamFace(codecs, ranged.base, 'crafted_bc7_raw16_mat', 0, 4);
  await streamFace(codecs, ranged.base, 'bc1_raw16_groups', 0, 1);
  await streamFace(codecs, ranged.base, 'bc6h_raw16_lzma2', 0, 0);
  await streamFace(codecs, ranged.base, 'coverage_bc1_pred16m', 1, 2, true);
  // Two prefetches of overlapping chunk sets at once: each chunk requested once.
  {
    const url = `${ranged.base}/crafted_bc7_raw16_mat.calf`, first = ranged.child.log.length;
    const source = await httpSource(url);
    const clip = await openClip(source, codecs);
    const lt = clip.tracks.findIndex((x) => x.kind === 1);
    const ids = clip.chunks.filter((c) => c.track === lt && c.stream >= 1 && c.stream <= 4 && c.view === 0 && c.face === 2).map((c) => c.id);
    check(ids.length > 2, `${ids.length} chunks of view 0 face 2`);
    const half = ids.slice(0, Math.ceil(ids.length / 2));
    await Promise.all([prefetch(clip, ids), prefetch(clip, half), prefetch(clip, ids)]);
    await new Promise((r) => setTimeout(r, 200));  // the server's last log lines
    const fromLog = new Map();
    for (const line of ranged.child.log.slice(first)) {
      const m = /^GET \/crafted_bc7_raw16_mat\.calf bytes=(\d+)-(\d+) /.exec(line);
      if (!m) continue;
      const start = Number(m[1]), end = Number(m[2]) + 1;
      for (const c of clip.chunks) if (c.offset >= start && c.offset + c.storedSize <= end) fromLog.set(c.id, (fromLog.get(c.id) ?? 0) + 1);
    }
    const counts = chunkFetchCounts(clip, source), requests = source.stats.requests - 2;
    check(ids.every((id) => fromLog.get(id) === 1), `overlapping prefetches: the server's log counts ${ids.map((id) => fromLog.get(id) ?? 0)} requests per chunk`);
    check(ids.every((id) => counts.get(id) === 1) && counts.size === ids.length, `overlapping prefetches: chunkFetchCounts ${[...counts]}`);
    // A trimmed cache: the kept chunk stays, the others are fetched again, once.
    const keep = ids[ids.length - 1];
    const dropped = trimCache(clip, 0, new Set([keep]));
    check(dropped === ids.length - 1 && clip.chunkCache.has(keep), `trimCache dropped ${dropped} of ${ids.length}, kept ${clip.chunkCache.has(keep)}`);
    const again = await prefetch(clip, ids);
    check(again.length === ids.length - 1 && !again.includes(keep), `after the trim ${again.length} chunks fetched again`);
    console.log(`overlapping prefetches: ${ids.length} chunks, ${requests} requests, each chunk once in the server's log; ` +
      `after trimming the cache to one chunk, ${again.length} fetched again`);
  }
  // No range support: one download, one notice, the same pictures.
  const source = await httpSource(`${plain.base}/bc1_raw16_zstd.calf`);
  check(source.notice && source.stats.requests === 1 && source.stats.bytes === source.size,
    `no-range server: ${source.stats.requests} requests, ${source.stats.bytes} bytes, notice '${source.notice}'`);
  const clip = await openClip(source, codecs);
  const lf = await openLightfield(clip, 0);
  const lines = [];
  await decodeFaceFrames(lf, 1, 3, (n, c, d, m) => { lines.push(`track 0 frame ${n} view 1 face 3 ${faceHash(codecs, c, d, m)}`); });
  const want = readFileSync(join(DIR, 'bc1_raw16_zstd.hashes'), 'utf8').split('\n').filter((l) => l.includes(' view 1 face 3 '));
  check(lines.join('\n') === want.join('\n') && source.stats.requests === 1, 'no-range server: decode differs or more requests');
  console.log(`no-range server: ${source.notice}; ${source.stats.requests} request, ${lines.length} frames as .hashes`);
} finally {
  ranged.child.kill();
  plain.child.kill();
}
for (const p of problems) console.log(`web streaming: ${p}`);
console.log(`web streaming: ${problems.length ? 'FAILED' : 'ok'}`);
process.exit(problems.length ? 1 : 0);
