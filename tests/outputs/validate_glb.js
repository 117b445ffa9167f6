// Runs the Khronos glTF validator (npm gltf-validator) on .glb files:
//   node validate_glb.js FILE.glb...
// Prints each report's counts and messages; exits 1 when a file has an error, or a warning
// that docs/outputs.md does not explain (ALLOWED_WARNINGS).
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

// Warnings the docs explain (docs/outputs.md, "Validator"): none so far.
const ALLOWED_WARNINGS = new Set([]);

async function main() {
  let failed = false;
  for (const file of process.argv.slice(2)) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
      uri: path.basename(file), maxIssues: 200, format: 'glb',
    });
    const i = report.issues;
    console.log(`${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos, ${i.numHints} hints` +
                ` (validator ${report.validatorVersion})`);
    for (const m of i.messages) {
      console.log(`  [${['error', 'warning', 'info', 'hint'][m.severity]}] ${m.code} ${m.pointer || ''}: ${m.message}`);
      if (m.severity === 0 || (m.severity === 1 && !ALLOWED_WARNINGS.has(m.code))) failed = true;
    }
    const info = report.info || {};
    console.log(`  info: ${info.animationCount} animations, ${info.totalVertexCount} vertices, ${info.maxInfluences} max influences, ${info.maxAttributes} max attributes`);
  }
  process.exit(failed ? 1 : 0);
}
main().catch((e) => { console.error(e); process.exit(2); });
