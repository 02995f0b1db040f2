// tests/schema/schema.test.js — api/scene.schema.json against the daemon: every document of
// corpus.js is validated by ajv (JSON Schema 2020-12, strict mode: a keyword ajv does not know
// fails the compile) and POSTed to a real umbrad on loopback (UMBRA_URL); the schema's verdict
// must equal the daemon's (200 = valid, 400 = invalid), and both the corpus's expectation.
// "server" documents are the rules the schema cannot state: the daemon refuses them, the schema
// accepts them. Prints "ok - ..." / "FAIL - ..." and, last, "N passed, N failed".
// Env: UMBRA_URL (required), SCHEMA (default api/scene.schema.json).
'use strict';
const fs = require('fs');
const path = require('path');
const { createRequire } = require('module');
// ajv is test tooling in tests/browser/package.json, next to puppeteer-core.
const requireTooling = createRequire(path.join(__dirname, '..', 'browser', 'package.json'));
const Ajv2020 = requireTooling('ajv/dist/2020');
const corpus = require('./corpus.js');

const url = process.env.UMBRA_URL;
const schemaPath = process.env.SCHEMA || path.join(__dirname, '..', '..', 'api', 'scene.schema.json');
let pass = 0, fail = 0;
const ok = (name) => { console.log(`ok - ${name}`); pass++; };
const nok = (name, why) => { console.log(`FAIL - ${name}${why ? ': ' + why : ''}`); fail++; };

async function daemonVerdict(doc, accept) {
  const headers = { 'Content-Type': 'application/json' };
  if (accept) headers.Accept = accept;
  const r = await fetch(`${url}/v1/render`, { method: 'POST', headers, body: JSON.stringify(doc) });
  const body = await r.text().catch(() => '');
  if (r.status === 200) return { valid: true, status: 200 };
  let problem = {};
  try { problem = JSON.parse(body); } catch (e) { /* not problem+json: reported below */ }
  return { valid: false, status: r.status, pointer: problem.pointer, detail: problem.detail };
}

async function main() {
  if (!url) { nok('UMBRA_URL is set'); return; }
  let validate;
  try {
    const ajv = new Ajv2020({ strict: true, strictRequired: false, strictTuples: false, allErrors: true });
    validate = ajv.compile(JSON.parse(fs.readFileSync(schemaPath, 'utf8')));
    ok('scene.schema.json compiles with ajv (2020-12, strict)');
  } catch (e) {
    nok('scene.schema.json compiles with ajv (2020-12, strict)', e.message);
    return;
  }
  const names = new Set();
  for (const [name, expect, doc, accept] of corpus) {
    if (names.has(name)) nok(`corpus names are unique: ${name}`);
    names.add(name);
    const schemaValid = validate(doc);
    const why = schemaValid ? '' : validate.errors.slice(0, 2).map((e) => `${e.instancePath || '/'} ${e.message}`).join('; ');
    let d;
    try { d = await daemonVerdict(doc, accept); } catch (e) { nok(name, `POST failed: ${e.message}`); continue; }
    const said = d.valid ? 'daemon 200' : `daemon ${d.status} ${d.pointer || ''} ${d.detail || ''}`.trim();
    if (!d.valid && d.status !== 400) { nok(name, `${said} (neither 200 nor 400)`); continue; }
    const daemonWants = expect === 'accept';
    if (d.valid !== daemonWants) { nok(name, `expected the daemon to ${expect}; ${said}`); continue; }
    const schemaWants = expect !== 'reject';   // "server": the schema cannot tell
    if (schemaValid !== schemaWants) {
      nok(name, `schema ${schemaValid ? 'accepts' : 'rejects (' + why + ')'}, ${said}`);
      continue;
    }
    ok(`${name}: ${expect === 'server' ? 'daemon 400, schema cannot tell' : said.split(' ').slice(0, 3).join(' ') + ', schema agrees'}`);
  }
}

main().catch((e) => nok('schema test', e.stack)).finally(() => console.log(`${pass} passed, ${fail} failed`));
