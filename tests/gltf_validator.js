// Run the Khronos glTF Validator on one file and print its JSON report.
// usage: NODE_PATH=<folder with node_modules/gltf-validator> node gltf_validator.js FILE
// (install it with `npm install gltf-validator` in a scratch folder); used by
// tests/test_gltf_write.py when RIGEDIT_GLTF_VALIDATOR points at this script.
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

const file = process.argv[2];
validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
  uri: path.basename(file),
  externalResourceFunction: (uri) => new Promise((resolve, reject) => {
    try {
      resolve(new Uint8Array(fs.readFileSync(path.join(path.dirname(file), decodeURIComponent(uri)))));
    } catch (e) {
      reject(e.toString());
    }
  }),
}).then((report) => console.log(JSON.stringify(report)))
  .catch((e) => { console.error(e); process.exit(1); });
