// Validates glTF files with the Khronos glTF-Validator and prints one JSON line per file:
// {"file": ..., "errors": N, "warnings": N, "messages": [{"code", "severity", "message", "pointer"}]}.
// Usage: node validate.mjs FILE...
import { readFile } from "node:fs/promises";
import validator from "gltf-validator";

for (const file of process.argv.slice(2)) {
  const bytes = new Uint8Array(await readFile(file));
  const report = await validator.validateBytes(bytes, { maxIssues: 100 });
  const messages = report.issues.messages.map(({ code, severity, message, pointer }) => ({
    code,
    severity,
    message,
    pointer,
  }));
  const { numErrors: errors, numWarnings: warnings } = report.issues;
  console.log(JSON.stringify({ file, errors, warnings, messages }));
}
