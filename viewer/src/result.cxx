// Result-directory loader (nav_view_result.h): the CSV tables become SI containers; degrees are
// converted here, at the I/O edge, and nowhere else in the viewer.
#include "navview/nav_view_result.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <sys/stat.h>

namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

// Something is there: a regular file is read, anything else (a FIFO, a directory) is refused by
// the reader with a message instead of being skipped as absent.
bool FileExists(const std::string &path) {
  struct stat st;
  return stat(path.c_str(), &st) == 0;
}

std::string Join(const std::string &dir, const std::string &name) {
  if (dir.empty() || dir.back() == '/') return dir + name;
  return dir + "/" + name;
}

// Look up required columns; on a missing one report it against the header line.
bool RequireColumns(const NavCsvTable &t, const std::string &file, const std::vector<std::string> &names,
                    std::vector<int> *idx, std::string *error) {
  idx->clear();
  for (const std::string &n : names) {
    const int c = t.Column(n);
    if (c < 0) {
      *error = file + ":1: error: missing column '" + n + "'";
      return false;
    }
    idx->push_back(c);
  }
  return true;
}

bool CheckTimes(const NavCsvTable &t, int col, const std::string &file, std::string *error) {
  for (size_t r = 1; r < t.rows; ++r)
    if (t.At(r, col) < t.At(r - 1, col)) {
      std::ostringstream m;
      m.precision(17);
      m << file << ":" << t.line_of_row[r] << ": error: t_s goes backwards (" << t.At(r, col) << " after "
        << t.At(r - 1, col) << ")";
      *error = m.str();
      return false;
    }
  return true;
}

bool LoadTrack(const std::string &path, NavTrack *out, std::string *error) {
  NavCsvTable t;
  if (!NavCsvReadFile(path, &t, error)) return false;
  std::vector<int> c;
  if (!RequireColumns(t, path, {"t_s", "pos_n_m", "pos_e_m", "pos_d_m", "roll_deg", "pitch_deg", "yaw_deg"},
                      &c, error))
    return false;
  if (t.rows == 0) {
    *error = path + ":2: error: no data rows";
    return false;
  }
  if (!CheckTimes(t, c[0], path, error)) return false;
  NavTrack track;
  track.t_s.resize(t.rows);
  track.pos_ned_m.resize(3 * t.rows);
  track.euler_rad.resize(3 * t.rows);
  for (size_t r = 0; r < t.rows; ++r) {
    track.t_s[r] = t.At(r, c[0]);
    for (int k = 0; k < 3; ++k) {
      track.pos_ned_m[3 * r + static_cast<size_t>(k)] = t.At(r, c[1 + k]);
      track.euler_rad[3 * r + static_cast<size_t>(k)] = t.At(r, c[4 + k]) * kDegToRad;
    }
  }
  const int clat = t.Column("lat_deg"), clon = t.Column("lon_deg"), ch = t.Column("h_m");
  if (clat >= 0 && clon >= 0 && ch >= 0) {
    track.geo.resize(3 * t.rows);
    for (size_t r = 0; r < t.rows; ++r) {
      track.geo[3 * r] = t.At(r, clat) * kDegToRad;
      track.geo[3 * r + 1] = t.At(r, clon) * kDegToRad;
      track.geo[3 * r + 2] = t.At(r, ch);
    }
  }
  *out = std::move(track);
  return true;
}

bool LoadErrors(const std::string &path, NavErrorSeries *out, std::string *error) {
  NavCsvTable t;
  if (!NavCsvReadFile(path, &t, error)) return false;
  std::vector<int> c;
  if (!RequireColumns(t, path,
                      {"t_s", "pos_err_n_m", "pos_err_e_m", "pos_err_d_m", "pos_err_h_m", "pos_err_v_m",
                       "att_err_rad", "roll_err_deg", "pitch_err_deg", "yaw_err_deg"},
                      &c, error))
    return false;
  if (!CheckTimes(t, c[0], path, error)) return false;
  NavErrorSeries e;
  const size_t n = t.rows;
  e.t_s.resize(n);
  e.pos_err_ned_m.resize(3 * n);
  e.pos_err_h_m.resize(n);
  e.pos_err_v_m.resize(n);
  e.att_err_rad.resize(n);
  e.euler_err_rad.resize(3 * n);
  for (size_t r = 0; r < n; ++r) {
    e.t_s[r] = t.At(r, c[0]);
    for (int k = 0; k < 3; ++k) {
      e.pos_err_ned_m[3 * r + static_cast<size_t>(k)] = t.At(r, c[1 + k]);
      e.euler_err_rad[3 * r + static_cast<size_t>(k)] = t.At(r, c[7 + k]) * kDegToRad;
    }
    e.pos_err_h_m[r] = t.At(r, c[4]);
    e.pos_err_v_m[r] = t.At(r, c[5]);
    e.att_err_rad[r] = t.At(r, c[6]);
  }
  const int vel = t.Column("vel_err_mps");
  if (vel >= 0) {
    e.vel_err_mps.resize(n);
    for (size_t r = 0; r < n; ++r)
      e.vel_err_mps[r] = t.At(r, vel);
  }
  *out = std::move(e);
  return true;
}

bool LoadEnvelope(const std::string &path, NavEnvelope *out, std::string *error) {
  NavCsvTable t;
  if (!NavCsvReadFile(path, &t, error)) return false;
  std::vector<int> c;
  if (!RequireColumns(t, path, {"t_s", "pos_rms_n_m", "pos_rms_e_m", "pos_rms_d_m", "pos_h_rms_m"}, &c,
                      error))
    return false;
  if (!CheckTimes(t, c[0], path, error)) return false;
  const int att = t.Column("att_rms_rad");
  NavEnvelope e;
  const size_t n = t.rows;
  e.t_s.resize(n);
  e.pos_rms_ned_m.resize(3 * n);
  e.pos_h_rms_m.resize(n);
  if (att >= 0) e.att_rms_rad.resize(n);
  for (size_t r = 0; r < n; ++r) {
    e.t_s[r] = t.At(r, c[0]);
    for (int k = 0; k < 3; ++k)
      e.pos_rms_ned_m[3 * r + static_cast<size_t>(k)] = t.At(r, c[1 + k]);
    e.pos_h_rms_m[r] = t.At(r, c[4]);
    if (att >= 0) e.att_rms_rad[r] = t.At(r, att);
  }
  const int vel = t.Column("vel_rms_mps");
  if (vel >= 0) {
    e.vel_rms_mps.resize(n);
    for (size_t r = 0; r < n; ++r)
      e.vel_rms_mps[r] = t.At(r, vel);
  }
  const int sd = t.Column("pos_sd_reported_n_m");
  if (sd >= 0 && t.Column("pos_sd_reported_e_m") == sd + 1 && t.Column("pos_sd_reported_d_m") == sd + 2) {
    bool any = false;
    std::vector<double> v(3 * n);
    for (size_t r = 0; r < n; ++r)
      for (int k = 0; k < 3; ++k) {
        v[3 * r + static_cast<size_t>(k)] = t.At(r, sd + k);
        any = any || v[3 * r + static_cast<size_t>(k)] > 0.0;
      }
    if (any) e.pos_sd_reported_ned_m = std::move(v);
  }
  *out = std::move(e);
  return true;
}

bool LoadGnss(const std::string &path, const std::string &outages, NavGnss *out, std::string *error) {
  NavCsvTable t;
  if (!NavCsvReadFile(path, &t, error)) return false;
  std::vector<int> c;
  if (!RequireColumns(t, path,
                      {"t_s", "lat_deg", "lon_deg", "h_m", "pos_n_m", "pos_e_m", "pos_d_m", "pos_sd_n_m",
                       "pos_sd_e_m", "pos_sd_d_m"},
                      &c, error))
    return false;
  if (!CheckTimes(t, c[0], path, error)) return false;
  NavGnss g;
  const size_t n = t.rows;
  g.t_s.resize(n);
  g.pos_ned_m.resize(3 * n);
  g.geo.resize(3 * n);
  g.pos_sd_ned_m.resize(3 * n);
  for (size_t r = 0; r < n; ++r) {
    g.t_s[r] = t.At(r, c[0]);
    g.geo[3 * r] = t.At(r, c[1]) * kDegToRad;
    g.geo[3 * r + 1] = t.At(r, c[2]) * kDegToRad;
    g.geo[3 * r + 2] = t.At(r, c[3]);
    for (int k = 0; k < 3; ++k) {
      g.pos_ned_m[3 * r + static_cast<size_t>(k)] = t.At(r, c[4 + k]);
      g.pos_sd_ned_m[3 * r + static_cast<size_t>(k)] = t.At(r, c[7 + k]);
    }
  }
  if (FileExists(outages)) {
    NavCsvTable o;
    if (!NavCsvReadFile(outages, &o, error)) return false;
    if (!RequireColumns(o, outages, {"t0_s", "t1_s"}, &c, error)) return false;
    for (size_t r = 0; r < o.rows; ++r) {
      g.outage_t0_s.push_back(o.At(r, c[0]));
      g.outage_t1_s.push_back(o.At(r, c[1]));
    }
  }
  *out = std::move(g);
  return true;
}

bool LoadImuErrors(const std::string &path, NavImuErrors *out, std::string *error) {
  NavCsvTable t;
  if (!NavCsvReadFile(path, &t, error)) return false;
  std::vector<int> c;
  if (!RequireColumns(t, path,
                      {"t_s", "gyro_err_x_dps", "gyro_err_y_dps", "gyro_err_z_dps", "accel_err_x_mps2",
                       "accel_err_y_mps2", "accel_err_z_mps2"},
                      &c, error))
    return false;
  NavImuErrors e;
  const size_t n = t.rows;
  e.t_s.resize(n);
  e.gyro_rps.resize(3 * n);
  e.accel_mps2.resize(3 * n);
  for (size_t r = 0; r < n; ++r) {
    e.t_s[r] = t.At(r, c[0]);
    for (int k = 0; k < 3; ++k) {
      e.gyro_rps[3 * r + static_cast<size_t>(k)] = t.At(r, c[1 + k]) * kDegToRad;
      e.accel_mps2[3 * r + static_cast<size_t>(k)] = t.At(r, c[4 + k]);
    }
  }
  *out = std::move(e);
  return true;
}

// estimate.csv of navsim estimate: only the covariance columns; empty fields (flat Earth scenes)
// make the parse fail, which the caller records as a note.
bool LoadCovariance(const std::string &path, NavCovariance *out, std::string *error) {
  NavCsvTable t;
  if (!NavCsvReadFile(path, &t, error)) return false;
  std::vector<int> c;
  if (!RequireColumns(t, path, {"t_s", "cov_pos_n_sd_m", "cov_pos_e_sd_m", "cov_pos_d_sd_m", "cov_pos_h_sd_m"}, &c,
                      error))
    return false;
  NavCovariance v;
  for (size_t r = 0; r < t.rows; ++r) {
    v.t_s.push_back(t.At(r, c[0]));
    for (int k = 0; k < 3; ++k)
      v.pos_sd_ned_m.push_back(t.At(r, c[1 + k]));
    v.pos_h_sd_m.push_back(t.At(r, c[4]));
  }
  *out = std::move(v);
  return true;
}

double UnitToSi(const std::string &u) {
  if (u == "m" || u == "m/s" || u == "rad") return 1.0;
  if (u == "cm" || u == "cm/s") return 0.01;
  if (u == "km") return 1000.0;
  if (u == "deg") return kDegToRad;
  if (u == "arcmin") return kDegToRad / 60.0;
  if (u == "arcsec") return kDegToRad / 3600.0;
  if (u == "mrad") return 1e-3;
  return 1.0;
}

// summary.json is navsim's own, flat and machine-written: two fields are picked out by key
// rather than pulling in a JSON library for a title and a run count.
std::string JsonStringAfter(const std::string &text, const std::string &key) {
  const size_t k = text.find("\"" + key + "\"");
  if (k == std::string::npos) return {};
  size_t q = text.find(':', k);
  if (q == std::string::npos) return {};
  q = text.find('"', q);
  if (q == std::string::npos) return {};
  const size_t e = text.find('"', q + 1);
  if (e == std::string::npos) return {};
  return text.substr(q + 1, e - q - 1);
}

int JsonIntAfter(const std::string &text, const std::string &key, int fallback) {
  const size_t k = text.find("\"" + key + "\"");
  if (k == std::string::npos) return fallback;
  const size_t q = text.find(':', k);
  if (q == std::string::npos) return fallback;
  const long v = std::strtol(text.c_str() + q + 1, nullptr, 10);
  return v > 0 && v < 100000000 ? static_cast<int>(v) : fallback;
}

std::string JsonStringIn(const std::string &obj, const std::string &key) {
  return JsonStringAfter(obj, key);
}

double JsonNumberIn(const std::string &obj, const std::string &key) {
  const size_t k = obj.find("\"" + key + "\"");
  if (k == std::string::npos) return NAN;
  const size_t q = obj.find(':', k);
  if (q == std::string::npos) return NAN;
  char *end = nullptr;
  const double v = std::strtod(obj.c_str() + q + 1, &end);
  return end == obj.c_str() + q + 1 ? NAN : v;
}

// "requirements": [ {...}, ... ] of summary.json (the requirements contract); objects may nest.
std::vector<NavRequirementVerdict> ParseRequirements(const std::string &text) {
  std::vector<NavRequirementVerdict> out;
  const size_t k = text.find("\"requirements\"");
  if (k == std::string::npos) return out;
  size_t p = text.find('[', k);
  if (p == std::string::npos) return out;
  int depth = 0;
  size_t obj_begin = 0;
  bool in_str = false;
  for (size_t i = p + 1; i < text.size(); ++i) {
    const char ch = text[i];
    if (in_str) {
      if (ch == '\\') ++i;
      else if (ch == '"') in_str = false;
      continue;
    }
    if (ch == '"') in_str = true;
    else if (ch == '{' || ch == '[') {
      if (depth == 0 && ch == '{') obj_begin = i;
      ++depth;
    } else if (ch == '}' || ch == ']') {
      if (depth == 0) break; // end of the requirements array
      --depth;
      if (depth == 0 && ch == '}') {
        const std::string obj = text.substr(obj_begin, i - obj_begin + 1);
        NavRequirementVerdict v;
        v.id = JsonStringIn(obj, "id");
        v.metric = JsonStringIn(obj, "metric");
        v.statistic = JsonStringIn(obj, "statistic");
        v.unit = JsonStringIn(obj, "unit");
        v.limit = JsonNumberIn(obj, "limit");
        v.value = JsonNumberIn(obj, "value");
        v.limit_si = v.limit * UnitToSi(v.unit);
        const size_t ps = obj.find("\"pass\"");
        v.pass = ps != std::string::npos && obj.find("true", ps) != std::string::npos &&
                 obj.find("true", ps) < obj.find_first_of(",}", ps);
        out.push_back(v);
      }
    }
  }
  return out;
}

} // namespace

size_t NavTimeIndex(const std::vector<double> &t_s, double t) {
  if (t_s.empty() || t <= t_s.front()) return 0;
  auto it = std::upper_bound(t_s.begin(), t_s.end(), t);
  return static_cast<size_t>(it - t_s.begin()) - 1;
}

double NavInterpolate(const std::vector<double> &t_s, const std::vector<double> &v, int stride, int comp,
                      double t) {
  if (t_s.empty() || v.size() < t_s.size() * static_cast<size_t>(stride)) return NAN;
  const size_t s = static_cast<size_t>(stride), c = static_cast<size_t>(comp);
  const size_t i = NavTimeIndex(t_s, t);
  if (i + 1 >= t_s.size() || t <= t_s[i]) return v[i * s + c];
  const double dt = t_s[i + 1] - t_s[i];
  const double a = dt > 0.0 ? (t - t_s[i]) / dt : 0.0;
  return v[i * s + c] + a * (v[(i + 1) * s + c] - v[i * s + c]);
}

bool NavLoadResultDir(const std::string &dir, NavResult *out, std::string *error) {
  struct stat st;
  if (stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
    *error = dir + ": error: not a result directory (navsim run --out DIR writes one)";
    return false;
  }
  NavResult r;
  r.dir = dir;
  if (!LoadTrack(Join(dir, "truth.csv"), &r.truth, error)) return false;
  if (!LoadTrack(Join(dir, "nav.csv"), &r.nav, error)) return false;

  const std::string err_path = Join(dir, "errors.csv");
  if (FileExists(err_path)) {
    if (!LoadErrors(err_path, &r.errors, error)) return false;
  } else {
    r.notes.push_back(err_path + ": not found; no error envelope, colouring or charts of run 0");
  }
  const std::string env_path = Join(dir, "mc_stats.csv");
  if (FileExists(env_path)) {
    if (!LoadEnvelope(env_path, &r.envelope, error)) return false;
  }

  const std::string gnss_path = Join(dir, "gnss.csv");
  if (FileExists(gnss_path)) {
    if (!LoadGnss(gnss_path, Join(dir, "gnss_outages.csv"), &r.gnss, error)) return false;
  }
  const std::string imu_path = Join(dir, "imu_errors.csv");
  if (FileExists(imu_path)) {
    if (!LoadImuErrors(imu_path, &r.imu_errors, error)) return false;
  }
  // Covariance analysis: estimate.csv in the directory, else in DIR-estimate (navsim estimate's
  // default next to navsim run's). Optional: a failure is a note, not an error.
  {
    std::string d = dir;
    while (d.size() > 1 && d.back() == '/')
      d.pop_back();
    for (const std::string &cand : {Join(dir, "estimate.csv"), d + "-estimate/estimate.csv"}) {
      if (!FileExists(cand)) continue;
      std::string cerr;
      if (LoadCovariance(cand, &r.covariance, &cerr)) break;
      r.notes.push_back(cerr + " (covariance analysis not used)");
    }
  }

  const std::string sum_path = Join(dir, "summary.json");
  if (FileExists(sum_path)) {
    std::string text;
    if (!NavReadRegularFile(sum_path, size_t{16} << 20, &text, error)) return false;
    const size_t scene = text.find("\"scene\"");
    if (scene != std::string::npos) r.scene_name = JsonStringAfter(text.substr(scene), "name");
    r.runs = JsonIntAfter(text, "runs", 1);
    r.requirements = ParseRequirements(text);
    r.summary_json = text;
  } else {
    r.notes.push_back(sum_path + ": not found");
  }
  if (r.scene_name.empty()) {
    std::string d = dir;
    while (d.size() > 1 && d.back() == '/')
      d.pop_back();
    const size_t slash = d.find_last_of('/');
    r.scene_name = slash == std::string::npos ? d : d.substr(slash + 1);
  }
  *out = std::move(r);
  return true;
}
