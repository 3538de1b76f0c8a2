// Runs Khronos' glTF-Validator (the npm package gltf-validator, installed by tools/setup.sh into
// build/npm) on one .glb / .gltf file: a glTF reader written independently of assimp.
// Usage: node gltf_validate.js FILE VALIDATOR_DIR
// Prints "errors E warnings W triangles T vertices V" (T and V as the validator counts them) and
// exits 1 when the file has errors or cannot be read.
'use strict';
const fs = require('fs');
const path = require('path');

const [file, validatorDir] = process.argv.slice(2);
if (!file || !validatorDir) {
  console.error('usage: node gltf_validate.js FILE VALIDATOR_DIR');
  process.exit(2);
}
const validator = require(path.resolve(validatorDir));
validator
  .validateBytes(new Uint8Array(fs.readFileSync(file)), {
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
                `triangles ${info.totalTriangleCount} vertices ${info.totalVertexCount}`);
    for (const m of report.issues.messages.filter((x) => x.severity === 0).slice(0, 5)) {
      console.log(`error ${m.code} ${m.pointer || ''}: ${m.message}`);
    }
    process.exit(report.issues.numErrors === 0 ? 0 : 1);
  })
  .catch((e) => {
    console.error('validator failed: ' + e);
    process.exit(1);
  });
