// The upload page: builds the parameter form from GET /v1/params, submits the
// model as multipart/form-data, polls the job, then shows the result GLB in a
// three.js viewer (orbit controls; toggles for debug layers when the job has
// them; the texture or a checker), the UV layout, a summary of the diagnostics
// against the targets (summary.js; the raw rows behind a disclosure and as a
// download) and, when the diagnostics carry a solver history, its convergence
// plot. A .gltf may come with the files it names (several files picked or
// dropped at once) or as a .zip of its folder.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { orderedStages, renderSummary } from './summary.js';

const $ = (id) => document.getElementById(id);
const state = { file: null, extra: [], params: [], token: localStorage.getItem('soupuv-token') || '' };
$('token-input').value = state.token;

function authHeaders() {
  const t = $('token-input').value.trim();
  if (t) localStorage.setItem('soupuv-token', t);
  return t ? { Authorization: `Bearer ${t}` } : {};
}

async function problemText(res) {
  try {
    const p = await res.json();
    return `${p.title || res.status}: ${p.detail || ''}`;
  } catch {
    return `HTTP ${res.status}`;
  }
}

// ---- parameters -------------------------------------------------------------
async function loadParams() {
  const res = await fetch('/v1/params', { headers: authHeaders() });
  if (!res.ok) return showFormError(await problemText(res));
  const { params } = await res.json();
  state.params = params;
  const box = $('params');
  for (const p of params) {
    const label = document.createElement('label');
    label.textContent = p.name.replace(/_/g, ' ');
    if (!p.supported) {
      label.classList.add('unsupported');
      label.title = `not supported by this server's soupuv build (${p.flag})`;
    }
    let input;
    if (p.type === 'array') {
      // seam_hints: JSON polylines, [[[x,y,z], ...], ...]
      input = document.createElement('textarea');
      input.rows = 2;
      input.placeholder = '[[[x,y,z],[x,y,z]], ...]';
      input.title = `at most ${p.max_polylines} polylines, ${p.max_points} points`;
    } else if (p.values) {
      input = document.createElement('select');
      if (p.default === null) input.append(new Option('(default)', ''));
      for (const v of p.values) input.append(new Option(v, v, false, v === p.default));
    } else if (p.type === 'boolean' && p.default === null) {
      // No fixed default (rebake: on when the input has colours): three choices.
      input = document.createElement('select');
      for (const [text, v] of [['(default)', ''], ['on', 'true'], ['off', 'false']]) input.append(new Option(text, v));
    } else if (p.type === 'boolean') {
      input = document.createElement('input');
      input.type = 'checkbox';
      input.checked = p.default === true;
    } else {
      input = document.createElement('input');
      input.type = 'number';
      input.placeholder = 'default';
      if (p.min !== undefined) input.min = p.min;
      if (p.max !== undefined) input.max = p.max;
      input.step = p.type === 'integer' ? '1' : 'any';
      if (p.default !== null) input.value = p.default;
    }
    input.name = p.name;
    input.disabled = !p.supported;
    if (p.name === 'debug_outputs' && p.supported)
      label.title = 'also the proxy, the field lines and the UV layout (the field-line file grows with the triangle count)';
    label.append(input);
    box.append(label);
  }
}

// Throws with a readable reason when a JSON parameter does not parse.
function collectParams() {
  const out = {};
  for (const p of state.params) {
    if (!p.supported) continue;
    const el = $('params').querySelector(`[name="${p.name}"]`);
    if (p.type === 'array') {
      if (el.value.trim() === '') continue;
      try {
        out[p.name] = JSON.parse(el.value);
      } catch {
        throw new Error(`${p.name.replace(/_/g, ' ')} is not valid JSON`);
      }
    } else if (p.type === 'boolean' && p.default === null) {
      if (el.value !== '') out[p.name] = el.value === 'true';
    } else if (p.type === 'boolean') {
      if (el.checked !== (p.default === true)) out[p.name] = el.checked;
    } else if (el.value !== '') {
      out[p.name] = p.type === 'integer' ? parseInt(el.value, 10) : p.type === 'number' ? parseFloat(el.value) : el.value;
    }
  }
  return out;
}

// ---- file choice ----------------------------------------------------------------
// The model (.glb/.gltf/.drc/.zip) among the chosen files; the others are the
// files a .gltf names (its .bin, its images), sent as "files" parts.
function chooseFiles(list) {
  const files = [...(list || [])];
  const isModel = (f) => /\.(glb|gltf|drc|zip)$/i.test(f.name);
  const file = files.find(isModel) || files[0] || null;
  state.file = file;
  state.extra = files.filter((f) => f !== file);
  const size = files.reduce((s, f) => s + f.size, 0);
  $('drop-text').textContent = file
    ? `${file.name}${state.extra.length ? ` + ${state.extra.length} file(s)` : ''} (${(size / 1024).toFixed(0)} KiB)`
    : 'Drop a file here';
  $('submit-button').disabled = !file;
}
const zone = $('drop-zone');
zone.addEventListener('dragover', (e) => { e.preventDefault(); zone.classList.add('over'); });
zone.addEventListener('dragleave', () => zone.classList.remove('over'));
zone.addEventListener('drop', (e) => {
  e.preventDefault();
  zone.classList.remove('over');
  if (e.dataTransfer.files.length) chooseFiles(e.dataTransfer.files);
});
$('file-input').addEventListener('change', (e) => chooseFiles(e.target.files));

function showFormError(text) {
  $('form-error').textContent = text;
  $('form-error').hidden = !text;
}

// ---- submit and poll ----------------------------------------------------------
$('job-form').addEventListener('submit', async (e) => {
  e.preventDefault();
  showFormError('');
  const form = new FormData();
  // Browsers label unknown extensions application/octet-stream; the server
  // also looks at the file name, but say what we know.
  const ext = state.file.name.split('.').pop().toLowerCase();
  const type = { glb: 'model/gltf-binary', gltf: 'model/gltf+json', drc: 'application/octet-stream', zip: 'application/zip' }[ext] || state.file.type;
  form.append('file', new Blob([state.file], { type }), state.file.name);
  for (const f of state.extra) form.append('files', f, f.name);
  let params;
  try {
    params = collectParams();
  } catch (err) {
    return showFormError(err.message);
  }
  form.append('params', new Blob([JSON.stringify(params)], { type: 'application/json' }));
  const tex = $('texture-input').files[0];
  if (tex) form.append('texture', tex, tex.name);
  $('submit-button').disabled = true;
  const res = await fetch('/v1/jobs', { method: 'POST', body: form, headers: authHeaders() });
  $('submit-button').disabled = false;
  if (res.status !== 202) return showFormError(await problemText(res));
  const job = await res.json();
  $('result-panel').hidden = true;
  $('job-panel').hidden = false;
  $('job-id').textContent = job.id;
  poll(job.id);
});

async function poll(id) {
  for (;;) {
    const res = await fetch(`/v1/jobs/${id}`, { headers: authHeaders() });
    if (!res.ok) return showFormError(await problemText(res));
    const job = await res.json();
    showJob(job);
    if (['succeeded', 'failed', 'canceled'].includes(job.state)) {
      if (job.state === 'succeeded') await showResult(job);
      return;
    }
    await new Promise((r) => setTimeout(r, 300));
  }
}

function showJob(job) {
  const s = $('job-state');
  s.textContent = job.state;
  s.dataset.state = job.state;
  $('job-stage').textContent = job.state === 'running' && job.stage ? `stage: ${job.stage.replace(/__/g, ' / ')}` : '';
  if (job.state === 'running' && job.stage) (window.__soupuvStagesSeen ||= []).push(job.stage);  // browser test
  $('job-progress').value = job.state === 'running' ? job.fraction || 0 : job.state === 'succeeded' ? 1 : 0;
  // Stages done so far, in the order the worker reported them, with seconds.
  const list = $('stages');
  list.textContent = '';
  for (const [name, secs] of orderedStages(job.stage_seconds)) {
    const li = document.createElement('li');
    li.textContent = `${name.replace(/__/g, ' / ')}: ${secs < 0.01 ? '<0.01' : secs.toFixed(2)} s`;
    list.append(li);
  }
  $('job-error').hidden = !job.error;
  if (job.error) $('job-error').textContent = `${job.error.code}: ${job.error.detail}`;
  const dl = $('downloads');
  dl.textContent = '';
  for (const [name, href] of Object.entries(job.links || {})) {
    if (name === 'self') continue;
    const a = document.createElement('a');
    a.href = href;
    a.textContent = name;
    a.download = '';
    dl.append(a, ' ');
  }
}

// ---- result -----------------------------------------------------------------------
async function fetchBuffer(href) {
  const res = await fetch(href, { headers: authHeaders() });
  if (!res.ok) throw new Error(await problemText(res));
  return res.arrayBuffer();
}

async function showResult(job) {
  $('result-panel').hidden = false;
  const layers = [{ name: 'textured soup', href: job.links.result, visible: true }];
  if (job.links['proxy.glb']) layers.push({ name: 'proxy', href: job.links['proxy.glb'], visible: false });
  if (job.links['field-lines.glb']) layers.push({ name: 'field lines', href: job.links['field-lines.glb'], visible: false });
  await viewer.show(layers);
  if (job.links['uv-layout.png']) {
    const blob = new Blob([await fetchBuffer(job.links['uv-layout.png'])], { type: 'image/png' });
    $('uv-layout').src = URL.createObjectURL(blob);
    $('uv-figure').hidden = false;
  }
  if (job.links.diagnostics) {
    const bytes = await fetchBuffer(job.links.diagnostics);
    const diag = JSON.parse(new TextDecoder().decode(bytes));
    renderSummary($('summary'), diag);
    showWarnings(diag.warnings || []);
    showDiagnostics(diag);
    $('diagnostics-download').href = URL.createObjectURL(new Blob([bytes], { type: 'application/json' }));
    $('diagnostics-download').download = `${job.id}-diagnostics.json`;
    plotConvergence(diag);
  }
  window.__soupuvResultShown = true;  // for the browser test: every panel is filled
}

function flatten(obj, prefix = '', out = []) {
  for (const [k, v] of Object.entries(obj)) {
    const key = prefix ? `${prefix}.${k}` : k;
    if (v && typeof v === 'object' && !Array.isArray(v)) flatten(v, key, out);
    else if (Array.isArray(v) && v.length > 8) out.push([key, `[${v.length} values]`]);
    // A short list of records (e.g. atlas.candidates) reads better one field per row.
    else if (Array.isArray(v) && v.some((e) => e && typeof e === 'object')) {
      v.forEach((e, i) => (e && typeof e === 'object' ? flatten(e, `${key}[${i}]`, out)
        : out.push([`${key}[${i}]`, JSON.stringify(e)])));
    }
    else out.push([key, typeof v === 'number' && !Number.isInteger(v) ? v.toPrecision(4) : JSON.stringify(v)]);
  }
  return out;
}

// Every field, one row each, behind the "All diagnostics" disclosure.
function showDiagnostics(diag) {
  const body = $('diagnostics').querySelector('tbody');
  body.textContent = '';
  const rows = flatten(diag);
  for (const [k, v] of rows) {
    const tr = body.insertRow();
    tr.insertCell().textContent = k;
    tr.insertCell().textContent = v;
  }
  $('raw-count').textContent = `${rows.length} rows`;
}

function showWarnings(warnings) {
  const list = $('warnings');
  list.textContent = '';
  for (const w of warnings) {
    const li = document.createElement('li');
    li.textContent = w;
    list.append(li);
  }
  $('warnings-wrap').hidden = warnings.length === 0;
}

// The first numeric array named like a residual history anywhere in the
// diagnostics (the charge solver's), drawn on a log scale.
function findHistory(obj, path = '') {
  for (const [k, v] of Object.entries(obj || {})) {
    const p = path ? `${path}.${k}` : k;
    if (Array.isArray(v) && v.length >= 1 && v.every((x) => typeof x === 'number') && /^(resid|history)/i.test(k)) return [p, v];
    if (v && typeof v === 'object' && !Array.isArray(v)) {
      const found = findHistory(v, p);
      if (found) return found;
    }
  }
  return null;
}

function plotConvergence(diag) {
  const found = findHistory(diag);
  $('plot-figure').hidden = !found;
  if (!found) return;
  const [name, values] = found;
  $('plot-caption').textContent = `${name} (log scale) per iteration: ${values.length} iteration${values.length > 1 ? 's' : ''}, last ${values[values.length - 1].toExponential(2)}`;
  const c = $('convergence');
  const g = c.getContext('2d');
  g.clearRect(0, 0, c.width, c.height);
  const logs = values.map((v) => Math.log10(Math.max(v, 1e-300)));
  const lo = Math.min(...logs), hi = Math.max(...logs);
  const x = (i) => 30 + (values.length > 1 ? i / (values.length - 1) : 0.5) * (c.width - 40);
  const y = (l) => 10 + (hi === lo ? 0.5 : (hi - l) / (hi - lo)) * (c.height - 30);
  g.strokeStyle = '#999';
  g.strokeRect(30, 10, c.width - 40, c.height - 30);
  g.fillStyle = '#333';
  g.font = '11px sans-serif';
  g.fillText(`1e${hi.toFixed(0)}`, 0, 14);
  g.fillText(`1e${lo.toFixed(0)}`, 0, c.height - 20);
  g.strokeStyle = '#1d3557';
  g.beginPath();
  logs.forEach((l, i) => (i ? g.lineTo(x(i), y(l)) : g.moveTo(x(i), y(l))));
  g.stroke();
  g.fillStyle = '#1d3557';  // a dot per iteration: a one-step solve is visible too
  logs.forEach((l, i) => g.fillRect(x(i) - 2, y(l) - 2, 4, 4));
  window.__soupuvPlotPoints = values.length;  // for the browser test
}

// ---- viewer -------------------------------------------------------------------------
const viewer = (() => {
  const canvas = $('viewer');
  // preserveDrawingBuffer: the browser test reads the pixels back.
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
  renderer.setClearColor(0x20262e);
  const scene = new THREE.Scene();
  scene.add(new THREE.HemisphereLight(0xffffff, 0x445566, 2.0));
  const sun = new THREE.DirectionalLight(0xffffff, 1.5);
  sun.position.set(1, 2, 3);
  scene.add(sun);
  const camera = new THREE.PerspectiveCamera(45, 4 / 3, 0.01, 1000);
  const controls = new OrbitControls(camera, canvas);
  let roots = [];

  function resize() {
    const w = canvas.clientWidth || 800, h = canvas.clientHeight || 600;
    renderer.setSize(w, h, false);
    camera.aspect = w / h;
    camera.updateProjectionMatrix();
  }
  function render() { renderer.render(scene, camera); }
  controls.addEventListener('change', render);
  window.addEventListener('resize', () => { resize(); render(); });

  // A checker shows the map itself (seams, stretch) where the texture (a
  // re-bake of the input's colours) is meant to hide it.
  const checker = (() => {
    const c = document.createElement('canvas');
    c.width = c.height = 512;
    const g = c.getContext('2d');
    for (let y = 0; y < 16; y++)
      for (let x = 0; x < 16; x++) {
        g.fillStyle = (x + y) % 2 ? '#f2f2f2' : `hsl(${(x * 22 + y * 7) % 360}, 55%, 45%)`;
        g.fillRect(x * 32, y * 32, 32, 32);
      }
    const t = new THREE.CanvasTexture(c);
    t.flipY = false;  // glTF's UV origin is the top-left
    t.colorSpace = THREE.SRGBColorSpace;
    t.wrapS = t.wrapT = THREE.RepeatWrapping;
    return t;
  })();
  function useChecker(root, on) {
    root.traverse((o) => {
      if (!o.isMesh) return;
      for (const m of Array.isArray(o.material) ? o.material : [o.material]) {
        if (!m.userData.ownMap) m.userData.ownMap = m.map || null;
        m.map = on ? checker : m.userData.ownMap;
        m.needsUpdate = true;
      }
    });
  }

  async function show(layers) {
    for (const r of roots) scene.remove(r);
    roots = [];
    $('layers').textContent = '';
    const loader = new GLTFLoader();
    for (const layer of layers) {
      const gltf = await loader.parseAsync(await fetchBuffer(layer.href), '');
      gltf.scene.visible = layer.visible;
      scene.add(gltf.scene);
      roots.push(gltf.scene);
      const label = document.createElement('label');
      const box = document.createElement('input');
      box.type = 'checkbox';
      box.checked = layer.visible;
      box.addEventListener('change', () => { gltf.scene.visible = box.checked; render(); });
      label.append(box, ` ${layer.name}`);
      $('layers').append(label);
    }
    const label = document.createElement('label');
    const box = document.createElement('input');
    box.type = 'checkbox';
    box.addEventListener('change', () => { useChecker(roots[0], box.checked); render(); });
    label.append(box, ' checker texture');
    $('layers').append(label);
    // Frame the first layer.
    resize();
    const bounds = new THREE.Box3().setFromObject(roots[0]);
    const size = bounds.getSize(new THREE.Vector3()).length() || 1;
    const center = bounds.getCenter(new THREE.Vector3());
    camera.near = size / 100;
    camera.far = size * 100;
    camera.position.copy(center).add(new THREE.Vector3(0.6, 0.5, 1).normalize().multiplyScalar(size * 1.2));
    camera.updateProjectionMatrix();
    controls.target.copy(center);
    controls.update();
    render();
    window.__soupuvViewerReady = true;  // for the browser test
  }
  return { show };
})();

loadParams();
