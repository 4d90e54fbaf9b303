// A/B comparison of two finished runs: the key-level difference of their scenes, and their
// verdicts and figures side by side. Pure functions of the runs' scene text and summary.json;
// main.js draws the charts, the map and the 3D view.
import YAML from 'yaml';

const isMap = (x) => x !== null && typeof x === 'object' && !Array.isArray(x);
const same = (a, b) => JSON.stringify(a) === JSON.stringify(b);

// The keys whose values differ between two parsed scenes: [{path: 'imu.catalog', a, b}], a or b
// undefined where the key is missing. Mappings are compared key by key; lists of mappings of the
// same length item by item (trajectory.waypoints.points[3].speed_mps); any other value (vectors,
// outage lists, lists of another length) as a whole.
export function sceneDiff(a, b, path = '', out = []) {
  if (isMap(a) && isMap(b)) {
    const keys = [...Object.keys(a), ...Object.keys(b).filter((k) => !(k in a))];
    for (const k of keys) sceneDiff(a[k], b[k], path ? `${path}.${k}` : k, out);
  } else if (Array.isArray(a) && Array.isArray(b) && a.length === b.length && a.some(isMap)) {
    a.forEach((x, i) => sceneDiff(x, b[i], `${path}[${i}]`, out));
  } else if (!same(a, b)) {
    out.push({ path, a, b });
  }
  return out;
}

// The model navsim simulated (summary.json setup.*.model_yaml: the catalog part with the scene's
// overrides) as an object, for the difference of what was simulated, not only what was written.
function modelOf(lines) {
  if (!Array.isArray(lines)) return undefined;
  try { return YAML.parse(lines.join('\n')) || undefined; } catch { return undefined; }
}
export function modelDiff(sa, sb) {
  const out = [];
  for (const k of ['imu', 'receiver']) {
    const a = modelOf(sa?.setup?.[k]?.model_yaml), b = modelOf(sb?.setup?.[k]?.model_yaml);
    if (a === undefined && b === undefined) continue;
    sceneDiff(a ?? {}, b ?? {}, '', out);
  }
  // Derived terms (unit conversions of the catalog's figures) to six significant digits.
  const round = (v) => (typeof v === 'number' && !Number.isInteger(v) ? +v.toPrecision(6) : v);
  return out.map((d) => ({ ...d, a: round(d.a), b: round(d.b) }));
}

export function formatValue(v) {
  if (v === undefined) return '(not set)';
  if (v === null) return 'null';
  if (typeof v === 'string') return v;
  if (Array.isArray(v) && v.length > 6 && v.every(isMap)) return `${v.length} items`;
  const s = JSON.stringify(v).replace(/"([^"]+)":/g, '$1: ').replace(/,/g, ', ');
  return s.length > 90 ? s.slice(0, 87) + '…' : s;
}

// Rows of the side-by-side verdict table: every requirement of either run (matched by id and
// statistic), the end of each outage of an outage_end requirement, then the figures every
// summary.json has. {label, unit, a, b, limit, passA, passB, kind: 'req'|'outage'|'figure'}.
export function verdictRows(sa, sb) {
  const rows = [];
  const reqs = (s) => (s && Array.isArray(s.requirements) ? s.requirements : []);
  const key = (r) => `${r.id}\u0000${r.statistic}`;
  const ra = new Map(reqs(sa).map((r) => [key(r), r])), rb = new Map(reqs(sb).map((r) => [key(r), r]));
  for (const k of [...ra.keys(), ...[...rb.keys()].filter((x) => !ra.has(x))]) {
    const a = ra.get(k), b = rb.get(k), r = a || b;
    const limits = [a?.limit, b?.limit].filter((x) => x !== undefined);
    rows.push({
      kind: 'req', label: r.id, statistic: r.statistic + (r.time_s !== undefined ? ` @ ${r.time_s} s` : ''), unit: r.unit || '',
      limit: limits.length === 2 && limits[0] !== limits[1] ? `${limits[0]} / ${limits[1]}` : limits[0],
      a: a?.value, b: b?.value, passA: a?.pass, passB: b?.pass,
    });
    if (r.statistic === 'outage_end') {
      const oa = a?.outages || [], ob = b?.outages || [];
      const spans = [...oa, ...ob.filter((o) => !oa.some((x) => x.t0_s === o.t0_s && x.t1_s === o.t1_s))];
      for (const o of spans) {
        const va = oa.find((x) => x.t0_s === o.t0_s && x.t1_s === o.t1_s), vb = ob.find((x) => x.t0_s === o.t0_s && x.t1_s === o.t1_s);
        rows.push({ kind: 'outage', label: `end of the outage ${o.t0_s}–${o.t1_s} s`, statistic: '', unit: r.unit || '', a: va?.value, b: vb?.value, limit: r.limit });
      }
    }
  }
  const fig = (label, unit, f, scale = 1) => {
    const g = (s) => { try { const v = f(s); return typeof v === 'number' ? v * scale : undefined; } catch { return undefined; } };
    const a = g(sa), b = g(sb);
    if (a !== undefined || b !== undefined) rows.push({ kind: 'figure', label, statistic: '', unit, a, b });
  };
  const deg = 180 / Math.PI;
  fig('horizontal error at the end, RMS over the runs', 'm', (s) => s.final_rms_over_runs.pos_err_h_m);
  fig('vertical error at the end, RMS over the runs', 'm', (s) => s.final_rms_over_runs.pos_err_v_m);
  fig('horizontal error, RMS over time and runs', 'm', (s) => s.stats.pos_err_h_m.rms);
  fig('horizontal error, 95th percentile', 'm', (s) => s.stats.pos_err_h_m.p95);
  fig('horizontal error, maximum', 'm', (s) => s.stats.pos_err_h_m.max);
  fig('velocity error, RMS', 'm/s', (s) => s.stats.vel_err_mps.rms);
  fig('attitude error, RMS', 'deg', (s) => s.stats.att_err_rad.rms, deg);
  fig('Monte Carlo runs', '', (s) => s.runs);
  return rows;
}

export const fmtNum = (v) => (typeof v === 'number' ? (Number.isInteger(v) && Math.abs(v) < 1e6 ? String(v) : v.toPrecision(4)) : '—');
export const verdictText = (p) => (p === true ? 'PASS' : p === false ? 'FAIL' : '');

// B relative to A: "−37 %" (lower is better for every row but the run count).
export function change(a, b) {
  if (typeof a !== 'number' || typeof b !== 'number') return '';
  if (a === b) return 'same';
  if (a === 0) return b > 0 ? 'up' : 'down';
  const pct = ((b - a) / Math.abs(a)) * 100;
  return `${pct > 0 ? '+' : '−'}${Math.abs(pct) < 10 ? Math.abs(pct).toFixed(1) : Math.abs(pct).toFixed(0)} %`;
}
