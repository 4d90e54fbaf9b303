// Scene model (nav_view_model.h): the geometry of the 3D view as plain arrays in frame r.
// Rotation maths goes through navcore (nav_math.h); the NED -> r mapping through NavNedToRender.
#include "navview/nav_view_model.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>

#include "navcore/nav_math.h"
#include "navview/nav_view_decimate.h"
#include "navview/nav_view_frame.h"

namespace {

// Nice step (1, 2, 5 x 10^k) not smaller than raw.
double NiceCeil(double raw) {
  if (!(raw > 0.0) || !std::isfinite(raw)) return 1.0;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  const double m = raw / p;
  const double step = m <= 1.0 ? 1.0 : (m <= 2.0 ? 2.0 : (m <= 5.0 ? 5.0 : 10.0));
  return step * p;
}

nav_mat3 EulerDcm(const NavTrack &track, size_t i) {
  const nav_euler e = {track.euler_rad[3 * i], track.euler_rad[3 * i + 1], track.euler_rad[3 * i + 2]};
  return nav_euler_to_dcm(e);
}

// Positions of a track in frame r, 3 per epoch.
std::vector<double> TrackToRender(const NavTrack &track) {
  std::vector<double> xyz(track.pos_ned_m.size());
  for (size_t i = 0; i < track.Size(); ++i)
    NavNedToRender(&track.pos_ned_m[3 * i], &xyz[3 * i]);
  return xyz;
}

// Decimate the 3D points xyz (optionally with a scaled 4th component) and fill the polyline.
NavPolyline DecimateToPolyline(const std::vector<double> &xyz, const std::vector<double> *scalar,
                               double scalar_scale, double tol) {
  const size_t n = xyz.size() / 3;
  std::vector<size_t> kept;
  if (scalar && scalar_scale > 0.0) {
    std::vector<double> p4(4 * n);
    for (size_t i = 0; i < n; ++i) {
      for (int k = 0; k < 3; ++k)
        p4[4 * i + static_cast<size_t>(k)] = xyz[3 * i + static_cast<size_t>(k)];
      p4[4 * i + 3] = (*scalar)[i] * scalar_scale;
    }
    kept = NavDecimatePolyline(p4.data(), n, 4, tol);
  } else {
    kept = NavDecimatePolyline(xyz.data(), n, 3, tol);
  }
  NavPolyline pl;
  pl.xyz_r.reserve(3 * kept.size());
  pl.source_index = kept;
  for (size_t i : kept) {
    for (int k = 0; k < 3; ++k)
      pl.xyz_r.push_back(xyz[3 * i + static_cast<size_t>(k)]);
    if (scalar) pl.scalar.push_back((*scalar)[i]);
  }
  return pl;
}

void QuatOut(const nav_mat3 &c_b_n, std::vector<double> *q_out) {
  double q[4];
  NavDcmToRenderQuat(&c_b_n.m[0][0], q);
  q_out->insert(q_out->end(), q, q + 4);
}

} // namespace

NavEnvelopeSource NavResolveEnvelopeSource(const NavResult &result, NavEnvelopeSource src) {
  if (src != NavEnvelopeSource::Auto) return src;
  if (result.envelope.Size() > 0) return NavEnvelopeSource::MonteCarlo;
  if (result.covariance.Size() > 0) return NavEnvelopeSource::Covariance;
  if (result.errors.Size() > 0) return NavEnvelopeSource::RunErrors;
  return NavEnvelopeSource::None;
}

const char *NavEnvelopeSourceName(NavEnvelopeSource src) {
  switch (src) {
  case NavEnvelopeSource::MonteCarlo: return "Monte Carlo RMS";
  case NavEnvelopeSource::Filter: return "filter sigma";
  case NavEnvelopeSource::Covariance: return "covariance analysis";
  case NavEnvelopeSource::RunErrors: return "run-0 error";
  default: return "none";
  }
}

bool NavSigmaNed(const NavResult &r, NavEnvelopeSource src, double t, double s[3]) {
  switch (src) {
  case NavEnvelopeSource::MonteCarlo:
    if (r.envelope.Size() == 0) return false;
    for (int k = 0; k < 3; ++k)
      s[k] = NavInterpolate(r.envelope.t_s, r.envelope.pos_rms_ned_m, 3, k, t);
    return true;
  case NavEnvelopeSource::Filter:
    if (r.envelope.pos_sd_reported_ned_m.empty()) return false;
    for (int k = 0; k < 3; ++k)
      s[k] = NavInterpolate(r.envelope.t_s, r.envelope.pos_sd_reported_ned_m, 3, k, t);
    return true;
  case NavEnvelopeSource::Covariance:
    if (r.covariance.Size() == 0) return false;
    for (int k = 0; k < 3; ++k)
      s[k] = NavInterpolate(r.covariance.t_s, r.covariance.pos_sd_ned_m, 3, k, t);
    return true;
  case NavEnvelopeSource::RunErrors:
    if (r.errors.Size() == 0) return false;
    for (int k = 0; k < 3; ++k)
      s[k] = std::fabs(NavInterpolate(r.errors.t_s, r.errors.pos_err_ned_m, 3, k, t));
    return true;
  default: return false;
  }
}

double NavSigmaH(const NavResult &r, NavEnvelopeSource src, double t) {
  switch (src) {
  case NavEnvelopeSource::MonteCarlo:
    return r.envelope.Size() ? NavInterpolate(r.envelope.t_s, r.envelope.pos_h_rms_m, 1, 0, t) : NAN;
  case NavEnvelopeSource::Covariance:
    return r.covariance.Size() ? NavInterpolate(r.covariance.t_s, r.covariance.pos_h_sd_m, 1, 0, t) : NAN;
  case NavEnvelopeSource::RunErrors:
    return r.errors.Size() ? NavInterpolate(r.errors.t_s, r.errors.pos_err_h_m, 1, 0, t) : NAN;
  case NavEnvelopeSource::Filter: {
    double s[3];
    return NavSigmaNed(r, src, t, s) ? std::hypot(s[0], s[1]) : NAN;
  }
  default: return NAN;
  }
}

std::vector<double> NavEllipsoidTimes(const NavResult &result, const NavViewOptions &opt) {
  if (!opt.ellipsoid_times_s.empty()) return opt.ellipsoid_times_s;
  std::vector<double> times;
  if (opt.ellipsoid_count <= 0 || result.truth.Size() == 0) return times;
  const double t0 = result.truth.t_s.front(), t1 = result.truth.t_s.back();
  for (int i = 0; i < opt.ellipsoid_count; ++i)
    times.push_back(t0 + (t1 - t0) * (i + 1.0) / opt.ellipsoid_count);
  // Plus the last reference epoch inside each GNSS outage: where the uncertainty peaks.
  const NavGnss &g = result.gnss;
  for (size_t o = 0; o < g.outage_t0_s.size(); ++o) {
    const size_t i = NavTimeIndex(result.truth.t_s, g.outage_t1_s[o]);
    size_t j = i;
    if (j > 0 && result.truth.t_s[j] >= g.outage_t1_s[o]) --j;
    const double t = result.truth.t_s[j];
    if (t >= g.outage_t0_s[o] && t < g.outage_t1_s[o]) times.push_back(t);
  }
  std::sort(times.begin(), times.end());
  return times;
}

double NavNiceGridSpacing(double extent_m) {
  return NiceCeil(extent_m / 10.0);
}

void NavResultBoundsRender(const NavResult &result, double b[6]) {
  const double inf = std::numeric_limits<double>::infinity();
  b[0] = b[2] = b[4] = inf;
  b[1] = b[3] = b[5] = -inf;
  auto add = [&](const NavTrack &t) {
    for (size_t i = 0; i < t.Size(); ++i) {
      double r[3];
      NavNedToRender(&t.pos_ned_m[3 * i], r);
      for (int k = 0; k < 3; ++k) {
        b[2 * k] = std::min(b[2 * k], r[k]);
        b[2 * k + 1] = std::max(b[2 * k + 1], r[k]);
      }
    }
  };
  add(result.truth);
  add(result.nav);
  for (const NavTrack &t : result.extra_runs)
    add(t);
  if (!(b[0] <= b[1])) {
    for (int k = 0; k < 6; ++k)
      b[k] = 0.0;
  }
}

bool NavTrackSample(const NavTrack &track, double t, double pos_r[3], double c_b_n[9]) {
  const size_t n = track.Size();
  if (n == 0) return false;
  const size_t i = NavTimeIndex(track.t_s, t);
  const size_t j = i + 1 < n ? i + 1 : i;
  const double dt = track.t_s[j] - track.t_s[i];
  const double a = (j != i && dt > 0.0) ? std::clamp((t - track.t_s[i]) / dt, 0.0, 1.0) : 0.0;
  double ned[3];
  for (int k = 0; k < 3; ++k) {
    const size_t ik = 3 * i + static_cast<size_t>(k), jk = 3 * j + static_cast<size_t>(k);
    ned[k] = track.pos_ned_m[ik] + a * (track.pos_ned_m[jk] - track.pos_ned_m[ik]);
  }
  NavNedToRender(ned, pos_r);
  if (c_b_n && track.HasAttitude()) {
    // Geodesic interpolation: C = C_i exp(a log(C_i^T C_j)) (body-frame increment).
    const nav_mat3 ci = EulerDcm(track, i);
    nav_mat3 c = ci;
    if (a > 0.0) {
      const nav_vec3 phi = nav_dcm_log(nav_mat3_tmul(ci, EulerDcm(track, j)));
      c = nav_mat3_mul(ci, nav_dcm_exp(nav_vec3_scale(phi, a)));
    }
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k)
        c_b_n[3 * r + k] = c.m[r][k];
  }
  return true;
}

bool NavBuildSceneModel(const NavResult &result, const NavViewOptions &opt, double tol_m, NavSceneModel *out,
                        std::string *error) {
  if (result.truth.Size() == 0 || result.nav.Size() == 0) {
    *error = "the result has no reference or no estimated epochs";
    return false;
  }
  if (!result.truth.HasAttitude()) {
    *error = "the reference track carries no attitude";
    return false;
  }
  NavSceneModel m;
  m.decimation_tol_m = tol_m;
  m.t_begin_s = result.truth.t_s.front();
  m.t_end_s = result.truth.t_s.back();
  NavResultBoundsRender(result, m.bounds_r);
  const double *b = m.bounds_r;
  const double extent_h = std::max(std::max(b[1] - b[0], b[3] - b[2]), 1.0);
  const double extent = std::max(extent_h, b[5] - b[4]);

  // Ground grid just below the lowest point so paths on the ground are not hidden by it.
  m.grid_spacing_m = NavNiceGridSpacing(extent_h);
  const double s = m.grid_spacing_m;
  // Whole cells around the paths, at least 0.3 cell of margin.
  m.grid_r[0] = std::floor((b[0] - 0.3 * s) / s) * s;
  m.grid_r[1] = std::ceil((b[1] + 0.3 * s) / s) * s;
  m.grid_r[2] = std::floor((b[2] - 0.3 * s) / s) * s;
  m.grid_r[3] = std::ceil((b[3] + 0.3 * s) / s) * s;
  m.ground_z_r = b[4] - 0.002 * extent;

  m.vehicle = opt.vehicle;
  if (m.vehicle == NavVehicleKind::Auto) {
    std::string n = result.scene_name;
    std::transform(n.begin(), n.end(), n.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    auto has = [&](const char *w) { return n.find(w) != std::string::npos; };
    if (has("aircraft") || has("flight") || has("uav") || has("climb") || has("plane"))
      m.vehicle = NavVehicleKind::Aircraft;
    else if (has("car") || has("drive") || has("vehicle") || has("road"))
      m.vehicle = NavVehicleKind::Car;
    else
      m.vehicle = NavVehicleKind::Generic;
  }
  m.triad_size_m = opt.triad_size_m > 0.0 ? opt.triad_size_m : 0.06 * extent_h;
  const double duration = m.t_end_s - m.t_begin_s;
  m.triad_interval_s = opt.triad_interval_s > 0.0 ? opt.triad_interval_s : NiceCeil(duration / 24.0);

  if (tol_m < 0.0) { // layout only
    *out = std::move(m);
    return true;
  }

  // Paths.
  const std::vector<double> ref_r = TrackToRender(result.truth);
  m.reference = DecimateToPolyline(ref_r, nullptr, 0.0, tol_m);
  m.full_points = result.truth.Size() + result.nav.Size();

  const bool have_errors = result.errors.Size() > 0;
  const std::vector<double> est_r = TrackToRender(result.nav);
  std::vector<double> est_err;
  if (have_errors) {
    est_err.resize(result.nav.Size());
    for (size_t i = 0; i < result.nav.Size(); ++i)
      est_err[i] = NavInterpolate(result.errors.t_s, result.errors.pos_err_h_m, 1, 0, result.nav.t_s[i]);
    m.error_max_m = *std::max_element(result.errors.pos_err_h_m.begin(), result.errors.pos_err_h_m.end());
  }
  if (opt.color_by_error && have_errors && m.error_max_m > 0.0) {
    // The colour may deviate by at most 1/64 of its range where the geometry error is tol_m.
    m.estimate = DecimateToPolyline(est_r, &est_err, 64.0 * tol_m / m.error_max_m, tol_m);
  } else {
    m.estimate = DecimateToPolyline(est_r, have_errors ? &est_err : nullptr, 0.0, tol_m);
  }
  for (const NavTrack &run : result.extra_runs) {
    m.extra_runs.push_back(DecimateToPolyline(TrackToRender(run), nullptr, 0.0, tol_m));
    m.full_points += run.Size();
  }

  // Error envelope: radius k * sigma at the reference epochs, decimated in (x, y, z, radius) so
  // both the centre line and the radius stay within tol_m.
  const NavEnvelopeSource src = NavResolveEnvelopeSource(result, opt.envelope_source);
  m.envelope_source = src;
  if (src == NavEnvelopeSource::Filter && result.envelope.pos_sd_reported_ned_m.empty()) {
    *error = "the filter-sigma envelope was requested but mc_stats.csv has no reported sigma (INS/GNSS "
             "Monte Carlo only)";
    return false;
  }
  if (src == NavEnvelopeSource::Covariance && result.covariance.Size() == 0) {
    *error = "the covariance-analysis envelope was requested but no estimate.csv was found (run navsim "
             "estimate SCENE --out DIR-estimate)";
    return false;
  }
  if (src == NavEnvelopeSource::MonteCarlo && result.envelope.Size() == 0) {
    *error = "the Monte Carlo envelope was requested but mc_stats.csv was not loaded";
    return false;
  }
  if (src == NavEnvelopeSource::RunErrors && !have_errors) {
    *error = "the run-0 envelope was requested but errors.csv was not loaded";
    return false;
  }
  if (src != NavEnvelopeSource::None && opt.envelope_k > 0.0) {
    const size_t n = result.truth.Size();
    std::vector<double> sigma(n), p4(4 * n);
    for (size_t i = 0; i < n; ++i) {
      const double t = result.truth.t_s[i];
      sigma[i] = NavSigmaH(result, src, t);
      for (int k = 0; k < 3; ++k)
        p4[4 * i + static_cast<size_t>(k)] = ref_r[3 * i + static_cast<size_t>(k)];
      p4[4 * i + 3] = opt.envelope_k * sigma[i];
    }
    const std::vector<size_t> kept = NavDecimatePolyline(p4.data(), n, 4, tol_m);
    for (size_t i : kept) {
      for (int k = 0; k < 3; ++k)
        m.envelope.xyz_r.push_back(ref_r[3 * i + static_cast<size_t>(k)]);
      m.envelope.sigma_m.push_back(sigma[i]);
      m.envelope.radius_m.push_back(opt.envelope_k * sigma[i]);
      m.envelope.source_index.push_back(i);
    }
    char buf[160];
    if (src == NavEnvelopeSource::MonteCarlo)
      std::snprintf(buf, sizeof buf, "%g\u00d7 RMS horizontal error (%d runs)", opt.envelope_k, result.runs);
    else if (src == NavEnvelopeSource::Filter)
      std::snprintf(buf, sizeof buf, "%g\u00d7 filter horizontal sigma", opt.envelope_k);
    else if (src == NavEnvelopeSource::Covariance)
      std::snprintf(buf, sizeof buf, "%g\u00d7 covariance-analysis horizontal sigma", opt.envelope_k);
    else
      std::snprintf(buf, sizeof buf, "%g\u00d7 horizontal error (run 0)", opt.envelope_k);
    m.envelope_label = buf;
  }

  // Covariance ellipsoids at chosen epochs, centred on the estimate (where the filter thinks it
  // is), semi-axes k sigma per N/E/D axis.
  if (src != NavEnvelopeSource::None && opt.envelope_k > 0.0) {
    for (double t : NavEllipsoidTimes(result, opt)) {
      NavEllipsoid e;
      if (!NavSigmaNed(result, src, t, e.sigma_ned_m)) break;
      e.t_s = t;
      NavTrackSample(result.nav, t, e.center_r, nullptr);
      double k_ned[3];
      for (int k = 0; k < 3; ++k)
        k_ned[k] = opt.envelope_k * e.sigma_ned_m[k];
      // Semi-axes are lengths: the N/E/D -> r map permutes them (signs drop out).
      NavNedToRender(k_ned, e.semi_axes_r);
      for (double &a : e.semi_axes_r)
        a = std::fabs(a);
      // An ellipsoid wider than the whole scene would hide it (a stationary alignment with
      // hundreds of metres of sigma): counted, not drawn; the legend says so.
      if (2.0 * std::max(e.semi_axes_r[0], e.semi_axes_r[1]) > extent_h) {
        ++m.ellipsoids_too_large;
        continue;
      }
      m.ellipsoids.push_back(e);
    }
  }

  // GNSS fixes and the reference path inside each outage.
  if (opt.show_gnss) {
    const NavGnss &g = result.gnss;
    for (size_t i = 0; i < g.Size(); ++i) {
      double r[3];
      NavNedToRender(&g.pos_ned_m[3 * i], r);
      m.gnss_r.insert(m.gnss_r.end(), r, r + 3);
    }
    for (size_t o = 0; o < g.outage_t0_s.size(); ++o) {
      std::vector<double> seg;
      double p[3];
      const double t0 = std::max(g.outage_t0_s[o], m.t_begin_s), t1 = std::min(g.outage_t1_s[o], m.t_end_s);
      if (!(t1 > t0)) continue;
      NavTrackSample(result.truth, t0, p, nullptr);
      seg.insert(seg.end(), p, p + 3);
      for (size_t i = NavTimeIndex(result.truth.t_s, t0); i < result.truth.Size(); ++i) {
        const double t = result.truth.t_s[i];
        if (t <= t0) continue;
        if (t >= t1) break;
        seg.insert(seg.end(), &ref_r[3 * i], &ref_r[3 * i] + 3);
      }
      NavTrackSample(result.truth, t1, p, nullptr);
      seg.insert(seg.end(), p, p + 3);
      m.outage_segments.push_back(DecimateToPolyline(seg, nullptr, 0.0, tol_m));
    }
  }

  // Triads at t0 + k * interval (computed, never accumulated).
  if (m.triad_interval_s > 0.0 && std::isfinite(m.triad_interval_s)) {
    for (long k = 0;; ++k) {
      const double t = m.t_begin_s + static_cast<double>(k) * m.triad_interval_s;
      if (t > m.t_end_s + 1e-9 * std::max(1.0, std::fabs(m.t_end_s)) || k > 100000) break;
      NavAppendTriadsAt(result, opt.att_exaggeration, t, &m.triads_ref, &m.triads_est);
    }
  }
  *out = std::move(m);
  return true;
}

void NavAppendTriadsAt(const NavResult &result, double k_att, double t, NavTriadSet *ref, NavTriadSet *est) {
  double p_ref[3], c_ref[9];
  if (!NavTrackSample(result.truth, t, p_ref, c_ref)) return;
  ref->t_s.push_back(t);
  ref->xyz_r.insert(ref->xyz_r.end(), p_ref, p_ref + 3);
  nav_mat3 c_truth;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      c_truth.m[r][c] = c_ref[3 * r + c];
  QuatOut(c_truth, &ref->q_b_r);

  if (!result.nav.HasAttitude()) return;
  double p_est[3], c_est_a[9];
  NavTrackSample(result.nav, t, p_est, c_est_a);
  nav_mat3 c_nav;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      c_nav.m[r][c] = c_est_a[3 * r + c];
  // Attitude error as a rotation of frame n: C_nav = exp([phi x]) C_truth. Showing
  // exp([k phi x]) C_truth scales the error angle by k and keeps its axis.
  const nav_vec3 phi = nav_dcm_log(nav_mat3_mul(c_nav, nav_mat3_transpose(c_truth)));
  const nav_mat3 c_show = nav_mat3_mul(nav_dcm_exp(nav_vec3_scale(phi, k_att)), c_truth);
  est->t_s.push_back(t);
  est->xyz_r.insert(est->xyz_r.end(), p_est, p_est + 3);
  QuatOut(c_show, &est->q_b_r);
}
