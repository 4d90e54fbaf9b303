/**
 * @file nav_ins.h
 * @brief Strapdown inertial navigation (mechanization) driven by IMU increments.
 *
 * Algorithms (numerics.md section 4):
 * - NAV_MECH_FIRST_ORDER (a): phi_k = dtheta_k; dv rotated with I + 1/2 [dtheta x];
 *   trapezoidal position.
 * - NAV_MECH_HIGH_ORDER (b): two-sample coning phi_k = dtheta_k + 1/12 dtheta_(k-1) x dtheta_k
 *   (E4.2), exact rotation compensation A(phi) (E4.4), two-sample sculling (E4.5), trapezoidal
 *   position.
 *
 * Frames (nav_ins_config.earth_model, .mech_frame):
 * - Flat Earth: the non-rotating scene frame l with uniform gravity g_l_mps2.
 * - WGS-84, NAV_MECH_NED: local-level NED; the state is kept as latitude, longitude, ellipsoidal
 *   height, v_eb_n and q_b_n. Body update exp(phi), navigation-frame update exp(-zeta) with
 *   zeta = (omega_ie_n + omega_en_n) dt at mid-interval, velocity with the frame-rotation term
 *   -1/2 [zeta x] C dv (plus its second-order terms for (b)), curvilinear trapezoidal position
 *   (numerics.md 4.1-4.3, NED rows), longitude wrapped to (-pi, pi]. It refuses
 *   (NAV_ERR_OUT_OF_RANGE, state untouched) when cos(lat) falls below NAV_INS_NED_MIN_COS_LAT,
 *   where the transport rate is singular (numerics.md 4.4 rule 4).
 * - WGS-84, NAV_MECH_ECEF: the state is r_eb_e, v_eb_e and q_b_e; the exact Earth-rotation step
 *   R_z(-omega_ie dt) on the left of the attitude; gravity, Coriolis and centrifugal terms in e
 *   (numerics.md 4.1-4.3, ECEF rows). No singularity anywhere (over the poles included).
 * On WGS-84, gravity (and the Coriolis and transport terms) are evaluated at mid-interval by a
 * predictor-corrector (second order; numerics.md 4.2), with the gravity model shared with the
 * truth generator (nav_gravity_e_mps2).
 *
 * The navigation never sees truth: it consumes increments only. Every step renormalises the
 * quaternion. Memory is allocated only by nav_ins_create. Objects are not synchronised: one
 * thread per object.
 *
 * Example (WGS-84, NED mechanization; the initial state is given in ECEF):
 * @code
 *   nav_ins_config cfg = nav_ins_config_default();
 *   cfg.earth_model = NAV_EARTH_WGS84;
 *   cfg.algorithm = NAV_MECH_HIGH_ORDER;
 *   cfg.mech_frame = NAV_MECH_NED;
 *   nav_ins *ins = NULL;
 *   if (nav_ins_create(&cfg, &s0, &ins) == NAV_OK) {       // s0: r, v, q_b_e in ECEF
 *     for (k = 1; k <= n; ++k)
 *       if (nav_ins_step(ins, &imu[k]) != NAV_OK) { puts(nav_ins_last_error(ins)); break; }
 *     const nav_ins_state *s = nav_ins_get_state(ins);      // ECEF again
 *     nav_ins_destroy(ins);
 *   }
 * @endcode
 */
#ifndef NAV_INS_H
#define NAV_INS_H

#include "nav_export.h"
#include "nav_math.h"
#include "nav_scene.h"
#include "nav_status.h"
#include "nav_truth.h"

NAV_BEGIN_DECLS

/**
 * The NED mechanization refuses to step when cos(lat) < this value (numerics.md 4.4 rule 4,
 * T5.5): above it, tan(lat) < 1e6 and the longitude rate stays finite and representable.
 */
#define NAV_INS_NED_MIN_COS_LAT 1e-6

/**
 * Navigation state in the scene frame F (nav_frames.h): F = l on flat Earth, F = e (ECEF) on
 * WGS-84 whatever frame the mechanization integrates in (a NED mechanization converts).
 */
typedef struct nav_ins_state {
  double t_s;
  nav_vec3 r_fb_f_m;   /**< position [m] */
  nav_vec3 v_fb_f_mps; /**< velocity relative to F, resolved in F [m/s] */
  nav_quat q_b_f;      /**< attitude */
} nav_ins_state;

/**
 * How the WGS-84 mechanizations evaluate the gravity, Coriolis and transport-rate terms over an
 * interval (numerics.md 4.2).
 */
typedef enum nav_ins_gravity_step {
  /** Mid-interval value by predictor-corrector: global velocity error O(dt^2) or better. */
  NAV_INS_GRAVITY_PREDICTOR_CORRECTOR = 0,
  /** Value at the start of the interval only: global velocity error O(dt). For comparisons and
   *  benchmarks (numerics.md T5.5 "1st-order gravity" columns); never the right choice otherwise. */
  NAV_INS_GRAVITY_START_OF_INTERVAL = 1
} nav_ins_gravity_step;

typedef struct nav_ins_config {
  nav_earth_model earth_model;
  nav_mech_algorithm algorithm;
  nav_mech_frame mech_frame;       /**< WGS-84: integrate in local-level NED or in ECEF */
  nav_gravity_model gravity_model; /**< WGS-84: must equal the truth's */
  nav_vec3 g_l_mps2;               /**< flat Earth: uniform gravity in l, e.g. (0, 0, 9.80665) */
  /**
   * WGS-84: hold the vertical channel. After every step the ellipsoidal height and the down
   * velocity are reset to the values of the initial state or of the last nav_ins_aid_vertical()
   * call (numerics.md 4.4 rule 6: "clamp"). Flat Earth: ignored.
   */
  bool clamp_vertical;
  nav_ins_gravity_step gravity_step; /**< WGS-84: default NAV_INS_GRAVITY_PREDICTOR_CORRECTOR */
} nav_ins_config;

typedef struct nav_ins nav_ins;

/** Defaults: flat Earth, first-order algorithm, NED, normal gravity, g = (0, 0, 9.80665),
 *  no vertical clamp, predictor-corrector gravity. */
NAV_API nav_ins_config nav_ins_config_default(void);

/** The mechanization a scene selects: Earth and gravity model, algorithm, frame, flat gravity;
 *  the other fields at their defaults. */
NAV_API nav_ins_config nav_ins_config_from_scene(const nav_scene *scene);

/**
 * Create a mechanization starting at @p initial.
 * @param[in]  cfg     configuration (copied)
 * @param[in]  initial initial state in F: l on flat Earth; on WGS-84 always ECEF (r_eb_e [m],
 *                     v_eb_e [m/s], q_b_e), also for the NED mechanization, which converts it
 * @param[out] out     the new object; destroy with nav_ins_destroy()
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, unknown enum value, non-finite or zero quaternion,
 *         non-finite state); NAV_ERR_OUT_OF_RANGE (NED mechanization with cos(lat) <
 *         NAV_INS_NED_MIN_COS_LAT at the initial position); NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_ins_create(const nav_ins_config *cfg, const nav_ins_state *initial,
                                                nav_ins **out);
/** Destroy; accepts NULL. */
NAV_API void nav_ins_destroy(nav_ins *ins);

/**
 * Advance by one IMU interval.
 * @return NAV_OK; NAV_ERR_NUMERIC if the increment or the resulting state is not finite;
 *         NAV_ERR_OUT_OF_RANGE if the NED mechanization would reach cos(lat) <
 *         NAV_INS_NED_MIN_COS_LAT (the pole: use NAV_MECH_ECEF there); NAV_ERR_INVALID_ARG for
 *         NULL or dt <= 0. On any error the state is left as it was and nav_ins_last_error()
 *         says why.
 */
NAV_API NAV_NODISCARD nav_status nav_ins_step(nav_ins *ins, const nav_imu_increment *imu);

/**
 * Reset height and vertical velocity to externally known values (vertical-channel aiding, used
 * by long free-inertial tests: the free vertical channel diverges as exp(t / 570 s)).
 * @param[in] h_m     flat Earth: height above the plane of the origin (-D) [m]; WGS-84:
 *                    ellipsoidal height [m] (latitude and longitude are kept)
 * @param[in] v_d_mps down velocity (in n) [m/s]; the north and east velocity are kept
 * @return NAV_OK; NAV_ERR_INVALID_ARG for NULL or non-finite values (state untouched).
 */
NAV_API NAV_NODISCARD nav_status nav_ins_aid_vertical(nav_ins *ins, double h_m, double v_d_mps);

/**
 * Replace the navigation state (closed-loop feedback of an aiding filter). The state is given in
 * F as for nav_ins_create(); the previous increments used by the coning and sculling terms and
 * the vertical hold are kept. Allocates nothing. On failure the state is unchanged.
 * @return NAV_OK; NAV_ERR_NUMERIC for a non-finite state; the statuses of nav_ins_create().
 */
NAV_API NAV_NODISCARD nav_status nav_ins_set_state(nav_ins *ins, const nav_ins_state *state);

/**
 * Current state in F (borrowed; valid until the next non-const call or destroy).
 * The NED mechanization computes this e-frame view of its geodetic state on the first call after
 * a step (a cache inside the object), so a caller that reads the state at an output rate does
 * not pay for the conversion at every step. Like every navcore object, one thread at a time,
 * getters included.
 */
NAV_API const nav_ins_state *nav_ins_get_state(const nav_ins *ins);

/** The geodetic state a WGS-84 NED mechanization integrates (no conversion). Plain value. */
typedef struct nav_ins_ned {
  double t_s;         /**< time of the state [s] */
  nav_geodetic pos;   /**< latitude, longitude [rad] (wrapped to (-pi, pi]), ellipsoidal height [m] */
  nav_vec3 v_n_mps;   /**< velocity relative to the Earth, NED [m/s] */
  nav_quat q_b_n;     /**< attitude, body to NED */
  double sin_lat;     /**< sin(lat), as the mechanization has it */
  double cos_lat;     /**< cos(lat) */
} nav_ins_ned;

/**
 * The NED state itself when the mechanization is WGS-84 in NED (what nav_ins_get_state()
 * converts to the e frame), for callers that need geodetic quantities at every step (the
 * INS/GNSS filter) without an ECEF round trip.
 * @return true and *out filled for a WGS-84 NED mechanization; false otherwise (use
 *         nav_ins_get_state()).
 */
NAV_API bool nav_ins_get_ned(const nav_ins *ins, nav_ins_ned *out);

/**
 * Detailed message of the last failure on this handle ("" if none), e.g. which latitude made
 * the NED mechanization refuse. Borrowed; valid until the next non-const call or destroy.
 */
NAV_API const char *nav_ins_last_error(const nav_ins *ins);

NAV_END_DECLS

#endif /* NAV_INS_H */
