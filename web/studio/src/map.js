// The map (OpenLayers) over offline data shipped in the bundle: the Natural Earth shaded relief,
// GSHHS land and lakes (converted at build time from the files navview's map reads), a
// graticule and a scale bar. Layers: the reference (planned waypoints or the run's truth), the
// estimate (nav.csv), the GNSS fixes (gnss.csv, outages leave gaps) and the waypoint markers.
import Map from 'ol/Map.js';
import View from 'ol/View.js';
import TileLayer from 'ol/layer/Tile.js';
import ImageLayer from 'ol/layer/Image.js';
import VectorLayer from 'ol/layer/Vector.js';
import Graticule from 'ol/layer/Graticule.js';
import VectorSource from 'ol/source/Vector.js';
import ImageStatic from 'ol/source/ImageStatic.js';
import GeoJSON from 'ol/format/GeoJSON.js';
import Feature from 'ol/Feature.js';
import LineString from 'ol/geom/LineString.js';
import Point from 'ol/geom/Point.js';
import MultiPoint from 'ol/geom/MultiPoint.js';
import { Style, Stroke, Fill, Circle as CircleStyle, Text } from 'ol/style.js';
import { fromLonLat, toLonLat } from 'ol/proj.js';
import { defaults as defaultControls, ScaleLine } from 'ol/control.js';
import { boundingExtent } from 'ol/extent.js';
import { nedToLonLat, lonLatToNed } from './geo.js';

void TileLayer;

export { nedToLonLat, lonLatToNed };

export class StudioMap {
  constructor(target, creditsEl) {
    this.origin = { lat: 0, lon: 0 };
    this.onClick = null;
    const geo = new GeoJSON({ featureProjection: 'EPSG:3857' });
    this.relief = new ImageLayer({
      source: new ImageStatic({ url: 'map/relief.png', imageExtent: [-180, -90, 180, 90], projection: 'EPSG:4326' }),
      opacity: 0.85,
      minResolution: 300, // from a few hundred km across, as navview's map
    });
    // Coastlines and lakes from regional scale up (navview: views wider than 15 km); at street
    // scale they are neither drawn nor loaded (OpenLayers loads a layer's source when it shows).
    const land = new VectorLayer({
      minResolution: 18,
      source: new VectorSource({ url: 'map/land.geojson', format: geo }),
      style: new Style({ fill: new Fill({ color: 'rgba(236,232,220,0.55)' }), stroke: new Stroke({ color: '#4d5c73', width: 1.2 }) }),
    });
    const lakes = new VectorLayer({
      minResolution: 18,
      source: new VectorSource({ url: 'map/lakes.geojson', format: geo }),
      style: new Style({ fill: new Fill({ color: 'rgba(170,200,230,0.8)' }), stroke: new Stroke({ color: '#4d5c73', width: 0.8 }) }),
    });
    // The sources report load errors (a bundle built without map data): no console noise, a note.
    for (const l of [land, lakes]) l.getSource().on('featuresloaderror', () => { this.missing = true; });
    const graticule = new Graticule({ strokeStyle: new Stroke({ color: 'rgba(60,70,90,0.35)', width: 1, lineDash: [2, 3] }), showLabels: true, wrapX: false, minResolution: 25 });
    // At street scale (where the graticule is off) a local metric grid around the scene origin,
    // as navview's map draws: lines every 1, 2 or 5 x 10^k m, about eight across the view.
    this.gridSrc = new VectorSource();
    this.refSrc = new VectorSource();
    this.estSrc = new VectorSource();
    this.refASrc = new VectorSource(); // A/B comparison: run A's reference (when it differs) and estimate
    this.estASrc = new VectorSource();
    this.fixSrc = new VectorSource();
    this.wpSrc = new VectorSource();
    const line = (color, width, dash) => new Style({ stroke: new Stroke({ color, width, lineDash: dash }) });
    this.map = new Map({
      target,
      keyboardEventTarget: target, // the focusable #map: arrow keys pan, + and - zoom
      controls: defaultControls({ attribution: false }).extend([new ScaleLine()]),
      layers: [
        this.relief, land, lakes, graticule,
        new VectorLayer({ source: this.gridSrc, maxResolution: 25, style: new Style({ stroke: new Stroke({ color: 'rgba(60,70,90,0.28)', width: 1 }) }) }),
        new VectorLayer({ source: this.fixSrc, style: new Style({ image: new CircleStyle({ radius: 2.2, fill: new Fill({ color: '#2a9d3a' }) }) }) }),
        new VectorLayer({ source: this.refASrc, style: line('#8a8f98', 3, [2, 4]) }),
        new VectorLayer({ source: this.refSrc, style: line('#111', 3) }),
        new VectorLayer({ source: this.estASrc, style: line('#1f5fbf', 2) }),
        new VectorLayer({ source: this.estSrc, style: line('#d1401f', 2, [6, 4]) }),
        new VectorLayer({
          source: this.wpSrc,
          style: (f) => new Style({
            image: new CircleStyle({ radius: 7, fill: new Fill({ color: '#1f5fbf' }), stroke: new Stroke({ color: '#fff', width: 2 }) }),
            text: new Text({ text: f.get('label') || '', offsetY: -14, font: 'bold 12px sans-serif', fill: new Fill({ color: '#10213d' }), stroke: new Stroke({ color: '#fff', width: 3 }) }),
          }),
        }),
      ],
      // Street scale until a scene is loaded and fitted: the world's coastlines are not parsed
      // for a picture nobody sees.
      view: new View({ center: fromLonLat([0, 0]), zoom: 16, maxZoom: 21 }),
    });
    this.map.on('moveend', () => this.metricGrid());
    this.map.on('click', (ev) => {
      if (!this.onClick) return;
      const [lon, lat] = toLonLat(ev.coordinate);
      this.onClick(lon, lat);
    });
    fetch('map/credits.json').then((r) => (r.ok ? r.json() : { credits: [] })).then((c) => {
      creditsEl.textContent = `Map data: ${c.credits.join(' ')} Graticule and scale drawn locally; no tiles are fetched.`;
    }).catch(() => {});
  }
  setOrigin(lat, lon) { this.origin = { lat, lon }; this.metricGrid(); }
  metricGrid() {
    this.gridSrc.clear();
    const view = this.map.getView();
    if (!(view.getResolution() < 25)) return;
    const ext = view.calculateExtent(this.map.getSize());
    const [w, sth] = toLonLat([ext[0], ext[1]]), [e, nth] = toLonLat([ext[2], ext[3]]);
    const [n0, e0] = lonLatToNed(this.origin, w, sth), [n1, e1] = lonLatToNed(this.origin, e, nth);
    const span = Math.max(e1 - e0, n1 - n0);
    const p = Math.pow(10, Math.floor(Math.log10(span / 8)));
    const step = [1, 2, 5, 10].map((k) => k * p).find((x) => span / x <= 10);
    const lines = [];
    for (let n = Math.ceil(n0 / step) * step; n <= n1; n += step) lines.push([[n, e0], [n, e1]]);
    for (let x = Math.ceil(e0 / step) * step; x <= e1; x += step) lines.push([[n0, x], [n1, x]]);
    for (const l of lines) this.gridSrc.addFeature(new Feature(new LineString(l.map(([a, b]) => fromLonLat(nedToLonLat(this.origin, a, b))))));
    this.gridStep = step;
  }
  centre() { return toLonLat(this.map.getView().getCenter()); }
  // Pixel of a local NED point (for tests and keyboard help).
  pixelOfNed(n, e) { return this.map.getPixelFromCoordinate(fromLonLat(nedToLonLat(this.origin, n, e))); }
  lineFromNed(ns, es, origin = this.origin) {
    const pts = [];
    for (let i = 0; i < ns.length; ++i) pts.push(fromLonLat(nedToLonLat(origin, ns[i], es[i])));
    return pts;
  }
  // origin: of the NED coordinates (a run's own scene origin; default the scene's being edited).
  setReference(ns, es, origin = this.origin) {
    this.refSrc.clear();
    if (ns.length > 1) this.refSrc.addFeature(new Feature(new LineString(this.lineFromNed(ns, es, origin))));
  }
  setEstimate(ns, es, origin = this.origin) {
    this.estSrc.clear();
    if (ns && ns.length > 1) this.estSrc.addFeature(new Feature(new LineString(this.lineFromNed(ns, es, origin))));
  }
  // Run A of a comparison: its estimate, and its reference when the trajectories differ (null:
  // none); local NED about A's own scene origin {lat, lon} (null: the shown scene's).
  setCompare(origin, refN, refE, estN, estE) {
    this.refASrc.clear();
    this.estASrc.clear();
    const o = origin || this.origin;
    if (refN && refN.length > 1) this.refASrc.addFeature(new Feature(new LineString(this.lineFromNed(refN, refE, o))));
    if (estN && estN.length > 1) this.estASrc.addFeature(new Feature(new LineString(this.lineFromNed(estN, estE, o))));
  }
  // The first point of a drawn line ('ref', 'est', 'refA', 'estA') as local NED [n, e] about
  // `origin` (default the shown scene's), read back from the map's geometry; null when not drawn.
  firstNed(which, origin = this.origin) {
    const src = { ref: this.refSrc, est: this.estSrc, refA: this.refASrc, estA: this.estASrc }[which];
    const f = src && src.getFeatures()[0];
    if (!f) return null;
    const [lon, lat] = toLonLat(f.getGeometry().getFirstCoordinate());
    return lonLatToNed(origin, lon, lat);
  }
  setFixes(lons, lats) {
    this.fixSrc.clear();
    if (!lons || !lons.length) return;
    const pts = [];
    for (let i = 0; i < lons.length; ++i) pts.push(fromLonLat([lons[i], lats[i]]));
    this.fixSrc.addFeature(new Feature(new MultiPoint(pts)));
  }
  setWaypoints(points) {
    this.wpSrc.clear();
    points.forEach(([n, e], i) => {
      const f = new Feature(new Point(fromLonLat(nedToLonLat(this.origin, n, e))));
      f.set('label', String(i + 1));
      this.wpSrc.addFeature(f);
    });
  }
  // Zoom to what is drawn (reference, waypoints), with a minimum extent of about 400 m.
  fit() {
    const coords = [];
    for (const src of [this.refSrc, this.wpSrc, this.estSrc])
      src.forEachFeature((f) => {
        const g = f.getGeometry();
        const c = g.getType() === 'Point' ? [g.getCoordinates()] : g.getCoordinates();
        coords.push(...c);
      });
    if (!coords.length) {
      this.map.getView().setCenter(fromLonLat([this.origin.lon, this.origin.lat]));
      this.map.getView().setZoom(15);
      return;
    }
    let ext = boundingExtent(coords);
    const pad = 300;
    ext = [ext[0] - pad, ext[1] - pad, ext[2] + pad, ext[3] + pad];
    this.map.getView().fit(ext, { padding: [30, 30, 30, 30], maxZoom: 18 });
  }
  whenRendered() {
    return new Promise((res) => this.map.once('rendercomplete', res));
  }
}
