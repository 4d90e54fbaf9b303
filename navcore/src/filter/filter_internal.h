/**
 * @file filter_internal.h
 * @brief Private pieces of the INS/GNSS filter shared by ekf.c, model.c, expm.c and the white-box
 *        tests (test_filter.c): the matrix exponential, Van Loan, and the F / G Q_c G^T / H
 *        builders. Never installed.
 */
#ifndef NAV_FILTER_INTERNAL_H
#define NAV_FILTER_INTERNAL_H

#include <stddef.h>

#include "navcore/nav_filter.h"

/* ---------------------------------------------------------------- matrix exponential (expm.c) */

/** Largest matrix the filter exponentiates: the Van Loan matrix of the largest state. */
#define NAV_EXPM_MAX_DIM (2 * NAV_FILTER_MAX_STATES)

/** What nav_expm() did: the Pade degree (3, 5, 7, 9 or 13) and the number of squarings. */
typedef struct nav_expm_info {
  unsigned pade_degree;
  unsigned squarings;
} nav_expm_info;

/** Doubles of work space nav_expm() needs for an n x n matrix: 7 n^2 + n. */
size_t nav_expm_work_size(size_t n);

/**
 * E = exp(A) for a dense n x n row-major matrix by scaling and squaring with diagonal Pade
 * approximants, N. J. Higham, "The scaling and squaring method for the matrix exponential
 * revisited", SIAM J. Matrix Anal. Appl. 26(4):1179-1193, 2005, algorithm 2.3 (degrees 3, 5, 7,
 * 9 without scaling, else degree 13 after scaling by 2^-s; theta_m from its table 2.3, 1-norm).
 * The rational solve uses LU with partial pivoting. Allocation-free.
 * @param[out] E     n x n result; must not alias A or work
 * @param[in]  A     n x n
 * @param[in]  n     1..NAV_EXPM_MAX_DIM
 * @param      work  nav_expm_work_size(n) doubles
 * @param[out] info  degree and squarings used; may be NULL
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, n out of range); NAV_ERR_NUMERIC (non-finite A or
 *         result, singular denominator).
 */
nav_status nav_expm(double *E, const double *A, size_t n, double *work, nav_expm_info *info);

/** Doubles of work space nav_filter_van_loan() needs for n states: 2 (2n)^2 + expm work. */
size_t nav_van_loan_work_size(size_t n);

/**
 * Van Loan discretisation (numerics.md E6.1; C. Van Loan, IEEE TAC 23(3), 1978): with
 * M = [[-F T, G Q_c G^T T], [0, F^T T]] and E = expm(M): Phi = E22^T, Q_d = Phi E12.
 * Takes the integrated quantities directly: FT = F T and QT = G Q_c G^T T (the decimated
 * covariance step passes sums over several IMU steps). Q_d is symmetrised.
 * The E12 block is linear in QT, so QT is scaled by a power of two (exact) to the size of FT
 * before the exponential and the result scaled back: a large or tiny Q then costs no squarings
 * and no accuracy.
 * @return NAV_OK or the status of nav_expm().
 */
nav_status nav_filter_van_loan(double *Phi, double *Qd, const double *FT, const double *QT, size_t n,
                               double *work, nav_expm_info *info);

/* ---------------------------------------------------------------- model (model.c) */

/** Earth quantities F needs at the linearisation point. */
typedef struct nav_filter_earth_terms {
  double R_M_m;    /**< meridian radius of curvature (without h) [m] */
  double R_N_m;    /**< prime-vertical radius of curvature (without h) [m] */
  double g_mps2;   /**< gravity magnitude [m/s^2] */
  double w_ie_rps; /**< Earth rotation rate [rad/s] */
} nav_filter_earth_terms;

/**
 * The process model of numerics.md 6.2 from a configuration: spectral densities q_c (VRW q_a =
 * N_a^2 on dv, ARW q_g = N_g^2 on phi; GM q = 2 sigma^2 / T and random walk q = K^2 on the sensor
 * and GNSS blocks) and the F diagonal of those blocks (-1/T for GM states). Writes the entries
 * of the blocks @p lay has and leaves the others (dr, the phi/dv diagonal) untouched.
 * The filter and the smoother build their models here, so the two cannot drift apart.
 */
void nav_filter_process_model(const nav_filter_config *cfg, const nav_filter_layout *lay, double *proc_diag,
                              double *qc);

/** WGS-84 radii R_M(lat), R_N(lat), normal gravity gamma(lat, h), omega_ie. */
nav_filter_earth_terms nav_filter_earth_terms_wgs84(double lat_rad, double h_m);

/**
 * Continuous-time F (n x n, row-major, fully written) of numerics.md 6.1 at @p nav.
 * @param proc_diag n values: the diagonal of the sensor/GNSS blocks (-1/T for GM states, 0
 *                  otherwise); entries 0..8 are ignored.
 */
void nav_filter_build_F(double *F, const nav_filter_layout *lay, const nav_filter_nav *nav,
                        const nav_filter_earth_terms *earth, const double *proc_diag);

/**
 * nav_filter_build_F without clearing F first: writes the same fixed set of entries (fixed by
 * the layout, whatever the navigation state), so on an F that holds the result of an earlier
 * build of the same layout (or zeros) the result is that of nav_filter_build_F. For the
 * filter's per-step build, where clearing the n x n matrix cost as much as the rest.
 */
void nav_filter_build_F_nonzero(double *F, const nav_filter_layout *lay, const nav_filter_nav *nav,
                                const nav_filter_earth_terms *earth, const double *proc_diag);

/**
 * G Q_c G^T (n x n, row-major, fully written): C diag(q_a) C^T on dv, C diag(q_g) C^T on phi,
 * diag(q) on the sensor/GNSS blocks (numerics.md 6.2).
 * @param qc n spectral densities: entries DV..DV+2 are N_a^2 and PHI..PHI+2 N_g^2 per body axis,
 *           the others the q of the state; entries 0..2 are ignored.
 */
void nav_filter_build_GQG(double *GQG, const nav_filter_layout *lay, nav_mat3 C_b_n, const double *qc);

/** H of the GNSS position update (3 x n), E6.3. */
void nav_filter_build_H_pos(double *H, const nav_filter_layout *lay, const nav_filter_nav *nav,
                            nav_vec3 l_ba_b_m);

/** H of the GNSS velocity update (3 x n), E6.4 with the Earth-rate term kept. */
void nav_filter_build_H_vel(double *H, const nav_filter_layout *lay, const nav_filter_nav *nav,
                            nav_vec3 l_ba_b_m);

/** Layout of a configuration's state mask. */
nav_filter_layout nav_filter_layout_of(unsigned states);

/**
 * Mutable x of a filter, for white-box tests that need an arbitrary error state (T6.1 style
 * propagation of dx0); the public API has no setter because closed-loop use never needs one.
 */
double *nav_filter_internal_state(nav_filter *f);

/*
 * nav_filter_predict for a caller whose lat, h, v_eb_n and C_b_n come from a running strapdown
 * INS in NED form (nav_ins_gnss_step, nav_ins_get_ned): the INS keeps those finite (it refuses a
 * step or a state that is not, and C_b_n is the DCM of its unit quaternion), so only f_ib_b,
 * w_ib_b, dt_s and the latitude's distance from the poles are checked here; when any of these is
 * in doubt the call is nav_filter_predict's, whose checks decide and word the failure. The same
 * values and the same errors as nav_filter_predict, without the finiteness test of all 20
 * numbers at every IMU step.
 */
nav_status nav_filter_predict_ins(nav_filter *f, const nav_filter_nav *nav, double dt_s);

#endif /* NAV_FILTER_INTERNAL_H */
