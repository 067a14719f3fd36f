// Runs the Khronos glTF validator on .glb files:
//
//     node tests/gltf/validate.js FILE.glb...
//
// Prints each file's issue counts and messages; exits 1 when any file has an
// error or a warning (infos and hints are printed only), 2 when the
// validator is not installed. tests/export.rs runs it on exports.
'use strict';

const fs = require('fs');
const path = require('path');

let validator;
try {
    validator = require('gltf-validator');
} catch (err) {
    console.error(`the glTF validator is not installed (${err.code}): run npm ci --prefix tests/gltf`);
    process.exit(2);
}

const SEVERITY = ['error', 'warning', 'info', 'hint'];

async function validate(file) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
        uri: path.basename(file),
        format: 'glb',
        maxIssues: 0, // all of them
    });
    const { numErrors, numWarnings, numInfos, numHints, messages } = report.issues;
    console.log(`${file}: ${numErrors} errors, ${numWarnings} warnings, ${numInfos} infos, ${numHints} hints`);
    for (const m of messages) {
        console.log(`  ${SEVERITY[m.severity]} ${m.code} ${m.pointer || m.offset || ''}: ${m.message}`);
    }
    return numErrors + numWarnings === 0;
}

async function main(files) {
    if (files.length === 0) {
        console.error('usage: node tests/gltf/validate.js FILE.glb...');
        return 2;
    }
    let clean = true;
    for (const file of files) {
        clean = (await validate(file)) && clean;
    }
    return clean ? 0 : 1;
}

main(process.argv.slice(2)).then(
    (code) => {
        process.exitCode = code;
    },
    (err) => {
        console.error(`validation failed: ${err}`);
        process.exitCode = 1;
    },
);
