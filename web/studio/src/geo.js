// Local NED coordinates about a scene origin <-> geodetic latitude and longitude (WGS-84), for
// the map; and the change of local frame between two scene origins, for drawing one run's path in
// another run's frame (A/B comparison). The map's formulas, for small offsets: the meridian and
// prime-vertical radii of curvature at the origin's latitude,
//   lat = lat0 + n / R_M(lat0),  lon = lon0 + e / (R_N(lat0) cos lat0),
//   R_N = a / W,  R_M = a (1 - e^2) / W^3,  W = sqrt(1 - e^2 sin^2 lat0),
// heights along the local vertical (h = h0 - d). Origins: {lat, lon, h} in degrees and metres.
const A = 6378137.0, E2 = 6.69437999014e-3;
function radii(latDeg) {
  const s = Math.sin((latDeg * Math.PI) / 180);
  const w = Math.sqrt(1 - E2 * s * s);
  return { rn: A / w, rm: (A * (1 - E2)) / (w * w * w) };
}
export function nedToLonLat(origin, n, e) {
  const { rn, rm } = radii(origin.lat);
  const lat = origin.lat + ((n / rm) * 180) / Math.PI;
  const lon = origin.lon + ((e / (rn * Math.cos((origin.lat * Math.PI) / 180))) * 180) / Math.PI;
  return [lon, lat];
}
export function lonLatToNed(origin, lon, lat) {
  const { rn, rm } = radii(origin.lat);
  return [((lat - origin.lat) * Math.PI * rm) / 180, ((lon - origin.lon) * Math.PI * rn * Math.cos((origin.lat * Math.PI) / 180)) / 180];
}
const sameOrigin = (a, b) => a.lat === b.lat && a.lon === b.lon && (a.h || 0) === (b.h || 0);

// Exact maths for taking one run's local NED to another's. navsim's local NED about an origin is
// the tangent frame r_ned = C_e_n (r_ecef - r0_ecef) (exact, through ECEF), and the formulas above
// are only its first-order approximation: 0.03 m off for origins 583 m apart, 14 m at 12 km,
// 240 m at 50 km (mostly the turn of north between the two longitudes). So the change of frame
// goes through the geodetic origins exactly:
//   r_ecef = (R_N + h) cos lat cos lon, (R_N + h) cos lat sin lon, (R_N (1 - e^2) + h) sin lat
//   C_e_n rows: north (-sin lat cos lon, -sin lat sin lon, cos lat), east (-sin lon, cos lon, 0),
//               down (-cos lat cos lon, -cos lat sin lon, -sin lat)
//   ned_to = C_e_n(to) C_e_n(from)^T ned_from + C_e_n(to) (r0_from - r0_to).
function ecef(o) {
  const la = (o.lat * Math.PI) / 180, lo = (o.lon * Math.PI) / 180, h = o.h || 0;
  const rn = A / Math.sqrt(1 - E2 * Math.sin(la) ** 2);
  return [(rn + h) * Math.cos(la) * Math.cos(lo), (rn + h) * Math.cos(la) * Math.sin(lo), (rn * (1 - E2) + h) * Math.sin(la)];
}
function cen(o) {
  const la = (o.lat * Math.PI) / 180, lo = (o.lon * Math.PI) / 180;
  const [sl, cl, so, co] = [Math.sin(la), Math.cos(la), Math.sin(lo), Math.cos(lo)];
  return [[-sl * co, -sl * so, cl], [-so, co, 0], [-cl * co, -cl * so, -sl]];
}
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];

// A function (n, e, d) -> [n, e, d] taking NED about origin `from` to NED about origin `to`
// ({lat, lon, h}); the identity (the same numbers) when the origins are equal or either is
// unknown.
export function nedFrameChange(from, to) {
  if (!from || !to || sameOrigin(from, to)) return (n, e, d) => [n, e, d];
  const cf = cen(from), ct = cen(to);
  const r0f = ecef(from), r0t = ecef(to);
  const dr = [r0f[0] - r0t[0], r0f[1] - r0t[1], r0f[2] - r0t[2]];
  const t = ct.map((row) => dot(row, dr));
  // M = C_e_n(to) C_e_n(from)^T: M[i][j] = row i of `to` . row j of `from`.
  const M = ct.map((ri) => cf.map((rj) => dot(ri, rj)));
  return (n, e, d) => M.map((row, i) => row[0] * n + row[1] * e + row[2] * d + t[i]);
}
// Horizontal distance (m) of origin `from` from origin `to`, measured in `to`'s local frame.
export function originDistance(from, to) {
  if (!from || !to) return 0;
  const [n, e] = nedFrameChange(from, to)(0, 0, 0);
  return Math.hypot(n, e);
}
// "583 m", "12.3 km".
export const formatDistance = (m) => (m < 1000 ? `${m.toFixed(0)} m` : `${(m / 1000).toFixed(m < 100000 ? 1 : 0)} km`);
