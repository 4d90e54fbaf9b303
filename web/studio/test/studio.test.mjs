// End-to-end tests of the browser studio in Debian's chromium against the real `navsim serve`
// (issue 20, Done when): A) a catalog IMU, four waypoints drawn on the map, a 60 s outage, 100
// Monte Carlo runs, the verdict read; B) the gyro-free scheme on the paper's parametric
// trajectory with its live preview. Every test asserts no page errors and no console errors,
// counts the ink of the canvases and saves screenshots into the build tree (web/shots).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { writeFileSync, mkdtempSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { missing, startServer, launch, openPage, canvasInk, shotPath, waitAttr, download } from './helpers.mjs';

const why = missing();
let server = null, browser = null;

before(async () => {
  if (why) return;
  server = await startServer();
  browser = await launch();
});
after(async () => {
  if (browser) await browser.close();
  if (server) assert.equal(await server.stop(), 0, 'navsim serve exits 0 on SIGTERM');
});

async function selectTab(page, id) {
  await page.click(`#${id}`);
  await page.waitForFunction((t) => document.getElementById(t).getAttribute('aria-selected') === 'true', {}, id);
}

async function api(path, init) {
  const r = await fetch(server.url + path, init);
  return { status: r.status, text: await r.text() };
}

test('A: catalog IMU, four waypoints on the map, a 60 s outage, 100 Monte Carlo runs, the verdict', { skip: why || false, timeout: 400000 }, async () => {
  const { page, problems } = await openPage(browser, server.url);
  // The default scene (urban-drive) is loaded and estimated.
  assert.equal(await waitAttr(page, '#estimate', 'data-state', ['ok', 'error', 'invalid'], 60000), 'ok',
    await page.$eval('#estimate', (e) => e.textContent));
  const schemes = await page.$$eval('#scheme option', (os) => os.map((o) => o.value));
  for (const s of ['free_ins', 'gyro_free', 'ins_gnss', 'gyro_free_gnss']) assert.ok(schemes.includes(s), `scheme ${s} offered (${schemes})`);

  // A catalog IMU other than the scene's.
  const imus = await page.$$eval('#imu-catalog option', (os) => os.map((o) => o.value).filter(Boolean));
  assert.ok(imus.length >= 3, `the IMU catalog has entries (${imus.length})`);
  const current = await page.$eval('#imu-catalog', (s) => s.value);
  const pick = imus.find((n) => n !== current && /ADIS|Honeywell|Xsens|Epson/i.test(n)) || imus.find((n) => n !== current);
  await page.select('#imu-catalog', pick);
  await page.waitForFunction((n) => document.getElementById('yaml').value.includes(`catalog: ${n}`) || document.getElementById('yaml').value.includes(`catalog: "${n}"`), {}, pick);

  // Four waypoints clicked on the map (real mouse clicks on the OpenLayers canvas).
  await page.click('#draw-waypoints');
  const box = await (await page.$('#map')).boundingBox();
  const cx = box.x + box.width / 2, cy = box.y + box.height / 2;
  const clicks = [[-160, 110], [-160, -110], [160, -110], [160, 110]];
  for (let i = 0; i < clicks.length; ++i) {
    await page.mouse.click(cx + clicks[i][0], cy + clicks[i][1]);
    await page.waitForFunction((n) => document.querySelectorAll('#wp-list li').length === n, {}, i + 1);
  }
  await page.click('#draw-waypoints');
  const wp = await page.evaluate(() => window.__studio && document.getElementById('yaml').value);
  assert.match(wp, /type: waypoints/);
  // The clicked points are where the page says they are: about 320 px apart east-west.
  const pts = await page.$$eval('#wp-list li', (ls) => ls.map((l) => l.textContent));
  assert.equal(pts.length, 4, pts.join(' | '));

  // One 60 s outage (the library scene's own are removed first), 100 runs.
  await page.click('#clear-outages');
  await page.$eval('#outage-start', (e) => { e.value = ''; });
  await page.type('#outage-start', '80');
  await page.$eval('#outage-length', (e) => { e.value = ''; });
  await page.type('#outage-length', '60');
  await page.click('#add-outage');
  await page.waitForFunction(() => document.querySelectorAll('#outage-list li').length === 1);
  assert.match(await page.$eval('#yaml', (e) => e.value), /outages: \[ ?\[ ?80, 140 ?\] ?\]/);
  await page.$eval('#runs', (e) => { e.value = ''; });
  await page.type('#runs', '100');
  await page.$eval('#runs', (e) => e.dispatchEvent(new Event('change')));
  assert.equal(await waitAttr(page, '#estimate', 'data-state', ['ok', 'error', 'invalid'], 60000), 'ok',
    await page.$eval('#estimate', (e) => e.textContent));
  await page.screenshot({ path: shotPath('A1-setup-1280x800.png') });

  await page.click('#run');
  const state = await waitAttr(page, '#run-state', 'data-state', ['done', 'failed', 'cancelled'], 300000);
  assert.equal(state, 'done', await page.$eval('#run-state', (e) => e.textContent));
  const verdict = await waitAttr(page, '#verdicts', 'data-state', ['pass', 'fail', 'none', 'missing'], 60000);
  assert.ok(['pass', 'fail'].includes(verdict), `a verdict (${verdict})`);
  const heading = await page.$eval('#verdicts h2', (e) => e.textContent);
  assert.match(heading, /^(PASS|FAIL).*\(100 runs\)$/);

  // The server ran what the page showed: 100 runs, the one outage, the drawn waypoints.
  const id = await page.evaluate(() => window.__studio.lastRun.id);
  const summary = JSON.parse((await api(`api/runs/${id}/files/summary.json`)).text);
  assert.equal(summary.runs, 100);
  assert.equal(summary.trajectory, 'waypoints');
  const oe = summary.requirements.find((r) => r.statistic === 'outage_end');
  assert.ok(oe && oe.outages.length === 1 && oe.outages[0].t0_s === 80 && oe.outages[0].t1_s === 140, JSON.stringify(oe));
  assert.equal(heading.startsWith('PASS'), summary.requirements.every((r) => r.pass === true));

  // Map with the results, charts and 3D: not blank.
  await page.screenshot({ path: shotPath('A2-map-results.png') });
  // The reference (black), the estimate (red-orange) and the GNSS fixes (green) are drawn.
  const mapInk = await canvasInk(page, '#map', [[17, 17, 17], [209, 64, 31], [42, 157, 58]]);
  assert.ok(mapInk.ink > 0.005 * mapInk.pixels, `map has ink ${JSON.stringify(mapInk)}`);
  assert.ok(mapInk.colours.every((c) => c > 100), `reference, estimate and fixes on the map ${JSON.stringify(mapInk)}`);
  await selectTab(page, 'tab-charts');
  await page.screenshot({ path: shotPath('A3-charts.png'), fullPage: true });
  const chartInk = await canvasInk(page, '#charts .chart canvas');
  assert.ok(chartInk.ink > 0.01 * chartInk.pixels, `chart has ink ${JSON.stringify(chartInk)}`);
  assert.ok((await page.$$('#charts .chart')).length >= 3);
  await selectTab(page, 'tab-3d');
  await page.screenshot({ path: shotPath('A4-3d.png') });
  const threeInk = await canvasInk(page, '#three canvas');
  assert.ok(threeInk.ink > 0.01 * threeInk.pixels, `3D has ink ${JSON.stringify(threeInk)}`);
  // The exaggeration slider (keyboard) redraws the estimate, its frames and the tube.
  const before3d = await page.$eval('#three canvas', (c) => c.toDataURL());
  await page.focus('#exaggeration');
  await page.keyboard.press('Home');
  assert.equal(await page.$eval('#exaggeration-out', (e) => e.textContent), '1×');
  await page.waitForFunction((b) => document.querySelector('#three canvas').toDataURL() !== b, {}, before3d);
  await page.screenshot({ path: shotPath('A4b-3d-exaggeration-1.png') });
  await selectTab(page, 'tab-results');
  const links = await page.$$eval('#downloads a', (as) => as.map((a) => a.textContent));
  for (const f of ['summary.json', 'nav.csv', 'errors.csv']) assert.ok(links.includes(f), `download ${f} (${links})`);
  await page.screenshot({ path: shotPath('A5-verdicts.png') });
  assert.deepEqual(problems, []);
  await page.close();
});

test('B: gyro-free scheme on the paper\'s parametric trajectory, live preview, run and verdict', { skip: why || false, timeout: 300000 }, async () => {
  const { page, problems } = await openPage(browser, server.url);
  await waitAttr(page, '#estimate', 'data-state', ['ok', 'error', 'invalid'], 60000);
  await page.select('#library', 'paper-parametric');
  await page.waitForFunction(() => document.getElementById('yaml').value.includes('name: paper-parametric'));
  await page.select('#scheme', 'gyro_free');
  await page.waitForFunction(() => /scheme: gyro_free\b/.test(document.getElementById('yaml').value) && /\narray:/.test(document.getElementById('yaml').value));
  assert.equal(await page.$eval('#traj-type', (s) => s.value), 'parametric');
  assert.equal(await page.$eval('#traj-parametric', (e) => e.hidden), false);
  // The live preview follows the formula's parameters.
  const ink0 = await canvasInk(page, '#param-preview');
  assert.ok(ink0.ink > 500, `preview drawn ${JSON.stringify(ink0)}`);
  const before = await page.$eval('#param-preview', (c) => c.toDataURL());
  const b0 = await page.$('[aria-label="B_m [1]"]');
  assert.ok(b0, 'the form has the B_m vector (from the schema)');
  await b0.click({ clickCount: 3 });
  await b0.type('40');
  await page.waitForFunction((b) => document.getElementById('param-preview').toDataURL() !== b, {}, before);
  assert.match(await page.$eval('#yaml', (e) => e.value), /B_m: \[ ?1, 40, 0.5 ?\]/);
  assert.equal(await waitAttr(page, '#estimate', 'data-state', ['ok', 'error', 'invalid'], 60000), 'ok',
    await page.$eval('#estimate', (e) => e.textContent));
  await page.$eval('#runs', (e) => { e.value = ''; });
  await page.type('#runs', '20');
  await page.$eval('#runs', (e) => e.dispatchEvent(new Event('change')));
  await page.screenshot({ path: shotPath('B1-gyro-free-parametric.png') });
  await page.click('#run');
  assert.equal(await waitAttr(page, '#run-state', 'data-state', ['done', 'failed', 'cancelled'], 200000), 'done',
    await page.$eval('#run-state', (e) => e.textContent));
  const verdict = await waitAttr(page, '#verdicts', 'data-state', ['pass', 'fail', 'none', 'missing'], 60000);
  assert.ok(['pass', 'fail'].includes(verdict), verdict);
  const id = await page.evaluate(() => window.__studio.lastRun.id);
  const summary = JSON.parse((await api(`api/runs/${id}/files/summary.json`)).text);
  assert.equal(summary.runs, 20);
  assert.equal(summary.trajectory, 'parametric');
  await selectTab(page, 'tab-3d');
  await page.screenshot({ path: shotPath('B2-3d.png') });
  const threeInk = await canvasInk(page, '#three canvas');
  assert.ok(threeInk.ink > 0.01 * threeInk.pixels, `3D has ink ${JSON.stringify(threeInk)}`);
  await selectTab(page, 'tab-charts');
  await page.screenshot({ path: shotPath('B3-charts.png'), fullPage: true });

  // The permalink: the downloaded scene is what the server ran, and opening it in a fresh page
  // and running it again gives the same summary (timing aside).
  await selectTab(page, 'tab-results');
  const dl = await download(browser, page, '#downloads a[download$=".yaml"]');
  assert.equal(dl.name, 'paper-parametric.yaml');
  const saved = dl.text;
  assert.equal(saved, (await api(`api/runs/${id}/files/scene.yaml`)).text);
  const file = join(mkdtempSync(join(tmpdir(), 'studio-')), 'saved.yaml');
  writeFileSync(file, saved);
  const again = await openPage(browser, server.url);
  await waitAttr(again.page, '#estimate', 'data-state', ['ok', 'error', 'invalid'], 60000);
  const input = await again.page.$('#open-file');
  await input.uploadFile(file);
  await again.page.waitForFunction((t) => document.getElementById('yaml').value === t, {}, saved);
  assert.equal(await again.page.$eval('#runs', (e) => e.value), '20');
  await again.page.click('#run');
  assert.equal(await waitAttr(again.page, '#run-state', 'data-state', ['done', 'failed', 'cancelled'], 200000), 'done');
  const id2 = await again.page.evaluate(() => window.__studio.lastRun.id);
  assert.notEqual(id2, id);
  const strip = (t) => { const j = JSON.parse(t); delete j.timing; return j; };
  assert.deepEqual(strip((await api(`api/runs/${id2}/files/summary.json`)).text), strip((await api(`api/runs/${id}/files/summary.json`)).text));
  assert.equal((await api(`api/runs/${id2}/files/nav.csv`)).text, (await api(`api/runs/${id}/files/nav.csv`)).text);
  assert.deepEqual(again.problems, []);
  await again.page.close();
  assert.deepEqual(problems, []);
  await page.close();
});

test('Cancel stops a running campaign; a GPX track becomes waypoints', { skip: why || false, timeout: 200000 }, async () => {
  const { page, problems } = await openPage(browser, server.url);
  await waitAttr(page, '#estimate', 'data-state', ['ok', 'error', 'invalid'], 60000);
  await page.$eval('#runs', (e) => { e.value = ''; });
  await page.type('#runs', '200');
  await page.click('#run');
  await waitAttr(page, '#run-state', 'data-state', ['running', 'done', 'failed'], 120000);
  assert.equal(await page.$eval('#cancel', (b) => b.disabled), false);
  await page.click('#cancel');
  assert.equal(await waitAttr(page, '#run-state', 'data-state', ['done', 'failed', 'cancelled'], 60000), 'cancelled');
  assert.equal(await page.$eval('#run', (b) => b.disabled), false);
  // A GPX track of five points around the Brandenburg Gate.
  const pts = [[52.5163, 13.3777], [52.5170, 13.3800], [52.5180, 13.3820], [52.5175, 13.3850], [52.5160, 13.3860]];
  const gpx = `<?xml version="1.0"?><gpx version="1.1" creator="test"><trk><trkseg>${pts.map(([la, lo]) => `<trkpt lat="${la}" lon="${lo}"/>`).join('')}</trkseg></trk></gpx>`;
  const file = join(mkdtempSync(join(tmpdir(), 'studio-')), 'track.gpx');
  writeFileSync(file, gpx);
  await (await page.$('#open-file')).uploadFile(file);
  await page.waitForFunction(() => document.querySelectorAll('#wp-list li').length === 5);
  const yaml = await page.$eval('#yaml', (e) => e.value);
  assert.match(yaml, /lat_deg: 52\.5163/);
  assert.equal(await waitAttr(page, '#estimate', 'data-state', ['ok', 'error', 'invalid'], 60000), 'ok',
    await page.$eval('#yaml-status', (e) => e.textContent));
  await page.screenshot({ path: shotPath('D1-gpx-waypoints.png') });
  // A KML line string (lon,lat[,h] triples) likewise.
  const kml = `<?xml version="1.0"?><kml xmlns="http://www.opengis.net/kml/2.2"><Placemark><LineString><coordinates>
    13.3777,52.5163,0 13.3800,52.5170,0 13.3820,52.5180,0</coordinates></LineString></Placemark></kml>`;
  const kfile = join(mkdtempSync(join(tmpdir(), 'studio-')), 'track.kml');
  writeFileSync(kfile, kml);
  await (await page.$('#open-file')).uploadFile(kfile);
  await page.waitForFunction(() => document.querySelectorAll('#wp-list li').length === 3);
  assert.deepEqual(problems, []);
  await page.close();
});

test('tablet-sized window and keyboard: tabs by arrow keys, the YAML view reports reader errors', { skip: why || false, timeout: 120000 }, async () => {
  const { page, problems } = await openPage(browser, server.url, 820, 1180);
  await waitAttr(page, '#estimate', 'data-state', ['ok', 'error', 'invalid'], 60000);
  const overflow = await page.evaluate(() => document.documentElement.scrollWidth - window.innerWidth);
  assert.ok(overflow <= 0, `no horizontal scrolling at 820 px (${overflow} px too wide)`);
  // Waypoints without a mouse: Draw, then Add at map centre by the keyboard, panning between.
  await page.focus('#draw-waypoints');
  await page.keyboard.press('Enter');
  await page.focus('#add-centre');
  await page.keyboard.press('Enter');
  await page.waitForFunction(() => document.querySelectorAll('#wp-list li').length === 1);
  await page.focus('#map');
  const c0 = await page.evaluate(() => window.__studio.map.centre());
  for (let i = 0; i < 4; ++i) await page.keyboard.press('ArrowRight');
  // The pan is animated: wait until the view has settled east of where it was.
  await page.waitForFunction((x0) => {
    const v = window.__studio.map.map.getView();
    return !v.getAnimating() && window.__studio.map.centre()[0] > x0;
  }, { polling: 50 }, c0[0]);
  await page.focus('#add-centre');
  await page.keyboard.press('Enter');
  await page.waitForFunction(() => document.querySelectorAll('#wp-list li').length === 2);
  const [p1, p2] = await page.$$eval('#wp-list li', (ls) => ls.map((l) => l.textContent.match(/^N (-?\d+) m, E (-?\d+) m/).slice(1).map(Number)));
  assert.ok(p2[1] > p1[1] + 50 && Math.abs(p2[0] - p1[0]) < 5, `the map panned east between the points (${p1} -> ${p2})`);
  await page.focus('#tab-map');
  await page.keyboard.press('ArrowRight');
  await page.keyboard.press('ArrowRight');
  await page.keyboard.press('ArrowRight');
  assert.equal(await page.evaluate(() => document.activeElement.id), 'tab-yaml');
  assert.equal(await page.$eval('#view-yaml', (e) => e.hidden), false);
  // A reader error is shown with its line and column, and the estimate says the scene is invalid.
  await page.focus('#yaml');
  await page.$eval('#yaml', (e) => {
    e.value = e.value.replace(/rate_hz: 100/, 'rate_hz: -5');
    e.dispatchEvent(new Event('input'));
  });
  assert.equal(await waitAttr(page, '#estimate', 'data-state', ['ok', 'error', 'invalid'], 60000), 'invalid');
  const msg = await page.$eval('#yaml-status', (e) => e.textContent);
  assert.match(msg, /^\d+:\d+: \S*rate_hz/);
  await page.screenshot({ path: shotPath('C1-tablet-yaml-error.png') });
  assert.deepEqual(problems, []);
  await page.close();
});
