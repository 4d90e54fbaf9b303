/*
 * Scenes in navsim serve: the check of a submitted scene (the library's reader, as navsim check),
 * the refusal of fields that name files, the sensor catalogs as JSON and the scene library.
 */
#define _GNU_SOURCE
#include "serve_internal.h"

#include <dirent.h>
#include <errno.h>
#include <libfyaml.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "navcore/nav_catalog.h"
#include "navcore/nav_io.h"
#include "navcore/nav_paths.h"
#include "navcore/nav_sensors.h"

/* ------------------------------------------------------------------ fields that name files */

/*
 * A scene may name files (trajectory.recorded.file, trajectory.motion_def.file,
 * gnss.constellation.almanac) that its reader opens relative to the scene. A server must read no
 * file a client names: such mapping keys are refused before the reader sees the text. The rule is
 * wide on purpose (any key "file", "*_file" or "almanac" at any depth) so that a field added later
 * is refused too. Only the event stream is read (aliases are never expanded); a text that is not
 * YAML is left to the reader, which stops at the syntax error before opening anything.
 */
#define SCAN_MAX_DEPTH 64

typedef struct scan_frame {
  bool is_map, want_key;
  char key[64];
} scan_frame;

static bool names_a_file(const char *key, size_t n) {
  if (n == 4 && memcmp(key, "file", 4) == 0) return true;
  if (n == 7 && memcmp(key, "almanac", 7) == 0) return true;
  return n > 5 && memcmp(key + n - 5, "_file", 5) == 0;
}

static void add_diag(serve_diags *d, int line, int col, const char *path, const char *msg) {
  if (d->n >= SERVE_MAX_DIAGS) return;
  serve_diag *e = &d->d[d->n++];
  e->line = line;
  e->col = col;
  snprintf(e->path, sizeof e->path, "%s", path);
  snprintf(e->message, sizeof e->message, "%s", msg);
}

static void frame_path(const scan_frame *st, int depth, const char *last, char *out, size_t size) {
  size_t n = 0;
  out[0] = '\0';
  for (int i = 0; i + 1 < depth; ++i) { /* the ancestors: each frame's key holds the child */
    if (!st[i].is_map || st[i].key[0] == '\0') continue;
    const int w = snprintf(out + n, size - n, "%s%s", n ? "." : "", st[i].key);
    if (w < 0 || (size_t)w >= size - n) return;
    n += (size_t)w;
  }
  snprintf(out + n, size - n, "%s%s", n ? "." : "", last);
}

/* Child node done in the frame on top: a map alternates key and value. */
static void node_done(scan_frame *st, int depth) {
  if (depth > 0 && st[depth - 1].is_map) st[depth - 1].want_key = !st[depth - 1].want_key;
}

static bool scan_file_fields(const char *text, size_t len, serve_diags *diags) {
  struct fy_parse_cfg cfg;
  memset(&cfg, 0, sizeof cfg);
  cfg.flags = (enum fy_parse_cfg_flags)(FYPCF_QUIET | FYPCF_DEFAULT_VERSION_1_2 | FYPCF_JSON_NONE);
  struct fy_parser *fyp = fy_parser_create(&cfg);
  if (!fyp) return true; /* no memory: the reader will say so */
  bool ok = true;
  scan_frame st[SCAN_MAX_DEPTH];
  int depth = 0;
  if (fy_parser_set_string(fyp, text, len) != 0) goto cleanup;
  for (;;) {
    struct fy_event *ev = fy_parser_parse(fyp);
    if (!ev) break;
    const struct fy_mark *m = fy_event_start_mark(ev);
    const int line = m ? m->line + 1 : 0, col = m ? m->column + 1 : 0;
    switch (ev->type) {
    case FYET_MAPPING_START:
    case FYET_SEQUENCE_START:
      if (depth > 0 && st[depth - 1].is_map && st[depth - 1].want_key) st[depth - 1].key[0] = '\0';
      if (depth >= SCAN_MAX_DEPTH) {
        add_diag(diags, line, col, "", "nesting is too deep for a scene file");
        ok = false;
        break;
      }
      st[depth].is_map = ev->type == FYET_MAPPING_START;
      st[depth].want_key = true;
      st[depth].key[0] = '\0';
      ++depth;
      break;
    case FYET_MAPPING_END:
    case FYET_SEQUENCE_END:
      if (depth > 0) --depth;
      node_done(st, depth);
      break;
    case FYET_SCALAR:
    case FYET_ALIAS:
      if (ev->type == FYET_SCALAR && depth > 0 && st[depth - 1].is_map && st[depth - 1].want_key) {
        size_t n = 0;
        const char *k = fy_token_get_text(ev->scalar.value, &n);
        if (k && names_a_file(k, n)) {
          char path[256], key[64];
          snprintf(key, sizeof key, "%.*s", (int)(n < 63 ? n : 63), k);
          frame_path(st, depth, key, path, sizeof path);
          char msg[512];
          snprintf(msg, sizeof msg,
                   "navsim serve reads no file named in a scene (%s): give the data in the scene itself, or "
                   "run this scene with navsim on your machine",
                   path);
          add_diag(diags, line, col, path, msg);
          ok = false;
        }
        if (depth > 0)
          snprintf(st[depth - 1].key, sizeof st[depth - 1].key, "%.*s", (int)(n < 63 ? n : 63), k ? k : "");
      } else if (depth > 0 && st[depth - 1].is_map && st[depth - 1].want_key) {
        st[depth - 1].key[0] = '\0';
      }
      node_done(st, depth);
      break;
    default: break;
    }
    fy_parser_event_free(fyp, ev);
    if (depth >= SCAN_MAX_DEPTH && !ok) break;
  }
cleanup:
  fy_parser_destroy(fyp);
  return ok;
}

/* ------------------------------------------------------------------ the check of a scene */

static pthread_mutex_t g_check_mu = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t g_check_cv = PTHREAD_COND_INITIALIZER;
static int g_check_free = 4;

void serve_checks_init(int max) {
  g_check_free = max > 0 ? max : 1;
}

void serve_check_enter(void) {
  pthread_mutex_lock(&g_check_mu);
  while (g_check_free == 0)
    pthread_cond_wait(&g_check_cv, &g_check_mu);
  --g_check_free;
  pthread_mutex_unlock(&g_check_mu);
}

void serve_check_leave(void) {
  pthread_mutex_lock(&g_check_mu);
  ++g_check_free;
  pthread_cond_signal(&g_check_cv);
  pthread_mutex_unlock(&g_check_mu);
}

static void collect(void *user, const nav_diag *d) {
  add_diag(user, d->line, d->col, d->path, d->message);
}

bool serve_scene_check(const char *text, size_t len, const char *tmp_dir, nav_scene *scene,
                       serve_diags *diags) {
  diags->n = 0;
  if (!scan_file_fields(text, len, diags)) return false;
  char path[SERVE_PATH_MAX + 32];
  snprintf(path, sizeof path, "%s/scene-XXXXXX.yaml", tmp_dir);
  const int fd = mkstemps(path, 5);
  if (fd < 0) {
    add_diag(diags, 0, 0, "", "the server cannot store the scene for checking");
    return false;
  }
  size_t off = 0;
  while (off < len) {
    const ssize_t w = write(fd, text + off, len - off);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) break;
    off += (size_t)w;
  }
  close(fd);
  nav_scene *sc = scene ? scene : malloc(sizeof *sc);
  bool ok = false;
  if (off != len || !sc) {
    add_diag(diags, 0, 0, "", "the server cannot store the scene for checking");
  } else {
    const nav_status st = nav_scene_read_file_to_run(path, sc, collect, diags);
    ok = st == NAV_OK;
    /* The callers free the scene with free(): it must own no heap data. A scene with heap data
     * (a fitted recorded reference) names a file, which scan_file_fields refused above; the
     * release makes that hold whatever the scan lets through. */
    if (ok) nav_scene_release(sc);
    if (!ok && diags->n == 0) add_diag(diags, 0, 0, "", nav_status_str(st));
  }
  unlink(path);
  if (sc != scene) free(sc);
  return ok;
}

char *serve_diags_json(const serve_diags *diags, const char *error, size_t *len) {
  sbuf b = {0};
  sb_puts(&b, "{\"ok\":false,\"error\":");
  sb_json_str(&b, error);
  sb_puts(&b, ",\"errors\":[");
  for (int i = 0; i < diags->n; ++i) {
    const serve_diag *d = &diags->d[i];
    sb_printf(&b, "%s{\"line\":%d,\"col\":%d,\"path\":", i ? "," : "", d->line, d->col);
    sb_json_str(&b, d->path);
    sb_puts(&b, ",\"message\":");
    sb_json_str(&b, d->message);
    sb_puts(&b, "}");
  }
  sb_puts(&b, "]}\n");
  return sb_take(&b, len);
}

/* ------------------------------------------------------------------ catalogs */

/* Datasheet units of the catalog terms (the inverse factors of nav_sensors.h, for display). */
static void num_or_null(sbuf *b, const char *key, bool on, double v) {
  const bool first = b->len > 0 && b->s[b->len - 1] == '{';
  sb_printf(b, "%s\"%s\":", first ? "" : ",", key);
  if (on)
    sb_json_num(b, v);
  else
    sb_puts(b, "null");
}

static char *imu_json(const nav_catalog *cat) {
  sbuf b = {0};
  const double rps_to_dph = 1.0 / nav_unit_deg_per_h_to_rps(1.0);
  const double arw_to_dpsh = 1.0 / nav_unit_deg_per_sqrt_h_to_rad_per_sqrt_s(1.0);
  sb_puts(&b, "[");
  for (size_t i = 0; i < nav_catalog_count(cat); ++i) {
    const nav_catalog_imu_entry *e = nav_catalog_imu_at(cat, i);
    const nav_gyro_error_config *g = &e->config.gyro;
    const nav_accel_error_config *a = &e->config.accel;
    sb_puts(&b, i ? ",\n{\"name\":" : "\n{\"name\":");
    sb_json_str(&b, e->name);
    sb_puts(&b, ",\"grade\":");
    sb_json_str(&b, e->grade);
    sb_printf(&b, ",\"cost_class\":%d,\"cost_band\":", e->cost_class);
    sb_json_str(&b, nav_catalog_cost_band(e->cost_class));
    sb_puts(&b, ",\"bias_model\":");
    sb_json_str(&b, nav_catalog_bias_model_name(e->bias_model));
    sb_puts(&b, ",\"verified\":");
    sb_json_str(&b, nav_catalog_verification_name(e->verified));
    sb_puts(&b, ",\"verified_text\":");
    sb_json_str(&b, e->verified_text);
    sb_puts(&b, ",\"source\":");
    sb_json_str(&b, e->source);
    sb_puts(&b, ",\"gyro\":{");
    num_or_null(&b, "arw_deg_per_sqrt_h", g->terms & NAV_IMU_TERM_NOISE,
                g->arw_rad_per_sqrt_s.x * arw_to_dpsh);
    num_or_null(&b, "bias_gm_deg_per_h", g->terms & NAV_IMU_TERM_BIAS_GM, g->bias_gm_sd_rps.x * rps_to_dph);
    num_or_null(&b, "bias_gm_tau_s", g->terms & NAV_IMU_TERM_BIAS_GM, g->bias_gm_tau_s.x);
    num_or_null(&b, "bias_turn_on_deg_per_h", g->terms & NAV_IMU_TERM_BIAS_TURN_ON,
                g->bias_turn_on_sd_rps.x * rps_to_dph);
    num_or_null(&b, "scale_factor_ppm", g->terms & NAV_IMU_TERM_SCALE_FACTOR, g->scale_factor_sd.x * 1e6);
    sb_puts(&b, "},\"accel\":{");
    num_or_null(&b, "vrw_mps_per_sqrt_h", a->terms & NAV_IMU_TERM_NOISE, a->vrw_mps_per_sqrt_s.x * 60.0);
    num_or_null(&b, "bias_gm_ug", a->terms & NAV_IMU_TERM_BIAS_GM,
                a->bias_gm_sd_mps2.x / nav_unit_ug_to_mps2(1.0));
    num_or_null(&b, "bias_gm_tau_s", a->terms & NAV_IMU_TERM_BIAS_GM, a->bias_gm_tau_s.x);
    num_or_null(&b, "bias_turn_on_mg", a->terms & NAV_IMU_TERM_BIAS_TURN_ON,
                a->bias_turn_on_sd_mps2.x / nav_unit_mg_to_mps2(1.0));
    num_or_null(&b, "scale_factor_ppm", a->terms & NAV_IMU_TERM_SCALE_FACTOR, a->scale_factor_sd.x * 1e6);
    sb_puts(&b, "}");
    num_or_null(&b, "misalignment_mrad", g->terms & NAV_IMU_TERM_MISALIGNMENT,
                g->misalignment_sd_rad.m[0][1] * 1e3);
    sb_puts(&b, "}");
  }
  sb_puts(&b, "\n]\n");
  return sb_take(&b, NULL);
}

static char *gnss_json(const nav_catalog *cat) {
  sbuf b = {0};
  sb_puts(&b, "[");
  for (size_t i = 0; i < nav_catalog_count(cat); ++i) {
    const nav_catalog_gnss_entry *e = nav_catalog_gnss_at(cat, i);
    const nav_gnss_model_config *c = &e->config;
    sb_puts(&b, i ? ",\n{\"name\":" : "\n{\"name\":");
    sb_json_str(&b, e->name);
    sb_printf(&b, ",\"cost_class\":%d,\"cost_band\":", e->cost_class);
    sb_json_str(&b, nav_catalog_cost_band(e->cost_class));
    sb_puts(&b, ",\"verified\":");
    sb_json_str(&b, nav_catalog_verification_name(e->verified));
    sb_puts(&b, ",\"verified_text\":");
    sb_json_str(&b, e->verified_text);
    sb_puts(&b, ",\"source\":");
    sb_json_str(&b, e->source);
    num_or_null(&b, "pos_sd_n_m", true, c->pos_gm_sd_m.x);
    num_or_null(&b, "pos_sd_e_m", true, c->pos_gm_sd_m.y);
    num_or_null(&b, "pos_sd_d_m", true, c->pos_gm_sd_m.z);
    num_or_null(&b, "pos_tau_s", true, c->pos_gm_tau_s.x);
    num_or_null(&b, "vel_sd_mps", c->terms & NAV_GNSS_TERM_VEL_WHITE, c->vel_sd_mps.x);
    num_or_null(&b, "update_rate_hz", true, c->update_rate_hz);
    sb_puts(&b, "}");
  }
  sb_puts(&b, "\n]\n");
  return sb_take(&b, NULL);
}

static void catalog_diag(void *user, const nav_diag *d) {
  char *why = user;
  if (why[0] == '\0') nav_diag_format(d, why, 512);
}

bool serve_catalogs_load(char **imu, char **gnss, char *why, size_t why_size) {
  char res[SERVE_PATH_MAX], path[SERVE_PATH_MAX + 64];
  *imu = *gnss = NULL;
  if (!nav_paths_resources_dir(res, sizeof res)) {
    snprintf(why, why_size, "the resources directory (catalogs) is not found; set NAV_SHARE_DIR");
    return false;
  }
  const nav_catalog_options opt = nav_catalog_options_default();
  const char *files[2] = {"imu_catalog.csv", "gnss_receivers.csv"};
  for (int k = 0; k < 2; ++k) {
    snprintf(path, sizeof path, "%s/%s", res, files[k]);
    nav_catalog *cat = NULL;
    char msg[512] = "";
    if (nav_catalog_load(path, &opt, &cat, catalog_diag, msg) != NAV_OK) {
      snprintf(why, why_size, "%s: %s", path, msg[0] ? msg : "cannot be read");
      free(*imu);
      *imu = NULL;
      return false;
    }
    char *j = k == 0 ? imu_json(cat) : gnss_json(cat);
    nav_catalog_destroy(cat);
    if (!j) {
      snprintf(why, why_size, "out of memory");
      free(*imu);
      *imu = NULL;
      return false;
    }
    *(k == 0 ? imu : gnss) = j;
  }
  return true;
}

/* ------------------------------------------------------------------ the scene library */

static bool safe_stem(const char *file, char *stem, size_t size) {
  const size_t n = strlen(file);
  if (n < 6 || n - 5 >= size || strcmp(file + n - 5, ".yaml") != 0) return false;
  for (size_t i = 0; i < n - 5; ++i) {
    const char c = file[i];
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' || c == '_')) return false;
  }
  snprintf(stem, size, "%.*s", (int)(n - 5), file);
  return true;
}

/* The leading comment block of a scene file, as one paragraph. */
static void description(const char *text, sbuf *out) {
  const char *p = text;
  bool any = false;
  while (*p == '#') {
    const char *e = strchr(p, '\n');
    const size_t n = e ? (size_t)(e - p) : strlen(p);
    const char *s = p + 1;
    size_t m = n - 1;
    while (m > 0 && *s == ' ') {
      ++s;
      --m;
    }
    if (m > 0 && out->len < 4000) {
      if (any) sb_puts(out, " ");
      sb_add(out, s, m);
      any = true;
    }
    if (!e) break;
    p = e + 1;
  }
}

static int by_name(const void *a, const void *b) {
  return strcmp(((const serve_scene_entry *)a)->name, ((const serve_scene_entry *)b)->name);
}

bool serve_library_load(serve_library *lib, const char *tmp_dir, char *why, size_t why_size) {
  memset(lib, 0, sizeof *lib);
  char dir[SERVE_PATH_MAX];
  if (!nav_paths_scenes_dir(dir, sizeof dir)) {
    snprintf(why, why_size, "the scene library directory is not found; set NAV_SHARE_DIR");
    return false;
  }
  DIR *d = opendir(dir);
  if (!d) {
    snprintf(why, why_size, "%s: %s", dir, strerror(errno));
    return false;
  }
  int cap = 0;
  struct dirent *de;
  while ((de = readdir(d)) != NULL) {
    serve_scene_entry e;
    if (!safe_stem(de->d_name, e.name, sizeof e.name)) continue;
    if (snprintf(e.path, sizeof e.path, "%s/%s", dir, de->d_name) >= (int)sizeof e.path) continue;
    if (lib->n == cap) {
      cap = cap ? 2 * cap : 32;
      serve_scene_entry *p = realloc(lib->e, (size_t)cap * sizeof *p);
      if (!p) break;
      lib->e = p;
    }
    lib->e[lib->n++] = e;
  }
  closedir(d);
  if (lib->n > 0) qsort(lib->e, (size_t)lib->n, sizeof *lib->e, by_name);
  /* Keep the scenes the server can run: valid, and naming no file. */
  sbuf b = {0};
  sb_puts(&b, "[");
  nav_scene *sc = malloc(sizeof *sc);
  serve_diags *diags = malloc(sizeof *diags);
  int kept = 0;
  for (int i = 0; sc && diags && i < lib->n; ++i) {
    size_t len = 0;
    char *text = serve_read_file(lib->e[i].path, 1u << 20, &len);
    const bool ok = text && serve_scene_check(text, len, tmp_dir, sc, diags);
    if (ok) {
      lib->e[kept] = lib->e[i];
      sb_puts(&b, kept ? ",\n{\"name\":" : "\n{\"name\":");
      sb_json_str(&b, lib->e[i].name);
      sb_puts(&b, ",\"title\":");
      sb_json_str(&b, sc->name);
      sb_puts(&b, ",\"scheme\":");
      sb_json_str(&b, nav_nav_scheme_name(sc->navigation.scheme));
      sb_puts(&b, ",\"duration_s\":");
      sb_json_num(&b, sc->trajectory.duration_s);
      sb_printf(&b, ",\"runs\":%ld,\"description\":", sc->simulation.runs);
      sbuf desc = {0};
      description(text, &desc);
      sb_json_str(&b, desc.s ? desc.s : "");
      sb_free(&desc);
      sb_puts(&b, "}");
      ++kept;
    }
    free(text);
  }
  free(sc);
  free(diags);
  lib->n = kept;
  sb_puts(&b, "\n]\n");
  lib->json = sb_take(&b, NULL);
  if (!lib->json) {
    snprintf(why, why_size, "out of memory");
    return false;
  }
  return true;
}

void serve_library_free(serve_library *lib) {
  free(lib->e);
  free(lib->json);
  memset(lib, 0, sizeof *lib);
}
