// Same pictures as calf-play: a small clip (the interior scene, 64² faces, 2 frames) is captured
// and encoded here, calf-play renders the poses of calf-capture's ground-truth eye path headless
// (GL through OSMesa, PNG frames), and the page (web/index.html, headless Chromium with
// SwiftShader) renders the same poses with the same shader body; each frame must be within
// MIN_DB of calf-play's, a blank canvas fails, and the page's active views and visible cells
// (the only ones it fetches) are calf-play's. Prints the dB per pose, the render ms of both and
// the bytes fetched; along the path the page fetches less than the whole clip and no chunk twice
// (the page's record of its range requests).
//
//   CALF_BIN=BUILD_DIR node web/test/match.mjs CHROMIUM
//   CALF_BIN=BUILD_DIR node web/test/match.mjs CHROMIUM --clip CLIP EYE_PATH   (a given clip)
import { execFileSync } from 'node:child_process';
import { copyFileSync, mkdirSync, mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startRangeServer, launchChromium, playClip, renderEyePath, colourCount } from './browser.mjs';
import { readPng, psnr } from './frames.mjs';

// The floor the brief sets is 40 dB; the measured figures are in docs/WEB.md.
const MIN_DB = 40;
const chromium = process.argv[2] && !process.argv[2].startsWith('--') ? process.argv[2] : '/usr/bin/chromium';
// --clip CLIP EYE_PATH: a measurement of a given clip (e.g. tools/demo.sh's) along a given eye
// path instead of the test's two clips; only calf-play is needed in CALF_BIN.
const clipAt = process.argv.indexOf('--clip');
const given = clipAt > 0 ? { clip: process.argv[clipAt + 1], path: process.argv[clipAt + 2] } : null;
const bin = process.env.CALF_BIN;
if (!bin) {
  console.log('web.match: CALF_BIN (the directory of calf-capture, calf-encode, calf-play) is not set');
  process.exit(1);
}

// Everything goes into a fresh temporary folder (the source tree is only read), served by the
// range server under /clips/.
const dir = mkdtempSync(join(process.env.CALF_WEB_TMP ?? tmpdir(), 'calf-web-match-'));
const run = (tool, args) => execFileSync(join(bin, tool), args, { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });
const t0 = Date.now();
if (given) {
  mkdirSync(join(dir, 'gt'));
  copyFileSync(given.clip, join(dir, 'given.calf'));
  copyFileSync(given.path, join(dir, 'gt', 'eye_path.json'));
} else {
  run('calf-capture', ['--scene', 'interior', '--face-size', '64', '--frames', '2', '--spp', '1', '--quiet', '--out', join(dir, 'cap')]);
  run('calf-capture', ['--scene', 'interior', '--ground-truth', '--gt-size', '64x48', '--frames', '2', '--spp', '1', '--quiet', '--out', join(dir, 'gt')]);
}
// The same capture twice: rgba16f colour (the page decodes it to RGBA on the CPU) and BC1 (the
// page uploads the blocks where WEBGL_compressed_texture_s3tc_srgb exists, as SwiftShader has).
const clips = given ? [['given', null]] : [['rgba16f', ['--color-format', 'rgba16f']], ['bc1', ['--color-format', 'bc1', '--bc1-fit', 'range', '--colour-rdo', '0']]];
const native = {};
for (const [name, args] of clips) {
  if (args) run('calf-encode', [join(dir, 'cap'), '-o', join(dir, `${name}.calf`), '--cell', '16', '--quiet', ...args]);
  const played = run('calf-play', [join(dir, `${name}.calf`), '--headless', '--eye-path', join(dir, 'gt', 'eye_path.json'), '--out', join(dir, `play-${name}`)]);
  native[name] = [...played.matchAll(/^pose (\d+) frame \d+: (\d+) views, (\d+)\/(\d+) cells, .*render ([0-9.]+) ms/gm)]
    .map((m) => ({ views: Number(m[2]), cells: Number(m[3]), total: Number(m[4]), ms: Number(m[5]) }));
  if (native[name].length === 0) throw new Error(`no pose lines in calf-play's output: ${played}`);
}
console.log(`web.match: clips and calf-play frames made in ${((Date.now() - t0) / 1000).toFixed(1)} s`);
const path = JSON.parse(readFileSync(join(dir, 'gt', 'eye_path.json'), 'utf8'));

const { server, port } = await startRangeServer({ '/clips': dir });
const problems = [];
const browser = await launchChromium(chromium);
const held = {};  // one page plays the clips in turn (the ray march compiles once)
try {
for (const [name] of clips) {
  const { page, consoleLines, ready, overlay } = await playClip(browser, held, `http://127.0.0.1:${port}`, `/clips/${name}.calf`);
  if (!ready) {
    problems.push(`${name}: the page did not open the clip: ${overlay} ${consoleLines.join(' | ')}`);
  } else {
    await renderEyePath(page, path, (i, got, rgb) => {
      const want = readPng(join(dir, `play-${name}`, `frame_${String(i).padStart(5, '0')}.png`));
      const db = psnr(rgb, want.rgb);
      const n = native[name][i] ?? {};
      console.log(`web.match: ${name} pose ${i} frame ${got.frame} (colour ${got.colourUpload}): ${got.active.length} views, ${got.visibleCells}/${got.totalCells} cells ` +
        `(calf-play ${n.views} views, ${n.cells}/${n.total}), ${db.toFixed(2)} dB against calf-play; ` +
        `render ${got.renderMs.toFixed(1)} ms (SwiftShader) against calf-play's ${n.ms} ms (llvmpipe); ` +
        `${got.bytes} of ${got.size} bytes fetched so far in ${got.requests} requests`);
      if (got.active.length !== n.views || got.visibleCells !== n.cells || got.totalCells !== n.total) {
        problems.push(`${name} pose ${i}: ${got.active.length} views, ${got.visibleCells}/${got.totalCells} cells; calf-play ${n.views}, ${n.cells}/${n.total}`);
      }
      if (name === 'bc1' && !got.colourUpload.startsWith('BC1')) problems.push(`bc1 pose ${i}: colour went up as ${got.colourUpload}, not as BC1 blocks`);
      const colours = colourCount(rgb);
      if (colours < 16) problems.push(`${name} pose ${i}: the canvas is blank (${colours} colours)`);
      if (!(db >= MIN_DB)) problems.push(`${name} pose ${i}: ${db.toFixed(2)} dB against calf-play, below ${MIN_DB}`);
    }, (i, message) => problems.push(`${name} pose ${i}: ${message} ${consoleLines.join(' | ')}`));
    // Along the path, with the prefetches done: less than the whole clip, no chunk twice.
    const f = await page.evaluate(async () => {
      const p = window.calfPlayer;
      await p.settled();
      const counts = p.fetchCounts();
      return { twice: [...counts].filter(([, k]) => k > 1).map(([id]) => id), chunks: counts.size, of: p.lf.clip.chunks.length,
        bytes: p.source.stats.bytes, size: p.source.size, requests: p.source.stats.requests, prefetched: p.stats.prefetched };
    });
    console.log(`web.match: ${name} along the path: ${f.bytes} of ${f.size} bytes fetched (${(100 * f.bytes / f.size).toFixed(1)} %), ` +
      `${f.chunks} of ${f.of} chunks in ${f.requests} requests, ${f.prefetched} of them prefetched, ${f.twice.length} fetched twice`);
    if (f.twice.length) problems.push(`${name}: chunks fetched twice: ${f.twice.slice(0, 10)}`);
    if (!(f.bytes < f.size)) problems.push(`${name}: the whole clip was fetched (${f.bytes} of ${f.size} bytes)`);
  }
}
} finally {
  await browser.close();
  server.kill();
}
for (const p of problems) console.log(`web.match: FAIL ${p}`);
if (problems.length === 0) rmSync(dir, { recursive: true, force: true });
else console.log(`web.match: its files are kept in ${dir}`);
process.exit(problems.length ? 1 : 0);
