// tests/browser/playground.test.js — the playground page in a real browser: Debian's chromium,
// headless, driven by puppeteer-core (test tooling only). Run by tests/browser/run.sh with
// UMBRA_URL (a running umbrad) and CHROMIUM; SHOT=path also saves a screenshot there.
// Prints "ok - x" / "FAIL - x" and, last, "N passed, N failed".
'use strict';
const puppeteer = require('puppeteer-core');
const fs = require('fs');
const os = require('os');
const path = require('path');
const { execFileSync } = require('child_process');

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

// Runs a part of the test; an exception in it (a wait that timed out) is one failure, and the
// rest still runs.
async function section(name, fn) {
  try { await fn(); } catch (e) { fail++; console.log('FAIL - ' + name + ': ' + String(e && e.message || e).split('\n')[0]); }
}

// Sets the editor's text and puts the caret where `mark` (a string in it, removed) was.
async function caretAt(page, text, mark) {
  await page.$eval('#editor', (e, text, mark) => {
    const at = text.indexOf(mark);
    e.value = text.replace(mark, '');
    e.dispatchEvent(new Event('input'));
    e.focus();
    e.setSelectionRange(at, at);
  }, text, mark);
}
const suggestions = (page) => page.$$eval('#suggest:not([hidden]) li', (l) => l.map((x) => ({ name: x.querySelector('b').textContent, help: x.title })));

// The clipboard's text once a click has changed it (the page writes it asynchronously).
async function copied(page, button) {
  await page.evaluate(() => navigator.clipboard.writeText(''));
  await page.click(button);
  await page.waitForFunction(async () => (await navigator.clipboard.readText()) !== '', { timeout: TIMEOUT, polling: 100 });
  return page.evaluate(() => navigator.clipboard.readText());
}

// The plan shown beside the image: its facts by name and its steps' estimate and measure.
function planShown(page) {
  return page.evaluate(() => {
    const box = document.getElementById('plan'), facts = {}, steps = {};
    document.querySelectorAll('#plan-facts tr').forEach((tr) => { facts[tr.dataset.fact] = { value: tr.querySelector('.v').textContent, why: tr.querySelector('.why').textContent }; });
    document.querySelectorAll('#plan-steps tbody tr').forEach((tr) => {
      steps[tr.dataset.step] = { est: parseFloat(tr.cells[1].textContent), measured: parseFloat(tr.cells[2].textContent) };
    });
    return { shown: !box.hidden && box.getBoundingClientRect().height > 0, facts, steps };
  });
}

const pngSize = (buf) => buf.length > 24 && buf.toString('latin1', 1, 4) === 'PNG' ? buf.readUInt32BE(16) + 'x' + buf.readUInt32BE(20) : 'not a PNG';

async function main() {
  const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'umbra-page-'));
  const browser = await puppeteer.launch({
    executablePath: CHROMIUM, headless: true,
    args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage', '--no-first-run'],
  });
  try {
    await browser.defaultBrowserContext().overridePermissions(URL, ['clipboard-read', 'clipboard-write', 'clipboard-sanitized-write']);
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

    await section('on open', async () => {
      // On open the first example is rendered, with no click.
      await page.waitForFunction(() => /^(done|error|request failed)/.test(document.getElementById('status').textContent), { timeout: TIMEOUT });
      const opened = await imageFacts(page, 'image');
      check('on open: the first example is rendered', sent.length === 1 && opened.w === 512 && opened.h === 384 && opened.colours > 100,
        sent.length + ' requests, ' + opened.w + 'x' + opened.h + ', ' + opened.colours + ' colours');
    });

    await section('completion and help', async () => {
      // Completion from api/scene.schema.json: the members allowed at the caret, with descriptions.
      await caretAt(page, '{\n  "camera": {\n    @\n  }\n}\n', '@');
      await page.keyboard.type('"f');
      await page.waitForSelector('#suggest:not([hidden]) li', { timeout: TIMEOUT });
      let sg = await suggestions(page);
      if (process.env.SHOT) await page.screenshot({ path: process.env.SHOT.replace(/\.png$/, '-completion.png') });
      const fov = sg.find((x) => x.name === 'fov_y');
      check('completion: camera members starting with f, described', fov && /Vertical field of view/.test(fov.help) &&
        ['far', 'fit'].every((n) => sg.some((x) => x.name === n)) && !sg.some((x) => x.name === 'width'), JSON.stringify(sg).slice(0, 300));
      await page.keyboard.press('ArrowDown');
      const second = sg[1].name;
      await page.keyboard.press('Tab');
      let edText = await page.$eval('#editor', (e) => e.value);
      check('completion: Tab takes the chosen member', edText.includes('    "' + second + '": \n') && await page.$eval('#suggest', (e) => e.hidden),
        JSON.stringify(edText));
      // The schema's if/then on "shape": a sphere's members, not a box's.
      await caretAt(page, '{\n  "objects": [\n    {"shape": "sphere", @}\n  ]\n}\n', '@');
      await page.keyboard.type('"');
      await page.waitForSelector('#suggest:not([hidden]) li', { timeout: TIMEOUT });
      sg = await suggestions(page);
      check('completion: follows "shape" (a sphere: radius, segments; no size)', ['radius', 'segments', 'material', 'transform'].every((n) => sg.some((x) => x.name === n)) &&
        !sg.some((x) => x.name === 'size' || x.name === 'shape'), sg.map((x) => x.name).join(','));
      await page.keyboard.press('Escape');
      await caretAt(page, '{\n  "lights": [{"type": "@"}]\n}\n', '@');
      await page.keyboard.press('Backspace');
      await page.keyboard.type('"s');
      await page.waitForSelector('#suggest:not([hidden]) li', { timeout: TIMEOUT });
      sg = await suggestions(page);
      await page.keyboard.press('Enter');
      edText = await page.$eval('#editor', (e) => e.value);
      check('completion: enum values ("type": "spot")', sg.length === 1 && sg[0].name === '"spot"' && edText.includes('"type": "spot"'), JSON.stringify(sg) + ' ' + JSON.stringify(edText));
      // Help for the member at the caret, and on hover.
      await caretAt(page, '{\n  "camera": {"position": [1, 2, 3], "fo@v_y": 30}\n}\n', '@');
      await page.keyboard.press('ArrowRight');
      const help = await page.$eval('#help', (e) => e.textContent);
      check('help: the caret\'s member, from the schema', /^\/camera\/fov_y — number.*default 45.*Vertical field of view/.test(help), help);
      const box = await page.$eval('#editor', (e) => { const r = e.getBoundingClientRect(); return { x: r.left, y: r.top }; });
      const cw = await page.evaluate(() => { const g = document.createElement('canvas').getContext('2d'); g.font = getComputedStyle(document.getElementById('editor')).font; return g.measureText('0000000000').width / 10; });
      await page.mouse.move(box.x + 8 + cw * 6.5, box.y + 6 + 18 * 1.5);
      const tip = await page.$eval('#editor', (e) => e.title);
      check('hover help: the member under the mouse', /^\/camera — object/.test(tip), tip);
    });

    // Pick an example, render: the image has the example's size and real content.
    await pick(page, 'Filter: pcss');
    let st = await rendered(page);
    let a = await imageFacts(page, 'image');
    const pcssText = await page.$eval('#editor', (e) => e.value);
    check('render: status done', st === 'done', st);
    check('render: image is 512x384', a.w === 512 && a.h === 384, a.w + 'x' + a.h);
    check('render: non-trivial content', a.colours > 100, a.colours + ' colours');
    // The plan beside the image: asked with Prefer: explain, shown as what was decided and why,
    // then each step's estimate beside its measure.
    let plan = await planShown(page);
    const pf = plan.facts;
    check('plan: asked with Prefer: explain', (sent[sent.length - 1].headers().prefer || '') === 'explain');
    check('plan: shown with views, shadow maps, triangles, pixel shading, visibility pass', plan.shown &&
      ['views', 'shadow maps', 'triangles', 'pixel shading', 'visibility pass', 'memory'].every((k) => pf[k]), JSON.stringify(pf).slice(0, 400));
    check('plan: one view of 512×384', pf.views && pf.views.value === '1 × 512×384 png', pf.views && pf.views.value);
    check('plan: the PCSS light\'s map, drawn or cached, and why', pf['map 0'] && / pcss: (drawn|cached)$/.test(pf['map 0'].value) &&
      pf['map 0'].why.length > 10, JSON.stringify(pf['map 0']));
    check('plan: triangles for the camera and the shadows', pf.triangles && /^[1-9][\d,]* camera, [1-9][\d,]* shadow$/.test(pf.triangles.value),
      pf.triangles && pf.triangles.value);
    check('plan: pixel shading on or off, with why', pf['pixel shading'] && /^(on|off)$/.test(pf['pixel shading'].value) && pf['pixel shading'].why.length > 10,
      JSON.stringify(pf['pixel shading']));
    check('plan: each step estimated and measured', plan.steps.main && plan.steps.main.est > 0 && plan.steps.main.measured > 0 &&
      plan.steps.shadow && plan.steps.shadow.est >= 0 && plan.steps.shadow.measured >= 0 && plan.steps.total.measured > 0, JSON.stringify(plan.steps));
    const etagPlan = await page.$eval('#etag', (e) => e.textContent);
    check('plan: an answer with its plan has no ETag, and says so', etagPlan === 'none (answered with its plan)', etagPlan);
    if (process.env.SHOT) {
      // Wide enough for the plan beside the image.
      await page.setViewport({ width: 1720, height: 900 });
      await page.screenshot({ path: process.env.SHOT.replace(/\.png$/, '-plan.png') });
      await page.setViewport({ width: 1280, height: 820 });
    }
    // Without the plan: the plain image, its ETag; with it again, the maps the plain render drew are cached.
    st = await rendered(page, () => page.click('#explain'));
    const etag = await page.$eval('#etag', (e) => e.textContent);
    const size = await page.$eval('#size', (e) => e.textContent);
    check('render: ETag and size shown', st === 'done' && /^"/.test(etag) && /^\d[\d,]* bytes$/.test(size), etag + ' / ' + size);
    check('plan off: no plan shown, no Prefer sent', !(await planShown(page)).shown && !sent[sent.length - 1].headers().prefer);
    const plainHash = (await imageFacts(page, 'image')).hash;
    st = await rendered(page, () => page.click('#explain'));
    plan = await planShown(page);
    check('plan again: every map cached, none drawn; the same image', st === 'done' && plan.facts['shadow maps'] &&
      /^0 drawn, [1-9]\d* cached$/.test(plan.facts['shadow maps'].value) && (await imageFacts(page, 'image')).hash === plainHash &&
      (await page.$eval('#size', (e) => e.textContent)) === size, JSON.stringify(plan.facts['shadow maps']));
    const bars = await page.$$eval('#timing div', (d) => d.map((x) => parseFloat(x.style.width)));
    check('render: Server-Timing bar has its stages', bars.length === 7 && bars.some((w) => w > 10), bars.join(','));
    check('line numbers in the gutter', (await page.$eval('#gutter', (g) => g.textContent.split('\n').length)) > 20);

    let dl = Buffer.alloc(0);
    await section('download', async () => {
      // The image downloads under a name that says what it is.
      const dlName = await page.$eval('#download', (e) => e.download);
      const cdp = await browser.target().createCDPSession();
      await cdp.send('Browser.setDownloadBehavior', { behavior: 'allow', downloadPath: tmp, eventsEnabled: true });
      const done = new Promise((res) => cdp.on('Browser.downloadProgress', (e) => { if (e.state !== 'inProgress') res(e.state); }));
      await page.click('#download');
      const dlState = await done;
      dl = fs.existsSync(path.join(tmp, dlName)) ? fs.readFileSync(path.join(tmp, dlName)) : Buffer.alloc(0);
      check('download: the PNG saved as ' + dlName, dlState === 'completed' && dlName === 'filter-pcss-512x384.png' && pngSize(dl) === '512x384' &&
        dl.length + ' bytes' === size.replace(/,/g, ''), dlState + ' ' + pngSize(dl) + ' ' + dl.length);
    });

    await section('copy as curl', async () => {
      // Copy as curl: the command makes the same request; its PNG is the page's (the download), byte for byte.
      const cmd = await copied(page, '#curl');
      let out = '';
      try { out = execFileSync('sh', ['-c', cmd], { cwd: tmp, timeout: TIMEOUT, encoding: 'utf8' }); } catch (e) { out = String(e.stderr || e); }
      const curlPng = fs.existsSync(path.join(tmp, 'filter-pcss.png')) ? fs.readFileSync(path.join(tmp, 'filter-pcss.png')) : Buffer.alloc(0);
      check('copy as curl: JSON body, the same image', /^curl .*--data-binary '\{/.test(cmd) && dl.length > 0 && curlPng.equals(dl),
        cmd.slice(0, 160) + ' → ' + pngSize(curlPng) + ' ' + out.slice(0, 200));
    });

    await section('copy link', async () => {
      // Copy link: the scene in the fragment; the link opens that scene and renders it.
      const link = await copied(page, '#share');
      check('copy link: the scene in the fragment', link.startsWith(URL + '/#scene=') && /&enc=deflate-raw$/.test(link) && (await page.evaluate(() => location.href)) === link, link.slice(0, 100));
      const page2 = await browser.newPage();
      const sent2 = [];
      page2.on('request', (r) => { if (r.url().endsWith('/v1/render')) sent2.push(r.postData() || ''); });
      page2.on('pageerror', (e) => errors.push(e.message));
      await page2.goto(link, { waitUntil: 'load' });
      await page2.waitForFunction(() => /^(done|error|request failed)/.test(document.getElementById('status').textContent), { timeout: TIMEOUT });
      const linked = await page2.evaluate(() => ({ text: document.getElementById('editor').value, label: document.querySelector('#examples option:checked').textContent }));
      check('link: opens with the scene, rendered', linked.text === pcssText && linked.label === 'Scene from the link' && sent2.length === 1 &&
        sent2[0] === JSON.stringify(JSON.parse(pcssText)), linked.label + ', ' + sent2.length + ' requests, ' + (linked.text === pcssText ? 'same text' : 'other text'));
      await page2.close();
    });

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
    await section('syntax error on the last line', async () => {
      // On the last line of a long document: the message fully inside the editor, with line and column.
      await pick(page, 'Cascades: a street at dusk');
      await page.$eval('#editor', (e) => { e.value = e.value.replace(/\}\s*$/, ''); e.dispatchEvent(new Event('input')); });
      st = await rendered(page);
      const last = await page.$eval('#error', (e) => {
        const ed = document.getElementById('editor'), r = e.getBoundingClientRect(), q = ed.getBoundingClientRect();
        return { text: e.textContent, line: +e.dataset.line, lines: ed.value.split('\n').length, inside: r.top >= q.top && r.bottom <= q.top + ed.clientHeight && r.height > 0 };
      });
      check('syntax error on the last line: fully shown, with its column', st.startsWith('not sent') && last.inside && last.line === last.lines &&
        /^line \d+, column \d+: JSON syntax: the document ends early/.test(last.text), JSON.stringify(last));
      if (process.env.SHOT) await page.screenshot({ path: process.env.SHOT.replace(/\.png$/, '-syntax.png') });
    });

    await section('shadow view lights', async () => {
      // The shadow view's light list names the lights and selects one.
      await pick(page, 'Spot and point lights');
      const nl = sent.length;
      st = await rendered(page, () => page.select('#debug', 'shadow'));
      const ls = await page.$eval('#debug-light', (s) => ({ texts: [...s.options].map((o) => o.text), shown: s.selectedIndex >= 0 ? s.options[s.selectedIndex].text : '' }));
      const lbody = sent.length > nl ? sent[sent.length - 1].postData() || '' : '';
      check('shadow view: the lights listed, the first selected', ls.texts.join('|') === '0: spot|1: point' && ls.shown === '0: spot' &&
        /"debug":"shadow","debug_light":0/.test(lbody) && st === 'done', JSON.stringify(ls) + ' ' + st);
      await rendered(page, () => page.select('#debug', ''));
    });

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
    const exLabel = await page.$eval('#examples option:checked', (o) => o.textContent);
    check('drop: the example list says the scene is the model\'s', exLabel === 'Dropped model: tetra.glb', exLabel);
    await section('copy as curl with a model', async () => {
      // Copy as curl with a model: multipart, the model by its file name.
      fs.writeFileSync(path.join(tmp, 'tetra.glb'), tetraGlb());
      const mcmd = await copied(page, '#curl');
      let mout = '';
      try { mout = execFileSync('sh', ['-c', mcmd], { cwd: tmp, timeout: TIMEOUT, encoding: 'utf8' }); } catch (e) { mout = String(e.stderr || e); }
      const mpng = fs.existsSync(path.join(tmp, 'tetra.png')) ? fs.readFileSync(path.join(tmp, 'tetra.png')) : Buffer.alloc(0);
      check('copy as curl: multipart, -F model=@tetra.glb, renders 512x512', / -F 'model=@tetra\.glb' /.test(mcmd) && pngSize(mpng) === '512x512',
        mcmd.slice(0, 200) + ' → ' + pngSize(mpng) + ' ' + mout.slice(0, 200));
    });
    check('no script errors', errors.length === 0, errors.join('; '));
    const domViolations = await page.evaluate(() => window.__csp || []);
    check('no Content-Security-Policy violations', violations.length === 0 && domViolations.length === 0,
      (violations.length + domViolations.length) + ': ' + violations.concat(domViolations).slice(0, 2).join('; ').slice(0, 400));

    await pick(page, 'Filter: hard');
    const modelLabel = await page.$eval('#model', (e) => e.textContent);
    check('an example picked after a drop: the model is let go', modelLabel === '', modelLabel);
    if (process.env.SHOT) {
      await page.waitForFunction(() => [...document.querySelectorAll('header button')].every((b) => !/copied/i.test(b.textContent)), { timeout: TIMEOUT });
      await pick(page, 'Filter: pcss');
      await rendered(page, () => page.click('#compare'));
      await page.screenshot({ path: process.env.SHOT });
    }
  } finally {
    await browser.close();
    fs.rmSync(tmp, { recursive: true, force: true });
  }
}

main().catch((e) => { fail++; console.log('FAIL - browser test: ' + (e && e.stack || e)); })
  .finally(() => { console.log(pass + ' passed, ' + fail + ' failed'); process.exitCode = fail ? 1 : 0; });
