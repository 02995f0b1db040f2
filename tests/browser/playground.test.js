// tests/browser/playground.test.js — the playground page in a real browser: Debian's chromium,
// headless, driven by puppeteer-core (test tooling only). Run by tests/browser/run.sh with
// UMBRA_URL (a running umbrad) and CHROMIUM; SHOT=path also saves a screenshot there.
// Prints "ok - x" / "FAIL - x" and, last, "N passed, N failed".
'use strict';
const puppeteer = require('puppeteer-core');

const URL = process.env.UMBRA_URL;
const CHROMIUM = process.env.CHROMIUM || '/usr/bin/chromium';
const TIMEOUT = 240000;   // one render on a busy lavapipe machine can be slow
let pass = 0, fail = 0;
function check(name, cond, why) {
  if (cond) { pass++; console.log('ok - ' + name); } else { fail++; console.log('FAIL - ' + name + (why ? ': ' + why : '')); }
}

// A binary glTF with one tetrahedron (positions + indices), built here.
function tetraGlb() {
  const pos = new Float32Array([0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1]);
  const idx = new Uint16Array([0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3]);
  const bin = Buffer.alloc(48 + 24);
  Buffer.from(pos.buffer).copy(bin, 0);
  Buffer.from(idx.buffer).copy(bin, 48);
  const gltf = {
    asset: { version: '2.0' }, scene: 0, scenes: [{ nodes: [0] }], nodes: [{ mesh: 0 }],
    meshes: [{ primitives: [{ attributes: { POSITION: 0 }, indices: 1 }] }],
    buffers: [{ byteLength: bin.length }],
    bufferViews: [{ buffer: 0, byteOffset: 0, byteLength: 48 }, { buffer: 0, byteOffset: 48, byteLength: 24 }],
    accessors: [
      { bufferView: 0, componentType: 5126, count: 4, type: 'VEC3', min: [0, 0, 0], max: [1, 1, 1] },
      { bufferView: 1, componentType: 5123, count: 12, type: 'SCALAR' },
    ],
  };
  let json = Buffer.from(JSON.stringify(gltf));
  json = Buffer.concat([json, Buffer.alloc((4 - json.length % 4) % 4, 0x20)]);
  const head = Buffer.alloc(12), jh = Buffer.alloc(8), bh = Buffer.alloc(8);
  head.write('glTF', 0); head.writeUInt32LE(2, 4); head.writeUInt32LE(12 + 8 + json.length + 8 + bin.length, 8);
  jh.writeUInt32LE(json.length, 0); jh.write('JSON', 4);
  bh.writeUInt32LE(bin.length, 0); bh.write('BIN\0', 4);
  return Buffer.concat([head, jh, json, bh, bin]);
}

// Size, distinct colours and a hash of an <img> on the page.
function imageFacts(page, id) {
  return page.evaluate((id) => {
    const img = document.getElementById(id);
    if (!img || !img.naturalWidth) return { w: 0, h: 0, colours: 0, hash: 0 };
    const c = document.createElement('canvas');
    c.width = img.naturalWidth; c.height = img.naturalHeight;
    const g = c.getContext('2d');
    g.drawImage(img, 0, 0);
    const d = g.getImageData(0, 0, c.width, c.height).data, seen = new Set();
    let hash = 0;
    for (let i = 0; i < d.length; i += 4) {
      const v = (d[i] << 24) | (d[i + 1] << 16) | (d[i + 2] << 8) | d[i + 3];
      seen.add(v);
      hash = (hash * 31 + v) | 0;
    }
    return { w: c.width, h: c.height, colours: seen.size, hash };
  }, id);
}

async function pick(page, label) {
  const value = await page.evaluate((label) => {
    const o = [...document.querySelectorAll('#examples option')].find((x) => x.textContent === label);
    return o ? o.value : null;
  }, label);
  if (value === null) throw new Error('no example ' + label);
  await page.select('#examples', value);
}

// Clicks render (or runs act) and waits for the status to settle.
async function rendered(page, act) {
  await page.waitForFunction(() => !document.getElementById('render').disabled, { timeout: TIMEOUT });
  await page.evaluate(() => { document.getElementById('status').textContent = ''; });
  await (act ? act() : page.click('#render'));
  await page.waitForFunction(() => {
    const s = document.getElementById('status').textContent;
    return s === 'done' || s.startsWith('error') || s.startsWith('not sent') || s.startsWith('request failed');
  }, { timeout: TIMEOUT });
  return page.$eval('#status', (e) => e.textContent);
}

async function main() {
  const browser = await puppeteer.launch({
    executablePath: CHROMIUM, headless: true,
    args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage', '--no-first-run'],
  });
  try {
    const page = await browser.newPage();
    await page.setViewport({ width: 1280, height: 820 });
    const sent = [];
    page.on('request', (r) => { if (r.url().endsWith('/v1/render')) sent.push(r); });
    const errors = [];
    page.on('pageerror', (e) => errors.push(e.message));
    // Content-Security-Policy violations: the console's report and the DOM event, both.
    const violations = [];
    page.on('console', (m) => { if (/Content Security Policy/i.test(m.text())) violations.push(m.text()); });
    await page.evaluateOnNewDocument(() => {
      document.addEventListener('securitypolicyviolation', (e) => {
        (window.__csp = window.__csp || []).push(e.violatedDirective + ' ' + (e.blockedURI || 'inline'));
      });
    });
    const resp = await page.goto(URL + '/', { waitUntil: 'load' });
    check('GET / serves the page', resp.status() === 200 && (await page.title()) === 'umbra playground', 'status ' + resp.status());
    const csp = resp.headers()['content-security-policy'] || '';
    check('GET / has a strict Content-Security-Policy', /default-src 'self'/.test(csp) && /frame-ancestors 'none'/.test(csp) &&
      !/unsafe-inline|unsafe-eval/.test(csp), csp);
    const labels = await page.$$eval('#examples option', (o) => o.map((x) => x.textContent));
    check('examples: every filter, cascades, lights, a model on a shadow catcher',
      ['hard', 'pcf', 'pcss', 'vsm', 'evsm'].every((f) => labels.includes('Filter: ' + f)) &&
      labels.some((l) => l.startsWith('Cascades')) && labels.includes('Spot and point lights') &&
      labels.includes('Model on a shadow catcher, transparent'), labels.join(' | '));
    if (process.env.BENCH) check('examples: the bench scenes are embedded', labels.includes('Bench: thumb-512'), labels.join(' | '));

    // Pick an example, render: the image has the example's size and real content.
    await pick(page, 'Filter: pcss');
    let st = await rendered(page);
    let a = await imageFacts(page, 'image');
    check('render: status done', st === 'done', st);
    check('render: image is 512x384', a.w === 512 && a.h === 384, a.w + 'x' + a.h);
    check('render: non-trivial content', a.colours > 100, a.colours + ' colours');
    const etag = await page.$eval('#etag', (e) => e.textContent);
    const size = await page.$eval('#size', (e) => e.textContent);
    check('render: ETag and size shown', /^"/.test(etag) && /^\d[\d,]* bytes$/.test(size), etag + ' / ' + size);
    const bars = await page.$$eval('#timing div', (d) => d.map((x) => parseFloat(x.style.width)));
    check('render: Server-Timing bar has its stages', bars.length === 7 && bars.some((w) => w > 10), bars.join(','));
    check('line numbers in the gutter', (await page.$eval('#gutter', (g) => g.textContent.split('\n').length)) > 20);

    // The cascades debug view of the street.
    await pick(page, 'Cascades: a street at dusk');
    await rendered(page);
    const street = await imageFacts(page, 'image');
    const before = sent.length;
    st = await rendered(page, () => page.select('#debug', 'cascades'));
    const casc = await imageFacts(page, 'image');
    const body = sent.length > before ? sent[sent.length - 1].postData() || '' : '';
    check('cascades view: requested as output.debug', /"debug":"cascades"/.test(body), body.slice(0, 120));
    check('cascades view: a different image of the same size', st === 'done' && casc.w === 640 && casc.hash !== street.hash,
      st + ' ' + casc.w + 'x' + casc.h);
    await rendered(page, () => page.select('#debug', ''));

    // A problem+json answer points at its line.
    await pick(page, 'An error (zero light direction)');
    st = await rendered(page);
    const text = await page.$eval('#editor', (e) => e.value);
    const lines = text.split('\n');
    const li = lines.findIndex((l, k) => /"direction"/.test(l) && lines.slice(0, k).some((x) => /"lights"/.test(x))) + 1;
    const err = await page.$eval('#error', (e) => ({ hidden: e.hidden, line: +e.dataset.line, text: e.textContent }));
    const bad = await page.$eval('#gutter .bad', (e) => +e.textContent).catch(() => 0);
    check('problem: shown', st.startsWith('error 400') && !err.hidden && /\/lights\/0\/direction/.test(err.text), st + ' ' + err.text);
    check('problem: at the line of /lights/0/direction (' + li + ')', err.line === li && bad === li, 'at ' + err.line + ', gutter ' + bad);
    if (process.env.SHOT) await page.screenshot({ path: process.env.SHOT.replace(/\.png$/, '-error.png') });

    // A JSON syntax error points at its line before anything is sent.
    const n0 = sent.length;
    await page.$eval('#editor', (e) => {
      e.value = '{\n  "width": 64,\n  "height": 64\n  "objects": []\n}\n';
      e.dispatchEvent(new Event('input'));
    });
    st = await rendered(page);
    const serr = await page.$eval('#error', (e) => ({ hidden: e.hidden, line: +e.dataset.line, text: e.textContent }));
    check('syntax error: nothing sent', sent.length === n0 && st.startsWith('not sent'), st);
    check('syntax error: at line 4', !serr.hidden && serr.line === 4, serr.line + ' ' + serr.text);

    // Compare two filters side by side.
    await pick(page, 'Filter: pcf');
    st = await rendered(page, () => page.click('#compare'));
    const ca = await imageFacts(page, 'image'), cb = await imageFacts(page, 'image2');
    const caps = await page.$$eval('figcaption', (f) => f.map((x) => x.textContent));
    check('compare: two images', st === 'done' && ca.w === 512 && cb.w === 512 && ca.hash !== cb.hash, st);
    check('compare: captions name the filters', /pcf/.test(caps[0]) && /pcss/.test(caps[1]), caps.join(' | '));
    await rendered(page, () => page.click('#compare'));

    // Drop a model: sent as multipart, rendered with the thumbnail preset.
    const glb = tetraGlb().toString('base64');
    const m0 = sent.length;
    st = await rendered(page, () => page.evaluate((b64) => {
      const bytes = Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
      const dt = new DataTransfer();
      dt.items.add(new File([bytes], 'tetra.glb', { type: 'model/gltf-binary' }));
      window.dispatchEvent(new DragEvent('drop', { dataTransfer: dt, bubbles: true, cancelable: true }));
    }, glb));
    const mr = sent[m0];
    const ctype = mr ? mr.headers()['content-type'] || '' : '';
    const d = await imageFacts(page, 'image');
    check('drop: sent as multipart/form-data', /^multipart\/form-data/.test(ctype), ctype);
    // The tetrahedron's visible face is evenly lit: beyond the white background, its grey and the
    // anti-aliased edges make a handful of colours (an empty image has 1).
    check('drop: the model renders (512x512, content)', st === 'done' && d.w === 512 && d.h === 512 && d.colours > 5,
      st + ' ' + d.w + 'x' + d.h + ' ' + d.colours);
    check('no script errors', errors.length === 0, errors.join('; '));
    const domViolations = await page.evaluate(() => window.__csp || []);
    check('no Content-Security-Policy violations', violations.length === 0 && domViolations.length === 0,
      (violations.length + domViolations.length) + ': ' + violations.concat(domViolations).slice(0, 2).join('; ').slice(0, 400));

    if (process.env.SHOT) {
      await pick(page, 'Filter: pcss');
      await rendered(page, () => page.click('#compare'));
      await page.screenshot({ path: process.env.SHOT });
    }
  } finally {
    await browser.close();
  }
}

main().catch((e) => { fail++; console.log('FAIL - browser test: ' + (e && e.stack || e)); })
  .finally(() => { console.log(pass + ' passed, ' + fail + ' failed'); process.exitCode = fail ? 1 : 0; });
