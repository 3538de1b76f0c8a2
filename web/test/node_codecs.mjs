// Loads the pinned npm packages (tools/setup.sh installs them into build/npm) for node and
// returns the page decoder's codecs, or null with the reason when a package is missing. AV1
// colour goes through libav.js's av1-opus variant (node has no WebCodecs); without it
// `codecs.av1` is null and `av1Missing` says why.
import { createRequire } from 'node:module';
import { existsSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';
import { makeCodecs } from '../src/codecs.js';

export const ROOT = join(dirname(fileURLToPath(import.meta.url)), '..', '..');
export const NPM = process.env.CALF_NPM_DIR ?? join(ROOT, 'build', 'npm');

export async function loadCodecs() {
  const modules = join(NPM, 'node_modules');
  for (const p of ['hash-wasm', 'fzstd', 'xz-decompress']) {
    if (!existsSync(join(modules, p, 'package.json'))) return { missing: `${p} is not installed in ${modules} (run tools/setup.sh)` };
  }
  const require = createRequire(pathToFileURL(join(NPM, 'package.json')));
  const hashWasm = require('hash-wasm');
  const fzstd = await import(pathToFileURL(join(modules, 'fzstd', 'esm', 'index.mjs')));
  const xz = require('xz-decompress');
  const variant = '@libav.js/variant-av1-opus';
  const av1Missing = existsSync(join(modules, variant, 'package.json')) ? null : `${variant} is not installed in ${modules} (run tools/setup.sh)`;
  const av1Wasm = av1Missing ? null : async () => {
    const libav = await require(variant).LibAV({ noworker: true });
    await libav.av_log_set_level(libav.AV_LOG_QUIET);  // problems come back as CALF-E301
    return libav;
  };
  return { codecs: await makeCodecs({ hashWasm, fzstd, xz, av1Wasm }), av1Missing };
}
