// Error charts (uPlot): the first run's errors, the Monte Carlo RMS over the runs, the filter's
// reported 1-sigma as a shaded band, the outage spans shaded grey and the requirement limits as
// dashed red lines.
import uPlot from 'uplot';

// CSV text -> {name: Float64Array}; empty cells are NaN.
export function parseCsv(text) {
  const lines = text.split('\n');
  const head = lines[0].trim().split(',');
  let n = 0;
  const cols = head.map(() => new Float64Array(lines.length));
  for (let i = 1; i < lines.length; ++i) {
    const l = lines[i];
    if (!l) continue;
    const f = l.split(',');
    for (let j = 0; j < head.length; ++j) cols[j][n] = f[j] === '' || f[j] === undefined ? NaN : +f[j];
    ++n;
  }
  const out = { length: n };
  head.forEach((h, j) => { out[h] = cols[j].subarray(0, n); });
  return out;
}

// Every k-th sample so that a chart gets at most max points.
export function decimate(arr, max) {
  if (!arr) return arr;
  const k = Math.max(1, Math.ceil(arr.length / max));
  if (k === 1) return Array.from(arr);
  const out = [];
  for (let i = 0; i < arr.length; i += k) out.push(arr[i]);
  return out;
}

// outages: [[t0, t1], ...] or [{span: [t0, t1], fill}, ...] (the fill of each span).
function spansPlugin(outages, limits) {
  return {
    hooks: {
      drawClear: [(u) => {
        const ctx = u.ctx;
        ctx.save();
        for (const o of outages) {
          const [t0, t1] = Array.isArray(o) ? o : o.span;
          ctx.fillStyle = (!Array.isArray(o) && o.fill) || 'rgba(120,120,120,0.18)';
          const x0 = u.valToPos(t0, 'x', true), x1 = u.valToPos(t1, 'x', true);
          ctx.fillRect(x0, u.bbox.top, Math.max(1, x1 - x0), u.bbox.height);
        }
        ctx.restore();
      }],
      draw: [(u) => {
        const ctx = u.ctx;
        ctx.save();
        ctx.strokeStyle = '#c62828';
        ctx.setLineDash([8, 5]);
        ctx.lineWidth = 2;
        ctx.font = `${12 * devicePixelRatio}px sans-serif`;
        ctx.fillStyle = '#c62828';
        // Labels of limits close to each other are set side by side, not over each other.
        const placed = [];
        for (const lim of [...limits].sort((a, b) => b.value - a.value)) {
          const y = u.valToPos(lim.value, 'y', true);
          if (!(y >= u.bbox.top && y <= u.bbox.top + u.bbox.height)) continue;
          ctx.beginPath();
          ctx.moveTo(u.bbox.left, y);
          ctx.lineTo(u.bbox.left + u.bbox.width, y);
          ctx.stroke();
          const w = ctx.measureText(lim.label).width;
          let right = u.bbox.left + u.bbox.width - 6;
          for (const p of placed) if (Math.abs(p.y - y) < 15 * devicePixelRatio) right = Math.min(right, p.x - 16 * devicePixelRatio);
          ctx.save();
          ctx.setLineDash([]);
          ctx.strokeStyle = 'rgba(255,255,255,0.9)';
          ctx.lineWidth = 3 * devicePixelRatio;
          ctx.strokeText(lim.label, right - w, y - 4); // a halo: readable over the other lines
          ctx.restore();
          ctx.fillText(lim.label, right - w, y - 4);
          placed.push({ x: right - w, y });
        }
        ctx.restore();
      }],
    },
  };
}

// One chart: series [{label, data, color, dash, band: [loIdx, hiIdx] }] over t.
function chart(host, title, unitLabel, t, series, outages, limits, width) {
  const div = document.createElement('div');
  div.className = 'chart';
  host.appendChild(div);
  let peak = 0;
  for (const se of series) for (const v of se.data) if (Number.isFinite(v) && Math.abs(v) > peak) peak = Math.abs(v);
  const maxY = Math.max(peak * 1.05, ...limits.map((l) => l.value * 1.15), 1e-9);
  const opts = {
    title,
    width,
    height: 220,
    plugins: [spansPlugin(outages, limits)],
    scales: { x: { time: false }, y: { range: (u, lo, hi) => [Math.min(lo, 0), Math.max(hi, maxY)] } },
    axes: [{ label: 't [s]' }, { label: unitLabel, size: 60, values: (u, ticks) => ticks.map((v) => +v.toPrecision(3)) }],
    series: [{ label: 't [s]' }, ...series.map((s) => ({ label: s.label, stroke: s.color, width: s.width || 1.5, dash: s.dash, fill: s.fill, spanGaps: !!s.spanGaps, points: { show: false } }))],
    bands: series.map((s, i) => (s.bandWith !== undefined ? { series: [i + 1, s.bandWith + 1], fill: s.bandFill } : null)).filter(Boolean),
  };
  return new uPlot(opts, [t, ...series.map((s) => s.data)], div);
}

// Build the charts of a run. files: {errors, mc_stats} parsed CSVs (mc_stats may be null).
export function drawCharts(host, files, outages, requirements, width) {
  host.textContent = '';
  const max = 4000;
  const err = files.errors;
  const mc = files.mc_stats;
  const t = decimate(err.t_s, max);
  const d = (a) => decimate(a, max);
  const lim = (metric) => requirements.filter((r) => r.metric === metric && Number.isFinite(r.limit))
    .map((r) => ({ value: r.limit * (r.unit === 'cm' ? 0.01 : r.unit === 'mm' ? 0.001 : r.unit === 'km' ? 1000 : 1), label: `${r.id} ${r.statistic} ≤ ${r.limit} ${r.unit || ''}` }));
  const charts = [];
  // North and east errors of run 0 with the reported +-1 sigma band (from mc_stats).
  if (mc && mc.pos_sd_reported_n_m && mc.length === err.length) {
    const sdN = d(mc.pos_sd_reported_n_m), sdE = d(mc.pos_sd_reported_e_m);
    charts.push(chart(host, 'North and east position error of run 1, with the filter’s ±1σ', 'error [m]', t, [
      { label: '+σ north', data: sdN, color: 'rgba(31,95,191,0.35)', width: 1 },
      { label: '−σ north', data: sdN.map((v) => -v), color: 'rgba(31,95,191,0.35)', width: 1, bandWith: 0, bandFill: 'rgba(31,95,191,0.12)' },
      { label: 'north', data: d(err.pos_err_n_m), color: '#1f5fbf' },
      { label: 'east', data: d(err.pos_err_e_m), color: '#e07b00' },
      { label: '±σ east', data: sdE, color: 'rgba(224,123,0,0.5)', width: 1, dash: [4, 3] },
    ], outages, [], width));
  }
  const hs = [{ label: 'run 1', data: d(err.pos_err_h_m), color: '#444', width: 1 }];
  if (mc && mc.pos_h_rms_m && mc.length === err.length) {
    hs.push({ label: 'RMS over runs', data: d(mc.pos_h_rms_m), color: '#1f5fbf', width: 2 });
    if (mc.pos_sd_reported_n_m)
      hs.push({ label: 'filter σ (horizontal)', data: d(mc.pos_sd_reported_n_m.map((v, i) => Math.hypot(v, mc.pos_sd_reported_e_m[i]))), color: '#2a9d3a', dash: [6, 4] });
  }
  charts.push(chart(host, 'Horizontal position error', 'error [m]', t, hs, outages, lim('horizontal_position'), width));
  charts.push(chart(host, 'Vertical position error', 'error [m]', t, [
    { label: 'run 1 (down)', data: d(err.pos_err_d_m), color: '#444', width: 1 },
    ...(mc && mc.pos_rms_d_m && mc.length === err.length ? [{ label: 'RMS over runs', data: d(mc.pos_rms_d_m), color: '#1f5fbf', width: 2 }] : []),
  ], outages, lim('vertical_position'), width));
  charts.push(chart(host, 'Velocity and yaw error', 'm/s  ·  deg', t, [
    { label: 'velocity error [m/s]', data: d(err.vel_err_mps), color: '#7b3fa0' },
    { label: 'yaw error [deg]', data: d(err.yaw_err_deg), color: '#b3261e' },
  ], outages, [], width));
  return charts;
}

// A/B comparison: the same quantities of two runs on shared axes (each run's own time base,
// joined onto the union of the two; a run's gaps are spanned). A solid blue, B dashed orange.
// run: {label, errors, mc_stats, outages, requirements}. Monte Carlo RMS when the run has it,
// else the first run's error (the label says which).
export const compareStyle = {
  A: { color: '#1f5fbf', dash: undefined, width: 2, span: 'rgba(31,95,191,0.13)' },
  B: { color: '#e07b00', dash: [10, 5], width: 2, span: 'rgba(224,123,0,0.16)' },
};
export function drawCompareCharts(host, runs, width) {
  host.textContent = '';
  const max = 3000;
  const quantities = [
    ['Horizontal position error', 'error [m]', 'horizontal_position', (e, m) => (m && m.pos_h_rms_m ? [m.pos_h_rms_m, true] : [e.pos_err_h_m, false])],
    ['Vertical position error', 'error [m]', 'vertical_position', (e, m) => (m && m.pos_rms_d_m ? [m.pos_rms_d_m, true] : [e.pos_err_v_m || e.pos_err_d_m, false])],
    ['Velocity error', 'error [m/s]', 'velocity', (e, m) => (m && m.vel_rms_mps ? [m.vel_rms_mps, true] : [e.vel_err_mps, false])],
    ['Attitude error', 'error [deg]', 'attitude', (e, m) => (m && m.att_rms_rad ? [m.att_rms_rad.map((v) => (v * 180) / Math.PI), true] : [e.att_err_rad.map((v) => (v * 180) / Math.PI), false])],
  ];
  // Outage spans: drawn once when both scenes have the same, else each in its run's tint.
  const key = (o) => JSON.stringify(o || []);
  const spans = key(runs.A.outages) === key(runs.B.outages) ? runs.A.outages.map((o) => ({ span: o }))
    : ['A', 'B'].flatMap((k) => runs[k].outages.map((o) => ({ span: o, fill: compareStyle[k].span })));
  const charts = [];
  for (const [title, unit, metric, pick] of quantities) {
    const tables = [], series = [];
    for (const k of ['A', 'B']) {
      const r = runs[k];
      const mcOk = r.mc_stats && r.mc_stats.length === r.errors.length ? r.mc_stats : null;
      const [y, rms] = pick(r.errors, mcOk);
      if (!y) continue;
      tables.push([decimate(r.errors.t_s, max), decimate(y, max)]);
      const st = compareStyle[k];
      series.push({ label: `${k} · ${rms ? `RMS over ${r.runs} runs` : 'run 1'} · ${r.label}`, color: st.color, dash: st.dash, width: st.width, spanGaps: true });
    }
    if (tables.length < 2) continue;
    const data = uPlot.join(tables);
    const limits = new Map();
    for (const k of ['A', 'B'])
      for (const r of runs[k].requirements || [])
        if (r.metric === metric && Number.isFinite(r.limit)) {
          const value = r.limit * (r.unit === 'cm' ? 0.01 : r.unit === 'mm' ? 0.001 : r.unit === 'km' ? 1000 : 1);
          const label = `${r.id} ${r.statistic} ≤ ${r.limit} ${r.unit || ''}`;
          limits.set(label, { value, label });
        }
    charts.push(chart(host, `${title}: A and B`, unit, data[0], series.map((s, i) => ({ ...s, data: data[i + 1] })), spans, [...limits.values()], width));
  }
  return charts;
}

// A chart as a picture, as the page shows it: its title, the plot and a legend of its series
// (uPlot draws the plot on a canvas and the title and legend in HTML). PNG data URL.
export function chartPng(u) {
  const src = u.ctx.canvas;
  const dpr = src.width / (u.width || src.width) || 1;
  const labels = u.series.slice(1).map((s, i) => ({ s, i: i + 1 })).filter(({ s }) => s.show !== false);
  const lineH = 18 * dpr, cols = Math.max(1, Math.floor(src.width / (300 * dpr)));
  const legendH = Math.ceil(labels.length / cols) * lineH + 6 * dpr;
  const titleH = 26 * dpr;
  const out = document.createElement('canvas');
  out.width = src.width;
  out.height = titleH + src.height + legendH;
  const ctx = out.getContext('2d');
  ctx.fillStyle = '#fff';
  ctx.fillRect(0, 0, out.width, out.height);
  ctx.fillStyle = '#1b1f24';
  ctx.font = `bold ${14 * dpr}px sans-serif`;
  ctx.textAlign = 'center';
  ctx.fillText(u.root.querySelector('.u-title')?.textContent || '', out.width / 2, 18 * dpr);
  ctx.textAlign = 'left';
  ctx.drawImage(src, 0, titleH);
  ctx.font = `${12 * dpr}px sans-serif`;
  const colW = src.width / cols;
  labels.forEach(({ s, i }, j) => {
    const x = (j % cols) * colW + 10 * dpr, y = titleH + src.height + Math.floor(j / cols) * lineH + 12 * dpr;
    const stroke = typeof s.stroke === 'function' ? s.stroke(u, i) : s.stroke;
    ctx.strokeStyle = stroke || '#000';
    ctx.lineWidth = 2 * dpr;
    ctx.setLineDash((s.dash || []).map((v) => v * dpr));
    ctx.beginPath();
    ctx.moveTo(x, y - 4 * dpr);
    ctx.lineTo(x + 26 * dpr, y - 4 * dpr);
    ctx.stroke();
    ctx.setLineDash([]);
    ctx.fillStyle = '#1b1f24';
    ctx.fillText(String(s.label).slice(0, 60), x + 32 * dpr, y);
  });
  return out.toDataURL('image/png');
}
