// navview: render a navsim result directory (3D view and error charts) headless to PNG, or open
// it interactively. A thin front end over libnavview.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>
#include <stdexcept>
#include <random>
#include <string>

#include "navcore/nav_version.h"
#include "navview/navview.h"
#include "navview/nav_map_tiles.h"

namespace {

void Usage(FILE *f) {
  std::fprintf(f,
               "usage: navview RESULT_DIR [--view 3d|top|map|errors|noise] [--png FILE] [--chart FILE]\n"
               "               [--size WxH] [--time T]\n"
               "               [--exaggerate K] [options]\n"
               "       navview --bench [--bench-epochs N] [--bench-paths M] [--size WxH]\n"
               "       navview --speed-vs-error bench.csv --png out.png\n"
               "       navview --allan allan.csv --png out.png\n"
               "       navview --tradeoff tradeoff.csv [--requirement ID] --png out.png\n"
               "       navview --sky RESULT_DIR --png out.png    (or --dop RESULT_DIR)\n"
               "\n"
               "Show the result directory written by `navsim run`: reference and estimated paths,\n"
               "attitude triads, the error-envelope tube, ground grid with scale, NED axes and legend.\n"
               "With --png and/or --chart it renders headless and exits; with neither it opens an\n"
               "interactive window (needs a display): the 3D view, or with --view map the geodetic map\n"
               "(drag = pan, wheel or +/- = zoom, r = reset, q = quit). Rendering always needs an X\n"
               "server: run headless jobs under xvfb-run -a.\n"
               "\n"
               "options:\n"
               "  --png FILE          write the view chosen by --view as PNG (default the 3D view)\n"
               "  --view NAME         3d | oblique | top (3D view), map (geodetic map), errors (error\n"
               "                      charts), noise (simulated sensor errors, imu_errors.csv)\n"
               "  --map               same as --view map\n"
               "  --map-span KM       map width [km] (default: fit the tracks); e.g. 4000 continent, 0.5 street\n"
               "  --map-center LAT,LON  map centre [deg] (default: the tracks' centre)\n"
               "  --tiles SRC         map tile layer (streets at street scale) over the land/water fill:\n"
               "                      FILE.mbtiles, a DIR of {z}/{x}/{y}.png tiles, a template\n"
               "                      DIR/{z}/{x}/{y}.png, or http(s)://HOST/{z}/{x}/{y}.png (fetched, cached\n"
               "                      in $NAVVIEW_TILE_CACHE or ~/.cache/navsim/tiles); zoom chosen by scale\n"
               "  --tiles-attribution TEXT  credit shown for the tiles (default: the MBTiles attribution)\n"
               "  --movie DIR         playback movie: DIR/frame_NNNN.png over the run (fixed camera) and\n"
               "                      DIR/playback.ogv (Ogg Theora); --movie-frames N (120), --movie-fps F\n"
               "                      (24), --movie-no-video (PNG frames only)\n"
               "  --movie FILE.mp4|FILE.webm  playback movie as one video: H.264 MP4 or VP9 WebM (ffmpeg),\n"
               "                      --duration-s S (10) long, --movie-fps F (30), --size WxH (even), the\n"
               "                      time read-out in every frame; --follow for the follow camera\n"
               "  --follow            follow camera: behind and above the vehicle (--follow-distance M,\n"
               "                      default automatic, 60 m for a drive of a few km)\n"
               "  --allan ALLAN_CSV   Allan deviation chart of navsim allan's allan.csv (with --png; no DIR)\n"
               "  --speed-vs-error BENCH_CSV  speed against error of navsim bench's bench.csv, one labelled panel\n"
               "                      per case (with --png; default size 1500x1200)\n"
               "  --tradeoff TRADEOFF_CSV  CPU time against requirement error of navsim tradeoff's tradeoff.csv,\n"
               "                      one panel per requirement (--requirement ID: that one only), labelled\n"
               "                      points, intervals, tolerance band and Pareto front (with --png)\n"
               "  --sky RESULT_DIR    sky plot of the satellites of run 0 (gnss_sats.csv, gnss_mask.csv of a\n"
               "                      scene with gnss.constellation): tracks, GPS / GLONASS, masks (with --png)\n"
               "  --dop RESULT_DIR    GDOP/PDOP/HDOP/VDOP and satellites in view over time (gnss_dop.csv),\n"
               "                      canyon spans and receiver outages (with --png)\n"
               "  --chart FILE        write the error-vs-time charts as PNG\n"
               "  --size WxH          image/window size in pixels (default 1000x700; charts 900x800)\n"
               "  --time T            playback time of the vehicle glyph and read-out [s] (default: end)\n"
               "  --exaggerate K      attitude-error exaggeration of the estimated triads (default 20)\n"
               "  --envelope-k K      tube radius = K x sigma_h (default 3)\n"
               "  --envelope SRC      auto | run | mc | filter | cov | none: tube and ellipsoid sigma from\n"
               "                      run-0 errors, Monte Carlo RMS, the filter's reported sigma (mc_stats),\n"
               "                      or the covariance analysis (estimate.csv in DIR or DIR-estimate);\n"
               "                      default auto: mc, else cov, else run\n"
               "  --ellipsoids N      covariance ellipsoids at N epochs spread over the run (default 6)\n"
               "  --ellipsoid-times T1,T2,...  ellipsoid epochs [s] instead\n"
               "  --vehicle KIND      auto | car | aircraft | generic (default auto: from the scene name)\n"
               "  --no-gnss           hide GNSS fixes and outage highlighting (gnss.csv)\n"
               "  --triad-interval S  seconds between triads (default: about 24 along the run)\n"
               "  --triad-size M      triad arrow length [m] (default: from the scene extent)\n"
               "  --color-by-error    colour the estimated path by horizontal error (with a scalar bar)\n"

               "  --no-text           no labels, legend or read-out\n"
               "  --msaa N            multisample anti-aliasing samples, 0 = off (default: 8 for PNG,\n"
               "                      0 for the interactive window and --bench)\n"
               "  --decimate-px PX    screen-space decimation tolerance in pixels (default 0.5)\n"
               "  --bench [FRAMES]    measure frames per second of the default view (offscreen); without\n"
               "                      RESULT_DIR on a synthetic one-hour, 200 Hz case with 20 paths\n"
               "  --bench-epochs N    epochs of the synthetic case (default 720000)\n"
               "  --bench-paths M     estimated paths of the synthetic case (default 20)\n"
               "  --version, -h/--help\n"
               "\n"
               "interactive keys: space play/pause, f camera follow, c colour by error, +/- exaggeration,\n"
               "p pick the path under the mouse, r reset camera, q quit; drag the time slider.\n"
               "\n"
               "exit codes: 0 success; 2 invalid command line; 1 other failure (input, display, output)\n");
}

bool ParseDouble(const char *s, double *out) {
  char *end = nullptr;
  const double v = std::strtod(s, &end);
  if (end == s || *end != '\0' || !std::isfinite(v)) return false;
  *out = v;
  return true;
}

bool ParseSize(const char *s, int *w, int *h) {
  int a = 0, b = 0;
  char x = 0, extra = 0;
  if (std::sscanf(s, "%d%c%d%c", &a, &x, &b, &extra) != 3 || (x != 'x' && x != 'X')) return false;
  if (a < 16 || b < 16 || a > 8192 || b > 8192) return false;
  *w = a;
  *h = b;
  return true;
}

// Synthetic one-hour drive for the benchmark: a smooth wandering loop of about 50 km, run 0 with
// a random-walk position error and attitude error, and further runs with their own random walks.
std::shared_ptr<NavResult> SyntheticResult(size_t epochs, int paths) {
  auto r = std::make_shared<NavResult>();
  r->scene_name = "synthetic bench";
  r->runs = paths;
  const double dt = 1.0 / 200.0, pi = 3.14159265358979323846;
  auto truth_at = [&](double t, double ned[3], double *yaw) {
    const double w1 = 2 * pi / 3600.0, w2 = 2 * pi / 300.0, w3 = 2 * pi / 1800.0;
    ned[0] = 6000.0 * std::sin(w1 * t) + 700.0 * std::sin(w2 * t);
    ned[1] = 4000.0 * std::sin(w3 * t) + 700.0 * std::cos(w2 * t);
    ned[2] = -20.0 * std::sin(w3 * t);
    const double vn = 6000.0 * w1 * std::cos(w1 * t) + 700.0 * w2 * std::cos(w2 * t);
    const double ve = 4000.0 * w3 * std::cos(w3 * t) - 700.0 * w2 * std::sin(w2 * t);
    *yaw = std::atan2(ve, vn);
  };
  std::mt19937_64 rng(42);
  std::normal_distribution<double> g(0.0, 1.0);
  NavTrack &tr = r->truth;
  NavTrack &nv = r->nav;
  tr.t_s.resize(epochs);
  tr.pos_ned_m.resize(3 * epochs);
  tr.euler_rad.resize(3 * epochs);
  nv = tr;
  NavErrorSeries &er = r->errors;
  er.t_s.resize(epochs);
  er.pos_err_ned_m.resize(3 * epochs);
  er.pos_err_h_m.resize(epochs);
  er.pos_err_v_m.resize(epochs);
  er.att_err_rad.resize(epochs);
  er.euler_err_rad.resize(3 * epochs);
  NavEnvelope &en = r->envelope;
  en.t_s.resize(epochs);
  en.pos_rms_ned_m.resize(3 * epochs);
  en.pos_h_rms_m.resize(epochs);
  en.att_rms_rad.resize(epochs);
  double walk[3] = {0, 0, 0}, att[3] = {0, 0, 0};
  for (size_t i = 0; i < epochs; ++i) {
    const double t = static_cast<double>(i) * dt;
    double ned[3], yaw;
    truth_at(t, ned, &yaw);
    tr.t_s[i] = nv.t_s[i] = er.t_s[i] = en.t_s[i] = t;
    for (int k = 0; k < 3; ++k) {
      walk[k] += 0.02 * g(rng);
      att[k] += 2e-6 * g(rng);
      tr.pos_ned_m[3 * i + k] = ned[k];
      nv.pos_ned_m[3 * i + k] = ned[k] + walk[k];
      er.pos_err_ned_m[3 * i + k] = walk[k];
      er.euler_err_rad[3 * i + k] = att[k];
    }
    tr.euler_rad[3 * i + 2] = yaw;
    for (int k = 0; k < 3; ++k)
      nv.euler_rad[3 * i + k] = tr.euler_rad[3 * i + k] + att[k];
    er.pos_err_h_m[i] = std::hypot(walk[0], walk[1]);
    er.pos_err_v_m[i] = std::fabs(walk[2]);
    er.att_err_rad[i] = std::sqrt(att[0] * att[0] + att[1] * att[1] + att[2] * att[2]);
    // RMS of a random walk with 0.02 m steps: 0.02 sqrt(i) per axis.
    const double s = 0.02 * std::sqrt(static_cast<double>(i));
    for (int k = 0; k < 3; ++k)
      en.pos_rms_ned_m[3 * i + k] = s;
    en.pos_h_rms_m[i] = s * std::sqrt(2.0);
    en.att_rms_rad[i] = 2e-6 * std::sqrt(3.0 * static_cast<double>(i));
  }
  for (int p = 1; p < paths; ++p) {
    NavTrack run;
    run.t_s = tr.t_s;
    run.pos_ned_m.resize(3 * epochs);
    double w[3] = {0, 0, 0};
    for (size_t i = 0; i < epochs; ++i)
      for (int k = 0; k < 3; ++k) {
        w[k] += 0.02 * g(rng);
        run.pos_ned_m[3 * i + k] = tr.pos_ned_m[3 * i + k] + w[k];
      }
    r->extra_runs.push_back(std::move(run));
  }
  return r;
}

} // namespace

static int NavviewMain(int argc, char **argv) {
  std::string dir, png, chart, view_kind = "3d", allan_csv, bench_csv, tradeoff_csv, tradeoff_req;
  std::string sky_dir, dop_dir;
  NavViewOptions opt;
  NavChartOptions copt;
  NavMapOptions mopt;
  bool size_given = false, bench = false, msaa_given = false;
  int bench_frames = 60, bench_paths = 20, movie_frames = 120;
  std::string movie_dir;
  double movie_fps = 24.0;
  bool movie_video = true, movie_fps_given = false;
  std::string movie_file;
  NavMovieOptions movie_opt;
  long bench_epochs = 720000;

  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto need = [&](const char *what) -> const char * {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "navview: %s needs %s\n", a.c_str(), what);
        std::exit(2);
      }
      return argv[++i];
    };
    auto bad = [&](const char *v) {
      std::fprintf(stderr, "navview: invalid value '%s' for %s\n", v, a.c_str());
      std::exit(2);
    };
    double v = 0.0;
    if (a == "-h" || a == "--help") {
      Usage(stdout);
      return 0;
    } else if (a == "--version") {
      std::printf("navview %d.%d.%d\n", NAV_VERSION_MAJOR, NAV_VERSION_MINOR, NAV_VERSION_PATCH);
      return 0;
    } else if (a == "--png") {
      png = need("a FILE");
    } else if (a == "--chart") {
      chart = need("a FILE");
    } else if (a == "--size") {
      const char *s = need("WxH");
      if (!ParseSize(s, &opt.width_px, &opt.height_px)) bad(s);
      copt.width_px = opt.width_px;
      copt.height_px = opt.height_px;
      size_given = true;
    } else if (a == "--time") {
      const char *s = need("T [s]");
      if (!ParseDouble(s, &opt.time_s)) bad(s);
    } else if (a == "--exaggerate") {
      const char *s = need("K");
      if (!ParseDouble(s, &v) || v < 0.0 || v > 1e6) bad(s);
      opt.att_exaggeration = v;
    } else if (a == "--envelope-k") {
      const char *s = need("K");
      if (!ParseDouble(s, &v) || v < 0.0 || v > 1e6) bad(s);
      opt.envelope_k = v;
      copt.band_k = v > 0.0 ? v : copt.band_k;
    } else if (a == "--envelope") {
      const std::string s = need("auto|run|mc|none");
      if (s == "auto")
        opt.envelope_source = NavEnvelopeSource::Auto;
      else if (s == "run")
        opt.envelope_source = NavEnvelopeSource::RunErrors;
      else if (s == "mc")
        opt.envelope_source = NavEnvelopeSource::MonteCarlo;
      else if (s == "filter")
        opt.envelope_source = NavEnvelopeSource::Filter;
      else if (s == "cov" || s == "covariance")
        opt.envelope_source = NavEnvelopeSource::Covariance;
      else if (s == "none")
        opt.envelope_source = NavEnvelopeSource::None;
      else
        bad(s.c_str());
    } else if (a == "--triad-interval") {
      const char *s = need("S [s]");
      if (!ParseDouble(s, &v) || v <= 0.0) bad(s);
      opt.triad_interval_s = v;
    } else if (a == "--triad-size") {
      const char *s = need("M [m]");
      if (!ParseDouble(s, &v) || v <= 0.0) bad(s);
      opt.triad_size_m = v;
    } else if (a == "--ellipsoids") {
      const char *s = need("N");
      if (!ParseDouble(s, &v) || v < 0 || v > 1000) bad(s);
      opt.ellipsoid_count = static_cast<int>(v);
    } else if (a == "--ellipsoid-times") {
      const std::string s = need("T1,T2,...");
      opt.ellipsoid_times_s.clear();
      size_t p = 0;
      while (p <= s.size()) {
        const size_t c = s.find(',', p);
        const std::string tok = s.substr(p, c == std::string::npos ? std::string::npos : c - p);
        if (!ParseDouble(tok.c_str(), &v)) bad(s.c_str());
        opt.ellipsoid_times_s.push_back(v);
        if (c == std::string::npos) break;
        p = c + 1;
      }
    } else if (a == "--vehicle") {
      const std::string s = need("auto|car|aircraft|generic");
      if (s == "auto")
        opt.vehicle = NavVehicleKind::Auto;
      else if (s == "car")
        opt.vehicle = NavVehicleKind::Car;
      else if (s == "aircraft")
        opt.vehicle = NavVehicleKind::Aircraft;
      else if (s == "generic")
        opt.vehicle = NavVehicleKind::Generic;
      else
        bad(s.c_str());
    } else if (a == "--no-gnss") {
      opt.show_gnss = false;
    } else if (a == "--color-by-error") {
      opt.color_by_error = true;
    } else if (a == "--view") {
      const std::string s = need("3d|oblique|top|map|errors|noise");
      if (s == "oblique" || s == "3d") {
        opt.camera = NavCameraPreset::Oblique;
        view_kind = "3d";
      } else if (s == "top") {
        opt.camera = NavCameraPreset::Top;
        view_kind = "3d";
      } else if (s == "map" || s == "errors" || s == "noise") {
        view_kind = s;
      } else {
        bad(s.c_str());
      }
    } else if (a == "--map") {
      view_kind = "map";
    } else if (a == "--map-span") {
      const char *s = need("KM");
      if (!ParseDouble(s, &v) || v <= 0.0 || v > 50000.0) bad(s);
      mopt.span_km = v;
    } else if (a == "--map-center") {
      const std::string s = need("LAT,LON [deg]");
      const size_t c = s.find(',');
      double la = 0, lo = 0;
      if (c == std::string::npos || !ParseDouble(s.substr(0, c).c_str(), &la) ||
          !ParseDouble(s.substr(c + 1).c_str(), &lo) || std::fabs(la) > 90 || std::fabs(lo) > 360)
        bad(s.c_str());
      mopt.center_lat_deg = la;
      mopt.center_lon_deg = lo;
    } else if (a == "--tiles") {
      mopt.tiles = need("an MBTiles FILE, a tile DIR or template DIR/{z}/{x}/{y}.png, or a URL template");
      if (mopt.tiles.empty()) bad("");
    } else if (a == "--tiles-attribution") {
      mopt.tiles_attribution = need("TEXT");
    } else if (a == "--movie") {
      const std::string m = need("DIR|FILE.mp4|FILE.webm");
      const bool video_file = (m.size() > 4 && m.compare(m.size() - 4, 4, ".mp4") == 0) ||
                              (m.size() > 5 && m.compare(m.size() - 5, 5, ".webm") == 0);
      (video_file ? movie_file : movie_dir) = m;
    } else if (a == "--duration-s") {
      const char *s = need("S");
      if (!ParseDouble(s, &v) || !(v > 0) || v > 3600) bad(s);
      movie_opt.duration_s = v;
    } else if (a == "--follow") {
      opt.follow = true;
    } else if (a == "--follow-distance") {
      const char *s = need("M");
      if (!ParseDouble(s, &v) || !(v > 0) || v > 1e7) bad(s);
      opt.follow_distance_m = v;
    } else if (a == "--movie-frames") {
      const char *s = need("N");
      if (!ParseDouble(s, &v) || v < 1 || v > 100000) bad(s);
      movie_frames = static_cast<int>(v);
    } else if (a == "--movie-fps") {
      const char *s = need("F");
      if (!ParseDouble(s, &v) || v <= 0 || v > 240) bad(s);
      movie_fps = v;
      movie_fps_given = true;
    } else if (a == "--movie-no-video") {
      movie_video = false;
    } else if (a == "--allan") {
      allan_csv = need("ALLAN_CSV");
    } else if (a == "--speed-vs-error") {
      bench_csv = need("BENCH_CSV");
    } else if (a == "--sky") {
      sky_dir = need("RESULT_DIR");
    } else if (a == "--dop") {
      dop_dir = need("RESULT_DIR");
    } else if (a == "--tradeoff") {
      tradeoff_csv = need("TRADEOFF_CSV");
    } else if (a == "--requirement") {
      tradeoff_req = need("ID");
    } else if (a == "--msaa") {
      const char *s = need("N");
      if (!ParseDouble(s, &v) || v < 0 || v > 16) bad(s);
      opt.multisamples = static_cast<int>(v);
      msaa_given = true;
    } else if (a == "--decimate-px") {
      const char *s = need("PX");
      if (!ParseDouble(s, &v) || v < 0.0 || v > 100.0) bad(s);
      opt.decimate_px = v;
    } else if (a == "--no-text") {
      opt.show_text = false;
      copt.show_text = false;
    } else if (a == "--bench") {
      bench = true;
      if (i + 1 < argc && argv[i + 1][0] != '-' && ParseDouble(argv[i + 1], &v)) {
        if (v < 1 || v > 100000) bad(argv[i + 1]);
        bench_frames = static_cast<int>(v);
        ++i;
      }
    } else if (a == "--bench-epochs") {
      const char *s = need("N");
      if (!ParseDouble(s, &v) || v < 2 || v > 1e8) bad(s);
      bench_epochs = static_cast<long>(v);
    } else if (a == "--bench-paths") {
      const char *s = need("M");
      if (!ParseDouble(s, &v) || v < 1 || v > 1000) bad(s);
      bench_paths = static_cast<int>(v);
    } else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "navview: unknown option '%s' (see navview --help)\n", a.c_str());
      return 2;
    } else if (dir.empty()) {
      dir = a;
    } else {
      std::fprintf(stderr, "navview: more than one RESULT_DIR ('%s', '%s')\n", dir.c_str(), a.c_str());
      return 2;
    }
  }
  if (!size_given) {
    copt.width_px = 900;
    copt.height_px = 800;
  }
  mopt.width_px = opt.width_px;
  mopt.height_px = opt.height_px;
  mopt.show_text = opt.show_text;
  mopt.show_gnss = opt.show_gnss;
  mopt.multisamples = opt.multisamples;
  // The tile source is checked before anything is drawn: a file that is not an MBTiles database,
  // a missing directory or a template without {z}/{x}/{y} is a bad option (exit 2).
  if (!mopt.tiles.empty()) {
    std::shared_ptr<NavTileSource> tiles;
    std::string terr;
    if (!NavTileSourceOpen(mopt.tiles, &tiles, &terr)) {
      std::fprintf(stderr, "navview: %s\n", terr.c_str());
      return 2;
    }
  } else if (!mopt.tiles_attribution.empty()) {
    std::fprintf(stderr, "navview: --tiles-attribution applies to --tiles only\n");
    return 2;
  }
  // Chart-only modes: no result directory.
  if (!tradeoff_req.empty() && tradeoff_csv.empty()) {
    std::fprintf(stderr, "navview: --requirement applies to --tradeoff only\n");
    return 2;
  }
  if (!tradeoff_csv.empty()) {
    if (png.empty()) {
      std::fprintf(stderr, "navview: --tradeoff needs --png FILE\n");
      return 2;
    }
    if (!size_given) {
      copt.width_px = 1000;
      copt.height_px = tradeoff_req.empty() ? 1100 : 700; // several panels without --requirement
    }
    std::string e2;
    if (!NavRenderTradeoffPng(tradeoff_csv, tradeoff_req, copt, png, &e2)) {
      std::fprintf(stderr, "navview: %s\n", e2.c_str());
      return 1;
    }
    return 0;
  }
  if (!sky_dir.empty() || !dop_dir.empty()) {
    if (png.empty()) {
      std::fprintf(stderr, "navview: --sky / --dop need --png FILE\n");
      return 2;
    }
    if (!size_given) {
      copt.width_px = sky_dir.empty() ? 1000 : 900;
      copt.height_px = sky_dir.empty() ? 700 : 800;
    }
    std::string e2;
    const bool ok = sky_dir.empty() ? NavRenderDopChartPng(dop_dir, copt, png, &e2)
                                    : NavRenderSkyPlotPng(sky_dir, copt, png, &e2);
    if (!ok) {
      std::fprintf(stderr, "navview: %s\n", e2.c_str());
      return 1;
    }
    return 0;
  }
  if (!allan_csv.empty() || !bench_csv.empty()) {
    if (png.empty()) {
      std::fprintf(stderr, "navview: --allan / --speed-vs-error need --png FILE\n");
      return 2;
    }
    if (!size_given) {
      // The speed-against-error chart is a grid of one panel per bench case.
      copt.width_px = allan_csv.empty() ? 1500 : 900;
      copt.height_px = allan_csv.empty() ? 1200 : 800;
    }
    std::string e2;
    const bool ok = allan_csv.empty() ? NavRenderSpeedVsErrorPng(bench_csv, copt, png, &e2)
                                      : NavRenderAllanChartPng(allan_csv, copt, png, &e2);
    if (!ok) {
      std::fprintf(stderr, "navview: %s\n", e2.c_str());
      return 1;
    }
    return 0;
  }
  if (dir.empty() && !bench) {
    Usage(stderr);
    return 2;
  }

  // Multisampling costs about a factor three in frame rate on llvmpipe: PNGs get 8 samples,
  // the interactive window and the benchmark none unless --msaa says otherwise.
  if (!msaa_given && (bench || (png.empty() && chart.empty() && movie_dir.empty() && movie_file.empty())))
    opt.multisamples = 0;
  // A 1920x1080 movie frame cost about 250 ms CPU on llvmpipe with 4x multisampling or with
  // FXAA, about 80 ms without: movies have none unless --msaa N is given.
  if (!msaa_given && !movie_file.empty()) opt.multisamples = 0;
  if (!movie_file.empty() && !size_given) {
    opt.width_px = 1920;
    opt.height_px = 1080;
  }
  movie_opt.fps = movie_fps_given ? movie_fps : 30.0;

  std::string err;
  std::shared_ptr<NavResult> result;
  if (!dir.empty()) {
    result = std::make_shared<NavResult>();
    if (!NavLoadResultDir(dir, result.get(), &err)) {
      std::fprintf(stderr, "navview: %s\n", err.c_str());
      return 1;
    }
    for (const std::string &n : result->notes)
      std::fprintf(stderr, "navview: note: %s\n", n.c_str());
  } else {
    std::printf("navview: synthesising %ld epochs x %d paths...\n", bench_epochs, bench_paths);
    std::fflush(stdout);
    result = SyntheticResult(static_cast<size_t>(bench_epochs), bench_paths);
  }

  NavSceneView view;
  view.SetResult(result);
  view.SetOptions(opt);
  if (bench) {
    NavBenchResult b;
    if (!view.Benchmark(bench_frames, &b, &err)) {
      std::fprintf(stderr, "navview: %s\n", err.c_str());
      return 1;
    }
    std::printf("navview bench: %dx%d, %zu epochs in %zu paths -> %zu drawn vertices (tolerance %.3g m)\n",
                opt.width_px, opt.height_px, b.full_points, 2 + result->extra_runs.size(), b.drawn_points,
                b.tol_m);
    std::printf(
        "navview bench: build + first frame %.2f s, %.1f frames/s over %d frames (%.1f ms CPU per frame, "
        "all threads)\n",
        b.build_s, b.fps, b.frames, 1e3 * b.cpu_s_per_frame);
    // One machine-readable line (navsim bench and scripts parse it): key=value, space-separated.
    std::printf("navview_bench fps=%.3f frames=%d build_s=%.3f cpu_ms_per_frame=%.3f epochs=%zu paths=%zu "
                "drawn_vertices=%zu tol_m=%.4g width=%d height=%d msaa=%d\n",
                b.fps, b.frames, b.build_s, 1e3 * b.cpu_s_per_frame,
                result->truth.Size(), 1 + result->extra_runs.size(), b.drawn_points, b.tol_m, opt.width_px,
                opt.height_px, opt.multisamples);
    if (png.empty() && chart.empty()) return 0;
  }
  int rc = 0;
  if (!png.empty() && view_kind != "3d") {
    bool ok = false;
    if (view_kind == "map") {
      NavMapInfo minfo;
      ok = NavRenderMapPng(*result, mopt, png, &err, &minfo);
      // The tile layer's notes (offline, unreadable tiles, not at this scale) also go to
      // stderr: they are on the map, but a script should see them too.
      if (ok && !mopt.tiles.empty())
        for (const std::string &n : minfo.notes)
          if (n.rfind("map tiles", 0) == 0 || n.rfind("tiles:", 0) == 0 || n.rfind(mopt.tiles + ":", 0) == 0)
            std::fprintf(stderr, "navview: warning: %s\n", n.c_str());
    } else if (view_kind == "errors")
      ok = NavRenderErrorChartPng(*result, copt, png, &err);
    else
      ok = NavRenderSensorErrorChartPng(*result, copt, png, &err);
    if (!ok) {
      std::fprintf(stderr, "navview: %s\n", err.c_str());
      rc = 1;
    }
  } else if (!png.empty()) {
    if (!view.RenderPng(png, &err)) {
      std::fprintf(stderr, "navview: %s\n", err.c_str());
      rc = 1;
    }
  }
  if (!chart.empty()) {
    if (!NavRenderErrorChartPng(*result, copt, chart, &err)) {
      std::fprintf(stderr, "navview: %s\n", err.c_str());
      rc = 1;
    }
  }
  if (!movie_dir.empty()) {
    if (!view.RenderMovie(movie_dir, movie_frames, movie_fps, movie_video, &err)) {
      std::fprintf(stderr, "navview: %s\n", err.c_str());
      rc = 1;
    }
  }
  if (!movie_file.empty()) {
    if (!view.RenderMovieFile(movie_file, movie_opt, {}, &err)) {
      std::fprintf(stderr, "navview: %s\n", err.c_str());
      rc = 1;
    }
  }
  if (png.empty() && chart.empty() && !bench && movie_dir.empty() && movie_file.empty() && view_kind == "map") {
    if (!NavRunMapInteractive(*result, mopt, &err)) {
      std::fprintf(stderr, "navview: %s\n", err.c_str());
      return 1;
    }
  } else if (png.empty() && chart.empty() && !bench && movie_dir.empty() && movie_file.empty()) {
    if (!view.RunInteractive(&err)) {
      std::fprintf(stderr, "navview: %s\n", err.c_str());
      return 1;
    }
  }
  return rc;
}

// No bad or huge result ends in an abort: the readers refuse what they cannot hold, and an
// allocation that still fails (a large file on a small machine, VTK's own buffers) is one
// message and exit 1, not std::terminate.
int main(int argc, char **argv) {
  try {
    return NavviewMain(argc, argv);
  } catch (const std::bad_alloc &) {
    std::fprintf(stderr,
                 "navview: error: out of memory (the result is too large for this machine: write it with a "
                 "lower output.rate_hz or a shorter duration)\n");
  } catch (const std::exception &e) {
    std::fprintf(stderr, "navview: error: %s\n", e.what());
  }
  return 1;
}
