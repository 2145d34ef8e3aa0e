// Run the Khronos glTF validator (npm gltf-validator) on one .gltf/.glb file and print
// "<errors> <warnings>" on the first line, then one line per error or warning.
// Usage: NODE_PATH=build-tools/node_modules node scripts/gltf_validate.js FILE
// (scripts/install-deps.sh installs the package into build-tools/ when npm is present.)
'use strict';
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');
const file = process.argv[2];
const data = new Uint8Array(fs.readFileSync(file));
const external = (uri) => new Promise((resolve, reject) => {
    try {
        resolve(new Uint8Array(fs.readFileSync(path.resolve(path.dirname(file), decodeURIComponent(uri)))));
    } catch (e) {
        reject(e.toString());
    }
});
validator.validateBytes(data, { uri: file, maxIssues: 1000, externalResourceFunction: external })
    .then((report) => {
        console.log(report.issues.numErrors + ' ' + report.issues.numWarnings);
        for (const m of report.issues.messages)
            if (m.severity <= 1) console.log((m.severity ? 'warning ' : 'error ') + m.code + ' ' + m.pointer + ': ' + m.message);
    })
    .catch((e) => {
        console.log('validator failed: ' + e);
        process.exit(2);
    });
