// umbra playground — the page's behaviour. No libraries; talks only to this daemon.
'use strict';

const LINE = 18;                 // px per editor line (playground.css: 13px/18px)
const FILTERS = ['hard', 'pcf', 'pcss', 'vsm', 'evsm'];
const STAGES = ['queue', 'parse', 'upload', 'shadow', 'main', 'readback', 'encode'];
const COLOURS = ['#b0bec5', '#8e7cc3', '#6fa8dc', '#e69138', '#3d85c6', '#93c47d', '#c27ba0'];
const $ = (id) => document.getElementById(id);

// ---- JSON with positions ----
// Parses JSON text as JSON.parse does, and records the line (1-based) where each member's value
// starts (for object members: the line of its key), keyed by RFC 6901 JSON Pointer. A syntax
// error throws {message, line, col}.
function parseJsonLines(text) {
  let i = 0, line = 1, col0 = 0;
  const lines = new Map();
  const fail = (msg) => { throw { message: msg, line, col: i - col0 + 1 }; };
  const ws = () => {
    for (;;) {
      const c = text[i];
      if (c === '\n') { line++; i++; col0 = i; }
      else if (c === ' ' || c === '\t' || c === '\r') i++;
      else return;
    }
  };
  const esc = (k) => String(k).replace(/~/g, '~0').replace(/\//g, '~1');
  function str() {
    const start = i++;
    for (;;) {
      const c = text[i];
      if (c === undefined || c === '\n') fail('unterminated string');
      if (c === '\\') { i += 2; continue; }
      if (c < ' ') fail('control character in a string');
      i++;
      if (c === '"') break;
    }
    try { return JSON.parse(text.slice(start, i)); } catch (e) { i = start; return fail('bad escape in a string'); }
  }
  function value(ptr) {
    ws();
    lines.has(ptr) || lines.set(ptr, line);
    const c = text[i];
    if (c === '{') {
      i++; const o = {}; ws();
      if (text[i] === '}') { i++; return o; }
      for (;;) {
        ws();
        if (text[i] !== '"') fail('expected a member name in double quotes');
        const keyLine = line, k = str();
        if (Object.prototype.hasOwnProperty.call(o, k)) fail('duplicate member "' + k + '"');
        lines.set(ptr + '/' + esc(k), keyLine);
        ws(); if (text[i] !== ':') fail('expected ":" after "' + k + '"'); i++;
        o[k] = value(ptr + '/' + esc(k));
        ws();
        if (text[i] === ',') { i++; continue; }
        if (text[i] === '}') { i++; return o; }
        fail('expected "," or "}"');
      }
    }
    if (c === '[') {
      i++; const a = []; ws();
      if (text[i] === ']') { i++; return a; }
      for (;;) {
        a.push(value(ptr + '/' + a.length));
        ws();
        if (text[i] === ',') { i++; continue; }
        if (text[i] === ']') { i++; return a; }
        fail('expected "," or "]"');
      }
    }
    if (c === '"') return str();
    const m = /^(-?(0|[1-9]\d*)(\.\d+)?([eE][+-]?\d+)?|true|false|null)/.exec(text.slice(i, i + 400));
    if (!m) fail(c === undefined ? 'unexpected end of the document' : 'unexpected "' + c + '"');
    i += m[0].length;
    return JSON.parse(m[0]);
  }
  const v = value('');
  ws();
  if (i < text.length) fail('text after the document');
  return { value: v, lines };
}

// The line a pointer names: its own, else its nearest ancestor's (a missing member's parent).
function lineOf(lines, ptr) {
  for (let p = ptr; ; p = p.slice(0, p.lastIndexOf('/'))) {
    if (lines.has(p)) return lines.get(p);
    if (!p) return 1;
  }
}

// ---- examples ----
const sun = (extra) => Object.assign({ type: 'directional', direction: [-0.5, -1, -0.3], intensity: 3 }, extra || {});
function filterScene(filter) {
  return {
    width: 512, height: 384,
    camera: { position: [4, 3, 5], target: [0, 0.7, 0], fov_y: 40 },
    environment: { background: [0.55, 0.6, 0.68], ambient: { intensity: 0.3 } },
    materials: { floor: { base_color: [0.75, 0.75, 0.72], roughness: 0.9 }, red: { base_color: [0.8, 0.25, 0.2], roughness: 0.5 } },
    objects: [
      { shape: 'plane', size: [12, 12], material: 'floor' },
      { shape: 'box', size: [1, 1.6, 1], material: 'red', transform: { translation: [-0.8, 0.8, 0], rotation: [0, 0.38, 0, 0.925] } },
      { shape: 'sphere', radius: 0.6, material: 'floor', transform: { translation: [1, 1.6, 0.6] } },
      { shape: 'cylinder', radius: 0.08, height: 1.0, transform: { translation: [1, 0.5, 0.6] } },
    ],
    lights: [sun({ angular_diameter: 3 })],
    shadows: { filter, resolution: 2048 },
  };
}
function cascadesScene() {
  const objects = [{ shape: 'plane', size: [300, 300], material: 'ground' }];
  for (let k = 0; k < 24; k++) {
    const z = -3 - k * 5, h = 2 + (k * 7) % 5;
    objects.push({ shape: 'box', size: [1.6, h, 1.6], material: 'wall', transform: { translation: [k % 2 ? 3 : -3, h / 2, z] } });
  }
  return {
    width: 640, height: 360,
    camera: { position: [0, 1.7, 6], target: [0, 1.2, -20], fov_y: 60, near: 0.1, far: 200 },
    environment: { background: [0.55, 0.7, 0.9], ambient: { sky: [0.55, 0.7, 0.9], ground: [0.3, 0.28, 0.25], intensity: 0.4 } },
    materials: { ground: { base_color: [0.45, 0.42, 0.38], roughness: 0.95 }, wall: { base_color: [0.8, 0.76, 0.7] } },
    objects,
    lights: [sun({ direction: [-0.6, -1, -0.4], shadow: { filter: 'pcf', directional: { mode: 'cascades', cascades: 4 } } })],
  };
}
function lightsScene() {
  return {
    width: 512, height: 384,
    camera: { position: [6, 5, 7], target: [0, 0.5, 0], fov_y: 45 },
    environment: { background: [0.05, 0.05, 0.06], ambient: { intensity: 0.15 } },
    materials: { floor: { base_color: [0.6, 0.6, 0.6], roughness: 0.9 }, gold: { base_color: [1, 0.78, 0.34], roughness: 0.3, metallic: 1 } },
    objects: [
      { shape: 'plane', size: [12, 12], material: 'floor' },
      { shape: 'box', size: [0.8, 1.4, 0.8], transform: { translation: [-1.2, 0.7, -0.5] } },
      { shape: 'cylinder', radius: 0.4, height: 1.2, material: 'gold', transform: { translation: [1, 0.6, 0.4] } },
    ],
    lights: [
      { type: 'spot', position: [0, 4.5, 2], direction: [0, -1, -0.45], color: [1, 0.85, 0.7], intensity: 60, outer_angle: 40, inner_angle: 25, radius: 0.1 },
      { type: 'point', position: [-2.5, 2.5, 2], color: [0.4, 0.6, 1], intensity: 25, radius: 0.05 },
    ],
    shadows: { filter: 'pcss' },
  };
}
// A small OBJ (a stepped tower) as an inline model: the thumbnail preset frames it and puts a
// shadow catcher under it; the background is transparent, so the shadow is in alpha.
function towerObj() {
  const v = [], f = [];
  const box = (x0, y0, z0, x1, y1, z1) => {
    const b = v.length / 3 + 1;
    for (let k = 0; k < 8; k++) v.push(k & 1 ? x1 : x0, k & 2 ? y1 : y0, k & 4 ? z1 : z0);
    [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
      .forEach((q) => f.push('f ' + q.map((n) => n + b).join(' ')));
  };
  box(-1, 0, -1, 1, 0.6, 1); box(-0.7, 0.6, -0.7, 0.7, 1.4, 0.7); box(-0.35, 1.4, -0.35, 0.35, 2.6, 0.35);
  let s = '';
  for (let k = 0; k < v.length; k += 3) s += 'v ' + v.slice(k, k + 3).join(' ') + '\n';
  return s + f.join('\n') + '\n';
}
function catcherScene() {
  return {
    preset: 'thumbnail', width: 384, height: 384,
    output: { transparent: true },
    objects: [{ shape: 'model', format: 'obj', data: btoa(towerObj()), material: { base_color: [0.3, 0.55, 0.85] } }],
  };
}
function errorScene() {
  const s = filterScene('pcf');
  s.lights[0].direction = [0, 0, 0];
  return s;
}
const EXAMPLES = [];
FILTERS.forEach((f) => EXAMPLES.push(['Filter: ' + f, () => filterScene(f)]));
EXAMPLES.push(['Cascades: a street at dusk', cascadesScene]);
EXAMPLES.push(['Spot and point lights', lightsScene]);
EXAMPLES.push(['Model on a shadow catcher, transparent', catcherScene]);
EXAMPLES.push(['Thumbnail preset (sphere)', () => ({ preset: 'thumbnail', objects: [{ shape: 'sphere', segments: 96 }] })]);
Object.keys(window.UMBRA_BENCH || {}).sort().forEach((k) => EXAMPLES.push(['Bench: ' + k, () => window.UMBRA_BENCH[k]]));
EXAMPLES.push(['An error (zero light direction)', errorScene]);

// ---- editor ----
const ed = $('editor');
function gutter(bad) {
  const n = ed.value.split('\n').length;
  let h = '';
  for (let k = 1; k <= n; k++) h += k === bad ? '<span class="bad">' + k + '</span>\n' : k + '\n';
  $('gutter').innerHTML = h;
  $('gutter').scrollTop = ed.scrollTop;
}
let errLine = 0;
function place() {
  const y = 6 + (errLine - 1) * LINE - ed.scrollTop;
  $('hl').style.top = y + 'px';
  $('hl').style.display = errLine ? 'block' : 'none';
  $('error').style.top = (y + LINE + 2) + 'px';
  $('gutter').scrollTop = ed.scrollTop;
}
function showError(line, msg) {
  errLine = line;
  $('error').textContent = 'line ' + line + ': ' + msg;
  $('error').hidden = false;
  $('error').dataset.line = line;
  gutter(line);
  // Scroll the line into view, then place the highlight and the message under it.
  const top = (line - 1) * LINE;
  if (top < ed.scrollTop || top > ed.scrollTop + ed.clientHeight - 3 * LINE) ed.scrollTop = Math.max(0, top - 3 * LINE);
  place();
}
function clearError() {
  errLine = 0;
  $('error').hidden = true;
  delete $('error').dataset.line;
  gutter(0);
  place();
}
ed.addEventListener('input', () => { if (errLine) clearError(); else gutter(0); });
ed.addEventListener('scroll', place);
ed.addEventListener('keydown', (e) => {
  if (e.key === 'Enter' && (e.ctrlKey || e.metaKey)) { e.preventDefault(); render(); }
  if (e.key === 'Tab') { e.preventDefault(); document.execCommand('insertText', false, '  '); }
});
// JSON.stringify with two-space indents, but arrays of numbers on one line ([0, 1, 0]).
function pretty(v) {
  return JSON.stringify(v, null, 2).replace(/\[\s+(-?[\d.eE+-]+(?:,\s+-?[\d.eE+-]+)*)\s+\]/g,
    (m, g) => '[' + g.split(/,\s+/).join(', ') + ']');
}
function setText(t) { ed.value = t; ed.scrollTop = 0; clearError(); }

// ---- the request ----
let model = null;   // {name, file, format}: a dropped model, sent as the multipart part "model"
function withView(doc, filter) {
  const d = JSON.parse(JSON.stringify(doc));
  const view = $('debug').value;
  if (view) {
    d.output = Object.assign({}, d.output, { debug: view });
    if (view === 'shadow') d.output.debug_light = +$('debug-light').value || 0;
  }
  if (filter) {
    // The compare filter wins over the root's and every light's own.
    d.shadows = Object.assign({}, typeof d.shadows === 'object' ? d.shadows : {}, { filter });
    (d.lights || []).forEach((l) => { if (l && l.shadow) l.shadow.filter = filter; });
  }
  return d;
}
function body(doc) {
  const json = JSON.stringify(doc);
  if (!model || !json.includes('"part":"model"')) return { body: json, headers: { 'Content-Type': 'application/json' } };
  const fd = new FormData();
  fd.append('scene', new Blob([json], { type: 'application/json' }), 'scene.json');
  fd.append('model', model.file, model.name);
  return { body: fd, headers: {} };
}
async function send(doc, img, cap) {
  const t0 = performance.now();
  const r = await fetch('/v1/render', Object.assign({ method: 'POST', headers: { Accept: 'image/png' } }, body(doc)));
  const rtt = performance.now() - t0;
  const blob = await r.blob();
  if (!r.ok) {
    let p = {};
    try { p = JSON.parse(await blob.text()); } catch (e) { p = { detail: 'HTTP ' + r.status }; }
    return { ok: false, status: r.status, problem: p, rtt };
  }
  if (img.src) URL.revokeObjectURL(img.src);
  await new Promise((res) => { img.onload = res; img.onerror = res; img.src = URL.createObjectURL(blob); });
  cap.textContent = img.naturalWidth + '×' + img.naturalHeight;
  return { ok: true, status: r.status, size: blob.size, etag: r.headers.get('ETag'), timing: r.headers.get('Server-Timing'), rtt };
}
function showTiming(header) {
  const dur = {};
  (header || '').split(',').forEach((m) => {
    const name = m.split(';')[0].trim(), d = /dur=([\d.]+)/.exec(m);
    if (name && d) dur[name] = +d[1];
  });
  const total = STAGES.reduce((a, s) => a + (dur[s] || 0), 0) || 1;
  // Elements with styles set through the DOM: the page's Content-Security-Policy refuses
  // style="" attributes in markup.
  const bar = $('timing'), legend = $('timing-legend');
  bar.replaceChildren();
  legend.replaceChildren();
  STAGES.forEach((s, k) => {
    const ms = (dur[s] || 0).toFixed(1) + ' ms';
    const d = document.createElement('div');
    d.dataset.stage = s;
    d.title = s + ' ' + ms;
    d.style.width = (100 * (dur[s] || 0) / total) + '%';
    d.style.background = COLOURS[k];
    bar.append(d);
    const span = document.createElement('span'), i = document.createElement('i');
    i.style.background = COLOURS[k];
    span.append(i, s + ' ' + ms);
    legend.append(span);
  });
  if (dur.total) {
    const span = document.createElement('span');
    span.textContent = 'total ' + dur.total.toFixed(1) + ' ms';
    legend.append(span);
  }
}
// One render at a time: a render asked for while one runs follows it (with the text and controls
// as they are then), so the page always ends showing what its controls say.
let busy = false, again = false;
async function render() {
  if (busy) { again = true; return; }
  busy = true;
  try { await renderNow(); } finally {
    busy = false;
    if (again) { again = false; render(); }
  }
}
async function renderNow() {
  let parsed;
  try { parsed = parseJsonLines(ed.value); } catch (e) {
    if (e.line === undefined) throw e;
    showError(e.line, 'JSON syntax: ' + e.message + ' (column ' + e.col + ')');
    $('status').textContent = 'not sent: the JSON does not parse';
    return;
  }
  clearError();
  const compare = $('compare').checked;
  $('render').disabled = true;
  $('status').textContent = 'rendering…';
  $('images').classList.toggle('two', compare);
  $('fig-b').hidden = !compare;
  try {
    const jobs = [send(withView(parsed.value, compare ? $('filter-a').value : null), $('image'), $('cap-a'))];
    if (compare) jobs.push(send(withView(parsed.value, $('filter-b').value), $('image2'), $('cap-b')));
    const res = await Promise.all(jobs);
    const bad = res.find((x) => !x.ok);
    const a = res[0];
    $('http').textContent = res.map((x) => x.status).join(', ');
    $('rtt').textContent = res.map((x) => x.rtt.toFixed(0) + ' ms').join(', ');
    if (bad) {
      const p = bad.problem, ptr = p.pointer || '';
      showError(lineOf(parsed.lines, ptr), (p.status || bad.status) + ' ' + (p.title || '') + ': ' + (ptr ? ptr + ': ' : '') + (p.detail || ''));
      // The image shown is no longer this text's: dim it and clear its facts.
      $('images').classList.add('stale');
      $('size').textContent = $('etag').textContent = '—';
      $('timing').innerHTML = $('timing-legend').innerHTML = '';
      $('status').textContent = again ? 'rendering…' : 'error ' + bad.status;
      return;
    }
    if (compare) {
      $('cap-a').textContent += ' · ' + $('filter-a').value;
      $('cap-b').textContent += ' · ' + $('filter-b').value;
    }
    $('images').classList.remove('stale');
    $('size').textContent = res.map((x) => x.size.toLocaleString('en') + ' bytes').join(', ');
    $('etag').textContent = res.map((x) => x.etag || '').join(', ');
    showTiming(a.timing);
    $('status').textContent = again ? 'rendering…' : 'done';
  } catch (e) {
    $('status').textContent = 'request failed: ' + e.message;
  } finally {
    $('render').disabled = false;
  }
}

// ---- controls ----
function lightsChanged() {
  let n = 0;
  try { n = (JSON.parse(ed.value).lights || []).length; } catch (e) { n = 0; }
  const sel = $('debug-light'), old = sel.value;
  sel.innerHTML = '';
  for (let k = 0; k < Math.max(n, 1); k++) sel.add(new Option(String(k), String(k)));
  if (+old < n) sel.value = old;
}
$('debug').addEventListener('change', () => { lightsChanged(); $('light-label').hidden = $('debug').value !== 'shadow'; render(); });
$('debug-light').addEventListener('change', render);
$('compare').addEventListener('change', () => {
  $('filter-a').disabled = $('filter-b').disabled = !$('compare').checked;
  render();
});
FILTERS.forEach((f) => { $('filter-a').add(new Option(f, f)); $('filter-b').add(new Option(f, f)); });
$('filter-a').value = 'pcf'; $('filter-b').value = 'pcss';
$('filter-a').addEventListener('change', render);
$('filter-b').addEventListener('change', render);
EXAMPLES.forEach((e, k) => $('examples').add(new Option(e[0], String(k))));
$('examples').addEventListener('change', () => {
  setText(pretty(EXAMPLES[+$('examples').value][1]()));
  lightsChanged();
});
$('render').addEventListener('click', render);

// ---- dropped models ----
const MODEL_EXT = ['glb', 'gltf', 'obj', 'stl', 'ply'];
function useModel(file) {
  const ext = (file.name.split('.').pop() || '').toLowerCase();
  if (!MODEL_EXT.includes(ext)) { $('status').textContent = file.name + ': not a model (' + MODEL_EXT.join(', ') + ')'; return; }
  model = { name: file.name, file, format: ext };
  $('model').textContent = 'model: ' + file.name + ' (' + file.size.toLocaleString('en') + ' bytes)';
  setText(pretty({ preset: 'thumbnail', objects: [{ shape: 'model', part: 'model', format: ext }] }));
  lightsChanged();
  render();
}
let depth = 0;
window.addEventListener('dragenter', (e) => { e.preventDefault(); depth++; $('drop').hidden = false; });
window.addEventListener('dragleave', () => { if (--depth <= 0) { depth = 0; $('drop').hidden = true; } });
window.addEventListener('dragover', (e) => e.preventDefault());
window.addEventListener('drop', (e) => {
  e.preventDefault();
  depth = 0; $('drop').hidden = true;
  const f = e.dataTransfer && e.dataTransfer.files[0];
  if (f) useModel(f);
});

fetch('/v1/info').then((r) => r.ok ? r.json() : null).then((i) => {
  if (i) $('device').textContent = (i.device || '') + (i.version ? ' · ' + i.version : '');
}).catch(() => {});
$('examples').value = '0';
setText(pretty(EXAMPLES[0][1]()));
lightsChanged();
window.umbraPlayground = { parseJsonLines, lineOf, render, useModel };
