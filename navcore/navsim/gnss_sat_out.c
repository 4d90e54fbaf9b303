/*
 * gnss_dop.csv: t_s, n_visible, gdop, pdop, hdop, vdop, tdop, in_canyon (DOPs empty without a
 *               solvable geometry: fewer than 3 + systems satellites)
 * gnss_sats.csv: t_s, system, prn, az_deg, el_deg, mask_el_deg, visible, one row per satellite
 *               above the horizon at each output epoch of run 0
 * gnss_mask.csv: t_s, in_canyon, heading_deg, az_deg, mask_el_deg: the sky mask (elevation mask,
 *               per-azimuth profile, canyon walls at the vehicle's heading) every 5 deg of azimuth,
 *               at the first output epoch and at the first output epoch at or after the middle of
 *               each canyon interval (the sky plot of navsim render --view sky draws them)
 */
#include "gnss_sat_out.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "navcore/nav_frames.h"
#include "navcore/nav_gnss_sat.h"

struct navsim_gnss_sat_out {
  FILE *dop;
  FILE *sats;
  FILE *mask;
  int masks_written; /* 0: none; k > 0: the open-sky mask and k - 1 canyons */
  nav_gnss_constellation_config cfg;
  nav_gnss_constellation c;
  nav_gnss_sat_view views[NAV_GNSS_MAX_SATS];
};

nav_status navsim_gnss_sat_out_begin(const nav_scene *scene, const char *dop_path, const char *sats_path,
                                     const char *mask_path, navsim_gnss_sat_out **out) {
  *out = NULL;
  if (!scene->gnss.constellation.enabled) return NAV_OK;
  navsim_gnss_sat_out *g = calloc(1, sizeof *g);
  if (!g) return NAV_ERR_NO_MEMORY;
  g->cfg = scene->gnss.constellation;
  nav_status st = nav_gnss_constellation_build(&g->cfg, &g->c);
  if (st != NAV_OK) {
    free(g);
    return st;
  }
  g->dop = fopen(dop_path, "w");
  g->sats = fopen(sats_path, "w");
  g->mask = fopen(mask_path, "w");
  if (!g->dop || !g->sats || !g->mask || fputs("t_s,in_canyon,heading_deg,az_deg,mask_el_deg\n", g->mask) < 0 ||
      fputs("t_s,n_visible,gdop,pdop,hdop,vdop,tdop,in_canyon\n", g->dop) < 0 ||
      fputs("t_s,system,prn,az_deg,el_deg,mask_el_deg,visible\n", g->sats) < 0) {
    (void)navsim_gnss_sat_out_end(g);
    return NAV_ERR_IO;
  }
  *out = g;
  return NAV_OK;
}

nav_status navsim_gnss_sat_out_record(navsim_gnss_sat_out *g, const nav_sim_record *r) {
  if (!g || r->run != 0 || !r->truth || !r->frame) return NAV_OK;
  const nav_traj_state *ts = r->truth;
  const nav_local_view v = nav_frame_view(r->frame, ts->r_fb_f_m, ts->v_fb_f_mps, ts->q_b_f);
  const nav_mat3 C = nav_quat_to_dcm(v.q_b_n);
  const double heading = atan2(C.m[1][0], C.m[0][0]); /* body x axis in NED */
  const nav_gnss_sky_mask mask = nav_gnss_constellation_mask_at(&g->cfg, ts->t_s);
  nav_gnss_dop dop;
  const nav_status st = nav_gnss_visibility(&g->c, &mask, g->cfg.epoch_gps_s + ts->t_s, v.pos, heading, g->views, &dop);
  if (st != NAV_OK) return st;
  int n = 0;
  if (dop.valid) {
    n = fprintf(g->dop, "%.9g,%d,%.6f,%.6f,%.6f,%.6f,%.6f,%d\n", ts->t_s, dop.n_visible, dop.gdop, dop.pdop, dop.hdop,
                dop.vdop, dop.tdop, mask.canyon_height_m > 0.0);
  } else {
    n = fprintf(g->dop, "%.9g,%d,,,,,,%d\n", ts->t_s, dop.n_visible, mask.canyon_height_m > 0.0);
  }
  if (n < 0) return NAV_ERR_IO;
  const double r2d = 180.0 / 3.14159265358979323846;
  /* The mask: at the first epoch, then once per canyon (at its middle). */
  const int k = g->masks_written;
  const bool due = k == 0 || (k - 1 < g->cfg.n_canyons &&
                              ts->t_s >= 0.5 * (g->cfg.canyons[k - 1].t0_s + g->cfg.canyons[k - 1].t1_s));
  if (due) {
    for (int a = 0; a <= 72; ++a) {
      const double az = (double)a * 5.0 / r2d;
      const double m = nav_gnss_mask_elevation_rad(&mask, az, heading);
      if (fprintf(g->mask, "%.9g,%d,%.4f,%.1f,%.4f\n", ts->t_s, mask.canyon_height_m > 0.0, heading * r2d,
                  (double)a * 5.0, m * r2d) < 0)
        return NAV_ERR_IO;
    }
    g->masks_written++;
  }
  for (int i = 0; i < g->c.n; ++i) {
    const nav_gnss_sat_view *s = &g->views[i];
    if (s->el_rad <= 0.0) continue;
    const double m = nav_gnss_mask_elevation_rad(&mask, s->az_rad, heading);
    if (fprintf(g->sats, "%.9g,%s,%d,%.4f,%.4f,%.4f,%d\n", ts->t_s, s->system == NAV_GNSS_SYS_GPS ? "G" : "R", s->prn,
                s->az_rad * r2d, s->el_rad * r2d, m * r2d, s->visible ? 1 : 0) < 0)
      return NAV_ERR_IO;
  }
  return NAV_OK;
}

bool navsim_gnss_sat_out_end(navsim_gnss_sat_out *g) {
  if (!g) return true;
  bool ok = true;
  /* Both files are closed whatever the first one gave. */
  FILE *files[3] = {g->dop, g->sats, g->mask};
  for (int i = 0; i < 3; ++i) {
    if (!files[i]) continue;
    const bool bad = ferror(files[i]) != 0;
    if (fclose(files[i]) != 0 || bad) ok = false;
  }
  free(g);
  return ok;
}
