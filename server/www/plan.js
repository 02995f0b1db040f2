// umbra playground — the render's plan (explain) shown beside the image: the multipart/mixed
// answer of `Prefer: explain` split into the image and the plan (api/explain.schema.json), and
// the plan as two short tables. Inlined before request.js (server/www/embed.sh), which calls
// parts() and showPlan(); uses editor.js's $().
'use strict';

// The parts of a multipart/mixed body (RFC 2046): [{type, bytes}], in order.
function parts(bytes, type) {
  const m = /boundary=("?)([^";]+)\1/.exec(type || '');
  if (!m) return [];
  const enc = new TextEncoder(), delim = enc.encode('--' + m[2]), next = enc.encode('\r\n--' + m[2]), blank = enc.encode('\r\n\r\n');
  const find = (needle, from) => {
    for (let i = bytes.indexOf(needle[0], from); i >= 0 && i <= bytes.length - needle.length; i = bytes.indexOf(needle[0], i + 1)) {
      let j = 1;
      while (j < needle.length && bytes[i + j] === needle[j]) j++;
      if (j === needle.length) return i;
    }
    return -1;
  };
  const out = [];
  for (let at = find(delim, 0); at >= 0;) {
    const head = at + delim.length;
    if (bytes[head] === 45 && bytes[head + 1] === 45) break;   // "--": the last boundary
    const start = find(blank, head), end = start < 0 ? -1 : find(next, start + 4);
    if (end < 0) break;
    const ct = /content-type:\s*([^\r\n]+)/i.exec(new TextDecoder().decode(bytes.subarray(head, start)));
    out.push({ type: ct ? ct[1].trim() : '', bytes: bytes.subarray(start + 4, end) });
    at = end + 2;
  }
  return out;
}
// The plan as two short tables: what was decided (and why), then each step's estimate beside
// what it measured. The JSON has every reason whole (POST /v1/explain, umbra-render --explain).
const count = (n) => (n || 0).toLocaleString('en');
const ms = (x) => (typeof x === 'number' ? x.toFixed(1) : '—');
function showPlan(p, note) {
  const box = $('plan');
  box.hidden = !p;
  const facts = $('plan-facts'), steps = $('plan-steps').tBodies[0];
  facts.replaceChildren();
  steps.replaceChildren();
  if (!p) return;
  $('plan-note').textContent = note || '';
  const cells = (tr, list) => list.forEach(([text, cls], k) => {
    const c = document.createElement(k ? 'td' : 'th');
    c.textContent = text;
    if (cls) c.className = cls;
    tr.append(c);
  });
  // A fact: its name, its value, and under the value the reason (the column stays narrow).
  const fact = (name, value, why) => {
    const tr = facts.insertRow();
    tr.dataset.fact = name;
    cells(tr, [[name], ['']]);
    const v = document.createElement('div'), w = document.createElement('div');
    v.className = 'v';
    w.className = 'why';
    v.textContent = value;
    w.textContent = why || '';
    tr.cells[1].append(v, w);
  };
  const t = p.totals, a = p.actual || {}, im = p.image;
  fact('views', im.views + ' × ' + im.width + '×' + im.height + ' ' + im.format, im.views > 1 ? im.columns + '×' + im.rows + ' sheet' : '');
  fact('shadow maps', t.shadow_maps_drawn + ' drawn, ' + t.shadow_maps_cached + ' cached',
    (t.shadow_texels / 1e6).toFixed(2) + ' Mtexel' + (p.analyzed ? '; measured ' + a.shadow_maps_drawn + ' drawn, ' + a.shadow_maps_reused + ' reused' : ''));
  const MAPS = 6;
  p.shadow_maps.slice(0, MAPS).forEach((m, k) => fact('map ' + k, 'light ' + m.light + ' ' + m.type + (m.kind !== m.type ? ' ' + m.kind : '') +
    ' ' + m.resolution + '² ' + m.filter + ': ' + (m.actual ? (m.actual.cached ? 'cached' : 'drawn') : m.state), m.why + (m.size ? '; size: ' + m.size : '')));
  if (p.shadow_maps.length > MAPS) fact('…', (p.shadow_maps.length - MAPS) + ' more maps', 'POST /v1/explain lists them all');
  fact('triangles', count(t.camera_triangles) + ' camera, ' + count(t.shadow_triangles) + ' shadow', t.sphere_proxies ? t.sphere_proxies + ' sphere proxies' : '');
  const v0 = p.views[0], n = p.views.length;
  const onOff = (key) => {
    const on = p.views.filter((v) => v[key].on).length;
    return n === 1 ? (on ? 'on' : 'off') : 'on in ' + on + ' of ' + n + ' views';
  };
  fact('pixel shading', onOff('pixel_shading'), v0.pixel_shading.why);
  fact('visibility pass', onOff('visibility_pass'), v0.visibility_pass.why);
  const left = p.objects.filter((o) => !o.casts);
  if (left.length) fact('not casting', left.map((o) => 'object ' + o.object).join(', '), left[0].why);
  fact('memory', (p.memory.device_bytes / 1e6).toFixed(1) + ' MB', 'device estimate, admitted by --max-memory');
  // The plan's passes summed by the stage Server-Timing names; measured per stage.
  const est = { upload: 0, shadow: 0, main: 0, readback: 0 };
  p.passes.forEach((s) => { est[s.pass === 'shadow_map' ? 'shadow' : s.pass in est ? s.pass : 'main'] += s.estimate_ms; });
  [['plan', null, p.planning_ms], ['upload', est.upload, a.upload_ms], ['shadow', est.shadow, a.shadow_ms], ['main', est.main, a.main_ms],
    ['readback', est.readback, a.readback_ms], ['encode', null, a.encode_ms], ['total', t.estimate_ms, a.total_ms]].forEach(([name, e, m]) => {
    const tr = steps.insertRow();
    tr.dataset.step = name;
    cells(tr, [[name], [ms(e)], [ms(m)]]);
  });
}
