// umbra playground — the editor: the page's constants, JSON read with the line of each member
// (for errors by JSON Pointer), the gutter and the error under its line. The first of the page's
// scripts (server/www/embed.sh inlines them in playground.html's order; they share its globals).
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
