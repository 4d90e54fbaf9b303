// Scene model (nav_view_model.h): the geometry of the 3D view as plain arrays in frame r.
// Rotation maths goes through navcore (nav_math.h); the NED -> r mapping through NavNedToRender.
#include "navview/nav_view_model.h"

#include <algorithm>
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
  NavEnvelopeSource src = opt.envelope_source;
  if (src == NavEnvelopeSource::Auto)
    src = result.envelope.Size() > 0 ? NavEnvelopeSource::MonteCarlo
                                     : (have_errors ? NavEnvelopeSource::RunErrors : NavEnvelopeSource::None);
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
      sigma[i] = src == NavEnvelopeSource::MonteCarlo
                     ? NavInterpolate(result.envelope.t_s, result.envelope.pos_h_rms_m, 1, 0, t)
                     : NavInterpolate(result.errors.t_s, result.errors.pos_err_h_m, 1, 0, t);
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
    else
      std::snprintf(buf, sizeof buf, "%g\u00d7 horizontal error (run 0)", opt.envelope_k);
    m.envelope_label = buf;
  }

  // Triads at t0 + k * interval (computed, never accumulated).
  if (m.triad_interval_s > 0.0 && std::isfinite(m.triad_interval_s)) {
    const double k_att = opt.att_exaggeration;
    for (long k = 0;; ++k) {
      const double t = m.t_begin_s + static_cast<double>(k) * m.triad_interval_s;
      if (t > m.t_end_s + 1e-9 * std::max(1.0, std::fabs(m.t_end_s)) || k > 100000) break;
      double p_ref[3], c_ref[9];
      NavTrackSample(result.truth, t, p_ref, c_ref);
      m.triads_ref.t_s.push_back(t);
      m.triads_ref.xyz_r.insert(m.triads_ref.xyz_r.end(), p_ref, p_ref + 3);
      nav_mat3 c_truth;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
          c_truth.m[r][c] = c_ref[3 * r + c];
      QuatOut(c_truth, &m.triads_ref.q_b_r);

      if (!result.nav.HasAttitude()) continue;
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
      m.triads_est.t_s.push_back(t);
      m.triads_est.xyz_r.insert(m.triads_est.xyz_r.end(), p_est, p_est + 3);
      QuatOut(c_show, &m.triads_est.q_b_r);
    }
  }
  *out = std::move(m);
  return true;
}
