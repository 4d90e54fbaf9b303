// The map's raster tile layer (nav_map_tiles.h): MBTiles (SQLite), XYZ directories and XYZ URLs
// (libcurl, disk cache), tiles decoded with VTK's PNG/JPEG readers from memory and resampled into
// the map's projection pixel by pixel.
#include "navview/nav_map_tiles.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <dirent.h>
#include <fstream>
#include <iterator>
#include <list>
#include <map>
#include <mutex>
#include <sys/stat.h>
#include <tuple>
#include <unistd.h>

#include <curl/curl.h>
#include <sqlite3.h>

#include <vtkImageData.h>
#include <vtkImageReader2.h>
#include <vtkJPEGReader.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkPointData.h>
#include <vtkDataArray.h>

#include "navcore/nav_version.h"

namespace {

constexpr double kPi = 3.14159265358979323846;
// Web-Mercator (EPSG:3857) is defined on a sphere of the WGS-84 equatorial radius; its tiles cover
// latitudes up to atan(sinh(pi)) = 85.0511 deg.
constexpr double kMercR = 6378137.0;
constexpr double kMercMaxLat = 85.05112877980659;
constexpr int kUrlMaxZoom = 19;
constexpr size_t kKeepDecoded = 160; // decoded tiles kept per source (~30 MB of 256 x 256 RGBA)
constexpr long kCacheFreshS = 7L * 24 * 3600;
constexpr long kOfflineRetryS = 60;

bool IsDir(const std::string &p) {
  struct stat st;
  return stat(p.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}
bool IsFile(const std::string &p, time_t *mtime = nullptr) {
  struct stat st;
  if (stat(p.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return false;
  if (mtime) *mtime = st.st_mtime;
  return true;
}

bool ReadFile(const std::string &p, std::vector<unsigned char> *out) {
  std::ifstream in(p, std::ios::binary);
  if (!in) return false;
  out->assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return !in.bad();
}

void MakeDirs(const std::string &d) {
  for (size_t p = 1; p != std::string::npos; p = d.find('/', p + 1))
    mkdir(d.substr(0, p).c_str(), 0755);
  mkdir(d.c_str(), 0755);
}

/** Write @p data to @p path through a temporary file and a rename: a cache file is whole or absent. */
bool WriteFileAtomic(const std::string &path, const std::vector<unsigned char> &data) {
  const size_t slash = path.rfind('/');
  if (slash != std::string::npos) MakeDirs(path.substr(0, slash));
  const std::string tmp = path + ".tmp" + std::to_string(static_cast<long>(getpid()));
  FILE *f = std::fopen(tmp.c_str(), "wb");
  if (!f) return false;
  const bool ok = std::fwrite(data.data(), 1, data.size(), f) == data.size();
  if (std::fclose(f) != 0 || !ok || std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    return false;
  }
  return true;
}

std::string Replace(std::string s, const std::string &what, const std::string &with) {
  for (size_t p = s.find(what); p != std::string::npos; p = s.find(what, p + with.size()))
    s.replace(p, what.size(), with);
  return s;
}

/** The tile's path or URL; {s} (a server letter of some URL templates) is always "a". */
std::string Expand(const std::string &tmpl, int z, int x, int y) {
  return Replace(Replace(Replace(Replace(tmpl, "{z}", std::to_string(z)), "{x}", std::to_string(x)), "{y}",
                         std::to_string(y)),
                 "{s}", "a");
}

/** Attribution text for the map: HTML tags dropped, the few entities attributions use decoded. */
std::string PlainText(const std::string &html) {
  std::string s;
  bool tag = false;
  for (char c : html) {
    if (c == '<')
      tag = true;
    else if (c == '>')
      tag = false;
    else if (!tag)
      s += (c == '\n' || c == '\r' || c == '\t') ? ' ' : c;
  }
  s = Replace(Replace(Replace(Replace(s, "&copy;", "\u00a9"), "&amp;", "&"), "&lt;", "<"), "&gt;", ">");
  s = Replace(s, "&nbsp;", " ");
  while (!s.empty() && s.back() == ' ')
    s.pop_back();
  while (!s.empty() && s.front() == ' ')
    s.erase(s.begin());
  return s;
}

/** Decode a PNG or JPEG held in memory into RGBA, row 0 at the top. */
bool Decode(const std::vector<unsigned char> &data, NavTileImage *out, std::string *why) {
  static const unsigned char png_magic[8] = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a};
  const bool png = data.size() >= 8 && std::memcmp(data.data(), png_magic, 8) == 0;
  const bool jpg = data.size() >= 3 && data[0] == 0xff && data[1] == 0xd8 && data[2] == 0xff;
  if (!png && !jpg) {
    char head[64];
    std::snprintf(head, sizeof head, "%zu bytes starting %02x %02x %02x %02x", data.size(),
                  data.size() > 0 ? data[0] : 0, data.size() > 1 ? data[1] : 0, data.size() > 2 ? data[2] : 0,
                  data.size() > 3 ? data[3] : 0);
    *why = std::string("not a PNG or JPEG image (") + head + ")";
    return false;
  }
  vtkSmartPointer<vtkImageReader2> rd;
  if (png)
    rd = vtkSmartPointer<vtkPNGReader>::New();
  else
    rd = vtkSmartPointer<vtkJPEGReader>::New();
  // A damaged image makes the reader print its own error through VTK's output window; the tile is
  // then reported once in the map's notes, which is the message that counts.
  rd->GlobalWarningDisplayOff();
  rd->SetMemoryBuffer(data.data());
  rd->SetMemoryBufferLength(static_cast<vtkIdType>(data.size()));
  rd->Update();
  vtkImageData *im = rd->GetOutput();
  int dims[3] = {0, 0, 0};
  im->GetDimensions(dims);
  vtkDataArray *sc = im->GetPointData() ? im->GetPointData()->GetScalars() : nullptr;
  if (dims[0] < 1 || dims[1] < 1 || !sc ||
      sc->GetNumberOfTuples() != static_cast<vtkIdType>(dims[0]) * dims[1] || dims[0] > 4096 ||
      dims[1] > 4096) {
    *why = std::string("damaged ") + (png ? "PNG" : "JPEG") + " image";
    return false;
  }
  const int nc = sc->GetNumberOfComponents();
  const double scale = sc->GetDataTypeSize() > 1 ? 255.0 / 65535.0 : 1.0; // 16-bit PNG
  out->w = dims[0];
  out->h = dims[1];
  out->rgba.assign(4 * static_cast<size_t>(out->w) * static_cast<size_t>(out->h), 255);
  for (int r = 0; r < out->h; ++r) {
    const int vy = out->h - 1 - r; // VTK images start at the bottom row
    for (int c = 0; c < out->w; ++c) {
      const vtkIdType id = static_cast<vtkIdType>(vy) * out->w + c;
      unsigned char *p = &out->rgba[4 * (static_cast<size_t>(r) * out->w + c)];
      auto comp = [&](int k) {
        return static_cast<unsigned char>(
            std::lround(std::clamp(sc->GetComponent(id, k) * scale, 0.0, 255.0)));
      };
      if (nc >= 3) {
        p[0] = comp(0);
        p[1] = comp(1);
        p[2] = comp(2);
        if (nc >= 4) p[3] = comp(3);
      } else { // grey, grey + alpha
        p[0] = p[1] = p[2] = comp(0);
        if (nc == 2) p[3] = comp(1);
      }
    }
  }
  return true;
}

size_t CurlWrite(char *ptr, size_t size, size_t nmemb, void *user) {
  auto *v = static_cast<std::vector<unsigned char> *>(user);
  v->insert(v->end(), reinterpret_cast<unsigned char *>(ptr),
            reinterpret_cast<unsigned char *>(ptr) + size * nmemb);
  return size * nmemb;
}

std::string CacheRoot() {
  const char *own = std::getenv("NAVVIEW_TILE_CACHE"), *xdg = std::getenv("XDG_CACHE_HOME"),
             *home = std::getenv("HOME");
  if (own && *own) return own;
  if (xdg && *xdg) return std::string(xdg) + "/navsim/tiles";
  if (home && *home) return std::string(home) + "/.cache/navsim/tiles";
  return "/tmp/navsim-tiles";
}

/** FNV-1a 64: a short, stable directory name for a URL template. */
std::string Hash(const std::string &s) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  char buf[24];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

} // namespace

struct NavTileSource::Impl {
  Kind kind = Kind::MBTiles;
  std::string spec, name, attribution, tmpl; // tmpl: directory or URL template
  int min_zoom = 0, max_zoom = 0;
  sqlite3 *db = nullptr;
  sqlite3_stmt *get = nullptr;
  CURL *curl = nullptr;
  std::string cache_dir, offline;
  time_t offline_since = 0;
  std::mutex mu;
  // Most recently used decoded tiles; a missing tile is kept as an empty image.
  std::list<std::tuple<int, int, int>> lru;
  std::map<std::tuple<int, int, int>, std::pair<NavTileImage, std::list<std::tuple<int, int, int>>::iterator>>
      decoded;

  ~Impl() {
    if (get) sqlite3_finalize(get);
    if (db) sqlite3_close(db);
    if (curl) curl_easy_cleanup(curl);
  }

  bool OpenMBTiles(std::string *error) {
    auto fail = [&](const std::string &what) {
      *error = spec + ": error: " + what;
      return false;
    };
    {
      std::ifstream in(spec, std::ios::binary);
      char head[16] = {0};
      in.read(head, 16);
      if (!in || std::memcmp(head, "SQLite format 3", 16) != 0)
        return fail("not an MBTiles file: a SQLite 3 database was expected (the file does not start with "
                    "\"SQLite format 3\")");
    }
    if (sqlite3_open_v2(spec.c_str(), &db, SQLITE_OPEN_READONLY | SQLITE_OPEN_NOMUTEX, nullptr) != SQLITE_OK)
      return fail(std::string("cannot open the SQLite database: ") +
                  (db ? sqlite3_errmsg(db) : "out of memory"));
    // Metadata (MBTiles 1.3: name/value rows); format png|jpg, attribution, zoom range.
    std::map<std::string, std::string> meta;
    {
      sqlite3_stmt *st = nullptr;
      if (sqlite3_prepare_v2(db, "SELECT name, value FROM metadata", -1, &st, nullptr) != SQLITE_OK)
        return fail(std::string("not an MBTiles file: no readable metadata table (") + sqlite3_errmsg(db) +
                    ")");
      int rc = sqlite3_step(st);
      for (; rc == SQLITE_ROW; rc = sqlite3_step(st)) {
        const unsigned char *k = sqlite3_column_text(st, 0), *v = sqlite3_column_text(st, 1);
        if (k && v) meta[reinterpret_cast<const char *>(k)] = reinterpret_cast<const char *>(v);
      }
      sqlite3_finalize(st);
      if (rc != SQLITE_DONE)
        return fail(std::string("damaged MBTiles file: reading metadata: ") + sqlite3_errmsg(db));
    }
    if (meta.count("format")) {
      const std::string &f = meta["format"];
      if (f != "png" && f != "jpg" && f != "jpeg")
        return fail("metadata format is \"" + f + "\": raster tiles (png or jpg) expected" +
                    (f == "pbf" ? " (vector tiles are not drawn)" : ""));
    }
    if (sqlite3_prepare_v2(
            db, "SELECT tile_data FROM tiles WHERE zoom_level = ? AND tile_column = ? AND tile_row = ?", -1,
            &get, nullptr) != SQLITE_OK)
      return fail(
          std::string("not an MBTiles file: no table tiles(zoom_level, tile_column, tile_row, tile_data) (") +
          sqlite3_errmsg(db) + ")");
    auto zoom_of = [&](const char *key, int *z) {
      if (!meta.count(key)) return false;
      char *end = nullptr;
      const long v = std::strtol(meta[key].c_str(), &end, 10);
      if (end == meta[key].c_str() || *end != '\0' || v < 0 || v > 30) return false;
      *z = static_cast<int>(v);
      return true;
    };
    bool have_min = zoom_of("minzoom", &min_zoom), have_max = zoom_of("maxzoom", &max_zoom);
    if (!have_min || !have_max) { // not in the metadata (it is optional): from the table
      sqlite3_stmt *st = nullptr;
      if (sqlite3_prepare_v2(db, "SELECT MIN(zoom_level), MAX(zoom_level) FROM tiles", -1, &st, nullptr) !=
          SQLITE_OK)
        return fail(std::string("reading the zoom levels: ") + sqlite3_errmsg(db));
      const int rc = sqlite3_step(st);
      if (rc != SQLITE_ROW) {
        const std::string m = sqlite3_errmsg(db);
        sqlite3_finalize(st);
        return fail("damaged MBTiles file: reading the zoom levels: " + m);
      }
      const bool empty = sqlite3_column_type(st, 0) == SQLITE_NULL;
      if (!have_min) min_zoom = sqlite3_column_int(st, 0);
      if (!have_max) max_zoom = sqlite3_column_int(st, 1);
      sqlite3_finalize(st);
      if (empty) return fail("the tiles table is empty: no tiles to draw");
    }
    if (min_zoom > max_zoom) return fail("metadata minzoom is above maxzoom");
    name = meta.count("name") ? meta["name"] : spec;
    attribution = meta.count("attribution") ? PlainText(meta["attribution"]) : "";
    return true;
  }

  bool OpenDirectory(std::string *error) {
    tmpl = spec;
    if (tmpl.find("{z}") == std::string::npos) {
      if (!IsDir(spec)) {
        *error = spec + ": error: no such file or directory (expected an MBTiles file, a directory of "
                        "{z}/{x}/{y}.png tiles, a template DIR/{z}/{x}/{y}.png or an http(s) URL template)";
        return false;
      }
      tmpl = (spec.back() == '/' ? spec : spec + "/") + "{z}/{x}/{y}.png";
    }
    if (tmpl.find("{x}") == std::string::npos || tmpl.find("{y}") == std::string::npos) {
      *error = spec + ": error: a tile template needs {z}, {x} and {y} (e.g. DIR/{z}/{x}/{y}.png)";
      return false;
    }
    // The fixed directory before the first placeholder must exist.
    const std::string head = tmpl.substr(0, tmpl.find('{'));
    const std::string dir = head.find('/') == std::string::npos ? "." : head.substr(0, head.rfind('/') + 1);
    if (!IsDir(dir)) {
      *error = spec + ": error: directory " + dir + " does not exist";
      return false;
    }
    name = spec;
    min_zoom = 0;
    max_zoom = kUrlMaxZoom;
    // DIR/{z}/...: the zoom levels present are DIR's numeric subdirectories.
    if (head == dir && tmpl.compare(head.size(), 4, "{z}/") == 0) {
      int lo = 99, hi = -1;
      DIR *d = opendir(dir.c_str());
      if (d) {
        for (dirent *e = readdir(d); e; e = readdir(d)) {
          char *end = nullptr;
          const long z = std::strtol(e->d_name, &end, 10);
          if (end != e->d_name && *end == '\0' && z >= 0 && z <= 30 && IsDir(dir + e->d_name)) {
            lo = std::min(lo, static_cast<int>(z));
            hi = std::max(hi, static_cast<int>(z));
          }
        }
        closedir(d);
      }
      if (hi < 0) {
        *error = spec + ": error: " + dir +
                 " holds no zoom-level directories (0, 1, ... 19): not a tile directory";
        return false;
      }
      min_zoom = lo;
      max_zoom = hi;
    }
    return true;
  }

  bool OpenUrl(std::string *error) {
    tmpl = spec;
    if (tmpl.find("{z}") == std::string::npos || tmpl.find("{x}") == std::string::npos ||
        tmpl.find("{y}") == std::string::npos) {
      *error =
          spec + ": error: a tile URL template needs {z}, {x} and {y} (e.g. https://HOST/{z}/{x}/{y}.png)";
      return false;
    }
    static std::once_flag curl_once;
    std::call_once(curl_once, [] { curl_global_init(CURL_GLOBAL_DEFAULT); });
    curl = curl_easy_init();
    if (!curl) {
      *error = spec + ": error: libcurl could not be initialised";
      return false;
    }
    name = spec;
    min_zoom = 0;
    max_zoom = kUrlMaxZoom;
    cache_dir = CacheRoot() + "/" + Hash(tmpl);
    return true;
  }

  /** The raw bytes of a tile: true with data, true with empty data when missing, false on error. */
  bool Raw(int z, int x, int y, std::vector<unsigned char> *data, std::string *why) {
    data->clear();
    if (kind == Kind::MBTiles) {
      sqlite3_reset(get);
      sqlite3_bind_int(get, 1, z);
      sqlite3_bind_int(get, 2, x);
      sqlite3_bind_int(get, 3, (1 << z) - 1 - y); // TMS rows count from the south
      const int rc = sqlite3_step(get);
      if (rc == SQLITE_ROW) {
        const void *b = sqlite3_column_blob(get, 0);
        const int n = sqlite3_column_bytes(get, 0);
        if (b && n > 0)
          data->assign(static_cast<const unsigned char *>(b), static_cast<const unsigned char *>(b) + n);
        sqlite3_reset(get);
        return true;
      }
      if (rc == SQLITE_DONE) return true;
      *why = std::string("SQLite: ") + sqlite3_errmsg(db);
      sqlite3_reset(get);
      return false;
    }
    if (kind == Kind::Directory) {
      const std::string p = Expand(tmpl, z, x, y);
      if (!IsFile(p)) return true;
      if (!ReadFile(p, data)) {
        *why = p + ": " + std::strerror(errno);
        return false;
      }
      return true;
    }
    // URL: the cache first.
    const std::string url = Expand(tmpl, z, x, y);
    std::string ext = tmpl.substr(tmpl.rfind('/') + 1);
    ext = ext.find('.') != std::string::npos ? ext.substr(ext.rfind('.')) : ".tile";
    if (ext.find_first_of("?&=") != std::string::npos) ext = ".tile";
    const std::string cached =
        cache_dir + "/" + std::to_string(z) + "/" + std::to_string(x) + "/" + std::to_string(y) + ext;
    time_t mtime = 0;
    const bool have_cache = IsFile(cached, &mtime);
    // A long-lived process (navstudio, an interactive map) asks the server again a minute after
    // it was found unreachable.
    if (!offline.empty() && std::time(nullptr) - offline_since > kOfflineRetryS) offline.clear();
    if (have_cache && (!offline.empty() || std::time(nullptr) - mtime < kCacheFreshS)) {
      if (!ReadFile(cached, data)) data->clear();
      return true;
    }
    if (!offline.empty()) return true; // offline, nothing cached: missing
    std::vector<unsigned char> body;
    char errbuf[CURL_ERROR_SIZE] = {0};
    curl_easy_reset(curl);
    curl_easy_setopt(curl, CURLOPT_URL, url.c_str());
    curl_easy_setopt(curl, CURLOPT_WRITEFUNCTION, CurlWrite);
    curl_easy_setopt(curl, CURLOPT_WRITEDATA, &body);
    curl_easy_setopt(curl, CURLOPT_ERRORBUFFER, errbuf);
    curl_easy_setopt(curl, CURLOPT_FOLLOWLOCATION, 1L);
    curl_easy_setopt(curl, CURLOPT_CONNECTTIMEOUT, 5L);
    curl_easy_setopt(curl, CURLOPT_TIMEOUT, 20L);
    curl_easy_setopt(curl, CURLOPT_NOSIGNAL, 1L);
    // Tile servers ask clients to identify themselves (e.g. the OpenStreetMap tile usage policy).
    char ua[96];
    std::snprintf(ua, sizeof ua, "navview/%d.%d.%d (navsim map tiles)", NAV_VERSION_MAJOR, NAV_VERSION_MINOR,
                  NAV_VERSION_PATCH);
    curl_easy_setopt(curl, CURLOPT_USERAGENT, ua);
    const CURLcode cc = curl_easy_perform(curl);
    if (cc != CURLE_OK) {
      if (cc == CURLE_COULDNT_RESOLVE_HOST || cc == CURLE_COULDNT_CONNECT || cc == CURLE_OPERATION_TIMEDOUT ||
          cc == CURLE_COULDNT_RESOLVE_PROXY || cc == CURLE_SEND_ERROR || cc == CURLE_RECV_ERROR ||
          cc == CURLE_GOT_NOTHING || cc == CURLE_SSL_CONNECT_ERROR) {
        // Unreachable: do not wait a timeout per tile; use what the cache holds from now on.
        offline_since = std::time(nullptr);
        offline = std::string("tiles: cannot reach the tile server (") +
                  (errbuf[0] ? errbuf : curl_easy_strerror(cc)) + "): offline? only cached tiles are drawn";
        if (have_cache && !ReadFile(cached, data)) data->clear();
        return true;
      }
      *why = url + ": " + (errbuf[0] ? errbuf : curl_easy_strerror(cc));
      return false;
    }
    long status = 0;
    curl_easy_getinfo(curl, CURLINFO_RESPONSE_CODE, &status);
    if (status == 404 || status == 204) return true;
    if (status != 200) {
      if (have_cache) { // a server error: the stale copy is better than nothing
        if (!ReadFile(cached, data)) data->clear();
        return true;
      }
      *why = url + ": HTTP status " + std::to_string(status);
      return false;
    }
    *data = std::move(body);
    NavTileImage check;
    std::string dwhy;
    if (Decode(*data, &check, &dwhy)) WriteFileAtomic(cached, *data); // only images go in the cache
    return true;
  }
};

NavTileSource::NavTileSource(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
NavTileSource::~NavTileSource() = default;
NavTileSource::Kind NavTileSource::GetKind() const {
  return impl_->kind;
}
const std::string &NavTileSource::Spec() const {
  return impl_->spec;
}
const std::string &NavTileSource::Name() const {
  return impl_->name;
}
const std::string &NavTileSource::Attribution() const {
  return impl_->attribution;
}
int NavTileSource::MinZoom() const {
  return impl_->min_zoom;
}
int NavTileSource::MaxZoom() const {
  return impl_->max_zoom;
}

std::string NavTileSource::OfflineNote() const {
  std::lock_guard<std::mutex> lock(impl_->mu);
  return impl_->offline;
}

NavTileSource::Fetch NavTileSource::Get(int z, int x, int y, NavTileImage *out, std::string *error) {
  Impl &m = *impl_;
  std::lock_guard<std::mutex> lock(m.mu);
  const auto key = std::make_tuple(z, x, y);
  auto it = m.decoded.find(key);
  if (it != m.decoded.end()) {
    m.lru.splice(m.lru.begin(), m.lru, it->second.second);
    *out = it->second.first;
    return out->w > 0 ? Fetch::Ok : Fetch::Missing;
  }
  std::vector<unsigned char> data;
  std::string why;
  char tile[48];
  std::snprintf(tile, sizeof tile, "tile %d/%d/%d", z, x, y);
  if (!m.Raw(z, x, y, &data, &why)) {
    *error = m.spec + ": error: " + tile + ": " + why;
    return Fetch::Failed;
  }
  NavTileImage im;
  if (!data.empty() && !Decode(data, &im, &why)) {
    *error = m.spec + ": error: " + tile + ": " + why;
    return Fetch::Failed;
  }
  // A tile missing only because the server is unreachable is not remembered as missing.
  if (im.w > 0 || m.offline.empty()) {
    m.lru.push_front(key);
    m.decoded[key] = {im, m.lru.begin()};
    while (m.lru.size() > kKeepDecoded) {
      m.decoded.erase(m.lru.back());
      m.lru.pop_back();
    }
  }
  *out = std::move(im);
  return out->w > 0 ? Fetch::Ok : Fetch::Missing;
}

bool NavTileSourceOpen(const std::string &spec, std::shared_ptr<NavTileSource> *out, std::string *error) {
  static std::mutex mu;
  static std::map<std::string, std::shared_ptr<NavTileSource>> open;
  std::lock_guard<std::mutex> lock(mu);
  if (spec.empty()) {
    *error =
        "tiles: error: empty tile source (expected an MBTiles file, a tile directory or template, or a URL)";
    return false;
  }
  auto it = open.find(spec);
  if (it != open.end()) {
    *out = it->second;
    return true;
  }
  auto impl = std::make_unique<NavTileSource::Impl>();
  impl->spec = spec;
  bool ok = false;
  if (spec.rfind("http://", 0) == 0 || spec.rfind("https://", 0) == 0) {
    impl->kind = NavTileSource::Kind::Url;
    ok = impl->OpenUrl(error);
  } else if (spec.find('{') == std::string::npos && IsFile(spec)) {
    impl->kind = NavTileSource::Kind::MBTiles;
    ok = impl->OpenMBTiles(error);
  } else {
    impl->kind = NavTileSource::Kind::Directory;
    ok = impl->OpenDirectory(error);
  }
  if (!ok) return false;
  std::shared_ptr<NavTileSource> src(new NavTileSource(std::move(impl)));
  open[spec] = src;
  *out = src;
  return true;
}

double NavTileZoomForScale(double m_per_px, double lat_deg) {
  const double c = std::cos(std::clamp(lat_deg, -kMercMaxLat, kMercMaxLat) * kPi / 180.0);
  return std::log2(2.0 * kPi * kMercR * c / (256.0 * m_per_px));
}

std::string NavTileCredit(const NavTileSource &src, const std::string &attribution_override) {
  if (!attribution_override.empty()) return "map tiles: " + attribution_override;
  if (!src.Attribution().empty()) return "map tiles: " + src.Attribution();
  return "map tiles: " + src.Name() + " (no attribution given: --tiles-attribution)";
}

void NavMapPaintTiles(NavTileSource &src, const NavMapFromPixel &from_pixel, double m_per_px, double lat_deg,
                      int w, int h, std::vector<unsigned char> *rgb, NavTilePaint *res) {
  *res = NavTilePaint();
  if (w < 1 || h < 1 || rgb->size() < 3 * static_cast<size_t>(w) * static_cast<size_t>(h)) return;
  // The nearest zoom to the scale: the tiles' pixels are then between 0.71 and 1.41 display
  // pixels. Beyond the source's deepest level its tiles are magnified; above its shallowest the
  // layer is left out (the caller's background shows) rather than fetch thousands of tiles.
  const double zf = NavTileZoomForScale(m_per_px, lat_deg);
  if (!std::isfinite(zf)) return;
  int z = static_cast<int>(std::lround(zf));
  if (z > src.MaxZoom()) z = src.MaxZoom();
  if (z < src.MinZoom()) {
    char buf[160];
    std::snprintf(buf, sizeof buf,
                  "map tiles: not drawn at this scale (zoom %d needed, the tiles start at %d)", z,
                  src.MinZoom());
    res->notes.push_back(buf);
    return;
  }
  res->zoom = z;
  const double n = std::ldexp(1.0, z);
  std::map<std::pair<int, int>, NavTileImage> tiles; // this paint's tiles; empty image: none
  int last_x = -1, last_y = -1;
  const NavTileImage *last = nullptr;
  auto tile_at = [&](int tx, int ty) -> const NavTileImage & {
    if (last && tx == last_x && ty == last_y) return *last;
    last_x = tx;
    last_y = ty;
    auto it = tiles.find({tx, ty});
    if (it != tiles.end()) return *(last = &it->second);
    NavTileImage im;
    std::string err;
    const NavTileSource::Fetch f = src.Get(z, tx, ty, &im, &err);
    if (f == NavTileSource::Fetch::Ok)
      ++res->tiles;
    else if (f == NavTileSource::Fetch::Missing)
      ++res->missing;
    else {
      if (res->failed == 0) res->notes.push_back(err);
      ++res->failed;
      im = NavTileImage();
    }
    return *(last = &tiles.emplace(std::make_pair(tx, ty), std::move(im)).first->second);
  };
  // Web-Mercator position, in tiles from the north-west corner of the world at zoom z, of a
  // display position; false off the Earth or beyond the Mercator latitudes.
  auto mercator = [&](double px, double py, double *fx, double *fy) {
    double la, lo;
    if (!from_pixel(px, py, &la, &lo) || !std::isfinite(la) || !std::isfinite(lo)) return false;
    if (std::fabs(la) > kMercMaxLat) return false;
    *fx = (std::remainder(lo, 360.0) + 180.0) / 360.0 * n;
    *fy = (1.0 - std::asinh(std::tan(la * kPi / 180.0)) / kPi) * 0.5 * n;
    return true;
  };
  // The exact mapping at the pixel centres of a grid every kCell pixels, bilinear in between:
  // the mapping bends on the scale of the Earth's radius, so over kCell pixels the interpolation
  // is off by about kCell^2 / 8 / (R / m_per_px) pixels (0.02 px for a view 4000 km across,
  // nothing at street scale), and it saves the inverse projection of every pixel (measured on a
  // 1280 x 800 map 1.5 km across: the tile layer cost 0.23 s of CPU projecting every pixel,
  // 0.06 s with this grid). A cell with a corner off the Earth or across the date line is
  // mapped pixel by pixel.
  constexpr int kCell = 16;
  const int gw = w / kCell + 2, gh = h / kCell + 2;
  std::vector<double> gfx(static_cast<size_t>(gw) * gh), gfy(gfx.size());
  std::vector<char> gok(gfx.size());
  for (int gj = 0; gj < gh; ++gj)
    for (int gi = 0; gi < gw; ++gi) {
      const size_t k = static_cast<size_t>(gj) * gw + gi;
      gok[k] = mercator(gi * kCell + 0.5, gj * kCell + 0.5, &gfx[k], &gfy[k]);
    }
  size_t painted = 0;
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const int gi = i / kCell, gj = j / kCell;
      const size_t k00 = static_cast<size_t>(gj) * gw + gi, k10 = k00 + 1, k01 = k00 + gw, k11 = k01 + 1;
      double fx, fy;
      const bool cell = gok[k00] && gok[k10] && gok[k01] && gok[k11] &&
                        std::max({gfx[k00], gfx[k10], gfx[k01], gfx[k11]}) -
                                std::min({gfx[k00], gfx[k10], gfx[k01], gfx[k11]}) <
                            0.5 * n;
      if (cell) {
        const double a = static_cast<double>(i - gi * kCell) / kCell,
                     b = static_cast<double>(j - gj * kCell) / kCell;
        fx = (1 - b) * ((1 - a) * gfx[k00] + a * gfx[k10]) + b * ((1 - a) * gfx[k01] + a * gfx[k11]);
        fy = (1 - b) * ((1 - a) * gfy[k00] + a * gfy[k10]) + b * ((1 - a) * gfy[k01] + a * gfy[k11]);
      } else if (!mercator(i + 0.5, j + 0.5, &fx, &fy)) {
        continue;
      }
      int tx = static_cast<int>(std::floor(fx)), ty = static_cast<int>(std::floor(fy));
      if (ty < 0 || ty >= static_cast<int>(n)) continue;
      tx = ((tx % static_cast<int>(n)) + static_cast<int>(n)) % static_cast<int>(n);
      const NavTileImage &t = tile_at(tx, ty);
      if (t.w == 0) continue;
      // Bilinear between the tile's pixel centres (clamped at its edges).
      const double u = std::clamp((fx - std::floor(fx)) * t.w - 0.5, 0.0, t.w - 1.0);
      const double v = std::clamp((fy - std::floor(fy)) * t.h - 0.5, 0.0, t.h - 1.0);
      const int u0 = static_cast<int>(u), v0 = static_cast<int>(v);
      const int u1 = std::min(u0 + 1, t.w - 1), v1 = std::min(v0 + 1, t.h - 1);
      const double au = u - u0, av = v - v0;
      double c[4];
      for (int k = 0; k < 4; ++k) {
        auto px = [&](int uu, int vv) {
          return double(t.rgba[4 * (static_cast<size_t>(vv) * t.w + uu) + k]);
        };
        c[k] = (1 - av) * ((1 - au) * px(u0, v0) + au * px(u1, v0)) +
               av * ((1 - au) * px(u0, v1) + au * px(u1, v1));
      }
      const double a = c[3] / 255.0;
      if (a <= 0.0) continue;
      unsigned char *d = &(*rgb)[3 * (static_cast<size_t>(j) * w + i)];
      for (int k = 0; k < 3; ++k)
        d[k] = static_cast<unsigned char>(std::lround(std::clamp(a * c[k] + (1 - a) * d[k], 0.0, 255.0)));
      ++painted;
    }
  res->coverage = static_cast<double>(painted) / (static_cast<double>(w) * h);
  const std::string off = src.OfflineNote();
  if (!off.empty()) res->notes.push_back(off);
  if (res->failed > 1)
    res->notes.push_back("map tiles: " + std::to_string(res->failed) + " tiles could not be read");
}
