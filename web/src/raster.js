// The tiles and mesh draws of calf-play's GL rasterisers (player/src/tiles_gl_renderer.cc,
// mesh_gl_renderer.cc) in WebGL2. Each track renders into a float layer holding linear colour and
// the radial distance from the eye (+inf where nothing is drawn); the layers are composited by
// depth in track order (Playback::render: a later layer wins where strictly nearer), and the
// result goes to the canvas through sRGB, as calf-play's PNG frames.
//
// Shared with the native source (web/src/glsl_raster.js, generated): the tiles vertex shader and
// the mesh fragment shader, verbatim. WebGL2 has no geometry shader, storage buffers or
// dual-source blending, so:
// - mesh: the geometry shader's work (per-triangle subset, material, texture pass, the face normal
//   and the side facing the eye) is done per pose on the CPU, which hands the fragment shader
//   the same varyings (eye-relative positions in double, as the native CPU folds the eye in);
// - tiles: the occlusion pre-pass keeps each pixel's nearest distance with alpha ≥ 0.9 through a
//   depth-tested pass into a float texture instead of atomicMin; the sorted pass blends
//   premultiplied colour (out = src + (1 − src.a) dst); a last depth-tested pass writes the
//   nearest distance with alpha ≥ 0.5 into the layer's fourth channel (the native MIN blend).
import { GL_TILES_VERTEX, GL_MESH_FRAGMENT } from './glsl_raster.js';
import { GLSL_CONVENTIONS } from './glsl_conventions.js';
import { keptProgram } from './raymarch.js';

const PROLOGUE = '#version 300 es\nprecision highp float;\nprecision highp int;\nprecision highp sampler2D;\nprecision highp sampler2DArray;\n';
const NEAR = 0.01;  // MeshRenderOptions::near, TilesRenderOptions::near
const KEY_LIGHT = [0.30304576, 0.80812204, 0.50507627], AMBIENT = 0.3;  // calf/format/mesh_lighting.h
const OCCLUSION_ALPHA = 0.9, OCCLUSION_EPSILON = 0.001;  // calf-play's --tiles-occlusion-* defaults
const NONE = 0xffffffff;

// Per-vertex inputs of the mesh fragment shader, from the CPU geometry stage.
const MESH_VERTEX = `
layout(location = 0) in vec3 position;  // object space
layout(location = 1) in vec3 normal;    // world, turned to the eye's side (the geometry shader's g_normal)
layout(location = 2) in vec3 colour;
layout(location = 3) in vec2 uv;
layout(location = 4) in vec3 base;
layout(location = 5) in vec3 emission;
layout(location = 6) in float textured;
// Object -> eye-relative world: columns of the 3 x 3 part and the translation minus the eye.
uniform vec3 model_x, model_y, model_z, model_t;
uniform CalfRasterCamera calf_camera;  // the GLSL conventions (glsl_conventions.js)
out vec3 g_rel;
out vec3 g_normal;
out vec3 g_colour;
out vec2 g_uv;
flat out vec3 g_base;
flat out vec3 g_emission;
flat out int g_textured;
void main() {
  g_rel = model_x * position.x + model_y * position.y + model_z * position.z + model_t;
  g_normal = normal; g_colour = colour; g_uv = uv;
  g_base = base; g_emission = emission; g_textured = int(textured);
  gl_Position = calf_raster_position(g_rel, calf_camera);
}
`;

// The tiles fragment shader without storage buffers: `mode` 0 the sorted colour pass (with the
// occlusion test against the pre-pass's texture), 1 the nearest distance of fragments whose alpha
// is at least `threshold` (depth-tested; the pre-pass and the layer's depth).
const TILES_FRAGMENT = `
in vec3 v_rel;
in vec3 v_uvw;
uniform sampler2DArray atlas;
uniform sampler2D occluders;
uniform int mode;
uniform bool occlusion_test;
uniform float occlusion_behind, threshold;
out vec4 out_colour;
void main() {
  vec4 t = texture(atlas, vec3(v_uvw.xy / v_uvw.z, 0.0));
  float d = length(v_rel);
  if (mode == 1) {
    if (t.a < threshold) discard;
    out_colour = vec4(d);
    gl_FragDepth = d / (1.0 + d);
    return;
  }
  if (occlusion_test && d > texelFetch(occluders, ivec2(gl_FragCoord.xy), 0).r * occlusion_behind) discard;
  out_colour = t;
}
`;

const FULLSCREEN = `
void main() {
  vec2 p = vec2(float((gl_VertexID & 1) << 2) - 1.0, float((gl_VertexID & 2) << 1) - 1.0);
  gl_Position = vec4(p, 0.0, 1.0);
}
`;

// composite_nearest (player/src/rendered_image.cc): the layer where strictly nearer.
const COMPOSITE = `
uniform sampler2D base_layer, layer;
out vec4 out_colour;
void main() {
  vec4 a = texelFetch(base_layer, ivec2(gl_FragCoord.xy), 0), b = texelFetch(layer, ivec2(gl_FragCoord.xy), 0);
  out_colour = b.a < a.a ? b : a;
}
`;

// The tiles layer: the blended colour and, from its own float texture, the distance.
const MERGE = `
uniform sampler2D colour_tex, distance_tex;
out vec4 out_colour;
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  out_colour = vec4(texelFetch(colour_tex, p, 0).rgb, texelFetch(distance_tex, p, 0).r);
}
`;

// srgb8_from_linear (player/src/image_compare.cc): clamp, sRGB transfer.
const PRESENT = `
uniform sampler2D frame_tex;
uniform ivec2 origin;
out vec4 out_colour;
vec3 srgb(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}
void main() { out_colour = vec4(srgb(texelFetch(frame_tex, ivec2(gl_FragCoord.xy) - origin, 0).rgb), 1.0); }
`;

function program(gl, vs, fs, what) {
  return keptProgram(gl, vs, fs, () => linkProgram(gl, vs, fs, what));
}

function linkProgram(gl, vs, fs, what) {
  const p = gl.createProgram();
  for (const [type, src] of [[gl.VERTEX_SHADER, vs], [gl.FRAGMENT_SHADER, fs]]) {
    const s = gl.createShader(type);
    gl.shaderSource(s, PROLOGUE + src);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(`${what}: ${gl.getShaderInfoLog(s)}`);
    gl.attachShader(p, s);
  }
  gl.linkProgram(p);
  if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(`${what}: ${gl.getProgramInfoLog(p)}`);
  return p;
}

const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const normalize = (a) => { const l = Math.sqrt(dot(a, a)); return [a[0] / l, a[1] / l, a[2] / l]; };

// camera_frame (format/src/camera.cc) and the projection uniforms of both rasterisers.
function setCamera(gl, p, camera) {
  const forward = normalize(camera.forward), right = normalize(cross(forward, camera.up)), up = cross(right, forward);
  const h = Math.tan(camera.fovY / 2);
  const U = (n) => gl.getUniformLocation(p, n);
  gl.uniform3fv(U('calf_camera.right'), right);
  gl.uniform3fv(U('calf_camera.up'), up);
  gl.uniform3fv(U('calf_camera.forward'), forward);
  gl.uniform1f(U('calf_camera.scale_x'), (h * camera.width) / camera.height);
  gl.uniform1f(U('calf_camera.scale_y'), h);
  gl.uniform1f(U('calf_camera.near_distance'), NEAR);
}

// linear_from_srgb (format/src/colour.cc), in double, rounded to binary32.
function linearFromSrgb(v) {
  if (!(v > 0)) return 0;
  const c = v >= 1 ? 1 : v;
  return Math.fround(c <= 0.04045 ? c / 12.92 : Math.pow((c + 0.055) / 1.055, 2.4));
}

// binary32 → binary16, round to nearest even (bc::float_to_half for the finite values here).
const f32 = new Float32Array(1), u32 = new Uint32Array(f32.buffer);
export function floatToHalf(x) {
  f32[0] = x;
  const b = u32[0], sign = (b >>> 16) & 0x8000, e = (b >>> 23) & 0xff, m = b & 0x7fffff;
  if (e === 0xff) return sign | 0x7c00 | (m ? 0x200 : 0);
  let exp = e - 127 + 15;
  if (exp >= 0x1f) return sign | 0x7c00;
  if (exp <= 0) {
    if (exp < -10) return sign;
    const mm = m | 0x800000, shift = 14 - exp;
    let h = mm >>> shift;
    const rem = mm & ((1 << shift) - 1), half = 1 << (shift - 1);
    if (rem > half || (rem === half && (h & 1))) ++h;
    return sign | h;
  }
  let h = (exp << 10) | (m >>> 13);
  const rem = m & 0x1fff;
  if (rem > 0x1000 || (rem === 0x1000 && (h & 1))) ++h;
  return sign | h;
}

// tiles_linear_atlas (player/src/tiles_atlas.cc): premultiplied sRGB bytes → premultiplied
// linear halves, a = A / 255, rgb = a · linear_from_srgb(min(1, C / A)).
export function tilesLinearAtlas(rgba) {
  const table = new Uint16Array(256 * 256);
  for (let a = 1; a < 256; ++a) {
    for (let c = 0; c < 256; ++c) {
      const enc = Math.min(1, Math.fround(c / a));
      table[256 * a + c] = floatToHalf(Math.fround(Math.fround(a / 255) * linearFromSrgb(enc)));
    }
  }
  const out = new Uint16Array(rgba.length);
  for (let k = 0; k < rgba.length; k += 4) {
    const row = 256 * rgba[k + 3];
    out[k] = table[row + rgba[k]]; out[k + 1] = table[row + rgba[k + 1]]; out[k + 2] = table[row + rgba[k + 2]];
    out[k + 3] = floatToHalf(Math.fround(rgba[k + 3] / 255));
  }
  return out;
}

// The mip chain of a mesh texture (SPEC §11.4.6, calf/format/mesh_texture.h): box filter in
// linear light, re-encoded to the nearest byte; alpha (sum + 2) / 4.
const SRGB_LINEAR = Float64Array.from({ length: 256 }, (_, i) => { const c = i / 255; return c <= 0.04045 ? c / 12.92 : Math.pow((c + 0.055) / 1.055, 2.4); });
function srgbByte(l) {  // the byte whose decoded value is nearest l
  let lo = 0, hi = 255;
  while (lo < hi) { const mid = (lo + hi + 1) >> 1; if (SRGB_LINEAR[mid] <= l) lo = mid; else hi = mid - 1; }
  return lo < 255 && SRGB_LINEAR[lo + 1] - l < l - SRGB_LINEAR[lo] ? lo + 1 : lo;
}
export function mipChain(W, H, texels) {
  const levels = [{ w: W, h: H, texels }];
  while (levels.at(-1).w > 1 || levels.at(-1).h > 1) {
    const p = levels.at(-1), w = Math.max(1, p.w >> 1), h = Math.max(1, p.h >> 1), out = new Uint8Array(4 * w * h);
    for (let y = 0; y < h; ++y) {
      for (let x = 0; x < w; ++x) {
        for (let c = 0; c < 4; ++c) {
          let s = 0;
          for (let j = 0; j < 2; ++j) {
            for (let i = 0; i < 2; ++i) {
              const v = p.texels[4 * (Math.min(2 * y + j, p.h - 1) * p.w + Math.min(2 * x + i, p.w - 1)) + c];
              s += c < 3 ? SRGB_LINEAR[v] : v;
            }
          }
          out[4 * (y * w + x) + c] = c < 3 ? srgbByte(s / 4) : (s + 2) >> 2;
        }
      }
    }
    levels.push({ w, h, texels: out });
  }
  return levels;
}

// A float render target of w × h: RGBA colour (fourth channel: distance) and a 32-bit depth buffer.
function makeTarget(gl, w, h, format) {
  const tex = gl.createTexture();
  gl.bindTexture(gl.TEXTURE_2D, tex);
  gl.texStorage2D(gl.TEXTURE_2D, 1, format, w, h);
  for (const [k, v] of [[gl.TEXTURE_MIN_FILTER, gl.NEAREST], [gl.TEXTURE_MAG_FILTER, gl.NEAREST]]) gl.texParameteri(gl.TEXTURE_2D, k, v);
  const depth = gl.createRenderbuffer();
  gl.bindRenderbuffer(gl.RENDERBUFFER, depth);
  gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH_COMPONENT32F, w, h);
  const fb = gl.createFramebuffer();
  gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
  gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0);
  gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.RENDERBUFFER, depth);
  if (gl.checkFramebufferStatus(gl.FRAMEBUFFER) !== gl.FRAMEBUFFER_COMPLETE) throw new Error('raster: incomplete float render target');
  return { tex, depth, fb, w, h };
}

// positions_at (SPEC §11.4.3): the vertex positions of prototype d at time tau, binary32.
function positionsAt(d, tau) {
  const S = d.times.length, pos = new Float32Array(d.positions.buffer, d.positions.byteOffset, d.positions.length);
  if (S === 0) return pos;
  const times = new Float32Array(d.times.buffer, d.times.byteOffset, S);
  const state = (k) => new Float32Array(d.states[k].buffer, d.states[k].byteOffset, d.states[k].length);
  if (tau <= times[0]) return state(0);
  if (tau >= times[S - 1]) return state(S - 1);
  let a = 0;
  while (a + 1 < S && times[a + 1] <= tau) ++a;
  const A = state(a), B = state(a + 1), w = Math.fround((tau - times[a]) / (times[a + 1] - times[a]));
  const out = new Float32Array(A.length);
  for (let i = 0; i < A.length; ++i) out[i] = Math.fround(A[i] + Math.fround(w * Math.fround(B[i] - A[i])));
  return out;
}

// The mesh track's draw: everything decoded at open (the tracks this plays are small).
export async function loadMesh(mesh) {
  const ix = mesh.index, prototypes = [], objects = [], textures = [];
  for (let p = 0; p < ix.prototypes.length; ++p) prototypes.push(await mesh.prototype(p));
  for (let o = 0; o < ix.objects.length; ++o) objects.push(await mesh.object(o));
  for (let x = 0; x < ix.textures.length; ++x) textures.push(await mesh.texture(x));
  return { kind: 'mesh', index: ix, prototypes, objects, textures, frameCount: mesh.header.frame_count,
    fps: mesh.header.fps_numerator / mesh.header.fps_denominator, triangles: Number(mesh.header.triangle_count) };
}

export async function loadTiles(tl) {
  return { kind: 'tiles', index: tl.index, n: tl.header.tile_count, quads: await tl.quads(), atlas: await tl.atlas(),
    W: tl.header.atlas_width, H: tl.header.atlas_height, frameCount: 1 };
}

export function makeRaster(gl) {
  if (!gl.getExtension('EXT_color_buffer_float')) throw new Error('WebGL2 without EXT_color_buffer_float: no float render target');
  const floatBlend = !!gl.getExtension('EXT_float_blend');
  const meshProgram = program(gl, GLSL_CONVENTIONS + MESH_VERTEX, GL_MESH_FRAGMENT, 'the mesh program');
  const tilesProgram = program(gl, GLSL_CONVENTIONS + GL_TILES_VERTEX, TILES_FRAGMENT, 'the tiles program');
  const compositeProgram = program(gl, FULLSCREEN, COMPOSITE, 'the composite program');
  const presentProgram = program(gl, FULLSCREEN, PRESENT, 'the present program');
  const mergeProgram = program(gl, FULLSCREEN, MERGE, 'the tiles merge program');
  const emptyVao = gl.createVertexArray();
  let targets = null;
  function ensureTargets(w, h) {
    if (targets && targets.w === w && targets.h === h) return;
    targets = { w, h, layers: [0, 1, 2].map(() => makeTarget(gl, w, h, gl.RGBA32F)),
      tiles: makeTarget(gl, w, h, floatBlend ? gl.RGBA32F : gl.RGBA16F), occluders: makeTarget(gl, w, h, gl.R32F),
      distance: makeTarget(gl, w, h, gl.R32F) };
  }
  const gpu = new Map();  // track data -> GL objects

  function meshGpu(m) {
    if (gpu.has(m)) return gpu.get(m);
    const g = { vao: gl.createVertexArray(), buffer: gl.createBuffer(), textures: [] };
    for (const t of m.textures) {
      const tex = gl.createTexture();
      gl.bindTexture(gl.TEXTURE_2D_ARRAY, tex);
      const levels = mipChain(t.W, t.H, t.texels);
      gl.texStorage3D(gl.TEXTURE_2D_ARRAY, levels.length, gl.SRGB8_ALPHA8, t.W, t.H, 1);
      gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
      levels.forEach((l, i) => gl.texSubImage3D(gl.TEXTURE_2D_ARRAY, i, 0, 0, 0, l.w, l.h, 1, gl.RGBA, gl.UNSIGNED_BYTE, l.texels));
      gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_MIN_FILTER, gl.LINEAR_MIPMAP_LINEAR);
      gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
      gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_WRAP_S, gl.REPEAT);
      gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_WRAP_T, gl.REPEAT);
      g.textures.push(tex);
    }
    gl.bindVertexArray(g.vao);
    gl.bindBuffer(gl.ARRAY_BUFFER, g.buffer);
    const stride = 4 * 18;
    [[0, 3, 0], [1, 3, 3], [2, 3, 6], [3, 2, 9], [4, 3, 11], [5, 3, 14], [6, 1, 17]].forEach(([loc, n, at]) => {
      gl.vertexAttribPointer(loc, n, gl.FLOAT, false, stride, 4 * at);
      gl.enableVertexAttribArray(loc);
    });
    gl.bindVertexArray(null);
    gpu.set(m, g);
    return g;
  }

  // The geometry stage of mesh_gl_renderer.cc's geometry shader, per pose: returns the vertex
  // data (18 floats a vertex) and the draws [texture, first, count], object by object.
  function meshGeometry(m, camera, frame) {
    const ix = m.index, eye = camera.position, tau = frame / m.fps;
    const floats = [], draws = [];
    let count = 0;
    const positions = new Map();
    m.objects.forEach((ob, o) => {
      const P = ix.prototypes[ob.prototype], d = m.prototypes[ob.prototype];
      if (!positions.has(ob.prototype)) positions.set(ob.prototype, positionsAt(d, tau));
      const pos = positions.get(ob.prototype);
      const N = ix.objects[o].N, f = Math.min(frame, N - 1);
      const tf = new Float32Array(ob.transforms.buffer, ob.transforms.byteOffset + 48 * f, 12);
      const r = [[tf[0], tf[1], tf[2], tf[3]], [tf[4], tf[5], tf[6], tf[7]], [tf[8], tf[9], tf[10], tf[11]]];
      const cof = [0, 1, 2].map((a) => [0, 1, 2].map((b) => {
        const a1 = (a + 1) % 3, a2 = (a + 2) % 3, b1 = (b + 1) % 3, b2 = (b + 2) % 3;
        return r[a1][b1] * r[a2][b2] - r[a1][b2] * r[a2][b1];
      }));
      const t = [r[0][3] - eye[0], r[1][3] - eye[1], r[2][3] - eye[2]];
      const world = (i) => [0, 1, 2].map((k) => r[k][0] * pos[3 * i] + r[k][1] * pos[3 * i + 1] + r[k][2] * pos[3 * i + 2] + t[k]);
      const normals = d.normals && new Float32Array(d.normals.buffer, d.normals.byteOffset, d.normals.length);
      const colours = d.colours && new Float32Array(d.colours.buffer, d.colours.byteOffset, d.colours.length);
      const uvs = d.uvs && new Float32Array(d.uvs.buffer, d.uvs.byteOffset, d.uvs.length);
      const model = [[r[0][0], r[1][0], r[2][0]], [r[0][1], r[1][1], r[2][1]], [r[0][2], r[1][2], r[2][2]], t];
      const byTexture = new Map();
      const K = ob.subset ? ob.subset.length : P.T;
      for (let k = 0; k < K; ++k) {
        const tri = ob.subset ? ob.subset[k] : k;
        let mat = d.materials ? d.materials[tri] : ob.material;
        if (mat === NONE) mat = ob.material;
        const tex = uvs ? ix.materials[mat].texture : NONE;
        if (!byTexture.has(tex)) byTexture.set(tex, []);
        const out = byTexture.get(tex);
        const vi = [d.indices[3 * tri], d.indices[3 * tri + 1], d.indices[3 * tri + 2]];
        const rel = vi.map(world);
        const face = cross(sub(rel[1], rel[0]), sub(rel[2], rel[0]));
        const side = dot(face, rel[0]) > 0 ? -1 : 1;
        const faceNormal = normalize(face).map((x) => x * side);
        const material = ix.materials[mat];
        for (let j = 0; j < 3; ++j) {
          const i = vi[j];
          const n = normals ? [0, 1, 2].map((a) => side * (cof[a][0] * normals[3 * i] + cof[a][1] * normals[3 * i + 1] + cof[a][2] * normals[3 * i + 2])) : faceNormal;
          out.push(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2], ...n, ...(colours ? [colours[3 * i], colours[3 * i + 1], colours[3 * i + 2]] : [1, 1, 1]),
            ...(uvs ? [uvs[2 * i], uvs[2 * i + 1]] : [0, 0]), ...material.base, ...material.emission, tex !== NONE ? 1 : 0);
        }
      }
      // Textured passes first, the untextured pass last (as the native passes).
      const keys = [...byTexture.keys()].sort((a, b) => (a === NONE) - (b === NONE) || a - b);
      for (const tex of keys) {
        const v = byTexture.get(tex);
        for (const x of v) floats.push(x);
        draws.push([tex, count, v.length / 18, model]);
        count += v.length / 18;
      }
    });
    return { data: new Float32Array(floats), draws, triangles: count / 3 };
  }

  function drawMesh(m, camera, frame, target) {
    const g = meshGpu(m);
    const geo = meshGeometry(m, camera, frame);
    gl.bindFramebuffer(gl.FRAMEBUFFER, target.fb);
    gl.viewport(0, 0, camera.width, camera.height);
    gl.clearBufferfv(gl.COLOR, 0, [0, 0, 0, Infinity]);
    gl.clearDepth(0);
    gl.clear(gl.DEPTH_BUFFER_BIT);
    gl.disable(gl.BLEND);
    gl.disable(gl.CULL_FACE);
    gl.enable(gl.DEPTH_TEST);
    gl.depthMask(true);
    gl.depthFunc(gl.GREATER);
    gl.useProgram(meshProgram);
    setCamera(gl, meshProgram, camera);
    gl.uniform3fv(gl.getUniformLocation(meshProgram, 'light'), KEY_LIGHT);
    gl.uniform1f(gl.getUniformLocation(meshProgram, 'ambient'), AMBIENT);
    gl.uniform1i(gl.getUniformLocation(meshProgram, 'base_texture'), 0);
    gl.bindVertexArray(g.vao);
    gl.bindBuffer(gl.ARRAY_BUFFER, g.buffer);
    gl.bufferData(gl.ARRAY_BUFFER, geo.data, gl.STREAM_DRAW);
    gl.activeTexture(gl.TEXTURE0);
    const model = ['model_x', 'model_y', 'model_z', 'model_t'].map((n) => gl.getUniformLocation(meshProgram, n));
    for (const [tex, first, count, m] of geo.draws) {
      for (let k = 0; k < 4; ++k) gl.uniform3fv(model[k], m[k]);
      gl.bindTexture(gl.TEXTURE_2D_ARRAY, tex === NONE ? null : g.textures[tex]);
      gl.drawArrays(gl.TRIANGLES, first, count);
    }
    gl.bindVertexArray(null);
    gl.bindTexture(gl.TEXTURE_2D_ARRAY, null);
    gl.disable(gl.DEPTH_TEST);
    return { triangles: geo.triangles };
  }

  function tilesGpu(s) {
    if (gpu.has(s)) return gpu.get(s);
    const origin = [0, 1, 2].map((k) => (s.index.viewMin[k] + s.index.viewMax[k]) / 2);
    const v = new Float32Array(24 * s.n);
    for (let t = 0; t < 4 * s.n; ++t) {
      for (let k = 0; k < 3; ++k) v[6 * t + k] = s.quads[6 * t + k] - origin[k];
      for (let k = 3; k < 6; ++k) v[6 * t + k] = s.quads[6 * t + k];
    }
    const g = { origin, vao: gl.createVertexArray(), buffer: gl.createBuffer(), indices: gl.createBuffer(), atlas: gl.createTexture() };
    gl.bindVertexArray(g.vao);
    gl.bindBuffer(gl.ARRAY_BUFFER, g.buffer);
    gl.bufferData(gl.ARRAY_BUFFER, v, gl.STATIC_DRAW);
    gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 24, 0);
    gl.enableVertexAttribArray(0);
    gl.vertexAttribPointer(1, 3, gl.FLOAT, false, 24, 12);
    gl.enableVertexAttribArray(1);
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, g.indices);
    gl.bindVertexArray(null);
    gl.bindTexture(gl.TEXTURE_2D_ARRAY, g.atlas);
    gl.texStorage3D(gl.TEXTURE_2D_ARRAY, 1, gl.RGBA16F, s.W, s.H, 1);
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 4);
    gl.texSubImage3D(gl.TEXTURE_2D_ARRAY, 0, 0, 0, 0, s.W, s.H, 1, gl.RGBA, gl.HALF_FLOAT, tilesLinearAtlas(s.atlas));
    for (const [k, x] of [[gl.TEXTURE_MIN_FILTER, gl.LINEAR], [gl.TEXTURE_MAG_FILTER, gl.LINEAR],
      [gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE], [gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE]]) gl.texParameteri(gl.TEXTURE_2D_ARRAY, k, x);
    gl.bindTexture(gl.TEXTURE_2D_ARRAY, null);
    gpu.set(s, g);
    return g;
  }

  function drawTiles(s, camera, target) {
    const g = tilesGpu(s);
    // tiles_back_to_front (player/src/tiles_draw_order.cc): farthest centre first, ties by index.
    const eye = camera.position, distance = new Float64Array(s.n);
    for (let t = 0; t < s.n; ++t) {
      const c = [0, 0, 0];
      for (let k = 0; k < 4; ++k) for (let a = 0; a < 3; ++a) c[a] += s.quads[24 * t + 6 * k + a];
      distance[t] = Math.hypot(c[0] / 4 - eye[0], c[1] / 4 - eye[1], c[2] / 4 - eye[2]);
    }
    const order = Array.from({ length: s.n }, (_, t) => t).sort((a, b) => (distance[a] !== distance[b] ? distance[b] - distance[a] : a - b));
    const idx = new Uint32Array(6 * s.n);
    order.forEach((t, k) => idx.set([4 * t, 4 * t + 1, 4 * t + 2, 4 * t, 4 * t + 2, 4 * t + 3], 6 * k));
    gl.bindVertexArray(g.vao);
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, g.indices);
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, idx, gl.STREAM_DRAW);
    gl.useProgram(tilesProgram);
    setCamera(gl, tilesProgram, camera);
    const U = (n) => gl.getUniformLocation(tilesProgram, n);
    gl.uniform3fv(U('eye_offset'), sub(eye, g.origin));
    gl.uniform1i(U('atlas'), 0);
    gl.uniform1i(U('occluders'), 1);
    gl.uniform1f(U('occlusion_behind'), 1 + OCCLUSION_EPSILON);
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D_ARRAY, g.atlas);
    gl.disable(gl.CULL_FACE);
    gl.viewport(0, 0, camera.width, camera.height);
    const draw = () => gl.drawElements(gl.TRIANGLES, idx.length, gl.UNSIGNED_INT, 0);
    // Nearest distance of fragments with alpha ≥ threshold into target fb's channels `mask`.
    const nearest = (fb, threshold, mask) => {
      gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
      gl.disable(gl.BLEND);
      gl.enable(gl.DEPTH_TEST);
      gl.depthMask(true);
      gl.depthFunc(gl.LESS);
      gl.clearDepth(1);
      gl.clear(gl.DEPTH_BUFFER_BIT);
      gl.colorMask(...mask);
      gl.uniform1i(U('mode'), 1);
      gl.uniform1f(U('threshold'), threshold);
      draw();
      gl.colorMask(true, true, true, true);
      gl.disable(gl.DEPTH_TEST);
    };
    // The occlusion pre-pass.
    gl.bindFramebuffer(gl.FRAMEBUFFER, targets.occluders.fb);
    gl.clearBufferfv(gl.COLOR, 0, [Infinity, Infinity, Infinity, Infinity]);
    nearest(targets.occluders.fb, OCCLUSION_ALPHA, [true, true, true, true]);
    // The sorted pass: src + (1 − src.a) dst over 0.
    gl.bindFramebuffer(gl.FRAMEBUFFER, targets.tiles.fb);
    gl.clearBufferfv(gl.COLOR, 0, [0, 0, 0, 0]);
    gl.activeTexture(gl.TEXTURE1);
    gl.bindTexture(gl.TEXTURE_2D, targets.occluders.tex);
    gl.activeTexture(gl.TEXTURE0);
    gl.enable(gl.BLEND);
    gl.blendFuncSeparate(gl.ONE, gl.ONE_MINUS_SRC_ALPHA, gl.ONE, gl.ONE_MINUS_SRC_ALPHA);
    gl.blendEquation(gl.FUNC_ADD);
    gl.uniform1i(U('mode'), 0);
    gl.uniform1i(U('occlusion_test'), 1);
    gl.colorMask(true, true, true, false);
    draw();
    gl.colorMask(true, true, true, true);
    gl.disable(gl.BLEND);
    // The layer's distance (binary32, as the native target's): the nearest tile with alpha ≥ 0.5,
    // +inf elsewhere; then colour and distance into the layer.
    gl.bindFramebuffer(gl.FRAMEBUFFER, targets.distance.fb);
    gl.clearBufferfv(gl.COLOR, 0, [Infinity, Infinity, Infinity, Infinity]);
    nearest(targets.distance.fb, 0.5, [true, true, true, true]);
    gl.bindVertexArray(null);
    gl.activeTexture(gl.TEXTURE1);
    gl.bindTexture(gl.TEXTURE_2D, targets.distance.tex);
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D_ARRAY, null);
    gl.bindTexture(gl.TEXTURE_2D, targets.tiles.tex);
    gl.bindFramebuffer(gl.FRAMEBUFFER, target.fb);
    gl.useProgram(mergeProgram);
    gl.uniform1i(gl.getUniformLocation(mergeProgram, 'colour_tex'), 0);
    gl.uniform1i(gl.getUniformLocation(mergeProgram, 'distance_tex'), 1);
    gl.bindVertexArray(emptyVao);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    gl.bindVertexArray(null);
    gl.bindTexture(gl.TEXTURE_2D, null);
    gl.activeTexture(gl.TEXTURE1);
    gl.bindTexture(gl.TEXTURE_2D, null);
    gl.activeTexture(gl.TEXTURE0);
    return { tiles: s.n };
  }

  // composite_nearest of layer into acc (player/src/rendered_image.cc), written into `into`.
  function composite(acc, layer, into) {
    gl.bindFramebuffer(gl.FRAMEBUFFER, into.fb);
    gl.viewport(0, 0, targets.w, targets.h);
    gl.useProgram(compositeProgram);
    gl.activeTexture(gl.TEXTURE0); gl.bindTexture(gl.TEXTURE_2D, acc.tex);
    gl.activeTexture(gl.TEXTURE1); gl.bindTexture(gl.TEXTURE_2D, layer.tex);
    gl.uniform1i(gl.getUniformLocation(compositeProgram, 'base_layer'), 0);
    gl.uniform1i(gl.getUniformLocation(compositeProgram, 'layer'), 1);
    gl.bindVertexArray(emptyVao);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    gl.activeTexture(gl.TEXTURE1); gl.bindTexture(gl.TEXTURE_2D, null);
    gl.activeTexture(gl.TEXTURE0);
    return into;
  }

  // Renders the tracks (in clip order) for camera at frame `frame` and presents the composite
  // into the canvas or out.framebuffer at out.viewport. Returns per-track figures.
  function render(tracks, camera, frame, out = null) {
    ensureTargets(camera.width, camera.height);
    const figures = [];
    let acc = null;
    for (const tr of tracks) {
      const layer = targets.layers[acc === targets.layers[0] ? 1 : 0];
      const f = Math.min(frame, tr.frameCount - 1);
      figures.push(tr.kind === 'mesh' ? drawMesh(tr, camera, f, layer) : drawTiles(tr, camera, layer));
      acc = acc ? composite(acc, layer, targets.layers.find((l) => l !== acc && l !== layer)) : layer;
    }
    gl.bindFramebuffer(gl.FRAMEBUFFER, out ? out.framebuffer : null);
    const vp = out ? out.viewport : { x: 0, y: 0 };
    gl.viewport(vp.x, vp.y, camera.width, camera.height);
    gl.useProgram(presentProgram);
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D, acc.tex);
    gl.uniform1i(gl.getUniformLocation(presentProgram, 'frame_tex'), 0);
    gl.uniform2i(gl.getUniformLocation(presentProgram, 'origin'), vp.x, vp.y);
    gl.bindVertexArray(emptyVao);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    gl.bindVertexArray(null);
    gl.bindTexture(gl.TEXTURE_2D, null);
    return figures;
  }
  return { render, floatBlend };
}
