/* Receiver outages from satellite visibility (gnss.constellation.min_satellites_for_fix): the
 * receiver model of the integrated schemes gives no fix at an epoch where fewer satellites than
 * that are visible along the true trajectory (docs/gnss-constellations.md section 6). Added to the
 * receiver configuration by nav_sim_gnss_config(), so the simulation, the covariance analysis, the
 * budget, the requirements and gnss.csv all see the same outages. */
#include <math.h>
#include <stdio.h>

#include "navcore/nav_frames.h"
#include "navcore/nav_gnss_sat.h"
#include "navcore/nav_traj.h"
#include "sim/sim_internal.h"
#include "traj/traj_internal.h"

nav_status nav_sim_gnss_visibility_outages(const nav_scene *sc, double dt_s, nav_gnss_model_config *out, char *msg,
                                           size_t msg_size) {
  const nav_gnss_constellation_config *cc = &sc->gnss.constellation;
  if (!sc->gnss.enabled || !cc->enabled || cc->min_satellites_for_fix <= 0) return NAV_OK;
  /* The tightly coupled scheme uses every satellite in view, however few: no fix is needed. */
  if (sc->navigation.scheme == NAV_SCHEME_INS_GNSS_TIGHT) return NAV_OK;
  if (!(out->update_rate_hz > 0.0)) return NAV_ERR_INVALID_ARG;
  nav_gnss_constellation c;
  nav_status st = nav_gnss_constellation_build(cc, &c);
  if (st != NAV_OK) {
    if (msg) snprintf(msg, msg_size, "gnss.constellation: cannot build the constellation");
    return st;
  }
  nav_traj *tr = NULL;
  st = nav_traj_create_msg(sc, dt_s, &tr, msg, msg_size);
  if (st != NAV_OK) return st;
  const nav_frame fr = nav_traj_frame(tr);
  const double duration = nav_traj_duration(tr);
  const int64_t n_ep = (int64_t)floor(duration * out->update_rate_hz + 1e-9);
  bool blocked = false;
  double t_start = 0.0;
  for (int64_t j = 0; j <= n_ep + 1 && st == NAV_OK; ++j) {
    const double t = (double)j / out->update_rate_hz;
    bool now = false;
    if (j <= n_ep) {
      nav_traj_state ts;
      st = nav_traj_eval(tr, t, &ts);
      if (st != NAV_OK) break;
      const nav_local_view v = nav_frame_view(&fr, ts.r_fb_f_m, ts.v_fb_f_mps, ts.q_b_f);
      const nav_mat3 C = nav_quat_to_dcm(v.q_b_n);
      const double heading = atan2(C.m[1][0], C.m[0][0]); /* as navsim's gnss_sat_out.c */
      const nav_gnss_sky_mask mask = nav_gnss_constellation_mask_at(cc, t);
      nav_gnss_dop dop;
      st = nav_gnss_visibility(&c, &mask, cc->epoch_gps_s + t, v.pos, heading, NULL, &dop);
      if (st != NAV_OK) break;
      now = dop.n_visible < cc->min_satellites_for_fix;
    }
    if (now && !blocked) {
      blocked = true;
      t_start = t;
    } else if (!now && blocked) {
      blocked = false;
      if (out->outage_count >= NAV_GNSS_MAX_OUTAGES) {
        if (msg)
          snprintf(msg, msg_size,
                   "more than %d GNSS outages (the scene's and those of fewer than %d visible satellites)",
                   NAV_GNSS_MAX_OUTAGES, cc->min_satellites_for_fix);
        st = NAV_ERR_OUT_OF_RANGE;
        break;
      }
      /* [first blocked epoch, first epoch with enough satellites again) */
      out->outages[out->outage_count++] = (nav_gnss_outage){t_start, t};
    }
  }
  nav_traj_destroy(tr);
  return st;
}
