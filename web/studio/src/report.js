// report.html of a run, made in the browser: one self-contained page (no script, no request:
// the pictures are PNG data URLs) with the set-up from summary.json, the verdicts, the figures,
// the error charts, the map and the 3D view as the page drew them, the comparison with run A
// when one is shown, and the scene YAML (embedded as text and as a data-URL download) so that the
// report reruns: `navsim run scene.yaml` gives the same results bit for bit.
import { fmtNum, verdictText, change, formatValue } from './compare.js';

const esc = (s) => String(s ?? '').replace(/[&<>"']/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;', "'": '&#39;' }[c]));
const b64 = (s) => btoa(String.fromCharCode(...new TextEncoder().encode(s)));
const row = (cells, tag = 'td') => `<tr>${cells.map((c) => `<${tag}>${c}</${tag}>`).join('')}</tr>`;
// A picture; the caption is shown unless the picture carries its own title (the charts).
const figure = (src, caption, shown = true) => (src ? `<figure><img src="${src}" alt="${esc(caption)}">${shown ? `<figcaption>${esc(caption)}</figcaption>` : ''}</figure>` : '');

function verdictTable(reqs) {
  if (!reqs.length) return '<p>The scene states no requirements.</p>';
  const body = reqs.map((r) => {
    const v = verdictText(r.pass) || 'n/a';
    let out = row([esc(r.id), esc(r.metric), esc(r.statistic + (r.time_s !== undefined ? ` @ ${r.time_s} s` : '')),
      `${fmtNum(r.value)} ${esc(r.unit || '')}`, `${esc(r.limit)} ${esc(r.unit || '')}`, `<span class="${v === 'PASS' ? 'pass' : v === 'FAIL' ? 'fail' : ''}">${v}</span>`]);
    for (const o of r.outages || [])
      out += row(['', '', `end of the outage ${o.t0_s}–${o.t1_s} s (at ${fmtNum(o.t_s)} s)`, `${fmtNum(o.value)} ${esc(r.unit || '')}`, '', '']);
    return out;
  }).join('');
  return `<table class="verdicts"><thead>${row(['requirement', 'metric', 'statistic', 'value', 'limit', 'verdict'], 'th')}</thead><tbody>${body}</tbody></table>`;
}

function setupTable(s, sceneObj) {
  const st = s.setup || {};
  const rows = [
    ['scene', `${esc(s.scene && s.scene.name)}`],
    ['navigation scheme', esc(st.scheme)],
    ['trajectory', `${esc(s.trajectory)}, ${fmtNum(s.duration_s)} s`],
    ['IMU', `${esc((st.imu && st.imu.catalog) || 'typed in')}, ${fmtNum(s.imu_rate_hz)} Hz`],
    ['GNSS receiver', st.receiver ? esc(st.receiver.catalog || st.receiver.source || 'typed in') : 'none'],
    ['GNSS outages', st.outages_s && st.outages_s.length ? esc(st.outages_s.map(([a, b]) => `${a}–${b} s`).join(', ')) : 'none'],
    ['lever arm (body, m)', st.lever_arm_b_m ? esc(st.lever_arm_b_m.join(', ')) : '—'],
    ['Earth, gravity', `${esc(s.earth_model)}, ${esc(s.gravity_model)}`],
    ['algorithm, frame', `${esc(s.algorithm)}, ${esc(s.mechanization_frame)}`],
    ['Monte Carlo runs, seed', `${fmtNum(s.runs)}, ${fmtNum(s.seed)}`],
    ['output rate', `${fmtNum(s.output_rate_hz)} Hz`],
  ];
  if (sceneObj && sceneObj.initial_errors) rows.push(['initial errors', esc(formatValue(sceneObj.initial_errors))]);
  let html = `<table class="setup"><tbody>${rows.map(([k, v]) => row([esc(k), v])).join('')}</tbody></table>`;
  for (const [k, what] of [['imu', 'The IMU model as simulated'], ['receiver', 'The receiver model as simulated']])
    if (st[k] && Array.isArray(st[k].model_yaml)) html += `<h3>${what}</h3><pre>${esc(st[k].model_yaml.join('\n'))}</pre>`;
  return html;
}

function figuresTable(s) {
  const deg = 180 / Math.PI;
  const f = s.final || {}, fr = s.final_rms_over_runs || {}, st = s.stats || {};
  const q = [
    ['horizontal position [m]', f.pos_err_h_m, fr.pos_err_h_m, st.pos_err_h_m],
    ['vertical position [m]', f.pos_err_v_m, fr.pos_err_v_m, st.pos_err_v_m],
    ['velocity [m/s]', f.vel_err_mps, fr.vel_err_mps, st.vel_err_mps],
    ['attitude [deg]', f.att_err_rad * deg, fr.att_err_rad * deg, st.att_err_rad && { rms: st.att_err_rad.rms * deg, p95: st.att_err_rad.p95 * deg, max: st.att_err_rad.max * deg }],
  ];
  return `<table class="figures"><thead>${row(['error', 'at the end, run 1', 'at the end, RMS over runs', 'RMS', '95th percentile', 'maximum'], 'th')}</thead><tbody>` +
    q.map(([k, a, b, c]) => row([esc(k), fmtNum(a), fmtNum(b), fmtNum(c && c.rms), fmtNum(c && c.p95), fmtNum(c && c.max)])).join('') + '</tbody></table>';
}

function compareSection(c, label, charts) {
  const diff = c.diff.length
    ? `<table class="diff"><thead>${row(['scene key', 'A', 'B (this run)'], 'th')}</thead><tbody>${c.diff.map((d) => row([`<code>${esc(d.path)}</code>`, esc(formatValue(d.a)), esc(formatValue(d.b))])).join('')}</tbody></table>`
    : '<p>The two scenes are the same.</p>';
  const md = c.modelDiff.length
    ? `<h3>The sensor models as simulated</h3><table class="diff"><thead>${row(['model term', 'A', 'B'], 'th')}</thead><tbody>${c.modelDiff.map((d) => row([`<code>${esc(d.path)}</code>`, esc(formatValue(d.a)), esc(formatValue(d.b))])).join('')}</tbody></table>` : '';
  const vr = c.rows.map((r) => {
    const cell = (v, p) => `${fmtNum(v)}${typeof v === 'number' && r.unit ? ' ' + esc(r.unit) : ''}${verdictText(p) ? ` <span class="${p ? 'pass' : 'fail'}">${verdictText(p)}</span>` : ''}`;
    return row([esc(r.label), esc(r.statistic), r.limit !== undefined ? `${esc(r.limit)} ${esc(r.unit)}` : '', cell(r.a, r.passA), cell(r.b, r.passB), r.label === 'Monte Carlo runs' ? '' : esc(change(r.a, r.b))]);
  }).join('');
  return `<h2>Comparison with run A</h2><p>A: ${esc(c.labelA)} (id <code>${esc(c.A.id)}</code>)<br>B: ${esc(label)} (this report's run)</p>` +
    `<h3>Set-up differences</h3>${diff}${md}` +
    `<h3>Verdicts and figures</h3><table class="ab"><thead>${row(['requirement or figure', 'statistic', 'limit', 'A', 'B', 'B vs A'], 'th')}</thead><tbody>${vr}</tbody></table>` +
    '<p>A solid blue, B dashed orange; grey spans: GNSS outages; dashed red: the requirement limits.</p>' +
    charts.map((src, i) => figure(src, `A and B, chart ${i + 1}`, false)).join('');
}

// ctx: {run: {id, summary, sceneText}, sceneObj (the parsed scene), label, pictures: {charts: [png], compare: [png], map, three},
//       exaggeration, compare: null | {A, labelA, diff, modelDiff, rows}, made}
export function buildReport(ctx) {
  const { run, pictures } = ctx;
  const s = run.summary || {};
  const reqs = Array.isArray(s.requirements) ? s.requirements : [];
  const failed = reqs.filter((r) => r.pass === false).length;
  const verdict = !reqs.length ? 'no requirements' : failed ? `FAIL: ${failed} of ${reqs.length} requirements not met` : `PASS: all ${reqs.length} requirements met`;
  const name = (s.scene && s.scene.name) || 'scene';
  const sceneObj = ctx.sceneObj || null;
  const chartCaptions = ['North and east position error of run 1 with the filter’s ±1σ', 'Horizontal position error', 'Vertical position error', 'Velocity and yaw error'];
  const charts = pictures.charts.map((src, i) => figure(src, chartCaptions[i + (pictures.charts.length === 3 ? 1 : 0)] || `chart ${i + 1}`, false)).join('');
  return `<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<meta name="generator" content="navsim studio">
<title>navsim report: ${esc(name)} (run ${esc(run.id.slice(0, 8))})</title>
<style>
body { font: 14px/1.45 system-ui, "DejaVu Sans", sans-serif; color: #1b1f24; max-width: 1100px; margin: 1.5rem auto; padding: 0 1rem; }
h1 { font-size: 1.5rem; } h2 { font-size: 1.2rem; margin-top: 2rem; border-bottom: 1px solid #d0d5dc; } h3 { font-size: 1rem; }
table { border-collapse: collapse; margin: .5rem 0; } td, th { padding: .2rem .6rem; border-bottom: 1px solid #d0d5dc; text-align: left; vertical-align: top; }
.pass { color: #1e7a34; font-weight: 600; } .fail { color: #b3261e; font-weight: 600; }
figure { margin: 1rem 0; } figure img { max-width: 100%; border: 1px solid #d0d5dc; } figcaption { color: #5b6470; font-size: .9em; }
pre { background: #f6f7f9; border: 1px solid #d0d5dc; padding: .5rem; overflow: auto; font: 12px/1.35 "DejaVu Sans Mono", monospace; }
.verdict { font-size: 1.15rem; }
</style>
</head>
<body>
<h1>navsim report: ${esc(name)}</h1>
<p>Run ${esc(ctx.label)}, id <code>${esc(run.id)}</code>; navsim ${esc(s.navsim_version || '')}; ${fmtNum(s.runs)} Monte Carlo runs, seed ${fmtNum(s.seed)}.
Made by navsim studio on ${esc(ctx.made)} from the run's summary.json and result files.</p>
<p class="verdict ${failed ? 'fail' : reqs.length ? 'pass' : ''}" id="verdict">${esc(verdict)}</p>
<h2>Verdicts</h2>
${verdictTable(reqs)}
<h2>Set-up</h2>
${setupTable(s, sceneObj)}
<h2>Errors</h2>
${figuresTable(s)}
${charts}
<h2>Paths</h2>
${figure(pictures.map, 'Map: reference (black), estimate (red-orange, dashed), GNSS fixes (green)' + (ctx.compare ? ', estimate of run A (blue)' : ''))}
${figure(pictures.three, `3D path: reference (black), estimate (red-orange) with its deviation ×${ctx.exaggeration ?? '?'}, attitude frames, error tube` + (ctx.compare ? '; estimate of run A (blue)' : ''))}
${ctx.compare ? compareSection(ctx.compare, ctx.label, pictures.compare) : ''}
<h2>Scene</h2>
<p>The scene this run was made from. Save it (<a download="${esc(name)}.yaml" href="data:application/yaml;base64,${b64(run.sceneText)}">${esc(name)}.yaml</a>)
and run <code>navsim run ${esc(name)}.yaml</code>, or open it in navstudio or the web studio: the results are the same bit for bit.</p>
<pre id="scene-yaml">${esc(run.sceneText)}</pre>
</body>
</html>
`;
}
