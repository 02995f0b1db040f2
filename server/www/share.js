// umbra playground — sharing: a link with the scene, the request as a curl command, the clipboard.
'use strict';

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
