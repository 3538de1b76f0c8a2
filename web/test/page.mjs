// The page (web/index.html) in headless Chromium (Debian's chromium through playwright-core,
// SwiftShader without a GPU): it opens a clip over range requests, its shader (calf's GLSL
// conventions, generated) compiles under WebGL2, and the centre pixel looking along each of the
// six axes shows the texel SPEC §11.1.1 puts there (face from the major axis, (s, t) from the
// face table), as the decoder decoded it. Bad input is one line in the overlay with its id: a file
// that is not a clip (CALF-E040), a clip with no track it plays (CALF-E460), and a chunk whose
// hash fails (CALF-E058) when a later pose first needs it, the last good frame staying on the
// canvas and the page still drawing afterwards. Streaming frame after frame from one pose: no
// chunk requested twice, none beyond what the frame and the two prefetched after it need, the
// next frame already fetched, and the overlay's bytes per second against the clip's. Inline
// input: a mouse drag and a finger's drag look, W and D move. A local file chosen in the page's
// picker plays.
//
//   node web/test/page.mjs CHROMIUM
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { ROOT, loadCodecs } from './node_codecs.mjs';
import { startRangeServer, launchChromium, openPage, colourCount } from './browser.mjs';
import { bytesSource, openClip } from '../src/container.js';
import { openLightfield, STREAM } from '../src/lightfield.js';

const chromium = process.argv[2] ?? '/usr/bin/chromium';

// A damaged copy of the clip: one byte flipped in each colour chunk of face 4 (+z) of every view,
// which a pose looking down -z does not need and one looking down +z does.
const clipFile = 'tests/conformance/lightfield/bc7_bc5_zstd_mat.calf';
const work = mkdtempSync(join(tmpdir(), 'calf-web-page-'));
const clipBytes = readFileSync(join(ROOT, clipFile));
const { codecs } = await loadCodecs();
// The clip's chunk index and timing, read here for the streaming checks.
const clipIndex = await openClip(bytesSource(new Uint8Array(clipBytes)), codecs);
{
  const bytes = new Uint8Array(clipBytes);
  const lf = await openLightfield(await openClip(bytesSource(bytes), codecs), 0);
  let flipped = 0;
  for (const [key, chunks] of lf.byKey) {
    const [stream, , face] = key.split('/').map(Number);
    if (stream !== STREAM.colour || face !== 4) continue;
    for (const c of chunks) { bytes[lf.clip.chunks[c.id].offset] ^= 0x40; ++flipped; }
  }
  if (flipped === 0) throw new Error('no colour chunk of face 4 to damage');
  writeFileSync(join(work, 'damaged.calf'), bytes);
}
const { server, port } = await startRangeServer({ '/clips': work });
const base = `http://127.0.0.1:${port}`;
const problems = [];
const browser = await launchChromium(chromium);
try {
  const clip = clipFile;
  const t0 = Date.now();
  const { page, consoleLines, ready, overlay } = await openPage(browser, `${base}/web/index.html?mode=env&clip=/${clip}`);
  console.log(`page: ${clip}: '${overlay}' (${Date.now() - t0} ms)`);
  if (!ready) {
    problems.push(`the page did not play ${clip}: ${overlay} ${consoleLines.join(' | ')}`);
  } else {
    // Centre pixel along each axis (yaw, pitch) against the texel SPEC §11.1.1 names.
    const checks = await page.evaluate(() => {
      const p = window.calfPlayer, gl = p.gl, N = p.lf.header.face_size;
      const srgb8 = (c) => Math.round(255 * Math.min(1, Math.max(0, c <= 0.0031308 ? 12.92 * c : 1.055 * c ** (1 / 2.4) - 0.055)));
      // SPEC §11.1.1: the face of the major axis (ties to x, then y), s_c and t_c per face.
      const faceSt = (d) => {
        const a = d.map(Math.abs);
        const face = a[0] >= a[1] && a[0] >= a[2] ? (d[0] < 0 ? 1 : 0) : a[1] >= a[2] ? (d[1] < 0 ? 3 : 2) : (d[2] < 0 ? 5 : 4);
        const [x, y, z] = d;
        const [sc, tc, m] = [[-z, -y, x], [z, -y, -x], [x, z, y], [x, -z, -y], [x, -y, z], [-x, -y, -z]][face];
        return { face, s: (sc / m + 1) / 2, t: (tc / m + 1) / 2 };
      };
      const out = [];
      p.state.frame = 0;
      for (const [yaw, pitch] of [[0, 0], [Math.PI / 2, 0], [Math.PI, 0], [-Math.PI / 2, 0], [0, 1.4], [0, -1.4], [0.3, 0.2]]) {
        Object.assign(p.state, { yaw, pitch });
        p.draw();
        const px = new Uint8Array(4);
        gl.readPixels(gl.drawingBufferWidth >> 1, gl.drawingBufferHeight >> 1, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
        // The centre pixel's ray through the pixel's centre, with the player's camera basis.
        const W = gl.drawingBufferWidth, H = gl.drawingBufferHeight, th = Math.tan(Math.PI / 6);
        const nx = (2 * ((W >> 1) + 0.5)) / W - 1, ny = (2 * ((H >> 1) + 0.5)) / H - 1;
        const cy = Math.cos(yaw), sy = Math.sin(yaw), cp = Math.cos(pitch), sp = Math.sin(pitch);
        const back = [sy * cp, -sp, cy * cp], right = [cy, 0, -sy];
        const up = [back[1] * right[2] - back[2] * right[1], back[2] * right[0] - back[0] * right[2], back[0] * right[1] - back[1] * right[0]];
        const cam = [nx * th * (W / H), ny * th, -1];
        const d = [0, 1, 2].map((k) => right[k] * cam[0] + up[k] * cam[1] + back[k] * cam[2]);
        const { face, s, t } = faceSt(d);
        const x = Math.min(N - 1, Math.floor(s * N)), y = Math.min(N - 1, Math.floor(t * N));
        const o = 4 * (face * N * N + y * N + x);
        const want = [0, 1, 2].map((c) => srgb8(p.frames[0][o + c]));
        out.push({ yaw, pitch, face, x, y, got: [...px.slice(0, 3)], want });
      }
      // A blank canvas fails: the six faces do not all show one colour.
      return out;
    });
    const distinct = new Set(checks.map((c) => c.got.join(','))).size;
    for (const c of checks) {
      const ok = c.got.every((g, i) => Math.abs(g - c.want[i]) <= 2);
      console.log(`page: yaw ${c.yaw.toFixed(2)} pitch ${c.pitch.toFixed(2)}: face ${c.face} texel (${c.x}, ${c.y}) ` +
        `shows ${c.got.join(',')}, decoded ${c.want.join(',')}${ok ? '' : '  MISMATCH'}`);
      if (!ok) problems.push(`yaw ${c.yaw} pitch ${c.pitch}: ${c.got} against ${c.want}`);
    }
    if (distinct < 3) problems.push(`only ${distinct} distinct colours along the axes: a blank canvas`);
  }
  // Bad input: one line in the overlay with the reader's id.
  const { overlay: line } = await openPage(browser, `${base}/web/index.html?clip=/web/index.html`, { timeout: 30000 });
  console.log(`page: not a clip: '${line}'`);
  if (!line.startsWith('CALF-E040 ') || line.includes('\n')) problems.push(`not a clip gave '${line}'`);
  // Nothing the page can play: a clip without tracks.
  const { overlay: meshLine } = await openPage(browser, `${base}/web/index.html?clip=/tests/conformance/container/valid/empty.calf`, { timeout: 30000 });
  console.log(`page: a clip without tracks: '${meshLine}'`);
  if (!meshLine.startsWith('CALF-E460 ') || meshLine.includes('\n')) problems.push(`a clip without tracks gave '${meshLine}'`);
  // Streaming, frame after frame from one pose (looking down +x, where the clip's cells have a
  // keyframe every frame), two frames of prefetch (the documented default,
  // given): no chunk is requested twice; after frame n (its prefetch done) every chunk fetched
  // is one that frames 0 … n + 2 need (a colour chunk: a frame of its own or, as the next
  // keyframe, one of the previous keyframe's; a depth chunk: a frame of its own), so the page
  // does not fetch every frame of a cell; frame n + 1 then needs no request. The overlay gives
  // the bytes per second fetched against the clip's size over its duration.
  {
    const K = 2, F = clipIndex.tracks[0].header.frame_count;
    const h = clipIndex.tracks[0].header, fps = h.fps_numerator / h.fps_denominator;
    const touch = await browser.newContext({ hasTouch: true });
    const { page: sp, ready: spReady, overlay: spLine, consoleLines: spConsole } = await openPage(browser,
      `${base}/web/index.html?autoplay=0&prefetch=${K}&clip=/${clipFile}`, { context: touch });
    if (!spReady) {
      problems.push(`the streaming page did not open the clip: ${spLine} ${spConsole.join(' | ')}`);
    } else {
      const colourRuns = new Map();  // colour chunk id -> the first frame of the previous keyframe of its cell
      for (const c of clipIndex.chunks) {
        if (c.stream !== STREAM.colour) continue;
        const prev = clipIndex.chunks.filter((o) => o.stream === c.stream && o.track === c.track && o.view === c.view && o.face === c.face &&
          o.region === c.region && o.firstFrame + o.frameCount === c.firstFrame);
        colourRuns.set(c.id, prev.length ? prev[0].firstFrame : c.firstFrame);
      }
      const allowed = (c, frames) => c.stream === STREAM.index || [...frames].some((m) => (c.stream === STREAM.colour ? colourRuns.get(c.id) : c.firstFrame) <= m &&
        m < c.firstFrame + (c.stream === STREAM.t ? F : c.frameCount));
      let last = null, total = 0;
      for (let n = 0; n < F; ++n) {
        const r = await sp.evaluate(async ({ time }) => {
          const p = window.calfPlayer, before = p.source.stats.requests;
          const got = await p.renderPose({ position: [0, 0, 0], forward: [1, 0, 0], up: [0, 1, 0], fovY: Math.PI / 3, width: 32, height: 32 }, time);
          const during = p.source.stats.requests - before;
          await p.settled();
          return { frame: got.frame, during, counts: [...p.fetchCounts()], overlay: document.getElementById('overlay').textContent, bytes: p.source.stats.bytes };
        }, { time: n / fps });
        const frames = new Set([...Array(n + 1).keys(), ...Array.from({ length: K }, (_, k) => (n + 1 + k) % F)]);
        const twice = r.counts.filter(([, k]) => k > 1), beyond = r.counts.filter(([id]) => !allowed(clipIndex.chunks[id], frames));
        console.log(`page: streaming frame ${r.frame}: ${r.during} requests for the frame, ${r.counts.length} of ${clipIndex.chunks.length} chunks fetched ` +
          `(${r.bytes} of ${clipBytes.length} bytes), ${twice.length} twice, ${beyond.length} beyond frame ${n + K}`);
        if (r.frame !== n) problems.push(`streaming: time ${n}/${fps} played frame ${r.frame}`);
        if (twice.length) problems.push(`streaming frame ${n}: chunks requested twice: ${twice.map(([id, k]) => `${id} (${k})`).join(', ')}`);
        if (beyond.length) problems.push(`streaming frame ${n}: chunks no frame up to ${n + K} needs: ${beyond.map(([id]) => id).join(', ')}`);
        if (n > 0 && r.during !== 0) problems.push(`streaming frame ${n}: ${r.during} requests, though the frame was prefetched`);
        last = r;
        total = r.counts.length;
      }
      const clipRate = `${(clipBytes.length / (F / fps) / 1024).toFixed(1)} KiB/s`;
      if (!/ [0-9]+\.[0-9] KiB\/s fetched against the clip's /.test(last.overlay) || !last.overlay.includes(`against the clip's ${clipRate}`)) {
        problems.push(`the overlay does not give the bytes per second against the clip's ${clipRate}: '${last.overlay}'`);
      }
      if (!(total > 0 && last.bytes < clipBytes.length)) problems.push(`streaming: ${last.bytes} of ${clipBytes.length} bytes fetched`);
      console.log(`page: overlay '${last.overlay}'`);
      // Inline: a mouse drag looks (yaw), a finger's drag looks (pitch), W and D move along the
      // view and to its right, 0.005 rad a pixel and 0.02 a frame (docs/WEB.md).
      const state = () => sp.evaluate(() => ({ eye: window.calfInline.eye.slice(), yaw: window.calfInline.yaw, pitch: window.calfInline.pitch }));
      const s0 = await state();
      await sp.mouse.move(300, 200);
      await sp.mouse.down();
      await sp.mouse.move(400, 200, { steps: 4 });
      await sp.mouse.up();
      const s1 = await state();
      const cdp = await touch.newCDPSession(sp);
      await cdp.send('Input.dispatchTouchEvent', { type: 'touchStart', touchPoints: [{ x: 300, y: 200 }] });
      for (const y of [220, 240, 260]) await cdp.send('Input.dispatchTouchEvent', { type: 'touchMove', touchPoints: [{ x: 300, y }] });
      await cdp.send('Input.dispatchTouchEvent', { type: 'touchEnd', touchPoints: [] });
      const s2 = await state();
      const moved = async (key) => {
        await sp.keyboard.down(key);
        await sp.evaluate(() => window.calfInline.step());
        await sp.keyboard.up(key);
        await sp.evaluate(() => window.calfInline.step());  // released: no further move
        return state();
      };
      const s3 = await moved('w'), s4 = await moved('d');
      const near = (a, b) => Math.abs(a - b) < 1e-9;
      const forward = [-Math.sin(s2.yaw) * Math.cos(s2.pitch), Math.sin(s2.pitch), -Math.cos(s2.yaw) * Math.cos(s2.pitch)];
      const right = [Math.cos(s2.yaw), 0, -Math.sin(s2.yaw)];
      console.log(`page: inline: mouse drag 100 px right: yaw ${s0.yaw} -> ${s1.yaw.toFixed(3)}; touch drag 60 px down: pitch ${s1.pitch} -> ${s2.pitch.toFixed(3)}; ` +
        `W: eye ${s2.eye.map((x) => x.toFixed(4))} -> ${s3.eye.map((x) => x.toFixed(4))}; D: -> ${s4.eye.map((x) => x.toFixed(4))}`);
      if (!near(s1.yaw - s0.yaw, -0.5) || !near(s1.pitch, s0.pitch)) problems.push(`inline: a mouse drag of 100 px right turned yaw by ${s1.yaw - s0.yaw}, pitch by ${s1.pitch - s0.pitch}`);
      if (!near(s2.pitch - s1.pitch, -0.3) || !near(s2.yaw, s1.yaw)) problems.push(`inline: a touch drag of 60 px down turned pitch by ${s2.pitch - s1.pitch}, yaw by ${s2.yaw - s1.yaw}`);
      if (![0, 1, 2].every((k) => near(s3.eye[k] - s2.eye[k], 0.02 * forward[k]))) problems.push(`inline: W moved the eye from ${s2.eye} to ${s3.eye}, not 0.02 along ${forward}`);
      if (![0, 1, 2].every((k) => near(s4.eye[k] - s3.eye[k], 0.02 * right[k]))) problems.push(`inline: D moved the eye from ${s3.eye} to ${s4.eye}, not 0.02 along ${right}`);
      // A local file chosen in the page's picker plays from memory.
      const local = 'tests/conformance/lightfield/bc1_raw16_zstd.calf';
      await sp.setInputFiles('#file', join(ROOT, local));
      await sp.waitForFunction(() => window.calfPlayer.source.local, null, { timeout: 60000 }).catch(() => {});
      const picked = await sp.evaluate(async () => {
        const p = window.calfPlayer;
        if (!p.source.local) return { line: document.getElementById('overlay').textContent };
        await p.renderPose({ position: [0, 0, 0], forward: [0, 0, -1], up: [0, 1, 0], fovY: Math.PI / 3, width: 32, height: 32 }, 0);
        return { line: document.getElementById('overlay').textContent, rgb: Array.from(p.pixels()), requests: p.source.stats.requests };
      });
      const size = readFileSync(join(ROOT, local)).length;
      console.log(`page: a local file: '${picked.line}', ${picked.rgb ? colourCount(picked.rgb) : 0} colours`);
      if (!picked.rgb || !picked.line.includes(`a local file of ${size} bytes`)) problems.push(`a local file did not play: '${picked.line}'`);
      else if (colourCount(picked.rgb) < 3) problems.push(`a local file drew a blank frame (${colourCount(picked.rgb)} colours)`);
      // A damaged chunk, first needed by the second pose.
      // (in the streaming page, whose shaders are compiled by now)
      const dmg = sp;
      const dmgLine = await sp.evaluate(async () => { try { await window.calfOpen('/clips/damaged.calf'); return null; } catch (e) { return e.message; } });
      if (dmgLine) {
        problems.push(`the damaged clip did not open: ${dmgLine}`);
      } else {
        const poses = await dmg.evaluate(async () => {
          const p = window.calfPlayer, cam = (z) => ({ position: [0, 0, 0], forward: [0, 0, z], up: [0, 1, 0], fovY: Math.PI / 3, width: 32, height: 32 });
          await p.renderPose(cam(-1), 0);
          const good = Array.from(p.pixels()), goodLine = document.getElementById('overlay').textContent;
          let thrown = null;
          try { await p.renderPose(cam(1), 0); } catch (e) { thrown = e.message; }
          const after = Array.from(p.pixels()), line = document.getElementById('overlay').textContent;
          await p.renderPose(cam(-1), 1 / 24);  // the page still draws
          return { good, goodLine, thrown, after, line, again: document.getElementById('overlay').textContent };
        });
        console.log(`page: damaged chunk: '${poses.goodLine}', then '${poses.line}', then '${poses.again}'`);
        if (!poses.line.startsWith('CALF-E058 ') || poses.line.includes('\n')) problems.push(`a damaged chunk gave '${poses.line}'`);
        if (!poses.thrown) problems.push('a damaged chunk did not fail the pose');
        if (poses.after.join() !== poses.good.join()) problems.push('the last good frame did not stay after the damaged chunk');
        if (!poses.again.startsWith('frame 1:')) problems.push(`after the damaged chunk the page did not draw: '${poses.again}'`);
      }
    }
    await touch.close();
  }
} finally {
  await browser.close();
  server.kill();
  rmSync(work, { recursive: true, force: true });
}
for (const p of problems) console.log(`web page: ${p}`);
console.log(`web page: ${problems.length ? 'FAILED' : 'ok'}`);
process.exit(problems.length ? 1 : 0);
