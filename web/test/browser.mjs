// What the browser tests share: the range server (web/test/range_server.py) serving the
// repository, with folders mounted under URL prefixes, and headless Chromium drawing WebGL2 with
// SwiftShader, as on a machine without a GPU.
import { spawn } from 'node:child_process';
import { createRequire } from 'node:module';
import { join } from 'node:path';
import { createInterface } from 'node:readline';
import { pathToFileURL } from 'node:url';
import { ROOT, NPM } from './node_codecs.mjs';

// Starts the range server on the repository, each of `mounts` ({ '/clips': DIR }) served under
// its prefix; resolves to { server, port } once the server prints its port.
export async function startRangeServer(mounts = {}) {
  const args = [join(ROOT, 'web/test/range_server.py'), ROOT];
  for (const [prefix, dir] of Object.entries(mounts)) args.push('--mount', `${prefix}=${dir}`);
  const server = spawn('/usr/bin/python3', args, { stdio: ['ignore', 'pipe', 'ignore'] });
  const line = await new Promise((resolve) => createInterface({ input: server.stdout }).once('line', resolve));
  return { server, port: line.split(' ')[1] };
}

// Headless Chromium, the binary at `executable`, through the pinned playwright-core.
export function launchChromium(executable) {
  const require = createRequire(pathToFileURL(join(NPM, 'package.json')));
  return require('playwright-core').chromium.launch({
    executablePath: executable,
    args: ['--no-sandbox', '--enable-unsafe-swiftshader', '--use-angle=swiftshader', '--ignore-gpu-blocklist'],
  });
}

// Opens `url` in a new page (of `context`, e.g. one with touch, else of the browser), `init` (a
// function) run before the page's scripts, the page's console and errors kept in `consoleLines`;
// waits until the page has opened its clip or failed. Returns { page, consoleLines, ready
// (window.calfStatus is 'ready'), overlay (its line) }.
export async function openPage(browser, url, { init = null, context = null, timeout = 60000 } = {}) {
  const page = await (context ?? browser).newPage();
  const consoleLines = [];
  page.on('console', (m) => consoleLines.push(m.text()));
  page.on('pageerror', (e) => consoleLines.push(e.message));
  if (init) await page.addInitScript(init);
  await page.goto(url);
  await page.waitForFunction(() => window.calfStatus !== 'loading', null, { timeout });
  const ready = (await page.evaluate(() => window.calfStatus)) === 'ready';
  return { page, consoleLines, ready, overlay: await page.textContent('#overlay') };
}

// The number of distinct colours in 8-bit RGB pixels (a blank canvas has few).
export function colourCount(rgb) {
  const seen = new Set();
  for (let k = 0; k + 2 < rgb.length; k += 3) seen.add((rgb[k] << 16) | (rgb[k + 1] << 8) | rgb[k + 2]);
  return seen.size;
}

// Renders each pose of a calf-capture eye path (its JSON) with the page's renderPose; calls
// onPose(i, result, rgb) with renderPose's result and the canvas's RGB bytes, or onError(i,
// message) when the pose throws.
export async function renderEyePath(page, path, onPose, onError) {
  for (let i = 0; i < path.poses.length; ++i) {
    const p = path.poses[i];
    const camera = { position: p.position, forward: p.forward, up: p.up, fovY: (p.fov_y_degrees * Math.PI) / 180, width: path.width, height: path.height };
    let got;
    try {
      got = await page.evaluate(async ({ camera, time }) => {
        const r = await window.calfPlayer.renderPose(camera, time);
        return { ...r, rgb: Array.from(window.calfPlayer.pixels()) };
      }, { camera, time: p.time });
    } catch (e) {
      onError(i, e.message.split('\n')[0]);
      continue;
    }
    await onPose(i, got, Uint8Array.from(got.rgb));
  }
}

// Plays `clip` (a URL path) in the page `held` keeps ({} at first): the first time a new page
// of `base`'s web/index.html?autoplay=0 (openPage), later the same page's window.calfOpen, so
// that its shaders compile once. Returns `held`: { page, consoleLines, ready, overlay }.
export async function playClip(browser, held, base, clip) {
  if (!held.page) return Object.assign(held, await openPage(browser, `${base}/web/index.html?autoplay=0&clip=${clip}`));
  return Object.assign(held, await held.page.evaluate(async (url) => {
    try {
      await window.calfOpen(url);
      return { ready: true, overlay: document.getElementById('overlay').textContent };
    } catch (e) {
      return { ready: false, overlay: e.message.split('\n')[0] };
    }
  }, clip));
}
