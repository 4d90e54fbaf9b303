/*
 * navsim run --export rinex (rinex_out.h): run 0's raw GNSS measurements as RINEX 3.04 files,
 * regenerated with the simulation's own receiver (nav_sim_gnss_raw) at the epochs the
 * simulation measures (sim.c aiding_fixes: receiver epochs with a fix, in time order, on the
 * reference at their time of validity), so that the draws are run 0's.
 */
#define _POSIX_C_SOURCE 200809L
#include "rinex_out.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli_util.h"
#include "navcore/nav_earth.h"
#include "navcore/nav_frames.h"
#include "navcore/nav_gnss_sat.h"
#include "navcore/nav_math.h"
#include "navcore/nav_rinex.h"
#include "navcore/nav_sensors.h"
#include "navcore/nav_sim.h"
#include "navcore/nav_truth.h"

/* GPS records every 2 h: a RINEX user takes the record whose toe is nearest (RTKLIB accepts
 * records up to 2 h from toe), so no epoch is more than 1 h from its record. */
#define GPS_STEP_S 7200.0

enum { F_OBS, F_NAV, F_PVT, F_COUNT };

struct navsim_rinex {
  nav_scene *scene; /* copy (large: on the heap) */
  nav_resultdir *rd;
  FILE *f[F_COUNT];
  nav_truth *truth;
  nav_frame frame;
  nav_gnss_model *gnss;  /* run 0's receiver epochs and outages */
  nav_sim_gnss_raw *raw; /* run 0's raw measurements */
  nav_gnss_constellation c;
  double dt_s;
  int64_t next_epoch;
  bool header_done;
  long epochs;
  double t_first_gps_s, t_last_gps_s;
  nav_rinex_obs_header hdr;
  nav_rinex_obs_epoch ep; /* large: kept here, not on the stack */
  char date[21];
};

static void set_msg(char *msg, size_t cap, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void set_msg(char *msg, size_t cap, const char *fmt, ...) {
  if (!msg || cap == 0) return;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, cap, fmt, ap);
  va_end(ap);
}

const char *navsim_rinex_unsupported(const nav_scene *sc) {
  if (!sc->gnss.constellation.enabled)
    return "the rinex export writes the simulated pseudoranges of gnss.constellation; this scene has no "
           "gnss.constellation section";
  if (!sc->gnss.enabled)
    return "the rinex export needs a gnss receiver (gnss.enabled) for its epochs and outages";
  if (sc->earth.model != NAV_EARTH_WGS84) return "the rinex export needs earth.model wgs84";
  if (sc->gnss.file[0] != '\0')
    return "the rinex export writes simulated raw data; this scene's fixes come from gnss.file";
  return NULL;
}

void navsim_rinex_destroy(navsim_rinex *x) {
  if (!x) return;
  for (int i = 0; i < F_COUNT; ++i)
    if (x->f[i]) fclose(x->f[i]);
  nav_sim_gnss_raw_destroy(x->raw);
  nav_gnss_model_destroy(x->gnss);
  nav_truth_destroy(x->truth);
  free(x->scene);
  free(x);
}

nav_status navsim_rinex_begin(const nav_scene *scene, bool ideal, nav_resultdir *rd, navsim_rinex **out,
                              char *msg, size_t msg_cap) {
  *out = NULL;
  const char *why = navsim_rinex_unsupported(scene);
  if (why) {
    set_msg(msg, msg_cap, "%s", why);
    return NAV_ERR_INVALID_ARG;
  }
  char m[256] = "";
  nav_status st = NAV_OK;
  navsim_rinex *x = calloc(1, sizeof *x);
  if (x) x->scene = malloc(sizeof *x->scene);
  if (!x || !x->scene) {
    navsim_rinex_destroy(x);
    return NAV_ERR_NO_MEMORY;
  }
  *x->scene = *scene;
  x->rd = rd;
  const nav_scene *sc = x->scene;
  st = nav_truth_create_msg(sc, &x->truth, m, sizeof m);
  if (st != NAV_OK) {
    set_msg(msg, msg_cap, "reference trajectory: %s", m[0] ? m : nav_status_str(st));
    goto fail;
  }
  x->frame = nav_truth_frame(x->truth);
  x->dt_s = nav_truth_dt(x->truth);
  nav_gnss_model_config gcfg;
  st = nav_sim_gnss_config(sc, x->dt_s, &gcfg, m, sizeof m);
  if (st != NAV_OK) {
    set_msg(msg, msg_cap, "GNSS outages: %s", m);
    goto fail;
  }
  if (ideal) gcfg.terms = 0;
  st = nav_gnss_model_create(&gcfg, &x->frame, sc->simulation.seed, 0u, &x->gnss);
  if (st == NAV_OK) st = nav_sim_gnss_raw_create(sc, 0u, ideal, &x->raw);
  if (st == NAV_OK) st = nav_gnss_constellation_build(&sc->gnss.constellation, &x->c);
  if (st != NAV_OK) {
    set_msg(msg, msg_cap, "GNSS receiver: %s", nav_status_str(st));
    goto fail;
  }
  char nm[NAV_SCENE_NAME_MAX], rel[NAV_SCENE_NAME_MAX + 32];
  navsim_safe_name(nm, sizeof nm, sc->name, "scene");
  const char *dir = nav_resultdir_file(rd, "rinex");
  if (!dir || (mkdir(dir, 0777) != 0 && errno != EEXIST)) {
    set_msg(msg, msg_cap, "cannot create rinex/");
    st = NAV_ERR_IO;
    goto fail;
  }
  for (int i = 0; i < F_COUNT; ++i) {
    if (i == F_PVT)
      snprintf(rel, sizeof rel, "rinex/pvt.csv");
    else
      snprintf(rel, sizeof rel, "rinex/%s.%s", nm, i == F_OBS ? "obs" : "nav");
    const char *p = nav_resultdir_file(rd, rel);
    x->f[i] = p ? fopen(p, "w") : NULL;
    if (!x->f[i]) {
      set_msg(msg, msg_cap, "cannot write %s", rel);
      st = NAV_ERR_IO;
      goto fail;
    }
  }
  if (fputs("t_s,t_gps_s,n_sats,x_m,y_m,z_m,ref_x_m,ref_y_m,ref_z_m,sd_n_m,sd_e_m,sd_d_m,pdop\n",
            x->f[F_PVT]) < 0) {
    st = NAV_ERR_IO;
    goto fail;
  }
  /* The header: C1C and D1C of every system the constellation has; a carrier phase is not
   * simulated, so none is written. */
  nav_rinex_obs_header *h = &x->hdr;
  snprintf(h->marker_name, sizeof h->marker_name, "%.60s", nm);
  snprintf(h->program, sizeof h->program, "navsim");
  snprintf(h->run_by, sizeof h->run_by, "navsim run");
  snprintf(h->receiver_type, sizeof h->receiver_type, "navsim simulation");
  snprintf(h->antenna_type, sizeof h->antenna_type, "NONE");
  const nav_gnss_constellation_config *cc = &sc->gnss.constellation;
  for (int s = 0; s < NAV_GNSS_SYS_COUNT; ++s) {
    const bool on =
        s == NAV_GNSS_SYS_GPS ? cc->gps != NAV_GNSS_SOURCE_OFF : cc->glonass != NAV_GNSS_SOURCE_OFF;
    if (!on) continue;
    h->n_types[s] = 2;
    snprintf(h->types[s][0], 4, "C1C");
    snprintf(h->types[s][1], 4, "D1C");
  }
  for (int i = 0; i < x->c.n && h->n_glo < NAV_RINEX_MAX_GLO_SLOTS; ++i) {
    if (x->c.sats[i].system != NAV_GNSS_SYS_GLONASS) continue;
    h->glo_slot[h->n_glo] = x->c.sats[i].prn;
    h->glo_channel[h->n_glo] = nav_rinex_glonass_nominal_channel(x->c.sats[i].prn);
    h->n_glo++;
  }
  h->interval_s = gcfg.update_rate_hz > 0.0 ? 1.0 / gcfg.update_rate_hz : 0.0;
  *out = x;
  return NAV_OK;
fail:
  navsim_rinex_destroy(x);
  return st;
}

/* The broadcast GPS record a RINEX user selects at t: the nearest toe of the 2 h grid. */
static nav_rinex_gps_eph gps_eph_at(const nav_gnss_orbit *o, double t_gps_s) {
  const double toe = floor(t_gps_s / GPS_STEP_S + 0.5) * GPS_STEP_S;
  return nav_rinex_gps_eph_from_orbit(o, toe, 0);
}

/* The GLONASS tb nearest to t: on the UTC grid of NAVSIM_RINEX_GLO_STEP_S (t - leap a multiple). */
static double glo_tb(double t_gps_s) {
  const double leap = (double)nav_rinex_leap_seconds(t_gps_s);
  return floor((t_gps_s - leap) / NAVSIM_RINEX_GLO_STEP_S + 0.5) * NAVSIM_RINEX_GLO_STEP_S + leap;
}

/* The satellite clock a RINEX user applies to this satellite at transmit time t [s]. */
static double sat_clock_s(const nav_gnss_orbit *o, double t) {
  if (o->system == NAV_GNSS_SYS_GLONASS) {
    const double tb = glo_tb(t);
    const nav_rinex_glo_eph e = nav_rinex_glo_eph_from_orbit(o, tb, 0, 0.0); /* the clock only */
    return nav_rinex_glo_clock_s(&e, t);
  }
  const nav_rinex_gps_eph e = gps_eph_at(o, t);
  return nav_rinex_gps_clock_s(&e, t, true);
}

static nav_status write_epoch(navsim_rinex *x, const nav_traj_state *ts, char *msg, size_t cap) {
  nav_ins_gnss_raw_epoch ep;
  nav_status st = nav_sim_gnss_raw_measure(x->raw, &x->frame, ts, &ep);
  if (st != NAV_OK) {
    set_msg(msg, cap, "raw GNSS measurements at t = %.6f s: %s", ts->t_s, nav_status_str(st));
    return st;
  }
  /* The reference antenna: r_a = r_b + C_b_e l (as the receiver measures it). */
  const nav_local_view v = nav_frame_view(&x->frame, ts->r_fb_f_m, ts->v_fb_f_mps, ts->q_b_f);
  const nav_mat3 C_b_e =
      nav_mat3_mul(nav_earth_dcm_n_e(v.pos.lat_rad, v.pos.lon_rad), nav_quat_to_dcm(v.q_b_n));
  const nav_vec3 r_ea_e =
      nav_vec3_add(nav_earth_geodetic_to_ecef(v.pos), nav_mat3_mul_vec(C_b_e, x->scene->gnss.model.r_ba_b_m));
  if (ep.n == 0) return NAV_OK;
  if (!x->header_done) {
    /* The creation date field holds the first epoch (UTC), not the wall clock: the same scene and
     * seed give bit-identical files. */
    const nav_rinex_date d = nav_rinex_date_from_gps(floor(ep.t_gps_s) - nav_rinex_leap_seconds(ep.t_gps_s));
    char tmp[64];
    snprintf(tmp, sizeof tmp, "%04d%02d%02d %02d%02d%02d UTC", d.year, d.month, d.day, d.hour, d.minute,
             (int)d.second);
    snprintf(x->date, sizeof x->date, "%.20s", tmp);
    snprintf(x->hdr.date, sizeof x->hdr.date, "%s", x->date);
    x->hdr.t_first_gps_s = ep.t_gps_s;
    x->hdr.approx_pos_e_m = r_ea_e;
    x->hdr.leap_seconds = nav_rinex_leap_seconds(ep.t_gps_s);
    st = nav_rinex_obs_write_header(x->f[F_OBS], &x->hdr);
    if (st != NAV_OK) {
      set_msg(msg, cap, "RINEX observation header: %s", nav_status_str(st));
      return st;
    }
    x->header_done = true;
    x->t_first_gps_s = ep.t_gps_s;
  }
  x->t_last_gps_s = ep.t_gps_s;
  x->epochs++;
  /* Observables: a receiver measures the range to the satellite's clock, so the exported code
   * and Doppler carry the satellite clock offset (af0, af1, relativistic term, TGD: what a user
   * of the navigation file corrects; docs/rinex.md): P = P_sim - c dt_sv(t_tx),
   * D = -(rr_sim - c dt_sv') / lambda. */
  nav_rinex_obs_epoch *o = &x->ep;
  o->t_gps_s = ep.t_gps_s;
  o->n = ep.n;
  nav_gnss_pseudorange pr[NAV_GNSS_MAX_SATS];
  int npr = 0;
  for (int i = 0; i < ep.n; ++i) {
    const nav_ins_gnss_sat_meas *s = &ep.sats[i];
    const nav_gnss_orbit *orb = s->sat;
    nav_rinex_obs_sat *os = &o->sats[i];
    memset(os, 0, sizeof *os);
    os->system = orb->system;
    os->prn = orb->prn;
    const double t_tx = ep.t_gps_s - s->pr_m / NAV_GNSS_C_MPS;
    const double dts = sat_clock_s(orb, t_tx);
    const double dts_rate = 0.5 * (sat_clock_s(orb, t_tx + 1.0) - sat_clock_s(orb, t_tx - 1.0));
    const int k = orb->system == NAV_GNSS_SYS_GLONASS ? nav_rinex_glonass_nominal_channel(orb->prn) : 0;
    const double lambda = NAV_GNSS_C_MPS / nav_rinex_l1_hz(orb->system, k);
    os->has[0] = s->has_pr;
    os->value[0] = s->pr_m - NAV_GNSS_C_MPS * dts;
    os->has[1] = s->has_rr;
    os->value[1] = -(s->rr_mps - NAV_GNSS_C_MPS * dts_rate) / lambda;
    if (s->has_pr && s->has_rr) pr[npr++] = (nav_gnss_pseudorange){orb, s->pr_m};
  }
  st = nav_rinex_obs_write_epoch(x->f[F_OBS], &x->hdr, o);
  if (st != NAV_OK) {
    set_msg(msg, cap, "RINEX observation epoch at t = %.6f s: %s", ts->t_s, nav_status_str(st));
    return st;
  }
  /* Our own fix of the same epoch, as the PVT fixes (sim.c pvt_fix) compute it. */
  if (npr < 4) return NAV_OK;
  nav_gnss_pvt p;
  st = nav_gnss_pvt_solve(npr, pr, ep.t_gps_s, &p);
  if (st != NAV_OK) return NAV_OK; /* no solution at this epoch: no row */
  const nav_vec3 sd = nav_vec3_scale(p.dop_ned, ep.pr_sd_m);
  if (fprintf(x->f[F_PVT], "%.6f,%.6f,%d,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f\n", ep.t_s,
              ep.t_gps_s, p.n_used, p.r_e_m.x, p.r_e_m.y, p.r_e_m.z, r_ea_e.x, r_ea_e.y, r_ea_e.z, sd.x, sd.y,
              sd.z, p.dop.pdop) < 0)
    return NAV_ERR_IO;
  return NAV_OK;
}

nav_status navsim_rinex_record(navsim_rinex *x, const nav_sim_record *r, char *msg, size_t cap) {
  if (!x || r->run != 0 || !r->truth) return NAV_OK;
  /* sim.c aiding_fixes after the IMU step ending at t_k = k dt: the receiver epochs up to
   * t_k + dt/2, those before the first step's interval skipped. */
  const int64_t k = (int64_t)llround(r->truth->t_s / x->dt_s);
  const double t_k = (double)k * x->dt_s;
  for (;;) {
    const double t_fix = nav_gnss_model_epoch_time_s(x->gnss, x->next_epoch);
    if (!(t_fix <= t_k + 0.5 * x->dt_s)) break;
    const int64_t epoch = x->next_epoch++;
    if (t_fix < 0.5 * x->dt_s) continue;
    const double kf = t_fix / x->dt_s;
    const int64_t kk = (int64_t)llround(kf);
    const bool on_grid = fabs(kf - (double)kk) < 1e-9 && kk >= 0;
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
    st = write_epoch(x, &ts, msg, cap);
    if (st != NAV_OK) return st;
  }
  return NAV_OK;
}

nav_status navsim_rinex_end(navsim_rinex *x, char *msg, size_t cap) {
  nav_status st = NAV_OK;
  if (!x) return NAV_ERR_INVALID_ARG;
  if (!x->header_done) {
    set_msg(msg, cap, "no receiver epoch saw a satellite: nothing to export");
    st = NAV_ERR_STATE;
    goto done;
  }
  const int leap = nav_rinex_leap_seconds(x->t_first_gps_s);
  nav_rinex_nav_header nh = {0};
  snprintf(nh.program, sizeof nh.program, "navsim");
  snprintf(nh.run_by, sizeof nh.run_by, "navsim run");
  snprintf(nh.date, sizeof nh.date, "%s", x->date);
  nh.leap_seconds = leap;
  st = nav_rinex_nav_write_header(x->f[F_NAV], &nh);
  /* Records on grids spanning the observations: every epoch is at most half a step from one. */
  for (int i = 0; i < x->c.n && st == NAV_OK; ++i) {
    const nav_gnss_orbit *o = &x->c.sats[i];
    const bool glo = o->system == NAV_GNSS_SYS_GLONASS;
    const double step = glo ? NAVSIM_RINEX_GLO_STEP_S : GPS_STEP_S;
    const double t0 = glo ? glo_tb(x->t_first_gps_s) : floor(x->t_first_gps_s / step + 0.5) * step;
    const double t1 = glo ? glo_tb(x->t_last_gps_s) : floor(x->t_last_gps_s / step + 0.5) * step;
    const long nrec = lround((t1 - t0) / step) + 1;
    for (long rec = 0; rec < nrec && st == NAV_OK; ++rec) {
      const double t = t0 + (double)rec * step;
      if (glo) {
        const nav_rinex_glo_eph e = nav_rinex_glo_eph_from_orbit(
            o, t, nav_rinex_glonass_nominal_channel(o->prn), 0.5 * NAVSIM_RINEX_GLO_STEP_S);
        st = nav_rinex_nav_write_glonass(x->f[F_NAV], &e, leap);
      } else {
        /* IODE distinguishes a satellite's records (readers drop repeated IODEs). */
        const nav_rinex_gps_eph e = nav_rinex_gps_eph_from_orbit(o, t, (int)(rec % 256));
        st = nav_rinex_nav_write_gps(x->f[F_NAV], &e);
      }
    }
  }
  if (st != NAV_OK) set_msg(msg, cap, "RINEX navigation file: %s", nav_status_str(st));
done:
  for (int i = 0; i < F_COUNT; ++i) {
    if (!x->f[i]) continue;
    const bool bad = ferror(x->f[i]) != 0;
    if (fclose(x->f[i]) != 0 || bad) {
      if (st == NAV_OK) set_msg(msg, cap, "writing rinex/ failed");
      st = st == NAV_OK ? NAV_ERR_IO : st;
    }
    x->f[i] = NULL;
  }
  navsim_rinex_destroy(x);
  return st;
}
