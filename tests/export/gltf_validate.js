// Runs Khronos' glTF-Validator (the npm package gltf-validator, installed by tools/setup.sh into
// build/npm) on one .glb / .gltf file: a glTF reader written independently of assimp.
// Usage: node gltf_validate.js FILE VALIDATOR_DIR
// Prints "errors E warnings W triangles T vertices V unused-extensions U" (T and V as the validator
// counts them; U: the names in extensionsUsed that no "extensions" object of the file uses, which
// the validator does not report) and exits 1 when the file has errors or cannot be read.
'use strict';
const fs = require('fs');
const path = require('path');

const [file, validatorDir] = process.argv.slice(2);
if (!file || !validatorDir) {
  console.error('usage: node gltf_validate.js FILE VALIDATOR_DIR');
  process.exit(2);
}
const validator = require(path.resolve(validatorDir));
const bytes = fs.readFileSync(file);

// The file's JSON: a .gltf's text, or a .glb's first chunk (after the 12-byte header and the
// chunk's length and type).
function gltfJson() {
  if (bytes.length >= 20 && bytes.readUInt32LE(0) === 0x46546c67) {
    return JSON.parse(bytes.subarray(20, 20 + bytes.readUInt32LE(12)).toString('utf8'));
  }
  return JSON.parse(bytes.toString('utf8'));
}
function unusedExtensions(json) {
  const used = new Set();
  const walk = (x) => {
    if (Array.isArray(x)) {
      x.forEach(walk);
    } else if (x !== null && typeof x === 'object') {
      for (const [k, v] of Object.entries(x)) {
        if (k === 'extensions' && v !== null && typeof v === 'object') {
          Object.keys(v).forEach((name) => used.add(name));
        }
        walk(v);
      }
    }
  };
  walk(json);
  return (json.extensionsUsed || []).filter((name) => !used.has(name));
}
const unused = unusedExtensions(gltfJson());

validator
  .validateBytes(new Uint8Array(bytes), {
    uri: path.basename(file),
    // A .gltf's buffer (calf writes NAME.bin beside NAME.gltf), read from the file's folder.
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        fs.readFile(path.join(path.dirname(file), decodeURIComponent(uri)), (err, data) =>
          err ? reject(err) : resolve(new Uint8Array(data)));
      }),
  })
  .then((report) => {
    const info = report.info || {};
    console.log(`errors ${report.issues.numErrors} warnings ${report.issues.numWarnings} ` +
                `triangles ${info.totalTriangleCount} vertices ${info.totalVertexCount} ` +
                `unused-extensions ${unused.length}${unused.length ? ' (' + unused.join(', ') + ')' : ''}`);
    for (const m of report.issues.messages.filter((x) => x.severity <= 1).slice(0, 5)) {
      console.log(`${m.severity === 0 ? 'error' : 'warning'} ${m.code} ${m.pointer || ''}: ${m.message}`);
    }
    process.exit(report.issues.numErrors === 0 ? 0 : 1);
  })
  .catch((e) => {
    console.error('validator failed: ' + e);
    process.exit(1);
  });
