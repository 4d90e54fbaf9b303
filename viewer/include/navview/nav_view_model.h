/**
 * @file nav_view_model.h
 * @brief The 3D scene as plain data: decimated paths, triads, envelope tube, grid, all in the
 *        render frame r (nav_view_frame.h). No VTK types; NavSceneView turns it into actors.
 *
 * Keeping the geometry out of VTK makes it testable without a display: the envelope radii, the
 * triad orientations and the decimation error are checked by unit tests.
 */
#ifndef NAV_VIEW_MODEL_H
#define NAV_VIEW_MODEL_H

#include <cmath>
#include <string>
#include <vector>

#include "navview/nav_view_result.h"

/** Where the radius of the error-envelope tube comes from. */
enum class NavEnvelopeSource {
  Auto,       /**< Monte Carlo RMS when mc_stats.csv is present, else run 0 errors */
  RunErrors,  /**< k * horizontal error of run 0 (errors.csv) */
  MonteCarlo, /**< k * RMS over runs of the horizontal error (mc_stats.csv) */
  Filter,     /**< k * the filter's reported horizontal sigma, mean over runs (mc_stats.csv) */
  Covariance, /**< k * the predicted horizontal sigma of the covariance analysis (estimate.csv) */
  None        /**< no tube */
};

/** Vehicle glyph at the playback time. */
enum class NavVehicleKind {
  Auto,     /**< from the scene name: aircraft/flight/uav/climb -> aircraft, car/drive -> car */
  Car,      /**< box body, cabin and a wedge nose */
  Aircraft, /**< fuselage, wings and tail */
  Generic   /**< an arrowhead (cone) along body x */
};

/** The envelope source actually used for @p result (Auto resolved; None when no data). */
NavEnvelopeSource NavResolveEnvelopeSource(const NavResult &result, NavEnvelopeSource requested);
/** Human-readable name of an envelope source ("MC RMS", "filter sigma", ...). */
const char *NavEnvelopeSourceName(NavEnvelopeSource src);
/** Per-axis 1-sigma N/E/D [m] at time @p t from @p src (MonteCarlo: RMS over runs per axis;
 *  Filter: reported sigma; Covariance: predicted sigma; RunErrors: |error| of run 0).
 *  @return false when the source has no data. */
bool NavSigmaNed(const NavResult &result, NavEnvelopeSource src, double t, double sigma_ned[3]);
/** Horizontal 1-sigma [m] at time @p t from @p src (NaN when the source has no data). */
double NavSigmaH(const NavResult &result, NavEnvelopeSource src, double t);

/** Attitude-error exaggeration of the estimated triads when the user gives none: navview,
 *  `navsim render`, the report and navstudio all start from it. A 0.1 deg error of a good INS
 *  becomes 2 deg, visible on a triad; the legend always states the factor. */
constexpr double kNavDefaultAttExaggeration = 20.0;

/** Camera presets of the 3D view. */
enum class NavCameraPreset {
  Oblique, /**< from the south-south-west, 50 deg above the horizon, perspective */
  Top      /**< plan view, north up, parallel projection */
};

/** Options of the 3D view. Defaults give the "default view" of the issue. */
struct NavViewOptions {
  int width_px = 1000;
  int height_px = 700;
  /** Playback time [s] of the vehicle glyph and the read-out; NaN: end of the run. */
  double time_s = NAN;
  /** Attitude-error exaggeration k: the estimated triad shows exp(k*phi) C_b_n(truth), where
   *  phi is the rotation vector of C_b_n(nav) C_b_n(truth)^T; k = 1 shows the true estimate. */
  double att_exaggeration = kNavDefaultAttExaggeration;
  /** Envelope tube radius = envelope_k * sigma_h [m]. */
  double envelope_k = 3.0;
  NavEnvelopeSource envelope_source = NavEnvelopeSource::Auto;
  /** Interval between triads [s]; <= 0: automatic (about 24 along the run). */
  double triad_interval_s = 0.0;
  /** Triad arrow length [m]; <= 0: automatic (from the scene extent). */
  double triad_size_m = 0.0;
  /** Colour the estimated path by horizontal error magnitude (with a scalar bar). */
  bool color_by_error = false;
  /** Draw text (title, read-out, legend, scale label, axis letters, scalar-bar labels). Render
   *  tests switch it off: no system-font text in compared images (style.md section 10). */
  bool show_text = true;
  bool show_grid = true;
  bool show_axes = true;
  bool show_triads = true;
  /** A triad pair (reference and estimate) at the playback time, moving with it. */
  bool show_triads_at_time = true;
  bool show_vehicle = true;
  /** Screen-space decimation tolerance [pixels]. */
  double decimate_px = 0.5;
  NavCameraPreset camera = NavCameraPreset::Oblique;
  /** Explicit camera (render frame r) instead of the preset, for render tests. */
  bool fixed_camera = false;
  double camera_position_r[3] = {0, 0, 1};
  double camera_focal_r[3] = {0, 0, 0};
  double camera_view_up_r[3] = {0, 1, 0};
  double camera_view_angle_deg = 30.0;
  /** Multisample anti-aliasing samples (0: off). */
  int multisamples = 8;
  /** Fast approximate anti-aliasing (a screen-space pass; movies: about a quarter of the cost
   *  of 4x multisampling per frame on llvmpipe). */
  bool fxaa = false;
  /** Covariance ellipsoids (semi-axes envelope_k x sigma N/E/D of the envelope source) at this
   *  many epochs spread evenly over the run (0: none). */
  int ellipsoid_count = 6;
  /** Explicit ellipsoid epochs [s] (override ellipsoid_count when not empty). */
  std::vector<double> ellipsoid_times_s;
  /** GNSS fixes as points and outage intervals highlighted on the reference path. */
  bool show_gnss = true;
  NavVehicleKind vehicle = NavVehicleKind::Auto;
  /** Follow camera: at every time the camera looks at the vehicle from behind and above (25 deg)
   *  at follow_distance_m; the triads and the vehicle are sized for that distance. */
  bool follow = false;
  /** Follow-camera distance [m]; <= 0: automatic (12 x the vehicle's length, at least 40 m). */
  double follow_distance_m = 0.0;
  /** The envelope tube and the ellipsoids are drawn at least this many pixels across at the
   *  current view scale, so a metre-level envelope stays visible at city scale (the legend says
   *  so); re-applied when the scale changes by more than 1.5x (zoom, follow camera). */
  double min_envelope_px = 3.0;
};

/** Epochs of the covariance ellipsoids: the options' explicit times, else ellipsoid_count epochs
 *  spread evenly over the run plus the last reference epoch inside each GNSS outage. */
std::vector<double> NavEllipsoidTimes(const NavResult &result, const NavViewOptions &opt);

/** A covariance ellipsoid in frame r: axis-aligned with N/E/D (diagonal sigma). */
struct NavEllipsoid {
  double t_s = 0.0;
  double center_r[3] = {0, 0, 0};
  double sigma_ned_m[3] = {0, 0, 0}; /**< the sigma fed in [m] */
  double semi_axes_r[3] = {0, 0, 0}; /**< k x sigma along x (east), y (north), z (up) [m] */
};

/** A decimated polyline in the render frame. */
struct NavPolyline {
  std::vector<double> xyz_r;        /**< 3 per kept point [m] */
  std::vector<double> scalar;       /**< optional per-point scalar (error magnitude [m]) */
  std::vector<size_t> source_index; /**< epoch index of each kept point in the full track */
  size_t Size() const { return xyz_r.size() / 3; }
};

/** Attitude triads: one per time, positions and body-to-render quaternions. */
struct NavTriadSet {
  std::vector<double> t_s;
  std::vector<double> xyz_r; /**< 3 per triad [m] */
  std::vector<double> q_b_r; /**< 4 per triad {w, x, y, z} */
  size_t Size() const { return t_s.size(); }
};

/** Error-envelope tube around the reference path. */
struct NavTube {
  std::vector<double> xyz_r;    /**< 3 per kept point [m] */
  std::vector<double> radius_m; /**< tube radius per kept point [m] */
  std::vector<double> sigma_m;  /**< the sigma fed in per kept point [m] (radius = k * sigma) */
  std::vector<size_t> source_index;
  size_t Size() const { return radius_m.size(); }
};

/** The whole 3D scene as data. */
struct NavSceneModel {
  NavPolyline reference;
  NavPolyline estimate;
  std::vector<NavPolyline> extra_runs;
  NavTriadSet triads_ref;
  NavTriadSet triads_est;
  NavTube envelope;
  std::string envelope_label;              /**< legend text of the tube, empty when there is none */
  NavEnvelopeSource envelope_source = NavEnvelopeSource::None; /**< resolved source */
  std::vector<NavEllipsoid> ellipsoids;
  size_t ellipsoids_too_large = 0; /**< not drawn: wider than the scene's horizontal extent */
  std::vector<double> gnss_r;                /**< 3 per GNSS fix: measured position in frame r [m] */
  std::vector<NavPolyline> outage_segments; /**< reference path inside each GNSS outage */
  NavVehicleKind vehicle = NavVehicleKind::Generic; /**< resolved vehicle glyph */
  double error_max_m = 0.0;                /**< colour range of the estimate [0, error_max_m] */
  double bounds_r[6] = {0, 0, 0, 0, 0, 0}; /**< xmin xmax ymin ymax zmin zmax of all paths [m] */
  double ground_z_r = 0.0;                 /**< z of the ground grid [m] */
  double grid_spacing_m = 1.0;
  double grid_r[4] = {0, 0, 0, 0}; /**< xmin xmax ymin ymax of the grid [m] */
  double triad_size_m = 1.0;
  double triad_interval_s = 1.0;
  double t_begin_s = 0.0, t_end_s = 0.0;
  double decimation_tol_m = 0.0;
  size_t full_points = 0; /**< epochs of all drawn paths before decimation */
};

/** Append the triads at time @p t: the reference attitude at the reference position to @p ref and,
 *  when the estimate has attitude, exp(k phi) C_b_n(truth) at the estimated position to @p est
 *  (phi = the attitude error as a rotation vector, k = @p k_att). The one triad computation of
 *  the scene (the model's triads every N s and the view's triad at the playback time). */
void NavAppendTriadsAt(const NavResult &result, double k_att, double t, NavTriadSet *ref, NavTriadSet *est);

/** Bounds {xmin xmax ymin ymax zmin zmax} in frame r of the reference, estimate and extra runs. */
void NavResultBoundsRender(const NavResult &result, double bounds_r[6]);

/** The "nice" grid spacing (1, 2 or 5 times a power of ten) giving at most about 12 cells
 *  across @p extent_m. */
double NavNiceGridSpacing(double extent_m);

/** Sample @p track at time @p t: position in frame r (linear interpolation) and, when the track
 *  has attitude, C_b_n as a row-major 3x3 (interpolated along the geodesic between epochs).
 *  @return false when the track is empty. */
bool NavTrackSample(const NavTrack &track, double t, double pos_r[3], double c_b_n[9]);

/**
 * Build the scene model of @p result.
 * @param[in]  result    the loaded result
 * @param[in]  options   view options (triads, envelope, colouring, exaggeration)
 * @param[in]  tol_m     decimation tolerance [m] (from the screen-space tolerance and the view);
 *                       negative: layout only (bounds, grid, triad size and interval, times),
 *                       no paths, tube or triads
 * @param[out] model     the scene
 * @param[out] error     message on failure (empty truth, no attitude...)
 * @return true on success.
 */
bool NavBuildSceneModel(const NavResult &result, const NavViewOptions &options, double tol_m,
                        NavSceneModel *model, std::string *error);

#endif /* NAV_VIEW_MODEL_H */
