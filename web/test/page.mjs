// The page (web/index.html) in headless Chromium (Debian's chromium through playwright-core,
// SwiftShader without a GPU): it opens a clip over range requests, its shader (calf's GLSL
// conventions, generated) compiles under WebGL2, and the centre pixel looking along each of the
// six axes shows the texel SPEC §11.1.1 puts there (face from the major axis, (s, t) from the
// face table), as the decoder decoded it. Bad input is one line in the overlay with its id: a file
// that is not a clip (CALF-E040), a clip with no track it plays (CALF-E460), and a chunk whose
// hash fails (CALF-E058) when a later pose first needs it, the last good frame staying on the
// canvas and the page still drawing afterwards.
//
//   node web/test/page.mjs CHROMIUM
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { ROOT, loadCodecs } from './node_codecs.mjs';
import { startRangeServer, launchChromium } from './browser.mjs';
import { bytesSource, openClip } from '../src/container.js';
import { openLightfield, STREAM } from '../src/lightfield.js';

const chromium = process.argv[2] ?? '/usr/bin/chromium';

// A damaged copy of the clip: one byte flipped in each colour chunk of face 4 (+z) of every view,
// which a pose looking down -z does not need and one looking down +z does.
const clipFile = 'tests/conformance/lightfield/bc7_bc5_zstd_mat.calf';
const work = mkdtempSync(join(tmpdir(), 'calf-web-page-'));
{
  const bytes = new Uint8Array(readFileSync(join(ROOT, clipFile)));
  const { codecs } = await loadCodecs();
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
  const page = await browser.newPage();
  const consoleLines = [];
  page.on('console', (m) => consoleLines.push(m.text()));
  page.on('pageerror', (e) => consoleLines.push(e.message));
  const clip = 'tests/conformance/lightfield/bc7_bc5_zstd_mat.calf';
  const t0 = Date.now();
  await page.goto(`${base}/web/index.html?mode=env&clip=/${clip}`);
  await page.waitForFunction(() => window.calfStatus !== 'loading', null, { timeout: 60000 });
  const overlay = await page.textContent('#overlay');
  console.log(`page: ${clip}: '${overlay}' (${Date.now() - t0} ms)`);
  if ((await page.evaluate(() => window.calfStatus)) !== 'ready') {
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
  const bad = await browser.newPage();
  await bad.goto(`${base}/web/index.html?clip=/web/index.html`);
  await bad.waitForFunction(() => window.calfStatus !== 'loading', null, { timeout: 30000 });
  const line = await bad.textContent('#overlay');
  console.log(`page: not a clip: '${line}'`);
  if (!line.startsWith('CALF-E040 ') || line.includes('\n')) problems.push(`not a clip gave '${line}'`);
  // Nothing the page can play: a clip without tracks.
  const mesh = await browser.newPage();
  await mesh.goto(`${base}/web/index.html?clip=/tests/conformance/container/valid/empty.calf`);
  await mesh.waitForFunction(() => window.calfStatus !== 'loading', null, { timeout: 30000 });
  const meshLine = await mesh.textContent('#overlay');
  console.log(`page: a clip without tracks: '${meshLine}'`);
  if (!meshLine.startsWith('CALF-E460 ') || meshLine.includes('\n')) problems.push(`a clip without tracks gave '${meshLine}'`);
  // A damaged chunk, first needed by the second pose.
  const dmg = await browser.newPage();
  await dmg.goto(`${base}/web/index.html?autoplay=0&clip=/clips/damaged.calf`);
  await dmg.waitForFunction(() => window.calfStatus !== 'loading', null, { timeout: 60000 });
  if ((await dmg.evaluate(() => window.calfStatus)) !== 'ready') {
    problems.push(`the damaged clip did not open: ${await dmg.textContent('#overlay')}`);
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
} finally {
  await browser.close();
  server.kill();
  rmSync(work, { recursive: true, force: true });
}
for (const p of problems) console.log(`web page: ${p}`);
console.log(`web page: ${problems.length ? 'FAILED' : 'ok'}`);
process.exit(problems.length ? 1 : 0);
