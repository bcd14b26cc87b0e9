// Validates one .glb/.gltf file with the Khronos glTF-Validator and prints a JSON summary:
// {"numErrors", "numWarnings", "numInfos", "numHints", "messages": [first 50 issues]}.
// Exit code: 0 when the file has no errors, 1 when it has, 2 on a usage or read failure.
// Usage: node tools/validate-gltf/validate.mjs FILE.glb
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import { validateBytes } from 'gltf-validator';

const file = process.argv[2];
if (!file || process.argv.length > 3) {
  console.error('usage: node validate.mjs FILE.glb');
  process.exit(2);
}

try {
  const bytes = new Uint8Array(await readFile(file));
  const report = await validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 0,
    writeTimestamp: false,
    externalResourceFunction: (uri) =>
      readFile(path.resolve(path.dirname(file), decodeURIComponent(uri))).then((data) => new Uint8Array(data)),
  });
  const { numErrors, numWarnings, numInfos, numHints, messages } = report.issues;
  const summary = {
    validatorVersion: report.validatorVersion,
    numErrors,
    numWarnings,
    numInfos,
    numHints,
    messages: messages.slice(0, 50).map(({ code, severity, pointer, message }) => ({ code, severity, pointer, message })),
  };
  console.log(JSON.stringify(summary));
  process.exit(numErrors > 0 ? 1 : 0);
} catch (error) {
  console.error(`validate.mjs: ${file}: ${error?.message ?? error}`);
  process.exit(2);
}
