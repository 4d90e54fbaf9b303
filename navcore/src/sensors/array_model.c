/*
 * Accelerometer-array error model (numerics.md 2.1-2.4 for each sensor; model, discretisation and
 * stream layout in nav_array.h). It is the accelerometer half of imu_model.c reduced to one axis
 * per sensor and to the terms an array needs; the Gauss-Markov pair discretisation is the same
 * (derivation in nav_sensors.h), repeated here because imu_model.c keeps it private.
 */
#include "navcore/nav_array.h"

#include <assert.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "navcore/nav_rng.h"

/* Cholesky factor of the covariance of (bias step, bias integral) over one interval:
 * b_k = phi b + l11 u1;  I_k = c_int b + l21 u1 + l22 u2 (nav_sensors.h). */
typedef struct pair_coef {
  double phi, c_int, l11, l21, l22;
} pair_coef;

struct nav_array_model {
  nav_array_error_config cfg;
  int n;
  double b0[NAV_ARRAY_MAX_SENSORS];   /* turn-on bias [m/s^2] */
  double sf[NAV_ARRAY_MAX_SENSORS];   /* scale-factor error [-] */
  double gm_b[NAV_ARRAY_MAX_SENSORS]; /* GM state [m/s^2] */
  nav_rng rng_gm[NAV_ARRAY_MAX_SENSORS], rng_noise[NAV_ARRAY_MAX_SENSORS];
  double dt_cached; /* 0 until the first sample (dt > 0 never matches it) */
  pair_coef gm_c;   /* for dt_cached: the same for every sensor */
  double noise_sd;  /* N sqrt(dt_cached) [m/s] */
};

nav_array_error_config nav_array_error_config_default(void) {
  nav_array_error_config c;
  /* All-bits-zero: every term off, every value 0.0. */
  memset(&c, 0, sizeof c);
  return c;
}

#if defined(__GNUC__)
__attribute__((format(printf, 5, 6)))
#endif
static void
issue(nav_scene_issue_fn report, void *user, int *count, const char *path, const char *fmt, ...) {
  ++*count;
  if (!report) return;
  char msg[256];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  report(user, path, msg);
}

static void check_sd(nav_scene_issue_fn report, void *user, int *count, const char *path, double v) {
  if (!(isfinite(v) && v >= 0.0))
    issue(report, user, count, path, "is a standard deviation or density and must be finite and >= 0, got %g",
          v);
}

nav_status nav_array_error_config_validate(const nav_array_error_config *cfg, nav_scene_issue_fn report,
                                           void *user) {
  if (cfg == NULL) return NAV_ERR_INVALID_ARG;
  int count = 0;
  if (cfg->terms & ~NAV_ARRAY_TERMS_ALL)
    issue(report, user, &count, "terms",
          "unknown term bits 0x%x (an array sensor has bias_turn_on, bias_gm, noise and scale_factor)",
          cfg->terms & ~NAV_ARRAY_TERMS_ALL);
  if (cfg->terms & NAV_IMU_TERM_BIAS_TURN_ON)
    check_sd(report, user, &count, "bias_turn_on_sd_mps2", cfg->bias_turn_on_sd_mps2);
  if (cfg->terms & NAV_IMU_TERM_BIAS_GM) {
    check_sd(report, user, &count, "bias_gm_sd_mps2", cfg->bias_gm_sd_mps2);
    if (!(isfinite(cfg->bias_gm_tau_s) && cfg->bias_gm_tau_s > 0.0))
      issue(report, user, &count, "bias_gm_tau_s",
            "correlation time must be finite and > 0 s, got %g (use bias_turn_on for a constant)",
            cfg->bias_gm_tau_s);
  }
  if (cfg->terms & NAV_IMU_TERM_NOISE)
    check_sd(report, user, &count, "vrw_mps_per_sqrt_s", cfg->vrw_mps_per_sqrt_s);
  if (cfg->terms & NAV_IMU_TERM_SCALE_FACTOR)
    check_sd(report, user, &count, "scale_factor_sd", cfg->scale_factor_sd);
  return count == 0 ? NAV_OK : NAV_ERR_INVALID_ARG;
}

/* f(x) = x - 3/2 + 2 exp(-x) - exp(-2x)/2 = Var(e2) / (2 sigma^2 T^2), x = dt/T. Below x = 0.5
 * the closed form cancels catastrophically (x = 1e-5: terms 1e-5, result 3e-16), so the Taylor
 * series sum_{n>=3} (-1)^n (2 - 2^(n-1)) x^n / n! is used there (as in imu_model.c). */
static double gm_pair_f(double x) {
  if (x >= 0.5) return x - 1.5 + 2.0 * exp(-x) - 0.5 * exp(-2.0 * x);
  double p = x * x * x / 6.0, pow2 = 4.0, sum = 0.0;
  for (int n = 3; n < 60; ++n) {
    const double term = ((n & 1) ? -1.0 : 1.0) * (2.0 - pow2) * p;
    sum += term;
    if (fabs(term) <= 1e-18 * fabs(sum)) break;
    p *= x / (double)(n + 1);
    pow2 *= 2.0;
  }
  return sum;
}

/* Exact joint discretisation of (b, integral of b) for a first-order GM over dt (nav_sensors.h). */
static pair_coef gm_pair(double sd, double tau, double dt) {
  pair_coef c;
  const double x = dt / tau;
  const double one_m_phi = -expm1(-x), one_m_phi2 = -expm1(-2.0 * x); /* exact when dt << T */
  const double var_b = sd * sd;
  c.phi = exp(-x);
  c.c_int = tau * one_m_phi;
  const double p11 = var_b * one_m_phi2;
  const double p12 = var_b * tau * one_m_phi * one_m_phi;
  const double p22 = 2.0 * var_b * tau * tau * gm_pair_f(x);
  c.l11 = sqrt(p11);
  c.l21 = p11 > 0.0 ? p12 / c.l11 : 0.0;
  c.l22 = sqrt(fmax(p22 - c.l21 * c.l21, 0.0)); /* fmax: last-ulp negatives for sd = 0 */
  return c;
}

/* A per-run constant: sd u with u the first draw of stream (kind, sensor). */
static double draw_const(uint64_t seed, uint64_t run, nav_rng_stream_kind kind, unsigned sensor, double sd) {
  nav_rng r;
  nav_rng_init(&r, seed, run, nav_rng_stream_id(kind, sensor));
  return sd * nav_rng_gauss(&r);
}

nav_status nav_array_model_create(const nav_array_error_config *cfg, int n_sensors, uint64_t seed,
                                  uint64_t run, nav_array_model **out) {
  assert(cfg != NULL && out != NULL);
  if (cfg == NULL || out == NULL || n_sensors < 1 || n_sensors > NAV_ARRAY_MAX_SENSORS)
    return NAV_ERR_INVALID_ARG;
  if (nav_array_error_config_validate(cfg, NULL, NULL) != NAV_OK) return NAV_ERR_INVALID_ARG;
  nav_array_model *m = calloc(1, sizeof *m);
  if (m == NULL) return NAV_ERR_NO_MEMORY;
  m->cfg = *cfg;
  m->n = n_sensors;
  for (unsigned i = 0; i < (unsigned)n_sensors; ++i) {
    if (cfg->terms & NAV_IMU_TERM_BIAS_TURN_ON)
      m->b0[i] = draw_const(seed, run, NAV_RNG_STREAM_ACCEL_BIAS_TURN_ON, i, cfg->bias_turn_on_sd_mps2);
    if (cfg->terms & NAV_IMU_TERM_SCALE_FACTOR)
      m->sf[i] = draw_const(seed, run, NAV_RNG_STREAM_ACCEL_SCALE_FACTOR, i, cfg->scale_factor_sd);
    if (cfg->terms & NAV_IMU_TERM_BIAS_GM) {
      nav_rng_init(&m->rng_gm[i], seed, run, nav_rng_stream_id(NAV_RNG_STREAM_ACCEL_BIAS_GM, i));
      /* Stationary start (E2.5): the first draw of the sensor's GM stream. */
      m->gm_b[i] = cfg->bias_gm_sd_mps2 * nav_rng_gauss(&m->rng_gm[i]);
    }
    if (cfg->terms & NAV_IMU_TERM_NOISE)
      nav_rng_init(&m->rng_noise[i], seed, run, nav_rng_stream_id(NAV_RNG_STREAM_ACCEL_NOISE, i));
  }
  *out = m;
  return NAV_OK;
}

void nav_array_model_destroy(nav_array_model *model) {
  free(model);
}

nav_status nav_array_model_apply(nav_array_model *model, const nav_array_increment *ideal,
                                 nav_array_increment *measured) {
  assert(model != NULL && ideal != NULL && measured != NULL);
  if (model == NULL || ideal == NULL || measured == NULL || ideal->n_sensors != model->n)
    return NAV_ERR_INVALID_ARG;
  const double dt = ideal->dt_s;
  if (!(isfinite(dt) && dt > 0.0)) return NAV_ERR_INVALID_ARG;
  for (int i = 0; i < model->n; ++i)
    if (!isfinite(ideal->dv_mps[i])) return NAV_ERR_NUMERIC;
  const unsigned terms = model->cfg.terms;
  if (dt != model->dt_cached) {
    if (terms & NAV_IMU_TERM_BIAS_GM)
      model->gm_c = gm_pair(model->cfg.bias_gm_sd_mps2, model->cfg.bias_gm_tau_s, dt);
    model->noise_sd = model->cfg.vrw_mps_per_sqrt_s * sqrt(dt);
    model->dt_cached = dt;
  }
  nav_array_increment y = *ideal;
  /* Each enabled term is one branch, then a straight loop over the sensors; the order within a
   * sensor only fixes which stream is read when (streams are independent). */
  if (terms & NAV_IMU_TERM_SCALE_FACTOR)
    for (int i = 0; i < model->n; ++i)
      y.dv_mps[i] += model->sf[i] * ideal->dv_mps[i]; /* (1 + s) dA as dA + s dA: s = 0 is exact */
  if (terms & NAV_IMU_TERM_BIAS_TURN_ON)
    for (int i = 0; i < model->n; ++i)
      y.dv_mps[i] += model->b0[i] * dt;
  if (terms & NAV_IMU_TERM_BIAS_GM) {
    const pair_coef *c = &model->gm_c;
    for (int i = 0; i < model->n; ++i) {
      /* Fixed draw order: u1 (bias step), then u2 (integral). */
      const double u1 = nav_rng_gauss(&model->rng_gm[i]);
      const double u2 = nav_rng_gauss(&model->rng_gm[i]);
      y.dv_mps[i] += c->c_int * model->gm_b[i] + c->l21 * u1 + c->l22 * u2;
      model->gm_b[i] = c->phi * model->gm_b[i] + c->l11 * u1;
    }
  }
  if (terms & NAV_IMU_TERM_NOISE)
    for (int i = 0; i < model->n; ++i)
      y.dv_mps[i] += model->noise_sd * nav_rng_gauss(&model->rng_noise[i]);
  *measured = y;
  return NAV_OK;
}

double nav_array_model_bias_turn_on(const nav_array_model *model, int i) {
  return model && i >= 0 && i < model->n ? model->b0[i] : 0.0;
}

double nav_array_model_scale_factor(const nav_array_model *model, int i) {
  return model && i >= 0 && i < model->n ? model->sf[i] : 0.0;
}

double nav_array_model_bias_gm(const nav_array_model *model, int i) {
  return model && i >= 0 && i < model->n ? model->gm_b[i] : 0.0;
}
