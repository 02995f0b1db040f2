// tests/browser/origin.test.js — real cross-origin callers in chromium (server/origin.c). Pages are
// served by a node http server of this test on two more ports of 127.0.0.1 (another port is
// another origin): ALLOWED and OTHER.
//   1. Against the daemon of run.sh (UMBRA_URL, default flags): an HTML multipart form on ALLOWED
//      posting a scene to /v1/render is refused (403 page naming --cors-origin) and nothing is
//      rendered (/metrics); a fetch() from there fails in the browser.
//   2. A second daemon started here with --cors-origin ALLOWED: fetch() from ALLOWED renders and
//      the page reads the image and the exposed ETag / Server-Timing; from OTHER, fetch() fails
//      and the form is refused.
// Env: UMBRA_URL, UMBRAD (the binary), CHROMIUM, T (a scratch folder), DAEMON_PRELOAD (ASan).
// Prints "ok - x" / "FAIL - x" and, last, "N passed, N failed".
'use strict';
const http = require('http');
const path = require('path');
const { spawn } = require('child_process');
const fs = require('fs');
const puppeteer = require('puppeteer-core');

const URL = process.env.UMBRA_URL;
const UMBRAD = process.env.UMBRAD || 'build/umbrad';
const CHROMIUM = process.env.CHROMIUM || '/usr/bin/chromium';
const T = process.env.T || fs.mkdtempSync('/tmp/umbra-origin.');
const TIMEOUT = 240000;
const SCENE = JSON.stringify({
  width: 32, height: 32, camera: { position: [0, 1, 4], target: [0, 0, 0] },
  objects: [{ shape: 'box' }], lights: [{ type: 'directional', direction: [-1, -2, -1] }], output: { msaa: 1 },
});
let pass = 0, fail = 0;
function check(name, cond, why) {
  if (cond) { pass++; console.log('ok - ' + name); } else { fail++; console.log('FAIL - ' + name + (why ? ': ' + why : '')); }
}

// The other origins' pages: /form?to=DAEMON (a form with a `scene` field, as any site could
// serve one) and / (an empty page to run fetch() from).
function page(req, res) {
  const u = new global.URL(req.url, 'http://x');
  let body = '<!doctype html><title>another origin</title>';
  if (u.pathname === '/form') {
    const to = u.searchParams.get('to').replace(/"/g, '');
    body += '<form method="post" enctype="multipart/form-data" action="' + to + '/v1/render">' +
      '<textarea name="scene">' + SCENE.replace(/&/g, '&amp;').replace(/</g, '&lt;') + '</textarea>' +
      '<button id="go">render</button></form>';
  }
  res.writeHead(200, { 'Content-Type': 'text/html; charset=utf-8' });
  res.end(body);
}
function listen() {
  return new Promise((resolve) => {
    const s = http.createServer(page);
    s.listen(0, '127.0.0.1', () => resolve(s));
  });
}
function get(url) {
  return new Promise((resolve) => {
    http.get(url, (r) => {
      let d = '';
      r.on('data', (c) => { d += c; });
      r.on('end', () => resolve({ status: r.statusCode, body: d }));
    }).on('error', () => resolve({ status: 0, body: '' }));
  });
}
async function renders(daemon, status) {
  const m = (await get(daemon + '/metrics')).body;
  const line = m.split('\n').find((l) => l.startsWith('umbra_requests_total{route="/v1/render",status="' + status + '"} '));
  return line ? +line.split(' ')[1] : 0;
}
// A second daemon, ready (bounded wait, no fixed sleep).
async function startDaemon(flags) {
  const portFile = path.join(T, 'cors.port');
  try { fs.unlinkSync(portFile); } catch (e) { /* absent */ }
  const log = fs.openSync(path.join(T, 'cors.log'), 'w');
  const env = Object.assign({}, process.env, { LD_PRELOAD: process.env.DAEMON_PRELOAD || '' });
  const proc = spawn(UMBRAD, ['--listen', '127.0.0.1:0', '--port-file', portFile].concat(flags),
    { stdio: ['ignore', log, log], env });
  const end = Date.now() + TIMEOUT;
  while (Date.now() < end && proc.exitCode === null) {
    const port = fs.existsSync(portFile) ? fs.readFileSync(portFile, 'utf8').trim() : '';
    if (port && (await get('http://127.0.0.1:' + port + '/readyz')).status === 200) return { proc, url: 'http://127.0.0.1:' + port };
    await new Promise((r) => setTimeout(r, 100));
  }
  proc.kill('SIGKILL');
  throw new Error('the --cors-origin daemon did not become ready: ' + fs.readFileSync(path.join(T, 'cors.log'), 'utf8').slice(-2000));
}
function stopDaemon(d) {
  return new Promise((resolve) => {
    if (d.proc.exitCode !== null) return resolve(d.proc.exitCode);
    d.proc.on('exit', (code) => resolve(code));
    d.proc.kill('SIGTERM');
  });
}

// Submits the form on `from` to `daemon`; the page the browser lands on.
async function submitForm(tab, from, daemon) {
  await tab.goto(from + '/form?to=' + encodeURIComponent(daemon), { waitUntil: 'load' });
  const [resp] = await Promise.all([tab.waitForNavigation({ timeout: TIMEOUT }), tab.click('#go')]);
  return { status: resp.status(), text: await tab.evaluate(() => document.body.innerText) };
}
// fetch() of a JSON render from the page at `from`: what the page could read of the answer.
async function fetchRender(tab, from, daemon) {
  await tab.goto(from + '/', { waitUntil: 'load' });
  return tab.evaluate(async (daemon, scene) => {
    try {
      const r = await fetch(daemon + '/v1/render', { method: 'POST', body: scene,
        headers: { 'Content-Type': 'application/json', Accept: 'image/png', 'X-Priority': 'interactive' } });
      const blob = await r.blob();
      const bmp = await createImageBitmap(blob);
      return { ok: true, status: r.status, w: bmp.width, h: bmp.height, type: blob.type,
        etag: r.headers.get('ETag'), timing: r.headers.get('Server-Timing') };
    } catch (e) {
      return { ok: false, error: String(e) };
    }
  }, daemon, SCENE);
}

async function main() {
  const [allowedSrv, otherSrv] = [await listen(), await listen()];
  const ALLOWED = 'http://127.0.0.1:' + allowedSrv.address().port;
  const OTHER = 'http://127.0.0.1:' + otherSrv.address().port;
  const browser = await puppeteer.launch({
    executablePath: CHROMIUM, headless: true,
    args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage', '--no-first-run'],
  });
  let cors = null;
  try {
    const tab = await browser.newPage();
    // 1. The default daemon: no cross-origin caller.
    const before = await renders(URL, 200), refused = await renders(URL, 403);
    const f = await submitForm(tab, ALLOWED, URL);
    check('default flags: a cross-origin HTML form is refused (403)', f.status === 403, 'status ' + f.status);
    check('default flags: the refusal names --cors-origin ' + ALLOWED, f.text.includes('--cors-origin ' + ALLOWED), f.text.slice(0, 300));
    const x = await fetchRender(tab, ALLOWED, URL);
    check('default flags: a cross-origin fetch() fails in the browser', !x.ok, JSON.stringify(x));
    check('default flags: nothing rendered (/metrics: no new 200)', (await renders(URL, 200)) === before);
    check('default flags: /metrics counts the refusals', (await renders(URL, 403)) >= refused + 1);

    // 2. A daemon that lets ALLOWED call it.
    cors = await startDaemon(['--workers', '1', '--no-playground', '--cors-origin', ALLOWED]);
    const n0 = await renders(cors.url, 200);
    const ok = await fetchRender(tab, ALLOWED, cors.url);
    check('--cors-origin: fetch() from that origin reads the image (32x32 PNG)',
      ok.ok && ok.status === 200 && ok.w === 32 && ok.h === 32 && ok.type === 'image/png', JSON.stringify(ok));
    check('--cors-origin: the page reads ETag and Server-Timing', ok.ok && /^"/.test(ok.etag || '') && /main;dur=/.test(ok.timing || ''),
      JSON.stringify(ok));
    check('--cors-origin: it rendered once', (await renders(cors.url, 200)) === n0 + 1);
    const no = await fetchRender(tab, OTHER, cors.url);
    check('--cors-origin: fetch() from an unlisted origin fails', !no.ok, JSON.stringify(no));
    const f2 = await submitForm(tab, OTHER, cors.url);
    check('--cors-origin: a form from an unlisted origin is refused (403)', f2.status === 403, 'status ' + f2.status);
    check('--cors-origin: no render for the unlisted origin', (await renders(cors.url, 200)) === n0 + 1);
  } finally {
    await browser.close();
    allowedSrv.close();
    otherSrv.close();
    if (cors) check('--cors-origin daemon exits 0 after SIGTERM', (await stopDaemon(cors)) === 0);
  }
}

main().catch((e) => { fail++; console.log('FAIL - origin test: ' + (e && e.stack || e)); })
  .finally(() => { console.log(pass + ' passed, ' + fail + ' failed'); process.exitCode = fail ? 1 : 0; });
