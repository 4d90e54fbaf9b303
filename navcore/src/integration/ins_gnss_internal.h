/* Private to navcore's integration module: the INS/GNSS object shared by the loosely coupled
 * updates (ins_gnss.c) and the tightly coupled ones (ins_gnss_tight.c), which use the same INS,
 * the same error-state filter and the same closed-loop feedback. */
#ifndef NAV_INS_GNSS_INTERNAL_H
#define NAV_INS_GNSS_INTERNAL_H

#include <stdbool.h>

#include "navcore/nav_ins_gnss.h"

struct nav_ins_gnss {
  nav_ins_gnss_config cfg;
  nav_frame frame;
  nav_ins *ins;
  nav_filter *kf;
  nav_vec3 b_g_rps, b_a_mps2; /* estimated biases, subtracted from the raw increments */
  nav_vec3 s_g, s_a;          /* estimated scale factors: compensated = (raw - b dt) / (1 + s) */
  nav_imu_increment last;     /* compensated increment of the last step */
  /* The compensated angle increment and interval of the step before it: its mean rate is needed
   * only at a fix epoch (nav_ins_gnss_epoch_nav), so the division is done there, not per step. */
  nav_vec3 prev_dtheta_b_rad;
  double prev_dt_s;
  bool have_step, have_prev;
  bool sf_on; /* the filter estimates scale factors */
  long updates;
  long raw_used, raw_rejected; /* tightly coupled: scalar measurements applied / gated out */
  char err[256];
};

/** nav_ins_gnss_step(x[l], raw[l]) for l = 0..3, st[l] its status, with the four strapdown steps
 *  in lockstep where they can be (nav_ins_step_lanes()): the same results and messages as four
 *  calls. */
void nav_ins_gnss_step_lanes(nav_ins_gnss *const x[4], const nav_imu_increment *const raw[4], nav_status st[4]);

/** Filter inputs from the INS and the compensated increment of the step just taken. */
nav_filter_nav nav_ins_gnss_filter_nav(const nav_frame *fr, const nav_ins *ins, const nav_imu_increment *imu);

/** The linearisation point at the current epoch (rate extrapolated to the epoch) and the INS's
 *  local view. */
nav_filter_nav nav_ins_gnss_epoch_nav(const nav_ins_gnss *x, nav_local_view *view);

/** Feed the filter's INS error estimates back into the INS (numerics.md 6.5), reset them, count
 *  the update and record it for the smoother. @p view: the INS view before the feedback. */
nav_status nav_ins_gnss_feedback(nav_ins_gnss *x, const nav_local_view *view, double t_s);

/** The tightly coupled filter of a scene (ins_gnss_tight): receiver-clock states from the
 *  constellation's oscillator model, the inter-system bias when GPS and GLONASS are both on, no
 *  GNSS position GM states (ins_gnss_tight.c). */
void nav_ins_gnss_tight_filter(const nav_scene *sc, nav_filter_config *c);

/** What the tightly coupled measurement rows need at one epoch (ins_gnss_tight.c). */
typedef struct nav_tight_geom {
  nav_filter_layout lay;
  nav_mat3 C_n_e;
  nav_vec3 r_ea_e, v_ea_e; /* antenna position and velocity (relative to the Earth), ECEF */
  double Hpos[3 * NAV_FILTER_MAX_STATES], Hvel[3 * NAV_FILTER_MAX_STATES];
} nav_tight_geom;

/** The antenna and the loose position/velocity Jacobians at the linearisation point @p nav with
 *  the geodetic position @p pos (the INS's, or the reference in covariance analysis). */
void nav_ins_gnss_tight_geometry(nav_tight_geom *g, const nav_filter_layout *lay, const nav_filter_nav *nav,
                                 nav_geodetic pos, nav_vec3 l_ba_b_m);

/** One satellite's pseudorange and range-rate H rows (n = lay.n_states each), predicted range and
 *  range rate (docs/ins-gnss-tight.md 3). */
void nav_ins_gnss_tight_rows(const nav_tight_geom *g, const nav_gnss_orbit *sat, double t_gps_s, double *H_pr,
                             double *H_rr, double *rho_m, double *rr_mps);

#endif /* NAV_INS_GNSS_INTERNAL_H */
