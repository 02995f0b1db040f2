// umbra playground — the controls, dropped models and the page's start. The last of the page's
// scripts (editor.js, examples.js, schema_help.js, plan.js, request.js, share.js come first: see
// playground.html). No libraries; talks only to this daemon.
'use strict';

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
