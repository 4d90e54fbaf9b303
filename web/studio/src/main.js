// navsim studio: the browser front end of `navsim serve`. The scene file is the one state: every
// form field, the map, the parametric preview and the YAML editor read and write the same YAML
// document (comments kept), which is what Run posts, what the estimate is made from, what the
// Download button saves and what the page URL carries (#scene=...), so a saved file or a URL
// reruns the same scene bit-identically in navsim and navstudio.
import YAML from 'yaml';
import { renderNode, schemaAt, deref, newItem } from './form.js';
import { StudioMap, lonLatToNed, nedToLonLat } from './map.js';
import { drawCharts, drawCompareCharts, chartPng, parseCsv } from './charts.js';
import { sceneDiff, modelDiff, verdictRows, formatValue, fmtNum, verdictText, change } from './compare.js';
import { buildReport } from './report.js';
import { View3D } from './view3d.js';
import { nedFrameChange, originDistance, formatDistance } from './geo.js';

void nedToLonLat;
const $ = (id) => document.getElementById(id);
const studio = (window.__studio = { timings: {}, errors: [] });
studio.sceneDiff = (a, b) => sceneDiff(YAML.parse(a), YAML.parse(b)); // for the tests

// ---------------------------------------------------------------- API
async function api(method, url, body, type = 'application/yaml') {
  const init = { method, headers: {} };
  if (body !== undefined) {
    init.body = body;
    init.headers['Content-Type'] = type;
  }
  const r = await fetch(url, init);
  const text = await r.text();
  let json = null;
  try { json = text ? JSON.parse(text) : null; } catch { json = null; }
  return { status: r.status, ok: r.ok, json, text, headers: r.headers };
}

// ---------------------------------------------------------------- the scene document
class Scene {
  constructor() { this.doc = new YAML.Document({}); }
  load(text) {
    const d = YAML.parseDocument(text, { prettyErrors: false });
    if (d.errors.length) throw new Error(d.errors[0].message);
    if (!YAML.isMap(d.contents)) throw new Error('a scene is a YAML mapping');
    this.doc = d;
  }
  get(path) {
    if (!path.length) return this.doc.toJS();
    const v = this.doc.getIn(path);
    return YAML.isNode(v) ? v.toJSON() : v;
  }
  set(path, v) {
    const node = this.doc.createNode(v);
    // Short vectors and small mappings in flow style, as the library scenes write them.
    const flowable = (x) => Array.isArray(x) ? x.length <= 6 && x.every((e) => typeof e !== 'object' || flowable(e)) :
      x && typeof x === 'object' ? Object.values(x).every((e) => typeof e !== 'object' || (Array.isArray(e) && flowable(e))) : false;
    if (YAML.isCollection(node) && flowable(v) && !(path.length === 1)) node.flow = true;
    if (YAML.isCollection(node) && Array.isArray(v) && v.length && typeof v[0] === 'object' && !Array.isArray(v[0])) node.flow = false;
    // Parents that do not exist yet are made as block mappings.
    for (let i = 1; i < path.length; ++i) {
      const p = path.slice(0, i);
      const cur = this.doc.getIn(p);
      if (cur === undefined || cur === null) this.doc.setIn(p, this.doc.createNode(typeof path[i] === 'number' ? [] : {}));
    }
    this.doc.setIn(path, node);
  }
  del(path) { if (this.doc.hasIn(path)) this.doc.deleteIn(path); }
  text() { return this.doc.toString({ lineWidth: 0, flowCollectionPadding: false }); }
}

const scene = new Scene();
let schema = null;
let catalogs = { imu: [], gnss: [] };
const mapView = new StudioMap($('map'), $('map-credits'));
studio.map = mapView;
let view3d = null;
let lastRun = null;

function status(msg) { $('status').textContent = msg; }

// ---------------------------------------------------------------- change propagation
let pendingCheck = null;
// Every change of the scene counts here: an answer to a validate or estimate request sent for an
// older scene is dropped, so it cannot overwrite the state of a newer one whose check is still
// waiting for its debounce.
let sceneGen = 0;
function changed(source, structure = false) {
  ++sceneGen;
  // A loaded scene is validated and estimated at once: the requests go out before the forms
  // and the map are built, which overlap the server's work.
  if (source === 'load') {
    clearTimeout(pendingCheck);
    $('estimate').dataset.state = 'pending';
    checkAndEstimate();
  }
  if (source !== 'yaml') $('yaml').value = scene.text();
  if (source !== 'form' || structure) renderForms();
  syncFlow();
  drawPreview();
  updateUrl();
  if (source === 'load') return;
  clearTimeout(pendingCheck);
  $('estimate').dataset.state = 'pending';
  pendingCheck = setTimeout(checkAndEstimate, source === 'yaml' ? 300 : 250);
}
const b64 = (s) => btoa(String.fromCharCode(...new TextEncoder().encode(s))).replace(/\+/g, '-').replace(/\//g, '_').replace(/=+$/, '');
const unb64 = (s) => new TextDecoder().decode(Uint8Array.from(atob(s.replace(/-/g, '+').replace(/_/g, '/')), (c) => c.charCodeAt(0)));

// ---------------------------------------------------------------- schema forms
const formScene = {
  get: (p) => scene.get(p),
  set: (p, v) => { scene.set(p, v); changed('form'); },
  del: (p) => { scene.del(p); changed('form'); },
};
function renderForms() {
  for (const host of document.querySelectorAll('.form[data-section]')) {
    const path = host.dataset.section.split('.');
    const key = path[path.length - 1];
    host.textContent = '';
    if (!schema) {
      host.innerHTML = '<p class="hint">The scene schema is not available from this server: edit the YAML view.</p>';
      continue;
    }
    const s = schemaAt(schema, path, scene);
    if (!s) continue;
    if (key === 'array' && !scene.get(['array'])) {
      host.innerHTML = '<p class="hint">The accelerometer array (gyro-free schemes) is set when such a scheme is chosen.</p>';
      continue;
    }
    renderNode(host, schema, s, key, path, formScene, () => changed('form', true), host.dataset.skip ? host.dataset.skip.split(',') : null);
  }
}

// ---------------------------------------------------------------- the paper's flow widgets
function enumOf(path, fallback) {
  const s = schema && schemaAt(schema, path, scene);
  return s && s.enum ? s.enum : fallback;
}
function fillSelect(sel, values, current, labels = {}) {
  const keep = sel.value;
  sel.textContent = '';
  for (const v of values) {
    const o = document.createElement('option');
    o.value = v;
    o.textContent = labels[v] || v;
    sel.appendChild(o);
  }
  sel.value = current !== undefined ? current : keep;
}
const schemeHelp = {
  free_ins: 'free inertial navigation: the IMU alone',
  gyro_free: 'gyro-free array INS: angular motion from an array of accelerometers',
  ins_gnss: 'INS/GNSS: loosely coupled Kalman filter',
  gyro_free_gnss: 'gyro-free array INS aided by GNSS',
};
function syncFlow() {
  const scheme = scene.get(['navigation', 'scheme']);
  const schemes = enumOf(['navigation', 'scheme'], []);
  fillSelect($('scheme'), schemes, scheme ?? (schemaAt(schema || {}, ['navigation', 'scheme'], scene) || {}).default,
    Object.fromEntries(schemes.map((v) => [v, schemeHelp[v] ? `${v} — ${schemeHelp[v]}` : v])));
  $('scheme-help').textContent = schemeHelp[$('scheme').value] || '';
  fillSelect($('imu-catalog'), ['', ...catalogs.imu.map((c) => c.name)], scene.get(['imu', 'catalog']) ?? '', { '': '(typed in below)' });
  const cur = catalogs.imu.find((c) => c.name === scene.get(['imu', 'catalog']));
  $('imu-catalog-info').textContent = cur ? describeImu(cur) : '';
  fillSelect($('gnss-catalog'), ['', ...catalogs.gnss.map((c) => c.name)], scene.get(['gnss', 'catalog']) ?? '', { '': '(typed in below)' });
  $('gnss-enabled').checked = scene.get(['gnss', 'enabled']) === true;
  const tt = scene.get(['trajectory', 'type']);
  fillSelect($('traj-type'), enumOf(['trajectory', 'type'], tt ? [tt] : []), tt);
  $('traj-waypoints').hidden = tt !== 'waypoints';
  $('traj-parametric').hidden = tt !== 'parametric';
  const o = scene.get(['earth', 'origin']) || {};
  mapView.setOrigin(o.lat_deg ?? 0, o.lon_deg ?? 0);
  const pts = waypoints();
  $('wp-list').textContent = '';
  pts.forEach((p, i) => {
    const li = document.createElement('li');
    li.textContent = `N ${p.ned_m[0].toFixed(0)} m, E ${p.ned_m[1].toFixed(0)} m, ${p.speed_mps ?? '?'} m/s`;
    li.dataset.index = i;
    $('wp-list').appendChild(li);
  });
  mapView.setWaypoints(tt === 'waypoints' ? pts.map((p) => p.ned_m) : []);
  const outs = scene.get(['gnss', 'outages']) || [];
  $('outage-list').textContent = '';
  for (const [a, b] of outs) {
    const li = document.createElement('li');
    li.textContent = `${a} s … ${b} s (${b - a} s)`;
    $('outage-list').appendChild(li);
  }
}
function describeImu(c) {
  const bits = [c.grade, c.cost_band && `cost ${c.cost_band}`];
  const fmt = (o, pre) => Object.entries(o || {}).filter(([, v]) => typeof v === 'number').map(([k, v]) => `${pre} ${k} ${+v.toPrecision(3)}`);
  bits.push(...fmt(c.gyro, 'gyro'), ...fmt(c.accel, 'accel'));
  if (c.verified) bits.push(`verified: ${c.verified}`);
  return bits.filter(Boolean).join(' · ');
}
function waypoints() {
  const p = scene.get(['trajectory', 'waypoints', 'points']);
  return Array.isArray(p) ? p.filter((x) => x && Array.isArray(x.ned_m)) : [];
}

// Trajectory kind switch: keep the scalar keys, drop the sections of the other kinds.
function setTrajectoryType(kind) {
  const kinds = enumOf(['trajectory', 'type'], [kind]);
  for (const k of kinds) if (k !== kind && scene.get(['trajectory', k]) !== undefined) scene.del(['trajectory', k]);
  scene.set(['trajectory', 'type'], kind);
  if (kind === 'waypoints') scene.del(['trajectory', 'duration_s']);
  if (kind !== 'waypoints' && scene.get(['trajectory', 'duration_s']) === undefined) scene.set(['trajectory', 'duration_s'], 60);
  const sub = schema && schemaAt(schema, ['trajectory', kind], scene);
  if (sub && scene.get(['trajectory', kind]) === undefined && kind !== 'waypoints') scene.set(['trajectory', kind], newItem(schema, sub));
}

let drawing = false, drawnThisSession = 0;
function addWaypoint(lon, lat) {
  if (scene.get(['trajectory', 'type']) !== 'waypoints') setTrajectoryType('waypoints');
  if (scene.get(['earth', 'origin']) === undefined) {
    scene.set(['earth', 'origin'], { lat_deg: +lat.toFixed(6), lon_deg: +lon.toFixed(6), h_m: 0 });
    mapView.setOrigin(lat, lon);
  }
  const [n, e] = lonLatToNed(mapView.origin, lon, lat);
  const speed = Math.max(0.1, +$('wp-speed').value || 10);
  let pts = drawnThisSession === 0 ? [] : scene.get(['trajectory', 'waypoints', 'points']) || [];
  // Start and end at rest; the points between at the chosen speed.
  if (pts.length) pts[pts.length - 1].speed_mps = pts.length === 1 ? 0 : speed;
  pts.push({ ned_m: [Math.round(n * 10) / 10, Math.round(e * 10) / 10, 0], speed_mps: pts.length === 0 ? 0 : 0 });
  if (pts.length >= 2) pts[pts.length - 2].speed_mps = pts.length === 2 ? 0 : speed;
  ++drawnThisSession;
  scene.set(['trajectory', 'waypoints', 'points'], pts);
  if (scene.get(['trajectory', 'waypoints', 'timing']) === undefined) scene.set(['trajectory', 'waypoints', 'timing'], 'speed');
  changed('flow', true);
}

// ---------------------------------------------------------------- previews
function parametricPath() {
  const p = scene.get(['trajectory', 'parametric']) || {};
  const T = +scene.get(['trajectory', 'duration_s']) || 0;
  const v = (k) => (Array.isArray(p[k]) ? p[k].map(Number) : [0, 0, 0]);
  const R0 = v('R0_m'), V0 = v('V0_mps'), A = v('A_mps2'), B = v('B_m'), C = v('C_hz'), D = v('D_rad');
  const n = 400, out = { t: [], n: [], e: [], d: [] };
  for (let i = 0; i <= n; ++i) {
    const t = (T * i) / n;
    // R(t) = R0 + V0 t + A t^2 + B sin(2 pi C t + D), per axis of the scene frame (NED).
    const r = [0, 1, 2].map((k) => R0[k] + V0[k] * t + A[k] * t * t + B[k] * Math.sin(2 * Math.PI * C[k] * t + D[k]));
    out.t.push(t); out.n.push(r[0]); out.e.push(r[1]); out.d.push(r[2]);
  }
  return out;
}
function drawPreview() {
  const tt = scene.get(['trajectory', 'type']);
  if (lastRun && lastRun.truth && lastRun.sceneText === scene.text()) return; // the run's truth is shown
  if (tt === 'parametric') {
    const p = parametricPath();
    mapView.setReference(p.n, p.e);
    const cv = $('param-preview'), ctx = cv.getContext('2d');
    const W = cv.width, H = cv.height;
    ctx.clearRect(0, 0, W, H);
    ctx.fillStyle = '#fff';
    ctx.fillRect(0, 0, W, H);
    const split = W * 0.62;
    const box = (xs, ys, x0, w, equal) => {
      let [a, b, c, d] = [Math.min(...xs), Math.max(...xs), Math.min(...ys), Math.max(...ys)];
      if (b - a < 1e-9) { a -= 1; b += 1; }
      if (d - c < 1e-9) { c -= 1; d += 1; }
      let sx = (w - 30) / (b - a), sy = (H - 30) / (d - c);
      if (equal) sx = sy = Math.min(sx, sy);
      return (x, y) => [x0 + 15 + (x - a) * sx, H - 15 - (y - c) * sy];
    };
    const line = (xs, ys, f, color) => {
      ctx.strokeStyle = color; ctx.lineWidth = 2; ctx.beginPath();
      xs.forEach((x, i) => { const [px, py] = f(x, ys[i]); i ? ctx.lineTo(px, py) : ctx.moveTo(px, py); });
      ctx.stroke();
    };
    line(p.e, p.n, box(p.e, p.n, 0, split, true), '#1f5fbf');
    const up = p.d.map((x) => -x);
    line(p.t, up, box(p.t, up, split, W - split, false), '#2a9d3a');
    ctx.fillStyle = '#333'; ctx.font = '12px sans-serif';
    ctx.fillText('north (up) vs east', 8, 14);
    ctx.fillText('height vs time', split + 8, 14);
    cv.dataset.drawn = String(p.t.length);
  } else if (tt === 'waypoints') {
    const pts = waypoints();
    mapView.setReference(pts.map((x) => x.ned_m[0]), pts.map((x) => x.ned_m[1]));
  } else {
    mapView.setReference([], []);
  }
  mapView.setEstimate(null);
  mapView.setFixes(null);
}

// ---------------------------------------------------------------- validation and estimate
// One validation + estimate at a time: a change made meanwhile runs one more afterwards (the
// server computes a bounded number of estimates at once and answers 429 beyond).
let checking = false, checkAgain = false;
async function checkAndEstimate() {
  if (checking) { checkAgain = true; return; }
  checking = true;
  try {
    await checkOnce();
  } catch (err) {
    $('estimate').dataset.state = 'error';
    $('estimate-body').textContent = `estimate failed: ${err.message}`;
  } finally {
    checking = false;
    if (checkAgain) { checkAgain = false; checkAndEstimate(); }
  }
}
const sleep = (ms) => new Promise((res) => setTimeout(res, ms));
async function postRetrying(url, text) {
  for (let i = 0; ; ++i) {
    const r = await api('POST', url, text);
    if (r.status !== 429 || i >= 20 || checkAgain) return r;
    const after = Math.min(2, Math.max(0.2, +(r.headers.get('Retry-After') || 0.5)));
    await sleep(after * 1000);
  }
}
async function checkOnce() {
  const text = scene.text();
  const gen = sceneGen;
  const t0 = performance.now();
  const v = await postRetrying('api/validate', text);
  if (checkAgain || gen !== sceneGen) return;
  const st = $('yaml-status');
  if (v.status === 200) {
    const warns = (v.json && Array.isArray(v.json.warnings)) ? v.json.warnings : [];
    st.className = warns.length ? 'bad' : 'good';
    st.textContent = warns.length ? 'valid scene, but: ' + warns.map((w) => `${w.path}: ${w.message}`).join('\n') : 'valid scene';
    if (warns.length) status(`this server would not run the scene as it stands: ${warns[0].message}`);
  } else {
    st.className = 'bad';
    const errs = (v.json && v.json.errors) || [];
    st.textContent = errs.length ? errs.map((e) => `${e.line}:${e.col}: ${e.path}: ${e.message}`).join('\n') : `validation failed (HTTP ${v.status})`;
    $('estimate').dataset.state = 'invalid';
    $('estimate-body').textContent = 'The scene is not valid: ' + st.textContent.split('\n')[0];
    return;
  }
  const e = await postRetrying('api/estimate', text);
  if (checkAgain || gen !== sceneGen) return;
  studio.timings.estimate_ms = performance.now() - t0;
  showEstimate(e);
}
function requirementTable(reqs, predicted) {
  const t = document.createElement('table');
  t.innerHTML = `<thead><tr><th>requirement</th><th>statistic</th><th>${predicted ? 'predicted' : 'value'}</th><th>limit</th><th>verdict</th></tr></thead>`;
  const tb = document.createElement('tbody');
  for (const r of reqs) {
    const tr = document.createElement('tr');
    const known = typeof r.value === 'number';
    const verdict = !known ? 'n/a' : r.pass === true ? 'PASS' : r.pass === false ? 'FAIL' : 'n/a';
    const val = typeof r.value === 'number' ? r.value.toPrecision(4) : '—';
    for (const [txt, cls] of [[r.id, ''], [r.statistic + (r.time_s !== undefined ? ` @ ${r.time_s} s` : ''), ''], [`${val} ${r.unit || ''}`, ''], [`${r.limit} ${r.unit || ''}`, ''], [verdict, verdict === 'PASS' ? 'pass' : verdict === 'FAIL' ? 'fail' : '']]) {
      const td = document.createElement('td');
      td.textContent = txt;
      if (cls) td.className = cls;
      tr.appendChild(td);
    }
    tb.appendChild(tr);
  }
  t.appendChild(tb);
  return t;
}
function showEstimate(e) {
  const body = $('estimate-body');
  body.textContent = '';
  if (!e.ok || !e.json) {
    $('estimate').dataset.state = 'error';
    body.textContent = `estimate failed (HTTP ${e.status}): ${(e.json && (e.json.error || e.json.message)) || e.text.slice(0, 200)}`;
    return;
  }
  const j = e.json;
  const p = document.createElement('p');
  const cov = j.covariance_final || {};
  const hs = cov.pos_h_sd_m ?? cov.pos_sd_h_m;
  p.textContent = `scheme ${j.scheme || scene.get(['navigation', 'scheme']) || '?'}, ${j.t_s !== undefined ? `${(+j.t_s).toFixed(0)} s` : ''}` +
    (typeof hs === 'number' ? `, predicted horizontal 1σ at the end ${hs.toPrecision(3)} m` : '');
  body.appendChild(p);
  const reqs = j.requirements || [];
  if (reqs.length) body.appendChild(requirementTable(reqs, true));
  else body.appendChild(Object.assign(document.createElement('p'), { className: 'hint', textContent: 'no requirements in the scene' }));
  $('estimate').dataset.state = 'ok';
  if (studio.timings.sceneLoadStart !== undefined && studio.timings.scene_to_picture_ms === undefined) {
    mapView.whenRendered().then(() => {
      const now = performance.now();
      studio.timings.scene_to_picture_ms = now - studio.timings.sceneLoadStart;
      studio.timings.page_to_picture_ms = now; // from the navigation start
    });
    mapView.map.render();
  }
}

// ---------------------------------------------------------------- runs
let currentRun = null;
function runState(state, progress) {
  $('run-state').textContent = state + (progress !== undefined && state === 'running' ? ` ${(progress * 100).toFixed(0)} %` : '');
  $('run-state').dataset.state = state;
  if (progress !== undefined) $('progress').value = progress;
  const active = state === 'queued' || state === 'running' || state === 'starting';
  $('run').disabled = active;
  $('cancel').disabled = !active;
}
async function startRun() {
  const runs = Math.max(1, Math.round(+$('runs').value || 1));
  // The scene saved with the result names its run count, so that it reruns the same campaign.
  if (scene.get(['simulation', 'runs']) !== runs) { scene.set(['simulation', 'runs'], runs); changed('flow'); }
  const text = scene.text();
  runState('starting', 0);
  const r = await api('POST', `api/runs?runs=${runs}`, text);
  if (r.status !== 202 || !r.json || !r.json.id) {
    runState('failed');
    $('run-state').textContent = `not started (HTTP ${r.status}): ${(r.json && (r.json.error || r.json.message)) || r.text.slice(0, 200)}` +
      (r.headers.get('Retry-After') ? ` — retry after ${r.headers.get('Retry-After')} s` : '');
    return;
  }
  const id = r.json.id;
  currentRun = { id, text, runs };
  runState('queued', 0);
  let es = null;
  const finish = async (state) => {
    if (!currentRun || currentRun.id !== id || currentRun.finished) return;
    currentRun.finished = true;
    if (es) es.close(); // the stream would otherwise hold one of the client's stream slots
    // "done" once the results are on the page (verdicts, charts, map, 3D and the comparison).
    if (state === 'done') {
      $('progress').value = 1;
      $('cancel').disabled = true;
      $('run-state').textContent = 'done, loading the results';
      try { await loadResults(id, text, currentRun.files); } finally { runState(state, 1); }
      return;
    }
    runState(state);
    if (state === 'failed' && currentRun.error) $('run-state').textContent = `failed: ${currentRun.error}`;
  };
  const onState = (j) => {
    if (!j || !j.state) return;
    if (['done', 'failed', 'cancelled'].includes(j.state)) {
      currentRun.files = Array.isArray(j.files) ? j.files : null;
      if (j.error) currentRun.error = j.error;
      finish(j.state);
    }
    else if (!currentRun.finished) runState(j.state, typeof j.progress === 'number' ? j.progress : undefined);
  };
  try {
    es = new EventSource(`api/runs/${id}/events`);
    es.onmessage = (ev) => { try { onState(JSON.parse(ev.data)); } catch { /* not JSON */ } };
    for (const name of ['progress', 'state', 'done', 'failed', 'cancelled'])
      es.addEventListener(name, (ev) => { try { onState(JSON.parse(ev.data)); } catch { /* not JSON */ } });
    es.addEventListener('end', () => es.close());
    es.onerror = () => { if (es) es.close(); };
  } catch { es = null; }
  // The state is also polled: events may be lost behind a proxy; the poll settles the end state.
  while (currentRun && currentRun.id === id && !currentRun.finished) {
    await new Promise((res) => setTimeout(res, 500));
    const s = await api('GET', `api/runs/${id}`);
    if (s.ok) onState(s.json);
    else if (s.status === 404) { finish('failed'); break; }
  }
}
async function cancelRun() {
  if (!currentRun) return;
  await api('DELETE', `api/runs/${currentRun.id}`);
}

const resultFiles = ['summary.json', 'nav.csv', 'truth.csv', 'errors.csv', 'mc_stats.csv', 'gnss.csv', 'tracks.kml', 'results.zip'];
// Finished runs fetched from the server, by id (the run shown, A and a few recent ones).
const runCache = new Map();
async function fetchRun(id, text, files) {
  if (runCache.has(id)) return runCache.get(id);
  // Only the files the run has (the state lists them): no request ends in a 404.
  if (!files) {
    const s = await api('GET', `api/runs/${id}`);
    if (!s.ok || !s.json || s.json.state !== 'done') return null;
    files = Array.isArray(s.json.files) ? s.json.files : [];
  }
  const get = async (name) => {
    if (!files.includes(name)) return null;
    const r = await fetch(`api/runs/${id}/files/${name}`);
    return r.ok ? r.text() : null;
  };
  const [summaryText, truthT, navT, errT, mcT, gnssT, sceneT] = await Promise.all(
    ['summary.json', 'truth.csv', 'nav.csv', 'errors.csv', 'mc_stats.csv', 'gnss.csv', text === undefined ? 'scene.yaml' : ''].map(get));
  const sceneText = text ?? sceneT ?? '';
  let summary = null;
  try { summary = summaryText ? JSON.parse(summaryText) : null; } catch { summary = null; }
  const run = {
    id, files, sceneText, summary,
    truth: truthT && parseCsv(truthT), nav: navT && parseCsv(navT), errors: errT && parseCsv(errT),
    mc: mcT && parseCsv(mcT), gnss: gnssT && parseCsv(gnssT),
  };
  runCache.set(id, run);
  // Keep the runs in view and the three most recent others.
  const keep = new Set([id, pinnedA, lastRun && lastRun.id]);
  const others = [...runCache.keys()].filter((k) => !keep.has(k));
  for (const k of others.slice(0, Math.max(0, others.length - 3))) runCache.delete(k);
  return run;
}
async function loadResults(id, text, files) {
  const run = await fetchRun(id, text, files);
  if (!run) { status(`run ${id.slice(0, 8)}… is no longer on the server`); return false; }
  rememberRun(run);
  showRun(run);
  fillRunSelects();
  updateUrl();
  await updateCompare();
  return true;
}
function showRun(run) {
  const { id, summary, truth, nav, errors, mc, gnss } = run;
  const text = run.sceneText;
  lastRun = run;
  studio.lastRun = { id, summary };
  // Verdicts.
  const v = $('verdicts');
  v.textContent = '';
  const reqs = (summary && summary.requirements) || [];
  const h = document.createElement('h2');
  const failed = reqs.filter((r) => r.pass === false).length;
  h.textContent = !summary ? 'No summary.json in the results' : reqs.length === 0 ? 'No requirements in the scene' :
    failed ? `FAIL: ${failed} of ${reqs.length} requirements not met (${summary.runs} runs)` : `PASS: all ${reqs.length} requirements met (${summary.runs} runs)`;
  h.className = failed ? 'fail' : reqs.length ? 'pass' : '';
  v.appendChild(h);
  v.appendChild(Object.assign(document.createElement('p'), { className: 'hint', textContent: `run ${runLabel(run)} (id ${id})` }));
  if (reqs.length) v.appendChild(requirementTable(reqs, false));
  v.dataset.state = !summary ? 'missing' : reqs.length === 0 ? 'none' : failed ? 'fail' : 'pass';
  // Downloads.
  const dl = $('downloads');
  dl.innerHTML = '<h2>Downloads</h2>';
  const ul = document.createElement('ul');
  const sceneLink = document.createElement('a');
  sceneLink.href = URL.createObjectURL(new Blob([text], { type: 'application/yaml' }));
  sceneLink.download = `${sceneName(run)}.yaml`;
  sceneLink.textContent = 'scene YAML (reruns this result bit-identically)';
  ul.appendChild(Object.assign(document.createElement('li'), {})).appendChild(sceneLink);
  const rep = document.createElement('button');
  rep.type = 'button';
  rep.id = 'download-report';
  rep.textContent = 'Download report.html';
  const repLi = document.createElement('li');
  repLi.append(rep, ' ', Object.assign(document.createElement('span'), { className: 'hint',
    textContent: 'one self-contained page made here in the browser: set-up, verdicts, figures, the charts, map and 3D pictures, the comparison with A when one is shown, and the scene to rerun' }));
  ul.appendChild(repLi);
  rep.addEventListener('click', () => downloadReport().catch((err) => { status(`report failed: ${err.message}`); studio.errors.push(String(err)); }));
  const files = run.files;
  for (const name of [...resultFiles, ...files.filter((f) => !resultFiles.includes(f) && f !== 'scene.yaml')]) {
    if (!files.includes(name)) continue;
    const a = document.createElement('a');
    a.href = `api/runs/${id}/files/${name}`;
    a.download = name;
    a.textContent = name;
    ul.appendChild(document.createElement('li')).appendChild(a);
  }
  dl.appendChild(ul);
  // Map: truth, estimate, fixes.
  const origin = runOrigin(run);
  mapView.setReference(truth ? truth.pos_n_m : [], truth ? truth.pos_e_m : [], origin);
  mapView.setEstimate(nav && nav.pos_n_m, nav && nav.pos_e_m, origin);
  mapView.setFixes(gnss && gnss.lon_deg, gnss && gnss.lat_deg);
  mapView.setWaypoints([]);
  mapView.fit();
  // Charts and 3D.
  const outages = (parseYamlSafe(text).gnss || {}).outages || [];
  if (errors) {
    studio.charts = drawCharts($('charts'), { errors, mc_stats: mc }, outages, reqs, chartWidth());
  }
  if (truth) {
    if (!view3d) view3d = new View3D($('three'));
    const sig = mc && mc.pos_h_rms_m && mc.length === truth.length ? mc.pos_h_rms_m : errors && errors.length === truth.length ? errors.pos_err_h_m : null;
    view3d.setData(truth, nav, sig);
    studio.view3d = view3d;
  }
  $('pin-a').disabled = false;
  status(`run ${runLabel(run)} shown`);
}
// The scene origin of a run's local NED coordinates (undefined: the edited scene's).
function runOrigin(run) {
  const o = (parseYamlSafe(run.sceneText).earth || {}).origin || {};
  return Number.isFinite(o.lat_deg) && Number.isFinite(o.lon_deg) ? { lat: o.lat_deg, lon: o.lon_deg, h: Number.isFinite(o.h_m) ? o.h_m : 0 } : undefined;
}
const chartWidth = () => Math.max(320, $('work').clientWidth - 40);
const sceneName = (run) => String(parseYamlSafe(run.sceneText).name || 'scene').replace(/[^A-Za-z0-9._-]+/g, '_');

// ---------------------------------------------------------------- the session's runs, A/B
// The finished runs of this browser (local storage, newest last, at most 12; each checked
// against the server when the page starts) are offered as A and B. The pair compared is in the
// URL fragment (#scene=...&a=ID&b=ID), so a reload or a link shows it again while the server
// still has both runs.
const RUNS_KEY = 'navsim-studio.runs';
let sessionRuns = [];
let pinnedA = null;
function loadSessionRuns() {
  try {
    const j = JSON.parse(localStorage.getItem(RUNS_KEY) || '[]');
    sessionRuns = Array.isArray(j) ? j.filter((r) => r && /^[0-9a-f]{32}$/.test(r.id) && typeof r.label === 'string') : [];
  } catch { sessionRuns = []; }
}
function saveSessionRuns() {
  try { localStorage.setItem(RUNS_KEY, JSON.stringify(sessionRuns.slice(-12))); } catch { /* storage off: this page only */ }
}
function describeRun(run) {
  const sc = parseYamlSafe(run.sceneText);
  const imu = (sc.imu && sc.imu.catalog) || 'typed-in IMU';
  const scheme = (sc.navigation && sc.navigation.scheme) || (run.summary && run.summary.setup && run.summary.setup.scheme) || '';
  const runs = run.summary ? run.summary.runs : (sc.simulation || {}).runs;
  return `${sc.name || 'scene'} · ${imu} · ${scheme} · ${runs} runs`;
}
function rememberRun(run) {
  let e = sessionRuns.find((r) => r.id === run.id);
  if (!e) {
    const n = sessionRuns.reduce((m, r) => Math.max(m, r.n || 0), 0) + 1;
    e = { id: run.id, n, label: describeRun(run), at: new Date().toISOString().slice(11, 19) };
    sessionRuns.push(e);
    while (sessionRuns.length > 12) sessionRuns.shift();
    saveSessionRuns();
  }
  run.entry = e;
  fillRunSelects();
}
const runLabel = (run) => (run.entry ? `#${run.entry.n} ${run.entry.label}` : run.id.slice(0, 8));
function fillRunSelects() {
  $('pin-a').setAttribute('aria-pressed', String(!!(pinnedA && lastRun && pinnedA === lastRun.id)));
  $('pin-a').textContent = pinnedA && lastRun && pinnedA === lastRun.id ? 'Pinned as A' : 'Pin result as A';
  const opts = sessionRuns.map((r) => [r.id, `#${r.n} ${r.label} (${r.at} UTC)`]);
  const fill = (sel, cur, none) => {
    sel.textContent = '';
    for (const [v, t] of [['', none], ...[...opts].reverse()]) sel.appendChild(Object.assign(document.createElement('option'), { value: v, textContent: t }));
    sel.value = cur && opts.some(([v]) => v === cur) ? cur : '';
  };
  fill($('compare-a'), pinnedA, '(none: pin a run as A)');
  fill($('compare-b'), lastRun && lastRun.id, '(no run shown)');
}
function updateUrl() {
  let h = '#scene=' + b64(scene.text());
  if (pinnedA) h += `&a=${pinnedA}`;
  if (lastRun) h += `&b=${lastRun.id}`;
  history.replaceState(null, '', h);
}
async function pinA(id) {
  pinnedA = id || null;
  fillRunSelects();
  updateUrl();
  if (pinnedA && (!lastRun || lastRun.id === pinnedA)) {
    const e = sessionRuns.find((r) => r.id === pinnedA);
    status(`run #${e ? e.n : '?'} pinned as A: change the scene (another IMU, say) and run B`);
  }
  await updateCompare();
}
let compareRuns = null;
async function updateCompare() {
  const host = $('compare');
  const B = lastRun;
  const A = pinnedA && B && pinnedA !== B.id ? await fetchRun(pinnedA) : null;
  if (pinnedA && B && pinnedA !== B.id && !A) {
    status('run A is no longer on the server');
    sessionRuns = sessionRuns.filter((r) => r.id !== pinnedA);
    saveSessionRuns();
    pinnedA = null;
    fillRunSelects();
    updateUrl();
  }
  if (!A || !B) {
    compareRuns = null;
    host.dataset.state = 'none';
    $('compare-body').innerHTML = '<p class="hint">Pin a finished run as A (the button next to Run), change the scene and run it: the run shown is B. Or pick any two of this browser\'s finished runs above.</p>';
    mapView.setCompare(null);
    if (view3d) view3d.setCompare(null);
    $('map-legend-a').hidden = true;
    $('three-legend-a').hidden = true;
    for (const id of ['map-legend-a-far', 'three-legend-a-far']) $(id).textContent = '';
    return;
  }
  if (!A.entry) A.entry = sessionRuns.find((r) => r.id === A.id);
  compareRuns = { A, B };
  const body = $('compare-body');
  body.textContent = '';
  const head = document.createElement('p');
  head.className = 'ab-head';
  for (const [k, r] of [['A', A], ['B', B]]) {
    const sp = document.createElement('span');
    sp.className = `ab-${k}`;
    sp.textContent = `${k}: ${runLabel(r)}`;
    head.appendChild(sp);
  }
  body.appendChild(head);
  // The scene keys that differ.
  const sa = parseYamlSafe(A.sceneText), sb = parseYamlSafe(B.sceneText);
  const diff = sceneDiff(sa, sb);
  const h3 = (t) => Object.assign(document.createElement('h3'), { textContent: t });
  body.appendChild(h3(diff.length ? `Set-up: ${diff.length} scene key${diff.length > 1 ? 's differ' : ' differs'}` : 'Set-up: the two scenes are the same'));
  if (diff.length) body.appendChild(diffTable(diff, 'scene key', 'compare-diff'));
  const md = modelDiff(A.summary, B.summary);
  if (md.length) {
    const d = document.createElement('details');
    d.appendChild(Object.assign(document.createElement('summary'), { textContent: `The sensor models as simulated: ${md.length} term${md.length > 1 ? 's differ' : ' differs'}` }));
    d.appendChild(diffTable(md, 'model term', 'compare-model-diff'));
    body.appendChild(d);
  }
  body.appendChild(h3('Verdicts and figures'));
  body.appendChild(verdictTable(verdictRows(A.summary, B.summary)));
  body.appendChild(h3('Errors of A and B'));
  const charts = document.createElement('div');
  charts.id = 'compare-charts';
  body.appendChild(charts);
  const runOf = (r) => ({
    label: `#${r.entry ? r.entry.n : '?'}`, runs: r.summary ? r.summary.runs : '?', errors: r.errors, mc_stats: r.mc,
    outages: (parseYamlSafe(r.sceneText).gnss || {}).outages || [], requirements: (r.summary && r.summary.requirements) || [],
  });
  studio.compareCharts = A.errors && B.errors ? drawCompareCharts(charts, { A: runOf(A), B: runOf(B) }, chartWidth()) : [];
  // Both paths on the map and in 3D: A's estimate (and A's reference when it is another).
  const sameRef = A.truth && B.truth && same(runOrigin(A), runOrigin(B)) && A.truth.length === B.truth.length && A.truth.pos_n_m.every((v, i) => Math.abs(v - B.truth.pos_n_m[i]) < 1e-3 && Math.abs(A.truth.pos_e_m[i] - B.truth.pos_e_m[i]) < 1e-3);
  const originA = runOrigin(A) || null;
  mapView.setCompare(originA, A.truth && !sameRef ? A.truth.pos_n_m : null, A.truth && !sameRef ? A.truth.pos_e_m : null, A.nav && A.nav.pos_n_m, A.nav && A.nav.pos_e_m);
  $('map-legend-a').hidden = false;
  $('three-legend-a').hidden = false;
  // Another scene origin: A's local metres are not B's; the 3D view takes them to B's frame
  // through the two geodetic origins (geo.js, exact through ECEF; the map draws each run about
  // its own origin), and the legends say how far A's origin is from B's.
  const originB = runOrigin(B) || null;
  const away = originA && originB && !same(originA, originB) ? originDistance(originA, originB) : 0;
  const farText = originA && originB && !same(originA, originB) ? ` (A is ${formatDistance(away)} from B's origin)` : '';
  for (const id of ['map-legend-a-far', 'three-legend-a-far']) $(id).textContent = farText;
  studio.compareOriginDistance = away;
  if (view3d && A.truth && A.nav) view3d.setCompare(A.truth, A.nav, nedFrameChange(originA, originB));
  host.dataset.state = 'ready';
  studio.compare = { a: A.id, b: B.id, diff: diff.map((d) => d.path) };
}
function diffTable(diff, what, id) {
  const t = document.createElement('table');
  t.id = id;
  t.innerHTML = `<thead><tr><th>${what}</th><th>A</th><th>B</th></tr></thead>`;
  const tb = document.createElement('tbody');
  for (const d of diff) {
    const tr = document.createElement('tr');
    for (const [txt, cls] of [[d.path, 'key'], [formatValue(d.a), 'ab-A'], [formatValue(d.b), 'ab-B']])
      tr.appendChild(Object.assign(document.createElement('td'), { textContent: txt, className: cls }));
    tb.appendChild(tr);
  }
  t.appendChild(tb);
  return t;
}
function verdictTable(rows) {
  const t = document.createElement('table');
  t.id = 'compare-verdicts';
  t.innerHTML = '<thead><tr><th>requirement or figure</th><th>statistic</th><th>limit</th><th>A</th><th>B</th><th>B vs A</th></tr></thead>';
  const tb = document.createElement('tbody');
  for (const r of rows) {
    const tr = document.createElement('tr');
    tr.className = `row-${r.kind}`;
    const cell = (v, pass) => {
      const td = document.createElement('td');
      td.textContent = `${fmtNum(v)}${typeof v === 'number' && r.unit ? ' ' + r.unit : ''}`;
      if (pass !== undefined && verdictText(pass)) {
        td.append(' ', Object.assign(document.createElement('span'), { className: pass ? 'pass' : 'fail', textContent: verdictText(pass) }));
      }
      return td;
    };
    tr.appendChild(Object.assign(document.createElement('td'), { textContent: r.label, className: r.kind === 'outage' ? 'sub' : '' }));
    tr.appendChild(Object.assign(document.createElement('td'), { textContent: r.statistic }));
    tr.appendChild(Object.assign(document.createElement('td'), { textContent: r.limit !== undefined ? `${r.limit} ${r.unit}` : '' }));
    tr.appendChild(cell(r.a, r.passA));
    tr.appendChild(cell(r.b, r.passB));
    tr.appendChild(Object.assign(document.createElement('td'), { textContent: r.label === 'Monte Carlo runs' ? '' : change(r.a, r.b) }));
    tb.appendChild(tr);
  }
  t.appendChild(tb);
  return t;
}

// ---------------------------------------------------------------- report.html
// Made here in the browser from what the page shows: the server cannot draw (navsim report needs
// an X server), the browser already has every picture.
async function downloadReport() {
  const run = lastRun;
  if (!run) return;
  status('making report.html …');
  const pictures = { charts: [], compare: [] };
  for (const u of studio.charts || []) pictures.charts.push(chartPng(u));
  if (compareRuns && compareRuns.B === run) for (const u of studio.compareCharts || []) pictures.compare.push(chartPng(u));
  pictures.map = await mapPicture();
  if (view3d) { view3d.render(); pictures.three = view3d.renderer.domElement.toDataURL('image/png'); }
  const html = buildReport({
    run, sceneObj: parseYamlSafe(run.sceneText), label: runLabel(run), pictures, exaggeration: view3d ? view3d.exaggeration : null,
    compare: compareRuns && compareRuns.B === run ? { A: compareRuns.A, labelA: runLabel(compareRuns.A), diff: sceneDiff(parseYamlSafe(compareRuns.A.sceneText), parseYamlSafe(run.sceneText)), modelDiff: modelDiff(compareRuns.A.summary, run.summary), rows: verdictRows(compareRuns.A.summary, run.summary) } : null,
    made: new Date().toISOString().replace(/\.\d+Z$/, 'Z'),
  });
  const a = document.createElement('a');
  a.href = URL.createObjectURL(new Blob([html], { type: 'text/html' }));
  a.download = `${sceneName(run)}-${run.id.slice(0, 8)}-report.html`;
  document.body.appendChild(a);
  a.click();
  a.remove();
  studio.reportBytes = html.length;
  status(`report.html of run ${runLabel(run)}: ${(html.length / 1024).toFixed(0)} KiB`);
}
// The map as the page draws it (its layer canvases composed); a hidden map panel is laid out
// off-screen for the picture and hidden again.
async function mapPicture() {
  const panel = $('view-map');
  const hidden = panel.hidden;
  if (hidden) { panel.classList.add('offscreen'); panel.hidden = false; mapView.map.updateSize(); mapView.fit(); }
  try {
    const rendered = mapView.whenRendered();
    mapView.map.render();
    await Promise.race([rendered, sleep(4000)]);
    const size = mapView.map.getSize();
    if (!size || !size[0] || !size[1]) return null;
    const out = document.createElement('canvas');
    out.width = size[0];
    out.height = size[1];
    const ctx = out.getContext('2d');
    ctx.fillStyle = '#cfe0ef';
    ctx.fillRect(0, 0, out.width, out.height);
    for (const c of $('map').querySelectorAll('.ol-layer canvas, canvas.ol-layer')) {
      if (!c.width) continue;
      const op = c.parentNode.style.opacity || c.style.opacity;
      ctx.globalAlpha = op === '' ? 1 : +op;
      const m = (c.style.transform || '').match(/^matrix\(([^(]*)\)$/);
      if (m) ctx.setTransform(...m[1].split(',').map(Number));
      else ctx.setTransform(out.width / c.width, 0, 0, out.height / c.height, 0, 0);
      ctx.drawImage(c, 0, 0);
    }
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.globalAlpha = 1;
    return out.toDataURL('image/png');
  } finally {
    if (hidden) { panel.hidden = true; panel.classList.remove('offscreen'); mapView.map.updateSize(); }
  }
}
const same = (a, b) => JSON.stringify(a) === JSON.stringify(b);
function parseYamlSafe(t) { try { return YAML.parse(t) || {}; } catch { return {}; } }

// ---------------------------------------------------------------- tabs
const tabs = [...document.querySelectorAll('[role=tab]')];
function selectTab(tab) {
  for (const t of tabs) {
    const on = t === tab;
    t.setAttribute('aria-selected', String(on));
    t.tabIndex = on ? 0 : -1;
    $(t.getAttribute('aria-controls')).hidden = !on;
  }
  if (tab.id === 'tab-3d' && view3d) view3d.resize();
  if (tab.id === 'tab-map') mapView.map.updateSize();
  if (tab.id === 'tab-charts' && studio.charts) for (const c of studio.charts) c.setSize({ width: chartWidth(), height: 220 });
  if (tab.id === 'tab-compare' && studio.compareCharts) for (const c of studio.compareCharts) c.setSize({ width: chartWidth(), height: 220 });
}
tabs.forEach((t, i) => {
  t.tabIndex = t.getAttribute('aria-selected') === 'true' ? 0 : -1;
  t.addEventListener('click', () => selectTab(t));
  t.addEventListener('keydown', (ev) => {
    const d = ev.key === 'ArrowRight' ? 1 : ev.key === 'ArrowLeft' ? -1 : 0;
    if (!d) return;
    const next = tabs[(i + d + tabs.length) % tabs.length];
    next.focus();
    selectTab(next);
  });
});

// ---------------------------------------------------------------- loading scenes
async function loadText(text, label) {
  try {
    scene.load(text);
  } catch (err) {
    $('yaml').value = text;
    status(`${label}: ${err.message}`);
    return false;
  }
  lastRun = null; // the views keep the last run's results until the next run (or a pick as B)
  $('pin-a').disabled = true;
  fillRunSelects();
  drawnThisSession = 0;
  $('yaml').value = scene.text();
  const runs = scene.get(['simulation', 'runs']);
  if (Number.isFinite(runs)) $('runs').value = runs;
  changed('load', true);
  mapView.fit();
  if (studio.timings.sceneLoadStart !== undefined) {
    mapView.whenRendered().then(() => { studio.timings.preview_ms = performance.now() - studio.timings.sceneLoadStart; });
    mapView.map.render();
  }
  status(`${label} loaded`);
  return true;
}
async function loadLibrary(name) {
  studio.timings = { sceneLoadStart: performance.now() };
  const r = await fetch(`api/scenes/${encodeURIComponent(name)}`);
  if (!r.ok) { status(`scene ${name}: HTTP ${r.status}`); return; }
  await loadText(await r.text(), `library scene ${name}`);
}
// GPX tracks: their points become waypoints around the first one.
function gpxToWaypoints(text) {
  const xml = new DOMParser().parseFromString(text, 'application/xml');
  const pts = [...xml.querySelectorAll('trkpt, rtept, wpt')].map((p) => [+p.getAttribute('lon'), +p.getAttribute('lat')]);
  const kml = [...xml.getElementsByTagName('coordinates')].flatMap((c) => c.textContent.trim().split(/\s+/).map((s) => s.split(',').map(Number)));
  return pts.length ? pts : kml.filter((p) => p.length >= 2).map((p) => [p[0], p[1]]);
}

// ---------------------------------------------------------------- wiring
$('library').addEventListener('change', () => { if ($('library').value) loadLibrary($('library').value); });
$('open-file').addEventListener('change', async () => {
  const f = $('open-file').files[0];
  if (!f) return;
  const text = await f.text();
  if (/\.(gpx|kml)$/i.test(f.name)) {
    const ll = gpxToWaypoints(text).filter((p) => Number.isFinite(p[0]) && Number.isFinite(p[1]));
    if (ll.length < 2) { status(`${f.name}: no track points found`); return; }
    const step = Math.max(1, Math.ceil(ll.length / 200));
    scene.set(['earth', 'origin'], { lat_deg: ll[0][1], lon_deg: ll[0][0], h_m: 0 });
    mapView.setOrigin(ll[0][1], ll[0][0]);
    drawnThisSession = 0;
    for (let i = 0; i < ll.length; i += step) addWaypoint(ll[i][0], ll[i][1]);
    mapView.fit();
    status(`${f.name}: ${Math.ceil(ll.length / step)} waypoints`);
  } else await loadText(text, f.name);
});
$('download-scene').addEventListener('click', () => {
  const a = document.createElement('a');
  a.href = URL.createObjectURL(new Blob([scene.text()], { type: 'application/yaml' }));
  a.download = `${scene.get(['name']) || 'scene'}.yaml`;
  document.body.appendChild(a);
  a.click();
  a.remove();
});
$('scheme').addEventListener('change', () => {
  const s = $('scheme').value;
  scene.set(['navigation', 'scheme'], s);
  if (/gyro_free/.test(s) && scene.get(['array']) === undefined && schema) {
    const a = schemaAt(schema, ['array'], scene);
    if (a) scene.set(['array'], newItem(schema, a));
  }
  if (!/gyro_free/.test(s)) scene.del(['array']);
  if (/gnss/.test(s)) scene.set(['gnss', 'enabled'], true);
  else if (scene.get(['gnss']) !== undefined) scene.set(['gnss', 'enabled'], false);
  changed('flow', true);
});
$('imu-catalog').addEventListener('change', () => {
  const v = $('imu-catalog').value;
  if (v) scene.set(['imu', 'catalog'], v); else scene.del(['imu', 'catalog']);
  changed('flow', true);
});
$('gnss-catalog').addEventListener('change', () => {
  const v = $('gnss-catalog').value;
  if (v) scene.set(['gnss', 'catalog'], v); else scene.del(['gnss', 'catalog']);
  changed('flow', true);
});
$('gnss-enabled').addEventListener('change', () => { scene.set(['gnss', 'enabled'], $('gnss-enabled').checked); changed('flow', true); });
$('traj-type').addEventListener('change', () => { setTrajectoryType($('traj-type').value); changed('flow', true); mapView.fit(); });
$('draw-waypoints').addEventListener('click', () => {
  drawing = !drawing;
  drawnThisSession = 0;
  $('draw-waypoints').setAttribute('aria-pressed', String(drawing));
  $('draw-waypoints').textContent = drawing ? 'Stop drawing' : 'Draw waypoints';
  document.body.classList.toggle('ol-waypoint-mode', drawing);
  mapView.onClick = drawing ? addWaypoint : null;
  if (drawing) status('click on the map to place waypoints (they replace the current ones)');
  else mapView.fit();
});
$('add-centre').addEventListener('click', () => { const [lon, lat] = mapView.centre(); if (!drawing) drawnThisSession = waypoints().length; addWaypoint(lon, lat); });
$('undo-waypoint').addEventListener('click', () => {
  const pts = scene.get(['trajectory', 'waypoints', 'points']) || [];
  if (pts.length) { pts.pop(); if (pts.length) pts[pts.length - 1].speed_mps = 0; scene.set(['trajectory', 'waypoints', 'points'], pts); changed('flow', true); }
});
$('add-outage').addEventListener('click', () => {
  const a = +$('outage-start').value, len = +$('outage-length').value;
  if (!(a >= 0 && len > 0)) { status('an outage needs a start >= 0 s and a length > 0 s'); return; }
  const outs = scene.get(['gnss', 'outages']) || [];
  outs.push([a, a + len]);
  outs.sort((x, y) => x[0] - y[0]);
  scene.set(['gnss', 'outages'], outs);
  changed('flow', true);
});
$('clear-outages').addEventListener('click', () => { scene.del(['gnss', 'outages']); changed('flow', true); });
$('yaml').addEventListener('input', () => {
  try {
    scene.load($('yaml').value);
  } catch (err) {
    ++sceneGen; // an answer still on its way is for the text before this edit
    clearTimeout(pendingCheck);
    $('yaml-status').className = 'bad';
    $('yaml-status').textContent = `YAML: ${err.message}`;
    $('estimate').dataset.state = 'invalid';
    return;
  }
  changed('yaml', true);
});
$('run').addEventListener('click', startRun);
$('pin-a').addEventListener('click', () => { if (lastRun) pinA(pinnedA === lastRun.id ? null : lastRun.id); });
$('compare-a').addEventListener('change', () => pinA($('compare-a').value));
$('compare-b').addEventListener('change', async () => {
  const id = $('compare-b').value;
  if (id && (!lastRun || id !== lastRun.id)) await loadResults(id);
});
$('cancel').addEventListener('click', cancelRun);
$('runs').addEventListener('change', () => {
  const n = Math.round(+$('runs').value);
  if (n >= 1) { scene.set(['simulation', 'runs'], n); changed('flow', true); }
});
$('exaggeration').addEventListener('input', () => {
  const k = +$('exaggeration').value;
  $('exaggeration-out').textContent = `${k}×`;
  if (view3d) view3d.setExaggeration(k);
});
window.addEventListener('resize', () => { mapView.map.updateSize(); if (view3d && !$('view-3d').hidden) view3d.resize(); });

// ---------------------------------------------------------------- start
async function start() {
  const [sc, sl, ci, cg] = await Promise.all([api('GET', 'api/schema'), api('GET', 'api/scenes'), api('GET', 'api/catalog/imu'), api('GET', 'api/catalog/gnss')]);
  if (sc.ok && sc.json) schema = sc.json;
  else status(`no scene schema from the server (HTTP ${sc.status}): forms are off, the YAML view works`);
  const arr = (j, k) => (Array.isArray(j) ? j : j && Array.isArray(j[k]) ? j[k] : []);
  catalogs = { imu: ci.ok ? arr(ci.json, 'imu') : [], gnss: cg.ok ? arr(cg.json, 'gnss') : [] };
  const scenes = sl.ok ? arr(sl.json, 'scenes') : [];
  fillSelect($('library'), ['', ...scenes.map((s) => s.name)], '', Object.fromEntries([['', '(choose a scene)'], ...scenes.map((s) => [s.name, s.description ? `${s.name} — ${s.description.slice(0, 60)}` : s.name])]));
  const m = location.hash.match(/#scene=([A-Za-z0-9_-]+)/);
  const runA = (location.hash.match(/[#&]a=([0-9a-f]{32})\b/) || [])[1];
  const runB = (location.hash.match(/[#&]b=([0-9a-f]{32})\b/) || [])[1];
  loadSessionRuns();
  fillRunSelects();
  if (m) await loadText(unb64(m[1]), 'scene from the URL');
  else if (scenes.some((s) => s.name === 'urban-drive')) { $('library').value = 'urban-drive'; await loadLibrary('urban-drive'); }
  else if (scenes.length) { $('library').value = scenes[0].name; await loadLibrary(scenes[0].name); }
  document.body.dataset.ready = '1';
  // The runs of the URL (the one shown and A), then the check of this browser's other runs.
  if (runB) {
    pinnedA = runA || null;
    const ok = await loadResults(runB);
    if (!ok) { pinnedA = null; updateUrl(); }
  } else if (runA) await pinA(runA);
  await checkSessionRuns();
}
// Runs this browser remembers that the server no longer has (expired) are dropped.
async function checkSessionRuns() {
  const known = new Set([pinnedA, lastRun && lastRun.id]);
  const gone = [];
  for (const r of sessionRuns.filter((x) => !known.has(x.id))) {
    const s = await api('GET', `api/runs/${r.id}`);
    if (s.status === 404 || (s.ok && s.json && s.json.state !== 'done')) gone.push(r.id);
  }
  if (gone.length) {
    sessionRuns = sessionRuns.filter((r) => !gone.includes(r.id));
    saveSessionRuns();
    fillRunSelects();
  }
}
window.addEventListener('error', (e) => studio.errors.push(String(e.message)));
start().catch((err) => { status(`start failed: ${err.message}`); studio.errors.push(String(err)); });
void deref;
