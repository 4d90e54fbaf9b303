/*
 * navsim run --export kfgins (see kfgins_out.h).
 */
#define _POSIX_C_SOURCE 200809L
#include "kfgins_out.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "navcore/nav_sim.h" /* nav_sim_gnss_config: the receiver the simulation uses */
#include "navcore/nav_frames.h"
#include "navcore/nav_ins_gnss.h"
#include "navcore/nav_math.h"
#include "navcore/nav_sensors.h"
#include "navcore/nav_recorded.h"
#include "navcore/nav_truth.h"

enum { F_IMU, F_GNSS, F_TRUTH, F_COUNT };
static const char *const k_names[F_COUNT] = {"kfgins/IMU.txt", "kfgins/GNSS.txt", "kfgins/truth.nav"};

struct navsim_kfgins {
  nav_scene *scene;        /* copy (large: on the heap) */
  bool ideal;
  nav_resultdir *rd;       /* borrowed */
  FILE *f[F_COUNT];
  nav_truth *truth;        /* the reference and the ideal increments */
  nav_frame frame;
  nav_imu_model *imu;      /* run 0's IMU error model; NULL with --ideal */
  nav_gnss_model *gnss;    /* run 0's receiver */
  bool gm_states;          /* the filter has GNSS GM states: R holds the white part only */
  int64_t n, k_done;       /* samples of the run; last IMU sample written (-1: none) */
  int64_t next_epoch;      /* next receiver epoch */
  long fixes;
  double dt_s;
  nav_rec_pva init;        /* run 0's initial state */
};

static void set_msg(char *msg, size_t cap, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void set_msg(char *msg, size_t cap, const char *fmt, ...) {
  if (!msg || cap == 0) return;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, cap, fmt, ap);
  va_end(ap);
}

const char *navsim_kfgins_unsupported(const nav_scene *sc) {
  /* ins_gnss_tight: IMU.txt, truth.nav and init.nav are what navsim replay --rinex-obs takes
   * beside the RINEX export; GNSS.txt then holds the receiver model's fixes at the receiver
   * epochs, which the tight filter did not use (docs/kfgins-export.md). */
  if (sc->navigation.scheme != NAV_SCHEME_INS_GNSS && sc->navigation.scheme != NAV_SCHEME_INS_GNSS_TIGHT)
    return "the kfgins export needs navigation.scheme ins_gnss or ins_gnss_tight (KF-GINS is an INS/GNSS filter)";
  if (sc->earth.model != NAV_EARTH_WGS84)
    return "the kfgins export needs earth.model wgs84 (the KF-GINS formats are geodetic on WGS-84)";
  if (sc->gnss.file[0] != '\0')
    return "the kfgins export writes the receiver model's fixes; this scene's fixes come from gnss.file, which "
           "KF-GINS can read as it is";
  return NULL;
}

void navsim_kfgins_destroy(navsim_kfgins *x) {
  if (!x) return;
  for (int i = 0; i < F_COUNT; ++i)
    if (x->f[i]) fclose(x->f[i]);
  nav_gnss_model_destroy(x->gnss);
  nav_imu_model_destroy(x->imu);
  nav_truth_destroy(x->truth);
  free(x->scene);
  free(x);
}

nav_status navsim_kfgins_begin(const nav_scene *scene, bool ideal, nav_resultdir *rd, navsim_kfgins **out, char *msg,
                               size_t msg_cap) {
  *out = NULL;
  const char *why = navsim_kfgins_unsupported(scene);
  if (why) {
    set_msg(msg, msg_cap, "%s", why);
    return NAV_ERR_INVALID_ARG;
  }
  char m[256] = "";
  nav_status st = NAV_OK;
  navsim_kfgins *x = calloc(1, sizeof *x);
  if (x) x->scene = malloc(sizeof *x->scene);
  if (!x || !x->scene) {
    navsim_kfgins_destroy(x);
    return NAV_ERR_NO_MEMORY;
  }
  *x->scene = *scene;
  x->ideal = ideal;
  x->rd = rd;
  x->k_done = -1;
  const nav_scene *sc = x->scene;
  st = nav_truth_create_msg(sc, &x->truth, m, sizeof m);
  if (st != NAV_OK) {
    set_msg(msg, msg_cap, "reference trajectory: %s", m[0] ? m : nav_status_str(st));
    goto fail;
  }
  x->frame = nav_truth_frame(x->truth);
  x->dt_s = nav_truth_dt(x->truth);
  x->n = nav_truth_sample_count(x->truth);
  if (!ideal) {
    st = nav_imu_model_create(&sc->imu.model, sc->simulation.seed, 0u, &x->imu);
    if (st != NAV_OK) {
      set_msg(msg, msg_cap, "IMU error model: %s", nav_status_str(st));
      goto fail;
    }
  }
  nav_gnss_model_config gcfg;
  st = nav_sim_gnss_config(sc, x->dt_s, &gcfg, m, sizeof m);
  if (st != NAV_OK) {
    set_msg(msg, msg_cap, "GNSS outages: %s", m);
    goto fail;
  }
  if (ideal) gcfg.terms = 0;
  st = nav_gnss_model_create(&gcfg, &x->frame, sc->simulation.seed, 0u, &x->gnss);
  if (st != NAV_OK) {
    set_msg(msg, msg_cap, "GNSS receiver model: %s", nav_status_str(st));
    goto fail;
  }
  x->gm_states = (nav_ins_gnss_config_from_scene(sc).filter.states & NAV_FILTER_STATE_GNSS_POS_GM) != 0;
  const char *dir = nav_resultdir_file(rd, "kfgins");
  if (!dir || (mkdir(dir, 0777) != 0 && errno != EEXIST)) {
    set_msg(msg, msg_cap, "cannot create kfgins/");
    st = NAV_ERR_IO;
    goto fail;
  }
  for (int i = 0; i < F_COUNT; ++i) {
    const char *p = nav_resultdir_file(rd, k_names[i]);
    x->f[i] = p ? fopen(p, "w") : NULL;
    if (!x->f[i]) {
      set_msg(msg, msg_cap, "cannot write %s", k_names[i]);
      st = NAV_ERR_IO;
      goto fail;
    }
  }
  *out = x;
  return NAV_OK;
fail:
  navsim_kfgins_destroy(x);
  return st;
}

/* A .nav row of a reference or navigation state given in the frame F. */
static nav_rec_pva pva_of(const nav_frame *fr, double t_s, nav_vec3 r_fb_f_m, nav_vec3 v_fb_f_mps, nav_quat q_b_f) {
  const nav_local_view v = nav_frame_view(fr, r_fb_f_m, v_fb_f_mps, q_b_f);
  bool lock = false;
  nav_rec_pva p;
  p.week = 0;
  p.t_s = t_s;
  p.pos = v.pos;
  p.v_n_mps = v.v_n_mps;
  p.att = nav_quat_to_euler(v.q_b_n, &lock);
  return p;
}

static bool write_pva(FILE *f, const nav_rec_pva *p) {
  return fprintf(f, "%d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", p->week, p->t_s,
                 p->pos.lat_rad * NAV_RAD2DEG, p->pos.lon_rad * NAV_RAD2DEG, p->pos.h_m, p->v_n_mps.x, p->v_n_mps.y,
                 p->v_n_mps.z, p->att.roll_rad * NAV_RAD2DEG, p->att.pitch_rad * NAV_RAD2DEG,
                 p->att.yaw_rad * NAV_RAD2DEG) >= 0;
}

static bool write_imu(FILE *f, const nav_imu_increment *m) {
  return fprintf(f, "%.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", m->t_s, m->dtheta_b_rad.x, m->dtheta_b_rad.y,
                 m->dtheta_b_rad.z, m->dv_b_mps.x, m->dv_b_mps.y, m->dv_b_mps.z) >= 0;
}

static nav_status truth_row(navsim_kfgins *x, int64_t k) {
  nav_traj_state ts;
  const nav_status st = nav_truth_state(x->truth, (double)k * x->dt_s, &ts);
  if (st != NAV_OK) return st;
  const nav_rec_pva p = pva_of(&x->frame, (double)k * x->dt_s, ts.r_fb_f_m, ts.v_fb_f_mps, ts.q_b_f);
  return write_pva(x->f[F_TRUTH], &p) ? NAV_OK : NAV_ERR_IO;
}

/*
 * The fixes the simulation applies after the IMU step @p m (sim.c aiding_fixes): receiver epochs
 * whose time of validity is within half an interval of the epoch, each measured on the
 * reference at its time of validity (on the sample grid: at k dt), R's position sigma the white
 * part only with GNSS GM states.
 */
static nav_status fixes_after(navsim_kfgins *x, const nav_imu_increment *m, char *msg, size_t cap) {
  for (;;) {
    const double t_fix = nav_gnss_model_epoch_time_s(x->gnss, x->next_epoch);
    if (!(t_fix <= m->t_s + 0.5 * m->dt_s)) break;
    const int64_t epoch = x->next_epoch++;
    if (t_fix < m->t_s - 0.5 * m->dt_s) continue;
    const double kf = t_fix / m->dt_s;
    const int64_t kk = (int64_t)llround(kf);
    const bool on_grid = fabs(kf - (double)kk) < 1e-9 && kk >= 0 && kk <= x->n;
    nav_traj_state ts;
    nav_status st = nav_truth_state(x->truth, on_grid ? (double)kk * x->dt_s : t_fix, &ts);
    if (st != NAV_OK) return st;
    nav_gnss_fix fix;
    bool has_fix = false;
    st = nav_gnss_model_measure(x->gnss, epoch, &ts, &fix, &has_fix);
    if (st != NAV_OK) {
      set_msg(msg, cap, "GNSS model: %s", nav_gnss_model_last_error(x->gnss));
      return st;
    }
    if (!has_fix) continue;
    const nav_vec3 sd = x->gm_states ? x->scene->gnss.model.pos_white_sd_m : fix.pos_sd_m;
    if (fprintf(x->f[F_GNSS], "%.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n",
                fix.t_s, fix.pos.lat_rad * NAV_RAD2DEG, fix.pos.lon_rad * NAV_RAD2DEG, fix.pos.h_m, sd.x, sd.y, sd.z,
                fix.v_fa_n_mps.x, fix.v_fa_n_mps.y, fix.v_fa_n_mps.z, fix.vel_sd_mps.x, fix.vel_sd_mps.y,
                fix.vel_sd_mps.z) < 0)
      return NAV_ERR_IO;
    x->fixes++;
  }
  return NAV_OK;
}

nav_status navsim_kfgins_record(navsim_kfgins *x, const nav_sim_record *r, char *msg, size_t cap) {
  if (!x || r->run != 0) return NAV_OK;
  const int64_t k = (int64_t)llround(r->truth->t_s / x->dt_s);
  if (x->k_done < 0) {
    if (k != 0) {
      set_msg(msg, cap, "kfgins export: the first record of run 0 is at t = %.6f s, not at 0", r->truth->t_s);
      return NAV_ERR_STATE;
    }
    /* The initial epoch: run 0's initial state, a zero increment, the reference. */
    x->init = pva_of(r->frame, 0.0, r->nav->r_fb_f_m, r->nav->v_fb_f_mps, r->nav->q_b_f);
    const nav_imu_increment zero = {0, 0.0, 0.0, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};
    if (!write_imu(x->f[F_IMU], &zero)) return NAV_ERR_IO;
    x->k_done = 0;
    return truth_row(x, 0);
  }
  for (int64_t kk = x->k_done + 1; kk <= k; ++kk) {
    nav_imu_increment ideal, meas;
    nav_status st = nav_truth_imu(x->truth, kk, &ideal);
    if (st != NAV_OK) return st;
    if (x->imu) {
      st = nav_imu_model_apply(x->imu, &ideal, &meas);
      if (st != NAV_OK) return st;
    } else {
      meas = ideal;
    }
    if (kk == k && r->imu_measured &&
        (meas.t_s != r->imu_measured->t_s ||
         memcmp(&meas.dtheta_b_rad, &r->imu_measured->dtheta_b_rad, sizeof meas.dtheta_b_rad) != 0 ||
         memcmp(&meas.dv_b_mps, &r->imu_measured->dv_b_mps, sizeof meas.dv_b_mps) != 0)) {
      set_msg(msg, cap,
              "kfgins export: the regenerated IMU increment at t = %.6f s differs from the one run 0's navigation "
              "used (internal error)",
              meas.t_s);
      return NAV_ERR_STATE;
    }
    if (!write_imu(x->f[F_IMU], &meas)) return NAV_ERR_IO;
    st = fixes_after(x, &meas, msg, cap);
    if (st == NAV_OK) st = truth_row(x, kk);
    if (st != NAV_OK) return st;
    x->k_done = kk;
  }
  return NAV_OK;
}

/* "[a, b, c]" of a vector times @p scale, %.17g. */
static void yaml_vec(FILE *f, nav_vec3 v, double scale) {
  fprintf(f, "[%.17g, %.17g, %.17g]", v.x * scale, v.y * scale, v.z * scale);
}

/* The x value of a per-axis parameter KF-GINS takes as one scalar, with a note when the axes differ. */
static void yaml_scalar(FILE *f, const char *key, nav_vec3 v, double scale, const char *unit) {
  fprintf(f, "    %s: %.17g  # %s", key, v.x * scale, unit);
  if (v.y != v.x || v.z != v.x) fprintf(f, "; navsim per axis: %.9g %.9g %.9g", v.x * scale, v.y * scale, v.z * scale);
  fputc('\n', f);
}

static nav_status write_yaml(navsim_kfgins *x, const char *path) {
  FILE *f = fopen(path, "w");
  if (!f) return NAV_ERR_IO;
  const nav_scene *sc = x->scene;
  const nav_ins_gnss_config xc = nav_ins_gnss_config_from_scene(sc);
  const nav_filter_config *fc = &xc.filter;
  const bool sf = (fc->states & NAV_FILTER_STATE_SCALE_FACTORS) != 0;
  const double rad_h = NAV_RAD2DEG * 3600.0; /* rad/s -> deg/h */
  const double mgal = 1e5;                   /* m/s^2 -> mGal */
  fprintf(f, "# KF-GINS configuration written by navsim run --export kfgins: run 0 of scene \"%s\"%s.\n", sc->name,
          x->ideal ? " (--ideal)" : "");
  fputs("# The files are beside this one; KF-GINS opens them relative to its working directory: run it from\n"
        "# this directory. Time base: scene time [s] (0 at the start of the scene), GPS week 0.\n"
        "# navsim replay reproduces run 0's solution from the same files:\n"
        "#   navsim replay --imu IMU.txt --gnss GNSS.txt --truth truth.nav --init init.nav --scene SCENE\n",
        f);
  fputs("imupath: \"IMU.txt\"\ngnsspath: \"GNSS.txt\"\noutputpath: \".\"\nimudatalen: 7\n", f);
  fprintf(f, "imudatarate: %.17g\nstarttime: 0\nendtime: -1\n", sc->imu.rate_hz);
  fputs("\n# Initial state of run 0 (the reference plus the drawn initial errors; init.nav holds the same row).\n",
        f);
  fprintf(f, "initpos: [%.17g, %.17g, %.17g]  # lat [deg], lon [deg], h [m]\n", x->init.pos.lat_rad * NAV_RAD2DEG,
          x->init.pos.lon_rad * NAV_RAD2DEG, x->init.pos.h_m);
  fputs("initvel: ", f);
  yaml_vec(f, x->init.v_n_mps, 1.0);
  fputs("  # N, E, D [m/s]\ninitatt: ", f);
  fprintf(f, "[%.17g, %.17g, %.17g]  # roll, pitch, yaw [deg]\n", x->init.att.roll_rad * NAV_RAD2DEG,
          x->init.att.pitch_rad * NAV_RAD2DEG, x->init.att.yaw_rad * NAV_RAD2DEG);
  fputs("initgyrbias: [0, 0, 0]  # deg/h\ninitaccbias: [0, 0, 0]  # mGal\n"
        "initgyrscale: [0, 0, 0]  # ppm\ninitaccscale: [0, 0, 0]  # ppm\n",
        f);
  fputs("\n# P0 of the scene's filter (navigation.initial errors and IMU model).\ninitposstd: ", f);
  yaml_vec(f, fc->init.pos_sd_m, 1.0);
  fputs("  # N, E, D [m]\ninitvelstd: ", f);
  yaml_vec(f, fc->init.vel_sd_mps, 1.0);
  fputs("  # [m/s]\ninitattstd: ", f);
  yaml_vec(f, fc->init.att_sd_rad, NAV_RAD2DEG);
  fputs("  # [deg]\ninitbgstd: ", f);
  yaml_vec(f, fc->init.gyro_bias_sd_rps, rad_h);
  fputs("  # [deg/h]\ninitbastd: ", f);
  yaml_vec(f, fc->init.accel_bias_sd_mps2, mgal);
  fputs("  # [mGal]\ninitsgstd: ", f);
  yaml_vec(f, sf ? fc->init.gyro_sf_sd : nav_vec3_zero(), 1e6);
  fputs("  # [ppm]\ninitsastd: ", f);
  yaml_vec(f, sf ? fc->init.accel_sf_sd : nav_vec3_zero(), 1e6);
  fputs("  # [ppm]\n", f);
  if (!sf)
    fputs("# navsim's filter has no scale-factor states for this scene (15 states); KF-GINS always has 21:\n"
          "# zero scale-factor sigmas keep them at zero.\n",
          f);
  if (x->gm_states)
    fputs("# navsim's filter also estimates GNSS position Gauss-Markov errors, which KF-GINS does not model.\n", f);
  fputs("\nimunoise:\n", f);
  yaml_scalar(f, "arw", fc->gyro_arw_rad_per_sqrt_s, NAV_RAD2DEG * 60.0, "deg/sqrt(h)");
  yaml_scalar(f, "vrw", fc->accel_vrw_mps_per_sqrt_s, 60.0, "m/s/sqrt(h)");
  const bool ggm = (fc->gyro_bias_terms & NAV_FILTER_PROC_GM) != 0, agm = (fc->accel_bias_terms & NAV_FILTER_PROC_GM) != 0;
  yaml_scalar(f, "gbstd", ggm ? fc->gyro_bias_gm_sd_rps : nav_vec3_zero(), rad_h, "deg/h, Gauss-Markov sigma");
  yaml_scalar(f, "abstd", agm ? fc->accel_bias_gm_sd_mps2 : nav_vec3_zero(), mgal, "mGal, Gauss-Markov sigma");
  const bool gsgm = sf && (fc->gyro_sf_terms & NAV_FILTER_PROC_GM) != 0;
  const bool asgm = sf && (fc->accel_sf_terms & NAV_FILTER_PROC_GM) != 0;
  yaml_scalar(f, "gsstd", gsgm ? fc->gyro_sf_gm_sd : nav_vec3_zero(), 1e6, "ppm");
  yaml_scalar(f, "asstd", asgm ? fc->accel_sf_gm_sd : nav_vec3_zero(), 1e6, "ppm");
  yaml_scalar(f, "corrtime", ggm ? fc->gyro_bias_gm_tau_s : agm ? fc->accel_bias_gm_tau_s : nav_vec3_make(3600.0, 3600.0, 3600.0),
              1.0 / 3600.0, "h, one correlation time for every Gauss-Markov state in KF-GINS");
  if ((fc->gyro_bias_terms | fc->accel_bias_terms) & NAV_FILTER_PROC_RW)
    fputs("    # navsim's filter also has bias random-walk terms, which KF-GINS does not model.\n", f);
  fputs("\nantlever: ", f);
  yaml_vec(f, xc.r_ba_b_m, 1.0);
  fputs("  # GNSS antenna from the IMU, body forward/right/down [m]\n", f);
  const bool bad = ferror(f) != 0;
  if (fclose(f) != 0 || bad) return NAV_ERR_IO;
  return NAV_OK;
}

nav_status navsim_kfgins_end(navsim_kfgins *x, char *msg, size_t cap) {
  if (!x) return NAV_OK;
  nav_status st = NAV_OK;
  if (x->k_done != x->n) {
    set_msg(msg, cap, "kfgins export: run 0's records ended at sample %lld of %lld", (long long)x->k_done,
            (long long)x->n);
    st = NAV_ERR_STATE;
  }
  for (int i = 0; i < F_COUNT; ++i) {
    const bool bad = ferror(x->f[i]) != 0;
    if (fclose(x->f[i]) != 0 || bad) {
      if (st == NAV_OK) set_msg(msg, cap, "writing %s failed", k_names[i]);
      if (st == NAV_OK) st = NAV_ERR_IO;
    }
    x->f[i] = NULL;
  }
  if (st == NAV_OK) {
    const char *p = nav_resultdir_file(x->rd, "kfgins/init.nav");
    FILE *f = p ? fopen(p, "w") : NULL;
    bool ok = f && write_pva(f, &x->init) && ferror(f) == 0;
    if (f && fclose(f) != 0) ok = false;
    if (!ok) {
      set_msg(msg, cap, "writing kfgins/init.nav failed");
      st = NAV_ERR_IO;
    }
  }
  if (st == NAV_OK) {
    const char *p = nav_resultdir_file(x->rd, "kfgins/kf-gins.yaml");
    st = p ? write_yaml(x, p) : NAV_ERR_IO;
    if (st != NAV_OK) set_msg(msg, cap, "writing kfgins/kf-gins.yaml failed");
  }
  navsim_kfgins_destroy(x);
  return st;
}
