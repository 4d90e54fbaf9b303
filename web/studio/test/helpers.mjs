// Shared set-up of the studio's end-to-end tests: the real `navsim serve` on a free port with a
// fresh data directory, Debian's chromium through puppeteer-core, and the page checks every test
// makes (no page errors, canvases with ink, screenshots into the build tree).
import { spawn, spawnSync } from 'node:child_process';
import { createRequire } from 'node:module';
import { mkdtempSync, mkdirSync, rmSync, existsSync, readdirSync, readFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
export const env = {
  navsim: process.env.NAVSIM,
  studio: process.env.NAV_STUDIO_DIR,
  nodeModules: process.env.NAV_NODE_MODULES || join(here, '..', 'node_modules'),
  chromium: process.env.NAV_CHROMIUM || '/usr/bin/chromium',
  shots: process.env.NAV_SHOTS || join(tmpdir(), 'navsim-studio-shots'),
};
const requireNm = createRequire(join(env.nodeModules, 'noop.js'));

// Why the tests cannot run here ('' when they can).
export function missing() {
  if (!env.navsim || !existsSync(env.navsim)) return 'NAVSIM (the navsim executable) is not set';
  const help = spawnSync(env.navsim, ['serve', '--help'], { encoding: 'utf8' });
  if (help.status !== 0) return `navsim serve is not built here (navsim serve --help: exit ${help.status})`;
  if (!env.studio || !existsSync(join(env.studio, 'manifest.txt'))) return 'NAV_STUDIO_DIR has no built studio';
  if (!existsSync(env.chromium)) return `no chromium at ${env.chromium}`;
  return '';
}

// Start `navsim serve --port 0`; resolves with {url, stop(), output()} once the first stdout line
// ("listening on http://HOST:PORT/") arrived.
// extra: more arguments of navsim serve (e.g. ['--config', FILE]).
export function startServer(extra = []) {
  const dataDir = mkdtempSync(join(tmpdir(), 'navsim-serve-'));
  const proc = spawn(env.navsim, ['serve', '--port', '0', '--data-dir', dataDir, '--studio-dir', env.studio, ...extra],
    { stdio: ['ignore', 'pipe', 'pipe'] });
  let out = '', err = '';
  proc.stderr.on('data', (d) => { err += d; });
  return new Promise((resolve, reject) => {
    const onData = (d) => {
      out += d;
      const nl = out.indexOf('\n');
      if (nl < 0) return;
      proc.stdout.off('data', onData);
      proc.stdout.on('data', (x) => { out += x; });
      const m = out.slice(0, nl).match(/^listening on (http:\/\/[^ ]+\/)$/);
      if (!m) { proc.kill('SIGTERM'); reject(new Error(`unexpected first line: ${out.slice(0, nl)}\n${err}`)); return; }
      resolve({
        url: m[1],
        output: () => out + err,
        stop: () => new Promise((res) => {
          if (proc.exitCode !== null) { rmSync(dataDir, { recursive: true, force: true }); res(proc.exitCode); return; }
          proc.once('exit', (code) => { rmSync(dataDir, { recursive: true, force: true }); res(code); });
          proc.kill('SIGTERM');
        }),
      });
    };
    proc.stdout.on('data', onData);
    proc.once('exit', (code) => reject(new Error(`navsim serve exited (${code}) before listening:\n${err}`)));
  });
}

export async function launch() {
  const puppeteer = requireNm('puppeteer-core');
  return puppeteer.launch({
    executablePath: env.chromium,
    headless: true,
    args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--disable-gpu-sandbox'],
  });
}

// A page that records every page error, console error and failed request.
export async function openPage(browser, url, width = 1280, height = 800) {
  const page = await browser.newPage();
  await page.setViewport({ width, height });
  const problems = [];
  page.on('pageerror', (e) => problems.push(`pageerror: ${e.message}`));
  // Chrome logs every HTTP error answer as a console error without its address; such answers are
  // judged by the response listener below (with the address), the other console errors here.
  page.on('console', (m) => {
    if (m.type() !== 'error' && m.type() !== 'assert') return;
    if (/^Failed to load resource: the server responded with a status of \d+/.test(m.text())) return;
    problems.push(`console ${m.type()}: ${m.text()}`);
  });
  // Expected error answers: 422 from /api/validate for a scene being edited (shown to the user as
  // the reader's messages), 429 from /api/validate and /api/estimate (the page waits and retries).
  page.on('response', (r) => {
    if (r.status() < 400) return;
    const u = new URL(r.url());
    if (r.status() === 422 && u.pathname === '/api/validate') return;
    if (r.status() === 429 && (u.pathname === '/api/validate' || u.pathname === '/api/estimate')) return;
    problems.push(`HTTP ${r.status()}: ${r.url()}`);
  });
  page.on('requestfailed', (r) => {
    const why = r.failure() && r.failure().errorText;
    // The page closes a run's event stream itself once the run has ended (by design, not a fault).
    if (why === 'net::ERR_ABORTED' && /\/api\/runs\/[0-9a-f]{32}\/events$/.test(r.url())) return;
    problems.push(`request failed: ${r.url()} ${why}`);
  });
  page.on('request', (r) => { if (!r.url().startsWith(url) && !r.url().startsWith('blob:') && !r.url().startsWith('data:')) problems.push(`external request: ${r.url()}`); });
  await page.goto(url, { waitUntil: 'load' });
  await page.waitForSelector('body[data-ready="1"]', { timeout: 60000 });
  return { page, problems };
}

// Pixels that differ from the most common colour of the canvases under a selector (all of them
// composed in document order, as the user sees them).
// colours: optional [[r, g, b], ...]: the count of pixels within 40 of each (per channel).
export function canvasInk(page, selector, colours = []) {
  return page.evaluate((sel, cols) => {
    const host = document.querySelector(sel);
    const cvs = host.tagName === 'CANVAS' ? [host] : [...host.querySelectorAll('canvas')];
    if (!cvs.length) return { canvases: 0, ink: 0, pixels: 0 };
    const w = Math.max(...cvs.map((c) => c.width)), h = Math.max(...cvs.map((c) => c.height));
    const out = document.createElement('canvas');
    out.width = w; out.height = h;
    const ctx = out.getContext('2d');
    for (const c of cvs) if (c.width && c.height) ctx.drawImage(c, 0, 0);
    const d = ctx.getImageData(0, 0, w, h).data;
    const count = new Map();
    for (let i = 0; i < d.length; i += 4 * 7) {
      const k = (d[i] << 16) | (d[i + 1] << 8) | d[i + 2];
      count.set(k, (count.get(k) || 0) + 1);
    }
    let bg = 0, best = -1;
    for (const [k, n] of count) if (n > best) { best = n; bg = k; }
    let ink = 0;
    const near = cols.map(() => 0);
    for (let i = 0; i < d.length; i += 4) {
      const k = (d[i] << 16) | (d[i + 1] << 8) | d[i + 2];
      if (d[i + 3] > 0 && k !== bg) ++ink;
      cols.forEach((c, j) => {
        if (Math.abs(d[i] - c[0]) <= 40 && Math.abs(d[i + 1] - c[1]) <= 40 && Math.abs(d[i + 2] - c[2]) <= 40) ++near[j];
      });
    }
    return { canvases: cvs.length, ink, pixels: w * h, colours: near };
  }, selector, colours);
}

// Click a download link and wait until its file is complete in a new directory; its text.
export async function download(browser, page, selector) {
  const dir = mkdtempSync(join(tmpdir(), 'studio-dl-'));
  const session = await browser.target().createCDPSession();
  await session.send('Browser.setDownloadBehavior', { behavior: 'allow', downloadPath: dir, eventsEnabled: true });
  const done = new Promise((resolve, reject) => {
    session.on('Browser.downloadProgress', (e) => {
      if (e.state === 'completed') resolve();
      if (e.state === 'canceled') reject(new Error('download cancelled'));
    });
  });
  await page.click(selector);
  await done;
  const files = readdirSync(dir);
  const text = readFileSync(join(dir, files[0]), 'utf8');
  rmSync(dir, { recursive: true, force: true });
  await session.detach();
  return { name: files[0], text };
}

export function shotPath(name) {
  mkdirSync(env.shots, { recursive: true });
  return join(env.shots, name);
}

// Wait until an element's attribute takes one of the values (polls the DOM, never a fixed time).
export async function waitAttr(page, selector, attr, values, timeout = 60000) {
  await page.waitForFunction((sel, a, vals) => {
    const el = document.querySelector(sel);
    return el && vals.includes(el.getAttribute(a));
  }, { timeout, polling: 100 }, selector, attr, values);
  return page.$eval(selector, (el, a) => el.getAttribute(a), attr);
}
