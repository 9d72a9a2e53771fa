// The schemas of `pdeshape schema` checked through the Even Better TOML language server
// (@taplo/lsp, locked in package-lock.json): every bundled example is valid against its schema
// (design or morph), a fit template against the template schema, a key another curve type takes
// is flagged in a [curves.X] table, and completion in a [curves.X] table of each type offers
// that type's own keys. Usage: node check.mjs PDESHAPE_BINARY REPOSITORY
import pkg from "@taplo/lsp";
import { execFileSync } from "node:child_process";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { fileURLToPath, pathToFileURL } from "node:url";

const { TaploLsp } = pkg;
const [bin, repo] = process.argv.slice(2);
if (!bin || !repo) {
  console.error("usage: node check.mjs PDESHAPE_BINARY REPOSITORY");
  process.exit(2);
}
const work = fs.mkdtempSync(path.join(os.tmpdir(), "pdeshape-schema-"));
const schemaFile = (kind) => {
  const p = path.join(work, `${kind}.schema.json`);
  fs.writeFileSync(p, execFileSync(bin, ["schema", "--kind", kind]));
  return p;
};
const schemas = { design: schemaFile("design"), morph: schemaFile("morph"), template: schemaFile("template") };

const env = {
  now: () => new Date(),
  envVar: (n) => process.env[n],
  envVars: () => Object.entries(process.env),
  stdErrAtty: () => false,
  stdin: process.stdin,
  stdout: process.stdout,
  stderr: process.stderr,
  glob: () => [],
  readFile: async (p) => fs.promises.readFile(p),
  writeFile: async (p, b) => fs.promises.writeFile(p, b),
  urlToFilePath: (u) => (u.startsWith("file:") ? fileURLToPath(u) : u),
  isAbsolute: (p) => path.isAbsolute(p),
  cwd: () => work,
  findConfigFile: () => undefined,
  fetch: { fetch, Headers, Request, Response },
};
const settings = {
  schema: { enabled: true, associations: {}, catalogs: [], links: false },
  completion: { maxKeys: 5 },
  formatter: {},
  rules: [],
};
let next = 0;
const pending = new Map();
const diagnostics = new Map();
const waiting = new Map();
let lsp;
// The server's own log lines (INFO/WARN) go to stderr; keep them out of the report.
const realWrite = process.stderr.write.bind(process.stderr);
process.stderr.write = (chunk, ...rest) =>
  process.env.TAPLO_LOG ? realWrite(chunk, ...rest) : true;
lsp = await TaploLsp.initialize(env, {
  onMessage(m) {
    if (m.id !== undefined && m.method === undefined) {
      const r = pending.get(m.id);
      pending.delete(m.id);
      if (r) r(m);
    } else if (m.method === "workspace/configuration") {
      lsp.send({ jsonrpc: "2.0", id: m.id, result: m.params.items.map(() => settings) });
    } else if (m.id !== undefined) {
      lsp.send({ jsonrpc: "2.0", id: m.id, result: null });
    } else if (m.method === "textDocument/publishDiagnostics") {
      diagnostics.set(m.params.uri, m.params.diagnostics);
      const w = waiting.get(m.params.uri);
      if (w) w();
    }
  },
});
const request = (method, params) =>
  new Promise((resolve) => {
    const id = ++next;
    pending.set(id, resolve);
    lsp.send({ jsonrpc: "2.0", id, method, params });
  });
const notify = (method, params) => lsp.send({ jsonrpc: "2.0", method, params });
const root = pathToFileURL(work).href;
await request("initialize", {
  processId: null,
  rootUri: root,
  capabilities: { workspace: { configuration: true } },
  initializationOptions: { configurationSection: "evenBetterToml", cachePath: path.join(work, "cache") },
  workspaceFolders: [{ uri: root, name: "schema" }],
});
notify("initialized", {});

let opened = 0;
// Opens `text` under `schema` (an Even Better TOML `#:schema` directive on the first line) and
// returns the document's URI once the server has published its diagnostics.
async function open(text, schema) {
  const uri = pathToFileURL(path.join(work, `doc${++opened}.toml`)).href;
  const published = new Promise((resolve) => waiting.set(uri, resolve));
  notify("textDocument/didOpen", {
    textDocument: { uri, languageId: "toml", version: 1, text: `#:schema ${pathToFileURL(schema).href}\n${text}` },
  });
  await Promise.race([published, new Promise((r) => setTimeout(r, 20000))]);
  // A second publication may follow the schema's association; let it arrive.
  await new Promise((r) => setTimeout(r, 300));
  return uri;
}
const errorsOf = (uri) => (diagnostics.get(uri) || []).filter((d) => d.severity === 1).map((d) => `${d.range.start.line}: ${d.message}`);

const failures = [];
// 1. Every example, valid against its schema.
const examples = [];
const walk = (dir) => {
  for (const e of fs.readdirSync(dir, { withFileTypes: true })) {
    const p = path.join(dir, e.name);
    if (e.isDirectory()) walk(p);
    else if (e.name.endsWith(".toml")) examples.push(p);
  }
};
walk(path.join(repo, "examples"));
examples.sort();
for (const p of examples) {
  const text = fs.readFileSync(p, "utf8");
  const kind = /^\[morph\]/m.test(text) ? "morph" : "design";
  const uri = await open(text, schemas[kind]);
  const errors = errorsOf(uri);
  if (!diagnostics.has(uri)) failures.push(`${path.relative(repo, p)}: no diagnostics published`);
  if (errors.length) failures.push(`${path.relative(repo, p)} (${kind}): ${errors.join("; ")}`);
}
console.log(`${examples.length} examples checked against their schemas`);

// 2. A fit template (the module documentation's).
{
  const template = `a = 0.5\n[[parts]]\nname = "left"\nmode = "tube"\naxis = [0, 0, 1]\norigin = [-1, 0, 0]\npositions = [0.0, 2.0]\nstart = "pole"\nsections = 32\n[[parts]]\nname = "bend"\nplanes = [\n  { point = [-1, 0, 2], normal = [0, 0, 1] },\n  { point = [0, 0, 3], normal = [1, 0, 0] },\n]\n`;
  const errors = errorsOf(await open(template, schemas.template));
  if (errors.length) failures.push(`template: ${errors.join("; ")}`);
  const bad = errorsOf(await open(template.replace('mode = "tube"', 'mode = "cube"'), schemas.template));
  if (!bad.length) failures.push("template: mode = \"cube\" not flagged");
}

// 3. Per curve type: its keys completed, a key of another type flagged.
const design = JSON.parse(fs.readFileSync(schemas.design, "utf8"));
const curve = design.definitions.CurveSpec;
const branches = [];
for (let c = curve; c && c.if; c = c.else) branches.push([c.if.properties.type.const, c.then]);
if (branches.length < 10) failures.push(`only ${branches.length} curve types in the schema`);
const allKeys = Object.keys(curve.properties);
let most = 0;
for (const [type, branch] of branches) {
  const own = Object.keys(branch.properties).filter((k) => k !== "type");
  const uri = await open(`[curves.c]\ntype = "${type}"\n\n`, schemas.design);
  const c = await request("textDocument/completion", { textDocument: { uri }, position: { line: 3, character: 0 } });
  const items = c.result ? (Array.isArray(c.result) ? c.result : c.result.items) : [];
  const labels = new Set(items.map((i) => i.label));
  const missing = own.filter((k) => !labels.has(k));
  if (missing.length) failures.push(`[curves.c] type = "${type}": completion lacks ${missing.join(", ")}`);
  if (items.length > allKeys.length) failures.push(`[curves.c] type = "${type}": ${items.length} completion items`);
  most = Math.max(most, items.length);
  const stranger = allKeys.find((k) => k !== "type" && !own.includes(k));
  const flagged = errorsOf(await open(`[curves.c]\ntype = "${type}"\n${stranger} = 1\n`, schemas.design));
  if (!flagged.some((e) => e.includes(`'${stranger}' was unexpected`)))
    failures.push(`[curves.c] type = "${type}" with ${stranger}: not flagged (${flagged.join("; ")})`);
}
console.log(`${branches.length} curve types: each completes its own keys (at most ${most} items), a key of another type is flagged`);
lsp.dispose();
fs.rmSync(work, { recursive: true, force: true });
if (failures.length) {
  for (const f of failures) console.log(`FAIL: ${f}`);
  console.log(`0 passed, ${failures.length} failed`);
  process.exit(1);
}
console.log("schema check passed");
process.exit(0);
