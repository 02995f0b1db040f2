// umbra playground — completion and help from the scene schema at the editor's caret.
'use strict';

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
