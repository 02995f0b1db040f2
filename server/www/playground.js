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
  const fail = (msg) => { throw { message: (i >= text.length ? 'the document ends early: ' : '') + msg, line, col: i - col0 + 1 }; };
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
    if (!m) fail(c === undefined ? 'a value expected' : 'unexpected "' + c + '"');
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
// The message goes under its line, or above it where under would leave the editor (the last lines).
function place() {
  const y = 6 + (errLine - 1) * LINE - ed.scrollTop, err = $('error');
  $('hl').style.top = y + 'px';
  $('hl').style.display = errLine ? 'block' : 'none';
  let top = y + LINE + 2;
  if (!err.hidden && top + err.offsetHeight > ed.clientHeight - 2) top = Math.max(2, y - err.offsetHeight - 2);
  err.style.top = top + 'px';
  $('gutter').scrollTop = ed.scrollTop;
}
function showError(line, msg, col) {
  errLine = line;
  $('error').textContent = 'line ' + line + (col ? ', column ' + col : '') + ': ' + msg;
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
ed.addEventListener('input', (e) => {
  if (errLine) clearError(); else gutter(0);
  lightsChanged();
  if (e.inputType && (e.inputType.startsWith('insert') || sugg)) showSuggest(false);
});
ed.addEventListener('scroll', () => { closeSuggest(); place(); });
ed.addEventListener('keydown', (e) => {
  if (e.key === 'Enter' && (e.ctrlKey || e.metaKey)) { e.preventDefault(); closeSuggest(); render(); return; }
  if (e.key === ' ' && e.ctrlKey) { e.preventDefault(); showSuggest(true); return; }
  if (sugg) {
    const n = sugg.items.length;
    if (e.key === 'ArrowDown' || e.key === 'ArrowUp') { e.preventDefault(); sugg.on = (sugg.on + (e.key === 'ArrowDown' ? 1 : n - 1)) % n; markSuggest(); return; }
    if (e.key === 'Tab' || e.key === 'Enter') { e.preventDefault(); acceptSuggest(sugg.on); return; }
    if (e.key === 'Escape') { e.preventDefault(); closeSuggest(); return; }
  }
  if (e.key === 'Tab') { e.preventDefault(); document.execCommand('insertText', false, '  '); }
});
// JSON.stringify with two-space indents, but arrays of numbers on one line ([0, 1, 0]).
function pretty(v) {
  return JSON.stringify(v, null, 2).replace(/\[\s+(-?[\d.eE+-]+(?:,\s+-?[\d.eE+-]+)*)\s+\]/g,
    (m, g) => '[' + g.split(/,\s+/).join(', ') + ']');
}
function setText(t) { ed.value = t; ed.scrollTop = 0; closeSuggest(); clearError(); helpLine(null); }

// ---- the schema: completion and help ----
// The scene schema (api/scene.schema.json, spliced in by embed.sh) walked along the JSON path at
// the caret. scanAt() reads the editor's text as it is, broken or half typed: a stack of the open
// objects and arrays, each with the members seen so far (values only when they are strings,
// numbers or booleans: enough for the schema's if/then on "shape" and "type").
const SCHEMA = window.UMBRA_SCHEMA || {};
function scanAt(text, cur) {
  const stack = [];
  let snap = null, i = 0;
  const top = () => stack[stack.length - 1];
  // The path to the innermost container: its frames, each with its key or index then.
  const frames = () => stack.map((f) => ({ kind: f.kind, members: f.members, seg: f.kind === 'obj' ? f.key : f.index }));
  const inKey = () => { const f = top(); return !!f && f.kind === 'obj' && f.expectKey; };
  const at = (extra) => { snap = Object.assign({ frames: frames(), where: stack.length ? (inKey() ? 'key' : 'value') : 'root', from: cur, to: cur, prefix: '' }, extra); };
  while (i < text.length) {
    const c = text[i];
    if (c === ' ' || c === '\n' || c === '\t' || c === '\r') { i++; continue; }
    if (!snap && i >= cur) at({});
    const start = i, f = top();
    if (c === '"') {
      for (i++; i < text.length && text[i] !== '"' && text[i] !== '\n'; i++) if (text[i] === '\\') i++;
      const closed = text[i] === '"';
      if (closed) i++;
      let s;
      try { s = JSON.parse(closed ? text.slice(start, i) : text.slice(start, i) + '"'); } catch (e) { s = text.slice(start + 1, closed ? i - 1 : i); }
      if (!snap && cur > start && (cur < i || !closed)) at({ inString: true, from: start, to: i, prefix: text.slice(start + 1, cur), token: s });
      if (inKey()) { f.key = s; f.expectKey = false; f.members[s] = undefined; } else if (f && f.kind === 'obj') f.members[f.key] = s;
      continue;
    }
    i++;
    if (c === '{' || c === '[') stack.push({ kind: c === '{' ? 'obj' : 'arr', key: null, index: 0, members: {}, expectKey: c === '{' });
    else if (c === '}' || c === ']') stack.pop();
    else if (c === ',' && f) { if (f.kind === 'obj') { f.expectKey = true; f.key = null; } else f.index++; }
    else if (c !== ':') {
      while (i < text.length && !/[\s,:{}[\]"]/.test(text[i])) i++;
      const w = text.slice(start, i);
      if (!snap && cur > start && cur <= i) at({ from: start, to: i, prefix: text.slice(start, cur), token: w });
      if (f && f.kind === 'obj' && !f.expectKey) { try { f.members[f.key] = JSON.parse(w); } catch (e) { /* half typed */ } }
    }
  }
  if (!snap) at({});
  return snap;
}
function schemaRef(ref) {
  return ref.replace(/^#\/?/, '').split('/').filter(Boolean)
    .reduce((o, k) => o && o[k.replace(/~1/g, '/').replace(/~0/g, '~')], SCHEMA);
}
// Does an `if` hold for an object whose members are known as far as scanAt saw them?
function holds(cond, members) {
  if (!members) return false;
  if ((cond.required || []).some((k) => !(k in members))) return false;
  return Object.entries(cond.properties || {}).every(([k, p]) => {
    if (!(k in members) || members[k] === undefined) return !(cond.required || []).includes(k);
    if ('const' in p) return members[k] === p.const;
    if (p.enum) return p.enum.includes(members[k]);
    return true;
  }) && !cond.not;
}
// Every schema node that applies to a value: $ref, allOf/anyOf/oneOf and if/then expanded.
function applying(s, members, out = [], depth = 0) {
  if (!s || typeof s !== 'object' || depth > 24) return out;
  out.push(s);
  if (s.$ref) applying(schemaRef(s.$ref), members, out, depth + 1);
  ['allOf', 'anyOf', 'oneOf'].forEach((k) => (s[k] || []).forEach((b) => applying(b, members, out, depth + 1)));
  if (s.if && s.then && holds(s.if, members)) applying(s.then, members, out, depth + 1);
  return out;
}
function childOf(nodes, seg) {
  const hit = [];
  if (typeof seg === 'number') nodes.forEach((n) => { if (n.items && typeof n.items === 'object') hit.push(n.items); });
  else {
    nodes.forEach((n) => { if (n.properties && n.properties[seg]) hit.push(n.properties[seg]); });
    if (!hit.length) nodes.forEach((n) => Object.entries(n.patternProperties || {}).forEach(([re, p]) => { if (new RegExp(re).test(seg)) hit.push(p); }));
    if (!hit.length) nodes.forEach((n) => { if (n.additionalProperties && typeof n.additionalProperties === 'object') hit.push(n.additionalProperties); });
  }
  return hit;
}
// The schema nodes of the container scanAt found (frames[n-1]): walked from the root.
function containerNodes(fr) {
  let nodes = applying(SCHEMA, fr.length ? fr[0].members : {});
  for (let k = 0; k + 1 < fr.length; k++) {
    const next = [];
    childOf(nodes, fr[k].seg).forEach((c) => applying(c, fr[k + 1].members, next));
    nodes = next;
  }
  return nodes;
}
// One line about a member: its type, enum, range and default, then its description.
function describe(schemas) {
  const nodes = [];
  schemas.forEach((s) => applying(s, {}, nodes));
  const real = nodes.filter((n) => n.type !== 'null');
  const types = [...new Set(real.map((n) => n.type).filter(Boolean).flat())];
  const en = [...new Set(real.flatMap((n) => n.enum || []))];
  const d = real.find((n) => n.description), def = real.find((n) => 'default' in n);
  const lo = real.find((n) => 'minimum' in n || 'exclusiveMinimum' in n), hi = real.find((n) => 'maximum' in n || 'exclusiveMaximum' in n);
  let facts = en.length ? en.map((x) => JSON.stringify(x)).join(' | ') : types.join(' or ');
  if (lo || hi) facts += ' ' + (lo ? ('minimum' in lo ? lo.minimum + ' ≤ ' : lo.exclusiveMinimum + ' < ') : '') + 'x' +
    (hi ? ('maximum' in hi ? ' ≤ ' + hi.maximum : ' < ' + hi.exclusiveMaximum) : '');
  if (def) facts += ', default ' + JSON.stringify(def.default);
  return { facts: facts.trim(), text: d ? d.description : '' };
}
// The members (or, in a value, the enum values) the schema allows at the caret.
function completions(text, cur) {
  const s = scanAt(text, cur), fr = s.frames;
  if (!fr.length || s.where === 'root') return { s, items: [] };
  const nodes = containerNodes(fr), f = fr[fr.length - 1];
  const items = [];
  if (s.where === 'key') {
    const seen = new Set();
    nodes.forEach((n) => Object.keys(n.properties || {}).forEach((k) => {
      if (seen.has(k) || (k in f.members && k !== s.token)) return;
      seen.add(k);
      const d = describe(childOf(nodes, k));
      items.push({ label: k, insert: JSON.stringify(k) + ': ', key: true, help: d.text || d.facts });
    }));
  } else {
    const vals = new Set();
    const inner = [];
    childOf(nodes, f.seg).forEach((c) => applying(c, {}, inner));
    inner.forEach((n) => { (n.enum || []).forEach((v) => vals.add(JSON.stringify(v))); if ('const' in n) vals.add(JSON.stringify(n.const)); if (n.type === 'boolean') { vals.add('true'); vals.add('false'); } });
    vals.forEach((v) => items.push({ label: v, insert: v, key: false, help: '' }));
  }
  const p = s.prefix.toLowerCase().replace(/^"/, '');
  const match = (x) => x.label.replace(/^"/, '').toLowerCase();
  return { s, items: items.filter((x) => match(x).startsWith(p)).concat(items.filter((x) => !match(x).startsWith(p) && match(x).includes(p))) };
}
// The member at a text offset, explained: its JSON Pointer, facts and description.
function helpAt(text, cur) {
  const s = scanAt(text, cur), fr = s.frames;
  if (!fr.length) return null;
  const f = fr[fr.length - 1];
  const seg = s.where === 'key' ? (s.inString ? s.token : null) : f.seg;
  if (seg === null || seg === undefined) return null;
  const ptr = fr.slice(0, -1).map((x) => x.seg).concat([seg]).map((k) => '/' + String(k).replace(/~/g, '~0').replace(/\//g, '~1')).join('');
  const schemas = childOf(containerNodes(fr), seg);
  if (!schemas.length) return { ptr, facts: 'not in the schema', text: '' };
  return Object.assign({ ptr }, describe(schemas));
}

// The suggestion list under the caret: Tab or Enter takes one, Escape closes it.
let sugg = null;   // {items, on, from, to, key}
let charW = 0;
function charWidth() {
  if (!charW) {
    const g = document.createElement('canvas').getContext('2d');
    g.font = getComputedStyle(ed).font;
    charW = g.measureText('0'.repeat(40)).width / 40 || 7.8;
  }
  return charW;
}
function closeSuggest() { sugg = null; $('suggest').hidden = true; }
function showSuggest(force) {
  const cur = ed.selectionStart;
  if (cur !== ed.selectionEnd) return closeSuggest();
  const { s, items } = completions(ed.value, cur);
  const typing = s.where === 'key' ? (s.inString || s.prefix) : s.inString;
  if (!items.length || (!force && !typing) || (items.length === 1 && items[0].label.replace(/"/g, '') === s.prefix.replace(/"/g, '') && !force)) return closeSuggest();
  sugg = { items: items.slice(0, 60), on: 0, from: s.from, to: s.to };
  const ul = $('suggest');
  ul.replaceChildren(...sugg.items.map((x, k) => {
    const li = document.createElement('li'), b = document.createElement('b'), sp = document.createElement('span');
    li.setAttribute('role', 'option');
    li.dataset.k = k;
    b.textContent = x.label;
    sp.textContent = x.help;
    li.title = x.help;
    li.append(b, sp);
    return li;
  }));
  const before = ed.value.slice(0, cur), line = before.split('\n').length, col = cur - before.lastIndexOf('\n') - 1;
  ul.style.left = Math.max(0, Math.min(8 + col * charWidth() - ed.scrollLeft, ed.clientWidth - 260)) + 'px';
  const y = 6 + line * LINE - ed.scrollTop;
  ul.hidden = false;
  ul.style.top = (y + ul.offsetHeight > ed.clientHeight ? Math.max(0, y - LINE - ul.offsetHeight) : y) + 'px';
  markSuggest();
}
function markSuggest() {
  [...$('suggest').children].forEach((li, k) => { li.classList.toggle('on', k === sugg.on); li.setAttribute('aria-selected', k === sugg.on); });
  const on = $('suggest').children[sugg.on];
  if (on) on.scrollIntoView({ block: 'nearest' });
}
function acceptSuggest(k) {
  const x = sugg.items[k];
  let to = sugg.to;
  let ins = x.insert;
  // A key that already has its colon keeps it.
  if (x.key && /^\s*:/.test(ed.value.slice(to))) ins = JSON.stringify(x.label);
  ed.focus();
  ed.setSelectionRange(sugg.from, to);
  closeSuggest();
  if (!document.execCommand('insertText', false, ins)) {
    ed.setRangeText(ins, ed.selectionStart, ed.selectionEnd, 'end');
    ed.dispatchEvent(new Event('input'));
  }
  cursorHelp();
}
$('suggest').addEventListener('mousedown', (e) => {
  const li = e.target.closest('li');
  if (li && sugg) { e.preventDefault(); acceptSuggest(+li.dataset.k); }
});
function helpLine(h) {
  const el = $('help');
  el.replaceChildren();
  if (!h) { el.textContent = 'Ctrl+Space: the members allowed here (Tab or Enter takes one); the caret\'s member is explained here.'; return; }
  const c = document.createElement('code');
  c.textContent = h.ptr;
  el.append(c, ' — ' + h.facts + (h.text ? '. ' + h.text : ''));
}
function cursorHelp() { helpLine(helpAt(ed.value, ed.selectionStart)); }
ed.addEventListener('keyup', (e) => { if (!['Tab', 'Enter', 'Escape'].includes(e.key)) cursorHelp(); });
ed.addEventListener('click', () => { closeSuggest(); cursorHelp(); });
ed.addEventListener('blur', closeSuggest);
// Hover: the member under the mouse, as the editor's tooltip.
ed.addEventListener('mousemove', (e) => {
  const r = ed.getBoundingClientRect();
  const line = Math.floor((e.clientY - r.top - 6 + ed.scrollTop) / LINE), col = Math.floor((e.clientX - r.left - 8 + ed.scrollLeft) / charWidth());
  const lines = ed.value.split('\n');
  let h = null;
  if (line >= 0 && line < lines.length && col >= 0 && col < lines[line].length && lines[line][col] !== ' ') {
    const off = lines.slice(0, line).reduce((a, l) => a + l.length + 1, 0) + col + 1;
    h = helpAt(ed.value, off);
  }
  ed.title = h ? h.ptr + ' — ' + h.facts + (h.text ? '. ' + h.text : '') : '';
});

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
// The render; with `explain` it is asked with its plan (`Prefer: explain`): the answer is then
// multipart/mixed, the image's own bytes and the plan (api/explain.schema.json), measured.
async function send(doc, img, cap, explain) {
  const t0 = performance.now();
  const b = body(doc);
  const headers = Object.assign(explain ? { Prefer: 'explain' } : {}, b.headers);
  const r = await fetch('/v1/render', { method: 'POST', headers, body: b.body });
  const rtt = performance.now() - t0;
  let blob = await r.blob(), plan = null;
  if (!r.ok) {
    let p = {};
    try { p = JSON.parse(await blob.text()); } catch (e) { p = { detail: 'HTTP ' + r.status }; }
    return { ok: false, status: r.status, problem: p, rtt };
  }
  if (r.headers.get('Preference-Applied') === 'explain') {
    const ps = parts(new Uint8Array(await blob.arrayBuffer()), r.headers.get('Content-Type'));
    const im = ps.find((x) => x.type.startsWith('image/')), pj = ps.find((x) => x.type === 'application/json');
    if (im) blob = new Blob([im.bytes], { type: im.type });
    try { plan = pj ? JSON.parse(new TextDecoder().decode(pj.bytes)) : null; } catch (e) { plan = null; }
  }
  if (img.src) URL.revokeObjectURL(img.src);
  await new Promise((res) => { img.onload = res; img.onerror = res; img.src = URL.createObjectURL(blob); });
  cap.textContent = img.naturalWidth + '×' + img.naturalHeight;
  return { ok: true, status: r.status, size: blob.size, etag: r.headers.get('ETag'), timing: r.headers.get('Server-Timing'), rtt, plan };
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
    showError(e.line, 'JSON syntax: ' + e.message, e.col);
    $('status').textContent = 'not sent: the JSON does not parse';
    $('images').classList.add('stale');
    return;
  }
  clearError();
  const compare = $('compare').checked;
  $('render').disabled = true;
  $('status').textContent = 'rendering…';
  $('images').classList.toggle('two', compare);
  $('fig-b').hidden = !compare;
  try {
    const explain = $('explain').checked;
    const jobs = [send(withView(parsed.value, compare ? $('filter-a').value : null), $('image'), $('cap-a'), explain)];
    if (compare) jobs.push(send(withView(parsed.value, $('filter-b').value), $('image2'), $('cap-b'), false));
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
      $('download').hidden = true;
      showPlan(null);
      $('status').textContent = again ? 'rendering…' : 'error ' + bad.status;
      return;
    }
    if (compare) {
      $('cap-a').textContent += ' · ' + $('filter-a').value;
      $('cap-b').textContent += ' · ' + $('filter-b').value;
    }
    $('images').classList.remove('stale');
    $('size').textContent = res.map((x) => x.size.toLocaleString('en') + ' bytes').join(', ');
    // An answer with its plan is no cacheable image: it has no ETag.
    $('etag').textContent = res.map((x) => x.etag || (x.plan ? 'none (answered with its plan)' : '')).join(', ');
    showTiming(a.timing);
    showPlan(a.plan, compare ? 'of the first image' : '');
    const dl = $('download');
    dl.href = $('image').src;
    dl.download = imageName(compare, $('image').naturalWidth, $('image').naturalHeight);
    dl.title = 'Save ' + dl.download;
    dl.hidden = false;
    $('status').textContent = again ? 'rendering…' : 'done';
  } catch (e) {
    $('status').textContent = 'request failed: ' + e.message;
  } finally {
    $('render').disabled = false;
  }
}

// The download's file name: the scene, the view and the size ("filter-pcss-512x384.png").
function imageName(compare, w, h) {
  const view = $('debug').value;
  return source.file + (view ? '-' + view + (view === 'shadow' ? '-light' + ($('debug-light').value || 0) : '') : '') +
    (compare ? '-' + $('filter-a').value : '') + '-' + w + 'x' + h + '.png';
}

// ---- sharing: a link with the scene, the request as curl ----
const b64url = (bytes) => {
  let t = '';
  for (let k = 0; k < bytes.length; k += 0x8000) t += String.fromCharCode.apply(null, bytes.subarray(k, k + 0x8000));
  return btoa(t).replace(/\+/g, '-').replace(/\//g, '_').replace(/=+$/, '');
};
const unb64url = (t) => Uint8Array.from(atob(t.replace(/-/g, '+').replace(/_/g, '/')), (c) => c.charCodeAt(0));
async function through(bytes, stream) {
  return new Uint8Array(await new Response(new Blob([bytes]).stream().pipeThrough(stream)).arrayBuffer());
}
// #scene=<base64url of the editor's text>, raw-deflated (&enc=deflate-raw) where the browser can.
async function shareLink() {
  const raw = new TextEncoder().encode(ed.value);
  const frag = window.CompressionStream
    ? 'scene=' + b64url(await through(raw, new CompressionStream('deflate-raw'))) + '&enc=deflate-raw'
    : 'scene=' + b64url(raw);
  return location.origin + location.pathname + '#' + frag;
}
// The scene of the page's link, into the editor; false when the link has none.
async function fromLink() {
  const p = new URLSearchParams(location.hash.slice(1)), t = p.get('scene');
  if (!t) return false;
  try {
    let bytes = unb64url(t);
    if (p.get('enc') === 'deflate-raw') bytes = await through(bytes, new DecompressionStream('deflate-raw'));
    setText(new TextDecoder('utf-8', { fatal: true }).decode(bytes));
  } catch (e) {
    $('status').textContent = 'the link\'s scene cannot be read: ' + (e.message || e);
    return false;
  }
  setSource('Scene from the link', 'shared-scene');
  lightsChanged();
  return true;
}
// POSIX shell single quotes: nothing inside is expanded; a ' becomes '\''.
const shq = (t) => "'" + String(t).replace(/'/g, "'\\''") + "'";
// The curl command for the request the page makes (the first, when comparing): the exact JSON
// body, or with a dropped model the same multipart parts (the model by its file name, the scene
// from the here-document).
function curlCommand() {
  const doc = JSON.parse(ed.value);
  const json = JSON.stringify(withView(doc, $('compare').checked ? $('filter-a').value : null));
  const head = ['curl', '-sS', '--fail-with-body', '-H', shq('Accept: image/png')];
  const tail = ['-o', shq(imageName($('compare').checked, 'W', 'H').replace('-WxH', '')), shq(location.origin + '/v1/render')];
  if (model && json.includes('"part":"model"')) {
    // JSON.stringify writes no raw newline, so no line of the document can end the here-document.
    return head.concat(['-F', shq('scene=<-;type=application/json'), '-F', shq('model=@' + model.name)], tail).join(' ') +
      " <<'EOF'\n" + json + '\nEOF\n';
  }
  return head.concat(['-H', shq('Content-Type: application/json'), '--data-binary', shq(json)], tail).join(' ') + '\n';
}
// The clipboard, or where it is refused (an insecure origin) a selected textarea and copy.
async function copy(text) {
  try { await navigator.clipboard.writeText(text); return true; } catch (e) {
    const t = document.createElement('textarea');
    t.value = text;
    document.body.append(t);
    t.select();
    const ok = document.execCommand('copy');
    t.remove();
    return ok;
  }
}
function said(button, text) {
  const was = button.dataset.label || (button.dataset.label = button.textContent);
  button.textContent = text;
  setTimeout(() => { button.textContent = was; }, 2000);
}
$('share').addEventListener('click', async () => {
  const link = await shareLink();
  history.replaceState(null, '', link);
  const ok = await copy(link);
  said($('share'), ok ? (model ? 'Copied (not the model file)' : 'Link copied') : 'Copy refused: see the address bar');
});
$('curl').addEventListener('click', async () => {
  let cmd;
  try { cmd = curlCommand(); } catch (e) { said($('curl'), 'The JSON does not parse'); return; }
  said($('curl'), (await copy(cmd)) ? 'curl copied' : 'Copy refused');
});

// ---- controls ----
// The shadow view's light list: "0: directional", ... from the text (kept while it does not
// parse); by default the first light that casts shadows.
function lightsChanged() {
  let doc;
  try { doc = JSON.parse(ed.value); } catch (e) { return; }
  const lights = doc && Array.isArray(doc.lights) ? doc.lights : [];
  const sel = $('debug-light'), old = sel.value;
  const names = lights.map((l, k) => k + ': ' + (l && l.name ? l.name + ' (' + l.type + ')' : (l && l.type) || '?'));
  if (!names.length) names.push(doc && doc.preset ? '0: the preset\'s light' : '0: (no lights)');
  if (names.join('\n') === [...sel.options].map((o) => o.text).join('\n') && sel.selectedIndex >= 0) return;
  sel.replaceChildren(...names.map((t, k) => new Option(t, String(k))));
  const first = Math.max(0, lights.findIndex((l) => l && l.shadow !== false));
  sel.value = old !== '' && +old < names.length ? old : String(first);
}
$('debug').addEventListener('change', () => { lightsChanged(); $('light-label').hidden = $('debug').value !== 'shadow'; render(); });
$('debug-light').addEventListener('change', render);
$('explain').addEventListener('change', render);
$('compare').addEventListener('change', () => {
  $('filter-a').disabled = $('filter-b').disabled = !$('compare').checked;
  render();
});
FILTERS.forEach((f) => { $('filter-a').add(new Option(f, f)); $('filter-b').add(new Option(f, f)); });
$('filter-a').value = 'pcf'; $('filter-b').value = 'pcss';
$('filter-a').addEventListener('change', render);
$('filter-b').addEventListener('change', render);
// What the editor holds: an example, or a scene that is none of them (a dropped model's, a link's)
// named by an extra entry in the list. `source.file` names downloads.
let source = { file: 'filter-hard' };
function setSource(label, file) {
  const sel = $('examples');
  let o = sel.querySelector('option[value="other"]');
  if (!o) { o = new Option('', 'other'); sel.add(o); }
  o.text = label;
  sel.value = 'other';
  source = { file };
}
const slug = (t) => t.toLowerCase().replace(/[^a-z0-9]+/g, '-').replace(/^-|-$/g, '') || 'scene';
EXAMPLES.forEach((e, k) => $('examples').add(new Option(e[0], String(k))));
$('examples').addEventListener('change', () => {
  const k = $('examples').value;
  if (k === 'other') return;
  const o = $('examples').querySelector('option[value="other"]');
  if (o) o.remove();
  // An example is not the dropped model's scene: the model goes with it.
  model = null;
  $('model').textContent = '';
  source = { file: slug(EXAMPLES[+k][0].replace(/^Filter: /, 'filter ')) };
  setText(pretty(EXAMPLES[+k][1]()));
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
  setSource('Dropped model: ' + file.name, slug(file.name.replace(/\.[^.]*$/, '')));
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
// On open: the link's scene, else the first example; rendered at once.
$('examples').value = '0';
setText(pretty(EXAMPLES[0][1]()));
lightsChanged();
fromLink().finally(render);
window.addEventListener('hashchange', () => fromLink().then((ok) => ok && render()));
window.umbraPlayground = { parseJsonLines, lineOf, render, useModel, scanAt, completions, helpAt, curlCommand, shareLink };
