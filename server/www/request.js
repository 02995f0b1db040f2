// umbra playground — the render request: the scene with the page's view, sent (with its plan:
// plan.js), the image, the timing bar and the download's name.
'use strict';

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
