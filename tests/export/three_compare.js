// The export in a real client: three.js's GLTFLoader in headless Chromium (driven by
// playwright-core) renders an exported .glb at the poses of an eye path, and each frame is compared
// with calf-play's headless frame of the same clip and pose (tests/export/three_compare.html).
// three and playwright-core come from build/npm (tools/setup.sh, pinned), Chromium from Debian;
// everything is served from a local HTTP server on 127.0.0.1, no network.
//
//   node three_compare.js poses MANIFEST.json OUT_EYE_PATH.json WIDTH HEIGHT
//     writes an eye path of 5 poses inside the capture set's view volume: its centre and four
//     points at 40 % of the way to corners, each looking in another direction
//   node three_compare.js compare NPM_DIR CHROMIUM MODEL.glb EYE_PATH.json FRAMES_DIR MIN_DB
//                         [SECOND.glb MIN_SAME_DB]
//     prints "pose P: PSNR X dB (blending in linear colour: Y dB)" per pose (X: three.js's
//     default rendering into the canvas, the figure MIN_DB applies to) and "three.js <version>:
//     min PSNR X dB over N poses in T s"; exits 1 when a pose is below MIN_DB or its canvas is
//     blank (one colour). With SECOND.glb (the same export with EXT_meshopt_compression), each
//     pose also prints SECOND's PSNR against MODEL's frame, which must reach MIN_SAME_DB, and a
//     line gives both files' bytes, their ratio and their load times in the page.
'use strict';
const fs = require('fs');
const http = require('http');
const path = require('path');

function fail(message) {
  console.error('three_compare: ' + message);
  process.exit(1);
}

function writePoses([manifestFile, outFile, width, height]) {
  const manifest = JSON.parse(fs.readFileSync(manifestFile, 'utf8'));
  const {min, max} = manifest.view_volume;
  const centre = min.map((v, i) => (v + max[i]) / 2);
  const half = min.map((v, i) => (max[i] - v) / 2);
  // Offsets (in units of the half extent) and view directions: every pose inside the region.
  const spots = [
    [[0, 0, 0], [0, 0, -1]],
    [[0.4, 0.4, 0.4], [-1, -0.2, -1]],
    [[-0.4, -0.4, 0.4], [1, 0.1, -1]],
    [[0.4, -0.4, -0.4], [-1, 0, 1]],
    [[-0.4, 0.4, -0.4], [1, -0.3, 0.5]],
  ];
  const poses = spots.map(([offset, forward]) => ({
    time: 0,
    position: centre.map((c, i) => c + offset[i] * half[i]),
    forward,
  }));
  const eyePath = {format: 'calf-eye-path', version: 1, width: Number(width),
                   height: Number(height), fov_y_degrees: 70, poses};
  fs.writeFileSync(outFile, JSON.stringify(eyePath, null, 1) + '\n');
}

function serve(routes) {
  const types = {'.js': 'text/javascript', '.html': 'text/html', '.json': 'application/json',
                 '.png': 'image/png', '.glb': 'model/gltf-binary'};
  const server = http.createServer((req, res) => {
    const url = decodeURIComponent(req.url.split('?')[0]);
    for (const [prefix, target] of routes) {
      const tree = prefix.length > 1 && prefix.endsWith('/');  // a directory, else one file
      if (url === prefix || (tree && url.startsWith(prefix))) {
        const file = tree ? path.join(target, url.slice(prefix.length)) : target;
        fs.readFile(file, (err, data) => {
          if (err) {
            res.writeHead(404);
            res.end();
            return;
          }
          res.writeHead(200, {'Content-Type': types[path.extname(file)] || 'application/octet-stream'});
          res.end(data);
        });
        return;
      }
    }
    res.writeHead(404);
    res.end();
  });
  return new Promise((resolve) => server.listen(0, '127.0.0.1', () => resolve(server)));
}

async function compare([npmDir, chromium, model, eyePath, framesDir, minDb, second, minSameDb]) {
  const started = Date.now();
  const modules = path.resolve(npmDir, 'node_modules');
  const {chromium: browserType} = require(path.join(modules, 'playwright-core'));
  const threeVersion = require(path.join(modules, 'three', 'package.json')).version;
  const server = await serve([
    ['/', path.join(__dirname, 'three_compare.html')],
    ['/three/', path.join(modules, 'three')],
    ['/model.glb', path.resolve(model)],
    ...(second ? [['/second.glb', path.resolve(second)]] : []),
    ['/eye_path.json', path.resolve(eyePath)],
    ['/frames/', path.resolve(framesDir)],
  ]);
  const browser = await browserType.launch({
    executablePath: chromium,
    headless: true,
    // WebGL without a GPU: ANGLE on SwiftShader, which recent Chromium enables only when asked.
    args: ['--no-sandbox', '--enable-unsafe-swiftshader', '--use-angle=swiftshader',
           '--ignore-gpu-blocklist'],
  });
  let result;
  try {
    const page = await browser.newPage();
    const logs = [];
    page.on('console', (m) => logs.push(m.text()));
    page.on('pageerror', (e) => logs.push(String(e)));
    // CALF_THREE_SAVE=DIR: three.js's frames are written there as three_NNNNN.png.
    const save = process.env.CALF_THREE_SAVE;
    const query = [save ? 'save' : '', second ? 'second' : ''].filter((q) => q).join('&');
    await page.goto(`http://127.0.0.1:${server.address().port}/${query ? '?' + query : ''}`);
    try {
      await page.waitForFunction(() => window.calfResult !== undefined, null, {timeout: 15000});
      result = await page.evaluate(() => window.calfResult);
    } catch (e) {
      result = {error: String(e)};
    }
    if (result.error) result.error += '\n' + logs.join('\n');
  } finally {
    await browser.close();
    server.close();
  }
  if (result.error) fail('the page failed: ' + result.error);
  if (process.env.CALF_THREE_SAVE) {
    result.poses.forEach((p, i) => fs.writeFileSync(
        path.join(process.env.CALF_THREE_SAVE, `three_${String(i).padStart(5, '0')}.png`),
        Buffer.from(p.png.split(',')[1], 'base64')));
  }
  // CALF_THREE_JSON=FILE: the per-pose figures are written there too (tests/export/blender_compare.sh).
  if (process.env.CALF_THREE_JSON) {
    fs.writeFileSync(process.env.CALF_THREE_JSON, JSON.stringify(
        result.poses.map((p) => ({psnr: p.psnr, psnr_linear: p.psnrLinear}))) + '\n');
  }
  let worst = Infinity, ok = true;
  result.poses.forEach((p, i) => {
    const same = second ? `; ${path.basename(second)} against it: ${p.psnrSecond.toFixed(2)} dB` : '';
    console.log(`pose ${i}: PSNR ${p.psnr.toFixed(2)} dB${p.blank ? ' (blank canvas)' : ''} ` +
                `(blending in linear colour: ${p.psnrLinear.toFixed(2)} dB)${same}`);
    worst = Math.min(worst, p.psnr);
    if (p.blank || !(p.psnr >= Number(minDb))) ok = false;
    if (second && !(p.psnrSecond >= Number(minSameDb))) ok = false;
  });
  if (second) {
    const bytes = fs.statSync(model).size, secondBytes = fs.statSync(second).size;
    console.log(`${path.basename(model)}: ${bytes} bytes, loaded in ${result.loadMs.toFixed(1)} ms; ` +
                `${path.basename(second)}: ${secondBytes} bytes (${(bytes / secondBytes).toFixed(2)} x ` +
                `smaller), loaded in ${result.secondLoadMs.toFixed(1)} ms (median of 5 loads each)`);
  }
  console.log(`three.js ${threeVersion} (${result.renderer}): min PSNR ${worst.toFixed(2)} dB over ` +
              `${result.poses.length} poses in ${((Date.now() - started) / 1000).toFixed(1)} s`);
  if (!ok) {
    fail(`a pose is below ${minDb} dB or blank` +
         (second ? `, or ${path.basename(second)} is below ${minSameDb} dB against it` : ''));
  }
}

const [command, ...args] = process.argv.slice(2);
if (command === 'poses' && args.length === 4) {
  writePoses(args);
} else if (command === 'compare' && (args.length === 6 || args.length === 8)) {
  compare(args).catch((e) => fail(String(e && e.stack || e)));
} else {
  console.error('usage: node three_compare.js poses MANIFEST OUT WIDTH HEIGHT | ' +
                'compare NPM_DIR CHROMIUM MODEL.glb EYE_PATH FRAMES_DIR MIN_DB [SECOND.glb MIN_SAME_DB]');
  process.exit(2);
}
