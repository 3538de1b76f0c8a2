// The page decoder's conformance run (format/SPEC.md §14): decodes every clip of
// tests/conformance/lightfield/, tiles/ and mesh/ under node (AV1 colour through libav.js's
// WebAssembly decoder, av1.js) and compares its hash lines with CLIP.hashes.
//
//   node web/test/conformance.mjs [CLIP.calf...]     default: every clip of the folder
//   node web/test/conformance.mjs --time CLIP.calf... decode ms of each clip: median, min and
//                                                    max of 5 runs (no comparison)
//
// Prints one line per clip (lines, decode ms) and one per difference; exits 1 on any
// difference, 77 (ctest's skip code) when node's packages are missing, unless CI=true.
import { readFileSync, readdirSync, existsSync } from 'node:fs';
import { join, basename } from 'node:path';
import { ROOT, loadCodecs } from './node_codecs.mjs';
import { openClip, bytesSource, readChunk, verifyContainer } from '../src/container.js';
import { parseRegion, parseAv1Gop, parseAv1Chunk, av1Colour, av1HdrColour, av1YcbcrToRgb, av1Ycbcr10ToRgb } from '../src/lightfield.js';
import { decodeLines } from '../src/hash_lines.js';
import { CalfError } from '../src/errors.js';
import { makeAv1Decoders } from '../src/av1.js';
import { generate as generateBcTables } from '../tools/gen_bc_tables.mjs';
import { generate as generateGlsl } from '../tools/gen_glsl_conventions.mjs';
import { generate as generateRaymarch } from '../tools/gen_glsl_raymarch.mjs';
import { generate as generateRaster } from '../tools/gen_glsl_raster.mjs';

// A wrong decode must fail: one byte of a colour chunk's payload flipped in
// rgba8_raw16_none (stored, plain directory), with the chunk's hash and the directory checksum
// rewritten so that the container accepts it, must change a hash line; without the rewrite the
// reader must refuse the chunk (CALF-E058).
async function negativeChecks(codecs) {
  const problems = [];
  const path = join(ROOT, 'tests/conformance/lightfield/rgba8_raw16_none.calf');
  const want = readFileSync(path.replace(/\.calf$/, '.hashes'), 'utf8').split('\n').filter(Boolean);
  const clean = new Uint8Array(readFileSync(path));
  const clip = await openClip(bytesSource(clean), codecs);
  const c = clip.chunks.find((x) => x.stream === 1 && x.compression === 0 && x.storedSize > 0);
  const bytes = clean.slice();
  bytes[c.offset + Math.floor(c.storedSize / 2)] ^= 0x01;
  try {
    await decodeLines(bytes, codecs);
    problems.push('a flipped colour byte without its hash rewritten decoded without CALF-E058');
  } catch (e) {
    if (!(e instanceof CalfError) || e.id !== 'CALF-E058') throw e;
  }
  const view = new DataView(bytes.buffer);
  const dirOffset = clip.directoryOffset, dirSize = bytes.length - dirOffset;
  const entry = dirOffset + (dirSize - 8) - 64 * (clip.chunks.length - c.id);
  view.setBigUint64(entry + 24, codecs.xxh3(bytes.subarray(c.offset, c.offset + c.storedSize)), true);
  view.setBigUint64(bytes.length - 8, codecs.xxh3(bytes.subarray(dirOffset, bytes.length - 8)), true);
  const got = await decodeLines(bytes, codecs);
  const changed = got.lines.filter((l, i) => l !== want[i]).length;
  if (got.lines.length !== want.length || changed === 0) {
    problems.push(`a flipped colour byte (chunk ${c.id}) left every hash line as it was`);
  }
  problems.push(...await coverageChecks(codecs));
  problems.push(...av1Checks());
  problems.push(...await profileChecks(codecs));
  return problems;
}

// The choice of back end by AV1 profile (av1.js makeAv1Decoders), over a stand-in WebCodecs whose
// VideoDecoder.isConfigSupported takes the Main profile only: 4:4:4 streams (the High profile) go
// to the WebAssembly decoder (`codecs.av1` under node), and av1_444_pred16m reproduces its hash
// lines through it; with no WebAssembly decoder the track is refused at open with one CALF-E203
// line naming the High profile.
async function profileChecks(codecs) {
  const problems = [];
  const mainOnly = {
    VideoDecoder: class {
      constructor() { throw new Error('the stand-in VideoDecoder decodes nothing'); }
      static async isConfigSupported({ codec }) { return { supported: codec.startsWith('av01.0.') }; }
    },
    EncodedVideoChunk: class {},
  };
  const both = makeAv1Decoders(mainOnly, codecs.av1), alone = makeAv1Decoders(mainOnly);
  const ends = [await both.backEnd(8, false), await both.backEnd(8, true), await both.backEnd(10, true), await alone.backEnd(8, true)].join();
  if (ends !== 'WebCodecs,WebAssembly,WebAssembly,') problems.push(`back ends of 8-bit 4:2:0, 8 and 10-bit 4:4:4, 4:4:4 alone: ${ends}`);
  const path = join(ROOT, 'tests/conformance/lightfield/av1_444_pred16m.calf');
  const want = readFileSync(path.replace(/\.calf$/, '.hashes'), 'utf8').split('\n').filter(Boolean);
  const bytes = new Uint8Array(readFileSync(path));
  const got = await decodeLines(bytes, { ...codecs, av1: both });
  if (got.problems.length || got.lines.join() !== want.join()) problems.push(`av1_444_pred16m through WebCodecs' fallback: ${got.problems[0] ?? 'hash lines differ'}`);
  if (both.open() !== 0) problems.push(`av1_444_pred16m through WebCodecs' fallback left ${both.open()} decoders open`);
  let refused = null;
  try {
    await decodeLines(bytes, { ...codecs, av1: alone });
  } catch (e) {
    if (!(e instanceof CalfError)) throw e;
    refused = e.message;
  }
  if (!refused?.startsWith('CALF-E203 track 0: colour format 14 (av1-444): no AV1 decoder here for the High profile')) {
    problems.push(`av1_444_pred16m where WebCodecs lacks the High profile and there is no WebAssembly decoder: ${refused ?? 'no problem'}`);
  }
  return problems;
}

// AV1 colour's parts that need no AV1 decoder (SPEC §11.1.12; the decodes are checked by the
// AV1 clips' hash lines): the integer YCbCr formulas (8 and 10 bits) and the HDR curve on texels
// worked out by hand from SPEC, a GOP chunk head or HDR curve that contradicts SPEC (CALF-E067),
// 4:4:4 pictures taking each texel's own chroma (av1-444, av1hdr-444), a picture that is not of
// the track's bits and chroma (4:2:0 for av1 and av1hdr, 4:4:4 for the -444 formats) or is
// smaller than the cell (CALF-E302, in the native decoder's words).
function av1Checks() {
  const problems = [];
  const rgb = new Uint8Array(3);
  for (const [ycc, expect] of [[[128, 128, 128], [128, 128, 128]], [[100, 128, 255], [255, 41, 100]],
    [[50, 0, 128], [50, 74, 0]], [[200, 255, 0], [0, 236, 255]]]) {
    av1YcbcrToRgb(...ycc, rgb);
    if (rgb.join() !== expect.join()) problems.push(`AV1 YCbCr ${ycc} gives RGB ${rgb}, SPEC §11.1.12 says ${expect}`);
  }
  const gop = (f, sizes, tail) => Uint8Array.from([f, 0, 0, 0, ...sizes.flatMap((n) => [n, 0, 0, 0]), ...tail]);
  const id = (f) => { try { f(); return null; } catch (e) { if (!(e instanceof CalfError)) throw e; return e.id; } };
  const units = parseAv1Gop(gop(2, [1, 2], [7, 8, 9]), 2, 'gop');
  if (units.length !== 2 || [...units[0]].join() !== '7' || [...units[1]].join() !== '8,9') problems.push('a 2-unit AV1 chunk does not split into its units');
  for (const [what, raw, frames] of [['3 bytes', Uint8Array.from([1, 0, 0]), 1], ['F against the keys', gop(2, [1, 2], [7, 8, 9]), 3],
    ['F = 0', gop(0, [], []), 0], ['a unit of 0 bytes', gop(2, [0, 3], [7, 8, 9]), 2], ['a unit past the end', gop(2, [1, 3], [7, 8, 9]), 2],
    ['a byte after the units', gop(2, [1, 1], [7, 8, 9]), 2], ['a head past the end', Uint8Array.from([3, 0, 0, 0, 1, 0, 0, 0]), 3]]) {
    const got = id(() => parseAv1Gop(raw, frames, 'gop'));
    if (got !== 'CALF-E067') problems.push(`an AV1 chunk with ${what} gives ${got ?? 'no problem'}, not CALF-E067`);
  }
  const plane = (n, v) => new Uint8Array(n).fill(v);
  const picture = (format, w, h) => ({ format, width: w, height: h, planes: [plane(w * h, 128), plane(w * h, 128), plane(w * h, 128)], strides: [w, w, w] });
  for (const [what, p] of [['an I444 picture', picture('I444', 8, 8)], ['a 10-bit picture', picture('I420P10', 8, 8)], ['a picture narrower than the cell', picture('I420', 6, 8)],
    ['a picture shorter than the cell', picture('I420', 8, 7)]]) {
    const got = id(() => av1Colour(p, 8, 8, 'cell'));
    if (got !== 'CALF-E302') problems.push(`${what} gives ${got ?? 'no problem'}, not CALF-E302`);
  }
  if (id(() => av1Colour(picture('I420', 8, 8), 8, 8, 'cell')) !== null) problems.push('an 8 × 8 I420 picture is refused for an 8 × 8 cell');
  // 4:4:4: in a 2 × 2 I444 picture of grey (128, 128, 128) but texel (1, 1) of (100, 128, 255),
  // texel (1, 1) is the colour of (100, 128, 255) alone and the others grey (a 4:2:0 index would
  // give every texel chroma (0, 0)).
  const one = (ycc, format = 'I420') => av1Colour({ format, width: 1, height: 1, planes: ycc.map((v) => Uint8Array.of(v)), strides: [1, 1, 1] }, 1, 1, 'cell', format === 'I444');
  const four = av1Colour({ format: 'I444', width: 2, height: 2, planes: [Uint8Array.of(128, 128, 128, 100), Uint8Array.of(128, 128, 128, 128), Uint8Array.of(128, 128, 128, 255)], strides: [2, 2, 2] }, 2, 2, 'cell', true);
  const grey = [...one([128, 128, 128])].join(), odd = [...one([100, 128, 255])].join();
  if ([0, 1, 2].some((k) => [...four.subarray(3 * k, 3 * k + 3)].join() !== grey) || [...four.subarray(9, 12)].join() !== odd) {
    problems.push(`a 2 × 2 I444 picture gives ${[...four]}, not grey with texel (1, 1) the colour of YCbCr (100, 128, 255)`);
  }
  if ([...one([100, 128, 255], 'I444')].join() !== odd) problems.push('a 1 × 1 I444 picture is not converted as an I420 one of the same samples');
  const layoutProblem = (what, p, chroma444, hdr, expect) => {
    let got = null;
    try {
      if (hdr) av1HdrColour(p, 8, 8, { base: 0x3c00, shift: 0 }, 'cell', chroma444);
      else av1Colour(p, 8, 8, 'cell', chroma444);
    } catch (e) {
      if (!(e instanceof CalfError)) throw e;
      got = e.message;
    }
    if (got !== expect) problems.push(`${what} gives ${got ?? 'no problem'}, not '${expect}'`);
  };
  layoutProblem('an I420 picture for a 4:4:4 cell', picture('I420', 8, 8), true, false,
    'CALF-E302 cell: a 8 x 8 4:2:0 picture of 8 bits for a 8 x 8 cell (8-bit 4:4:4 expected by the track\'s colour format)');
  layoutProblem('an I444 picture for a 4:2:0 cell', picture('I444', 8, 8), false, false,
    'CALF-E302 cell: a 8 x 8 4:4:4 picture of 8 bits for a 8 x 8 cell (8-bit 4:2:0 expected by the track\'s colour format)');
  layoutProblem('an I444P10 picture for an 8-bit 4:4:4 cell', picture('I444P10', 8, 8), true, false,
    'CALF-E302 cell: a 8 x 8 4:4:4 picture of 10 bits for a 8 x 8 cell (8-bit 4:4:4 expected by the track\'s colour format)');
  layoutProblem('an I444 picture for a 4:4:4 cell', picture('I444', 8, 8), true, false, null);
  // av1hdr: 10-bit codes (u, v about 512, clamped to 0 … 1023), worked out by hand from SPEC.
  const rgb10 = new Uint16Array(3);
  for (const [ycc, expect] of [[[512, 512, 512], [512, 512, 512]], [[400, 512, 1023], [1023, 161, 400]], [[100, 0, 512], [100, 196, 0]]]) {
    av1Ycbcr10ToRgb(...ycc, rgb10);
    if (rgb10.join() !== expect.join()) problems.push(`AV1 10-bit YCbCr ${ycc} gives codes ${rgb10}, SPEC §11.1.12 says ${expect}`);
  }
  // Texel (0, 0) of YCbCr (400, 512, 1023) on the curve base 0x3C00 (1.0), shift 0: codes 1023,
  // 161, 400 are the halves 0x3FFF, 0x3CA1, 0x3D90; texel (1, 0) of Y 0 on base 0x7000, shift 5
  // with codes beyond 0x7BFF is capped there (65504).
  const plane16 = (n, v) => new Uint16Array(n).fill(v);
  const hdrPicture = (format, w, h, y = 400) => ({ format, width: w, height: h, planes: [plane16(w * h, y), plane16(w * h, 512), plane16(w * h, 1023)], strides: [w, w, w] });
  const hdr = av1HdrColour(hdrPicture('I420P10', 2, 2), 2, 2, { base: 0x3c00, shift: 0 }, 'cell');
  if ([...hdr.subarray(0, 3)].join() !== [1.9990234375, 1.1572265625, 1.390625].join()) problems.push(`HDR AV1 codes 1023, 161, 400 on base 0x3C00 shift 0 give ${[...hdr.subarray(0, 3)]}`);
  const capped = av1HdrColour(hdrPicture('I420P10', 2, 2, 1000), 2, 2, { base: 0x7000, shift: 5 }, 'cell');
  if (capped[0] !== 65504) problems.push(`HDR AV1 code 1023 on base 0x7000 shift 5 gives ${capped[0]}, not 65504 (0x7BFF)`);
  // av1hdr-444: texel (1, 1) of a 2 × 2 I444P10 picture of codes (512, 512, 512) but texel
  // (1, 1) of (400, 512, 1023) takes its own chroma, as above.
  const hdr444 = av1HdrColour({ format: 'I444P10', width: 2, height: 2, planes: [Uint16Array.of(512, 512, 512, 400), Uint16Array.of(512, 512, 512, 512), Uint16Array.of(512, 512, 512, 1023)], strides: [2, 2, 2] },
    2, 2, { base: 0x3c00, shift: 0 }, 'cell', true);
  // Code 512 is the half 0x3E00 (1.5) on that curve.
  if ([...hdr444.subarray(9, 12)].join() !== [1.9990234375, 1.1572265625, 1.390625].join() || [...hdr444.subarray(0, 9)].some((v) => v !== 1.5)) {
    problems.push(`a 2 × 2 I444P10 picture gives ${[...hdr444]}, not codes 512 with texel (1, 1) codes 1023, 161, 400`);
  }
  layoutProblem('an I420P10 picture for a 4:4:4 HDR cell', hdrPicture('I420P10', 8, 8), true, true,
    'CALF-E302 cell: a 8 x 8 4:2:0 picture of 10 bits for a 8 x 8 cell (10-bit 4:4:4 expected by the track\'s colour format)');
  layoutProblem('an I444P10 picture for a 4:2:0 HDR cell', hdrPicture('I444P10', 8, 8), false, true,
    'CALF-E302 cell: a 8 x 8 4:4:4 picture of 10 bits for a 8 x 8 cell (10-bit 4:2:0 expected by the track\'s colour format)');
  layoutProblem('an I444P10 picture for a 4:4:4 HDR cell', hdrPicture('I444P10', 8, 8), true, true, null);
  for (const [what, p] of [['an 8-bit picture', picture('I420', 8, 8)], ['a picture narrower than the cell', hdrPicture('I420P10', 6, 8)]]) {
    const got = id(() => av1HdrColour(p, 8, 8, { base: 0x3c00, shift: 0 }, 'cell'));
    if (got !== 'CALF-E302') problems.push(`${what} for an HDR cell gives ${got ?? 'no problem'}, not CALF-E302`);
  }
  const curve = (base, shift, rest) => Uint8Array.from([base & 0xff, base >> 8, shift & 0xff, shift >> 8, ...rest]);
  const hdrUnits = parseAv1Chunk(curve(0x7bff, 5, [1, 0, 0, 0, 1, 0, 0, 0, 9]), 1, true, 'gop');
  if (hdrUnits.curve.base !== 0x7bff || hdrUnits.curve.shift !== 5 || [...hdrUnits.units[0]].join() !== '9') problems.push('an HDR AV1 chunk does not split into its curve and units');
  for (const [what, raw] of [['3 bytes', Uint8Array.from([0, 4, 0])], ['base 0x7C00', curve(0x7c00, 0, [1, 0, 0, 0, 1, 0, 0, 0, 9])],
    ['shift 6', curve(0x0400, 6, [1, 0, 0, 0, 1, 0, 0, 0, 9])], ['a bad GOP after the curve', curve(0x0400, 0, [2, 0, 0, 0, 1, 0, 0, 0, 9])]]) {
    const got = id(() => parseAv1Chunk(raw, 1, true, 'gop'));
    if (got !== 'CALF-E067') problems.push(`an HDR AV1 chunk with ${what} gives ${got ?? 'no problem'}, not CALF-E067`);
  }
  return problems;
}

// SPEC §11.1.11's worked example decodes to its texels. A wrong coverage decode must fail: in
// coverage_bc1_pred16m's coverage chunk with the most edge texels, a flipped bit of the first
// mask high byte, the first mask low byte or the last near count changes a hash line or gives
// CALF-E065; a near count of 17 gives CALF-E065; a changed payload size gives CALF-E202.
async function coverageChecks(codecs) {
  const problems = [];
  // SPEC §11.1.11's worked example: a 4 × 2 tile, texel (1, 0) mask 0x0033 near 12, texel (3, 1)
  // mask 0xfff0 near 0, the others plain.
  const example = Uint8Array.from([1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 4, 0, 2, 0, 0x82, 0x00, 0xff, 0x33, 0xf0, 0x0c, 0x00]);
  const values = [...parseRegion(example, 'coverage', 0, 4, 2, 1, 'worked example')[0][0].values];
  const expect = [0xffff, 0, 0x0033, 12, 0xffff, 0, 0xffff, 0, 0xffff, 0, 0xffff, 0, 0xffff, 0, 0xfff0, 0];
  if (values.join() !== expect.join()) problems.push(`SPEC §11.1.11's worked example decodes to ${values.join()}`);
  const path = join(ROOT, 'tests/conformance/lightfield/coverage_bc1_pred16m.calf');
  const want = readFileSync(path.replace(/\.calf$/, '.hashes'), 'utf8').split('\n').filter(Boolean);
  const bytes = new Uint8Array(readFileSync(path));
  // The chunk's head (§11.1.6) and bitmaps read here, independently of the decoder.
  const layout = (raw) => {
    const v = new DataView(raw.buffer, raw.byteOffset, raw.length);
    const F = v.getUint32(0, true);
    let R = 0;
    for (let i = 0; i < F; ++i) R += v.getUint32(4 + 4 * i, true);
    let p = 4 + 4 * F + 8 * R, edges = 0;
    for (let k = 0; k < R; ++k) {
      const o = 4 + 4 * F + 8 * k, n = v.getUint16(o + 4, true) * v.getUint16(o + 6, true);
      for (let i = 0; i < n; ++i) edges += (raw[p + (i >> 3)] >> (i & 7)) & 1;
      p += Math.ceil(n / 8);
    }
    return { planes: p, edges };
  };
  let target = null;
  await decodeLines(bytes, codecs, (clip) => {
    for (const c of clip.chunks) {
      if (c.stream !== 5) continue;
      const l = layout(clip.chunkCache.get(c.id));
      if (!target || l.edges > target.edges) target = { id: c.id, ...l };
    }
  });
  if (!target || target.edges === 0) return ['coverage_bc1_pred16m: no coverage chunk with an edge texel'];
  const { id, planes, edges } = target;
  const run = async (what, change, accept) => {
    let got;
    try {
      got = await decodeLines(bytes, codecs, (clip) => { clip.chunkCache.set(id, change(clip.chunkCache.get(id))); });
    } catch (e) {
      if (!(e instanceof CalfError)) throw e;
      got = { lines: [], problems: [e.message] };
    }
    const changed = got.lines.length !== want.length || got.lines.some((l, i) => l !== want[i]);
    const first = got.problems[0] ?? null;
    if (!accept(changed, first)) problems.push(`coverage chunk ${id}: ${what}: ${first ?? (changed ? 'hash lines changed' : 'every hash line as it was')}`);
  };
  const flip = (at) => (raw) => { raw[at] ^= 0x01; return raw; };
  const changedOr065 = (changed, first) => first ? first.startsWith('CALF-E065 ') : changed;
  await run('a flipped mask high byte', flip(planes), changedOr065);
  await run('a flipped mask low byte', flip(planes + edges), changedOr065);
  await run('a flipped near count', flip(planes + 3 * edges - 1), changedOr065);
  await run('near count 17', (raw) => { raw[planes + 2 * edges] = 17; return raw; }, (_, first) => first?.startsWith('CALF-E065 '));
  await run('a byte short', (raw) => raw.subarray(0, raw.length - 1), (_, first) => first?.startsWith('CALF-E202 '));
  return problems;
}

// The container corpus (tests/conformance/container/manifest.txt): every valid file opens,
// verifies and decodes each chunk to the manifest's size and XXH3-64; every malformed file
// gives the manifest's id first (open's error, else verification's first problem).
async function containerCorpus(codecs) {
  const dir = join(ROOT, 'tests/conformance/container');
  const problems = [];
  let files = 0;
  const opened = new Map();
  for (const line of readFileSync(join(dir, 'manifest.txt'), 'utf8').split('\n')) {
    const w = line.split(' ');
    if (w[0] === 'valid' || w[0] === 'malformed') {
      ++files;
      const bytes = new Uint8Array(readFileSync(join(dir, w[1])));
      let first = null;
      try {
        const clip = await openClip(bytesSource(bytes), codecs);
        opened.set(w[1], clip);
        const found = await verifyContainer(clip);
        if (found.length) first = found[0];
      } catch (e) {
        if (!(e instanceof CalfError)) throw e;
        first = e;
      }
      const want = w[0] === 'valid' ? null : w[2];
      if ((first?.id ?? null) !== want) problems.push(`${w[1]}: expected ${want ?? 'no problem'}, got ${first?.message ?? 'no problem'}`);
    } else if (w[0] === 'chunk') {
      const clip = opened.get(w[1]);
      if (!clip) continue;
      const raw = await readChunk(clip, Number(w[2]));
      const hash = codecs.xxh3(raw).toString(16).padStart(16, '0');
      if (raw.length !== Number(w[3]) || hash !== w[4]) problems.push(`${w[1]} chunk ${w[2]}: ${raw.length} bytes ${hash}, expected ${w[3]} ${w[4]}`);
    }
  }
  return { files, problems };
}

// The damaged lightfield clips of the decoder's fuzz corpus (valid chunk hashes, a broken
// §11.1 layout): each bad_* gives CALF-E202, each valid_* decodes without a problem.
async function lightfieldCorpus(codecs) {
  const dir = join(ROOT, 'tests/fuzz/corpus/lightfield_decoder_fuzz');
  const problems = [];
  const files = readdirSync(dir).filter((f) => f.endsWith('.calf')).sort();
  for (const f of files) {
    let first;
    try {
      first = (await decodeLines(new Uint8Array(readFileSync(join(dir, f))), codecs)).problems[0] ?? null;
    } catch (e) {
      if (!(e instanceof CalfError)) throw e;
      first = e.message;
    }
    const ok = f.startsWith('bad_') ? first?.startsWith('CALF-E202 ') : first === null;
    if (!ok) problems.push(`${f}: ${first ?? 'no problem'}`);
  }
  return { files: files.length, problems };
}

// The damaged tiles and mesh clips of the fuzz corpora: the first id of each bad_* file is the
// one calf-verify (the C++ reader) gives; each valid_* file decodes without a problem.
const KIND_CORPUS = {
  'tiles_track_fuzz/bad_band_rows.calf': 'CALF-E212', 'tiles_track_fuzz/bad_index_version.calf': 'CALF-E211',
  'tiles_track_fuzz/bad_quad_w.calf': 'CALF-E212', 'tiles_track_fuzz/bad_view_region.calf': 'CALF-E212',
  'tiles_track_fuzz/valid_bc7_none.calf': null, 'tiles_track_fuzz/valid_rgba8_none.calf': null,
  'mesh_track_fuzz/bad_index_version.calf': 'CALF-E220', 'mesh_track_fuzz/bad_position_nan.calf': 'CALF-E223',
  'mesh_track_fuzz/bad_run_gap.calf': 'CALF-E222', 'mesh_track_fuzz/bad_texture_width.calf': 'CALF-E224',
  'mesh_track_fuzz/bad_uv_nan.calf': 'CALF-E223', 'mesh_track_fuzz/bad_vertex_index.calf': 'CALF-E222',
  'mesh_track_fuzz/valid_full_none.calf': null, 'mesh_track_fuzz/valid_subset_none.calf': null,
  'mesh_track_fuzz/valid_subset_zstd.calf': null, 'mesh_track_fuzz/valid_textured_none.calf': null,
};
async function kindCorpus(codecs) {
  const problems = [];
  for (const [f, want] of Object.entries(KIND_CORPUS)) {
    let got = null;
    try {
      await decodeLines(new Uint8Array(readFileSync(join(ROOT, 'tests/fuzz/corpus', f))), codecs);
    } catch (e) {
      if (!(e instanceof CalfError)) throw e;
      got = e;
    }
    if ((got?.id ?? null) !== want) problems.push(`${f}: expected ${want ?? 'no problem'}, got ${got?.message ?? 'no problem'}`);
  }
  return { files: Object.keys(KIND_CORPUS).length, problems };
}

async function main() {
  const loaded = await loadCodecs();
  if (!loaded.codecs) {
    console.log(`web conformance: skipped: ${loaded.missing}`);
    process.exit(process.env.CI === 'true' ? 1 : 77);
  }
  const { codecs } = loaded;
  if (!codecs.av1) {
    console.log(`web conformance: skipped: ${loaded.av1Missing ?? 'no AV1 decoder'}`);
    process.exit(process.env.CI === 'true' ? 1 : 77);
  }
  if (process.argv[2] === '--time') {
    for (const path of process.argv.slice(3)) {
      const bytes = new Uint8Array(readFileSync(path));
      const ms = [];
      let lines = 0;
      for (let i = 0; i < 5; ++i) {
        const t0 = performance.now();
        lines = (await decodeLines(bytes, codecs)).lines.length;
        ms.push(performance.now() - t0);
      }
      ms.sort((a, b) => a - b);
      console.log(`${basename(path)}: ${lines} faces decoded and hashed in ${ms[2].toFixed(0)} ms (median of 5; ${ms[0].toFixed(0)} – ${ms[4].toFixed(0)})`);
    }
    process.exit(0);
  }
  let failures = 0;
  // The generated sources are what their native sources give today.
  for (const [file, generate, tool] of [['web/src/bc_tables.js', generateBcTables, 'gen_bc_tables.mjs'],
    ['web/src/glsl_conventions.js', generateGlsl, 'gen_glsl_conventions.mjs'],
    ['web/src/glsl_raymarch.js', generateRaymarch, 'gen_glsl_raymarch.mjs'],
    ['web/src/glsl_raster.js', generateRaster, 'gen_glsl_raster.mjs']]) {
    if (readFileSync(join(ROOT, file), 'utf8') !== generate()) {
      console.log(`web conformance: ${file} is out of date (node web/tools/${tool})`);
      ++failures;
    }
  }
  const clips = process.argv.length > 2 ? process.argv.slice(2)
    : ['lightfield', 'tiles', 'mesh'].flatMap((d) => readdirSync(join(ROOT, 'tests/conformance', d))
      .filter((f) => f.endsWith('.calf')).sort().map((f) => join(ROOT, 'tests/conformance', d, f)));
  let totalMs = 0;
  for (const path of clips) {
    const name = basename(path, '.calf');
    const hashesPath = path.replace(/\.calf$/, '.hashes');
    const want = existsSync(hashesPath) ? readFileSync(hashesPath, 'utf8').split('\n').filter(Boolean) : [];
    const bytes = new Uint8Array(readFileSync(path));
    const t0 = performance.now();
    let got;
    try {
      got = await decodeLines(bytes, codecs);
    } catch (e) {
      if (!(e instanceof CalfError)) throw e;
      got = { lines: [], problems: [e.message] };
    }
    const ms = performance.now() - t0;
    totalMs += ms;
    const diffs = [];
    for (let i = 0; i < Math.max(want.length, got.lines.length); ++i) {
      if (want[i] !== got.lines[i]) diffs.push(`line ${i + 1}: expected '${want[i] ?? ''}', got '${got.lines[i] ?? ''}'`);
    }
    // A clip with a dropped view has problems (SPEC §14); any other clip must have none.
    const expectProblem = name.includes('dropped_view');
    if (expectProblem !== (got.problems.length > 0)) diffs.push(`problems: ${got.problems.join('; ') || 'none'}`);
    if (expectProblem && !got.problems.every((p) => p.startsWith('CALF-E202'))) diffs.push(`problems: ${got.problems.join('; ')}`);
    console.log(`${name}: ${diffs.length ? 'FAIL' : 'ok'}, ${got.lines.length} lines, ${ms.toFixed(1)} ms` +
      (got.problems.length ? ` (${got.problems[0]})` : ''));
    for (const d of diffs.slice(0, 5)) console.log(`  ${name}: ${d}`);
    if (diffs.length) ++failures;
  }
  if (process.argv.length <= 2) {
    const negative = await negativeChecks(codecs);
    for (const p of negative) console.log(`web conformance: ${p}`);
    if (!negative.length) {
      console.log('web conformance: a flipped colour byte is refused (CALF-E058), and with its hash rewritten changes a hash line; ' +
        'flipped coverage bytes change a hash line or give CALF-E065; AV1 colour\'s YCbCr formulas and HDR curve give SPEC\'s values, 4:4:4 pictures each texel\'s own chroma, 4:4:4 goes to the WebAssembly decoder where WebCodecs lacks the High profile (else CALF-E203), bad GOP heads and curves CALF-E067, bad pictures CALF-E302');
    }
    failures += negative.length;
    const t0 = performance.now();
    const corpus = await containerCorpus(codecs);
    for (const p of corpus.problems) console.log(`web conformance: container corpus: ${p}`);
    console.log(`web conformance: container corpus: ${corpus.files - corpus.problems.length} of ${corpus.files} files as the manifest says, ${(performance.now() - t0).toFixed(0)} ms`);
    failures += corpus.problems.length;
    const damaged = await lightfieldCorpus(codecs);
    for (const p of damaged.problems) console.log(`web conformance: lightfield fuzz corpus: ${p}`);
    console.log(`web conformance: lightfield fuzz corpus: ${damaged.files - damaged.problems.length} of ${damaged.files} clips refused (CALF-E202) or decoded as their names say`);
    failures += damaged.problems.length;
    const kinds = await kindCorpus(codecs);
    for (const p of kinds.problems) console.log(`web conformance: tiles and mesh fuzz corpora: ${p}`);
    console.log(`web conformance: tiles and mesh fuzz corpora: ${kinds.files - kinds.problems.length} of ${kinds.files} clips refused with calf-verify's id or decoded`);
    failures += kinds.problems.length;
  }
  console.log(`web conformance: ${clips.length - failures} of ${clips.length} clips reproduce their hashes ` +
    `(AV1 colour, 4:2:0 and 4:4:4, through the WebAssembly decoder), ${totalMs.toFixed(0)} ms decoding`);
  process.exit(failures ? 1 : 0);
}

if (process.argv[1] && import.meta.url.endsWith(basename(process.argv[1]))) await main();
