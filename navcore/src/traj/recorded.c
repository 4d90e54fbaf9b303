/*
 * Recorded reference trajectories (nav_track.h): a least-squares fit of uniform quintic
 * B-splines to recorded samples, and the trajectory model that evaluates it.
 *
 * Why B-splines fitted by least squares, and not an interpolant through the samples: recorded
 * positions, velocities and attitudes are not exactly consistent with each other (irregular
 * sample times, rounding of the printed digits, the first row of a KF-GINS file being the
 * configured initial state: tests/data/recorded/README.md), so an interpolant would turn every
 * inconsistency into a spike of acceleration or angular acceleration, which the ideal IMU
 * would faithfully report. The fit spreads them, and what it cannot follow shows up in the
 * residuals instead of in the sensor data. The knot rate sets the bandwidth of the model.
 *
 * Why quintic: position must have a continuous acceleration (the specific force) and attitude a
 * continuous angular acceleration (nav_traj_state.dw_fb_b_rps2); quintic B-splines are C4, so
 * both are continuous with one derivative to spare (a continuous jerk keeps the Gauss-Legendre
 * quadrature of the ideal IMU at its design order across knots).
 *
 * Why p / |p| for attitude: a 4-vector spline normalised is smooth wherever |p| > 0, has no
 * gimbal lock (unlike Euler-angle splines) and gives the body rate in closed form:
 *   q = p / s, s = |p|:  conj(p) (x) p' = s s' + s^2 conj(q) (x) q', and conj(q) (x) q' = [0, w/2]
 *   => w_nb_b = 2 vec(conj(p) (x) p') / s^2                       (q_b_n Hamilton, q' = q (x) [0, w] / 2)
 *   => w' = 2 vec(conj(p) (x) p'') / s^2 - w 2 (p . p') / s^2       (vec(conj(p') (x) p') = 0)
 * The fit is linear (each component separately) once the sample quaternions are made
 * sign-continuous.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "navcore/nav_track.h"
#include "traj/traj_internal.h"

/* 120 x the uniform quintic B-spline basis on one knot interval: with u in [0, 1] the local
 * parameter of interval j, 120 B_i(u) = sum_k K[k][i] u^k weights control point j + i
 * (cardinal B-spline of order 6, N6(u + 5 - i) = (1/120) sum_m (-1)^m C(6,m) (u + 5 - i - m)_+^5;
 * de Boor, A Practical Guide to Splines, ch. IX). Row k sums to 120 for k = 0 and to 0 otherwise
 * (partition of unity); test_recorded checks that quadratics are reproduced exactly. */
static const double k_b5[6][6] = {
    {1.0, 26.0, 66.0, 26.0, 1.0, 0.0},    {-5.0, -50.0, 0.0, 50.0, 5.0, 0.0},
    {10.0, 20.0, -60.0, 20.0, 10.0, 0.0}, {-10.0, 20.0, 0.0, -20.0, 10.0, 0.0},
    {5.0, -20.0, 30.0, -20.0, 5.0, 0.0},  {-1.0, 5.0, -10.0, 10.0, -5.0, 1.0},
};

/* Band width of the normal equations, diagonal included: a sample touches 6 consecutive control
 * points. */
#define BAND 6
/* Penalty on third differences of the control points, relative to the weight of one sample
 * (see nav_track.h): definite normal equations in gaps, negligible elsewhere (on the vendored
 * KF-GINS slice, 1e-9 instead changes the printed residuals by < 0.1 mm; 1e-3 would start to
 * smooth the attitude, +0.005 deg RMS). */
#define PENALTY_REL 1e-6
/* |p| below this at a sample or on a fine grid means the attitude spline nearly vanishes:
 * the rotation between knots is too large for a chordal fit (unit samples give |p| ~ 1). */
#define MIN_ATT_NORM 0.5
/* Attitude samples this far apart (rotation angle) make the quaternion sign ambiguous. */
#define MAX_ATT_STEP_RAD (0.5 * NAV_PI)

/* ------------------------------------------------------------------ basis and evaluation */

/* b[d][i] = d^d B_i / du^d at u, d = 0..2. */
static void basis(double u, double b[3][6]) {
  for (int i = 0; i < 6; ++i) {
    double v = 0.0, d1 = 0.0, d2 = 0.0;
    for (int k = 5; k >= 0; --k) {
      d2 = d2 * u + 2.0 * d1;
      d1 = d1 * u + v;
      v = v * u + k_b5[k][i];
    }
    b[0][i] = v / 120.0;
    b[1][i] = d1 / 120.0;
    b[2][i] = d2 / 120.0;
  }
}

/* Knot interval of scene time t and the local parameter u; outside [0, intervals] the end
 * polynomials continue (smoothly, as nav_traj_eval promises slightly beyond both ends). */
static int locate(const nav_traj_recorded *rec, double t, double *u) {
  const int intervals = rec->count - 5;
  const double x = t / rec->knot_dt_s;
  double j = floor(x);
  if (j < 0.0) j = 0.0;
  if (j > (double)(intervals - 1)) j = (double)(intervals - 1);
  *u = x - j;
  return (int)j;
}

/* Curvilinear metres per radian of latitude and of longitude at the reference point. */
static void scales(const nav_traj_recorded *rec, double *m_lat, double *m_lon) {
  *m_lat = nav_earth_radius_meridian_m(rec->ref_lat_rad) + rec->ref_h_m;
  *m_lon = (nav_earth_radius_prime_vertical_m(rec->ref_lat_rad) + rec->ref_h_m) * cos(rec->ref_lat_rad);
}

/* The splines at scene time t: r[d] = d^d r_ned / dt^d, p[d] = d^d p / dt^d (d = 0..2). */
typedef struct spline_val {
  nav_vec3 r[3];
  double p[3][4];
} spline_val;

static spline_val spline_at(const nav_traj_recorded *rec, double t) {
  double u = 0.0, b[3][6];
  const int j = locate(rec, t, &u);
  basis(u, b);
  const double inv_dt[3] = {1.0, 1.0 / rec->knot_dt_s, 1.0 / (rec->knot_dt_s * rec->knot_dt_s)};
  spline_val s;
  memset(&s, 0, sizeof s);
  for (int d = 0; d < 3; ++d) {
    double x = 0.0, y = 0.0, z = 0.0, q[4] = {0.0, 0.0, 0.0, 0.0};
    for (int i = 0; i < 6; ++i) {
      const double w = b[d][i];
      const nav_vec3 c = rec->ctrl_ned_m[j + i];
      const nav_quat cq = rec->ctrl_q[j + i];
      x += w * c.x;
      y += w * c.y;
      z += w * c.z;
      q[0] += w * cq.w;
      q[1] += w * cq.x;
      q[2] += w * cq.y;
      q[3] += w * cq.z;
    }
    s.r[d] = nav_vec3_make(x * inv_dt[d], y * inv_dt[d], z * inv_dt[d]);
    for (int c = 0; c < 4; ++c)
      s.p[d][c] = q[c] * inv_dt[d];
  }
  return s;
}

static nav_quat quat_of(const double p[4]) {
  nav_quat q = {p[0], p[1], p[2], p[3]};
  return q;
}

/* Geodetic kinematics of the model at scene time t (the nav_geo_kin contract of
 * traj_internal.h), with the scales of scales(). The longitude is not wrapped (continuous along
 * the track). */
static nav_geo_kin geo_at(const nav_traj_recorded *rec, double m_lat, double m_lon, double t) {
  const spline_val s = spline_at(rec, t);
  nav_geo_kin g;
  /* Affine map (nav_scene.h, nav_traj_recorded): the derivatives carry over exactly. */
  g.pos.lat_rad = rec->ref_lat_rad + s.r[0].x / m_lat;
  g.pos.lon_rad = rec->ref_lon_rad + s.r[0].y / m_lon;
  g.pos.h_m = rec->ref_h_m - s.r[0].z;
  g.dpos = nav_vec3_make(s.r[1].x / m_lat, s.r[1].y / m_lon, -s.r[1].z);
  g.ddpos = nav_vec3_make(s.r[2].x / m_lat, s.r[2].y / m_lon, -s.r[2].z);
  /* Attitude q = p / |p|, rate and its derivative in closed form (file comment). */
  const nav_quat p = quat_of(s.p[0]), dp = quat_of(s.p[1]), ddp = quat_of(s.p[2]);
  const double s2 = p.w * p.w + p.x * p.x + p.y * p.y + p.z * p.z;
  const double pdp = p.w * dp.w + p.x * dp.x + p.y * dp.y + p.z * dp.z;
  const nav_quat a1 = nav_quat_mul(nav_quat_conj(p), dp);
  const nav_quat a2 = nav_quat_mul(nav_quat_conj(p), ddp);
  const nav_vec3 w = nav_vec3_make(2.0 * a1.x / s2, 2.0 * a1.y / s2, 2.0 * a1.z / s2);
  g.q_b_n = nav_quat_normalize(p);
  g.w_nb_b_rps = w;
  g.dw_nb_b_rps2 = nav_vec3_sub(nav_vec3_make(2.0 * a2.x / s2, 2.0 * a2.y / s2, 2.0 * a2.z / s2),
                                nav_vec3_scale(w, 2.0 * pdp / s2));
  return g;
}

/* Velocity N, E, D of geodetic kinematics (numerics.md E3.9). */
static nav_vec3 ned_velocity(const nav_geo_kin *g) {
  const double lat = g->pos.lat_rad, h = g->pos.h_m;
  return nav_vec3_make((nav_earth_radius_meridian_m(lat) + h) * g->dpos.x,
                       (nav_earth_radius_prime_vertical_m(lat) + h) * cos(lat) * g->dpos.y, -g->dpos.z);
}

static bool fitted(const nav_traj_recorded *rec) {
  return rec->count >= 6 && rec->count <= NAV_RECORDED_MAX_CTRL && rec->ctrl_ned_m != NULL &&
         rec->ctrl_q != NULL && rec->knot_dt_s > 0.0 &&
         isfinite(rec->knot_dt_s) && isfinite(rec->t0_s) && isfinite(rec->ref_lat_rad) &&
         isfinite(rec->ref_lon_rad) && isfinite(rec->ref_h_m) &&
         fabs(rec->ref_lat_rad) <= NAV_TRACK_MAX_ABS_LAT_RAD;
}

/* ------------------------------------------------------------------ public evaluation */

nav_status nav_track_eval(const nav_traj_recorded *rec, double t_s, nav_track_sample *out) {
  if (!rec || !out || !fitted(rec) || !isfinite(t_s)) return NAV_ERR_INVALID_ARG;
  double m_lat = 0.0, m_lon = 0.0;
  scales(rec, &m_lat, &m_lon);
  const nav_geo_kin g = geo_at(rec, m_lat, m_lon, t_s);
  nav_track_sample s;
  s.t_s = rec->t0_s + t_s;
  s.pos = g.pos;
  s.pos.lon_rad = nav_earth_wrap_lon(g.pos.lon_rad);
  s.v_n_mps = ned_velocity(&g);
  bool lock = false;
  s.att = nav_quat_to_euler(g.q_b_n, &lock);
  *out = s;
  return NAV_OK;
}

nav_status nav_track_set_scene_start(const nav_traj_recorded *rec, nav_scene *scene, bool origin_too) {
  nav_track_sample s;
  if (!scene || nav_track_eval(rec, 0.0, &s) != NAV_OK) return NAV_ERR_INVALID_ARG;
  if (origin_too) {
    scene->earth.origin_lat_rad = s.pos.lat_rad;
    scene->earth.origin_lon_rad = s.pos.lon_rad;
    scene->earth.origin_h_m = s.pos.h_m;
  }
  scene->trajectory.initial_attitude = s.att;
  return NAV_OK;
}

const char *nav_recorded_format_name(nav_recorded_format f) {
  switch (f) {
  case NAV_RECORDED_KF_GINS_NAV: return "kf_gins_nav";
  }
  return "unknown";
}

static bool sample_finite(const nav_track_sample *s) {
  return isfinite(s->t_s) && isfinite(s->pos.lat_rad) && isfinite(s->pos.lon_rad) && isfinite(s->pos.h_m) &&
         nav_vec3_isfinite(s->v_n_mps) && isfinite(s->att.roll_rad) && isfinite(s->att.pitch_rad) &&
         isfinite(s->att.yaw_rad);
}

/* Running statistics of one metric. */
typedef struct run_stat {
  bool any;
  double sum2, max, t_max;
} run_stat;

static void stat_add(run_stat *r, double v, double t) {
  r->sum2 += v * v;
  if (!r->any || v > r->max) {
    r->max = v;
    r->t_max = t;
  }
  r->any = true;
}

/* Position-spline acceleration at t (curvilinear N, E, D metres; the transport terms are far
 * below the plausibility margins of nav_track_warnings). */
static nav_vec3 spline_acc(const nav_traj_recorded *rec, double t) { return spline_at(rec, t).r[2]; }

/*
 * The model's acceleration and jerk at the samples and midway between them, against what the
 * recorded velocities support: |v_j - v_i| / (t_j - t_i) over steps of at least half the mean
 * sample spacing (closer rows, such as an extra row a few ms after another, would turn velocity
 * noise into acceleration), and the change of those accelerations per second. The jerk of the
 * model is a central difference of its analytic acceleration (h = knot spacing / 20: the
 * acceleration is a quartic polynomial per interval, so the error is O(h^2) of its 5th
 * derivative, far below the margins).
 */
static void dynamics(const nav_traj_recorded *rec, const nav_track_sample *s, size_t n, double m_lat, double m_lon,
                     nav_recorded_fit_stats *f) {
  (void)m_lat;
  (void)m_lon;
  const double span = s[n - 1].t_s - s[0].t_s;
  f->sample_rate_hz = n > 1 && span > 0.0 ? (double)(n - 1) / span : 0.0;
  const double h = rec->knot_dt_s / 20.0;
  for (size_t i = 0; i < n; ++i) {
    const double t = s[i].t_s - rec->t0_s;
    for (int mid = 0; mid < 2; ++mid) {
      if (mid && i + 1 == n) break;
      const double tt = mid ? 0.5 * (t + (s[i + 1].t_s - rec->t0_s)) : t;
      const double a = nav_vec3_norm(spline_acc(rec, tt));
      if (a > f->fit_acc_max_mps2) {
        f->fit_acc_max_mps2 = a;
        f->fit_acc_max_t_s = tt;
      }
      const double j = nav_vec3_norm(nav_vec3_scale(nav_vec3_sub(spline_acc(rec, tt + h), spline_acc(rec, tt - h)),
                                                    0.5 / h));
      if (j > f->fit_jerk_max_mps3) {
        f->fit_jerk_max_mps3 = j;
        f->fit_jerk_max_t_s = tt;
      }
    }
  }
  if (n < 2 || !(span > 0.0)) return;
  const double step_min = 0.5 * span / (double)(n - 1);
  bool have_prev = false;
  nav_vec3 a_prev = {0.0, 0.0, 0.0};
  double t_prev = 0.0;
  size_t j = 0;
  for (size_t i = 0; i < n; ++i) {
    if (j <= i) j = i + 1;
    while (j < n && s[j].t_s - s[i].t_s < step_min) ++j;
    if (j >= n) break;
    const double dt = s[j].t_s - s[i].t_s;
    const nav_vec3 a = nav_vec3_scale(nav_vec3_sub(s[j].v_n_mps, s[i].v_n_mps), 1.0 / dt);
    const double tm = 0.5 * (s[i].t_s + s[j].t_s);
    if (nav_vec3_norm(a) > f->rec_acc_max_mps2) f->rec_acc_max_mps2 = nav_vec3_norm(a);
    if (have_prev && tm - t_prev >= step_min) {
      const double jr = nav_vec3_norm(nav_vec3_sub(a, a_prev)) / (tm - t_prev);
      if (jr > f->rec_jerk_max_mps3) f->rec_jerk_max_mps3 = jr;
    }
    if (!have_prev || tm - t_prev >= step_min) {
      a_prev = a;
      t_prev = tm;
      have_prev = true;
    }
  }
}

unsigned nav_track_warnings(const nav_traj_recorded *rec, char *msg, size_t msg_size) {
  if (msg && msg_size) msg[0] = '\0';
  if (!rec || !fitted(rec)) return 0;
  const nav_recorded_fit_stats *f = &rec->fit;
  unsigned w = 0;
  size_t used = 0;
#define ADD(...)                                                                      \
  do {                                                                                \
    if (msg && used < msg_size) {                                                     \
      const int k = snprintf(msg + used, msg_size - used, __VA_ARGS__);              \
      if (k > 0) used += (size_t)k < msg_size - used ? (size_t)k : msg_size - used - 1; \
    }                                                                                 \
  } while (0)
  if (f->sample_rate_hz > 0.0 && rec->knot_rate_hz > f->sample_rate_hz) {
    w |= NAV_TRACK_WARN_KNOTS_OUTRUN;
    ADD("%sthe knots (%g Hz) outrun the samples (%.3g Hz on average): between samples the spline is free, and "
        "residuals near 0 do not mean a good model; set trajectory.recorded.knot_rate_hz to %.3g Hz or less.",
        used ? " " : "", rec->knot_rate_hz, f->sample_rate_hz, f->sample_rate_hz);
  }
  if (f->fit_acc_max_mps2 > 1.5 * f->rec_acc_max_mps2 + 0.1) {
    w |= NAV_TRACK_WARN_ACCEL;
    ADD("%sthe fitted acceleration reaches %.3g m/s^2 at t = %.6g s, while the recorded velocities show at most "
        "%.3g m/s^2: lower trajectory.recorded.knot_rate_hz or raise vel_sd_mps.",
        used ? " " : "", f->fit_acc_max_mps2, f->fit_acc_max_t_s, f->rec_acc_max_mps2);
  }
  if (f->fit_jerk_max_mps3 > 1.5 * f->rec_jerk_max_mps3 + 0.5) {
    w |= NAV_TRACK_WARN_JERK;
    ADD("%sthe fitted jerk reaches %.3g m/s^3 at t = %.6g s, while the recorded velocities show at most %.3g "
        "m/s^3: lower trajectory.recorded.knot_rate_hz.",
        used ? " " : "", f->fit_jerk_max_mps3, f->fit_jerk_max_t_s, f->rec_jerk_max_mps3);
  }
#undef ADD
  return w;
}

nav_status nav_track_residuals(const nav_traj_recorded *rec, const nav_track_sample *samples, size_t n,
                               nav_recorded_fit_stats *out) {
  if (!rec || !samples || !out || n == 0 || !fitted(rec)) return NAV_ERR_INVALID_ARG;
  for (size_t i = 0; i < n; ++i)
    if (!sample_finite(&samples[i])) return NAV_ERR_INVALID_ARG;
  run_stat pos = {false, 0.0, 0.0, 0.0}, vel = pos, att = pos, gap = pos;
  double sum_h2 = 0.0, sum_v2 = 0.0, m_lat = 0.0, m_lon = 0.0;
  scales(rec, &m_lat, &m_lon);
  for (size_t i = 0; i < n; ++i) {
    const nav_track_sample *s = &samples[i];
    const double t = s->t_s - rec->t0_s;
    const nav_geo_kin g = geo_at(rec, m_lat, m_lon, t);
    /* Model minus record in NED at the recorded position (Groves 2nd ed. eq. 2.119 scales). */
    const double lat = s->pos.lat_rad, h = s->pos.h_m;
    const double dn = (g.pos.lat_rad - lat) * (nav_earth_radius_meridian_m(lat) + h);
    const double de = remainder(g.pos.lon_rad - s->pos.lon_rad, NAV_TWO_PI) *
                      (nav_earth_radius_prime_vertical_m(lat) + h) * cos(lat);
    const double dd = -(g.pos.h_m - h);
    const double dh2 = dn * dn + de * de;
    sum_h2 += dh2;
    sum_v2 += dd * dd;
    stat_add(&pos, sqrt(dh2 + dd * dd), t);
    stat_add(&vel, nav_vec3_norm(nav_vec3_sub(ned_velocity(&g), s->v_n_mps)), t);
    stat_add(&att, nav_quat_angle_between(g.q_b_n, nav_euler_to_quat(s->att)), t);
    stat_add(&gap, i > 0 ? fabs(s->t_s - samples[i - 1].t_s) : 0.0, t);
  }
  const double dn = (double)n;
  nav_recorded_fit_stats f;
  memset(&f, 0, sizeof f);
  dynamics(rec, samples, n, m_lat, m_lon, &f);
  f.samples = (long)n;
  f.pos_rms_m = sqrt(pos.sum2 / dn);
  f.pos_max_m = pos.max;
  f.pos_max_t_s = pos.t_max;
  f.pos_h_rms_m = sqrt(sum_h2 / dn);
  f.pos_v_rms_m = sqrt(sum_v2 / dn);
  f.vel_rms_mps = sqrt(vel.sum2 / dn);
  f.vel_max_mps = vel.max;
  f.vel_max_t_s = vel.t_max;
  f.att_rms_rad = sqrt(att.sum2 / dn);
  f.att_max_rad = att.max;
  f.att_max_t_s = att.t_max;
  f.max_gap_s = gap.max;
  f.max_gap_t_s = gap.t_max;
  *out = f;
  return NAV_OK;
}

/* ------------------------------------------------------------------ banded least squares */

/* Symmetric band matrix, upper part: a[i * BAND + d] = A[i][i + d], d = 0..BAND-1. */
static void band_add_outer(double *a, int j, const double *x, double w) {
  for (int r = 0; r < 6; ++r)
    for (int c = r; c < 6; ++c)
      a[(size_t)(j + r) * BAND + (size_t)(c - r)] += w * x[r] * x[c];
}

/* In-place band Cholesky A = U^T U (U upper, same band). false if not definite. */
static bool band_cholesky(double *a, int n) {
  for (int j = 0; j < n; ++j) {
    double s = a[(size_t)j * BAND];
    const int k0 = j - (BAND - 1) > 0 ? j - (BAND - 1) : 0;
    for (int k = k0; k < j; ++k) {
      const double ukj = a[(size_t)k * BAND + (size_t)(j - k)];
      s -= ukj * ukj;
    }
    if (!(s > 0.0) || !isfinite(s)) return false;
    const double ujj = sqrt(s);
    a[(size_t)j * BAND] = ujj;
    for (int i = j + 1; i < n && i - j < BAND; ++i) {
      double t = a[(size_t)j * BAND + (size_t)(i - j)];
      const int m0 = i - (BAND - 1) > 0 ? i - (BAND - 1) : 0;
      for (int k = m0; k < j; ++k)
        t -= a[(size_t)k * BAND + (size_t)(j - k)] * a[(size_t)k * BAND + (size_t)(i - k)];
      a[(size_t)j * BAND + (size_t)(i - j)] = t / ujj;
    }
  }
  return true;
}

/* Solve U^T U x = b for m right-hand sides stored b[i * m + c]; x overwrites b. */
static void band_solve(const double *u, int n, double *b, int m) {
  for (int c = 0; c < m; ++c) {
    for (int i = 0; i < n; ++i) {
      double s = b[(size_t)i * (size_t)m + (size_t)c];
      const int k0 = i - (BAND - 1) > 0 ? i - (BAND - 1) : 0;
      for (int k = k0; k < i; ++k)
        s -= u[(size_t)k * BAND + (size_t)(i - k)] * b[(size_t)k * (size_t)m + (size_t)c];
      b[(size_t)i * (size_t)m + (size_t)c] = s / u[(size_t)i * BAND];
    }
    for (int i = n - 1; i >= 0; --i) {
      double s = b[(size_t)i * (size_t)m + (size_t)c];
      for (int k = i + 1; k < n && k - i < BAND; ++k)
        s -= u[(size_t)i * BAND + (size_t)(k - i)] * b[(size_t)k * (size_t)m + (size_t)c];
      b[(size_t)i * (size_t)m + (size_t)c] = s / u[(size_t)i * BAND];
    }
  }
}

/* Penalty lambda sum_r (c_r - 3 c_r+1 + 3 c_r+2 - c_r+3)^2 added to the normal matrix. */
static void band_add_penalty(double *a, int n, double lambda) {
  static const double d3[4] = {-1.0, 3.0, -3.0, 1.0};
  for (int r = 0; r + 3 < n; ++r)
    for (int i = 0; i < 4; ++i)
      for (int k = i; k < 4; ++k)
        a[(size_t)(r + i) * BAND + (size_t)(k - i)] += lambda * d3[i] * d3[k];
}

/* ------------------------------------------------------------------ the fit */

static void set_msg(char *msg, size_t size, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

static void set_msg(char *msg, size_t size, const char *fmt, ...) {
  if (!msg || size == 0) return;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, size, fmt, ap);
  va_end(ap);
}

static nav_status check_inputs(const nav_traj_recorded *rec, const nav_track_sample *s, size_t n, char *msg,
                               size_t msg_size) {
  if (!(rec->knot_rate_hz > 0.0 && rec->knot_rate_hz <= 1000.0)) {
    set_msg(msg, msg_size, "knot_rate_hz must be within (0, 1000] (got %g)", rec->knot_rate_hz);
    return NAV_ERR_INVALID_ARG;
  }
  if (!(rec->pos_sd_m > 0.0 && isfinite(rec->pos_sd_m)) ||
      !(rec->vel_sd_mps > 0.0 && isfinite(rec->vel_sd_mps))) {
    set_msg(msg, msg_size, "pos_sd_m and vel_sd_mps must be finite and > 0 (got %g, %g)", rec->pos_sd_m,
            rec->vel_sd_mps);
    return NAV_ERR_INVALID_ARG;
  }
  if (n < 2) {
    set_msg(msg, msg_size, "needs at least 2 samples (got %zu)", n);
    return NAV_ERR_INVALID_ARG;
  }
  for (size_t i = 0; i < n; ++i) {
    if (!sample_finite(&s[i])) {
      set_msg(msg, msg_size, "sample %zu is not finite", i);
      return NAV_ERR_INVALID_ARG;
    }
    if (fabs(s[i].pos.lat_rad) > NAV_TRACK_MAX_ABS_LAT_RAD) {
      set_msg(msg, msg_size,
              "sample %zu (t %.6f s) is at latitude %.6f deg; recorded trajectories stay within "
              "89 deg of the equator (the longitude scale vanishes at the poles)",
              i, s[i].t_s, s[i].pos.lat_rad * NAV_RAD2DEG);
      return NAV_ERR_INVALID_ARG;
    }
    if (!(s[i].pos.h_m > -1.0e5 && s[i].pos.h_m < 1.0e8)) {
      set_msg(msg, msg_size, "sample %zu (t %.6f s): height %g m is outside (-1e5, 1e8) m", i, s[i].t_s,
              s[i].pos.h_m);
      return NAV_ERR_INVALID_ARG;
    }
    if (i > 0 && !(s[i].t_s > s[i - 1].t_s)) {
      set_msg(msg, msg_size, "sample %zu: time %.6f s does not increase (previous %.6f s)", i, s[i].t_s,
              s[i - 1].t_s);
      return NAV_ERR_INVALID_ARG;
    }
  }
  const double span = s[n - 1].t_s - s[0].t_s;
  const double intervals = ceil(span * rec->knot_rate_hz - 1e-9);
  if (!(intervals + 5.0 <= (double)NAV_RECORDED_MAX_CTRL)) {
    /* The largest rate that fits, cut (not rounded up) to 4 significant digits. */
    const double max_rate = (double)(NAV_RECORDED_MAX_CTRL - 5) / span;
    const double unit = pow(10.0, floor(log10(max_rate)) - 3.0);
    set_msg(msg, msg_size,
            "%.3f s at knot_rate_hz %g needs %.0f control points, more than the %d a recorded reference may "
            "have; use "
            "knot_rate_hz <= %.4g or a shorter window (start_s, end_s)",
            span, rec->knot_rate_hz, intervals + 5.0, NAV_RECORDED_MAX_CTRL, floor(max_rate / unit) * unit);
    return NAV_ERR_OUT_OF_RANGE;
  }
  return NAV_OK;
}

/* One block for count position and count attitude control points (nav_scene.h, ctrl_ned_m): the
 * positions first, the quaternions after them (both arrays of doubles, so aligned). Sets
 * rec->ctrl_ned_m and rec->ctrl_q, or leaves them NULL and returns false. */
static bool ctrl_alloc(nav_traj_recorded *rec, int count) {
  rec->ctrl_ned_m = NULL;
  rec->ctrl_q = NULL;
  if (count <= 0 || count > NAV_RECORDED_MAX_CTRL) return false;
  unsigned char *block = malloc((size_t)count * (sizeof(nav_vec3) + sizeof(nav_quat)));
  if (!block) return false;
  rec->ctrl_ned_m = (nav_vec3 *)(void *)block;
  rec->ctrl_q = (nav_quat *)(void *)(block + (size_t)count * sizeof(nav_vec3));
  return true;
}

nav_status nav_track_fit(nav_traj_recorded *rec, const nav_track_sample *s, size_t n, char *msg,
                         size_t msg_size) {
  nav_traj_recorded *work = NULL;
  double *ap = NULL, *aq = NULL, *bp = NULL, *bq = NULL;
  nav_status st = NAV_OK;
  if (msg && msg_size) msg[0] = '\0';
  if (!rec || !s) return NAV_ERR_INVALID_ARG;
  st = check_inputs(rec, s, n, msg, msg_size);
  if (st != NAV_OK) return st;

  work = malloc(sizeof *work);
  if (!work) return NAV_ERR_NO_MEMORY;
  *work = *rec;
  work->ctrl_ned_m = NULL; /* rec's control points (if any) stay rec's */
  work->ctrl_q = NULL;
  work->t0_s = s[0].t_s;
  work->span_s = s[n - 1].t_s - s[0].t_s;
  work->ref_lat_rad = s[0].pos.lat_rad;
  work->ref_lon_rad = s[0].pos.lon_rad;
  work->ref_h_m = s[0].pos.h_m;
  work->knot_dt_s = 1.0 / rec->knot_rate_hz;
  const int intervals = (int)fmax(1.0, ceil(work->span_s * rec->knot_rate_hz - 1e-9));
  const int count = intervals + 5;
  work->count = count;
  const double dt = work->knot_dt_s;
  if (!ctrl_alloc(work, count)) {
    st = NAV_ERR_NO_MEMORY;
    goto cleanup;
  }

  ap = calloc((size_t)count * BAND, sizeof *ap);
  aq = calloc((size_t)count * BAND, sizeof *aq);
  bp = calloc((size_t)count * 3, sizeof *bp);
  bq = calloc((size_t)count * 4, sizeof *bq);
  if (!ap || !aq || !bp || !bq) {
    st = NAV_ERR_NO_MEMORY;
    goto cleanup;
  }

  {
    double m_lat = 0.0, m_lon = 0.0;
    scales(work, &m_lat, &m_lon);
    const double w_p = 1.0 / (rec->pos_sd_m * rec->pos_sd_m);
    const double w_v = 1.0 / (rec->vel_sd_mps * rec->vel_sd_mps);
    double lon_unwrapped = work->ref_lon_rad;
    nav_quat q_prev = nav_euler_to_quat(s[0].att);
    for (size_t i = 0; i < n; ++i) {
      const nav_track_sample *x = &s[i];
      double u = 0.0, b[3][6], bd[6];
      const int j = locate(work, x->t_s - work->t0_s, &u);
      basis(u, b);
      for (int k = 0; k < 6; ++k)
        bd[k] = b[1][k] / dt;
      /* Targets in the curvilinear coordinates: the longitude continued across +-180 deg, the
       * recorded velocity as d(N, E, D)/dt through the radii at the sample (E3.9). */
      if (i > 0) lon_unwrapped += remainder(x->pos.lon_rad - s[i - 1].pos.lon_rad, NAV_TWO_PI);
      const double lat = x->pos.lat_rad, h = x->pos.h_m;
      const double r[3] = {(lat - work->ref_lat_rad) * m_lat, (lon_unwrapped - work->ref_lon_rad) * m_lon,
                           work->ref_h_m - h};
      const double v[3] = {x->v_n_mps.x * m_lat / (nav_earth_radius_meridian_m(lat) + h),
                           x->v_n_mps.y * m_lon / ((nav_earth_radius_prime_vertical_m(lat) + h) * cos(lat)),
                           x->v_n_mps.z};
      band_add_outer(ap, j, b[0], w_p);
      band_add_outer(ap, j, bd, w_v);
      for (int k = 0; k < 6; ++k)
        for (int c = 0; c < 3; ++c)
          bp[(size_t)(j + k) * 3 + (size_t)c] += w_p * b[0][k] * r[c] + w_v * bd[k] * v[c];
      /* Attitude: the quaternion of the sample with the sign closest to the previous one. */
      nav_quat q = nav_euler_to_quat(x->att);
      const double dot = q.w * q_prev.w + q.x * q_prev.x + q.y * q_prev.y + q.z * q_prev.z;
      if (dot < 0.0) q = (nav_quat){-q.w, -q.x, -q.y, -q.z};
      if (i > 0 && 2.0 * acos(fmin(1.0, fabs(dot))) >= MAX_ATT_STEP_RAD) {
        set_msg(msg, msg_size,
                "samples %zu and %zu (t %.6f and %.6f s) are %.1f deg apart in attitude; consecutive samples "
                "must be less than 90 deg apart",
                i - 1, i, s[i - 1].t_s, x->t_s, 2.0 * acos(fmin(1.0, fabs(dot))) * NAV_RAD2DEG);
        st = NAV_ERR_INVALID_ARG;
        goto cleanup;
      }
      q_prev = q;
      band_add_outer(aq, j, b[0], 1.0);
      const double qc[4] = {q.w, q.x, q.y, q.z};
      for (int k = 0; k < 6; ++k)
        for (int c = 0; c < 4; ++c)
          bq[(size_t)(j + k) * 4 + (size_t)c] += b[0][k] * qc[c];
    }
    band_add_penalty(ap, count, PENALTY_REL * (w_p + w_v / (dt * dt)));
    band_add_penalty(aq, count, PENALTY_REL);
  }
  if (!band_cholesky(ap, count) || !band_cholesky(aq, count)) {
    set_msg(msg, msg_size, "the least-squares normal equations are not positive definite");
    st = NAV_ERR_NUMERIC;
    goto cleanup;
  }
  band_solve(ap, count, bp, 3);
  band_solve(aq, count, bq, 4);
  for (int k = 0; k < count; ++k) {
    work->ctrl_ned_m[k] = nav_vec3_make(bp[(size_t)k * 3], bp[(size_t)k * 3 + 1], bp[(size_t)k * 3 + 2]);
    work->ctrl_q[k] =
        (nav_quat){bq[(size_t)k * 4], bq[(size_t)k * 4 + 1], bq[(size_t)k * 4 + 2], bq[(size_t)k * 4 + 3]};
    if (!nav_vec3_isfinite(work->ctrl_ned_m[k]) || !isfinite(bq[(size_t)k * 4]) ||
        !isfinite(bq[(size_t)k * 4 + 1]) || !isfinite(bq[(size_t)k * 4 + 2]) ||
        !isfinite(bq[(size_t)k * 4 + 3])) {
      set_msg(msg, msg_size, "the fit is not finite");
      st = NAV_ERR_NUMERIC;
      goto cleanup;
    }
  }
  /* The attitude spline must stay away from 0 wherever it is evaluated: at the samples and on a
   * grid of 8 points per knot interval over the fitted span. */
  {
    double worst = INFINITY, t_worst = 0.0;
    for (size_t i = 0; i < n; ++i) {
      const double t = s[i].t_s - work->t0_s;
      const spline_val v = spline_at(work, t);
      const double m =
          sqrt(v.p[0][0] * v.p[0][0] + v.p[0][1] * v.p[0][1] + v.p[0][2] * v.p[0][2] + v.p[0][3] * v.p[0][3]);
      if (m < worst) {
        worst = m;
        t_worst = t;
      }
    }
    for (int k = 0; k <= 8 * intervals; ++k) {
      const double t = (double)k * dt / 8.0;
      const spline_val v = spline_at(work, t);
      const double m =
          sqrt(v.p[0][0] * v.p[0][0] + v.p[0][1] * v.p[0][1] + v.p[0][2] * v.p[0][2] + v.p[0][3] * v.p[0][3]);
      if (m < worst) {
        worst = m;
        t_worst = t;
      }
    }
    if (!(worst >= MIN_ATT_NORM)) {
      set_msg(
          msg, msg_size,
          "the attitude turns too fast for knot_rate_hz %g near t = %.3f s (spline norm %.3f < %.1f); raise "
          "knot_rate_hz",
          rec->knot_rate_hz, work->t0_s + t_worst, worst, MIN_ATT_NORM);
      st = NAV_ERR_NUMERIC;
      goto cleanup;
    }
  }
  st = nav_track_residuals(work, s, n, &work->fit);
  if (st != NAV_OK) goto cleanup;
  /* The model moves to rec. What rec pointed to before is not freed: rec may be a plain copy of
   * another record's settings (nav_track.h). */
  *rec = *work;
  work->ctrl_ned_m = NULL;
  work->ctrl_q = NULL;

cleanup:
  free(ap);
  free(aq);
  free(bp);
  free(bq);
  if (work) nav_traj_recorded_release(work);
  free(work);
  return st;
}

/* ------------------------------------------------------------------ ownership */

void nav_traj_recorded_release(nav_traj_recorded *rec) {
  if (!rec) return;
  free(rec->ctrl_ned_m); /* ctrl_q is in the same block (ctrl_alloc) */
  rec->ctrl_ned_m = NULL;
  rec->ctrl_q = NULL;
  rec->count = 0;
}

nav_status nav_traj_recorded_copy(nav_traj_recorded *dst, const nav_traj_recorded *src) {
  if (!dst || !src) return NAV_ERR_INVALID_ARG;
  if (dst == src) return NAV_OK;
  *dst = *src;
  dst->ctrl_ned_m = NULL;
  dst->ctrl_q = NULL;
  if (src->ctrl_ned_m == NULL || src->ctrl_q == NULL || src->count <= 0) {
    dst->count = 0;
    return NAV_OK;
  }
  if (!ctrl_alloc(dst, src->count)) {
    dst->count = 0;
    return NAV_ERR_NO_MEMORY;
  }
  memcpy(dst->ctrl_ned_m, src->ctrl_ned_m, (size_t)src->count * sizeof *src->ctrl_ned_m);
  memcpy(dst->ctrl_q, src->ctrl_q, (size_t)src->count * sizeof *src->ctrl_q);
  return NAV_OK;
}

/* ------------------------------------------------------------------ trajectory model */

typedef struct rec_model {
  nav_traj_recorded rec;
  double m_lat, m_lon; /* scales() of rec, computed once */
} rec_model;

static nav_status rec_eval(void *self, double t_s, nav_geo_kin *out) {
  const rec_model *m = self;
  *out = geo_at(&m->rec, m->m_lat, m->m_lon, t_s);
  return NAV_OK;
}

static void rec_destroy(void *self) {
  rec_model *m = self;
  nav_traj_recorded_release(&m->rec);
  free(m);
}

nav_status nav_traj_recorded_create(const nav_scene *scene, double dt_s, nav_traj_model *out, char *msg,
                                    size_t msg_size) {
  (void)dt_s;
  if (msg && msg_size) msg[0] = '\0';
  if (!scene || !out) return NAV_ERR_INVALID_ARG;
  const nav_traj_recorded *rec = &scene->trajectory.recorded;
  if (!fitted(rec)) {
    set_msg(msg, msg_size,
            "trajectory.recorded: no fitted samples (read the scene with navcore_io, or call nav_track_fit)");
    return NAV_ERR_INVALID_ARG;
  }
  rec_model *m = malloc(sizeof *m);
  if (!m) return NAV_ERR_NO_MEMORY;
  /* The trajectory object owns a copy of the control points: it does not depend on the scene's
   * lifetime. */
  if (nav_traj_recorded_copy(&m->rec, rec) != NAV_OK) {
    free(m);
    return NAV_ERR_NO_MEMORY;
  }
  scales(rec, &m->m_lat, &m->m_lon);
  memset(out, 0, sizeof *out);
  out->name = "recorded";
  out->duration_s = rec->span_s;
  out->self = m;
  out->eval_geodetic = rec_eval;
  out->destroy = rec_destroy;
  return NAV_OK;
}
