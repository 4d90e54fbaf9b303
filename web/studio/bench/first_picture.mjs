// navsim bench case "studio-first-picture": scene to first picture in the browser. Starts the
// real `navsim serve`, opens the studio in Debian's chromium (a fresh page each time, so the
// bundle, the schema and the catalogs load as for a new visitor) and reads the page's own
// timings of urban-drive, its default scene: from the navigation start, and from choosing the
// scene in the library, to the estimate shown and the map drawn with the path.
//   node first_picture.mjs SAMPLES   (env as the tests: NAVSIM, NAV_STUDIO_DIR, NAV_NODE_MODULES)
// Prints one line: first_picture_ms: samples=N median=.. p90=.. select_median=.. preview_median=..
// estimate_median=.. loadavg=.. (preview: the map drawn with the path, before the estimate)
import { missing, startServer, launch, openPage, waitAttr } from '../test/helpers.mjs';
import { loadavg } from 'node:os';

const n = Math.max(1, +process.argv[2] || 5);
const why = missing();
if (why) {
  console.log(`first_picture_ms: not measured: ${why}`);
  process.exit(3);
}
const server = await startServer();
const browser = await launch();
const page_ms = [], select_ms = [], est_ms = [], preview_ms = [];
const get = (p) => p.evaluate(() => window.__studio.timings);
const waitPicture = (p) => p.waitForFunction(() => window.__studio.timings.scene_to_picture_ms !== undefined, { timeout: 60000, polling: 20 });
try {
  // One warm-up visit (the server reads its catalogs and scene library on first use).
  const warm = await openPage(browser, server.url);
  await waitAttr(warm.page, '#estimate', 'data-state', ['ok', 'error', 'invalid']);
  await warm.page.close();
  for (let i = 0; i < n; ++i) {
    const { page, problems } = await openPage(browser, server.url);
    await waitPicture(page);
    const t = await get(page);
    if ((await page.$eval('#estimate', (e) => e.dataset.state)) !== 'ok') throw new Error('estimate failed: ' + (await page.$eval('#estimate', (e) => e.textContent)));
    page_ms.push(t.page_to_picture_ms);
    // Choosing the scene again from the library (page already loaded).
    await page.select('#library', 'paper-parametric');
    await waitAttr(page, '#estimate', 'data-state', ['ok', 'error', 'invalid']);
    await page.select('#library', 'urban-drive');
    await waitPicture(page);
    const t2 = await get(page);
    select_ms.push(t2.scene_to_picture_ms);
    est_ms.push(t2.estimate_ms);
    preview_ms.push(t2.preview_ms);
    if (problems.length) throw new Error(problems.join('; '));
    await page.close();
  }
} finally {
  await browser.close();
  await server.stop();
}
const q = (a, f) => { const s = [...a].sort((x, y) => x - y); return s[Math.min(s.length - 1, Math.floor(f * s.length))]; };
console.log(`first_picture_ms: samples=${n} median=${q(page_ms, 0.5).toFixed(0)} p90=${q(page_ms, 0.9).toFixed(0)} ` +
  `select_median=${q(select_ms, 0.5).toFixed(0)} preview_median=${q(preview_ms, 0.5).toFixed(0)} estimate_median=${q(est_ms, 0.5).toFixed(0)} loadavg=${loadavg()[0].toFixed(2)}`);
