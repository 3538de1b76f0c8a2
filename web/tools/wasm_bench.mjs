// JS or WebAssembly for the page decoder's hot path (docs/WEB.md "Decoder: JS or WASM"): the
// per-chunk work after decompression, on the same chunks of each clip, under node:
// - JS: lightfield.js's decodeColour (a colour keyframe payload to linear floats) and
//   parseRegion + applyRegionFrame (every frame of a depth region chunk applied to a tile state);
// - WASM: calf's C++ for the same work (lf::colour_payload_gpu_bytes + decode_gpu_colour,
//   lf::parse_region_chunk + region_rect_gpu_bytes + decode_gpu_depth; web/tools/wasm_decode.cc),
//   built here with Debian's emcc -O3 (STANDALONE_WASM, no JS glue; its WASI imports are stubs
//   that are never called).
// Both must give the same bytes for every chunk. Prints, per clip, ms per frame (every chunk of
// every view and face, divided by the clip's frames; median of REPEAT runs, with min – max),
// decoded bytes per second, the first (cold) run, the WASM module's compile + instantiate ms, and
// the code sizes (plain and gzip). Not a test: skips with one line without emcc.
//
//   node web/tools/wasm_bench.mjs [CLIP.calf...]     default: build/demo/interior.calf
import { execFileSync } from 'node:child_process';
import { existsSync, mkdirSync, readFileSync, statSync } from 'node:fs';
import { join } from 'node:path';
import { gzipSync } from 'node:zlib';
import { ROOT, loadCodecs } from '../test/node_codecs.mjs';
import { bytesSource, openClip, readChunk } from '../src/container.js';
import { STREAM, applyRegionFrame, decodeColour, openLightfield, parseRegion } from '../src/lightfield.js';

const REPEAT = 7;
const emcc = (() => {
  try { return execFileSync('sh', ['-c', 'command -v emcc'], { encoding: 'utf8' }).trim(); } catch { return ''; }
})();
if (!emcc) {
  console.log('wasm_bench: skipped: emcc is not installed (Debian: apt-get install emscripten)');
  process.exit(0);
}
const clips = process.argv.length > 2 ? process.argv.slice(2) : [join(ROOT, 'build/demo/interior.calf')];

// The module: calf's sources it needs, with the C++20 stand-ins emscripten 3.1.6 lacks.
const out = join(ROOT, 'build/wasm-bench');
mkdirSync(out, { recursive: true });
const wasmPath = join(out, 'calf_decode.wasm');
const F = (f) => join(ROOT, 'format/src', f);
const sources = [join(ROOT, 'web/tools/wasm_decode.cc'), ...['bc1_bc45.cc', 'bc6h_decode.cc', 'bc7_decode.cc', 'bc_common.cc', 'colour.cc',
  'lightfield_layout.cc', 'depth_predict.cc', 'status.cc', 'log_depth.cc', 'container_types.cc'].map(F), join(ROOT, 'decoder/src/cpu_textures.cc')];
const tb = performance.now();
const stale = !existsSync(wasmPath) || [...sources, join(ROOT, 'web/tools/wasm_compat.h')].some((f) => statSync(f).mtimeMs > statSync(wasmPath).mtimeMs);
if (stale) execFileSync(emcc, ['-O3', '-std=c++20', '-fno-exceptions', '-include', join(ROOT, 'web/tools/wasm_compat.h'),
  '-I', join(ROOT, 'format/include'), '-I', join(ROOT, 'decoder/include'), ...sources, '-o', wasmPath, '--no-entry', '-sSTANDALONE_WASM',
  '-sEXPORTED_FUNCTIONS=_calf_wasm_colour,_calf_wasm_depth,_malloc,_free', '-sALLOW_MEMORY_GROWTH', '-sERROR_ON_UNDEFINED_SYMBOLS=0'],
{ stdio: ['ignore', 'ignore', 'inherit'], env: { ...process.env, NODE_PATH: process.env.NODE_PATH ?? '/usr/share/nodejs' } });
const buildS = (performance.now() - tb) / 1000;
const wasmBytes = readFileSync(wasmPath);
// The WASI imports: an empty environment (libc's start-up asks for it); the others only serve
// abort and printing, which the decoder never reaches.
const stub = () => { throw new Error('an OS call from the WASM decoder'); };
let memory = null;
const imports = { env: { emscripten_notify_memory_growth: () => {} },
  wasi_snapshot_preview1: { ...Object.fromEntries(['proc_exit', 'fd_close', 'fd_write', 'fd_seek'].map((k) => [k, stub])),
    environ_sizes_get: (count, size) => { new DataView(memory.buffer).setUint32(count, 0, true); new DataView(memory.buffer).setUint32(size, 0, true); return 0; },
    environ_get: () => 0 } };
const instantiate = async () => {
  const t = performance.now();
  const module = await WebAssembly.compile(wasmBytes);
  const instance = await WebAssembly.instantiate(module, imports);
  memory = instance.exports.memory;
  instance.exports._initialize();
  return { wasm: instance.exports, ms: performance.now() - t };
};
const starts = [];
for (let i = 0; i < REPEAT; ++i) starts.push((await instantiate()).ms);
const { wasm } = await instantiate();
const jsFiles = ['web/src/lightfield.js', 'web/src/bc.js', 'web/src/bc_tables.js'].map((f) => readFileSync(join(ROOT, f)));
const jsSize = jsFiles.reduce((s, b) => s + b.length, 0), jsGzip = jsFiles.reduce((s, b) => s + gzipSync(b, { level: 9 }).length, 0);

// Copies `bytes` into the module's memory at a buffer of at least `need` bytes kept between calls.
const buffers = {};
function place(name, need) {
  if (!buffers[name] || buffers[name].size < need) {
    if (buffers[name]) wasm.free(buffers[name].ptr);
    buffers[name] = { ptr: wasm.malloc(need), size: need };
  }
  return buffers[name].ptr;
}
// WASM: one colour payload → Float32Array view of its texels in the module's memory.
function wasmColour(job) {
  const n = 3 * job.w * job.h;
  const src = place('in', job.raw.length), dst = place('out', 4 * n);
  new Uint8Array(wasm.memory.buffer, src, job.raw.length).set(job.raw);
  const e = wasm.calf_wasm_colour(job.format, src, job.raw.length, job.w, job.h, dst);
  if (e) throw new Error(`${job.what}: CALF-E${String(e).padStart(3, '0')} from the WASM decoder`);
  return new Float32Array(wasm.memory.buffer, dst, n);
}
function wasmDepth(job) {
  const n = job.w * job.h;
  const src = place('in', job.raw.length), dst = place('state', 2 * n);
  new Uint8Array(wasm.memory.buffer, src, job.raw.length).set(job.raw);
  new Uint16Array(wasm.memory.buffer, dst, n).fill(0);
  const e = wasm.calf_wasm_depth(job.format, src, job.raw.length, job.frames, job.w, job.h, dst);
  if (e) throw new Error(`${job.what}: CALF-E${String(e).padStart(3, '0')} from the WASM decoder`);
  return new Uint16Array(wasm.memory.buffer, dst, n);
}
const jsColour = (job) => decodeColour(job.raw, job.format, job.w, job.h, job.what);
function jsDepth(job) {
  const frames = parseRegion(job.raw, 'depth', job.format, job.w, job.h, job.frames, job.what);
  const state = new Uint16Array(job.w * job.h);
  for (const rects of frames) applyRegionFrame(rects, state, job.w, 1);
  return state;
}
const same = (a, b) => a.length === b.length && Buffer.from(a.buffer, a.byteOffset, a.byteLength).equals(Buffer.from(b.buffer, b.byteOffset, b.byteLength));

const { codecs } = await loadCodecs();
console.log(`wasm_bench: emcc -O3 build ${stale ? `${buildS.toFixed(1)} s` : 'up to date'}; WASM ${wasmBytes.length} bytes (${gzipSync(wasmBytes, { level: 9 }).length} gzip), ` +
  `compile + instantiate ${median(starts).toFixed(1)} ms (median of ${REPEAT}; ${Math.min(...starts).toFixed(1)} – ${Math.max(...starts).toFixed(1)}); ` +
  `JS lightfield.js + bc.js + bc_tables.js ${jsSize} bytes (${jsGzip} gzip)`);
for (const path of clips) {
  if (!existsSync(path)) { console.log(`wasm_bench: ${path}: no such clip`); continue; }
  const clip = await openClip(bytesSource(new Uint8Array(readFileSync(path))), codecs);
  const t = clip.tracks.findIndex((x) => x.kind === 1);
  const lf = await openLightfield(clip, t);
  const h = lf.header;
  const colour = [], depth = [];
  for (const [key, chunks] of lf.byKey) {
    const [stream, v, face, r] = key.split('/').map(Number);
    for (const c of chunks) {
      const what = `view ${v} face ${face} region ${r} chunk ${c.id}`;
      if (stream === STREAM.colour) {
        const { w, h: rh } = lf.cells.rect(r);
        colour.push({ raw: await readChunk(clip, c.id), format: h.colour_format, w, h: rh, what });
      } else if (stream === STREAM.depth) {
        const { w, h: rh } = lf.tiles.rect(r);
        depth.push({ raw: await readChunk(clip, c.id), format: h.depth_format, w, h: rh, frames: c.frameCount, what });
      }
    }
  }
  const name = path.split('/').pop();
  const lines = [];
  for (const [kind, jobs, js, wa, texelBytes] of [['colour', colour, jsColour, wasmColour, 12], ['depth', depth, jsDepth, wasmDepth, 2]]) {
    const decoded = jobs.reduce((s, j) => s + texelBytes * j.w * j.h, 0);
    const row = {};
    for (const [impl, f] of [['JS', js], ['WASM', wa]]) {
      const ms = [];
      for (let i = 0; i < REPEAT; ++i) {
        const t0 = performance.now();
        for (const j of jobs) f(j);
        ms.push(performance.now() - t0);
      }
      row[impl] = ms;
    }
    lines.push(`wasm_bench: ${name} ${kind}: JS ${fmtRow(row.JS, h.frame_count, decoded)}; WASM ${fmtRow(row.WASM, h.frame_count, decoded)}; ` +
      `JS / WASM ${(median(row.JS.slice(1)) / median(row.WASM.slice(1))).toFixed(2)}`);
  }
  // The same output, chunk by chunk (after the timing, so that its first run is cold).
  let differ = 0;
  for (const j of colour) if (!same(jsColour(j), wasmColour(j))) ++differ;
  for (const j of depth) if (!same(jsDepth(j), wasmDepth(j))) ++differ;
  console.log(`wasm_bench: ${name}: ${h.view_count} views, ${h.face_size}² faces, ${h.frame_count} frames, colour format ${h.colour_format}, depth format ${h.depth_format}, ` +
    `${statSync(path).size} bytes; ${colour.length} colour and ${depth.length} depth chunks, ${differ} decoded differently by JS and WASM`);
  for (const l of lines) console.log(l);
  if (differ) process.exitCode = 1;
}

function median(a) {
  const s = [...a].sort((x, y) => x - y);
  return s[Math.floor(s.length / 2)];
}
// Run 0 is the first (cold: JIT warm-up for JS, first calls for WASM); the statistics are of the
// runs after it.
function fmtRow(ms, frames, decoded) {
  const warm = ms.slice(1);
  return `${(median(warm) / frames).toFixed(2)} ms/frame (${(Math.min(...warm) / frames).toFixed(2)} – ${(Math.max(...warm) / frames).toFixed(2)}), ` +
    `${(decoded / (median(warm) / 1000) / 1e6).toFixed(0)} MB/s decoded, first run ${(ms[0] / frames).toFixed(2)} ms/frame`;
}
