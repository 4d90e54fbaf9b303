/**
 * @file nav_view_result.h
 * @brief Loading a navsim result directory (truth.csv, nav.csv, errors.csv, mc_stats.csv,
 *        summary.json) into plain C++ containers. No VTK types (style.md section 2).
 *
 * Units: the files carry degrees in their `_deg` columns (I/O edge); everything stored here is
 * SI (`_rad`, `_m`, `_s`). Positions are in the scene-fixed NED frame `l` (origin at the scene
 * origin), attitudes are ZYX Euler angles of C_b_n.
 *
 * Errors are reported as "FILE:LINE: error: MESSAGE" (LINE is 1-based; the header is line 1),
 * the same shape as `navsim check`. Nothing here throws or aborts on bad input.
 */
#ifndef NAV_VIEW_RESULT_H
#define NAV_VIEW_RESULT_H

#include <cstddef>
#include <string>
#include <vector>

/** A parsed numeric CSV table: one header line of column names, then rows of numbers. */
struct NavCsvTable {
  std::vector<std::string> columns; /**< column names, in file order */
  std::vector<double> values;       /**< row-major, rows * columns.size() values */
  std::vector<int> line_of_row;     /**< 1-based file line of each row (for messages) */
  size_t rows = 0;

  /** Index of column @p name, or -1 when absent. */
  int Column(const std::string &name) const;
  /** Value of row @p row, column @p col (no bounds check). */
  double At(size_t row, int col) const { return values[row * columns.size() + static_cast<size_t>(col)]; }
};

/**
 * Parse CSV text with a header line. Every data field must be a finite decimal number; blank
 * lines are ignored, CR-LF line ends are accepted.
 * @param[in]  text          the whole file content
 * @param[in]  display_name  file name used in error messages
 * @param[out] out           the table (left untouched on failure)
 * @param[out] error         "display_name:LINE: error: ..." on failure
 * @return true on success.
 */
bool NavCsvParse(const std::string &text, const std::string &display_name, NavCsvTable *out,
                 std::string *error);

/**
 * The largest result file navview reads (bytes): 256 MiB, about 850 000 rows of errors.csv as
 * navsim writes it (about 315 bytes a row; an hour at 200 Hz output is 720 000). Measured: a
 * result of 800 000 epochs (errors.csv 239 MB, truth.csv and nav.csv 198 MB each) renders
 * --view errors in 2.8 s at 553 MB peak resident memory. A larger file is refused at once with
 * its size and this limit, before anything is read, instead of an out-of-memory abort.
 */
constexpr size_t kNavCsvMaxFileBytes = size_t{256} << 20;

/**
 * Read a whole regular file into @p text. A FIFO, device or directory is refused at once (no
 * blocking open), as is a file larger than @p max_bytes.
 * @param[out] error  "PATH: error: ..." on failure
 * @return true on success.
 */
bool NavReadRegularFile(const std::string &path, size_t max_bytes, std::string *text, std::string *error);

/** Read and parse a CSV file (NavCsvParse on its content); I/O errors name the file; a FIFO,
 *  device, directory or a file over kNavCsvMaxFileBytes is refused with a message. */
bool NavCsvReadFile(const std::string &path, NavCsvTable *out, std::string *error);

/** A state history at the output rate (truth.csv or nav.csv), SI units. */
struct NavTrack {
  std::vector<double> t_s;       /**< epoch times [s], non-decreasing */
  std::vector<double> pos_ned_m; /**< 3 per epoch: north, east, down in frame l [m] */
  std::vector<double> euler_rad; /**< 3 per epoch: roll, pitch, yaw of C_b_n [rad]; may be empty */
  /** 3 per epoch: latitude [rad], longitude [rad], height [m] (lat_deg, lon_deg, h_m columns);
   *  may be empty (then the map view uses a local tangent plane). */
  std::vector<double> geo;
  size_t Size() const { return t_s.size(); }
  bool HasAttitude() const { return !euler_rad.empty(); }
  bool HasGeodetic() const { return !geo.empty(); }
};

/** gnss.csv and gnss_outages.csv (INS/GNSS results). Empty when absent. */
struct NavGnss {
  std::vector<double> t_s;          /**< fix times of validity [s] */
  std::vector<double> pos_ned_m;    /**< 3 per fix: measured antenna position in frame l [m] */
  std::vector<double> geo;          /**< 3 per fix: lat [rad], lon [rad], h [m] */
  std::vector<double> pos_sd_ned_m; /**< 3 per fix: reported 1-sigma N/E/D [m] */
  std::vector<double> outage_t0_s;  /**< outage intervals [t0, t1) [s] */
  std::vector<double> outage_t1_s;
  size_t Size() const { return t_s.size(); }
  /** Whether @p t lies inside an outage interval. */
  bool InOutage(double t) const {
    for (size_t i = 0; i < outage_t0_s.size(); ++i)
      if (t >= outage_t0_s[i] && t < outage_t1_s[i]) return true;
    return false;
  }
};

/** Predicted 1-sigma position errors of a covariance analysis (estimate.csv cov_* columns). */
struct NavCovariance {
  std::vector<double> t_s;
  std::vector<double> pos_sd_ned_m; /**< 3 per epoch [m] */
  std::vector<double> pos_h_sd_m;   /**< sqrt(sigma_N^2 + sigma_E^2) [m] */
  size_t Size() const { return t_s.size(); }
};

/** imu_errors.csv: simulated sensor errors of run 0 (SI: rad/s and m/s^2). */
struct NavImuErrors {
  std::vector<double> t_s;
  std::vector<double> gyro_rps;   /**< 3 per epoch [rad/s] */
  std::vector<double> accel_mps2; /**< 3 per epoch [m/s^2] */
  size_t Size() const { return t_s.size(); }
};

/** One requirement verdict of summary.json "requirements" (user units, as written). */
struct NavRequirementVerdict {
  std::string id, metric, statistic, unit;
  double limit = 0.0, value = 0.0;
  double limit_si = 0.0; /**< limit in SI (m, m/s, rad) for drawing on the charts */
  bool pass = false;
};

/** errors.csv of run 0 (navigation minus reference), SI units. Empty when absent. */
struct NavErrorSeries {
  std::vector<double> t_s;
  std::vector<double> pos_err_ned_m; /**< 3 per epoch [m] */
  std::vector<double> pos_err_h_m;   /**< horizontal error magnitude [m] */
  std::vector<double> pos_err_v_m;   /**< vertical error magnitude [m] */
  std::vector<double> att_err_rad;   /**< attitude error angle [rad] */
  std::vector<double> euler_err_rad; /**< 3 per epoch: roll, pitch, yaw error [rad] */
  /** |velocity error| [m/s]; empty when errors.csv has no vel_err_mps column */
  std::vector<double> vel_err_mps;
  size_t Size() const { return t_s.size(); }
};

/** mc_stats.csv: per-epoch statistics over the Monte Carlo runs, SI units. Empty when absent. */
struct NavEnvelope {
  std::vector<double> t_s;
  std::vector<double> pos_rms_ned_m; /**< 3 per epoch: RMS over runs of the N, E, D errors [m] */
  std::vector<double> pos_h_rms_m;   /**< RMS over runs of the horizontal error [m] */
  std::vector<double> att_rms_rad;   /**< RMS over runs of the attitude error [rad]; may be empty */
  std::vector<double> vel_rms_mps;   /**< RMS over runs of |velocity error| [m/s]; may be empty */
  /** 3 per epoch: mean over runs of the filter's reported position sigma N/E/D [m]; empty when
   *  the column is absent or all zero (free INS). */
  std::vector<double> pos_sd_reported_ned_m;
  size_t Size() const { return t_s.size(); }
};

/** Everything the viewer shows of one result. */
struct NavResult {
  std::string dir;        /**< the result directory (empty for in-memory results) */
  std::string scene_name; /**< from summary.json, else the directory name */
  int runs = 1;           /**< Monte Carlo runs (summary.json) */
  NavTrack truth;         /**< reference (truth.csv) */
  NavTrack nav;           /**< estimate of run 0 (nav.csv) */
  /** Further estimated paths (e.g. a handful of Monte Carlo runs), positions only; in-memory
   *  results may fill it, navsim result directories do not carry them yet. */
  std::vector<NavTrack> extra_runs;
  NavErrorSeries errors;          /**< errors.csv (run 0) */
  NavEnvelope envelope;           /**< mc_stats.csv */
  NavGnss gnss;                   /**< gnss.csv, gnss_outages.csv */
  NavCovariance covariance;       /**< estimate.csv in DIR or in DIR-estimate (navsim estimate) */
  NavImuErrors imu_errors;        /**< imu_errors.csv */
  std::vector<NavRequirementVerdict> requirements; /**< summary.json "requirements" */
  std::string summary_json;       /**< the text of summary.json (empty when absent) */
  std::vector<std::string> notes; /**< non-fatal remarks (missing optional files) */
};

/**
 * Load a result directory written by `navsim run`.
 * truth.csv and nav.csv are required (t_s, pos_n_m, pos_e_m, pos_d_m, roll_deg, pitch_deg,
 * yaw_deg); errors.csv, mc_stats.csv and summary.json are optional (a note is recorded).
 * @param[in]  dir    the directory
 * @param[out] out    the result (left untouched on failure)
 * @param[out] error  "FILE:LINE: error: ..." or "DIR: error: ..." on failure
 * @return true on success.
 */
bool NavLoadResultDir(const std::string &dir, NavResult *out, std::string *error);

/**
 * Index of the last epoch with t_s[i] <= t (0 when t precedes the first epoch, Size()-1 when it
 * follows the last), by binary search. @p t_s must be non-empty and non-decreasing.
 */
size_t NavTimeIndex(const std::vector<double> &t_s, double t);

/** Linear interpolation of a per-epoch series (@p stride values per epoch, component @p comp)
 *  at time @p t, clamped to the ends. Returns NaN for an empty series. */
double NavInterpolate(const std::vector<double> &t_s, const std::vector<double> &v, int stride, int comp,
                      double t);

#endif /* NAV_VIEW_RESULT_H */
