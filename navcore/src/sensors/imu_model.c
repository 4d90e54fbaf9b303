/*
 * IMU error model (numerics.md 2.1-2.4) and the bias-instability mapping (2.3).
 * The model, its discretisation and its stream layout are described in nav_sensors.h; this file
 * explains only implementation choices.
 */
#include "navcore/nav_sensors.h"

#include <assert.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "navcore/nav_rng.h"
#include "nav_clones.h"
#include "rng/rng_internal.h"
#include "math/lanes4.h"
#include "sensors/imu_model_internal.h"

/* ------------------------------------------------------------------ bias instability -> GM */

double nav_gm_sigma_from_bias_instability(double b_instability, nav_bi_convention convention) {
  switch (convention) {
  case NAV_BI_ALLAN_PEAK: return b_instability / NAV_GM_ALLAN_PEAK_SIGMA_RATIO;
  case NAV_BI_SIGMA_EQUALS_B: return b_instability;
  }
  return NAN;
}

nav_gm_params nav_gm_from_bias_instability(double b_instability, double tau_min_s,
                                           nav_bi_convention convention) {
  nav_gm_params p;
  p.sigma = nav_gm_sigma_from_bias_instability(b_instability, convention);
  p.tau_s = tau_min_s / NAV_GM_ALLAN_PEAK_TAU_RATIO;
  return p;
}

const char *nav_bi_convention_name(nav_bi_convention c) {
  switch (c) {
  case NAV_BI_ALLAN_PEAK: return "allan_peak";
  case NAV_BI_SIGMA_EQUALS_B: return "sigma_equals_b";
  }
  return "unknown";
}

/* ------------------------------------------------------------------ configuration */

nav_imu_model_config nav_imu_model_config_default(void) {
  nav_imu_model_config c;
  /* All-bits-zero is 0.0 for IEEE-754 doubles and 0 for the masks: every term off. */
  memset(&c, 0, sizeof c);
  return c;
}

typedef struct checker {
  nav_scene_issue_fn report;
  void *user;
  int problems;
} checker;

static void issue(checker *ck, const char *path, const char *fmt, ...) {
  ck->problems++;
  if (!ck->report) return;
  char msg[256];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  ck->report(ck->user, path, msg);
}

static double vget(nav_vec3 v, int i) {
  return i == 0 ? v.x : (i == 1 ? v.y : v.z);
}

/* Each component finite and >= lo (strict: > lo). */
static void check_vec(checker *ck, const char *prefix, const char *name, nav_vec3 v, bool strict,
                      bool finite_only) {
  for (int i = 0; i < 3; ++i) {
    const double x = vget(v, i);
    char path[96];
    snprintf(path, sizeof path, "%s.%s[%d]", prefix, name, i);
    if (!isfinite(x)) {
      issue(ck, path, "must be a finite number, got %g", x);
    } else if (finite_only) {
      continue;
    } else if (strict && !(x > 0.0)) {
      issue(ck, path, "must be > 0, got %g", x);
    } else if (!strict && x < 0.0) {
      issue(ck, path, "is a standard deviation or density and must be >= 0, got %g", x);
    }
  }
}

static void check_mat(checker *ck, const char *prefix, const char *name, const nav_mat3 *m, bool nonneg,
                      bool zero_diagonal) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const double x = m->m[i][j];
      char path[96];
      snprintf(path, sizeof path, "%s.%s[%d][%d]", prefix, name, i, j);
      if (!isfinite(x))
        issue(ck, path, "must be a finite number, got %g", x);
      else if (zero_diagonal && i == j && x != 0.0)
        issue(ck, path, "diagonal must be 0 (scale-factor errors belong in scale_factor_*), got %g", x);
      else if (nonneg && x < 0.0)
        issue(ck, path, "is a standard deviation and must be >= 0, got %g", x);
    }
}

static void check_tau(checker *ck, const char *prefix, nav_vec3 tau) {
  for (int i = 0; i < 3; ++i) {
    const double x = vget(tau, i);
    char path[96];
    snprintf(path, sizeof path, "%s.bias_gm_tau_s[%d]", prefix, i);
    if (!(isfinite(x) && x > 0.0))
      issue(ck, path, "correlation time must be finite and > 0 s, got %g (use bias_turn_on for a constant)",
            x);
  }
}

nav_status nav_imu_model_config_validate(const nav_imu_model_config *cfg, nav_scene_issue_fn report,
                                         void *user) {
  if (cfg == NULL) return NAV_ERR_INVALID_ARG;
  checker ck = {report, user, 0};
  const nav_gyro_error_config *g = &cfg->gyro;
  const nav_accel_error_config *a = &cfg->accel;
  if (g->terms & ~NAV_IMU_TERMS_GYRO_ALL)
    issue(&ck, "gyro.terms", "unknown term bits 0x%x", g->terms & ~NAV_IMU_TERMS_GYRO_ALL);
  if (a->terms & ~NAV_IMU_TERMS_ACCEL_ALL)
    issue(&ck, "accel.terms", "unknown term bits 0x%x (g-sensitivity is a gyro term)",
          a->terms & ~NAV_IMU_TERMS_ACCEL_ALL);

  if (g->terms & NAV_IMU_TERM_BIAS_TURN_ON) {
    check_vec(&ck, "gyro", "bias_turn_on_fixed_rps", g->bias_turn_on_fixed_rps, false, true);
    check_vec(&ck, "gyro", "bias_turn_on_sd_rps", g->bias_turn_on_sd_rps, false, false);
  }
  if (g->terms & NAV_IMU_TERM_BIAS_GM) {
    check_vec(&ck, "gyro", "bias_gm_sd_rps", g->bias_gm_sd_rps, false, false);
    check_tau(&ck, "gyro", g->bias_gm_tau_s);
  }
  if (g->terms & NAV_IMU_TERM_BIAS_RW)
    check_vec(&ck, "gyro", "bias_rw_rps_per_sqrt_s", g->bias_rw_rps_per_sqrt_s, false, false);
  if (g->terms & NAV_IMU_TERM_NOISE)
    check_vec(&ck, "gyro", "arw_rad_per_sqrt_s", g->arw_rad_per_sqrt_s, false, false);
  if (g->terms & NAV_IMU_TERM_SCALE_FACTOR) {
    check_vec(&ck, "gyro", "scale_factor_fixed", g->scale_factor_fixed, false, true);
    check_vec(&ck, "gyro", "scale_factor_sd", g->scale_factor_sd, false, false);
  }
  if (g->terms & NAV_IMU_TERM_MISALIGNMENT) {
    check_mat(&ck, "gyro", "misalignment_fixed_rad", &g->misalignment_fixed_rad, false, true);
    check_mat(&ck, "gyro", "misalignment_sd_rad", &g->misalignment_sd_rad, true, true);
  }
  if (g->terms & NAV_IMU_TERM_G_SENSITIVITY) {
    check_mat(&ck, "gyro", "g_sensitivity_fixed_rps_per_mps2", &g->g_sensitivity_fixed_rps_per_mps2, false,
              false);
    check_mat(&ck, "gyro", "g_sensitivity_sd_rps_per_mps2", &g->g_sensitivity_sd_rps_per_mps2, true, false);
  }
  if (g->terms & NAV_IMU_TERM_QUANTISATION)
    check_vec(&ck, "gyro", "quant_step_rad", g->quant_step_rad, true, false);
  if (g->terms & NAV_IMU_TERM_SATURATION) check_vec(&ck, "gyro", "range_rps", g->range_rps, true, false);

  if (a->terms & NAV_IMU_TERM_BIAS_TURN_ON) {
    check_vec(&ck, "accel", "bias_turn_on_fixed_mps2", a->bias_turn_on_fixed_mps2, false, true);
    check_vec(&ck, "accel", "bias_turn_on_sd_mps2", a->bias_turn_on_sd_mps2, false, false);
  }
  if (a->terms & NAV_IMU_TERM_BIAS_GM) {
    check_vec(&ck, "accel", "bias_gm_sd_mps2", a->bias_gm_sd_mps2, false, false);
    check_tau(&ck, "accel", a->bias_gm_tau_s);
  }
  if (a->terms & NAV_IMU_TERM_BIAS_RW)
    check_vec(&ck, "accel", "bias_rw_mps2_per_sqrt_s", a->bias_rw_mps2_per_sqrt_s, false, false);
  if (a->terms & NAV_IMU_TERM_NOISE)
    check_vec(&ck, "accel", "vrw_mps_per_sqrt_s", a->vrw_mps_per_sqrt_s, false, false);
  if (a->terms & NAV_IMU_TERM_SCALE_FACTOR) {
    check_vec(&ck, "accel", "scale_factor_fixed", a->scale_factor_fixed, false, true);
    check_vec(&ck, "accel", "scale_factor_sd", a->scale_factor_sd, false, false);
  }
  if (a->terms & NAV_IMU_TERM_MISALIGNMENT) {
    check_mat(&ck, "accel", "misalignment_fixed_rad", &a->misalignment_fixed_rad, false, true);
    check_mat(&ck, "accel", "misalignment_sd_rad", &a->misalignment_sd_rad, true, true);
  }
  if (a->terms & NAV_IMU_TERM_QUANTISATION)
    check_vec(&ck, "accel", "quant_step_mps", a->quant_step_mps, true, false);
  if (a->terms & NAV_IMU_TERM_SATURATION) check_vec(&ck, "accel", "range_mps2", a->range_mps2, true, false);
  return ck.problems == 0 ? NAV_OK : NAV_ERR_INVALID_ARG;
}

/* ------------------------------------------------------------------ model */

/* Cholesky factor of the covariance of (bias step e1, integral e2) for one axis; see the header.
 * b_k = phi b + l11 u1;  I_k = c_int b + l21 u1 + l22 u2. */
/* Slots of the interval cache of a model (power of two). */
#define DT_CACHE_SLOTS 16

typedef struct pair_coef {
  double phi, c_int, l11, l21, l22;
} pair_coef;

/* One sensor triad in a layout that the per-sample loop reads straight (arrays, not nav_vec3,
 * so the axis loops index without branches). Units: rad and rad/s for the gyro, m/s and m/s^2 for
 * the accelerometer. */
typedef struct triad {
  unsigned terms;
  bool apply_m;   /* scale factor or misalignment on: multiply by (I + M) */
  bool any_bias;  /* turn-on, GM or random-walk bias on */
  double b0[3];   /* turn-on bias */
  double gm_b[3]; /* GM state */
  double gm_sd[3], gm_tau[3];
  double rw_b[3]; /* random-walk state */
  double rw_k[3];
  double ib[3];        /* the bias integral over the last interval (its mean is ib / dt) */
  double n_density[3]; /* white noise density N */
  nav_mat3 m;          /* M: scale factor on the diagonal, misalignment off it */
  double q_step[3], q_res[3];
  double range[3];
  /* The three axes' streams of each term side by side (rng_internal.h): one vector step draws a
   * deviate for every axis, the same values as one nav_rng_gauss() per axis and deviate. */
  nav_rng_lanes rng_noise, rng_gm, rng_rw;
} triad;

/* The dt-dependent coefficients of both triads (0: gyro, 1: accelerometer) for one interval. */
typedef struct dt_slot {
  double dt; /* 0: empty */
  pair_coef gm_c[2][3], rw_c[2][3];
  double n_sd[2][3]; /* N sqrt(dt) */
} dt_slot;

struct nav_imu_model {
  triad gyro, accel;
  bool apply_g;
  bool ideal; /* no term on at all: apply() is a checked copy */
  nav_mat3 g_sens;
  double dt_cached; /* 0 until the first sample: dt must be > 0, so 0 never matches */
  /* Coefficients of recently seen intervals. The increments' dt = t_k - t_(k-1) of a uniform
   * grid differs from sample to sample in its last bits (t_k = k dt rounded), which made
   * set_dt (two exp/expm1 per GM axis) run at nearly every sample; the few distinct values
   * are cached by their exact bits, so the coefficients are exactly those set_dt computes.
   * The samples read them through cur (the slot of dt_cached): a change of dt, at about every
   * other sample early in a run, is a pointer switch, not a copy of the coefficients. */
  dt_slot dt_cache[DT_CACHE_SLOTS];
  const dt_slot *cur;
  nav_imu_run_constants consts;
  nav_imu_bias_state bias;
  /* nav_imu_model_defer_bias(): the bias values of bias are formed by nav_imu_model_bias() when it
   * is called after a sample (bias_stale) instead of at every sample; bias_dt is that sample's dt. */
  bool defer_bias, bias_stale;
  double bias_dt;
  char last_error[256];
};

/*
 * f(x) = x - 3/2 + 2 exp(-x) - exp(-2x)/2, x = dt/T: Var(e2) / (2 sigma^2 T^2) of the GM pair.
 * f(x) = x^3/3 - x^4/4 + 7 x^5/60 - ...: for small x the closed form cancels catastrophically (at
 * x = 1e-5, the usual dt/T of a MEMS model, the terms are 1e-5 and the result 3e-16), so below
 * x = 0.5 the Taylor series sum_{n>=3} (-1)^n (2 - 2^(n-1)) x^n / n! is used. At x = 0.5 the
 * closed form loses only log10(1.5/0.029) ~ 2 digits and the series converges with ratio
 * <= 2x/n; above 0.5 the closed form is accurate to about 1e-14 relative.
 */
static double gm_pair_f(double x) {
  if (x >= 0.5) return x - 1.5 + 2.0 * exp(-x) - 0.5 * exp(-2.0 * x);
  double p = x * x * x / 6.0; /* x^n / n! at n = 3 */
  double pow2 = 4.0;          /* 2^(n-1) at n = 3 */
  double sum = 0.0;
  for (int n = 3; n < 60; ++n) {
    const double term = ((n & 1) ? -1.0 : 1.0) * (2.0 - pow2) * p;
    sum += term;
    if (fabs(term) <= 1e-18 * fabs(sum)) break;
    p *= x / (double)(n + 1);
    pow2 *= 2.0;
  }
  return sum;
}

/* Exact joint discretisation of (b, integral b) for a first-order GM over dt (header, E2.4). */
static pair_coef gm_pair(double sd, double tau, double dt) {
  pair_coef c;
  const double x = dt / tau;
  /* 1 - phi and 1 - phi^2 through expm1: exact to an ulp even when dt << T. */
  const double one_m_phi = -expm1(-x);
  const double one_m_phi2 = -expm1(-2.0 * x);
  const double var_b = sd * sd;
  c.phi = exp(-x);
  c.c_int = tau * one_m_phi;
  const double p11 = var_b * one_m_phi2;
  const double p12 = var_b * tau * one_m_phi * one_m_phi;
  const double p22 = 2.0 * var_b * tau * tau * gm_pair_f(x);
  c.l11 = sqrt(p11);
  c.l21 = p11 > 0.0 ? p12 / c.l11 : 0.0;
  /* The conditional variance p22 - p12^2/p11 tends to sigma^2 T^2 x^3 / 6 (= q dt^3 / 12, the
   * random-walk value); the subtraction cancels only 2 of 3 parts, so no series is needed. The
   * fmax guards the last-ulp negative result for sd = 0 or extreme x. */
  c.l22 = sqrt(fmax(p22 - c.l21 * c.l21, 0.0));
  return c;
}

/* Exact joint discretisation of (b, integral b) for a random walk with density k over dt (E2.7). */
static pair_coef rw_pair(double k, double dt) {
  pair_coef c;
  const double sdt = sqrt(dt);
  c.phi = 1.0;
  c.c_int = dt;
  c.l11 = k * sdt;
  c.l21 = 0.5 * k * dt * sdt;       /* cov / l11 = (k^2 dt^2 / 2) / (k sqrt(dt)) */
  c.l22 = k * dt * sqrt(dt / 12.0); /* k^2 dt^3/3 - (k dt^1.5 / 2)^2 = k^2 dt^3 / 12 */
  return c;
}

/* The coefficients of both triads for interval dt, into slot e. */
static void slot_fill(const nav_imu_model *m, dt_slot *e, double dt) {
  const triad *t[2] = {&m->gyro, &m->accel};
  for (int s = 0; s < 2; ++s) {
    const double sdt = sqrt(dt);
    for (int i = 0; i < 3; ++i) {
      if (t[s]->terms & NAV_IMU_TERM_BIAS_GM) e->gm_c[s][i] = gm_pair(t[s]->gm_sd[i], t[s]->gm_tau[i], dt);
      if (t[s]->terms & NAV_IMU_TERM_BIAS_RW) e->rw_c[s][i] = rw_pair(t[s]->rw_k[i], dt);
      e->n_sd[s][i] = t[s]->n_density[i] * sdt;
    }
  }
  e->dt = dt;
}

/* Make the coefficients for interval dt current: from the cache when this exact dt was seen,
 * else computed into its slot (the slot from the bits of dt). */
NAV_CLONE_INLINE void set_dt(nav_imu_model *m, double dt) {
  uint64_t bits;
  memcpy(&bits, &dt, sizeof bits);
  bits ^= bits >> 29;
  bits *= 0x9E3779B97F4A7C15ull;
  dt_slot *e = &m->dt_cache[bits >> 60 & (DT_CACHE_SLOTS - 1)];
  if (e->dt != dt) slot_fill(m, e, dt);
  m->cur = e;
  m->dt_cached = dt;
}

static void vec_to_arr(double a[3], nav_vec3 v) {
  a[0] = v.x;
  a[1] = v.y;
  a[2] = v.z;
}

static nav_vec3 arr_to_vec(const double a[3]) {
  return nav_vec3_make(a[0], a[1], a[2]);
}

static void rng_triplet(nav_rng r[3], uint64_t seed, uint64_t run, nav_rng_stream_kind kind) {
  for (unsigned i = 0; i < 3; ++i)
    nav_rng_init(&r[i], seed, run, nav_rng_stream_id(kind, i));
}

/* A per-run random scalar: fixed + sd u with u the first draw of stream (kind, channel). */
static double draw_const(uint64_t seed, uint64_t run, nav_rng_stream_kind kind, unsigned channel,
                         double fixed, double sd) {
  nav_rng r;
  nav_rng_init(&r, seed, run, nav_rng_stream_id(kind, channel));
  return fixed + sd * nav_rng_gauss(&r);
}

/* Stream kinds of one triad. */
typedef struct triad_kinds {
  nav_rng_stream_kind noise, turn_on, gm, rw, sf, ma;
} triad_kinds;

/* The parameters common to both triads, gathered once so that one init routine serves both. */
typedef struct triad_params {
  unsigned terms;
  nav_vec3 b0_fixed, b0_sd, gm_sd, gm_tau, rw_k, n, sf_fixed, sf_sd, q_step, range;
  nav_mat3 ma_fixed, ma_sd;
} triad_params;

static void triad_init(triad *t, const triad_params *p, const triad_kinds *k, uint64_t seed, uint64_t run) {
  memset(t, 0, sizeof *t);
  t->terms = p->terms;
  const double b0_fixed[3] = {p->b0_fixed.x, p->b0_fixed.y, p->b0_fixed.z};
  const double b0_sd[3] = {p->b0_sd.x, p->b0_sd.y, p->b0_sd.z};
  const double sf_fixed[3] = {p->sf_fixed.x, p->sf_fixed.y, p->sf_fixed.z};
  const double sf_sd[3] = {p->sf_sd.x, p->sf_sd.y, p->sf_sd.z};
  if (t->terms & NAV_IMU_TERM_BIAS_TURN_ON)
    for (unsigned i = 0; i < 3; ++i)
      t->b0[i] = draw_const(seed, run, k->turn_on, i, b0_fixed[i], b0_sd[i]);
  nav_rng r[3];
  if (t->terms & NAV_IMU_TERM_BIAS_GM) {
    vec_to_arr(t->gm_sd, p->gm_sd);
    vec_to_arr(t->gm_tau, p->gm_tau);
    rng_triplet(r, seed, run, k->gm);
    /* Stationary start (E2.5): the first draw of each axis' GM stream. */
    for (int i = 0; i < 3; ++i)
      t->gm_b[i] = t->gm_sd[i] * nav_rng_gauss(&r[i]);
    nav_rng_lanes_pack(&t->rng_gm, r, 3);
  }
  if (t->terms & NAV_IMU_TERM_BIAS_RW) {
    vec_to_arr(t->rw_k, p->rw_k);
    rng_triplet(r, seed, run, k->rw);
    nav_rng_lanes_pack(&t->rng_rw, r, 3);
  }
  if (t->terms & NAV_IMU_TERM_NOISE) {
    vec_to_arr(t->n_density, p->n);
    rng_triplet(r, seed, run, k->noise);
    nav_rng_lanes_pack(&t->rng_noise, r, 3);
  }
  if (t->terms & NAV_IMU_TERM_SCALE_FACTOR)
    for (unsigned i = 0; i < 3; ++i)
      t->m.m[i][i] = draw_const(seed, run, k->sf, i, sf_fixed[i], sf_sd[i]);
  if (t->terms & NAV_IMU_TERM_MISALIGNMENT)
    for (unsigned i = 0; i < 3; ++i)
      for (unsigned j = 0; j < 3; ++j)
        if (i != j)
          t->m.m[i][j] = draw_const(seed, run, k->ma, 3 * i + j, p->ma_fixed.m[i][j], p->ma_sd.m[i][j]);
  t->apply_m = (t->terms & (NAV_IMU_TERM_SCALE_FACTOR | NAV_IMU_TERM_MISALIGNMENT)) != 0;
  t->any_bias = (t->terms & (NAV_IMU_TERM_BIAS_TURN_ON | NAV_IMU_TERM_BIAS_GM | NAV_IMU_TERM_BIAS_RW)) != 0;
  if (t->terms & NAV_IMU_TERM_QUANTISATION) vec_to_arr(t->q_step, p->q_step);
  if (t->terms & NAV_IMU_TERM_SATURATION) vec_to_arr(t->range, p->range);
}

nav_status nav_imu_model_create(const nav_imu_model_config *cfg, uint64_t seed, uint64_t run,
                                nav_imu_model **out) {
  assert(cfg != NULL && out != NULL);
  if (cfg == NULL || out == NULL) return NAV_ERR_INVALID_ARG;
  if (nav_imu_model_config_validate(cfg, NULL, NULL) != NAV_OK) return NAV_ERR_INVALID_ARG;
  nav_imu_model *m = calloc(1, sizeof *m);
  if (m == NULL) return NAV_ERR_NO_MEMORY;

  const nav_gyro_error_config *g = &cfg->gyro;
  const nav_accel_error_config *a = &cfg->accel;
  const triad_params gp = {g->terms,
                           g->bias_turn_on_fixed_rps,
                           g->bias_turn_on_sd_rps,
                           g->bias_gm_sd_rps,
                           g->bias_gm_tau_s,
                           g->bias_rw_rps_per_sqrt_s,
                           g->arw_rad_per_sqrt_s,
                           g->scale_factor_fixed,
                           g->scale_factor_sd,
                           g->quant_step_rad,
                           g->range_rps,
                           g->misalignment_fixed_rad,
                           g->misalignment_sd_rad};
  const triad_params ap = {a->terms,
                           a->bias_turn_on_fixed_mps2,
                           a->bias_turn_on_sd_mps2,
                           a->bias_gm_sd_mps2,
                           a->bias_gm_tau_s,
                           a->bias_rw_mps2_per_sqrt_s,
                           a->vrw_mps_per_sqrt_s,
                           a->scale_factor_fixed,
                           a->scale_factor_sd,
                           a->quant_step_mps,
                           a->range_mps2,
                           a->misalignment_fixed_rad,
                           a->misalignment_sd_rad};
  const triad_kinds gk = {NAV_RNG_STREAM_GYRO_NOISE,        NAV_RNG_STREAM_GYRO_BIAS_TURN_ON,
                          NAV_RNG_STREAM_GYRO_BIAS_GM,      NAV_RNG_STREAM_GYRO_BIAS_RW,
                          NAV_RNG_STREAM_GYRO_SCALE_FACTOR, NAV_RNG_STREAM_GYRO_MISALIGNMENT};
  const triad_kinds ak = {NAV_RNG_STREAM_ACCEL_NOISE,        NAV_RNG_STREAM_ACCEL_BIAS_TURN_ON,
                          NAV_RNG_STREAM_ACCEL_BIAS_GM,      NAV_RNG_STREAM_ACCEL_BIAS_RW,
                          NAV_RNG_STREAM_ACCEL_SCALE_FACTOR, NAV_RNG_STREAM_ACCEL_MISALIGNMENT};
  triad_init(&m->gyro, &gp, &gk, seed, run);
  triad_init(&m->accel, &ap, &ak, seed, run);
  m->apply_g = (g->terms & NAV_IMU_TERM_G_SENSITIVITY) != 0;
  if (m->apply_g)
    for (unsigned i = 0; i < 3; ++i)
      for (unsigned j = 0; j < 3; ++j)
        m->g_sens.m[i][j] =
            draw_const(seed, run, NAV_RNG_STREAM_GYRO_G_SENSITIVITY, 3 * i + j,
                       g->g_sensitivity_fixed_rps_per_mps2.m[i][j], g->g_sensitivity_sd_rps_per_mps2.m[i][j]);

  m->ideal = g->terms == 0 && a->terms == 0;
  m->consts.gyro_bias_turn_on_rps = arr_to_vec(m->gyro.b0);
  m->consts.accel_bias_turn_on_mps2 = arr_to_vec(m->accel.b0);
  m->consts.M_g = m->gyro.m;
  m->consts.M_a = m->accel.m;
  m->consts.G_g_rps_per_mps2 = m->g_sens;

  m->bias.k = -1;
  m->bias.t_s = 0.0;
  m->bias.gyro_gm_rps = arr_to_vec(m->gyro.gm_b);
  m->bias.gyro_rw_rps = nav_vec3_zero();
  m->bias.gyro_rps = nav_vec3_add(m->consts.gyro_bias_turn_on_rps, m->bias.gyro_gm_rps);
  m->bias.gyro_mean_rps = nav_vec3_zero();
  m->bias.accel_gm_mps2 = arr_to_vec(m->accel.gm_b);
  m->bias.accel_rw_mps2 = nav_vec3_zero();
  m->bias.accel_mps2 = nav_vec3_add(m->consts.accel_bias_turn_on_mps2, m->bias.accel_gm_mps2);
  m->bias.accel_mean_mps2 = nav_vec3_zero();
  m->dt_cached = 0.0;
  *out = m;
  return NAV_OK;
}

void nav_imu_model_destroy(nav_imu_model *model) {
  free(model);
}

/*
 * One triad, one interval, with the triad's coefficients for dt (gm_c, rw_c, n_sd). x: ideal
 * increment; extra: added before noise (gyro: G_g dv), NULL if none. Writes the measured increment into y,
 * the bias integral over the interval into t->ib (when the triad has a bias term), the saturation flags (bits
 * 0-2) into *sat. Each enabled term is one branch followed by straight per-axis code.
 *
 * Inlined into nav_imu_model_apply, with every intermediate in a local array that does not escape
 * (so in registers) and each output written once: values that went through memory with scalar
 * stores and came back as 16-byte pairs (or the reverse) could not be forwarded from the store
 * buffer, a stall of ~10 cycles per such read at every sample.
 */
NAV_CLONE_INLINE void triad_apply(triad *t, const pair_coef *gm_c, const pair_coef *rw_c, const double *n_sd,
                                  const double x[3], const double *extra, double dt, double y_out[3],
                                  unsigned *sat) {
  const unsigned terms = t->terms;
  double y[3];
  if (t->apply_m) {
    /* (I + M) x, written as x + M x so that M = 0 reproduces x bit for bit. */
    for (int i = 0; i < 3; ++i)
      y[i] = x[i] + (t->m.m[i][0] * x[0] + t->m.m[i][1] * x[1] + t->m.m[i][2] * x[2]);
  } else {
    y[0] = x[0];
    y[1] = x[1];
    y[2] = x[2];
  }
  double ib[3] = {0.0, 0.0, 0.0}; /* integral of the bias over the interval */
  if (terms & NAV_IMU_TERM_BIAS_TURN_ON)
    for (int i = 0; i < 3; ++i)
      ib[i] += t->b0[i] * dt;
  /* Draws: one vector step per term, triad and draw (rng_internal.h) gives one deviate per axis,
   * the same values as one nav_rng_gauss() per axis and deviate. Per axis the order is fixed: u1
   * (bias step), then u2 (integral). */
  double u1s[4], u2s[4];
  if (terms & NAV_IMU_TERM_BIAS_GM) {
    nav_rng_lanes_gauss(&t->rng_gm, 3, u1s);
    nav_rng_lanes_gauss(&t->rng_gm, 3, u2s);
    for (int i = 0; i < 3; ++i) {
      const pair_coef *c = &gm_c[i];
      const double u1 = u1s[i], u2 = u2s[i], b = t->gm_b[i];
      ib[i] += c->c_int * b + c->l21 * u1 + c->l22 * u2;
      t->gm_b[i] = c->phi * b + c->l11 * u1;
    }
  }
  if (terms & NAV_IMU_TERM_BIAS_RW) {
    nav_rng_lanes_gauss(&t->rng_rw, 3, u1s);
    nav_rng_lanes_gauss(&t->rng_rw, 3, u2s);
    for (int i = 0; i < 3; ++i) {
      const pair_coef *c = &rw_c[i];
      const double u1 = u1s[i], u2 = u2s[i], b = t->rw_b[i];
      ib[i] += c->c_int * b + c->l21 * u1 + c->l22 * u2;
      t->rw_b[i] = b + c->l11 * u1;
    }
  }
  if (t->any_bias)
    for (int i = 0; i < 3; ++i) {
      y[i] += ib[i];
      t->ib[i] = ib[i];
    }
  if (extra)
    for (int i = 0; i < 3; ++i)
      y[i] += extra[i];
  if (terms & NAV_IMU_TERM_NOISE) {
    nav_rng_lanes_gauss(&t->rng_noise, 3, u1s);
    for (int i = 0; i < 3; ++i)
      y[i] += n_sd[i] * u1s[i];
  }
  unsigned flags = 0;
  if (terms & NAV_IMU_TERM_SATURATION)
    for (int i = 0; i < 3; ++i) {
      const double lim = t->range[i] * dt;
      if (y[i] > lim) {
        y[i] = lim;
        flags |= 1u << i;
      } else if (y[i] < -lim) {
        y[i] = -lim;
        flags |= 1u << i;
      }
    }
  *sat = flags;
  if (terms & NAV_IMU_TERM_QUANTISATION)
    for (int i = 0; i < 3; ++i) {
      /* E2.8 with the residual r = S_k - Q_k carried instead of the running sums S and Q: the same
       * sequence in exact arithmetic, but |r| <= step/2 stays small, whereas S grows without bound
       * (an accelerometer integrates g: 1e7 m/s after 12 days) and Q_k - Q_(k-1) would lose
       * digits. round() is independent of the floating-point rounding mode. */
      const double v = t->q_res[i] + y[i];
      const double q = t->q_step[i] * round(v / t->q_step[i]);
      t->q_res[i] = v - q;
      y[i] = q;
    }
  y_out[0] = y[0];
  y_out[1] = y[1];
  y_out[2] = y[2];
}

static nav_status fail(nav_imu_model *m, nav_status st, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(m->last_error, sizeof m->last_error, fmt, ap);
  va_end(ap);
  return st;
}

/* The bias values of the last sample in the bias state: the states, the total b_0 + b_GM + b_RW
 * and the interval mean (integral / dt), for the triads that have a bias term (the others keep
 * their values from create). */
NAV_CLONE_INLINE void form_bias_values(nav_imu_model *m) {
  nav_imu_bias_state *b = &m->bias;
  const double dt = m->bias_dt;
  if (m->gyro.any_bias) {
    b->gyro_gm_rps = arr_to_vec(m->gyro.gm_b);
    b->gyro_rw_rps = arr_to_vec(m->gyro.rw_b);
    b->gyro_rps = nav_vec3_add(nav_vec3_add(m->consts.gyro_bias_turn_on_rps, b->gyro_gm_rps), b->gyro_rw_rps);
    b->gyro_mean_rps = nav_vec3_make(m->gyro.ib[0] / dt, m->gyro.ib[1] / dt, m->gyro.ib[2] / dt);
  }
  if (m->accel.any_bias) {
    b->accel_gm_mps2 = arr_to_vec(m->accel.gm_b);
    b->accel_rw_mps2 = arr_to_vec(m->accel.rw_b);
    b->accel_mps2 =
        nav_vec3_add(nav_vec3_add(m->consts.accel_bias_turn_on_mps2, b->accel_gm_mps2), b->accel_rw_mps2);
    b->accel_mean_mps2 = nav_vec3_make(m->accel.ib[0] / dt, m->accel.ib[1] / dt, m->accel.ib[2] / dt);
  }
  m->bias_stale = false;
}

void nav_imu_model_defer_bias(nav_imu_model *model) {
  if (model) model->defer_bias = true;
}

/* Compiled for the baseline and for AVX2 (nav_clones.h; the same operations in the same order,
 * bit-identical). */
NAV_HOT_CLONES nav_status nav_imu_model_apply(nav_imu_model *model, const nav_imu_increment *ideal,
                                              nav_imu_increment *measured) {
  assert(model != NULL && ideal != NULL && measured != NULL);
  if (model == NULL || ideal == NULL || measured == NULL) return NAV_ERR_INVALID_ARG;
  const double dt = ideal->dt_s;
  if (!(isfinite(dt) && dt > 0.0))
    return fail(model, NAV_ERR_INVALID_ARG, "sample %lld: dt_s must be finite and > 0, got %g",
                (long long)ideal->k, dt);
  if (!nav_vec3_isfinite(ideal->dtheta_b_rad) || !nav_vec3_isfinite(ideal->dv_b_mps))
    return fail(model, NAV_ERR_NUMERIC, "sample %lld: non-finite ideal increment", (long long)ideal->k);
  model->last_error[0] = '\0';
  nav_imu_bias_state *b = &model->bias;
  if (model->ideal) {
    /* Every term off: the measured record is the ideal one (checked above like any other). */
    *measured = *ideal;
    b->k = measured->k;
    b->t_s = measured->t_s;
    return NAV_OK;
  }
  if (dt != model->dt_cached) set_dt(model, dt);

  const double dth[3] = {ideal->dtheta_b_rad.x, ideal->dtheta_b_rad.y, ideal->dtheta_b_rad.z};
  const double dv[3] = {ideal->dv_b_mps.x, ideal->dv_b_mps.y, ideal->dv_b_mps.z};
  double yg[3], ya[3];
  unsigned sat_g = 0, sat_a = 0;
  /* Accelerometer first, then gyro: the order only fixes which stream is read when; streams are
   * independent, so it does not affect values. G_g acts on the true dv (E2.2: G_g f). */
  const dt_slot *c = model->cur;
  triad_apply(&model->accel, c->gm_c[1], c->rw_c[1], c->n_sd[1], dv, NULL, dt, ya, &sat_a);
  double gdv[3];
  const double *extra = NULL;
  if (model->apply_g) {
    for (int i = 0; i < 3; ++i)
      gdv[i] = model->g_sens.m[i][0] * dv[0] + model->g_sens.m[i][1] * dv[1] + model->g_sens.m[i][2] * dv[2];
    extra = gdv;
  }
  triad_apply(&model->gyro, c->gm_c[0], c->rw_c[0], c->n_sd[0], dth, extra, dt, yg, &sat_g);

  const int64_t k = ideal->k;
  const double t_s = ideal->t_s;
  measured->k = k;
  measured->t_s = t_s;
  measured->dt_s = dt;
  measured->dtheta_b_rad.x = yg[0];
  measured->dtheta_b_rad.y = yg[1];
  measured->dtheta_b_rad.z = yg[2];
  measured->dv_b_mps.x = ya[0];
  measured->dv_b_mps.y = ya[1];
  measured->dv_b_mps.z = ya[2];

  /* Bias bookkeeping only for triads that have a bias term: an ideal triad costs nothing here. */
  b->k = k;
  b->t_s = t_s;
  model->bias_dt = dt;
  model->bias_stale = true;
  if (!model->defer_bias) form_bias_values(model);
  b->saturated = sat_g | (sat_a << 3);
  if (b->saturated) b->saturated_samples++;
  return NAV_OK;
}

const nav_imu_run_constants *nav_imu_model_constants(const nav_imu_model *model) {
  return model ? &model->consts : NULL;
}

/* A deferring model (nav_imu_model_defer_bias) is written here, through a cast: every model is
 * allocated by nav_imu_model_create, none is defined const. */
const nav_imu_bias_state *nav_imu_model_bias(const nav_imu_model *model) {
  if (model == NULL) return NULL;
  if (model->bias_stale) form_bias_values((nav_imu_model *)model);
  return &model->bias;
}

const char *nav_imu_model_last_error(const nav_imu_model *model) {
  return model ? model->last_error : "";
}

/* ------------------------------------------------------ four models in lockstep (vector lanes) */

/* One triad of four models: lane l of every value is model l's. The streams of a term are held
 * per axis (rng_x[i], lane l: model l's stream of axis i), so one vector draw serves the four
 * runs; each stream still yields its words in its own order (u1 then u2 per sample and axis). */
typedef struct lanes_triad {
  nav_l4 b0[3], gm_b[3], rw_b[3], ib[3], q_res[3];
  nav_l4 m[3][3];
  nav_rng_lanes rng_noise[3], rng_gm[3], rng_rw[3];
} lanes_triad;

struct nav_imu_lanes {
  lanes_triad gyro, accel;
  nav_l4 g_sens[3][3];
  nav_imu_model *m[NAV_LANES];
  bool applied; /* a sample went through the lanes: the bias state's fields below are the last one's */
  int64_t k;
  double t_s, dt;
  unsigned sat_last[NAV_LANES];
  uint64_t sat_count[NAV_LANES];
};

/* The parameters a triad's per-sample arithmetic reads from its model (not its per-run draws):
 * the four models must agree on them bit for bit, since the lanes read model 0's coefficients. */
static bool triad_same_config(const triad *a, const triad *b) {
  return a->terms == b->terms && a->apply_m == b->apply_m && a->any_bias == b->any_bias &&
         memcmp(a->gm_sd, b->gm_sd, sizeof a->gm_sd) == 0 &&
         memcmp(a->gm_tau, b->gm_tau, sizeof a->gm_tau) == 0 &&
         memcmp(a->rw_k, b->rw_k, sizeof a->rw_k) == 0 &&
         memcmp(a->n_density, b->n_density, sizeof a->n_density) == 0 &&
         memcmp(a->q_step, b->q_step, sizeof a->q_step) == 0 &&
         memcmp(a->range, b->range, sizeof a->range) == 0;
}

/* The streams of one term (the nav_rng_lanes at byte offset member of each triad: lane i is axis
 * i) to the lanes of the group (lanes[i], lane l: model l's stream of axis i), or back. */
static void move_streams(nav_rng_lanes lanes[3], triad *const t[NAV_LANES], size_t member, bool into_lanes) {
  for (int l = 0; l < NAV_LANES; ++l) {
    nav_rng_lanes *m = (nav_rng_lanes *)((char *)t[l] + member);
    for (int i = 0; i < 3; ++i)
      for (int w = 0; w < 4; ++w) {
        if (into_lanes)
          lanes[i].s[w][l] = m->s[w][i];
        else
          m->s[w][i] = lanes[i].s[w][l];
      }
  }
}

/* All three terms' streams of a triad, into the lanes or back. */
static void move_triad_streams(lanes_triad *g, triad *const t[NAV_LANES], bool into_lanes) {
  move_streams(g->rng_noise, t, offsetof(triad, rng_noise), into_lanes);
  move_streams(g->rng_gm, t, offsetof(triad, rng_gm), into_lanes);
  move_streams(g->rng_rw, t, offsetof(triad, rng_rw), into_lanes);
}

static void triad_to_lanes(lanes_triad *g, triad *const t[NAV_LANES]) {
  for (int l = 0; l < NAV_LANES; ++l)
    for (int i = 0; i < 3; ++i) {
      g->b0[i][l] = t[l]->b0[i];
      g->gm_b[i][l] = t[l]->gm_b[i];
      g->rw_b[i][l] = t[l]->rw_b[i];
      g->ib[i][l] = t[l]->ib[i];
      g->q_res[i][l] = t[l]->q_res[i];
      for (int j = 0; j < 3; ++j)
        g->m[i][j][l] = t[l]->m.m[i][j];
    }
  move_triad_streams(g, t, true);
}

/* The state a sample changes (the per-run constants b0 and M stay as they are in the models). */
static void triad_from_lanes(lanes_triad *g, triad *const t[NAV_LANES]) {
  for (int l = 0; l < NAV_LANES; ++l)
    for (int i = 0; i < 3; ++i) {
      t[l]->gm_b[i] = g->gm_b[i][l];
      t[l]->rw_b[i] = g->rw_b[i][l];
      t[l]->ib[i] = g->ib[i][l];
      t[l]->q_res[i] = g->q_res[i][l];
    }
  move_triad_streams(g, t, false);
}

nav_imu_lanes *nav_imu_lanes_open(nav_imu_model *const models[NAV_LANES]) {
  for (int l = 0; l < NAV_LANES; ++l) {
    const nav_imu_model *m = models[l], *m0 = models[0];
    if (m == NULL || m->ideal || !m->defer_bias || m->apply_g != m0->apply_g ||
        !triad_same_config(&m->gyro, &m0->gyro) || !triad_same_config(&m->accel, &m0->accel))
      return NULL;
  }
  /* 32-byte lanes: aligned_alloc wants a size that is a multiple of the alignment. */
  const size_t size = (sizeof(nav_imu_lanes) + 31u) / 32u * 32u;
  nav_imu_lanes *g = aligned_alloc(32, size);
  if (g == NULL) return NULL;
  memset(g, 0, size);
  triad *gy[NAV_LANES], *ac[NAV_LANES];
  for (int l = 0; l < NAV_LANES; ++l) {
    g->m[l] = models[l];
    gy[l] = &models[l]->gyro;
    ac[l] = &models[l]->accel;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        g->g_sens[i][j][l] = models[l]->g_sens.m[i][j];
  }
  triad_to_lanes(&g->gyro, gy);
  triad_to_lanes(&g->accel, ac);
  return g;
}

void nav_imu_lanes_close(nav_imu_lanes *g) {
  if (g == NULL) return;
  triad *gy[NAV_LANES], *ac[NAV_LANES];
  for (int l = 0; l < NAV_LANES; ++l) {
    gy[l] = &g->m[l]->gyro;
    ac[l] = &g->m[l]->accel;
  }
  triad_from_lanes(&g->gyro, gy);
  triad_from_lanes(&g->accel, ac);
  if (g->applied)
    for (int l = 0; l < NAV_LANES; ++l) {
      nav_imu_model *m = g->m[l];
      /* What the last sample's nav_imu_model_apply() would have left (model 0's coefficients are
       * already those of g->dt). */
      m->last_error[0] = '\0';
      if (m->dt_cached != g->dt) set_dt(m, g->dt);
      m->bias.k = g->k;
      m->bias.t_s = g->t_s;
      m->bias_dt = g->dt;
      m->bias_stale = true;
      m->bias.saturated = g->sat_last[l];
      m->bias.saturated_samples += g->sat_count[l];
    }
  free(g);
}

/* triad_apply() for the four lanes, the same operations in the same order in each lane. x is the
 * shared ideal increment; extra as there (one value per lane), NULL if none; the saturation flags
 * of lane l go into sat[l]. */
NAV_CLONE_INLINE void lanes_triad_apply(lanes_triad *t, const triad *cfg, const pair_coef *gm_c,
                                        const pair_coef *rw_c, const double *n_sd, const double x[3],
                                        const nav_l4 *extra, double dt, nav_l4 y_out[3],
                                        unsigned sat[NAV_LANES]) {
  const unsigned terms = cfg->terms;
  nav_l4 y[3];
  const nav_l4 xs[3] = {l4_splat(x[0]), l4_splat(x[1]), l4_splat(x[2])};
  if (cfg->apply_m) {
    for (int i = 0; i < 3; ++i)
      y[i] = xs[i] + (t->m[i][0] * xs[0] + t->m[i][1] * xs[1] + t->m[i][2] * xs[2]);
  } else {
    y[0] = xs[0];
    y[1] = xs[1];
    y[2] = xs[2];
  }
  const nav_l4 dts = l4_splat(dt);
  nav_l4 ib[3] = {l4_splat(0.0), l4_splat(0.0), l4_splat(0.0)};
  if (terms & NAV_IMU_TERM_BIAS_TURN_ON)
    for (int i = 0; i < 3; ++i)
      ib[i] += t->b0[i] * dts;
  double u1s[4], u2s[4];
  if (terms & NAV_IMU_TERM_BIAS_GM)
    for (int i = 0; i < 3; ++i) {
      nav_rng_lanes_gauss(&t->rng_gm[i], NAV_LANES, u1s);
      nav_rng_lanes_gauss(&t->rng_gm[i], NAV_LANES, u2s);
      const pair_coef *c = &gm_c[i];
      const nav_l4 u1 = {u1s[0], u1s[1], u1s[2], u1s[3]}, u2 = {u2s[0], u2s[1], u2s[2], u2s[3]},
                   b = t->gm_b[i];
      ib[i] += l4_splat(c->c_int) * b + l4_splat(c->l21) * u1 + l4_splat(c->l22) * u2;
      t->gm_b[i] = l4_splat(c->phi) * b + l4_splat(c->l11) * u1;
    }
  if (terms & NAV_IMU_TERM_BIAS_RW)
    for (int i = 0; i < 3; ++i) {
      nav_rng_lanes_gauss(&t->rng_rw[i], NAV_LANES, u1s);
      nav_rng_lanes_gauss(&t->rng_rw[i], NAV_LANES, u2s);
      const pair_coef *c = &rw_c[i];
      const nav_l4 u1 = {u1s[0], u1s[1], u1s[2], u1s[3]}, u2 = {u2s[0], u2s[1], u2s[2], u2s[3]},
                   b = t->rw_b[i];
      ib[i] += l4_splat(c->c_int) * b + l4_splat(c->l21) * u1 + l4_splat(c->l22) * u2;
      t->rw_b[i] = b + l4_splat(c->l11) * u1;
    }
  if (cfg->any_bias)
    for (int i = 0; i < 3; ++i) {
      y[i] += ib[i];
      t->ib[i] = ib[i];
    }
  if (extra)
    for (int i = 0; i < 3; ++i)
      y[i] += extra[i];
  if (terms & NAV_IMU_TERM_NOISE)
    for (int i = 0; i < 3; ++i) {
      nav_rng_lanes_gauss(&t->rng_noise[i], NAV_LANES, u1s);
      const nav_l4 u = {u1s[0], u1s[1], u1s[2], u1s[3]};
      y[i] += l4_splat(n_sd[i]) * u;
    }
  for (int l = 0; l < NAV_LANES; ++l)
    sat[l] = 0;
  if (terms & NAV_IMU_TERM_SATURATION)
    for (int i = 0; i < 3; ++i) {
      /* The scalar branches (clip above, else clip below) as masks on the unclipped value. */
      const double lim = cfg->range[i] * dt;
      const nav_m4 hi = y[i] > l4_splat(lim), lo = (y[i] < l4_splat(-lim)) & ~hi;
      y[i] = l4_sel(hi, l4_splat(lim), l4_sel(lo, l4_splat(-lim), y[i]));
      for (int l = 0; l < NAV_LANES; ++l)
        if (hi[l] | lo[l]) sat[l] |= 1u << i;
    }
  if (terms & NAV_IMU_TERM_QUANTISATION)
    for (int i = 0; i < 3; ++i)
      for (int l = 0; l < NAV_LANES; ++l) {
        /* As triad_apply (round() per lane: it rounds halves away from zero, which the vector
         * rounding instruction does not). */
        const double v = t->q_res[i][l] + y[i][l];
        const double q = cfg->q_step[i] * round(v / cfg->q_step[i]);
        t->q_res[i][l] = v - q;
        y[i][l] = q;
      }
  y_out[0] = y[0];
  y_out[1] = y[1];
  y_out[2] = y[2];
}

NAV_HOT_CLONES bool nav_imu_lanes_apply(nav_imu_lanes *g, const nav_imu_increment *ideal,
                                        nav_imu_increment *const measured[NAV_LANES]) {
  const double dt = ideal->dt_s;
  if (!(isfinite(dt) && dt > 0.0) || !nav_vec3_isfinite(ideal->dtheta_b_rad) ||
      !nav_vec3_isfinite(ideal->dv_b_mps))
    return false;
  nav_imu_model *m0 = g->m[0];
  if (dt != m0->dt_cached) set_dt(m0, dt);
  const dt_slot *c = m0->cur;
  const double dth[3] = {ideal->dtheta_b_rad.x, ideal->dtheta_b_rad.y, ideal->dtheta_b_rad.z};
  const double dv[3] = {ideal->dv_b_mps.x, ideal->dv_b_mps.y, ideal->dv_b_mps.z};
  nav_l4 yg[3], ya[3];
  unsigned sat_g[NAV_LANES], sat_a[NAV_LANES];
  lanes_triad_apply(&g->accel, &m0->accel, c->gm_c[1], c->rw_c[1], c->n_sd[1], dv, NULL, dt, ya, sat_a);
  nav_l4 gdv[3];
  const nav_l4 *extra = NULL;
  if (m0->apply_g) {
    const nav_l4 d0 = l4_splat(dv[0]), d1 = l4_splat(dv[1]), d2 = l4_splat(dv[2]);
    for (int i = 0; i < 3; ++i)
      gdv[i] = g->g_sens[i][0] * d0 + g->g_sens[i][1] * d1 + g->g_sens[i][2] * d2;
    extra = gdv;
  }
  lanes_triad_apply(&g->gyro, &m0->gyro, c->gm_c[0], c->rw_c[0], c->n_sd[0], dth, extra, dt, yg, sat_g);
  const int64_t k = ideal->k;
  const double t_s = ideal->t_s;
  for (int l = 0; l < NAV_LANES; ++l) {
    nav_imu_increment *o = measured[l];
    o->k = k;
    o->t_s = t_s;
    o->dt_s = dt;
    o->dtheta_b_rad.x = yg[0][l];
    o->dtheta_b_rad.y = yg[1][l];
    o->dtheta_b_rad.z = yg[2][l];
    o->dv_b_mps.x = ya[0][l];
    o->dv_b_mps.y = ya[1][l];
    o->dv_b_mps.z = ya[2][l];
    const unsigned sat = sat_g[l] | (sat_a[l] << 3);
    g->sat_last[l] = sat;
    if (sat) g->sat_count[l]++;
  }
  g->applied = true;
  g->k = k;
  g->t_s = t_s;
  g->dt = dt;
  return true;
}
