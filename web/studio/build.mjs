// Build of the browser studio: bundles src/main.js with esbuild, copies the page and its style,
// converts the offline map data (the same files navview's map reads: GSHHS coastlines and lakes
// as shapefiles and the Natural Earth shaded relief raster of Debian's python-cartopy-data) into
// GeoJSON and PNG inside the bundle, and writes manifest.txt: every file the server may serve,
// one relative path per line.
//
//   node build.mjs OUT_DIR [--map-data DIR]
//
// No file of the bundle refers to another origin: the page loads only what this script writes.
import { createRequire } from 'node:module';
import { mkdirSync, copyFileSync, writeFileSync, existsSync, rmSync, readdirSync, statSync, readFileSync } from 'node:fs';
import { dirname, join, resolve, relative } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
// The npm packages live in the build tree (NAV_NODE_MODULES, set by CMake) or, when the script is
// run by hand after `npm ci` here, next to this file.
const nodeModules = process.env.NAV_NODE_MODULES || join(here, 'node_modules');
const requireNm = createRequire(join(nodeModules, 'noop.js'));
const { build } = requireNm('esbuild');
const shapefile = requireNm('shapefile');
const args = process.argv.slice(2);
if (args.length < 1) {
  console.error('usage: node build.mjs OUT_DIR [--map-data DIR]');
  process.exit(2);
}
const out = resolve(args[0]);
let mapData = process.env.NAVVIEW_MAP_DATA || '/usr/share/cartopy/data';
const i = args.indexOf('--map-data');
if (i >= 0 && args[i + 1]) mapData = args[i + 1];

// Files of an earlier build (its manifest) are removed; nothing else in OUT_DIR is touched.
const oldManifest = join(out, 'manifest.txt');
if (existsSync(oldManifest))
  for (const f of readFileSync(oldManifest, 'utf8').split('\n'))
    if (f && !f.includes('..')) rmSync(join(out, f), { force: true });
mkdirSync(join(out, 'map'), { recursive: true });

await build({
  entryPoints: [join(here, 'src/main.js')],
  bundle: true,
  minify: true,
  sourcemap: false,
  format: 'esm',
  target: ['es2020'],
  outfile: join(out, 'studio.js'),
  nodePaths: [nodeModules],
  legalComments: 'external',
  logLevel: 'warning',
});
// The CSS of the npm packages (OpenLayers, uPlot) and ours, in one file.
await build({
  entryPoints: [join(here, 'src/studio.css')],
  bundle: true,
  minify: true,
  outfile: join(out, 'studio.css'),
  nodePaths: [nodeModules],
  logLevel: 'warning',
});
copyFileSync(join(here, 'src/index.html'), join(out, 'index.html'));
copyFileSync(join(here, 'src/favicon.svg'), join(out, 'favicon.svg'));

// Offline map data. Coordinates are rounded to 1e-4 degree (about 10 m), far below the crude
// coastline's own resolution (about 25 km), to keep the files small.
const credits = [];
async function shpToGeoJSON(shp, name, what) {
  if (!existsSync(shp)) {
    credits.push(`${what}: not available at build time (${shp} missing)`);
    return false;
  }
  const round = (c) => Math.round(c * 1e4) / 1e4;
  const features = [];
  const src = await shapefile.open(shp);
  for (;;) {
    const r = await src.read();
    if (r.done) break;
    const g = r.value.geometry;
    if (!g) continue;
    const mapRing = (ring) => ring.map(([x, y]) => [round(x), round(y)]);
    if (g.type === 'Polygon') g.coordinates = g.coordinates.map(mapRing);
    else if (g.type === 'MultiPolygon') g.coordinates = g.coordinates.map((p) => p.map(mapRing));
    features.push({ type: 'Feature', properties: {}, geometry: g });
  }
  writeFileSync(join(out, 'map', name), JSON.stringify({ type: 'FeatureCollection', features }));
  return true;
}
const gshhs = [
  [join(mapData, 'shapefiles/gshhs/c/GSHHS_c_L1.shp'), 'land.geojson', 'land (GSHHS crude, level 1)'],
  [join(mapData, 'shapefiles/gshhs/l/GSHHS_l_L2.shp'), 'lakes.geojson', 'lakes (GSHHS low, level 2)'],
];
let anyShp = false;
for (const [shp, name, what] of gshhs) anyShp = (await shpToGeoJSON(shp, name, what)) || anyShp;
if (anyShp)
  credits.push(
    'Coastlines and lakes: GSHHG (Global Self-consistent, Hierarchical, High-resolution Geography ' +
      'Database) by P. Wessel and W. H. F. Smith, LGPL, as shipped by Debian python-cartopy-data.'
  );
const relief = join(mapData, 'raster/natural_earth/50-natural-earth-1-downsampled.png');
if (existsSync(relief)) {
  copyFileSync(relief, join(out, 'map', 'relief.png'));
  credits.push('Shaded relief: Natural Earth (public domain), as shipped by Debian python-cartopy-data.');
} else {
  credits.push(`shaded relief: not available at build time (${relief} missing)`);
}
writeFileSync(join(out, 'map', 'credits.json'), JSON.stringify({ credits }, null, 1));

// manifest.txt: every file of the bundle (the server serves only these): what this script wrote.
const files = [];
(function walk(d) {
  for (const e of readdirSync(d)) {
    const p = join(d, e);
    if (statSync(p).isDirectory()) walk(p);
    else files.push(relative(out, p));
  }
})(join(out, 'map'));
files.push('index.html', 'favicon.svg', 'studio.js', 'studio.css', 'manifest.txt');
if (existsSync(join(out, 'studio.js.LEGAL.txt'))) files.push('studio.js.LEGAL.txt');
files.sort();
writeFileSync(join(out, 'manifest.txt'), files.join('\n') + '\n');
console.log(`studio: ${files.length} files in ${out}`);
