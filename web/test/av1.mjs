// AV1 colour (format/SPEC.md §11.1.12) in the page, where WebCodecs decodes it (web.conformance
// checks the WebAssembly back end under node). In headless Chromium:
// - the page's decoder reproduces every hash line of tests/conformance/lightfield/av1_pred16m
//   and av1_hdr_pred16m (10-bit pictures, the HDR curve) with WebCodecs, and of av1_hdr_pred16m
//   with the page's WebAssembly back end too (web/src/hash_lines.js, as web.conformance runs
//   it under node); likewise the 4:4:4 clips av1_444_pred16m and av1_hdr_444_pred16m (the AV1
//   High profile) through the back end the page picks for them (WebCodecs where its
//   VideoDecoder.isConfigSupported takes 'av01.1.04M.08' / '.10'; the line names it);
// - the AV1 clip of the decoder's fuzz corpus decodes without a problem;
// - a temporal unit made garbage (its chunk's bytes changed in the decoder's cache) gives
//   CALF-E301, as calf-verify gives;
// - the page plays the clip along a 4-pose eye path (one per frame), each frame >= MIN_DB against
//   calf-play's GL frame of the same pose (CALF_BIN), with calf-play's active views and cells;
//   av1_hdr_pred16m, av1_444_pred16m and av1_hdr_444_pred16m one pose each, likewise; colour
//   goes up as the native player uploads it (SRGB8_ALPHA8 bytes, RGBA16F halves);
// - the page's AV1 decoders close with the track they decode: a whole clip's decode leaves none
//   open, and a clip the page replaces closes its own;
// - garbage units met while playing give one line in the overlay (CALF-E301) and the last good
//   frame stays on the canvas.
//
//   CALF_BIN=BUILD_DIR node web/test/av1.mjs CHROMIUM
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { ROOT, loadCodecs } from './node_codecs.mjs';
import { startRangeServer, launchChromium, playClip, renderEyePath } from './browser.mjs';
import { readPng, psnr } from './frames.mjs';
import { bytesSource, openClip, readChunk } from '../src/container.js';
import { parseViewIndex } from '../src/lightfield.js';

const MIN_DB = 40;
const chromium = process.argv[2] ?? '/usr/bin/chromium';
const bin = process.env.CALF_BIN;
if (!bin) {
  console.log('web.av1: CALF_BIN (the directory of calf-play) is not set');
  process.exit(1);
}
const clipPath = 'tests/conformance/lightfield/av1_pred16m.calf';
const hdrPath = 'tests/conformance/lightfield/av1_hdr_pred16m.calf';
const hashes = (path) => readFileSync(join(ROOT, path.replace(/\.calf$/, '.hashes')), 'utf8').split('\n').filter(Boolean);
const want = hashes(clipPath), wantHdr = hashes(hdrPath);
const path444 = 'tests/conformance/lightfield/av1_444_pred16m.calf', hdrPath444 = 'tests/conformance/lightfield/av1_hdr_444_pred16m.calf';
const want444 = hashes(path444), wantHdr444 = hashes(hdrPath444);
// The AV1 clip of the decoder's fuzz corpus, which must decode without a problem.
const fuzzClip = 'tests/fuzz/corpus/lightfield_decoder_fuzz/valid_av1_f16_5fr.calf';
const dir = mkdtempSync(join(process.env.CALF_WEB_TMP ?? tmpdir(), 'calf-web-av1-'));

// The eye path: from the views' centre, looking along four directions, at frames 0 … 3 (a
// frame's start time plus a quarter frame).
const { codecs } = await loadCodecs();
const clip = await openClip(bytesSource(new Uint8Array(readFileSync(join(ROOT, clipPath)))), codecs);
const h = clip.tracks[0].header, fps = h.fps_numerator / h.fps_denominator;
const positions = [];
for (const c of clip.chunks) {
  if (c.track === 0 && c.stream === 0) positions.push(parseViewIndex(await readChunk(clip, c.id), 'index', h.material_format).position);
}
const centre = [0, 1, 2].map((k) => positions.reduce((s, p) => s + p[k], 0) / positions.length);
const looks = [[1, 0, 0.3], [-0.2, 0.1, 1], [-1, -0.3, 0], [0.3, 0.2, -1]];
const path = { format: 'calf-eye-path', version: 1, width: 64, height: 48, fov_y_degrees: 70,
  poses: looks.map((f, i) => ({ time: (i + 0.25) / fps, fov_y_degrees: 70, position: centre, forward: f, up: [0, 1, 0] })) };
writeFileSync(join(dir, 'eye_path.json'), JSON.stringify(path));
const played = execFileSync(join(bin, 'calf-play'), [join(ROOT, clipPath), '--headless', '--eye-path', join(dir, 'eye_path.json'), '--out', join(dir, 'play')],
  { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });
const native = [...played.matchAll(/^pose (\d+) frame \d+: (\d+) views, (\d+)\/(\d+) cells, .*render ([0-9.]+) ms/gm)]
  .map((m) => ({ views: Number(m[2]), cells: Number(m[3]), total: Number(m[4]), ms: Number(m[5]) }));
if (native.length !== path.poses.length) throw new Error(`calf-play gave ${native.length} pose lines: ${played}`);
// The HDR clip: one pose (the first's direction at frame 1).
const hdrPose = { format: 'calf-eye-path', version: 1, width: 64, height: 48, fov_y_degrees: 70, poses: [{ ...path.poses[1] }] };
writeFileSync(join(dir, 'hdr_path.json'), JSON.stringify(hdrPose));
// The HDR clip and the 4:4:4 ones, one pose each, in the page that replaces the clip before.
const onePose = [[hdrPath, 'av1_hdr_pred16m', 'RGBA16F'], [path444, 'av1_444_pred16m', 'SRGB8_ALPHA8'], [hdrPath444, 'av1_hdr_444_pred16m', 'RGBA16F']].map(([clip, name, upload]) => {
  const played1 = execFileSync(join(bin, 'calf-play'), [join(ROOT, clip), '--headless', '--eye-path', join(dir, 'hdr_path.json'), '--out', join(dir, `play_${name}`)],
    { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });
  const poses = [...played1.matchAll(/^pose (\d+) frame \d+: (\d+) views, (\d+)\/(\d+) cells, .*render ([0-9.]+) ms/gm)]
    .map((m) => ({ views: Number(m[2]), cells: Number(m[3]), total: Number(m[4]), ms: Number(m[5]) }));
  if (poses.length !== 1) throw new Error(`calf-play gave ${poses.length} pose lines for ${clip}: ${played1}`);
  return { clip, name, upload, native: poses };
});

const { server, port } = await startRangeServer();
const problems = [];
const browser = await launchChromium(chromium);
const t0 = Date.now();
try {
  const held = {};
  const { page, consoleLines, ready, overlay } = await playClip(browser, held, `http://127.0.0.1:${port}`, `/${clipPath}`);
  if (!ready) throw new Error(`the page did not open ${clipPath}: ${overlay} ${consoleLines.join(' | ')}`);
  // The page's decoder, with the page's codecs (WebCodecs for AV1), on the whole clip; then with
  // one unit of the first colour chunk made garbage (every byte 0xff, its size kept).
  const got = await page.evaluate(async ({ url, hdrUrl, fuzzUrl, url444, hdrUrl444 }) => {
    const { decodeLines } = await import('/web/src/hash_lines.js');
    const { wasmAv1 } = await import('/web/src/av1.js');
    const codecs = window.calfPlayer.lf.clip.codecs;
    const bytes = new Uint8Array(await (await fetch(url)).arrayBuffer());
    const hdrBytes = new Uint8Array(await (await fetch(hdrUrl)).arrayBuffer());
    const openBefore = codecs.av1.open();
    let t = performance.now();
    const clean = await decodeLines(bytes, codecs);
    const ms = performance.now() - t;
    t = performance.now();
    const hdr = await decodeLines(hdrBytes, codecs);
    const hdrMs = performance.now() - t;
    t = performance.now();
    const hdrWasm = await decodeLines(hdrBytes, { ...codecs, av1: wasmAv1(window.calfAv1Wasm) });
    const hdrWasmMs = performance.now() - t;
    const high = [];
    for (const [u, bits] of [[url444, 8], [hdrUrl444, 10]]) {
      const b = new Uint8Array(await (await fetch(u)).arrayBuffer());
      const how = await codecs.av1.backEnd(bits, true);
      t = performance.now();
      high.push({ how, ...await decodeLines(b, codecs), ms: performance.now() - t });
    }
    const openAfter = codecs.av1.open();
    let damaged;
    try {
      damaged = await decodeLines(bytes, codecs, (clip) => {
        const c = clip.chunks.find((x) => x.stream === 1 && x.frameCount > 1);
        const raw = clip.chunkCache.get(c.id), v = new DataView(raw.buffer, raw.byteOffset, raw.length);
        const at = 4 + 4 * v.getUint32(0, true) + v.getUint32(4, true);  // unit 1
        raw.fill(0xff, at, at + v.getUint32(8, true));
      });
    } catch (e) {
      damaged = { lines: [], problems: [e.message] };
    }
    const fuzz = await decodeLines(new Uint8Array(await (await fetch(fuzzUrl)).arrayBuffer()), codecs);
    return { clean, ms, hdr, hdrMs, hdrWasm, hdrWasmMs, high, openBefore, openAfter, damaged: damaged.problems[0] ?? null, fuzz: { lines: fuzz.lines.length, problem: fuzz.problems[0] ?? null } };
  }, { url: `/${clipPath}`, hdrUrl: `/${hdrPath}`, fuzzUrl: `/${fuzzClip}`, url444: `/${path444}`, hdrUrl444: `/${hdrPath444}` });
  for (const [name, wanted, result, ms, how] of [['av1_pred16m', want, got.clean, got.ms, 'WebCodecs'], ['av1_hdr_pred16m', wantHdr, got.hdr, got.hdrMs, 'WebCodecs'],
    ['av1_hdr_pred16m', wantHdr, got.hdrWasm, got.hdrWasmMs, 'WebAssembly'],
    ['av1_444_pred16m', want444, got.high[0], got.high[0].ms, got.high[0].how], ['av1_hdr_444_pred16m', wantHdr444, got.high[1], got.high[1].ms, got.high[1].how]]) {
    const diffs = [];
    for (let i = 0; i < Math.max(wanted.length, result.lines.length); ++i) {
      if (wanted[i] !== result.lines[i]) diffs.push(`line ${i + 1}: expected '${wanted[i] ?? ''}', got '${result.lines[i] ?? ''}'`);
    }
    console.log(`web.av1: ${name} in the page's decoder (${how}): ${wanted.length - diffs.length} of ${wanted.length} hash lines reproduced, ` +
      `${ms.toFixed(0)} ms${result.problems.length ? ` (${result.problems[0]})` : ''}`);
    for (const d of diffs.slice(0, 5)) problems.push(`conformance of ${name} (${how}): ${d}`);
    if (result.problems.length) problems.push(`conformance of ${name} (${how}): ${result.problems[0]}`);
  }
  console.log(`web.av1: the page's AV1 decoders open: ${got.openBefore} before the clips' decodes, ${got.openAfter} after`);
  if (got.openAfter !== got.openBefore) problems.push(`the decodes of whole clips left ${got.openAfter - got.openBefore} AV1 decoders open`);
  console.log(`web.av1: ${fuzzClip}: ${got.fuzz.lines} lines, ${got.fuzz.problem ?? 'no problem'}`);
  if (got.fuzz.problem || got.fuzz.lines === 0) problems.push(`${fuzzClip}: ${got.fuzz.lines} lines, ${got.fuzz.problem ?? 'no problem'}`);
  console.log(`web.av1: a garbage temporal unit: ${got.damaged ?? 'no problem'}`);
  if (!got.damaged?.startsWith('CALF-E301 ')) problems.push(`a garbage temporal unit gave ${got.damaged ?? 'no problem'}, not CALF-E301`);

  // Playback against calf-play.
  const frames = [];
  await renderEyePath(page, path, (i, r, rgb) => {
    const png = readPng(join(dir, 'play', `frame_${String(i).padStart(5, '0')}.png`));
    const db = psnr(rgb, png.rgb), n = native[i];
    frames.push(rgb);
    console.log(`web.av1: pose ${i} frame ${r.frame}: ${r.active.length} views, ${r.visibleCells}/${r.totalCells} cells (calf-play ${n.views}, ${n.cells}/${n.total}), ` +
      `${db.toFixed(2)} dB against calf-play; render ${r.renderMs.toFixed(1)} ms (SwiftShader) against calf-play's ${n.ms} ms (llvmpipe)`);
    if (r.frame !== i) problems.push(`pose ${i}: frame ${r.frame}`);
    if (r.active.length !== n.views || r.visibleCells !== n.cells || r.totalCells !== n.total) problems.push(`pose ${i}: views or cells differ from calf-play's`);
    if (!(db >= MIN_DB)) problems.push(`pose ${i}: ${db.toFixed(2)} dB against calf-play, below ${MIN_DB}`);
    if (new Set(rgb).size < 4) problems.push(`pose ${i}: the canvas is blank`);
    if (!r.colourUpload.startsWith('SRGB8_ALPHA8')) problems.push(`pose ${i}: colour went up as ${r.colourUpload}, not SRGB8_ALPHA8 (rgba8's bytes)`);
  }, (i, message) => problems.push(`pose ${i}: ${message}`));

  // Garbage units while playing: every colour chunk's units after the first made garbage in the
  // cache, then the first pose at frame 1 (its cells' decoders go on from frame 0 … 3, so they
  // restart at a key frame; frame 1's unit is garbage).
  const bad = await page.evaluate(async (camera) => {
    const p = window.calfPlayer, cache = p.lf.clip.chunkCache;
    for (const c of p.lf.clip.chunks) {
      if (c.stream !== 1 || c.frameCount < 2 || !cache.has(c.id)) continue;
      const raw = cache.get(c.id).slice(), v = new DataView(raw.buffer);
      const at = 4 + 4 * v.getUint32(0, true) + v.getUint32(4, true);
      raw.fill(0xff, at);
      cache.set(c.id, raw);
    }
    const before = Array.from(p.pixels());
    let thrown = null;
    try { await p.renderPose(camera, 1.25 / p.fps); } catch (e) { thrown = e.message; }
    const after = Array.from(p.pixels());
    return { thrown, overlay: document.getElementById('overlay').textContent, same: before.every((x, i) => x === after[i]) };
  }, { position: path.poses[0].position, forward: path.poses[0].forward, up: [0, 1, 0], fovY: (70 * Math.PI) / 180, width: 64, height: 48 });
  console.log(`web.av1: garbage units while playing: overlay '${bad.overlay}', the last frame ${bad.same ? 'stays' : 'changed'}`);
  if (!bad.overlay.startsWith('CALF-E301 ') || bad.overlay.includes('\n')) problems.push(`garbage units while playing: overlay '${bad.overlay}'`);
  if (!bad.same) problems.push('garbage units while playing: the canvas changed');

  // The HDR clip, one pose, in the same page (RGBA16F colour); the clip it replaces closes its
  // AV1 decoders. Then the 4:4:4 clips likewise (SRGB8_ALPHA8, RGBA16F).
  const openedBefore = await page.evaluate(() => { window.calfReplaced = window.calfPlayer; return window.calfReplaced.lf.clip.codecs.av1.open(); });
  for (const [k, { clip, name, upload, native: nativeOne }] of onePose.entries()) {
    const played = await playClip(browser, held, `http://127.0.0.1:${port}`, `/${clip}`);
    if (k === 0) {
      const openedAfter = await page.evaluate(() => window.calfReplaced.lf.clip.codecs.av1.open());
      console.log(`web.av1: av1_pred16m's AV1 decoders open: ${openedBefore} while it plays, ${openedAfter} once av1_hdr_pred16m replaced it`);
      if (!(openedBefore > 0 && openedAfter === 0)) problems.push(`the replaced clip's AV1 decoders: ${openedBefore} open while it played, ${openedAfter} after`);
    }
    if (!played.ready) {
      problems.push(`the page did not open ${clip}: ${played.overlay}`);
      continue;
    }
    await renderEyePath(page, hdrPose, (i, r, rgb) => {
      const png = readPng(join(dir, `play_${name}`, `frame_${String(i).padStart(5, '0')}.png`));
      const db = psnr(rgb, png.rgb), n = nativeOne[i];
      console.log(`web.av1: ${name} pose ${i} frame ${r.frame}: ${r.active.length} views, ${r.visibleCells}/${r.totalCells} cells (calf-play ${n.views}, ${n.cells}/${n.total}), ` +
        `${db.toFixed(2)} dB against calf-play, colour ${r.colourUpload}; render ${r.renderMs.toFixed(1)} ms (SwiftShader) against calf-play's ${n.ms} ms (llvmpipe)`);
      if (r.active.length !== n.views || r.visibleCells !== n.cells || r.totalCells !== n.total) problems.push(`${name} pose ${i}: views or cells differ from calf-play's`);
      if (!(db >= MIN_DB)) problems.push(`${name} pose ${i}: ${db.toFixed(2)} dB against calf-play, below ${MIN_DB}`);
      if (new Set(rgb).size < 4) problems.push(`${name} pose ${i}: the canvas is blank`);
      if (!r.colourUpload.startsWith(upload)) problems.push(`${name} pose ${i}: colour went up as ${r.colourUpload}, not ${upload}`);
    }, (i, message) => problems.push(`${name} pose ${i}: ${message}`));
  }
} finally {
  await browser.close();
  server.kill();
}
console.log(`web.av1: ${((Date.now() - t0) / 1000).toFixed(1)} s in Chromium`);
for (const p of problems) console.log(`web.av1: FAIL ${p}`);
if (problems.length === 0) rmSync(dir, { recursive: true, force: true });
else console.log(`web.av1: its files are kept in ${dir}`);
process.exit(problems.length ? 1 : 0);
