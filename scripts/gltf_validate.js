// Run the Khronos glTF validator (npm gltf-validator) on .gltf/.glb files. For each file it
// prints "<errors> <warnings> <file>", then one indented line per error or warning.
// Usage: NODE_PATH=build-tools/node_modules node scripts/gltf_validate.js FILE...
// (scripts/install-deps.sh installs the package into build-tools/ when npm is present.)
'use strict';
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

async function run(file) {
    const data = new Uint8Array(fs.readFileSync(file));
    const external = (uri) => new Promise((resolve, reject) => {
        try {
            resolve(new Uint8Array(fs.readFileSync(path.resolve(path.dirname(file), decodeURIComponent(uri)))));
        } catch (e) {
            reject(e.toString());
        }
    });
    const report = await validator.validateBytes(data, { uri: file, maxIssues: 1000, externalResourceFunction: external });
    console.log(report.issues.numErrors + ' ' + report.issues.numWarnings + ' ' + file);
    for (const m of report.issues.messages)
        if (m.severity <= 1) console.log('  ' + (m.severity ? 'warning ' : 'error ') + m.code + ' ' + m.pointer + ': ' + m.message);
}

(async () => {
    for (const f of process.argv.slice(2)) {
        try {
            await run(f);
        } catch (e) {
            console.log('-1 -1 ' + f + '\n  validator failed: ' + e);
        }
    }
})();
