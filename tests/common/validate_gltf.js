// Validates a glTF 2.0 file (.glb or .gltf) with the Khronos glTF validator (npm package
// `gltf-validator`, found through NODE_PATH) and prints its report as JSON on standard output.
// Usage: node validate_gltf.js FILE
const fs = require('fs');
const validator = require('gltf-validator');
const file = process.argv[2];
const bytes = new Uint8Array(fs.readFileSync(file));
validator
  .validateBytes(bytes, { maxIssues: 100, externalResourceFunction: () => Promise.reject(new Error('external resources are not used')) })
  .then((report) => { process.stdout.write(JSON.stringify(report)); })
  .catch((e) => { process.stderr.write(String(e) + '\n'); process.exit(1); });
