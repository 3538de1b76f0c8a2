// WebXR under an emulated device: a fake `navigator.xr` and `XRWebGLLayer` (installed before the
// page's scripts) hand the page an immersive-vr session whose frames carry two XRViews, the eyes
// `OFFSET` left and right of the head, each drawn into its half of the canvas. Checks that the
// session starts, that each frame draws both eyes, that the page's eye positions are the head's
// plus the known offsets, that each half equals the page's single-eye render at that eye's pose
// (and not the other eye's: the halves differ as the offset predicts), and that the overlay says
// so when the head leaves the view volume.
//
//   node web/test/xr.mjs CHROMIUM
import { startRangeServer, launchChromium, openPage, colourCount } from './browser.mjs';
import { psnr } from './frames.mjs';

const chromium = process.argv[2] ?? '/usr/bin/chromium';
const OFFSET = 0.25;  // half the eye separation, in scene units (the clip's views span [-1, 1]³)
const EYE = 48;       // each eye's viewport, square

// Runs in the page before its scripts: a device with two eyes, driven by fakeXr.step(head).
function installFakeXr() {
  const perspective = (fovY, aspect, near, far) => {
    const f = 1 / Math.tan(fovY / 2), P = new Float32Array(16);
    P[0] = f / aspect; P[5] = f; P[10] = -(far + near) / (far - near); P[11] = -1; P[14] = (-2 * far * near) / (far - near);
    return P;
  };
  const transform = (p) => {
    const m = new Float32Array(16);
    m[0] = m[5] = m[10] = m[15] = 1;
    m[12] = p[0]; m[13] = p[1]; m[14] = p[2];
    return { position: { x: p[0], y: p[1], z: p[2], w: 1 }, orientation: { x: 0, y: 0, z: 0, w: 1 }, matrix: m };
  };
  const fake = { session: null, pending: null, offset: 0, started: false };
  class Session {
    async requestReferenceSpace(type) { return { type }; }
    updateRenderState(state) { this.renderState = state; }
    requestAnimationFrame(cb) { fake.pending = cb; return 1; }
    addEventListener() {}
    async end() {}
  }
  window.XRWebGLLayer = class {
    constructor(session, gl) {
      this.framebuffer = null;  // the canvas
      this.framebufferWidth = gl.canvas.width;
      this.framebufferHeight = gl.canvas.height;
    }
    getViewport(view) {
      const w = this.framebufferWidth / 2;
      return { x: view.eye === 'left' ? 0 : w, y: 0, width: w, height: this.framebufferHeight };
    }
  };
  // One frame with the head at `head` (reference space), looking down -z.
  fake.step = (head) => {
    const cb = fake.pending;
    if (!cb) return false;
    fake.pending = null;
    const eye = (name, dx) => ({ eye: name, transform: transform([head[0] + dx, head[1], head[2]]), projectionMatrix: perspective(Math.PI / 3, 1, 0.01, 100) });
    const views = [eye('left', -fake.offset), eye('right', fake.offset)];
    cb(performance.now(), { getViewerPose: () => ({ transform: transform(head), views }) });
    return true;
  };
  Object.defineProperty(navigator, 'xr', {
    configurable: true,
    value: {
      isSessionSupported: async (mode) => mode === 'immersive-vr',
      requestSession: async (mode) => {
        if (mode !== 'immersive-vr') throw new Error(`unsupported mode ${mode}`);
        fake.started = true;
        fake.session = new Session();
        return fake.session;
      },
    },
  });
  // The emulated device takes any context (Chromium's own call waits for a real device).
  WebGL2RenderingContext.prototype.makeXRCompatible = async () => {};
  window.fakeXr = fake;
}

const { server, port } = await startRangeServer();
const problems = [];
const browser = await launchChromium(chromium);
try {
  const { page, consoleLines, ready, overlay } = await openPage(browser,
    `http://127.0.0.1:${port}/web/index.html?autoplay=0&xrtime=0&clip=/tests/conformance/lightfield/bc7_bc5_zstd_mat.calf`, { init: installFakeXr });
  if (!ready) throw new Error(`the page did not open the clip: ${overlay} ${consoleLines.join(' | ')}`);
  if (!(await page.isVisible('#vr'))) problems.push('no Enter VR button with navigator.xr offering immersive-vr');
  await page.evaluate(({ offset, eye }) => {
    window.fakeXr.offset = offset;
    const c = document.getElementById('view');
    c.width = 2 * eye; c.height = eye;
  }, { offset: OFFSET, eye: EYE });
  await page.click('#vr');
  // Frames until one is drawn from data prepared for its own pose (the fetch and decode run
  // between frames).
  const frameAt = async (head) => {
    for (let i = 0; i < 400; ++i) {
      const state = await page.evaluate((h) => {
        window.fakeXr.step(h);
        const x = window.calfXr;
        return x ? { current: x.current, error: x.error, frames: x.frames } : null;
      }, head);
      if (state?.error) throw new Error(`the session's frame failed: ${state.error}`);
      if (state?.current) return state;
      await new Promise((r) => setTimeout(r, 50));
    }
    throw new Error(`no frame drawn for head ${head}: '${await page.textContent('#overlay')}' ${consoleLines.join(' | ')}`);
  };
  const first = await frameAt([0, 0, 0]);
  const started = await page.evaluate(() => window.fakeXr.started);
  if (!started) problems.push('the page did not request an immersive-vr session');
  const stereo = await page.evaluate(() => ({
    eyes: window.calfXr.eyes, rgb: Array.from(window.calfPlayer.pixels()), overlay: document.getElementById('overlay').textContent,
  }));
  console.log(`xr: session started, frame ${first.frames} drawn: '${stereo.overlay}'`);
  if (stereo.eyes.length !== 2) problems.push(`${stereo.eyes.length} eyes drawn, not 2`);
  if (!stereo.overlay.includes('two eyes')) problems.push(`the overlay does not report two eyes: '${stereo.overlay}'`);
  if (stereo.overlay.includes('outside the view volume')) problems.push(`inside the volume, the overlay says outside: '${stereo.overlay}'`);
  // The eyes' positions: the head's plus the known offsets (the page's origin is its own).
  const [l, r] = stereo.eyes.map((e) => e.camera.position);
  const sep = [r[0] - l[0], r[1] - l[1], r[2] - l[2]];
  if (Math.abs(sep[0] - 2 * OFFSET) > 1e-6 || Math.abs(sep[1]) > 1e-6 || Math.abs(sep[2]) > 1e-6) problems.push(`the eyes are ${sep} apart, not ${2 * OFFSET} along x`);
  // The halves, and the page's single-eye render of each eye's pose (no projection matrix: fovY).
  const half = (rgb, k) => {
    const out = new Uint8Array(3 * EYE * EYE);
    for (let y = 0; y < EYE; ++y) out.set(rgb.slice(3 * (y * 2 * EYE + k * EYE), 3 * (y * 2 * EYE + (k + 1) * EYE)), 3 * y * EYE);
    return out;
  };
  const halves = [half(stereo.rgb, 0), half(stereo.rgb, 1)];
  const singles = [];
  for (const e of stereo.eyes) {
    const { position, forward, up, fovY } = e.camera;
    singles.push(Uint8Array.from(await page.evaluate(async (camera) => {
      await window.calfPlayer.renderPose(camera, 0);
      return Array.from(window.calfPlayer.pixels());
    }, { position, forward, up, fovY, width: EYE, height: EYE })));
  }
  const db = (a, b) => psnr(a, b);
  const colours = colourCount(halves[0]);
  const same = [db(halves[0], singles[0]), db(halves[1], singles[1])], crossed = [db(halves[0], singles[1]), db(halves[1], singles[0])];
  const between = db(halves[0], halves[1]);
  console.log(`xr: left half against the single-eye render at the left eye ${same[0].toFixed(2)} dB, at the right eye ${crossed[0].toFixed(2)} dB; ` +
    `right half ${same[1].toFixed(2)} / ${crossed[1].toFixed(2)} dB; the halves against each other ${between.toFixed(2)} dB; ${colours} colours`);
  if (colours < 16) problems.push(`the left eye is blank (${colours} colours)`);
  for (const k of [0, 1]) {
    if (!(same[k] >= 40)) problems.push(`eye ${k}: ${same[k].toFixed(2)} dB against its single-eye render, below 40`);
    if (!(crossed[k] < same[k])) problems.push(`eye ${k}: no closer to its own pose's render than to the other eye's`);
  }
  if (!(between < 40)) problems.push(`the two halves are alike (${between.toFixed(2)} dB): the eye offset is not rendered`);
  // The head outside the view volume ([-1, 1]³): the overlay says so.
  await frameAt([3, 0, 0]);
  const outside = await page.textContent('#overlay');
  console.log(`xr: head at (3, 0, 0): '${outside}'`);
  if (!outside.includes('outside the view volume')) problems.push(`outside the view volume, the overlay says '${outside}'`);
} catch (e) {
  problems.push(e.message.split('\n')[0]);
} finally {
  await browser.close();
  server.kill();
}
for (const p of problems) console.log(`web xr: ${p}`);
console.log(`web xr: ${problems.length ? 'FAILED' : 'ok'}`);
process.exit(problems.length ? 1 : 0);
