// Loads the pinned npm packages (tools/setup.sh installs them into build/npm) for node and
// returns the page decoder's codecs, or null with the reason when a package is missing.
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
  return { codecs: await makeCodecs({ hashWasm, fzstd, xz }) };
}
