// The page's player, first stage (docs/WEB.md): opens a clip by URL over range requests, decodes
// view 0 of its lightfield track on the CPU and shows it as an environment around the camera in
// a WebGL2 fragment shader that looks the cube faces up with calf's own GLSL conventions
// (glsl_conventions.js, generated from the native player's source). No ray march yet: the
// picture is view 0's colour seen from its centre. Errors are one line in the overlay; the last
// good frame stays.
import { openClip } from './container.js';
import { openLightfield, decodeFaceFrames } from './lightfield.js';
import { httpSource } from './stream.js';
import { makeCodecs } from './codecs.js';
import { GLSL_CONVENTIONS } from './glsl_conventions.js';

const VERTEX = `#version 300 es
out vec2 ndc;
void main() {
  ndc = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2)) * 2.0 - 1.0;
  gl_Position = vec4(ndc, 0.0, 1.0);
}`;

const FRAGMENT = `#version 300 es
precision highp float;
precision highp int;
precision highp sampler2DArray;
${GLSL_CONVENTIONS}
in vec2 ndc;
out vec4 outColour;
uniform sampler2DArray colour_tex;  // the 6 faces of one view, linear RGB
uniform uint face_size;
uniform mat3 camera;                // columns: right, up, back (scene axes)
uniform float tan_half_fov;
uniform float aspect;
vec3 srgb(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}
void main() {
  vec3 d = normalize(camera * vec3(ndc.x * tan_half_fov * aspect, ndc.y * tan_half_fov, -1.0));
  int face = calf_face_from_direction(d);
  vec2 texel = calf_texel_coord_from_st(calf_st_from_direction(d, face), face_size);
  ivec2 t = clamp(ivec2(floor(texel)), ivec2(0), ivec2(int(face_size) - 1));
  outColour = vec4(srgb(texelFetch(colour_tex, ivec3(t, face), 0).rgb), 1.0);
}`;

function compile(gl, type, source) {
  const s = gl.createShader(type);
  gl.shaderSource(s, source);
  gl.compileShader(s);
  if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(`shader: ${gl.getShaderInfoLog(s)}`);
  return s;
}

// deps: the npm modules ({hashWasm, fzstd, xz}); status(text) shows one line.
export async function startPlayer({ canvas, url, deps, status }) {
  const gl = canvas.getContext('webgl2', { preserveDrawingBuffer: true });
  if (!gl) throw new Error('WebGL2 is not available');
  const program = gl.createProgram();
  gl.attachShader(program, compile(gl, gl.VERTEX_SHADER, VERTEX));
  gl.attachShader(program, compile(gl, gl.FRAGMENT_SHADER, FRAGMENT));
  gl.linkProgram(program);
  if (!gl.getProgramParameter(program, gl.LINK_STATUS)) throw new Error(`program: ${gl.getProgramInfoLog(program)}`);
  const codecs = await makeCodecs(deps);
  const source = await httpSource(url);
  if (source.notice) status(source.notice);
  const clip = await openClip(source, codecs);
  const t = clip.tracks.findIndex((x) => x.kind === 1);
  if (t < 0) throw new Error('the clip has no lightfield track this page can play');
  const lf = await openLightfield(clip, t);
  const v = lf.views.findIndex((x) => x);
  const N = lf.header.face_size, F = lf.header.frame_count;
  const t0 = performance.now();
  const frames = Array.from({ length: F }, () => new Float32Array(6 * 4 * N * N));
  for (let face = 0; face < 6; ++face) {
    await decodeFaceFrames(lf, v, face, (n, colour) => {
      const dst = frames[n];
      for (let i = 0; i < N * N; ++i) {
        const o = 4 * (face * N * N + i);
        dst[o] = colour[3 * i]; dst[o + 1] = colour[3 * i + 1]; dst[o + 2] = colour[3 * i + 2]; dst[o + 3] = 1;
      }
    });
  }
  const decodeMs = performance.now() - t0;
  const tex = gl.createTexture();
  gl.bindTexture(gl.TEXTURE_2D_ARRAY, tex);
  gl.texStorage3D(gl.TEXTURE_2D_ARRAY, 1, gl.RGBA32F, N, N, 6);
  gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
  gl.texParameteri(gl.TEXTURE_2D_ARRAY, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
  gl.useProgram(program);
  const u = (name) => gl.getUniformLocation(program, name);
  gl.uniform1i(u('colour_tex'), 0);
  gl.uniform1ui(u('face_size'), N);
  gl.uniform1f(u('tan_half_fov'), Math.tan((60 * Math.PI) / 360));
  const state = { frame: 0, yaw: 0, pitch: 0 };
  const draw = () => {
    gl.texSubImage3D(gl.TEXTURE_2D_ARRAY, 0, 0, 0, 0, N, N, 6, gl.RGBA, gl.FLOAT, frames[state.frame]);
    const cy = Math.cos(state.yaw), sy = Math.sin(state.yaw), cp = Math.cos(state.pitch), sp = Math.sin(state.pitch);
    const back = [sy * cp, -sp, cy * cp], right = [cy, 0, -sy];
    const up = [back[1] * right[2] - back[2] * right[1], back[2] * right[0] - back[0] * right[2], back[0] * right[1] - back[1] * right[0]];
    gl.uniformMatrix3fv(u('camera'), false, [...right, ...up, ...back]);
    gl.uniform1f(u('aspect'), canvas.width / canvas.height);
    gl.viewport(0, 0, canvas.width, canvas.height);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
  };
  draw();
  status(`view ${v} of ${lf.header.view_count}, ${F} frames of ${N}² faces decoded in ${decodeMs.toFixed(0)} ms; ` +
    `${source.stats.bytes} of ${source.size} bytes fetched`);
  return { gl, lf, state, draw, frames, decodeMs };
}
