// Runs the Khronos glTF validator (npm gltf-validator, pinned in package.json)
// on one glTF/GLB file. Exits 0 when the report has no errors, 1 when it has
// any (they are printed), 2 when the file cannot be read or validated.
//
//   node tests/tools/validate.mjs FILE.glb [--max-warnings N] [--quiet] [--soupuv-output]
//
// --soupuv-output also checks what soupuv promises on top of validity: every
// primitive has TEXCOORD_0, its material a baseColorTexture on texCoord 0, and
// every image lives in the BIN chunk (bufferView + mimeType, no URI).
//
// External resources are resolved beside the file, so a .gltf with .bin files
// validates too.
import fs from 'node:fs';
import path from 'node:path';
import { createRequire } from 'node:module';

const require = createRequire(import.meta.url);
const validator = require('gltf-validator');

const args = process.argv.slice(2);
const file = args.find((a) => !a.startsWith('--'));
const quiet = args.includes('--quiet');
const soupuvOutput = args.includes('--soupuv-output');
const maxWarningsAt = args.indexOf('--max-warnings');
const maxWarnings = maxWarningsAt >= 0 ? Number(args[maxWarningsAt + 1]) : Infinity;
if (!file) {
  console.error('usage: node validate.mjs FILE.glb [--max-warnings N] [--quiet]');
  process.exit(2);
}

let bytes;
try {
  bytes = fs.readFileSync(file);
} catch (e) {
  console.error(`validate: cannot read ${file}: ${e.message}`);
  process.exit(2);
}

// The JSON chunk of a GLB (or the whole file for .gltf).
function gltfJson(bytes) {
  if (bytes.length >= 20 && bytes.readUInt32LE(0) === 0x46546c67) {
    const length = bytes.readUInt32LE(12);
    return JSON.parse(bytes.subarray(20, 20 + length).toString('utf8'));
  }
  return JSON.parse(bytes.toString('utf8'));
}

function soupuvProblems(doc) {
  const problems = [];
  (doc.meshes ?? []).forEach((mesh, m) => mesh.primitives.forEach((p, i) => {
    const where = `meshes[${m}].primitives[${i}]`;
    if (p.attributes?.TEXCOORD_0 === undefined) problems.push(`${where} has no TEXCOORD_0`);
    const material = doc.materials?.[p.material];
    const texture = material?.pbrMetallicRoughness?.baseColorTexture;
    if (!texture) problems.push(`${where}: its material has no baseColorTexture`);
    else if ((texture.texCoord ?? 0) !== 0) problems.push(`${where}: baseColorTexture not on TEXCOORD_0`);
  }));
  if (!(doc.meshes ?? []).length) problems.push('no meshes');
  if (!(doc.images ?? []).length) problems.push('no images');
  (doc.images ?? []).forEach((img, i) => {
    if (img.uri !== undefined || img.bufferView === undefined || !img.mimeType)
      problems.push(`images[${i}] is not embedded with bufferView + mimeType`);
  });
  return problems;
}

const severities = ['error', 'warning', 'info', 'hint'];
try {
  const report = await validator.validateBytes(new Uint8Array(bytes), {
    uri: path.basename(file),
    maxIssues: 1000,
    externalResourceFunction: (uri) =>
      fs.promises.readFile(path.resolve(path.dirname(file), decodeURIComponent(uri))),
  });
  const { numErrors, numWarnings, numInfos, numHints } = report.issues;
  for (const m of report.issues.messages) {
    if (m.severity === 0 || (m.severity === 1 && !quiet))
      console.log(`${severities[m.severity]} ${m.code} ${m.pointer ?? ''}: ${m.message}`);
  }
  console.log(`${file}: ${numErrors} errors, ${numWarnings} warnings, ${numInfos} infos, ${numHints} hints`);
  const problems = soupuvOutput ? soupuvProblems(gltfJson(bytes)) : [];
  for (const p of problems) console.log(`soupuv-output: ${p}`);
  process.exit(numErrors > 0 || numWarnings > maxWarnings || problems.length > 0 ? 1 : 0);
} catch (e) {
  console.error(`validate: ${file}: ${e}`);
  process.exit(2);
}
