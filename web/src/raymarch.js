// The lightfield render of calf-play's GL renderer in WebGL2: the native ray-march shader
// (glsl_raymarch.js, generated from player/src/gl_raymarch_shader.cc) after the native GLSL
// conventions, with the uniforms, view records and march range that player/src/lightfield_gl_renderer.cc
// and lightfield_representation.cc give it, and the view selection of
// player/src/view_selection.cc. Colour is uploaded per frame as decoded (one slot, t already
// applied on the CPU, SPEC §11.1.4), depth as r16 codes, coverage (§11.1.11) as the native
// coverage texels.
import { GLSL_CONVENTIONS } from './glsl_conventions.js';
import { GL_FULLSCREEN_VERTEX, GL_RAYMARCH_FRAGMENT } from './glsl_raymarch.js';
import { SRGB } from './lightfield.js';
import { E, fail } from './errors.js';

export const MAX_ACTIVE_VIEWS = 256;  // kGlMaxActiveViews

// calf-play's defaults (LightfieldRenderOptions, ViewSelectionOptions; headless: no frame budget).
export const RENDER_DEFAULTS = {
  steps: 64, refine_steps: 8, depth_footprint: 0.9, smooth_depth_ratio: 0, min_view_distance: -1,
  depth_decay: 500, cam_decay: 20, blend_views: 0, bilinear_colour: true, depth_aware_colour: true,
  colour_depth_tolerance: 0.1, colour_sharpen: 0, colour_sharpen_jump_texels: 8, mixed_texel_penalty: 3, mixed_texel_bend_texels: 5,
  tight_march_start: true, surface_hints: 1, surface_hint_margin_texels: 0.2, surface_hint_vetoes: 1,
  surface_hint_substeps: 4, supersample: 1, rr: false, rr_start: 0.05, rr_max_depth: 1,
  rr_replace_view_reflection: true, coverage: 0, coverage_threshold: 0.5, coverage_cluster: 0.05,
  coverage_agreement: 1, surface_hint_coverage: 1,
};
// The render options a page URL may set (index.html?coverage=3&hint-coverage=1&colour-sharpen=0.1&hints=4),
// named as calf-play's and bench-player_quality's options, with their ranges; the window player's
// C key turns `coverage` on (its given mode, else 3) and off.
export const RENDER_PARAMETERS = [
  { name: 'coverage', option: 'coverage', min: 0, max: 5, integer: true },
  { name: 'coverage-threshold', option: 'coverage_threshold', min: 0, max: 1, integer: false },
  { name: 'coverage-cluster', option: 'coverage_cluster', min: 0, max: Infinity, integer: false },
  { name: 'coverage-agreement', option: 'coverage_agreement', min: 1, max: 65536, integer: true },
  { name: 'hint-coverage', option: 'surface_hint_coverage', min: 0, max: 1, integer: true },
  { name: 'colour-sharpen', option: 'colour_sharpen', min: 0, max: 1, integer: false },
  { name: 'colour-sharpen-jump', option: 'colour_sharpen_jump_texels', min: 0, max: Infinity, integer: false },
  { name: 'steps', option: 'steps', min: 1, max: 65536, integer: true },
  { name: 'hints', option: 'surface_hints', min: 0, max: 4, integer: true },
  { name: 'hint-substeps', option: 'surface_hint_substeps', min: 1, max: 64, integer: true },
  { name: 'hint-vetoes', option: 'surface_hint_vetoes', min: 0, max: 65536, integer: true },
  { name: 'hint-margin', option: 'surface_hint_margin_texels', min: 0, max: Infinity, integer: false },
  { name: 'depth-decay', option: 'depth_decay', min: 0, minExclusive: true, max: Infinity, integer: false },
  { name: 'cam-decay', option: 'cam_decay', min: 0, max: Infinity, integer: false },
  { name: 'blend-views', option: 'blend_views', min: 0, max: 8, integer: true },
  { name: 'supersample', option: 'supersample', min: 1, max: 8, integer: true },
];
// The render options that `params` (URLSearchParams) give on top of RENDER_DEFAULTS; a value that
// is not a number in its range is CALF-E403, as the native renderer's options.
export function renderOptionsFromParams(params) {
  const o = { ...RENDER_DEFAULTS };
  for (const p of RENDER_PARAMETERS) {
    const text = params.get(p.name);
    if (text === null) continue;
    const x = Number(text);
    const below = p.minExclusive ? x <= p.min : x < p.min;
    if (text.trim() === '' || !Number.isFinite(x) || below || x > p.max || (p.integer && !Number.isInteger(x))) {
      const range = p.max === Infinity ? `${p.minExclusive ? '>' : '>='} ${p.min}` : `in ${p.min}..${p.max}`;
      fail(E.playerOptions, `${p.name}=${text}: expected ${p.integer ? 'an integer' : 'a finite number'} ${range}`);
    }
    o[p.option] = x;
  }
  return o;
}
export const SELECTION_DEFAULTS = { redundancy_angle_deg: 5, max_active: 9, incumbent_margin: 0.05 };

// GLSL 4.50 → GLSL ES 3.00: ES has no binding qualifier (the page sets sampler units and the
// block binding from JavaScript instead); everything else compiles as it is.
export function fragmentSource({ depthBc5 = false, hints = 1, coverage = false } = {}) {
  let body = GL_RAYMARCH_FRAGMENT;
  const rewrites = [[/layout\(std140, binding = 0\) uniform CalfViews/, 'layout(std140) uniform CalfViews'],
    [/layout\(binding = (\d)\) uniform/g, 'uniform']];
  for (const [from, to] of rewrites) {
    if (!from.test(body)) throw new Error(`raymarch: the native shader no longer has ${from}`);
    body = body.replace(from, to);
  }
  return '#version 300 es\nprecision highp float;\nprecision highp int;\n' +
    'precision highp sampler2DArray;\nprecision highp usampler2DArray;\n' +
    `#define CALF_MAX_VIEWS ${MAX_ACTIVE_VIEWS}\n${depthBc5 ? '#define CALF_DEPTH_BC5\n' : ''}` +
    `#define CALF_HINTS ${hints}\n${coverage ? '#define CALF_COVERAGE\n' : ''}${GLSL_CONVENTIONS}${body}`;
}

const PRESENT = `#version 300 es
precision highp float;
uniform highp sampler2D frame_tex;
uniform ivec2 origin;  // the viewport's lower left corner (one eye of a stereo frame)
out vec4 out_colour;
// srgb8_from_linear (player/src/image_compare.cc): clamp, sRGB transfer.
vec3 srgb(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}
void main() { out_colour = vec4(srgb(texelFetch(frame_tex, ivec2(gl_FragCoord.xy) - origin, 0).rgb), 1.0); }`;

const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const len = (a) => Math.sqrt(dot(a, a));
const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const normalize = (a) => scale(a, 1 / len(a));
function angleBetween(a, b) {  // sampling.cc: atan2(|a x b|, a . b)
  return Math.atan2(len(cross(a, b)), dot(a, b));
}

// ViewSelector::select without a frame budget or view cone (calf-play headless): rank by
// distance (incumbents discounted), drop views within the redundancy angle of a kept one, keep
// at most max_active. `state.wasActive` carries the incumbents from frame to frame.
export function selectViews(views, eye, state, o = SELECTION_DEFAULTS) {
  if (!state.wasActive) state.wasActive = new Uint8Array(views.length);
  const ranked = [];
  views.forEach((v, i) => {
    if (!v) return;  // dropped view (excluded)
    const distance = len(sub(v.position, eye));
    let key = distance;
    if (state.wasActive[i]) key *= 1 - o.incumbent_margin;
    ranked.push({ view: i, key: Number.isNaN(key) ? Infinity : key, distance });
  });
  ranked.sort((a, b) => (a.key !== b.key ? a.key - b.key : a.distance !== b.distance ? a.distance - b.distance : a.view - b.view));
  const red = (o.redundancy_angle_deg * Math.PI) / 180;
  const kept = [];
  for (const r of ranked) {
    if (kept.length === o.max_active) continue;
    const dir = sub(views[r.view].position, eye);
    let redundant = false;
    if (red > 0 && r.distance !== 0) {
      for (const k of kept) {
        const kdir = sub(views[k].position, eye);
        if (len(kdir) > 0 && angleBetween(dir, kdir) < red) { redundant = true; break; }
      }
    }
    if (!redundant) kept.push(r.view);
  }
  state.wasActive = new Uint8Array(views.length);
  for (const v of kept) state.wasActive[v] = 1;
  return kept;
}

// march_range_for over every usable view of the clip (LightfieldRepresentation::frame_options).
export function marchRange(views, eye) {
  let far = 0, near = Infinity;
  for (const v of views) {
    if (!v) continue;
    far = Math.max(far, len(sub(eye, v.position)) + v.zFar);
    near = Math.min(near, v.zNear / 4);
  }
  return { near: Math.max(near, far / (1 << 20)), far };
}

// glsl_log_range: ln z_near and the step in double, rounded to float once.
function logRange(v) {
  const step = (Math.log(v.zFar) - Math.log(v.zNear)) / 65534;
  return { log_near: Math.log(v.zNear), step, inv_step: 1 / step };
}

function compile(gl, type, source, what) {
  const s = gl.createShader(type);
  gl.shaderSource(s, source);
  gl.compileShader(s);
  if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(`${what} shader: ${gl.getShaderInfoLog(s).split('\n')[0]}`);
  return s;
}

// Linked programs by context and source: a second clip opened on the same canvas reuses them
// (SwiftShader takes seconds to compile the ray march). link() makes one when none is kept.
const programs = new WeakMap();
export function keptProgram(gl, vs, fs, link) {
  if (!programs.has(gl)) programs.set(gl, new Map());
  const known = programs.get(gl), key = `${vs}\n//\n${fs}`;
  if (!known.has(key)) known.set(key, link());
  return known.get(key);
}

function program(gl, vs, fs, what) {
  return keptProgram(gl, vs, fs, () => linkProgram(gl, vs, fs, what));
}

function linkProgram(gl, vs, fs, what) {
  const p = gl.createProgram();
  gl.attachShader(p, compile(gl, gl.VERTEX_SHADER, vs, what));
  gl.attachShader(p, compile(gl, gl.FRAGMENT_SHADER, fs, what));
  gl.linkProgram(p);
  if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(`${what} program: ${gl.getProgramInfoLog(p).split('\n')[0]}`);
  return p;
}

// The compressed colour texture for a BCn colour format where the browser exposes it (the
// native GlViews formats: sRGB BC1 and BC7, unsigned BC6H), else null (decode to RGBA).
export function bcUpload(gl, format, faceSize) {
  if (faceSize % 4 !== 0) return null;
  if (format === 4) {  // bc1
    const e = gl.getExtension('WEBGL_compressed_texture_s3tc_srgb');
    return e && { internal: e.COMPRESSED_SRGB_S3TC_DXT1_EXT, blockBytes: 8, name: 'BC1 (WEBGL_compressed_texture_s3tc_srgb)' };
  }
  if (format === 8 || format === 7) {  // bc7, bc6h
    const e = gl.getExtension('EXT_texture_compression_bptc');
    if (!e) return null;
    return format === 8 ? { internal: e.COMPRESSED_SRGB_ALPHA_BPTC_UNORM_EXT, blockBytes: 16, name: 'BC7 (EXT_texture_compression_bptc)' }
      : { internal: e.COMPRESSED_RGB_BPTC_UNSIGNED_FLOAT_EXT, blockBytes: 16, name: 'BC6H (EXT_texture_compression_bptc)' };
  }
  return null;
}

// The texture of colour decoded on the CPU, by colour format: AV1 pictures as the native player
// uploads them (GlViews: av1 and av1-444 as rgba8's sRGB bytes, SRGB8_ALPHA8; av1hdr and
// av1hdr-444 as rgba16f's halves, RGBA16F), any other format as binary32 (RGBA32F).
export function cpuUpload(gl, format) {
  if (format === 12 || format === 14) return { internal: gl.SRGB8_ALPHA8, srgb: true, name: 'SRGB8_ALPHA8 (AV1, decoded on the CPU)' };
  if (format === 13 || format === 15) return { internal: gl.RGBA16F, srgb: false, name: 'RGBA16F (HDR AV1, decoded on the CPU)' };
  return { internal: gl.RGBA32F, srgb: false, name: 'RGBA32F (decoded on the CPU)' };
}

// The sRGB byte whose rgba8 decoding (§11.1.5, lightfield.js's SRGB) is `v`: the colour of an
// av1 picture went through it, so this is exact.
function srgbByte(v) {
  let lo = 0, hi = 255;
  while (lo < hi) {
    const mid = (lo + hi) >> 1;
    if (SRGB[mid] < v) lo = mid + 1;
    else hi = mid;
  }
  return lo;
}

// A renderer for one lightfield track: `views` are the clip's view records (null: dropped),
// faces of `faceSize` texels in cells of `cellSize`. With `bc` (bcUpload), colour keyframes are
// uploaded as blocks into two slots a face and the cell texture holds each cell's slot and t, as
// in the native player; without, one slot of `cpu` (cpuUpload) holds the colour the CPU decoded.
// With `coverage` (the clip has a coverage stream) the shader is compiled with CALF_COVERAGE and
// every view has six coverage layers (layer 6 × view + face, as the native GlViews lays out a
// clip whose views all carry coverage); without, the shader is the one without coverage.
// `options` are read at each render (the C key changes options.coverage).
export function makeRaymarcher(gl, { views, faceSize, cellSize, options = { ...RENDER_DEFAULTS }, bc = null, cpu = cpuUpload(gl, 0), coverage = false }) {
  if (!gl.getExtension('EXT_color_buffer_float')) throw new Error('WebGL2 without EXT_color_buffer_float: no float render target');
  const vertex = `#version 300 es\n${GL_FULLSCREEN_VERTEX}`;
  const march = program(gl, vertex, fragmentSource({ hints: options.surface_hints, coverage }), 'ray-march');
  const present = program(gl, vertex, PRESENT, 'present');
  const N = faceSize, layers = 6 * views.length, cellsPerSide = Math.ceil(N / cellSize);
  const texture = (unit, internal, w, h, d) => {
    const t = gl.createTexture();
    gl.activeTexture(gl.TEXTURE0 + unit);
    gl.bindTexture(gl.TEXTURE_2D_ARRAY, t);
    gl.texStorage3D(gl.TEXTURE_2D_ARRAY, 1, internal, w, h, d);
    gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
    gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
    return t;
  };
  // Units as the native binding qualifiers: colour 0, depth 1, cells 2, material 3.
  const slots = bc ? 2 : 1;
  const colourTex = texture(0, bc ? bc.internal : cpu.internal, N, N, slots * layers);
  const depthTex = texture(1, gl.R16UI, N, N, layers);
  const cellTex = texture(2, gl.R32UI, cellsPerSide, cellsPerSide, layers);
  gl.texSubImage3D(gl.TEXTURE_2D_ARRAY, 0, 0, 0, 0, cellsPerSide, cellsPerSide, layers, gl.RED_INTEGER, gl.UNSIGNED_INT,
    new Uint32Array(cellsPerSide * cellsPerSide * layers));  // slot 0, t = 0: the colour as uploaded
  const materialTex = texture(3, gl.RGBA8, 1, 1, 1);
  // Coverage texels (RGBA8UI: mask low byte, mask high byte, near count, far count), cleared to
  // the plain texel (mask 0xFFFF: every cell its own surface) as the native renderer clears them;
  // a one-texel placeholder without coverage.
  const coverageLayers = coverage ? layers : 1, coverageSide = coverage ? N : 1;
  const coverageTex = texture(4, gl.RGBA8UI, coverageSide, coverageSide, coverageLayers);
  const plain = new Uint8Array(4 * coverageSide * coverageSide * coverageLayers);
  for (let i = 0; i < plain.length; i += 4) plain[i] = plain[i + 1] = 255;
  gl.texSubImage3D(gl.TEXTURE_2D_ARRAY, 0, 0, 0, 0, coverageSide, coverageSide, coverageLayers, gl.RGBA_INTEGER, gl.UNSIGNED_BYTE, plain);
  gl.useProgram(march);
  ['colour_tex', 'depth_tex', 'cell_tex', 'material_tex', 'coverage_tex'].forEach((name, unit) => gl.uniform1i(gl.getUniformLocation(march, name), unit));
  gl.uniformBlockBinding(march, gl.getUniformBlockIndex(march, 'CalfViews'), 0);
  const viewBuffer = gl.createBuffer();
  const vao = gl.createVertexArray();
  let target = null, targetTex = null, targetW = 0, targetH = 0;
  const rgba = cpu.srgb ? new Uint8Array(4 * N * N) : new Float32Array(4 * N * N);

  // colour: 3 floats a texel (linear RGB), depth: r16 codes, of one face of one view. RGBA16F
  // takes the floats as they are (the colour of a format it serves is half floats: exact).
  function uploadFace(view, face, colour, depth) {
    if (cpu.srgb) {
      for (let i = 0; i < N * N; ++i) {
        rgba[4 * i] = srgbByte(colour[3 * i]); rgba[4 * i + 1] = srgbByte(colour[3 * i + 1]); rgba[4 * i + 2] = srgbByte(colour[3 * i + 2]); rgba[4 * i + 3] = 255;
      }
    } else {
      for (let i = 0; i < N * N; ++i) {
        rgba[4 * i] = colour[3 * i]; rgba[4 * i + 1] = colour[3 * i + 1]; rgba[4 * i + 2] = colour[3 * i + 2]; rgba[4 * i + 3] = 1;
      }
    }
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D_ARRAY, colourTex);
    gl.texSubImage3D(gl.TEXTURE_2D_ARRAY, 0, 0, 0, 6 * view + face, N, N, 1, gl.RGBA, cpu.srgb ? gl.UNSIGNED_BYTE : gl.FLOAT, rgba);
    gl.activeTexture(gl.TEXTURE1);
    gl.bindTexture(gl.TEXTURE_2D_ARRAY, depthTex);
    gl.texSubImage3D(gl.TEXTURE_2D_ARRAY, 0, 0, 0, 6 * view + face, N, N, 1, gl.RED_INTEGER, gl.UNSIGNED_SHORT, depth);
  }

  // The depth codes of one face of one view.
  function uploadDepth(view, face, depth) {
    gl.activeTexture(gl.TEXTURE1);
    gl.bindTexture(gl.TEXTURE_2D_ARRAY, depthTex);
    gl.texSubImage3D(gl.TEXTURE_2D_ARRAY, 0, 0, 0, 6 * view + face, N, N, 1, gl.RED_INTEGER, gl.UNSIGNED_SHORT, depth);
  }
  // The coverage of one face of one view: 4 bytes a texel (coverageGpuBytes).
  function uploadCoverage(view, face, bytes) {
    gl.activeTexture(gl.TEXTURE4);
    gl.bindTexture(gl.TEXTURE_2D_ARRAY, coverageTex);
    gl.texSubImage3D(gl.TEXTURE_2D_ARRAY, 0, 0, 0, 6 * view + face, N, N, 1, gl.RGBA_INTEGER, gl.UNSIGNED_BYTE, bytes);
  }
  // BCn: a keyframe's blocks (rect's blocks row by row) into a slot of one face of one view.
  function uploadBlocks(view, face, slot, rect, blocks) {
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D_ARRAY, colourTex);
    gl.compressedTexSubImage3D(gl.TEXTURE_2D_ARRAY, 0, rect.x, rect.y, slots * (6 * view + face) + slot, rect.w, rect.h, 1, bc.internal, blocks);
  }
  // BCn: the cells of one face of one view: (slot a << 8) | t per cell (the native cell texture).
  function uploadCells(view, face, values) {
    gl.activeTexture(gl.TEXTURE2);
    gl.bindTexture(gl.TEXTURE_2D_ARRAY, cellTex);
    gl.texSubImage3D(gl.TEXTURE_2D_ARRAY, 0, 0, 0, 6 * view + face, cellsPerSide, cellsPerSide, 1, gl.RED_INTEGER, gl.UNSIGNED_INT, values);
  }

  // camera: { position, forward, up, fovY (radians), width, height, projection (optional: a
  // column-major perspective matrix, e.g. an XRView's, whose frustum replaces fovY) }; active:
  // clip view indices. Draws into the canvas (sRGB, as calf-play's PNG frames), or into
  // out.framebuffer at out.viewport (one eye of a WebXR frame).
  function render(camera, active, out = null) {
    const o = options;
    const { near, far } = marchRange(views, camera.position);
    const fwd = normalize(camera.forward), right = normalize(cross(fwd, camera.up)), up = cross(right, fwd);
    const h = Math.tan(camera.fovY / 2), aspect = camera.width / camera.height;
    // The eye ray through NDC (a, b) is forward + a right + b up; a perspective matrix P puts it
    // at forward + (a + P[8]) / P[0] right + (b + P[9]) / P[5] up.
    const P = camera.projection;
    const rayForward = P ? [0, 1, 2].map((k) => fwd[k] + (P[8] / P[0]) * right[k] + (P[9] / P[5]) * up[k]) : fwd;
    const rayRight = P ? scale(right, 1 / P[0]) : scale(right, h * aspect), rayUp = P ? scale(up, 1 / P[5]) : scale(up, h);
    // The std140 records of CalfView: 13 scalars padded to 64 bytes each.
    const records = new ArrayBuffer(MAX_ACTIVE_VIEWS * 64);
    const f32 = new Float32Array(records), u32 = new Uint32Array(records), i32 = new Int32Array(records);
    active.forEach((v, k) => {
      const info = views[v], r = logRange(info), b = 16 * k;
      f32.set([info.position[0] - camera.position[0], info.position[1] - camera.position[1], info.position[2] - camera.position[2],
        r.log_near, r.step, r.inv_step, info.zNear, info.zFar], b);
      // No material layer (the page draws none); the view's coverage layers where the clip has them.
      u32[b + 8] = N; u32[b + 9] = cellSize; u32[b + 10] = 6 * v; i32[b + 11] = -1; i32[b + 12] = coverage ? 6 * v : -1;
    });
    gl.bindBuffer(gl.UNIFORM_BUFFER, viewBuffer);
    gl.bufferData(gl.UNIFORM_BUFFER, records, gl.STREAM_DRAW);
    gl.bindBufferBase(gl.UNIFORM_BUFFER, 0, viewBuffer);
    [colourTex, depthTex, cellTex, materialTex, coverageTex].forEach((t, unit) => {
      gl.activeTexture(gl.TEXTURE0 + unit);
      gl.bindTexture(gl.TEXTURE_2D_ARRAY, t);
    });
    if (!target || targetW !== camera.width || targetH !== camera.height) {
      if (target) { gl.deleteFramebuffer(target); gl.deleteTexture(targetTex); }
      targetTex = gl.createTexture();
      gl.activeTexture(gl.TEXTURE5);
      gl.bindTexture(gl.TEXTURE_2D, targetTex);
      gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA32F, camera.width, camera.height);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
      target = gl.createFramebuffer();
      gl.bindFramebuffer(gl.FRAMEBUFFER, target);
      gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, targetTex, 0);
      targetW = camera.width; targetH = camera.height;
    }
    gl.bindFramebuffer(gl.FRAMEBUFFER, target);
    gl.useProgram(march);
    const U = (name) => gl.getUniformLocation(march, name);
    gl.uniform1ui(U('view_count'), active.length);
    gl.uniform1ui(U('colour_slots'), slots);
    gl.uniform1ui(U('steps'), o.steps);
    gl.uniform1ui(U('refine_steps'), o.refine_steps);
    gl.uniform1f(U('march_near'), near);
    gl.uniform1f(U('march_log_ratio'), Math.log(far / near));
    gl.uniform1f(U('min_view_distance'), o.min_view_distance < 0 ? near : o.min_view_distance);
    gl.uniform1f(U('footprint_limit'), o.depth_footprint - 1e-9);
    gl.uniform1f(U('smooth_log_ratio'), Math.log1p(o.smooth_depth_ratio));
    gl.uniform1f(U('depth_decay'), o.depth_decay);
    gl.uniform1f(U('cam_decay'), o.cam_decay);
    gl.uniform1ui(U('blend_views'), o.blend_views);
    gl.uniform1f(U('colour_depth_tolerance'), o.colour_depth_tolerance);
    gl.uniform1f(U('colour_sharpen'), o.colour_sharpen);
    gl.uniform1f(U('colour_sharpen_jump_texels'), o.colour_sharpen_jump_texels);
    gl.uniform1f(U('mixed_penalty_factor'), Math.exp(-o.mixed_texel_penalty));
    gl.uniform1f(U('mixed_texel_bend_texels'), o.mixed_texel_bend_texels);
    gl.uniform1ui(U('coverage_mode'), o.coverage);
    gl.uniform1f(U('coverage_threshold'), o.coverage_threshold);
    gl.uniform1f(U('coverage_cluster'), o.coverage_cluster);
    gl.uniform1ui(U('coverage_agreement'), o.coverage_agreement);
    gl.uniform1i(U('tight_march_start'), o.tight_march_start ? 1 : 0);
    gl.uniform1i(U('bilinear_colour'), o.bilinear_colour ? 1 : 0);
    gl.uniform1i(U('depth_aware_colour'), o.depth_aware_colour ? 1 : 0);
    gl.uniform1f(U('surface_hint_margin_texels'), o.surface_hint_margin_texels);
    gl.uniform1ui(U('surface_hint_vetoes'), o.surface_hint_vetoes);
    gl.uniform1ui(U('surface_hint_substeps'), o.surface_hint_substeps);
    gl.uniform1ui(U('surface_hint_coverage'), o.surface_hint_coverage);
    gl.uniform1i(U('rr'), 0);  // no material textures on the page yet
    gl.uniform1i(U('rr_replace_view_reflection'), o.rr_replace_view_reflection ? 1 : 0);
    gl.uniform1f(U('rr_start'), o.rr_start);
    gl.uniform1ui(U('rr_max_depth'), o.rr_max_depth);
    gl.uniform2ui(U('image_size'), camera.width, camera.height);
    gl.uniform1ui(U('supersample'), o.supersample);
    // Every ray of the pixel in one pass (calf-play draws one pass per ray for llvmpipe's loop
    // limit; browsers' GPUs have none).
    gl.uniform1ui(U('ray_first'), 0);
    gl.uniform1ui(U('ray_count'), o.supersample * o.supersample);
    gl.uniform3f(U('cam_forward'), ...rayForward);
    gl.uniform3f(U('cam_right'), ...rayRight);
    gl.uniform3f(U('cam_up'), ...rayUp);
    for (const cap of [gl.DEPTH_TEST, gl.BLEND, gl.SCISSOR_TEST, gl.CULL_FACE, gl.STENCIL_TEST]) gl.disable(cap);
    gl.viewport(0, 0, camera.width, camera.height);
    gl.bindVertexArray(vao);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    gl.bindFramebuffer(gl.FRAMEBUFFER, out ? out.framebuffer : null);
    const vp = out ? out.viewport : { x: 0, y: 0 };
    gl.viewport(vp.x, vp.y, camera.width, camera.height);
    gl.useProgram(present);
    gl.activeTexture(gl.TEXTURE5);
    gl.bindTexture(gl.TEXTURE_2D, targetTex);
    gl.uniform1i(gl.getUniformLocation(present, 'frame_tex'), 5);
    gl.uniform2i(gl.getUniformLocation(present, 'origin'), vp.x, vp.y);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    gl.bindVertexArray(null);
  }
  return { uploadFace, uploadDepth, uploadCoverage, uploadBlocks, uploadCells, render, options };
}
