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

#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "nav_test.h"
#include "navview/nav_view_decimate.h"
#include "navview/nav_view_frame.h"
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
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
