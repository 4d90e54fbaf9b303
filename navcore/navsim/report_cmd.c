/*
 * navsim render / navsim report (see report_cmd.h).
 *
 * Both drive the viewer program navview (built with -DNAV_BUILD_VIEWER=ON; the one next to this
 * navsim, installed or in the build tree (nav_paths_program), else navview on PATH). Without
 * DISPLAY every navview call runs under `xvfb-run -a`.
 */
#define _POSIX_C_SOURCE 200809L
#include "cli_util.h"
#include "report_cmd.h"

#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "navcore/nav_paths.h"
#include "navcore/nav_results.h"
#include "navcore/nav_version.h"

/* A file written at @p path inside the result directory @p dir is added to its manifest, so that
 * a later navsim run may replace the directory with it (nav_resultdir_record; a directory navsim
 * did not write is left as it is). */
static void record_output(const char *dir, const char *path) {
  size_t n = strlen(dir);
  while (n > 1 && dir[n - 1] == '/') --n;
  if (strncmp(path, dir, n) == 0 && path[n] == '/') (void)nav_resultdir_record(dir, path + n + 1);
}

enum { RC_OK = 0, RC_FAIL = 1, RC_INVALID = 2 };

/* navview of this installation or build tree, else the one on PATH. */
static const char *viewer_exe(void) {
  static char path[4096];
  if (path[0] == '\0' && !nav_paths_program("navview", path, sizeof path)) snprintf(path, sizeof path, "navview");
  return path;
}

static bool need_xvfb(void) {
  const char *d = getenv("DISPLAY");
  return d == NULL || d[0] == '\0';
}

static bool is_dir(const char *p) {
  struct stat st;
  return stat(p, &st) == 0 && S_ISDIR(st.st_mode);
}

static bool is_file(const char *p) {
  struct stat st;
  return stat(p, &st) == 0 && S_ISREG(st.st_mode);
}

static long file_size(const char *p) {
  struct stat st;
  return stat(p, &st) == 0 && S_ISREG(st.st_mode) ? (long)st.st_size : -1;
}

/* argv of a navview call, with the xvfb-run prefix when needed. */
typedef struct argvec {
  char *a[96];
  int n;
} argvec;

static void av_init(argvec *v) {
  v->n = 0;
  if (need_xvfb()) {
    v->a[v->n++] = "xvfb-run";
    v->a[v->n++] = "-a";
    v->a[v->n++] = "-s";
    v->a[v->n++] = "-screen 0 1920x1200x24";
  }
  v->a[v->n++] = (char *)viewer_exe();
  v->a[v->n] = NULL;
}

static void av_add(argvec *v, const char *s) {
  if (v->n < 94) {
    v->a[v->n++] = (char *)s;
    v->a[v->n] = NULL;
  }
}

/* Run a child to completion; its exit code, or 1 when it cannot start or dies. */
static int run_child(char **args, bool quiet_stdout) {
  fflush(stdout);
  fflush(stderr);
  const pid_t pid = fork();
  if (pid < 0) {
    fprintf(stderr, "navsim: cannot fork: %s\n", strerror(errno));
    return RC_FAIL;
  }
  if (pid == 0) {
    if (quiet_stdout) {
      FILE *dn = freopen("/dev/null", "w", stdout);
      (void)dn;
    }
    execvp(args[0], args);
    fprintf(stderr, "navsim: cannot start %s: %s%s\n", args[0], strerror(errno),
            need_xvfb() ? " (no DISPLAY: xvfb-run is needed)" : "");
    _exit(127);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return RC_FAIL;
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status) == 127 ? RC_FAIL : WEXITSTATUS(status);
  fprintf(stderr, "navsim: %s ended abnormally\n", args[0]);
  return RC_FAIL;
}

/* Path to this navsim executable, for `navsim run` on a scene given to render. */
static void self_exe(char *buf, size_t cap, const char *argv0) {
  if (!nav_paths_executable(buf, cap)) snprintf(buf, cap, "%s", argv0 ? argv0 : "navsim");
}

static const char *k_usage_render =
    "usage: navsim render RESULT_DIR|SCENE [--view VIEW] [--out FILE.png] [--size WxH] [--time T_S]\n"
    "                     [navview options]\n"
    "       navsim render RESULT_DIR|SCENE --view 3d --movie FILE.mp4|FILE.webm [--duration-s S]\n"
    "                     [--size WxH] [--follow] [--follow-distance M] [navview options]\n"
    "\n"
    "Render one view of a result directory of navsim run with the VTK viewer (navview):\n"
    "  3d      reference and estimated paths, GNSS fixes and outages, attitude triads, error tube\n"
    "          and covariance ellipsoids, vehicle, grid with scale, legend (default)\n"
    "  top     the 3D view from above, estimate coloured by horizontal error\n"
    "  map     geodetic map: tracks over an offline background, graticule, scale bar;\n"
    "          --tiles FILE.mbtiles|DIR|URL_TEMPLATE [--tiles-attribution TEXT]: streets from\n"
    "          raster tiles at street scale (docs/map-data.md)\n"
    "  errors  error-vs-time charts with k-sigma bands and requirement limits\n"
    "  noise   simulated sensor errors (imu_errors.csv)\n"
    "  allan   Allan deviation of DIR/allan.csv (navsim allan --out DIR)\n"
    "  bench   speed against error of DIR/bench.csv (navsim bench --out DIR)\n"
    "  tradeoff  CPU time against each requirement of DIR/tradeoff.csv, one panel per requirement\n"
    "          (navsim tradeoff --out DIR)\n"
    "  sky     sky plot of run 0's satellites: azimuth/elevation tracks, GPS and GLONASS, masks\n"
    "          (a scene with gnss.constellation: gnss_sats.csv, gnss_mask.csv)\n"
    "  dop     GDOP/PDOP/HDOP/VDOP and satellites in view over time, canyon spans and receiver\n"
    "          outages (gnss_dop.csv)\n"
    "--movie writes a playback movie of the 3D view instead of a PNG: H.264 MP4 or VP9 WebM\n"
    "(encoded by ffmpeg), S seconds long (default 10) at 30 frames/s, 1920x1080 unless --size,\n"
    "the time read-out in each frame, --follow: the camera follows the vehicle.\n"
    "--out defaults to RESULT_DIR/VIEW.png. A SCENE file is run first (navsim run --out\n"
    "out/render-<file stem>). Without --view and --out (and with --png/--chart) the old form\n"
    "writes RESULT_DIR/view.png and RESULT_DIR/errors.png. Other options go to navview\n"
    "(navview --help: --exaggerate, --envelope, --ellipsoids, --vehicle, --map-span, ...).\n"
    "Rendering needs an X server: without DISPLAY it runs under xvfb-run.\n"
    "\n"
    "exit codes: those of navview: 0 success, 2 bad options, 1 unreadable result directory or other failure\n";

int navsim_render(int argc, char **argv) {
  if (argc < 1 || navsim_is_help(argv[0])) {
    fputs(k_usage_render, argc < 1 ? stderr : stdout);
    return argc < 1 ? RC_INVALID : RC_OK;
  }
  const char *view = NULL, *out = NULL, *movie = NULL;
  bool has_png = false, has_chart = false;
  argvec v;
  av_init(&v);
  const int base = v.n;
  (void)base;
  char dir[4096];
  snprintf(dir, sizeof dir, "%s", argv[0]);
  for (int i = 1; i < argc; ++i) {
    if (navsim_is_help(argv[i])) {
      fputs(k_usage_render, stdout);
      return RC_OK;
    }
    if ((strcmp(argv[i], "--view") == 0 || strcmp(argv[i], "--out") == 0 || strcmp(argv[i], "--movie") == 0) &&
        i + 1 >= argc) {
      fprintf(stderr, "navsim render: %s needs a value\n", argv[i]);
      return RC_INVALID;
    }
    if (strcmp(argv[i], "--view") == 0) view = argv[++i];
    else if (strcmp(argv[i], "--out") == 0) out = argv[++i];
    else if (strcmp(argv[i], "--movie") == 0) {
      /* A video file; a directory (PNG frames and .ogv) passes through to navview as before. */
      const char *m = argv[++i];
      const size_t ml = strlen(m);
      if ((ml > 4 && strcmp(m + ml - 4, ".mp4") == 0) || (ml > 5 && strcmp(m + ml - 5, ".webm") == 0)) movie = m;
    }
    else if (strcmp(argv[i], "--png") == 0) has_png = true;
    else if (strcmp(argv[i], "--chart") == 0) has_chart = true;
  }
  if (view && strcmp(view, "3d") != 0 && strcmp(view, "top") != 0 && strcmp(view, "map") != 0 &&
      strcmp(view, "errors") != 0 && strcmp(view, "noise") != 0 && strcmp(view, "allan") != 0 &&
      strcmp(view, "bench") != 0 && strcmp(view, "tradeoff") != 0 && strcmp(view, "sky") != 0 &&
      strcmp(view, "dop") != 0) {
    fprintf(stderr,
            "navsim render: --view: expected 3d, top, map, errors, noise, allan, bench, tradeoff, sky or dop, got "
            "\"%s\"\n",
            view);
    return RC_INVALID;
  }
  /* A scene file: run it first. */
  if (is_file(argv[0])) {
    const char *base_name = strrchr(argv[0], '/');
    base_name = base_name ? base_name + 1 : argv[0];
    char stem[256];
    snprintf(stem, sizeof stem, "%s", base_name);
    char *dot = strrchr(stem, '.');
    if (dot) *dot = '\0';
    snprintf(dir, sizeof dir, "out/render-%s", stem);
    char exe[4096];
    self_exe(exe, sizeof exe, "navsim");
    char *run_args[] = {exe, "run", argv[0], "--out", dir, "--quiet", NULL};
    const int rc = run_child(run_args, false);
    if (rc != 0) return rc;
  } else if (!is_dir(argv[0])) {
    FILE *f = NULL;
    char why[320];
    if (nav_io_fopen_regular(argv[0], &f, why, sizeof why) == NAV_ERR_PARSE) { /* a FIFO or device */
      fprintf(stderr, "%s: error: %s; expected a result directory or a scene file\n", argv[0], why);
      return RC_INVALID;
    }
    if (f) fclose(f);
    fprintf(stderr, "%s: error: not a result directory or scene file\n", argv[0]);
    return RC_FAIL;
  }
  if (navsim_refuse_special_result_files(dir) != 0) return RC_INVALID;
  if (movie) {
    /* The playback movie of the 3D view (navview --movie FILE.mp4|FILE.webm). */
    if ((view && strcmp(view, "3d") != 0) || out) {
      fprintf(stderr, "navsim render: --movie %s: a video of the 3D view: expected --view 3d (the default) and no "
                      "--out\n", movie);
      return RC_INVALID;
    }
    av_add(&v, dir);
    av_add(&v, "--view");
    av_add(&v, "3d");
    for (int i = 1; i < argc; ++i) {
      if (strcmp(argv[i], "--view") == 0) {
        ++i;
        continue;
      }
      av_add(&v, argv[i]);
    }
    const int rc = run_child(v.a, false);
    if (rc == 0) record_output(dir, movie);
    return rc;
  }

  char out_buf[4200], in_buf[4200], png2[4200];
  const bool legacy = !view && !out;
  if (legacy && !has_png && !has_chart) {
    /* The old default: the 3D view and the error charts. */
    snprintf(out_buf, sizeof out_buf, "%s/view.png", dir);
    snprintf(png2, sizeof png2, "%s/errors.png", dir);
    av_add(&v, dir);
    for (int i = 1; i < argc; ++i)
      av_add(&v, argv[i]);
    av_add(&v, "--png");
    av_add(&v, out_buf);
    av_add(&v, "--chart");
    av_add(&v, png2);
    const int rc = run_child(v.a, false);
    if (rc == 0) {
      record_output(dir, out_buf);
      record_output(dir, png2);
    }
    return rc;
  }
  if (!view) view = "3d";
  if (!out) {
    snprintf(out_buf, sizeof out_buf, "%s/%s.png", dir, view);
    out = out_buf;
  }
  if (strcmp(view, "allan") == 0 || strcmp(view, "bench") == 0 || strcmp(view, "tradeoff") == 0) {
    snprintf(in_buf, sizeof in_buf, "%s/%s.csv", dir, view);
    av_add(&v, strcmp(view, "allan") == 0 ? "--allan" : strcmp(view, "bench") == 0 ? "--speed-vs-error" : "--tradeoff");
    av_add(&v, in_buf);
  } else if (strcmp(view, "sky") == 0 || strcmp(view, "dop") == 0) {
    av_add(&v, strcmp(view, "sky") == 0 ? "--sky" : "--dop");
    av_add(&v, dir);
  } else {
    av_add(&v, dir);
    av_add(&v, "--view");
    av_add(&v, view);
  }
  for (int i = 1; i < argc; ++i) {
    if (strcmp(argv[i], "--view") == 0 || strcmp(argv[i], "--out") == 0) {
      ++i;
      continue;
    }
    av_add(&v, argv[i]);
  }
  av_add(&v, "--png");
  av_add(&v, out);
  const int rc = run_child(v.a, false);
  if (rc == 0) record_output(dir, out);
  return rc;
}

/* ------------------------------------------------------------------------------------ report */

static char *read_all(const char *path, size_t *len) {
  FILE *f = NULL;
  char why[320];
  if (nav_io_fopen_regular(path, &f, why, sizeof why) != NAV_OK) return NULL; /* no FIFO blocks here */
  size_t cap = 1 << 16, n = 0;
  char *b = malloc(cap + 1);
  while (b) {
    const size_t r = fread(b + n, 1, cap - n, f);
    n += r;
    if (n < cap) break;
    cap *= 2;
    char *nb = realloc(b, cap + 1);
    if (!nb) {
      free(b);
      b = NULL;
    }
    b = nb;
  }
  fclose(f);
  if (!b) return NULL;
  b[n] = '\0';
  if (len) *len = n;
  return b;
}

/* ---------------------------------------------------------------- summary.json syntax */

/* A strict JSON syntax check (RFC 8259: one value, then only whitespace), so that a cut or
 * damaged summary.json is reported instead of read as "no requirements" or "no statistics".
 * On failure *at is the byte offset of the problem and *why says what was expected there. */
typedef struct jcheck {
  const char *s;
  size_t n, i;
  const char *why;
} jcheck;

static void jws(jcheck *c) {
  while (c->i < c->n && (c->s[c->i] == ' ' || c->s[c->i] == '\t' || c->s[c->i] == '\n' || c->s[c->i] == '\r'))
    ++c->i;
}

static bool jfail(jcheck *c, const char *why) {
  if (!c->why) c->why = why;
  return false;
}

static bool jvalue(jcheck *c, int depth);

static bool jstring(jcheck *c) {
  ++c->i; /* the opening quote */
  while (c->i < c->n) {
    const unsigned char ch = (unsigned char)c->s[c->i];
    if (ch == '"') {
      ++c->i;
      return true;
    }
    if (ch < 0x20) return jfail(c, "a control character inside a string");
    if (ch == '\\') {
      ++c->i;
      if (c->i >= c->n) break;
      const char e = c->s[c->i];
      if (e == 'u') {
        for (int k = 1; k <= 4; ++k) {
          const size_t j = c->i + (size_t)k;
          const char h = j < c->n ? c->s[j] : '\0';
          if (!((h >= '0' && h <= '9') || (h >= 'a' && h <= 'f') || (h >= 'A' && h <= 'F'))) {
            c->i = j;
            return jfail(c, "four hexadecimal digits after \\u");
          }
        }
        c->i += 4;
      } else if (!strchr("\"\\/bfnrt", e) || e == '\0') {
        return jfail(c, "an escape (\\\" \\\\ \\/ \\b \\f \\n \\r \\t \\uXXXX)");
      }
    }
    ++c->i;
  }
  return jfail(c, "the closing quote of a string");
}

static bool jdigits(jcheck *c) {
  const size_t a = c->i;
  while (c->i < c->n && c->s[c->i] >= '0' && c->s[c->i] <= '9') ++c->i;
  return c->i > a;
}

static bool jnumber(jcheck *c) {
  if (c->s[c->i] == '-') ++c->i;
  if (c->i < c->n && c->s[c->i] == '0') ++c->i;
  else if (!jdigits(c)) return jfail(c, "a digit");
  if (c->i < c->n && c->s[c->i] == '.') {
    ++c->i;
    if (!jdigits(c)) return jfail(c, "a digit after the decimal point");
  }
  if (c->i < c->n && (c->s[c->i] == 'e' || c->s[c->i] == 'E')) {
    ++c->i;
    if (c->i < c->n && (c->s[c->i] == '+' || c->s[c->i] == '-')) ++c->i;
    if (!jdigits(c)) return jfail(c, "a digit in the exponent");
  }
  /* A number cut at the end of the file looks complete: the caller sees the missing bracket. */
  return true;
}

static bool jword(jcheck *c, const char *w) {
  const size_t k = strlen(w);
  for (size_t j = 0; j < k; ++j, ++c->i)
    if (c->i >= c->n || c->s[c->i] != w[j]) return jfail(c, "true, false or null");
  return true;
}

static bool jvalue(jcheck *c, int depth) {
  jws(c);
  if (c->i >= c->n) return jfail(c, "a value");
  if (depth > 256) return jfail(c, "nesting of at most 256 levels");
  const char ch = c->s[c->i];
  if (ch == '{' || ch == '[') {
    const char close = ch == '{' ? '}' : ']';
    ++c->i;
    jws(c);
    if (c->i < c->n && c->s[c->i] == close) {
      ++c->i;
      return true;
    }
    for (;;) {
      if (ch == '{') {
        jws(c);
        if (c->i >= c->n || c->s[c->i] != '"') return jfail(c, "a key (a string in double quotes)");
        if (!jstring(c)) return false;
        jws(c);
        if (c->i >= c->n || c->s[c->i] != ':') return jfail(c, "':' after the key");
        ++c->i;
      }
      if (!jvalue(c, depth + 1)) return false;
      jws(c);
      if (c->i < c->n && c->s[c->i] == ',') {
        ++c->i;
        continue;
      }
      if (c->i < c->n && c->s[c->i] == close) {
        ++c->i;
        return true;
      }
      return jfail(c, ch == '{' ? "',' or '}' in an object" : "',' or ']' in an array");
    }
  }
  if (ch == '"') return jstring(c);
  if (ch == '-' || (ch >= '0' && ch <= '9')) return jnumber(c);
  if (ch == 't') return jword(c, "true");
  if (ch == 'f') return jword(c, "false");
  if (ch == 'n') return jword(c, "null");
  return jfail(c, "a value (object, array, string, number, true, false or null)");
}

/* NULL when @p text is one JSON value; else what is wrong, at byte *at. */
static const char *json_syntax_error(const char *text, size_t n, size_t *at) {
  jcheck c = {text, n, 0, NULL};
  if (jvalue(&c, 0)) {
    jws(&c);
    if (c.i < c.n) {
      c.why = "the end of the file after the JSON value";
    }
  }
  *at = c.i;
  return c.why;
}

/* The result directory's summary.json must exist and be whole: it holds the verdicts and the
 * statistics, and a page without them would say "no requirements" where they failed. 0, or the
 * exit code after a message. */
static int check_summary(const char *dir) {
  char path[4300];
  snprintf(path, sizeof path, "%s/summary.json", dir);
  struct stat sb;
  if (stat(path, &sb) != 0) {
    fprintf(stderr,
            "%s: error: missing: a result directory of navsim holds summary.json (run, estimate, replay, allan "
            "and bench write it), with the statistics and the requirement verdicts; run the command again\n",
            path);
    return RC_INVALID;
  }
  if (!S_ISREG(sb.st_mode)) {
    fprintf(stderr, "%s: error: not a regular file; a result directory's summary.json is a JSON file\n", path);
    return RC_INVALID;
  }
  size_t n = 0;
  char *text = read_all(path, &n);
  if (!text) {
    fprintf(stderr, "%s: error: cannot read: %s\n", path, strerror(errno));
    return RC_FAIL;
  }
  size_t at = 0;
  const char *why = memchr(text, '\0', n) ? "a NUL byte (binary data)" : json_syntax_error(text, n, &at);
  if (why && memchr(text, '\0', n)) at = (size_t)((const char *)memchr(text, '\0', n) - text);
  int rc = 0;
  if (why) {
    long line = 1, col = 1;
    for (size_t k = 0; k < at && k < n; ++k) {
      if (text[k] == '\n') {
        ++line;
        col = 1;
      } else {
        ++col;
      }
    }
    if (at >= n)
      fprintf(stderr,
              "%s:%ld:%ld: error: truncated JSON: the file ends at byte %zu where %s was expected (cut short?); the "
              "result directory is damaged (run the command that wrote it again)\n",
              path, line, col, n, why);
    else
      fprintf(stderr,
              "%s:%ld:%ld: error: invalid JSON at byte %zu of %zu: expected %s; the result directory is damaged "
              "(run the command that wrote it again)\n",
              path, line, col, at, n, why);
    rc = RC_INVALID;
  }
  free(text);
  return rc;
}

static void html_escape(FILE *f, const char *s, size_t n) {
  for (size_t i = 0; i < n && s[i]; ++i) {
    const char c = s[i];
    if (c == '<') fputs("&lt;", f);
    else if (c == '>') fputs("&gt;", f);
    else if (c == '&') fputs("&amp;", f);
    else if (c == '"') fputs("&quot;", f);
    else fputc(c, f);
  }
}

static void html_text(FILE *f, const char *s) { html_escape(f, s, strlen(s)); }

static void base64(FILE *f, const unsigned char *p, size_t n) {
  static const char t[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  for (size_t i = 0; i < n; i += 3) {
    const unsigned v = (unsigned)p[i] << 16 | (i + 1 < n ? (unsigned)p[i + 1] << 8 : 0u) | (i + 2 < n ? p[i + 2] : 0u);
    fputc(t[(v >> 18) & 63], f);
    fputc(t[(v >> 12) & 63], f);
    fputc(i + 1 < n ? t[(v >> 6) & 63] : '=', f);
    fputc(i + 2 < n ? t[v & 63] : '=', f);
  }
}

/* The string value of "key" at or after p (within a JSON text written by navsim). */
static bool json_str(const char *p, const char *key, char *out, size_t cap) {
  char k[128];
  snprintf(k, sizeof k, "\"%s\"", key);
  const char *q = p ? strstr(p, k) : NULL;
  if (!q) return false;
  q = strchr(q + strlen(k), ':');
  if (!q) return false;
  while (*++q == ' ') {
  }
  if (*q != '"') return false;
  ++q;
  size_t n = 0;
  while (*q && *q != '"' && n + 1 < cap) {
    if (*q == '\\' && q[1]) ++q;
    out[n++] = *q++;
  }
  out[n] = '\0';
  return true;
}

static bool json_num(const char *p, const char *key, double *out) {
  char k[128];
  snprintf(k, sizeof k, "\"%s\"", key);
  const char *q = p ? strstr(p, k) : NULL;
  if (!q) return false;
  q = strchr(q + strlen(k), ':');
  if (!q) return false;
  char *end = NULL;
  const double v = strtod(q + 1, &end);
  if (end == q + 1) return false;
  *out = v;
  return true;
}

/* The text of the object or array that follows "key", up to its matching bracket (copied). */
static char *json_block(const char *text, const char *key) {
  char k[128];
  snprintf(k, sizeof k, "\"%s\"", key);
  const char *q = strstr(text, k);
  if (!q) return NULL;
  q = strchr(q + strlen(k), ':');
  if (!q) return NULL;
  while (*++q == ' ') {
  }
  if (*q != '{' && *q != '[') return NULL;
  int depth = 0;
  bool str = false;
  for (const char *e = q; *e; ++e) {
    if (str) {
      if (*e == '\\' && e[1]) ++e;
      else if (*e == '"') str = false;
      continue;
    }
    if (*e == '"') str = true;
    else if (*e == '{' || *e == '[') ++depth;
    else if ((*e == '}' || *e == ']') && --depth == 0) {
      const size_t n = (size_t)(e - q) + 1;
      char *b = malloc(n + 1);
      if (!b) return NULL;
      memcpy(b, q, n);
      b[n] = '\0';
      return b;
    }
  }
  return NULL;
}

/* The strings of a JSON array text (as navsim writes them: escapes \" \\ \n), one line each, as
 * HTML text. */
static void html_string_lines(FILE *f, const char *arr) {
  for (const char *q = arr ? strchr(arr, '"') : NULL; q; q = strchr(q, '"')) {
    ++q;
    while (*q && *q != '"') {
      char c = *q;
      if (c == '\\' && q[1]) {
        ++q;
        c = *q == 'n' ? '\n' : *q == 't' ? '\t' : *q;
      }
      html_escape(f, &c, 1);
      ++q;
    }
    fputc('\n', f);
    if (*q) ++q;
  }
}

/* The "setup" of summary.json (issue 18): scheme, IMU, receiver, outages, lever arm, seed and
 * runs; the fit residuals of a recorded reference and the source of recorded GNSS fixes. */
static void write_setup(FILE *f, const char *summary) {
  char *setup = json_block(summary, "setup");
  char buf[512];
  double x;
  if (setup) {
    fputs("<h2>Setup</h2>\n<table>\n", f);
    if (json_str(setup, "scheme", buf, sizeof buf)) {
      fputs("<tr><th class=\"l\">navigation scheme</th><td class=\"l\">", f);
      html_text(f, buf);
      fputs("</td></tr>\n", f);
    }
    char *imu = json_block(setup, "imu");
    if (imu) {
      fputs("<tr><th class=\"l\">IMU</th><td class=\"l\">", f);
      if (json_str(imu, "catalog", buf, sizeof buf) && buf[0]) html_text(f, buf);
      else fputs("(no catalog part: the scene's own terms)", f);
      char *lines = json_block(imu, "model_yaml");
      fputs("<pre>", f);
      html_string_lines(f, lines);
      fputs("</pre></td></tr>\n", f);
      free(lines);
      free(imu);
    }
    char *rx = json_block(setup, "receiver");
    if (rx) {
      char src[64] = "";
      json_str(rx, "source", src, sizeof src);
      fputs("<tr><th class=\"l\">GNSS receiver</th><td class=\"l\">", f);
      if (strcmp(src, "none") == 0) fputs("none (the scheme uses no GNSS)", f);
      else if (strcmp(src, "file") == 0) fputs("recorded fixes from a file (gnss.file; the file's sigmas)", f);
      else if (json_str(rx, "catalog", buf, sizeof buf) && buf[0]) html_text(f, buf);
      else fputs("receiver model of the scene", f);
      char *lines = json_block(rx, "model_yaml");
      if (lines && strchr(lines, '"')) {
        fputs("<pre>", f);
        html_string_lines(f, lines);
        fputs("</pre>", f);
      }
      free(lines);
      fputs("</td></tr>\n", f);
      free(rx);
    }
    char *out = json_block(setup, "outages_s");
    if (out) {
      fputs("<tr><th class=\"l\">GNSS outages [s]</th><td class=\"l\">", f);
      if (strcmp(out, "[]") == 0) fputs("none in the scene", f);
      else html_text(f, out);
      fputs("</td></tr>\n", f);
      free(out);
    }
    char *la = json_block(setup, "lever_arm_b_m");
    if (la) {
      fputs("<tr><th class=\"l\">lever arm (antenna from IMU, body axes) [m]</th><td class=\"l\">", f);
      const char *q = la + 1;
      for (int k = 0; k < 3; ++k) {
        char *end = NULL;
        const double v = strtod(q, &end);
        if (end == q) break;
        fprintf(f, "%s%.6g", k ? ", " : "", v);
        q = end + (*end == ',' ? 1 : 0);
      }
      fputs("</td></tr>\n", f);
      free(la);
    }
    if (json_num(summary, "seed", &x)) fprintf(f, "<tr><th class=\"l\">seed</th><td class=\"l\">%.0f</td></tr>\n", x);
    if (json_num(summary, "runs", &x)) fprintf(f, "<tr><th class=\"l\">runs</th><td class=\"l\">%.0f</td></tr>\n", x);
    fputs("</table>\n", f);
    free(setup);
  }
  char *gs = json_block(summary, "gnss_source");
  if (gs) {
    fputs("<p>GNSS fixes from the file <code>", f);
    if (json_str(gs, "file", buf, sizeof buf)) html_text(f, buf);
    fputs("</code>", f);
    if (json_num(gs, "fixes", &x)) fprintf(f, ": %.0f fixes", x);
    if (json_num(gs, "fixes_in_run_outside_outages", &x)) fprintf(f, ", %.0f in the run outside the outages", x);
    if (json_num(gs, "t0_file_s", &x)) fprintf(f, "; scene time = file time &minus; %.3f s", x);
    fputs("; the filter used the file's sigmas.</p>\n", f);
    free(gs);
  }
  char *rf = json_block(summary, "recorded_fit");
  if (rf) {
    static const struct {
      const char *rms, *max, *t, *label, *unit;
    } rows[] = {{"pos_rms_m", "pos_max_m", "pos_max_t_s", "position", "m"},
                {"vel_rms_mps", "vel_max_mps", "vel_max_t_s", "velocity", "m/s"},
                {"att_rms_deg", "att_max_deg", "att_max_t_s", "attitude", "deg"}};
    fputs("<h2>Recorded reference: fit residuals</h2>\n<p>The spline model against the recorded samples of <code>", f);
    if (json_str(rf, "file", buf, sizeof buf)) html_text(f, buf);
    fputs("</code>", f);
    if (json_num(rf, "samples", &x)) fprintf(f, " (%.0f samples)", x);
    fputs(".</p>\n<table>\n<tr><th class=\"l\">residual</th><th>RMS</th><th>max</th><th>at t [s]</th>"
          "<th class=\"l\">unit</th></tr>\n",
          f);
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; ++i) {
      double r = 0, m = 0, t = 0;
      if (!json_num(rf, rows[i].rms, &r) || !json_num(rf, rows[i].max, &m)) continue;
      json_num(rf, rows[i].t, &t);
      fprintf(f, "<tr><td class=\"l\">%s</td><td>%.4g</td><td>%.4g</td><td>%.6g</td><td class=\"l\">%s</td></tr>\n",
              rows[i].label, r, m, t, rows[i].unit);
    }
    fputs("</table>\n", f);
    if (json_str(rf, "warning", buf, sizeof buf)) {
      fputs("<p class=\"fail\">Warning: ", f);
      html_text(f, buf);
      fputs("</p>\n", f);
    }
    free(rf);
  }
}

typedef struct figure {
  const char *key;   /* file stem */
  const char *title; /* caption */
  const char *what;  /* one-line explanation */
  bool ok;
} figure;

/* One CSV line (navsim's own files: "..." quoting, "" inside quotes) into at most @p cap fields,
   written into @p line in place. @return the number of fields. */
static int csv_fields(char *line, char **field, int cap) {
  int n = 0;
  char *w = line;
  bool q = false;
  if (cap > 0) field[n++] = w;
  for (char *r = line; *r && *r != '\n' && *r != '\r'; ++r) {
    if (*r == '"') {
      if (q && r[1] == '"') *w++ = *r++;
      else q = !q;
    } else if (*r == ',' && !q) {
      *w++ = '\0';
      if (n < cap) field[n++] = w;
    } else {
      *w++ = *r;
    }
  }
  *w = '\0';
  return n;
}

/* The table of navsim tradeoff's tradeoff.csv: one row per variant, per requirement its value with
   the interval (P: on the Pareto front), whether it is within the tolerance, the recommendation. */
static void tradeoff_section(FILE *f, const char *csv, const char *summary) {
  char *text = read_all(csv, NULL);
  if (!text) return;
  fputs("<h2>Speed against error (navsim tradeoff)</h2>\n", f);
  char what[600];
  if (summary && json_str(summary, "requirements_of", what, sizeof what)) {
    fputs("<p>The requirement verdicts above are those of ", f);
    html_text(f, what);
    fputs(" (recommended.yaml); the full model's and every variant's are in the table.</p>\n", f);
  }
  enum { MAXF = 24 };
  char *fld[MAXF];
  char *save = NULL;
  char *line = strtok_r(text, "\n", &save);
  int c_var = -1, c_change = -1, c_status = -1, c_note = -1, c_cpu = -1, c_req = -1, c_unit = -1, c_val = -1,
      c_lo = -1, c_hi = -1, c_within = -1, c_pareto = -1, c_rec = -1;
  const int nh = line ? csv_fields(line, fld, MAXF) : 0;
  for (int k = 0; k < nh; ++k) {
    const char *h = fld[k];
    int *slot = !strcmp(h, "variant") ? &c_var : !strcmp(h, "change") ? &c_change : !strcmp(h, "status") ? &c_status
              : !strcmp(h, "note") ? &c_note : !strcmp(h, "cpu_s_per_run") ? &c_cpu : !strcmp(h, "requirement") ? &c_req
              : !strcmp(h, "unit") ? &c_unit : !strcmp(h, "value") ? &c_val : !strcmp(h, "ci_low") ? &c_lo
              : !strcmp(h, "ci_high") ? &c_hi : !strcmp(h, "within_tolerance") ? &c_within
              : !strcmp(h, "pareto") ? &c_pareto : !strcmp(h, "recommended") ? &c_rec : NULL;
    if (slot) *slot = k;
  }
  if (c_var < 0 || c_change < 0 || c_status < 0 || c_note < 0 || c_cpu < 0 || c_req < 0 || c_unit < 0 || c_val < 0 ||
      c_lo < 0 || c_hi < 0 || c_within < 0 || c_pareto < 0 || c_rec < 0) {
    fputs("<p>tradeoff.csv: unexpected columns (not written by this navsim).</p>\n", f);
    free(text);
    return;
  }
  fputs("<table>\n<tr><th class=\"l\">variant</th><th class=\"l\">change</th><th>CPU s/run</th>"
        "<th class=\"l\">requirement</th><th>value [95 % interval]</th><th class=\"l\">within tolerance</th>"
        "<th class=\"l\">Pareto</th></tr>\n",
        f);
  for (line = strtok_r(NULL, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
    if (csv_fields(line, fld, MAXF) != nh) continue;
    const bool rec = !strcmp(fld[c_rec], "true"), skipped = strcmp(fld[c_status], "ok") != 0;
    fputs(rec ? "<tr style=\"background:#e6f0fa\"><td class=\"l\"><b>" : "<tr><td class=\"l\">", f);
    html_text(f, fld[c_var]);
    fputs(rec ? " (recommended)</b></td><td class=\"l\">" : "</td><td class=\"l\">", f);
    html_text(f, fld[c_change]);
    if (skipped) {
      fputs("</td><td class=\"l\" colspan=\"5\">skipped: ", f);
      html_text(f, fld[c_note]);
      fputs("</td></tr>\n", f);
      continue;
    }
    fprintf(f, "</td><td>%.3g</td><td class=\"l\">", atof(fld[c_cpu]));
    html_text(f, fld[c_req]);
    fputs("</td><td>", f);
    fprintf(f, "%.4g [%.4g, %.4g] ", atof(fld[c_val]), atof(fld[c_lo]), atof(fld[c_hi]));
    html_text(f, fld[c_unit]);
    fprintf(f, "</td><td class=\"l\">%s</td><td class=\"l\">%s</td></tr>\n",
            !strcmp(fld[c_within], "true") ? "yes" : "no", !strcmp(fld[c_pareto], "true") ? "front" : "");
  }
  fputs("</table>\n", f);
  free(text);
}

static const char *k_usage_report =
    "usage: navsim report RESULT_DIR [--out DIR|FILE.html] [--size WxH]\n"
    "\n"
    "Write an HTML page about a result directory of navsim run, for presentations: the scene\n"
    "summary, the statistics table, the requirement verdicts (summary.json \"requirements\") and\n"
    "every figure the directory supports (3D view, plan view coloured by error, map, error charts,\n"
    "simulated sensor errors, and allan.csv / bench.csv / tradeoff.csv when present), rendered by\n"
    "navview; for navsim tradeoff's directory also the table of its variants.\n"
    "The page is self-contained (figures embedded); the PNG files are kept next to it.\n"
    "--out: a directory (the page is DIR/report.html) or a FILE.html (figures in its directory);\n"
    "default RESULT_DIR/report/. Rendering needs an X server: without DISPLAY, xvfb-run.\n"
    "\n"
    "exit codes: 0 success; 1 a figure or the page could not be written; 2 bad command line\n";

static int mkdir_p(const char *path) {
  char tmp[4096];
  snprintf(tmp, sizeof tmp, "%s", path);
  for (char *p = tmp + 1; *p; ++p)
    if (*p == '/') {
      *p = '\0';
      if (mkdir(tmp, 0755) != 0 && errno != EEXIST) return -1;
      *p = '/';
    }
  if (mkdir(tmp, 0755) != 0 && errno != EEXIST) return -1;
  return 0;
}

int navsim_report(int argc, char **argv) {
  if (argc < 1 || navsim_is_help(argv[0])) {
    fputs(k_usage_report, argc < 1 ? stderr : stdout);
    return argc < 1 ? RC_INVALID : RC_OK;
  }
  const char *dir = argv[0], *out = NULL, *size = "1200x800";
  for (int i = 1; i < argc; ++i) {
    if (navsim_is_help(argv[i])) {
      fputs(k_usage_report, stdout);
      return RC_OK;
    } else if ((strcmp(argv[i], "--out") == 0 || strcmp(argv[i], "--size") == 0) && i + 1 < argc) {
      if (argv[i][2] == 'o') out = argv[++i];
      else size = argv[++i];
    } else {
      fprintf(stderr, "navsim report: unknown or incomplete option \"%s\" (see navsim report --help)\n", argv[i]);
      return RC_INVALID;
    }
  }
  if (!is_dir(dir)) {
    fprintf(stderr, "%s: error: not a result directory (navsim run --out DIR writes one)\n", dir);
    return RC_FAIL;
  }
  if (navsim_refuse_special_result_files(dir) != 0) return RC_INVALID;
  {
    const int src = check_summary(dir);
    if (src != 0) return src;
  }
  char out_dir[4096], page[4300], tmp_page[4400];
  const size_t ol = out ? strlen(out) : 0;
  if (out && ol > 5 && strcmp(out + ol - 5, ".html") == 0) {
    snprintf(page, sizeof page, "%s", out);
    snprintf(out_dir, sizeof out_dir, "%s", out);
    char *slash = strrchr(out_dir, '/');
    if (slash) *slash = '\0';
    else snprintf(out_dir, sizeof out_dir, ".");
  } else {
    snprintf(out_dir, sizeof out_dir, "%s", out ? out : dir);
    if (!out) strncat(out_dir, "/report", sizeof out_dir - strlen(out_dir) - 1);
    snprintf(page, sizeof page, "%s/report.html", out_dir);
  }
  {
    struct stat sb;
    if (stat(out_dir, &sb) == 0 && !S_ISDIR(sb.st_mode)) {
      fprintf(stderr,
              "navsim report: --out \"%s\" is a file, not a directory: give a directory (the page is DIR/report.html) "
              "or a FILE.html\n",
              out_dir);
      return RC_INVALID;
    }
  }
  if (mkdir_p(out_dir) != 0) {
    fprintf(stderr, "navsim report: cannot create \"%s\": %s\n", out_dir, strerror(errno));
    return RC_FAIL;
  }

  char path[4300], in_csv[4300];
  snprintf(path, sizeof path, "%s/summary.json", dir);
  char *summary = read_all(path, NULL);
  snprintf(path, sizeof path, "%s/imu_errors.csv", dir);
  const bool have_imu = is_file(path);
  snprintf(path, sizeof path, "%s/allan.csv", dir);
  const bool have_allan = is_file(path);
  snprintf(path, sizeof path, "%s/bench.csv", dir);
  const bool have_bench = is_file(path);
  snprintf(path, sizeof path, "%s/truth.csv", dir);
  const bool have_truth = is_file(path);
  snprintf(path, sizeof path, "%s/tradeoff.csv", dir);
  const bool have_tradeoff = is_file(path);

  figure figs[] = {
      {"3d", "3D view", "Reference (black) and estimated path (red), GNSS fixes (green) and outages (pink), "
                        "attitude triads (error exaggerated 20\xc3\x97), error-envelope tube and covariance "
                        "ellipsoids, the vehicle at the end of the run.", false},
      {"top", "Plan view, estimate coloured by horizontal error", "The estimated path coloured by the "
                                                                  "horizontal error of run 0, with its scale.", false},
      {"map", "Geodetic map", "Tracks in latitude/longitude over the offline background (Natural Earth / "
                              "GSHHS), graticule or local metric grid, scale bar.", false},
      {"map-region", "Geodetic map, regional scale", "Where the run is: 600 km across.", false},
      {"errors", "Errors against time", "Run 0 with the k\xcf\x83 bands (Monte Carlo RMS, filter \xcf\x83, "
                                        "covariance analysis) and the requirement limits.", false},
      {"noise", "Simulated sensor errors", "Measured minus ideal IMU output of run 0 (gyros, accelerometers).",
       false},
      {"allan", "Allan deviation", "Log-log, with slope guides.", false},
      {"bench", "Speed against error", "navsim bench: one panel per case, each marker labelled with its variant.", false},
      {"tradeoff", "Speed against error per modelling choice",
       "navsim tradeoff: CPU time per Monte Carlo run against each requirement's value with its 95 % "
       "bootstrap interval; green within the tolerance of the full model (dashed band), grey outside, the full "
       "model as a cross, the recommended variant as a blue diamond, the Pareto front in red.", false},
  };
  const int nfig = (int)(sizeof figs / sizeof figs[0]);
  int failures = 0;
  for (int k = 0; k < nfig; ++k) {
    figure *fg = &figs[k];
    const bool applicable = (strcmp(fg->key, "noise") == 0   ? have_imu
                             : strcmp(fg->key, "allan") == 0 ? have_allan
                             : strcmp(fg->key, "bench") == 0 ? have_bench
                             : strcmp(fg->key, "tradeoff") == 0 ? have_tradeoff
                                                             : have_truth);
    if (!applicable) continue;
    snprintf(path, sizeof path, "%s/%s.png", out_dir, fg->key);
    argvec v;
    av_init(&v);
    if (strcmp(fg->key, "allan") == 0 || strcmp(fg->key, "bench") == 0 || strcmp(fg->key, "tradeoff") == 0) {
      snprintf(in_csv, sizeof in_csv, "%s/%s.csv", dir, fg->key);
      av_add(&v, fg->key[0] == 'a' ? "--allan" : fg->key[0] == 'b' ? "--speed-vs-error" : "--tradeoff");
      av_add(&v, in_csv);
    } else {
      av_add(&v, dir);
      av_add(&v, "--view");
      av_add(&v, strcmp(fg->key, "map-region") == 0 ? "map" : fg->key);
      if (strcmp(fg->key, "3d") == 0) {
        av_add(&v, "--exaggerate");
        av_add(&v, "20");
      } else if (strcmp(fg->key, "top") == 0) {
        av_add(&v, "--color-by-error");
      } else if (strcmp(fg->key, "map-region") == 0) {
        av_add(&v, "--map-span");
        av_add(&v, "600");
      }
    }
    av_add(&v, "--size");
    av_add(&v, size);
    av_add(&v, "--png");
    av_add(&v, path);
    const int rc = run_child(v.a, true);
    fg->ok = rc == 0 && file_size(path) > 1000;
    if (!fg->ok) {
      fprintf(stderr, "navsim report: figure %s failed (navview exit %d)\n", fg->key, rc);
      ++failures;
    }
  }

  snprintf(tmp_page, sizeof tmp_page, "%s.tmp-%ld", page, (long)getpid());
  FILE *f = fopen(tmp_page, "w");
  if (!f) {
    fprintf(stderr, "navsim report: cannot write \"%s\": %s\n", tmp_page, strerror(errno));
    free(summary);
    return RC_FAIL;
  }
  char name[512] = "", buf[512];
  if (!summary || !json_str(strstr(summary, "\"scene\""), "name", name, sizeof name)) {
    const char *s = strrchr(dir, '/');
    snprintf(name, sizeof name, "%s", s && s[1] ? s + 1 : dir);
  }
  fputs("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>navsim report: ", f);
  html_text(f, name);
  fputs("</title>\n<style>\nbody{font-family:'DejaVu Sans',sans-serif;margin:2em auto;max-width:1250px;color:#112;}\n"
        "h1{font-size:1.6em;margin-bottom:0.2em}h2{font-size:1.25em;margin-top:1.6em;border-bottom:1px solid #ccd}\n"
        "table{border-collapse:collapse;margin:0.6em 0}td,th{border:1px solid #ccd;padding:0.25em 0.7em;"
        "text-align:right}th{background:#eef0f6}td.l,th.l{text-align:left}\n.pass{color:#070;font-weight:bold}"
        ".fail{color:#b00;font-weight:bold}\nfigure{margin:1.2em 0}figure img{max-width:100%;border:1px solid #dde}"
        "figcaption{color:#334;margin-top:0.3em}\npre{background:#f6f7fa;padding:0.8em;overflow:auto;font-size:0.85em}"
        "\n</style>\n<script>\n"
        "/* Marks every figure as loaded (naturalWidth > 0) for the headless check. */\n"
        "window.addEventListener('load', function () {\n"
        "  var n = 0; for (var i = 0; i < document.images.length; ++i) {\n"
        "    var im = document.images[i]; var ok = im.complete && im.naturalWidth > 0;\n"
        "    im.setAttribute('data-loaded', ok ? 'yes' : 'no'); if (ok) ++n; }\n"
        "  document.body.setAttribute('data-images-loaded', String(n));\n"
        "});\n</script>\n</head><body>\n",
        f);
  fputs("<h1>", f);
  html_text(f, name);
  fputs("</h1>\n<p>navsim ", f);
  html_text(f, nav_version_string());
  fputs(" report of <code>", f);
  html_text(f, dir);
  fputs("</code></p>\n", f);

  /* Scene summary. */
  fputs("<h2>Scene</h2>\n<table>\n", f);
  static const char *skeys[] = {"seed", "runs", "earth_model", "gravity_model", "algorithm", "mechanization_frame",
                                "trajectory", "duration_s", "imu_rate_hz", "output_rate_hz"};
  if (summary) {
    for (size_t i = 0; i < sizeof skeys / sizeof skeys[0]; ++i) {
      double x;
      if (json_str(summary, skeys[i], buf, sizeof buf)) {
      } else if (json_num(summary, skeys[i], &x)) {
        snprintf(buf, sizeof buf, "%.10g", x);
      } else {
        continue;
      }
      fprintf(f, "<tr><th class=\"l\">%s</th><td class=\"l\">", skeys[i]);
      html_text(f, buf);
      fputs("</td></tr>\n", f);
    }
  } else {
    fputs("<tr><td class=\"l\">summary.json not found</td></tr>\n", f);
  }
  fputs("</table>\n", f);

  if (summary) write_setup(f, summary);

  /* Statistics. */
  char *stats = summary ? json_block(summary, "stats") : NULL;
  if (stats) {
    static const struct {
      const char *key, *label, *unit;
    } rows[] = {{"pos_err_h_m", "horizontal position", "m"},
                {"pos_err_v_m", "vertical position", "m"},
                {"vel_err_mps", "velocity", "m/s"},
                {"att_err_rad", "attitude", "rad"},
                {"yaw_err_rad", "yaw", "rad"}};
    fputs("<h2>Error statistics</h2>\n<p>Over every run and epoch (summary.json <code>stats</code>).</p>\n"
          "<table>\n<tr><th class=\"l\">error</th><th>RMS</th><th>max</th><th>95 %</th><th class=\"l\">unit</th>"
          "</tr>\n",
          f);
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; ++i) {
      char *blk = json_block(stats, rows[i].key);
      if (!blk) continue;
      double rms = 0, mx = 0, p95 = 0;
      json_num(blk, "rms", &rms);
      json_num(blk, "max", &mx);
      json_num(blk, "p95", &p95);
      fprintf(f, "<tr><td class=\"l\">%s</td><td>%.4g</td><td>%.4g</td><td>%.4g</td><td class=\"l\">%s</td></tr>\n",
              rows[i].label, rms, mx, p95, rows[i].unit);
      free(blk);
    }
    fputs("</table>\n", f);
    char *fin = json_block(summary, "final");
    char *finr = json_block(summary, "final_rms_over_runs");
    if (fin) {
      double h = 0, vv = 0, ve = 0, at = 0;
      json_num(fin, "pos_err_h_m", &h);
      json_num(fin, "pos_err_v_m", &vv);
      json_num(fin, "vel_err_mps", &ve);
      json_num(fin, "att_err_rad", &at);
      fprintf(f, "<p>Final errors of run 0: horizontal %.4g m, vertical %.4g m, velocity %.4g m/s, attitude %.4g rad",
              h, vv, ve, at);
      if (finr && json_num(finr, "pos_err_h_m", &h) && json_num(finr, "pos_err_v_m", &vv))
        fprintf(f, "; RMS over runs: horizontal %.4g m, vertical %.4g m", h, vv);
      fputs(".</p>\n", f);
    }
    free(fin);
    free(finr);
    free(stats);
  }

  /* Requirement verdicts. */
  fputs("<h2>Requirements</h2>\n", f);
  char *req = summary ? json_block(summary, "requirements") : NULL;
  int nreq = 0, nfail = 0, nna = 0;
  if (req) {
    const char *p = req + 1;
    int depth = 0;
    const char *obj = NULL;
    bool str = false;
    for (; *p; ++p) {
      if (str) {
        if (*p == '\\' && p[1]) ++p;
        else if (*p == '"') str = false;
        continue;
      }
      if (*p == '"') str = true;
      else if (*p == '{' || *p == '[') {
        if (depth++ == 0 && *p == '{') obj = p;
      } else if (*p == '}' || *p == ']') {
        if (depth == 0) break;
        if (--depth == 0 && *p == '}' && obj) {
          const size_t n = (size_t)(p - obj) + 1;
          char *o = malloc(n + 1);
          if (!o) break;
          memcpy(o, obj, n);
          o[n] = '\0';
          char id[128] = "", metric[64] = "", stat[64] = "", unit[32] = "";
          double limit = 0, value = 0;
          json_str(o, "id", id, sizeof id);
          json_str(o, "metric", metric, sizeof metric);
          json_str(o, "statistic", stat, sizeof stat);
          json_str(o, "unit", unit, sizeof unit);
          json_num(o, "limit", &limit);
          const bool have_value = json_num(o, "value", &value);
          const char *ps = strstr(o, "\"pass\"");
          const bool pass = ps && strncmp(ps + 6 + strspn(ps + 6, ": "), "true", 4) == 0;
          /* A verdict without data says so (issue 25): "evaluated": false and its reason. */
          const char *pe = strstr(o, "\"evaluated\"");
          const bool na = pe && strncmp(pe + 11 + strspn(pe + 11, ": "), "false", 5) == 0;
          char reason[160] = "";
          if (na) json_str(o, "reason", reason, sizeof reason);
          if (nreq == 0)
            fputs("<table>\n<tr><th class=\"l\">id</th><th class=\"l\">metric</th><th class=\"l\">statistic</th>"
                  "<th>value</th><th>limit</th><th class=\"l\">unit</th><th class=\"l\">verdict</th></tr>\n",
                  f);
          fputs("<tr><td class=\"l\">", f);
          html_text(f, id);
          fputs("</td><td class=\"l\">", f);
          html_text(f, metric);
          fputs("</td><td class=\"l\">", f);
          html_text(f, stat);
          if (have_value) fprintf(f, "</td><td>%.4g</td>", value);
          else fputs("</td><td>&ndash;</td>", f);
          fprintf(f, "<td>%.4g</td><td class=\"l\">", limit);
          html_text(f, unit);
          if (na) {
            fputs("</td><td class=\"l\">not evaluated", f);
            if (reason[0]) {
              fputs(": ", f);
              html_text(f, reason);
            }
            fputs("</td></tr>\n", f);
          } else {
            fprintf(f, "</td><td class=\"l %s\">%s</td></tr>\n", pass ? "pass" : "fail", pass ? "pass" : "FAIL");
          }
          ++nreq;
          if (na) ++nna;
          else if (!pass) ++nfail;
          free(o);
          obj = NULL;
        }
      }
    }
    if (nreq > 0 && nna > 0)
      fprintf(f, "</table>\n<p>%d of %d requirements met, %d not evaluated.</p>\n", nreq - nfail - nna, nreq, nna);
    else if (nreq > 0)
      fprintf(f, "</table>\n<p>%d of %d requirements met.</p>\n", nreq - nfail, nreq);
    free(req);
  }
  if (nreq == 0) fputs("<p>The scene states no requirements.</p>\n", f);
  if (have_tradeoff) {
    snprintf(path, sizeof path, "%s/tradeoff.csv", dir);
    tradeoff_section(f, path, summary);
  }

  /* Figures, embedded. */
  fputs("<h2>Figures</h2>\n", f);
  for (int k = 0; k < nfig; ++k) {
    if (!figs[k].ok) continue;
    snprintf(path, sizeof path, "%s/%s.png", out_dir, figs[k].key);
    size_t n = 0;
    char *png = read_all(path, &n);
    if (!png) continue;
    fprintf(f, "<figure id=\"fig-%s\"><img alt=\"", figs[k].key);
    html_text(f, figs[k].title);
    fputs("\" src=\"data:image/png;base64,", f);
    base64(f, (const unsigned char *)png, n);
    fputs("\"><figcaption><b>", f);
    html_text(f, figs[k].title);
    fputs(".</b> ", f);
    html_text(f, figs[k].what);
    fprintf(f, " (<code>%s.png</code>)</figcaption></figure>\n", figs[k].key);
    free(png);
  }
  if (summary) {
    fputs("<h2>summary.json</h2>\n<details><summary>show</summary><pre>", f);
    html_text(f, summary);
    fputs("</pre></details>\n", f);
  }
  fputs("</body></html>\n", f);
  const bool bad = ferror(f) != 0;
  if (fclose(f) != 0 || bad || rename(tmp_page, page) != 0) {
    fprintf(stderr, "navsim report: writing \"%s\" failed\n", page);
    remove(tmp_page);
    free(summary);
    return RC_FAIL;
  }
  free(summary);
  int nok = 0;
  for (int k = 0; k < nfig; ++k) {
    nok += figs[k].ok ? 1 : 0;
    if (figs[k].ok) {
      snprintf(path, sizeof path, "%s/%s.png", out_dir, figs[k].key);
      record_output(dir, path);
    }
  }
  record_output(dir, page);
  printf("report     %s (%d figure%s%s)\n", page, nok, nok == 1 ? "" : "s", failures ? ", some failed" : "");
  return failures ? RC_FAIL : RC_OK;
}
