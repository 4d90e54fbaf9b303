/*
 * test_navview_model: the display geometry of libnavview without a display.
 * - Decimation keeps every dropped point within the tolerance (circle, seeded random walks in 3D
 *   and 4D, a path that doubles back, degenerate inputs), and the scene model's paths and tube
 *   obey the tolerance it was built with.
 * - The render-frame adapter maps N, E, D to +y, +x, -z.
 * - Envelope radii equal k times the sigma fed in (Monte Carlo RMS and run-0 errors).
 * - Triad orientations equal the quaternions fed in (reference; estimate at k = 1), k = 0 shows
 *   the reference attitude, and k scales the error angle.
 * Random tests are seeded; the seed is printed first.
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
extern "C" {
#include <cmocka.h>
}

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sys/stat.h>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "nav_test.h"
#include "navview/nav_view_decimate.h"
#include "navview/nav_view_frame.h"
#include "navview/nav_view_map.h"
#include "navview/nav_view_model.h"
#include "navview/nav_view_result.h"
#include "navview/nav_view_scene.h"

namespace {

const uint64_t kSeed = 20240607;

NavResult load_tiny() {
  NavResult r;
  std::string err;
  if (!NavLoadResultDir(NAVVIEW_TEST_DATA_DIR "/tiny", &r, &err)) fail_msg("%s", err.c_str());
  return r;
}

nav_vec3 rotate(const double q[4], nav_vec3 v) {
  return nav_quat_rotate(nav_quat{q[0], q[1], q[2], q[3]}, v);
}

void check_bound(const std::vector<double> &pts, int dim, double tol, size_t *kept_out) {
  const size_t n = pts.size() / static_cast<size_t>(dim);
  const std::vector<size_t> kept = NavDecimatePolyline(pts.data(), n, dim, tol);
  assert_true(kept.size() >= 2);
  assert_int_equal(kept.front(), 0);
  assert_int_equal(kept.back(), n - 1);
  for (size_t i = 1; i < kept.size(); ++i)
    assert_true(kept[i] > kept[i - 1]);
  const double e = NavDecimationError(pts.data(), n, dim, kept);
  if (!(e <= tol)) fail_msg("decimation error %.17g exceeds tolerance %.17g (dim %d, n %zu)", e, tol, dim, n);
  if (kept_out) *kept_out = kept.size();
}

void test_decimate_circle(void **) {
  // 100 000 points on a 1 km circle: the chord sagitta r(1 - cos(a/2)) <= tol gives the count.
  const size_t n = 100000;
  const double r = 1000.0, tol = 0.5;
  std::vector<double> p(3 * n);
  for (size_t i = 0; i < n; ++i) {
    const double a = NAV_TWO_PI * static_cast<double>(i) / static_cast<double>(n - 1);
    p[3 * i] = r * std::cos(a);
    p[3 * i + 1] = r * std::sin(a);
    p[3 * i + 2] = 0.0;
  }
  size_t kept = 0;
  check_bound(p, 3, tol, &kept);
  const double seg = 2.0 * std::acos(1.0 - tol / r);
  const size_t ideal = static_cast<size_t>(std::ceil(NAV_TWO_PI / seg));
  std::printf("circle: %zu of %zu points kept (ideal chord count %zu)\n", kept, n, ideal);
  assert_true(kept >= ideal);
  assert_true(kept <= 2 * ideal + 2);
}

void test_decimate_random_walks(void **) {
  std::printf("seed %llu\n", static_cast<unsigned long long>(kSeed));
  std::mt19937_64 rng(kSeed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.01, 5.0);
  for (int c = 0; c < 30; ++c) {
    const int dim = 2 + c % 3;
    const size_t n = 2000 + static_cast<size_t>(c) * 700;
    std::vector<double> p(static_cast<size_t>(dim) * n, 0.0);
    for (size_t i = 1; i < n; ++i)
      for (int k = 0; k < dim; ++k)
        p[static_cast<size_t>(dim) * i + k] = p[static_cast<size_t>(dim) * (i - 1) + k] + g(rng);
    check_bound(p, dim, u(rng), nullptr);
  }
}

void test_decimate_doubling_back_and_edges(void **) {
  // Out and back along a line: the turning point is 10 away from the end-to-end segment (of
  // length 0) and must stay.
  std::vector<double> p;
  for (int i = 0; i <= 10; ++i)
    p.insert(p.end(), {static_cast<double>(i), 0.0, 0.0});
  for (int i = 9; i >= 0; --i)
    p.insert(p.end(), {static_cast<double>(i), 0.0, 0.0});
  std::vector<size_t> kept = NavDecimatePolyline(p.data(), p.size() / 3, 3, 0.1);
  assert_int_equal(kept.size(), 3);
  assert_int_equal(kept[1], 10);
  // Collinear points vanish even at tolerance 0; a vehicle at rest collapses to one segment.
  std::vector<double> line = {0, 0, 0, 1, 1, 1, 2, 2, 2, 2, 2, 2, 2, 2, 2, 3, 3, 3};
  kept = NavDecimatePolyline(line.data(), 6, 3, 0.0);
  assert_int_equal(kept.size(), 2);
  assert_int_equal(NavDecimatePolyline(line.data(), 0, 3, 1.0).size(), 0);
  assert_int_equal(NavDecimatePolyline(line.data(), 1, 3, 1.0).size(), 1);
  assert_int_equal(NavDecimatePolyline(line.data(), 2, 3, 1.0).size(), 2);
  assert_int_equal(NavDecimatePolyline(line.data(), 6, 5, 1.0).size(), 0); // invalid dimension
}

void test_render_adapter(void **) {
  const double n[3] = {1, 0, 0}, e[3] = {0, 1, 0}, d[3] = {0, 0, 1};
  double r[3];
  NavNedToRender(n, r);
  assert_vec3_near((nav_vec3{r[0], r[1], r[2]}), (nav_vec3{0, 1, 0}), 0.0);
  NavNedToRender(e, r);
  assert_vec3_near((nav_vec3{r[0], r[1], r[2]}), (nav_vec3{1, 0, 0}), 0.0);
  NavNedToRender(d, r);
  assert_vec3_near((nav_vec3{r[0], r[1], r[2]}), (nav_vec3{0, 0, -1}), 0.0);

  // Level, heading north: forward -> +y (north), right -> +x (east), down -> -z.
  double q[4];
  NavEulerToRenderQuat(0.0, 0.0, 0.0, q);
  assert_vec3_near(rotate(q, nav_vec3{1, 0, 0}), (nav_vec3{0, 1, 0}), 1e-15);
  assert_vec3_near(rotate(q, nav_vec3{0, 1, 0}), (nav_vec3{1, 0, 0}), 1e-15);
  assert_vec3_near(rotate(q, nav_vec3{0, 0, 1}), (nav_vec3{0, 0, -1}), 1e-15);
  // Heading east, nose up 30 deg: forward -> (cos30, 0, sin30).
  NavEulerToRenderQuat(0.0, 30.0 * NAV_DEG2RAD, 90.0 * NAV_DEG2RAD, q);
  assert_vec3_near(rotate(q, nav_vec3{1, 0, 0}), (nav_vec3{std::cos(NAV_PI / 6), 0, 0.5}), 1e-15);
  assert_true(q[0] >= 0.0);
}

void test_envelope_radii(void **) {
  const NavResult r = load_tiny();
  NavViewOptions opt;
  opt.envelope_k = 3.0;
  NavSceneModel m;
  std::string err;
  // Monte Carlo RMS (auto picks it when mc_stats.csv is present).
  assert_true(NavBuildSceneModel(r, opt, 0.05, &m, &err));
  assert_true(m.envelope.Size() >= 2);
  assert_true(m.envelope_label.find("RMS") != std::string::npos);
  for (size_t i = 0; i < m.envelope.Size(); ++i) {
    const size_t src = m.envelope.source_index[i];
    const double sigma = r.envelope.pos_h_rms_m[src]; // same epochs in the tiny result
    assert_near(m.envelope.sigma_m[i], sigma, 0.0);
    assert_near(m.envelope.radius_m[i], 3.0 * sigma, 1e-15 * sigma);
    double p[3];
    NavNedToRender(&r.truth.pos_ned_m[3 * src], p);
    assert_vec3_near(
        (nav_vec3{m.envelope.xyz_r[3 * i], m.envelope.xyz_r[3 * i + 1], m.envelope.xyz_r[3 * i + 2]}),
        (nav_vec3{p[0], p[1], p[2]}), 0.0);
  }
  // Run-0 errors.
  opt.envelope_source = NavEnvelopeSource::RunErrors;
  opt.envelope_k = 2.0;
  assert_true(NavBuildSceneModel(r, opt, 0.05, &m, &err));
  for (size_t i = 0; i < m.envelope.Size(); ++i) {
    const double sigma = r.errors.pos_err_h_m[m.envelope.source_index[i]];
    assert_near(m.envelope.radius_m[i], 2.0 * sigma, 1e-15 * sigma);
  }
  // Between epochs the radius follows linear interpolation of sigma: check the tube's own
  // decimation bound in (position, radius).
  std::vector<double> p4;
  for (size_t i = 0; i < r.truth.Size(); ++i) {
    double p[3];
    NavNedToRender(&r.truth.pos_ned_m[3 * i], p);
    p4.insert(p4.end(), {p[0], p[1], p[2], 2.0 * r.errors.pos_err_h_m[i]});
  }
  assert_true(NavDecimationError(p4.data(), r.truth.Size(), 4, m.envelope.source_index) <= 0.05);
  // None, and a missing source is an error rather than a silent fallback.
  opt.envelope_source = NavEnvelopeSource::None;
  assert_true(NavBuildSceneModel(r, opt, 0.05, &m, &err));
  assert_int_equal(m.envelope.Size(), 0);
  NavResult no_mc = r;
  no_mc.envelope = NavEnvelope();
  opt.envelope_source = NavEnvelopeSource::MonteCarlo;
  assert_false(NavBuildSceneModel(no_mc, opt, 0.05, &m, &err));
  assert_true(err.find("mc_stats.csv") != std::string::npos);
}

void test_model_paths_within_tolerance(void **) {
  const NavResult r = load_tiny();
  NavViewOptions opt;
  for (double tol : {0.01, 0.2, 1.0}) {
    NavSceneModel m;
    std::string err;
    assert_true(NavBuildSceneModel(r, opt, tol, &m, &err));
    std::vector<double> full(3 * r.truth.Size());
    for (size_t i = 0; i < r.truth.Size(); ++i)
      NavNedToRender(&r.truth.pos_ned_m[3 * i], &full[3 * i]);
    const double e = NavDecimationError(full.data(), r.truth.Size(), 3, m.reference.source_index);
    std::printf("tol %.2f m: reference %zu of %zu points, error %.3g m\n", tol, m.reference.Size(),
                r.truth.Size(), e);
    assert_true(e <= tol);
    assert_int_equal(m.reference.xyz_r.size(), 3 * m.reference.source_index.size());
  }
}

double quat_angle(const double a[4], const double b[4]) {
  return nav_quat_angle_between(nav_quat{a[0], a[1], a[2], a[3]}, nav_quat{b[0], b[1], b[2], b[3]});
}

void test_triad_orientation(void **) {
  const NavResult r = load_tiny();
  NavViewOptions opt;
  opt.triad_interval_s = 10.0; // epochs at whole seconds: triads fall on samples
  opt.att_exaggeration = 1.0;  // the true estimate (the default is kNavDefaultAttExaggeration)
  NavSceneModel m;
  std::string err;
  assert_true(NavBuildSceneModel(r, opt, 0.05, &m, &err));
  assert_int_equal(m.triads_ref.Size(), 13); // 0, 10, ..., 120 s
  assert_int_equal(m.triads_est.Size(), 13);
  for (size_t k = 0; k < m.triads_ref.Size(); ++k) {
    const size_t i = static_cast<size_t>(std::lround(m.triads_ref.t_s[k]));
    double q_ref[4], q_nav[4];
    NavEulerToRenderQuat(r.truth.euler_rad[3 * i], r.truth.euler_rad[3 * i + 1], r.truth.euler_rad[3 * i + 2],
                         q_ref);
    NavEulerToRenderQuat(r.nav.euler_rad[3 * i], r.nav.euler_rad[3 * i + 1], r.nav.euler_rad[3 * i + 2],
                         q_nav);
    const nav_quat a = {m.triads_ref.q_b_r[4 * k], m.triads_ref.q_b_r[4 * k + 1],
                        m.triads_ref.q_b_r[4 * k + 2], m.triads_ref.q_b_r[4 * k + 3]};
    assert_quat_near(a, (nav_quat{q_ref[0], q_ref[1], q_ref[2], q_ref[3]}), 1e-12);
    const nav_quat b = {m.triads_est.q_b_r[4 * k], m.triads_est.q_b_r[4 * k + 1],
                        m.triads_est.q_b_r[4 * k + 2], m.triads_est.q_b_r[4 * k + 3]};
    assert_quat_near(b, (nav_quat{q_nav[0], q_nav[1], q_nav[2], q_nav[3]}), 1e-12);
    double p[3];
    NavNedToRender(&r.nav.pos_ned_m[3 * i], p);
    assert_near(m.triads_est.xyz_r[3 * k], p[0], 1e-12);
    assert_near(m.triads_est.xyz_r[3 * k + 1], p[1], 1e-12);
  }
  // k = 0: the estimated triad shows the reference attitude; k = 8: eight times the error angle.
  NavSceneModel m0, m8;
  opt.att_exaggeration = 0.0;
  assert_true(NavBuildSceneModel(r, opt, 0.05, &m0, &err));
  opt.att_exaggeration = 8.0;
  assert_true(NavBuildSceneModel(r, opt, 0.05, &m8, &err));
  for (size_t k = 1; k < m.triads_ref.Size(); ++k) {
    const double *ref = &m.triads_ref.q_b_r[4 * k];
    assert_near(quat_angle(&m0.triads_est.q_b_r[4 * k], ref), 0.0, 1e-7);
    const double e1 = quat_angle(&m.triads_est.q_b_r[4 * k], ref);
    const double e8 = quat_angle(&m8.triads_est.q_b_r[4 * k], ref);
    assert_true(e1 > 0.0);
    assert_near(e8, 8.0 * e1, 1e-9);
  }
}

void test_pick_full_rate(void **) {
  // Picking searches the full-rate estimate, not the decimated polyline: query points on every
  // epoch return that epoch. No window is needed.
  auto r = std::make_shared<NavResult>(load_tiny());
  NavSceneView view;
  view.SetResult(r);
  for (size_t i = 0; i < r->nav.Size(); i += 7) {
    double p[3];
    NavNedToRender(&r->nav.pos_ned_m[3 * i], p);
    p[2] += 0.01;
    NavPickResult pick;
    assert_true(view.PickNearest(p, &pick));
    assert_int_equal(pick.epoch, i);
    assert_near(pick.t_s, r->nav.t_s[i], 0.0);
    assert_near(pick.distance_m, 0.01, 1e-9);
    assert_near(pick.pos_err_h_m, r->errors.pos_err_h_m[i], 1e-12);
  }
}

void test_grid_spacing(void **) {
  assert_near(NavNiceGridSpacing(1800.0), 200.0, 0.0);
  assert_near(NavNiceGridSpacing(100.0), 10.0, 0.0);
  assert_near(NavNiceGridSpacing(120.0), 20.0, 0.0);
  assert_near(NavNiceGridSpacing(4.0e4), 5000.0, 0.0);
  assert_near(NavNiceGridSpacing(0.0), 1.0, 0.0);
}

// Filter sigma and covariance analysis: tube radius = k * horizontal sigma fed in; ellipsoid
// semi-axes = k * sigma N/E/D fed in, mapped to x = east, y = north, z = up.
void test_envelope_sources_and_ellipsoids(void **) {
  NavResult r = load_tiny();
  const size_t n = r.envelope.Size();
  r.envelope.pos_sd_reported_ned_m.resize(3 * n);
  for (size_t i = 0; i < n; ++i) {
    r.envelope.pos_sd_reported_ned_m[3 * i] = 0.4 + 0.01 * static_cast<double>(i);
    r.envelope.pos_sd_reported_ned_m[3 * i + 1] = 0.2 + 0.03 * static_cast<double>(i);
    r.envelope.pos_sd_reported_ned_m[3 * i + 2] = 0.9;
  }
  r.covariance.t_s = r.envelope.t_s;
  for (size_t i = 0; i < n; ++i) {
    const double sn = 1.0 + 0.02 * static_cast<double>(i), se = 0.5, sd = 2.0;
    r.covariance.pos_sd_ned_m.insert(r.covariance.pos_sd_ned_m.end(), {sn, se, sd});
    r.covariance.pos_h_sd_m.push_back(std::hypot(sn, se));
  }
  NavViewOptions opt;
  opt.envelope_k = 3.0;
  opt.ellipsoid_times_s = {0.0, 30.0, 61.0, 120.0}; // 61 s: between epochs, interpolated
  NavSceneModel m;
  std::string err;
  for (NavEnvelopeSource src : {NavEnvelopeSource::Filter, NavEnvelopeSource::Covariance}) {
    opt.envelope_source = src;
    assert_true(NavBuildSceneModel(r, opt, 0.05, &m, &err));
    assert_true(m.envelope_source == src);
    assert_true(m.envelope.Size() >= 2);
    for (size_t i = 0; i < m.envelope.Size(); ++i) {
      const size_t k = m.envelope.source_index[i];
      const double sh = src == NavEnvelopeSource::Filter
                            ? std::hypot(r.envelope.pos_sd_reported_ned_m[3 * k], r.envelope.pos_sd_reported_ned_m[3 * k + 1])
                            : r.covariance.pos_h_sd_m[k];
      assert_near(m.envelope.sigma_m[i], sh, 1e-15 * sh);
      assert_near(m.envelope.radius_m[i], 3.0 * sh, 1e-14 * sh);
    }
    assert_int_equal(m.ellipsoids.size(), 4);
    for (const NavEllipsoid &e : m.ellipsoids) {
      const std::vector<double> &sig =
          src == NavEnvelopeSource::Filter ? r.envelope.pos_sd_reported_ned_m : r.covariance.pos_sd_ned_m;
      for (int a = 0; a < 3; ++a) {
        const double s_in = NavInterpolate(r.envelope.t_s, sig, 3, a, e.t_s);
        assert_near(e.sigma_ned_m[a], s_in, 1e-15 * s_in);
      }
      // N -> y, E -> x, D -> z (lengths).
      assert_near(e.semi_axes_r[0], 3.0 * e.sigma_ned_m[1], 1e-15);
      assert_near(e.semi_axes_r[1], 3.0 * e.sigma_ned_m[0], 1e-15);
      assert_near(e.semi_axes_r[2], 3.0 * e.sigma_ned_m[2], 1e-15);
      // Centred on the estimate at its epoch.
      double p[3];
      assert_true(NavTrackSample(r.nav, e.t_s, p, nullptr));
      assert_vec3_near((nav_vec3{e.center_r[0], e.center_r[1], e.center_r[2]}), (nav_vec3{p[0], p[1], p[2]}), 0.0);
    }
  }
  // A requested source without data is an error that names what is missing.
  NavResult bare = load_tiny();
  opt.envelope_source = NavEnvelopeSource::Filter;
  assert_false(NavBuildSceneModel(bare, opt, 0.05, &m, &err));
  assert_true(err.find("reported sigma") != std::string::npos);
  opt.envelope_source = NavEnvelopeSource::Covariance;
  assert_false(NavBuildSceneModel(bare, opt, 0.05, &m, &err));
  assert_true(err.find("estimate.csv") != std::string::npos);
  // Evenly spread ellipsoids: count and times.
  opt.envelope_source = NavEnvelopeSource::MonteCarlo;
  opt.ellipsoid_times_s.clear();
  opt.ellipsoid_count = 5;
  assert_true(NavBuildSceneModel(bare, opt, 0.05, &m, &err));
  assert_int_equal(m.ellipsoids.size(), 5);
  assert_near(m.ellipsoids.back().t_s, 120.0, 1e-12);
  assert_near(m.ellipsoids.front().t_s, 24.0, 1e-12);
}

// tiny-gnss: gnss.csv, gnss_outages.csv, imu_errors.csv and summary.json "requirements" load;
// the outage segment follows the reference inside [40, 70) s; the vehicle kind follows the name.
void test_gnss_outages_requirements(void **) {
  NavResult r;
  std::string err;
  if (!NavLoadResultDir(NAVVIEW_TEST_DATA_DIR "/tiny-gnss", &r, &err)) fail_msg("%s", err.c_str());
  assert_int_equal(r.gnss.Size(), 46);
  assert_int_equal(r.gnss.outage_t0_s.size(), 1);
  assert_true(r.gnss.InOutage(40.0) && r.gnss.InOutage(69.9) && !r.gnss.InOutage(70.0) && !r.gnss.InOutage(39.9));
  for (double t : r.gnss.t_s)
    assert_false(r.gnss.InOutage(t));
  assert_int_equal(r.imu_errors.Size(), 120);
  assert_near(r.imu_errors.gyro_rps[0], (0.02 + 0.01 * std::sin(1.3)) * 3.14159265358979323846 / 180.0, 1e-8);
  assert_int_equal(r.requirements.size(), 3);
  assert_string_equal(r.requirements[0].id.c_str(), "h-rms");
  assert_near(r.requirements[0].limit_si, 2.5, 1e-12); // 250 cm
  assert_true(r.requirements[0].pass);
  assert_string_equal(r.requirements[1].metric.c_str(), "vertical_position");
  assert_false(r.requirements[1].pass); // nested "outages" array does not confuse the parser
  assert_near(r.requirements[2].limit_si, 3.0 * 3.14159265358979323846 / 180.0, 1e-12);
  assert_true(r.truth.HasGeodetic());
  assert_near(r.truth.geo[0], 48.137 * 3.14159265358979323846 / 180.0, 1e-12);

  NavViewOptions opt;
  NavSceneModel m;
  assert_true(NavBuildSceneModel(r, opt, 0.01, &m, &err));
  assert_int_equal(m.gnss_r.size(), 3 * r.gnss.Size());
  double p[3];
  NavNedToRender(&r.gnss.pos_ned_m[0], p);
  assert_vec3_near((nav_vec3{m.gnss_r[0], m.gnss_r[1], m.gnss_r[2]}), (nav_vec3{p[0], p[1], p[2]}), 0.0);
  assert_int_equal(m.outage_segments.size(), 1);
  const NavPolyline &seg = m.outage_segments[0];
  double a[3], b[3];
  NavTrackSample(r.truth, 40.0, a, nullptr);
  NavTrackSample(r.truth, 70.0, b, nullptr);
  assert_vec3_near((nav_vec3{seg.xyz_r[0], seg.xyz_r[1], seg.xyz_r[2]}), (nav_vec3{a[0], a[1], a[2]}), 0.0);
  const size_t last = seg.Size() - 1;
  assert_vec3_near((nav_vec3{seg.xyz_r[3 * last], seg.xyz_r[3 * last + 1], seg.xyz_r[3 * last + 2]}),
                   (nav_vec3{b[0], b[1], b[2]}), 0.0);
  assert_true(m.vehicle == NavVehicleKind::Generic); // "tiny-figure-eight-gnss"
  // Default ellipsoids: 6 evenly spread plus the last epoch inside the outage [40, 70): 69 s.
  const std::vector<double> et = NavEllipsoidTimes(r, opt);
  assert_int_equal(et.size(), 7);
  assert_true(std::find(et.begin(), et.end(), 69.0) != et.end());
  assert_int_equal(m.ellipsoids.size(), 7);
  r.scene_name = "urban-drive";
  assert_true(NavBuildSceneModel(r, opt, -1.0, &m, &err));
  assert_true(m.vehicle == NavVehicleKind::Car);
  r.scene_name = "aircraft-climb-turn";
  assert_true(NavBuildSceneModel(r, opt, -1.0, &m, &err));
  assert_true(m.vehicle == NavVehicleKind::Aircraft);
  opt.show_gnss = false;
  assert_true(NavBuildSceneModel(r, opt, 0.01, &m, &err));
  assert_true(m.gnss_r.empty() && m.outage_segments.empty());
}

// The shapefile reader on a hand-made file: one polygon record with two parts.
void test_shapefile_and_graticule(void **) {
  std::vector<unsigned char> b(100, 0);
  auto be32 = [&](size_t at, uint32_t v) {
    for (int i = 0; i < 4; ++i)
      b[at + static_cast<size_t>(i)] = static_cast<unsigned char>(v >> (24 - 8 * i));
  };
  auto le32 = [&](int32_t v) {
    for (int i = 0; i < 4; ++i)
      b.push_back(static_cast<unsigned char>(static_cast<uint32_t>(v) >> (8 * i)));
  };
  auto lef = [&](double d) {
    uint64_t u;
    std::memcpy(&u, &d, 8);
    for (int i = 0; i < 8; ++i)
      b.push_back(static_cast<unsigned char>(u >> (8 * i)));
  };
  be32(0, 9994);
  const double pts[5][2] = {{10, 50}, {11, 50}, {11, 51}, {-20.5, 64}, {-21, 65.25}};
  const size_t content = 4 + 32 + 4 + 4 + 2 * 4 + 5 * 16;
  b.resize(108, 0);
  be32(100, 1);
  be32(104, static_cast<uint32_t>(content / 2));
  le32(5);
  for (double d : {-21.0, 50.0, 11.0, 65.25})
    lef(d);
  le32(2);
  le32(5);
  le32(0);
  le32(3);
  for (const auto &p : pts) {
    lef(p[0]);
    lef(p[1]);
  }
  const std::string path = std::string(NAVVIEW_TEST_OUT_DIR) + "/navview_test.shp";
  FILE *f = std::fopen(path.c_str(), "wb");
  if (!f) {
    std::string d = NAVVIEW_TEST_OUT_DIR;
    for (size_t q = 1; q != std::string::npos; q = d.find('/', q + 1))
      mkdir(d.substr(0, q).c_str(), 0755);
    mkdir(d.c_str(), 0755);
    f = std::fopen(path.c_str(), "wb");
  }
  assert_non_null(f);
  std::fwrite(b.data(), 1, b.size(), f);
  std::fclose(f);
  std::vector<std::vector<double>> parts;
  std::string err;
  assert_true(NavReadShapefile(path, &parts, &err));
  assert_int_equal(parts.size(), 2);
  assert_int_equal(parts[0].size(), 6);
  assert_int_equal(parts[1].size(), 4);
  assert_near(parts[1][2], -21.0, 0.0);
  assert_near(parts[1][3], 65.25, 0.0);
  // A truncated file is an error, not a crash.
  f = std::fopen(path.c_str(), "wb");
  std::fwrite(b.data(), 1, b.size() - 7, f);
  std::fclose(f);
  parts.clear();
  assert_false(NavReadShapefile(path, &parts, &err));
  assert_true(err.find("truncated") != std::string::npos);
  std::remove(path.c_str());
  // Graticule: 3 or more lines across.
  for (double span : {360.0, 36.0, 5.0, 0.7, 0.013})
    assert_true(span / NavGraticuleStepDeg(span) >= 3.0 && span / NavGraticuleStepDeg(span) < 16.0);
}

} // namespace

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_decimate_circle),
      cmocka_unit_test(test_decimate_random_walks),
      cmocka_unit_test(test_decimate_doubling_back_and_edges),
      cmocka_unit_test(test_render_adapter),
      cmocka_unit_test(test_envelope_radii),
      cmocka_unit_test(test_model_paths_within_tolerance),
      cmocka_unit_test(test_triad_orientation),
      cmocka_unit_test(test_pick_full_rate),
      cmocka_unit_test(test_grid_spacing),
      cmocka_unit_test(test_envelope_sources_and_ellipsoids),
      cmocka_unit_test(test_gnss_outages_requirements),
      cmocka_unit_test(test_shapefile_and_graticule),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
