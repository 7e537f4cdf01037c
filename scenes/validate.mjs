// Validates every scenes/*.gltf with the Khronos glTF validator (npm package gltf-validator),
// loading the external .bin buffers and PNG images, prints each report's messages and exits
// non-zero if any scene has an error (or, with --strict, a warning).
//
//   cd scenes && npm ci --silent && node validate.mjs [--strict]
import { readFile, readdir } from 'node:fs/promises';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import validator from 'gltf-validator';

const here = dirname(fileURLToPath(import.meta.url));
const strict = process.argv.includes('--strict');
const severities = ['error', 'warning', 'info', 'hint'];

const files = (await readdir(here)).filter((f) => f.endsWith('.gltf')).sort();
if (files.length === 0) {
  console.error(`no .gltf files in ${here}`);
  process.exit(1);
}
let failed = 0;
for (const file of files) {
  const bytes = new Uint8Array(await readFile(join(here, file)));
  const report = await validator.validateBytes(bytes, {
    uri: file,
    maxIssues: 0,
    externalResourceFunction: (uri) =>
      readFile(join(here, decodeURIComponent(uri))).then((b) => new Uint8Array(b)),
  });
  const { numErrors, numWarnings, numInfos, numHints } = report.issues;
  const info = report.info ?? {};
  console.log(
    `${file}: ${numErrors} errors, ${numWarnings} warnings, ${numInfos} infos, ${numHints} hints` +
      ` (${info.totalTriangleCount ?? '?'} triangles, ${info.drawCallCount ?? '?'} draw calls,` +
      ` ${info.maxAttributes ?? '?'} max attributes)`,
  );
  for (const m of report.issues.messages) {
    console.log(`  ${severities[m.severity] ?? m.severity} ${m.code} at ${m.pointer ?? '-'}: ${m.message}`);
  }
  if (numErrors > 0 || (strict && numWarnings > 0)) failed += 1;
}
if (failed > 0) {
  console.error(`${failed} of ${files.length} scenes failed validation`);
  process.exit(1);
}
console.log(`all ${files.length} scenes valid`);
