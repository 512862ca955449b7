// The camera's page: log in, the photo folder as a gallery, one photo large; a tap or a dragged
// rectangle picks the focus, shows a quick preview at once and the full-size re-render when it
// is done; save writes a new photo beside the original. Plain JavaScript, same-origin requests
// only. For the browser test the page records in document.body.dataset: state (login, gallery,
// photo, preview, rendered, saved), previewMs (pointerup to the preview shown) and savedName.
'use strict';

const $ = (id) => document.getElementById(id);
const view = { name: null, info: null, gen: 0, params: null, blobUrl: null };
window.lbLatencies = [];

function setState(state) { document.body.dataset.state = state; }
function status(text) { $('status').textContent = text || ''; }

function show(section) {
  for (const id of ['login', 'gallery', 'viewer']) $(id).hidden = id !== section;
  $('back').hidden = section !== 'viewer';
}

// fetch with the server's conventions: 401 -> the login form, 503 -> try again a moment later
// (the camera is taking a photo or the renderer is busy), unless a newer request made this one
// pointless.
async function call(url, options, stillWanted) {
  for (let attempt = 0; ; ++attempt) {
    const response = await fetch(url, Object.assign({ credentials: 'same-origin' }, options));
    if (response.status === 401) {
      showLogin();
      throw new Error('login needed');
    }
    if (response.status === 503 && attempt < 20 && (!stillWanted || stillWanted())) {
      status('camera busy, waiting…');
      await new Promise((resolve) => setTimeout(resolve, 300 + 200 * attempt));
      if (stillWanted && !stillWanted()) throw new Error('superseded');
      continue;
    }
    if (!response.ok) {
      // The server answers {"error": "..."}: show its words, not the JSON.
      let text = response.statusText;
      try {
        const body = (await response.text()).trim();
        try { text = JSON.parse(body).error || body; } catch (e) { text = body || text; }
      } catch (e) { /* keep statusText */ }
      throw new Error(response.status === 422 ? 'this photo cannot be refocused: ' + text : text);
    }
    return response;
  }
}

function form(fields) {
  return {
    method: 'POST',
    headers: { 'Content-Type': 'application/x-www-form-urlencoded' },
    body: new URLSearchParams(fields).toString(),
  };
}

function showLogin() {
  show('login');
  setState('login');
  $('token').focus();
}

$('login-form').addEventListener('submit', async (event) => {
  event.preventDefault();
  $('login-error').hidden = true;
  const response = await fetch('/api/login', form({ token: $('token').value }));
  if (!response.ok) {
    $('login-error').hidden = false;
    return;
  }
  $('token').value = '';
  openGallery();
});

async function openGallery() {
  show('gallery');
  status('');
  if (await listPhotos()) setState('gallery');
}

// The gallery's thumbnails, newest first; false when the list could not be had.
async function listPhotos() {
  let list;
  try {
    list = await (await call('/api/photos')).json();
  } catch (e) {
    if (e.message !== 'login needed') status(e.message);
    return false;
  }
  const photos = (list.photos || []).slice().sort((a, b) => b.mtime - a.mtime);
  const ul = $('thumbs');
  ul.replaceChildren();
  for (const p of photos) {
    const li = document.createElement('li');
    li.dataset.name = p.name;
    const img = document.createElement('img');
    img.loading = 'lazy';
    img.alt = p.name;
    img.src = '/thumbs/' + encodeURIComponent(p.name);
    const caption = document.createElement('span');
    caption.textContent = p.name;
    li.append(img, caption);
    li.addEventListener('click', () => openPhoto(p.name));
    ul.append(li);
  }
  $('empty').hidden = photos.length > 0;
  return true;
}

function setImage(src) {
  return new Promise((resolve, reject) => {
    const img = $('photo');
    img.onload = () => resolve();
    img.onerror = () => reject(new Error('the image did not load'));
    img.src = src;
  });
}

function useBlob(blob) {
  const url = URL.createObjectURL(blob);
  if (view.blobUrl) URL.revokeObjectURL(view.blobUrl);
  view.blobUrl = url;
  return url;
}

async function openPhoto(name) {
  view.name = name;
  view.gen += 1;
  view.params = null;
  show('viewer');
  $('saved').hidden = true;
  $('guess').hidden = true;
  $('save').disabled = true;
  $('selection').hidden = true;
  $('download').href = '/photos/' + encodeURIComponent(name) + '?download=1';
  $('download').setAttribute('download', name);
  status('loading…');
  try {
    const [info] = await Promise.all([
      call('/api/info/' + encodeURIComponent(name)).then((r) => r.json()),
      setImage('/photos/' + encodeURIComponent(name)),
    ]);
    view.info = info;
    const c = info.current || {};
    if (c.f) {
      $('f').value = c.f;
      $('f-out').value = Number(c.f).toFixed(1);
    }
    $('blades').value = String(c.blades || 0);
    markFocus(c.x0 ?? 0.5, c.y0 ?? 0.5);
    $('hint').hidden = !info.refocusable;
    $('guess').hidden = !(info.refocusable && info.depthGuess);
    $('controls').hidden = false;
    for (const el of [$('f'), $('blades')]) el.disabled = !info.refocusable;
    status(info.refocusable ? '' : 'this photo has no depth map: it cannot be refocused');
    setState('photo');
  } catch (e) {
    status(e.message);
  }
}

function markFocus(x, y) {
  const mark = $('focus-mark');
  mark.style.left = 100 * x + '%';
  mark.style.top = 100 * y + '%';
  mark.hidden = false;
}

// Pointer position as fractions of the displayed image.
function fraction(event) {
  const r = $('photo').getBoundingClientRect();
  const clamp = (v) => Math.min(1, Math.max(0, v));
  return { x: clamp((event.clientX - r.left) / r.width), y: clamp((event.clientY - r.top) / r.height) };
}

let drag = null;
$('stage').addEventListener('pointerdown', (event) => {
  if (!view.info || !view.info.refocusable) return;
  event.preventDefault();
  $('stage').setPointerCapture(event.pointerId);
  drag = fraction(event);
});
$('stage').addEventListener('pointermove', (event) => {
  if (!drag) return;
  const p = fraction(event);
  const sel = $('selection');
  sel.style.left = 100 * Math.min(drag.x, p.x) + '%';
  sel.style.top = 100 * Math.min(drag.y, p.y) + '%';
  sel.style.width = 100 * Math.abs(p.x - drag.x) + '%';
  sel.style.height = 100 * Math.abs(p.y - drag.y) + '%';
  sel.hidden = false;
});
$('stage').addEventListener('pointerup', (event) => {
  if (!drag) return;
  const tapped = performance.now();
  const p = fraction(event);
  let x0 = Math.min(drag.x, p.x), x1 = Math.max(drag.x, p.x);
  let y0 = Math.min(drag.y, p.y), y1 = Math.max(drag.y, p.y);
  drag = null;
  $('selection').hidden = true;
  const r = $('photo').getBoundingClientRect();
  if ((x1 - x0) * r.width < 8 && (y1 - y0) * r.height < 8) {  // a tap, not a drag
    x0 = x1 = (x0 + x1) / 2;
    y0 = y1 = (y0 + y1) / 2;
  }
  view.params = { x0, y0, x1, y1 };
  markFocus((x0 + x1) / 2, (y0 + y1) / 2);
  refocus(tapped);
});
$('stage').addEventListener('pointercancel', () => {
  drag = null;
  $('selection').hidden = true;
});

function requestFields() {
  const p = view.params;
  return {
    name: view.name,
    x0: p.x0.toFixed(4), y0: p.y0.toFixed(4), x1: p.x1.toFixed(4), y1: p.y1.toFixed(4),
    f: $('f').value,
    blades: $('blades').value,
  };
}

// Preview first (shown as soon as it arrives), then the full-size render; a newer tap or
// setting makes both of an older one pointless.
async function refocus(startedAt) {
  if (!view.params) return;
  const gen = ++view.gen;
  const wanted = () => gen === view.gen;
  $('save').disabled = true;
  $('saved').hidden = true;
  status('preview…');
  try {
    const fields = requestFields();
    const preview = await (await call('/api/preview', form(fields), wanted)).blob();
    if (!wanted()) return;
    window.lbPreviewBlob = preview;  // the test measures the preview itself
    await setImage(useBlob(preview));
    const ms = performance.now() - startedAt;
    window.lbLatencies.push(ms);
    document.body.dataset.previewMs = ms.toFixed(1);
    setState('preview');
    status(`preview in ${Math.round(ms)} ms; rendering full size…`);
    $('save').disabled = false;
    const full = await (await call('/api/render', form(fields), wanted)).blob();
    if (!wanted()) return;
    await setImage(useBlob(full));
    setState('rendered');
    status(`full size in ${Math.round(performance.now() - startedAt)} ms`);
  } catch (e) {
    if (wanted() && e.message !== 'superseded' && e.message !== 'login needed') status(e.message);
  }
}

$('f').addEventListener('input', () => { $('f-out').value = Number($('f').value).toFixed(1); });
$('f').addEventListener('change', () => refocus(performance.now()));
$('blades').addEventListener('change', () => refocus(performance.now()));

$('save').addEventListener('click', async () => {
  if (!view.params) return;
  $('save').disabled = true;
  status('saving…');
  try {
    const saved = await (await call('/api/save', form(requestFields()))).json();
    $('saved').textContent = 'Saved as ' + saved.name;
    $('saved').hidden = false;
    document.body.dataset.savedName = saved.name;
    setState('saved');
    status('');
    listPhotos();  // the new photo in the gallery for when the user goes back
  } catch (e) {
    status(e.message);
  }
  $('save').disabled = false;
});

$('back').addEventListener('click', () => {
  view.gen += 1;  // drop whatever is still on its way
  openGallery();
});

openGallery();
