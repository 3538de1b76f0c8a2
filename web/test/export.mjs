// calf-export --web (docs/EXPORT.md): the folder it writes holds the page, its scripts, the npm
// modules the page imports (for a clip with AV1 colour the WebAssembly AV1 decoder too, for
// another not) and the clip; served as the command prints it (python3's http.server, no range
// requests) and opened at its root in headless Chromium, the page plays the clip it names by
// default, says in one line that the server sent the whole clip (no range requests), and draws a
// frame that is not blank: a BC clip, and an AV1 one through the folder's WebAssembly decoder.
//
//   CALF_EXPORT=build/.../calf-export node web/test/export.mjs CHROMIUM
import { execFileSync, spawn } from 'node:child_process';
import { existsSync, mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { createInterface } from 'node:readline';
import { launchChromium } from './browser.mjs';
import { ROOT } from './node_codecs.mjs';

const chromium = process.argv[2] ?? '/usr/bin/chromium';
const exporter = process.env.CALF_EXPORT;
if (!exporter) throw new Error('CALF_EXPORT names no calf-export');

const problems = [];
const AV1_FILES = ['npm/@libav.js/variant-av1-opus/dist/libav-av1-opus.mjs',
  'npm/@libav.js/variant-av1-opus/dist/libav-6.10.9.0-av1-opus.wasm.wasm'];

// Exports `name` (a conformance clip), serves the folder and plays it at the folder's root with
// `query`; `av1`: the clip has AV1 colour, so the folder must hold the WebAssembly decoder (and a
// clip without must not carry its 4.9 MB).
async function exportAndPlay(name, query, av1) {
  const clipFile = join(ROOT, 'tests/conformance/lightfield', name);
  const work = mkdtempSync(join(tmpdir(), 'calf-web-export-'));
  const dir = join(work, 'site');
  let server = null, browser = null;
  try {
    const printed = execFileSync(exporter, ['--web', dir, clipFile], { encoding: 'utf8' });
    console.log(printed.trimEnd());
    const command = printed.trimEnd().split('\n').at(-1);
    if (!command.startsWith('python3 -m http.server ') || !command.includes(dir)) problems.push(`${name}: no serve command: '${command}'`);
    for (const f of ['index.html', 'src/player.js', 'src/march_player.js', 'npm/fzstd/esm/index.mjs',
      'npm/hash-wasm/dist/index.esm.js', 'npm/xz-decompress/dist/package/xz-decompress.js', name]) {
      if (!existsSync(join(dir, f))) problems.push(`${name}: no ${f} in the folder`);
    }
    for (const f of AV1_FILES) {
      if (existsSync(join(dir, f)) !== av1) problems.push(`${name}: ${f} ${av1 ? 'missing from' : 'in'} the folder`);
    }
    if (!readFileSync(join(dir, name)).equals(readFileSync(clipFile))) problems.push(`${name}: the clip copy differs`);
    if (readFileSync(join(dir, 'index.html'), 'utf8').includes('../build/npm/')) problems.push(`${name}: the page still loads ../build/npm/`);

    // The printed command, on a free port.
    server = spawn('/usr/bin/python3', ['-m', 'http.server', '--bind', '127.0.0.1', '--directory', dir, '0'], { stdio: ['ignore', 'pipe', 'ignore'] });
    const line = await new Promise((resolve) => createInterface({ input: server.stdout }).once('line', resolve));
    const port = /port (\d+)/.exec(line)[1];
    browser = await launchChromium(chromium);
    const page = await browser.newPage();
    const consoleLines = [];
    page.on('pageerror', (e) => consoleLines.push(e.message));
    await page.goto(`http://127.0.0.1:${port}/?autoplay=0${query}`);  // the test draws
    await page.waitForFunction(() => window.calfStatus !== 'loading', null, { timeout: 60000 });
    const overlay = await page.textContent('#overlay');
    console.log(`export: ${name} at the folder's root: '${overlay}'`);
    // http.server answers a range request with the whole file: one notice line says so.
    const notice = (await page.evaluate(() => window.calfStatusLines)).filter((l) => l.startsWith('the server ignores range requests'));
    console.log(`export: the notice: '${notice[0]}'`);
    if (notice.length !== 1 || notice[0].includes('\n')) problems.push(`${name}: no one-line notice of the whole download: ${JSON.stringify(notice)}`);
    if ((await page.evaluate(() => window.calfStatus)) !== 'ready') {
      problems.push(`${name}: the page did not play its clip: ${overlay} ${consoleLines.join(' | ')}`);
    } else {
      const colours = await page.evaluate(async () => {
        const p = window.calfPlayer;
        await p.renderPose({ position: [0, 0, 0], forward: [0, 0, -1], up: [0, 1, 0], fovY: Math.PI / 3, width: 32, height: 32 }, 0);
        const px = p.pixels(), seen = new Set();
        for (let i = 0; i < px.length; i += 4) seen.add(`${px[i]},${px[i + 1]},${px[i + 2]}`);
        return seen.size;
      });
      console.log(`export: ${name}: a 32 x 32 frame with ${colours} distinct colours`);
      if (colours < 3) problems.push(`${name}: a blank frame (${colours} colours) ${consoleLines.join(' | ')}`);
    }
  } finally {
    if (browser) await browser.close();
    if (server) server.kill();
    rmSync(work, { recursive: true, force: true });
  }
}

await exportAndPlay('bc7_bc5_zstd_mat.calf', '', false);
// AV1 colour through the folder's own WebAssembly decoder (&av1=wasm: as in a browser whose
// WebCodecs has no AV1), the 4:4:4 clip so that the High profile is covered too.
await exportAndPlay('av1_444_pred16m.calf', '&av1=wasm', true);
if (problems.length) {
  for (const p of problems) console.log(`FAIL: ${p}`);
  process.exit(1);
}
console.log('export: ok');
