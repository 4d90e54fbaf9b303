// End-to-end test of the studio's A/B comparison and its report.html download in Debian's
// chromium against the real `navsim serve` (issue 20, Deliver 3): urban-drive with 5 Monte Carlo
// runs is run and pinned as A, the IMU is changed to another catalog part and the scene is run
// as B; the comparison must list the changed key, draw both runs' errors on shared axes with a
// legend naming both, show both verdicts with the figures of summary.json, draw A's estimate on
// the map and in 3D, survive a reload (the run ids are in the URL fragment), and the report must
// be a self-contained page with the verdicts, decodable embedded pictures and the scene that
// reruns. Controls are driven by the keyboard. Screenshots go to the build tree (web/shots).
// A second test runs urban-drive with its origin moved 500 m north and 300 m east as A and the
// original as B: A's first points must be drawn in B's frame where exact ECEF maths puts them
// (within 0.5 m) in 3D and on the map, and the legends must give the distance.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { writeFileSync, mkdtempSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { pathToFileURL } from 'node:url';
import { missing, startServer, launch, openPage, canvasInk, shotPath, waitAttr, download } from './helpers.mjs';

const why = missing();
let server = null, browser = null;
const t0 = Date.now();

before(async () => {
  if (why) return;
  server = await startServer();
  browser = await launch();
});
after(async () => {
  if (browser) await browser.close();
  if (server) assert.equal(await server.stop(), 0, 'navsim serve exits 0 on SIGTERM');
  if (!why) console.log(`compare test: ${((Date.now() - t0) / 1000).toFixed(1)} s in all`);
});

async function api(path) {
  const r = await fetch(server.url + path);
  return { status: r.status, text: await r.text() };
}
// Activate a control by the keyboard: focus, then Enter (buttons) or the arrow keys (tabs).
async function press(page, id) {
  await page.focus(`#${id}`);
  await page.keyboard.press('Enter');
}
async function selectTab(page, id) {
  await press(page, id);
  await page.waitForFunction((t) => document.getElementById(t).getAttribute('aria-selected') === 'true', {}, id);
}
async function runAndWait(page) {
  const before = await page.evaluate(() => (window.__studio.lastRun ? window.__studio.lastRun.id : ''));
  await press(page, 'run');
  assert.equal(await waitAttr(page, '#run-state', 'data-state', ['done', 'failed', 'cancelled'], 120000), 'done',
    await page.$eval('#run-state', (e) => e.textContent));
  await page.waitForFunction((b) => window.__studio.lastRun && window.__studio.lastRun.id !== b, {}, before);
  return page.evaluate(() => window.__studio.lastRun.id);
}
const fmt = (v) => (Number.isInteger(v) ? String(v) : v.toPrecision(4));

test('A/B: run A, pin it, another IMU, run B: diff, overlaid charts, verdicts side by side, map and 3D, reload, report.html',
  { skip: why || false, timeout: 300000 }, async () => {
    const { page, problems } = await openPage(browser, server.url);
    assert.equal(await waitAttr(page, '#estimate', 'data-state', ['ok', 'error', 'invalid'], 60000), 'ok');
    assert.match(await page.$eval('#yaml', (e) => e.value), /name: urban-drive/);
    // Every control of the comparison has a name a screen reader reads.
    for (const id of ['pin-a', 'compare-a', 'compare-b', 'tab-compare']) {
      const name = await page.evaluate((i) => {
        const el = document.getElementById(i);
        return (el.labels && el.labels[0] ? el.labels[0].textContent : el.textContent).trim();
      }, id);
      assert.ok(name.length > 3, `#${id} has a label (${name})`);
    }
    assert.equal(await page.$eval('#pin-a', (b) => b.disabled), true, 'nothing to pin before a run');
    // The key-level difference: nested keys, keys on one side only, lists of mappings item by item
    // when they have the same length, vectors and other lists whole.
    const d = await page.evaluate(() => window.__studio.sceneDiff(
      'a: {b: 1, c: [1, 2, 3]}\np: [{x: 1, y: 2}, {x: 3}]\nq: [[0, 1]]\nr: 5\n',
      'a: {b: 1, c: [1, 2, 4], d: x}\np: [{x: 1, y: 3}, {x: 3}]\nq: [[0, 1], [2, 3]]\n'));
    assert.deepEqual(d, [
      { path: 'a.c', a: [1, 2, 3], b: [1, 2, 4] }, { path: 'a.d', b: 'x' }, { path: 'p[0].y', a: 2, b: 3 },
      { path: 'q', a: [[0, 1]], b: [[0, 1], [2, 3]] }, { path: 'r', a: 5 }]);

    // A: urban-drive as it is (Xsens MTi-300), 5 runs.
    await page.$eval('#runs', (e) => { e.value = ''; });
    await page.type('#runs', '5');
    await page.$eval('#runs', (e) => e.dispatchEvent(new Event('change')));
    const idA = await runAndWait(page);
    await press(page, 'pin-a');
    await page.waitForFunction(() => document.getElementById('pin-a').getAttribute('aria-pressed') === 'true');
    assert.match(location_hash(await page.url()), new RegExp(`[#&]a=${idA}\\b`));

    // B: another IMU from the catalog, chosen by the keyboard.
    const imuA = await page.$eval('#imu-catalog', (s) => s.value);
    assert.equal(imuA, 'Xsens MTi-300');
    const imuB = 'Honeywell HG1700 (AG58 class)';
    await page.select('#imu-catalog', imuB);
    await page.waitForFunction((n) => document.getElementById('yaml').value.includes(`catalog: ${n}`) || document.getElementById('yaml').value.includes(`catalog: "${n}"`), {}, imuB);
    await waitAttr(page, '#estimate', 'data-state', ['ok', 'error', 'invalid'], 60000);
    const idB = await runAndWait(page);
    assert.notEqual(idA, idB);
    assert.equal(await page.$eval('#pin-a', (b) => b.getAttribute('aria-pressed')), 'false', 'the run shown (B) is not A');

    // The comparison: ready, A and B named, the changed key listed with both values.
    await selectTab(page, 'tab-compare');
    assert.equal(await waitAttr(page, '#compare', 'data-state', ['ready'], 60000), 'ready');
    assert.equal(await page.$eval('#compare-a', (s) => s.value), idA);
    assert.equal(await page.$eval('#compare-b', (s) => s.value), idB);
    const diff = await page.$$eval('#compare-diff tbody tr', (rs) => rs.map((r) => [...r.cells].map((c) => c.textContent)));
    assert.deepEqual(diff, [['imu.catalog', imuA, imuB]], 'only the IMU differs between the scenes (runs were 5 in both)');
    const model = await page.$$eval('#compare-model-diff tbody tr td.key', (ts) => ts.map((t) => t.textContent));
    assert.ok(model.includes('imu.gyro.arw_deg_per_sqrt_h') && model.includes('imu.catalog'), `model terms that differ: ${model}`);

    // Verdicts side by side: each requirement and each outage end with the values of the two
    // runs' summary.json, as printed.
    const sA = JSON.parse((await api(`api/runs/${idA}/files/summary.json`)).text);
    const sB = JSON.parse((await api(`api/runs/${idB}/files/summary.json`)).text);
    const rows = await page.$$eval('#compare-verdicts tbody tr', (rs) => rs.map((r) => [...r.cells].map((c) => c.textContent)));
    const cep = rows.find((r) => r[0] === 'h-cep95');
    const rA = sA.requirements.find((r) => r.id === 'h-cep95'), rB = sB.requirements.find((r) => r.id === 'h-cep95');
    assert.ok(cep, JSON.stringify(rows));
    assert.equal(cep[3], `${fmt(rA.value)} m ${rA.pass ? 'PASS' : 'FAIL'}`);
    assert.equal(cep[4], `${fmt(rB.value)} m ${rB.pass ? 'PASS' : 'FAIL'}`);
    assert.notEqual(rA.value, rB.value, 'another IMU gives another CEP95');
    const oeA = sA.requirements.find((r) => r.statistic === 'outage_end'), oeB = sB.requirements.find((r) => r.statistic === 'outage_end');
    for (let i = 0; i < oeA.outages.length; ++i) {
      const o = oeA.outages[i];
      const row = rows.find((r) => r[0] === `end of the outage ${o.t0_s}–${o.t1_s} s`);
      assert.ok(row, `outage ${o.t0_s} row (${JSON.stringify(rows)})`);
      assert.equal(row[3], `${fmt(o.value)} m`);
      assert.equal(row[4], `${fmt(oeB.outages[i].value)} m`);
    }
    const cepRms = rows.find((r) => r[0] === 'horizontal error, RMS over time and runs');
    assert.equal(cepRms[3], `${fmt(sA.stats.pos_err_h_m.rms)} m`);

    // The overlaid charts: both series drawn (A blue, B orange) on the first chart, the legend
    // names both runs.
    const n = await page.$$eval('#compare-charts .chart', (cs) => cs.length);
    assert.equal(n, 4, 'horizontal, vertical, velocity and attitude');
    const ink = await canvasInk(page, '#compare-charts .chart canvas', [[31, 95, 191], [224, 123, 0]]);
    assert.ok(ink.ink > 0.01 * ink.pixels, `chart has ink ${JSON.stringify(ink)}`);
    assert.ok(ink.colours[0] > 200 && ink.colours[1] > 200, `A (blue) and B (orange) lines drawn ${JSON.stringify(ink)}`);
    const legend = await page.$eval('#compare-charts .chart .u-legend', (l) => l.textContent);
    assert.match(legend, /A · RMS over 5 runs · #\d+/);
    assert.match(legend, /B · RMS over 5 runs · #\d+/);
    await page.screenshot({ path: shotPath('AB1-compare.png'), fullPage: true });

    // Both estimates on the map (A blue, B red-orange) and in 3D.
    await selectTab(page, 'tab-map');
    assert.equal(await page.$eval('#map-legend-a', (e) => e.hidden), false);
    await page.evaluate(() => new Promise((res) => { window.__studio.map.map.once('rendercomplete', res); window.__studio.map.map.render(); }));
    await page.screenshot({ path: shotPath('AB2-map.png') });
    const mapInk = await canvasInk(page, '#map', [[31, 95, 191], [209, 64, 31], [17, 17, 17]]);
    assert.ok(mapInk.colours.every((c) => c > 100), `A's and B's estimates and the reference on the map ${JSON.stringify(mapInk)}`);
    await selectTab(page, 'tab-3d');
    await page.screenshot({ path: shotPath('AB3-3d.png') });
    // A's estimate is the only dark blue (the error tube is a light, translucent blue); B's
    // estimate is drawn as before (thin red-orange, looked at in the screenshot).
    const threeInk = await canvasInk(page, '#three canvas', [[31, 95, 191]]);
    assert.ok(threeInk.ink > 0.01 * threeInk.pixels && threeInk.colours[0] > 100, `A's estimate in 3D ${JSON.stringify(threeInk)}`);
    assert.equal(await page.$eval('#three-legend-a', (e) => e.hidden), false);
    // Equal scene origins: A is drawn from its own local metres, unchanged (the same numbers as
    // its truth.csv and nav.csv, float32 in the GPU's buffer), and no distance is reported.
    const [tA, nA] = [await csvFirst(`api/runs/${idA}/files/truth.csv`), await csvFirst(`api/runs/${idA}/files/nav.csv`)];
    const same3d = await page.evaluate(() => ({ k: window.__studio.view3d.exaggeration, estA: window.__studio.view3d.firstNed('estA'), refA: window.__studio.view3d.firstNed('refA') }));
    assert.equal(same3d.refA, null, 'the same reference is not drawn twice');
    assertNear(same3d.estA, exaggerated(ned(tA), ned(nA), same3d.k), 1e-3, "A's first estimate point in 3D, equal origins");
    assert.equal(await page.$eval('#three-legend-a-far', (e) => e.textContent), '');
    assert.equal(await page.$eval('#map-legend-a-far', (e) => e.textContent), '');

    // report.html: a download made in the page; a valid page with the verdicts, the comparison,
    // decodable embedded pictures and the scene, opened from a file without a network.
    await selectTab(page, 'tab-results');
    await page.waitForSelector('#download-report');
    const rep = await download(browser, page, '#download-report');
    assert.match(rep.name, new RegExp(`^urban-drive-${idB.slice(0, 8)}-report\\.html$`));
    assert.match(rep.text, /^<!doctype html>\n<html lang="en">/);
    assert.match(rep.text, /<\/html>\n$/);
    assert.ok(!/<script|src="http|href="http/i.test(rep.text), 'no script and no external reference');
    const file = join(mkdtempSync(join(tmpdir(), 'studio-report-')), rep.name);
    writeFileSync(file, rep.text);
    const rp = await browser.newPage();
    await rp.setViewport({ width: 1280, height: 900 });
    const repProblems = [];
    rp.on('pageerror', (e) => repProblems.push(e.message));
    rp.on('request', (r) => { if (!r.url().startsWith('file:') && !r.url().startsWith('data:')) repProblems.push(`request ${r.url()}`); });
    await rp.goto(pathToFileURL(file).href, { waitUntil: 'load' });
    const info = await rp.evaluate(() => ({
      title: document.title,
      verdict: document.getElementById('verdict').textContent,
      verdictRows: [...document.querySelectorAll('table.verdicts tbody tr')].map((r) => [...r.cells].map((c) => c.textContent)),
      images: [...document.images].map((i) => ({ w: i.naturalWidth, h: i.naturalHeight, alt: i.alt, png: i.src.startsWith('data:image/png;base64,') })),
      diff: [...document.querySelectorAll('table.diff tbody tr')].map((r) => r.cells[0].textContent),
      scene: document.getElementById('scene-yaml').textContent,
      sceneLink: document.querySelector('a[download$=".yaml"]').href,
    }));
    assert.match(info.title, /urban-drive/);
    const failed = sB.requirements.filter((r) => r.pass === false).length;
    assert.equal(info.verdict, failed ? `FAIL: ${failed} of ${sB.requirements.length} requirements not met` : `PASS: all ${sB.requirements.length} requirements met`);
    const cepRep = info.verdictRows.find((r) => r[0] === 'h-cep95');
    assert.deepEqual([cepRep[3], cepRep[5]], [`${fmt(rB.value)} m`, rB.pass ? 'PASS' : 'FAIL']);
    // 4 error charts, the map, the 3D view and 4 comparison charts, every one a decodable PNG.
    assert.equal(info.images.length, 10, JSON.stringify(info.images.map((i) => i.alt)));
    for (const im of info.images) assert.ok(im.png && im.w > 200 && im.h > 150, `picture decodes: ${JSON.stringify(im)}`);
    assert.ok(info.diff.includes('imu.catalog'));
    const posted = (await api(`api/runs/${idB}/files/scene.yaml`)).text;
    assert.equal(info.scene, posted, 'the embedded scene is the one the server ran');
    const linked = Buffer.from(info.sceneLink.split(',')[1], 'base64').toString('utf8');
    assert.equal(linked, posted, 'the scene download of the report is the one the server ran');
    // The pictures are not blank: the map picture shows both estimates.
    const mapPic = await rp.evaluate(() => {
      const img = [...document.images].find((i) => i.alt.startsWith('Map'));
      const c = document.createElement('canvas');
      c.width = img.naturalWidth; c.height = img.naturalHeight;
      const x = c.getContext('2d');
      x.drawImage(img, 0, 0);
      const d = x.getImageData(0, 0, c.width, c.height).data;
      const near = (r, g, b) => { let k = 0; for (let i = 0; i < d.length; i += 4) if (Math.abs(d[i] - r) < 40 && Math.abs(d[i + 1] - g) < 40 && Math.abs(d[i + 2] - b) < 40) ++k; return k; };
      return { blue: near(31, 95, 191), orange: near(209, 64, 31) };
    });
    assert.ok(mapPic.blue > 100 && mapPic.orange > 100, `the report's map shows A and B ${JSON.stringify(mapPic)}`);
    await rp.screenshot({ path: shotPath('AB4-report.png'), fullPage: true });
    assert.deepEqual(repProblems, []);
    await rp.close();

    // A reload keeps the comparison: the run ids are in the URL fragment.
    const url = page.url();
    assert.match(url, new RegExp(`&a=${idA}&b=${idB}$`));
    await page.reload({ waitUntil: 'load' });
    await page.waitForSelector('body[data-ready="1"]', { timeout: 60000 });
    assert.equal(await waitAttr(page, '#compare', 'data-state', ['ready'], 60000), 'ready');
    assert.deepEqual(await page.evaluate(() => window.__studio.compare), { a: idA, b: idB, diff: ['imu.catalog'] });
    assert.equal(await page.$eval('#verdicts', (e) => e.dataset.state), sB.requirements.every((r) => r.pass) ? 'pass' : 'fail');
    await selectTab(page, 'tab-compare');
    // Any two of the browser's runs: B back to A's run shows it, and A compared with itself is no comparison.
    const optsB = await page.$$eval('#compare-b option', (os) => os.map((o) => o.value).filter(Boolean));
    assert.ok(optsB.includes(idA) && optsB.includes(idB), `both runs offered after the reload (${optsB})`);
    await page.select('#compare-a', '');
    assert.equal(await waitAttr(page, '#compare', 'data-state', ['none'], 10000), 'none');
    await page.select('#compare-a', idB);
    await page.select('#compare-b', idA);
    await page.waitForFunction((a) => window.__studio.compare && window.__studio.compare.b === a && document.getElementById('compare').dataset.state === 'ready', {}, idA);
    const swapped = await page.$$eval('#compare-diff tbody tr', (rs) => rs.map((r) => [...r.cells].map((c) => c.textContent)));
    assert.deepEqual(swapped, [['imu.catalog', imuB, imuA]]);
    await page.screenshot({ path: shotPath('AB5-after-reload-swapped.png'), fullPage: true });
    // A tablet-sized window: the comparison fits without horizontal scrolling.
    await page.setViewport({ width: 820, height: 1180 });
    await page.evaluate(() => new Promise((res) => requestAnimationFrame(() => requestAnimationFrame(res))));
    const overflow = await page.evaluate(() => document.documentElement.scrollWidth - window.innerWidth);
    await page.$eval('#view-compare', (e) => e.scrollIntoView());
    await page.screenshot({ path: shotPath('AB6-compare-tablet.png') });
    assert.ok(overflow <= 0, `no horizontal scrolling at 820 px (${overflow} px too wide)`);
    assert.deepEqual(problems, []);
    assert.deepEqual(await page.evaluate(() => window.__studio.errors), []);
    await page.close();
  });

function location_hash(u) { return new URL(u).hash; }

// The first data row of a result CSV as {column: number}.
async function csvFirst(path) {
  const r = await api(path);
  assert.equal(r.status, 200, path);
  const lines = r.text.split('\n').filter((l) => l && !l.startsWith('#'));
  const head = lines[0].split(','), row = lines[1].split(',').map(Number);
  return Object.fromEntries(head.map((h, i) => [h.trim(), row[i]]));
}
const ned = (row) => [row.pos_n_m, row.pos_e_m, row.pos_d_m];
const add = (a, b) => a.map((x, i) => x + b[i]);
// How view3d draws an estimate point: its reference plus the deviation times the exaggeration.
const exaggerated = (r, e, k) => r.map((x, i) => x + k * (e[i] - x));
function assertNear(got, want, tol, what) {
  assert.ok(Array.isArray(got), `${what}: drawn (${JSON.stringify(got)})`);
  const d = Math.hypot(...want.map((w, i) => got[i] - w));
  assert.ok(d <= tol, `${what}: drawn at ${JSON.stringify(got)}, expected ${JSON.stringify(want)} (${d.toFixed(4)} m off, tolerance ${tol} m)`);
}
// WGS-84 geodetic -> ECEF, and the NED coordinates of an ECEF point about an origin: the exact
// tangent-plane maths (not the studio's small-offset formulas), as an independent expectation.
const WGS_A = 6378137.0, WGS_F = 1 / 298.257223563, WGS_E2 = WGS_F * (2 - WGS_F);
function ecef(latDeg, lonDeg, h) {
  const la = (latDeg * Math.PI) / 180, lo = (lonDeg * Math.PI) / 180;
  const rn = WGS_A / Math.sqrt(1 - WGS_E2 * Math.sin(la) ** 2);
  return [(rn + h) * Math.cos(la) * Math.cos(lo), (rn + h) * Math.cos(la) * Math.sin(lo), (rn * (1 - WGS_E2) + h) * Math.sin(la)];
}
function nedAbout(o, p) {
  const la = (o.lat * Math.PI) / 180, lo = (o.lon * Math.PI) / 180;
  const r0 = ecef(o.lat, o.lon, o.h), d = p.map((x, i) => x - r0[i]);
  const [sl, cl, so, co] = [Math.sin(la), Math.cos(la), Math.sin(lo), Math.cos(lo)];
  return [-sl * co * d[0] - sl * so * d[1] + cl * d[2], -so * d[0] + co * d[1], -cl * co * d[0] - cl * so * d[1] - sl * d[2]];
}

test('A/B with other scene origins: A (urban-drive moved 500 m north, 300 m east) is drawn in B\'s frame in 3D and on the map',
  { skip: why || false, timeout: 300000 }, async () => {
    const { page, problems } = await openPage(browser, server.url);
    assert.equal(await waitAttr(page, '#estimate', 'data-state', ['ok', 'error', 'invalid'], 60000), 'ok');
    await page.$eval('#runs', (e) => { e.value = ''; });
    await page.type('#runs', '1');
    await page.$eval('#runs', (e) => e.dispatchEvent(new Event('change')));
    await page.waitForFunction(() => /\bruns: 1\b/.test(document.getElementById('yaml').value));
    const yamlB = await page.$eval('#yaml', (e) => e.value);
    const mo = yamlB.match(/origin: \{ ?lat_deg: ([-0-9.]+), lon_deg: ([-0-9.]+), h_m: ([-0-9.]+) ?\}/);
    assert.ok(mo, 'urban-drive has an origin mapping');
    const oB = { lat: +mo[1], lon: +mo[2], h: +mo[3] };
    // A's origin: 500 m north and 300 m east of B's (WGS-84 radii of curvature at B's latitude),
    // written to 1e-7 degrees; the expectation below is computed from the written numbers.
    const s = Math.sin((oB.lat * Math.PI) / 180), w = Math.sqrt(1 - WGS_E2 * s * s);
    const rm = (WGS_A * (1 - WGS_E2)) / w ** 3, rn = WGS_A / w;
    const oA = { lat: +(oB.lat + (500 / rm) * (180 / Math.PI)).toFixed(7), lon: +(oB.lon + (300 / (rn * Math.cos((oB.lat * Math.PI) / 180))) * (180 / Math.PI)).toFixed(7), h: oB.h };
    const yamlA = yamlB.replace(mo[0], `origin: {lat_deg: ${oA.lat}, lon_deg: ${oA.lon}, h_m: ${oA.h}}`);
    const setYaml = async (t) => {
      await page.$eval('#yaml', (e, v) => { e.value = v; e.dispatchEvent(new Event('input')); }, t);
      await page.waitForFunction((v) => document.getElementById('yaml').value === v || document.getElementById('yaml').value.includes(v.match(/origin: .*/)[0]), {}, t);
      assert.equal(await waitAttr(page, '#estimate', 'data-state', ['ok', 'error', 'invalid'], 60000), 'ok');
    };
    await setYaml(yamlA);
    const idA = await runAndWait(page);
    await press(page, 'pin-a');
    await page.waitForFunction(() => document.getElementById('pin-a').getAttribute('aria-pressed') === 'true');
    await setYaml(yamlB);
    const idB = await runAndWait(page);
    await selectTab(page, 'tab-compare');
    assert.equal(await waitAttr(page, '#compare', 'data-state', ['ready'], 60000), 'ready');
    const diff = await page.$$eval('#compare-diff tbody tr', (rs) => rs.map((r) => r.cells[0].textContent));
    assert.deepEqual(diff, ['earth.origin.lat_deg', 'earth.origin.lon_deg'], 'only the origin differs');

    // Where A's first point belongs in B's frame: A's local NED plus A's origin, exactly in ECEF.
    const offset = nedAbout(oB, ecef(oA.lat, oA.lon, oA.h));
    assert.ok(Math.abs(offset[0] - 500) < 0.1 && Math.abs(offset[1] - 300) < 0.1, `A's origin in B's frame ${offset}`);
    const [tA, nA] = [await csvFirst(`api/runs/${idA}/files/truth.csv`), await csvFirst(`api/runs/${idA}/files/nav.csv`)];
    const refWant = add(ned(tA), offset), estWant = add(ned(nA), offset);

    await selectTab(page, 'tab-3d');
    const got = await page.evaluate(() => ({ k: window.__studio.view3d.exaggeration, ref: window.__studio.view3d.firstNed('ref'), refA: window.__studio.view3d.firstNed('refA'), estA: window.__studio.view3d.firstNed('estA') }));
    const tB = await csvFirst(`api/runs/${idB}/files/truth.csv`);
    assertNear(got.ref, ned(tB), 1e-3, "B's reference in 3D");
    assertNear(got.refA, refWant, 0.5, "A's first reference point in B's frame (3D)");
    assertNear(got.estA, exaggerated(refWant, estWant, got.k), 0.5, "A's first estimate point in B's frame (3D)");
    assert.equal(await page.$eval('#three-legend-a-far', (e) => e.textContent), " (A is 583 m from B's origin)");
    console.log(`3D: A's first reference point ${got.refA.map((x) => x.toFixed(3))} m, expected ${refWant.map((x) => x.toFixed(3))} m`);
    await page.screenshot({ path: shotPath('AB7-3d-other-origin.png'), fullPage: true });

    await selectTab(page, 'tab-map');
    assert.equal(await page.$eval('#map-legend-a-far', (e) => e.textContent), " (A is 583 m from B's origin)");
    const onMap = await page.evaluate((o) => ({ refA: window.__studio.map.firstNed('refA', o), estA: window.__studio.map.firstNed('estA', o) }), oB);
    assertNear(onMap.refA, refWant.slice(0, 2), 0.5, "A's first reference point in B's frame (map)");
    assertNear(onMap.estA, estWant.slice(0, 2), 0.5, "A's first estimate point in B's frame (map)");
    await page.evaluate(() => new Promise((res) => { window.__studio.map.map.once('rendercomplete', res); window.__studio.map.map.render(); }));
    await page.screenshot({ path: shotPath('AB8-map-other-origin.png'), fullPage: true });
    assert.deepEqual(problems, []);
    assert.deepEqual(await page.evaluate(() => window.__studio.errors), []);
    await page.close();
  });
