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
