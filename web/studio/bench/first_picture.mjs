// navsim bench case "studio-first-picture": scene to first picture in the browser. Starts the
// real `navsim serve`, opens the studio in Debian's chromium (a fresh page each time, so the
// bundle, the schema and the catalogs load as for a new visitor) and reads the page's own
// timings of urban-drive, its default scene: from the navigation start, and from choosing the
// scene in the library, to the estimate shown and the map drawn with the path.
//   node first_picture.mjs SAMPLES   (env as the tests: NAVSIM, NAV_STUDIO_DIR, NAV_NODE_MODULES)
// Prints one line: first_picture_ms: samples=N median=.. p90=.. before_scene_median=..
// estimate_median=.. preview_median=.. cached_median=.. cached_p90=.. cached_estimate_median=..
// select_median=.. select_preview_median=.. select_estimate_median=.. loadavg=..
// median/p90: a fresh page to the estimate shown and the map drawn, every estimate computed (the
// server's answer cache off); before_scene: the page, bundle, schema and catalogs before the
// scene loads; estimate: validate + estimate round trip; preview: the map drawn with the path;
// cached_*: the same with the server as configured by default (the answer cached); select_*:
// choosing urban-drive again in the library of a loaded page (cache on).
import { missing, startServer, launch, openPage, waitAttr } from '../test/helpers.mjs';
import { loadavg, tmpdir } from 'node:os';
import { mkdtempSync, writeFileSync, rmSync } from 'node:fs';
import { join, dirname } from 'node:path';

const n = Math.max(1, +process.argv[2] || 5);
const why = missing();
if (why) {
  console.log(`first_picture_ms: not measured: ${why}`);
  process.exit(3);
}
// Two servers: as served (its cache of estimate answers on: the warm-up visit leaves urban-drive's
// answer there, as any earlier visitor would) and cold (estimate_cache_entries = 0: every estimate
// computed by navsim estimate, as for a scene nobody posted before).
const coldConf = join(mkdtempSync(join(tmpdir(), 'navsim-fp-')), 'cold.conf');
writeFileSync(coldConf, 'estimate_cache_entries = 0\n');
const browser = await launch();
const q = (a, f) => { const s = [...a].sort((x, y) => x - y); return s[Math.min(s.length - 1, Math.floor(f * s.length))]; };
const get = (p) => p.evaluate(() => window.__studio.timings);
const waitPicture = (p) => p.waitForFunction(() => window.__studio.timings.scene_to_picture_ms !== undefined, { timeout: 60000, polling: 20 });
async function measure(extra, select) {
  const server = await startServer(extra);
  const m = { page: [], before: [], select: [], est: [], preview: [], first_est: [], first_preview: [] };
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
      m.page.push(t.page_to_picture_ms);
      m.before.push(t.page_to_picture_ms - t.scene_to_picture_ms); // page, bundle, schema, catalogs
      m.first_est.push(t.estimate_ms);
      m.first_preview.push(t.preview_ms);
      if (select) {
        // Choosing the scene again from the library (page already loaded).
        await page.select('#library', 'paper-parametric');
        await waitAttr(page, '#estimate', 'data-state', ['ok', 'error', 'invalid']);
        await page.select('#library', 'urban-drive');
        await waitPicture(page);
        const t2 = await get(page);
        m.select.push(t2.scene_to_picture_ms);
        m.est.push(t2.estimate_ms);
        m.preview.push(t2.preview_ms);
      }
      if (problems.length) throw new Error(problems.join('; '));
      await page.close();
    }
  } finally {
    await server.stop();
  }
  return m;
}
let warm, cold;
try {
  cold = await measure(['--config', coldConf], false);
  warm = await measure([], true);
} finally {
  await browser.close();
  rmSync(dirname(coldConf), { recursive: true, force: true });
}
const med = (a) => q(a, 0.5).toFixed(0);
console.log(`first_picture_ms: samples=${n} median=${med(cold.page)} p90=${q(cold.page, 0.9).toFixed(0)} ` +
  `before_scene_median=${med(cold.before)} estimate_median=${med(cold.first_est)} preview_median=${med(cold.first_preview)} ` +
  `cached_median=${med(warm.page)} cached_p90=${q(warm.page, 0.9).toFixed(0)} cached_estimate_median=${med(warm.first_est)} ` +
  `select_median=${med(warm.select)} select_preview_median=${med(warm.preview)} select_estimate_median=${med(warm.est)} ` +
  `loadavg=${loadavg()[0].toFixed(2)}`);
