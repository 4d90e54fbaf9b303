/*
 * gnss.csv / gnss_outages.csv writer (see gnss_out.h).
 *
 * gnss.csv:          t_s,lat_deg,lon_deg,h_m,pos_n_m,pos_e_m,pos_d_m,pos_sd_n_m,pos_sd_e_m,pos_sd_d_m
 *                    one row per fix of run 0 (every fix up to the last output epoch, at the
 *                    receiver's rate whatever the output rate): the measured antenna position
 *                    (geodetic and NED about the scene origin) and the reported 1-sigma. The
 *                    receiver model is evaluated on the reference at each fix's time of validity
 *                    (its own truth object), as the simulation does.
 * gnss_outages.csv:  t0_s,t1_s   every outage interval of the receiver (scene outages and the
 *                    segment-tied ones), no fix has its time of validity in [t0_s, t1_s).
 */
#include "gnss_out.h"

#include <math.h>
#include <stdlib.h>

#include "navcore/nav_sim.h" /* nav_sim_gnss_config: the receiver the simulation uses */
#include "navcore/nav_frames.h"
#include "navcore/nav_math.h"
#include "navcore/nav_recorded.h"
#include "navcore/nav_sensors.h"
#include "navcore/nav_truth.h"

struct navsim_gnss_out {
  FILE *f;
  nav_ins_gnss_fix *fixes; /* gnss.file: the recorded fixes (scene time base), else NULL */
  size_t fix_count;
  nav_gnss_model_config cfg; /* outages of the recorded fixes */
  nav_gnss_model *model;
  nav_truth *truth; /* the reference at the fix times */
  int64_t next_epoch;
  bool bad;
};

nav_status navsim_gnss_out_begin(const nav_scene *scene, bool ideal, const char *gnss_path, const char *outages_path,
                                 navsim_gnss_out **out) {
  *out = NULL;
  if (scene->navigation.scheme != NAV_SCHEME_INS_GNSS && scene->navigation.scheme != NAV_SCHEME_GYRO_FREE_GNSS)
    return NAV_OK;
  nav_gnss_model_config cfg;
  char msg[256];
  nav_status st = nav_sim_gnss_config(scene, 1.0 / scene->imu.rate_hz, &cfg, msg, sizeof msg);
  if (st != NAV_OK) return st;
  if (ideal) cfg.terms = 0;
  FILE *fo = fopen(outages_path, "w");
  if (!fo) return NAV_ERR_IO;
  bool bad = fputs("t0_s,t1_s\n", fo) < 0;
  for (size_t i = 0; i < cfg.outage_count; ++i)
    if (fprintf(fo, "%.17g,%.17g\n", cfg.outages[i].t0_s, cfg.outages[i].t1_s) < 0) bad = true;
  if (ferror(fo)) bad = true;
  if (fclose(fo) != 0 || bad) return NAV_ERR_IO;
  /* Fixes from the least-squares PVT of the simulated pseudoranges (gnss.constellation.fixes:
   * pvt) are not the receiver model's: this writer evaluates the model, so it writes no gnss.csv
   * rather than a list of fixes the filter never saw. */
  if (nav_scene_gnss_pvt_fixes(scene)) return NAV_OK;

  navsim_gnss_out *g = calloc(1, sizeof *g);
  if (!g) return NAV_ERR_NO_MEMORY;
  g->cfg = cfg;
  if (scene->gnss.file[0] != '\0') {
    /* The recorded fixes the simulation applies (its caller reported any problem with the file). */
    st = nav_gnss_file_load(scene, &g->fixes, &g->fix_count, NULL, NULL);
    if (st != NAV_OK) {
      free(g);
      return st;
    }
  }
  const nav_frame frame = nav_frame_from_scene(scene);
  st = nav_gnss_model_create(&cfg, &frame, scene->simulation.seed, 0u, &g->model);
  if (st != NAV_OK) {
    free(g->fixes);
    free(g);
    return st;
  }
  st = nav_truth_create_msg(scene, &g->truth, msg, sizeof msg);
  if (st != NAV_OK) {
    nav_gnss_model_destroy(g->model);
    free(g->fixes);
    free(g);
    return st;
  }
  g->f = fopen(gnss_path, "w");
  if (!g->f || fputs("t_s,lat_deg,lon_deg,h_m,pos_n_m,pos_e_m,pos_d_m,pos_sd_n_m,pos_sd_e_m,pos_sd_d_m\n", g->f) < 0) {
    if (g->f) fclose(g->f);
    nav_gnss_model_destroy(g->model);
    nav_truth_destroy(g->truth);
    free(g->fixes);
    free(g);
    return NAV_ERR_IO;
  }
  *out = g;
  return NAV_OK;
}

static bool in_outage(const nav_gnss_model_config *c, double t_s) {
  for (size_t i = 0; i < c->outage_count; ++i)
    if (t_s >= c->outages[i].t0_s && t_s < c->outages[i].t1_s) return true;
  return false;
}

/* gnss.file: the recorded fixes up to this output epoch that the simulation applies (not before
 * the run, not in an outage), with the file's sigmas. */
static nav_status recorded_rows(navsim_gnss_out *g, const nav_sim_record *r, double t) {
  while ((size_t)g->next_epoch < g->fix_count) {
    const nav_ins_gnss_fix *fix = &g->fixes[g->next_epoch];
    if (fix->t_s > t + 1e-6) break;
    g->next_epoch++;
    if (fix->t_s < 0.0 || in_outage(&g->cfg, fix->t_s)) continue;
    const nav_vec3 ned = nav_frame_geodetic_to_local(r->frame, fix->pos);
    if (fprintf(g->f, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.9g,%.9g,%.9g\n", fix->t_s,
                fix->pos.lat_rad * NAV_RAD2DEG, fix->pos.lon_rad * NAV_RAD2DEG, fix->pos.h_m, ned.x, ned.y, ned.z,
                fix->pos_sd_m.x, fix->pos_sd_m.y, fix->pos_sd_m.z) < 0)
      return NAV_ERR_IO;
  }
  return NAV_OK;
}

nav_status navsim_gnss_out_record(navsim_gnss_out *g, const nav_sim_record *r) {
  if (!g || r->run != 0) return NAV_OK;
  const double t = r->truth->t_s;
  if (g->fixes) return recorded_rows(g, r, t);
  for (;;) {
    const double t_fix = nav_gnss_model_epoch_time_s(g->model, g->next_epoch);
    if (t_fix > t + 1e-6) break;
    const int64_t epoch = g->next_epoch++;
    nav_traj_state ts;
    if (fabs(t_fix - t) <= 1e-6) {
      ts = *r->truth;
      ts.t_s = t_fix;
    } else {
      const nav_status tst = nav_truth_state(g->truth, t_fix, &ts);
      if (tst != NAV_OK) return tst;
    }
    nav_gnss_fix fix;
    bool has_fix = false;
    const nav_status st = nav_gnss_model_measure(g->model, epoch, &ts, &fix, &has_fix);
    if (st != NAV_OK) return st;
    if (!has_fix) continue;
    const nav_local_view v = nav_frame_view(r->frame, fix.r_fa_f_m, ts.v_fb_f_mps, ts.q_b_f);
    if (fprintf(g->f, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.9g,%.9g,%.9g\n", fix.t_s,
                fix.pos.lat_rad * NAV_RAD2DEG, fix.pos.lon_rad * NAV_RAD2DEG, fix.pos.h_m, v.r_ned_m.x, v.r_ned_m.y,
                v.r_ned_m.z, fix.pos_sd_m.x, fix.pos_sd_m.y, fix.pos_sd_m.z) < 0)
      return NAV_ERR_IO;
  }
  return NAV_OK;
}

bool navsim_gnss_out_end(navsim_gnss_out *g) {
  if (!g) return true;
  bool ok = ferror(g->f) == 0;
  if (fclose(g->f) != 0) ok = false;
  nav_gnss_model_destroy(g->model);
  nav_truth_destroy(g->truth);
  free(g->fixes);
  free(g);
  return ok;
}
