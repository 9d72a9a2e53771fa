// Runs the Khronos glTF validator on each .glb named on the command line and prints one JSON line
// per file: {"file", "errors", "warnings", "infos", "messages"}. Exits 1 if any file has an error
// or a warning.
import { readFile } from "node:fs/promises";
import validator from "gltf-validator";

let bad = 0;
for (const file of process.argv.slice(2)) {
  const data = new Uint8Array(await readFile(file));
  const report = await validator.validateBytes(data, { maxIssues: 50 });
  const i = report.issues;
  const messages = i.messages
    .filter((m) => m.severity <= 1)
    .map((m) => `${m.code} ${m.pointer ?? ""} ${m.message}`);
  console.log(
    JSON.stringify({
      file,
      errors: i.numErrors,
      warnings: i.numWarnings,
      infos: i.numInfos,
      messages,
    }),
  );
  if (i.numErrors > 0 || i.numWarnings > 0) bad += 1;
}
process.exit(bad > 0 ? 1 : 0);
