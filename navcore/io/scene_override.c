/*
 * Scene overrides "PATH=VALUE" on the parsed YAML document (nav_scene_override.h). The document
 * is edited with libfyaml's node API and emitted, and the emitted text goes through the
 * table-driven scene reader (scene_read.c): there is no second reader of scene fields.
 */
#define _POSIX_C_SOURCE 200809L

#include <ctype.h>
#include <libfyaml.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "navcore/nav_io.h"
#include "navcore/nav_scene_override.h"

struct nav_scene_doc {
  struct fy_document *fyd;
  char *path;
};

static void say(char *msg, size_t size, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static void say(char *msg, size_t size, const char *fmt, ...) {
  if (!msg || !size) return;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, size, fmt, ap);
  va_end(ap);
}

nav_status nav_scene_doc_load(const char *path, nav_scene_doc **out, char *msg, size_t msg_size) {
  if (msg && msg_size) msg[0] = '\0';
  if (!path || !out) return NAV_ERR_INVALID_ARG;
  *out = NULL;
  FILE *f = NULL;
  char why[320];
  const nav_status open_st = nav_io_fopen_regular(path, &f, why, sizeof why);
  if (open_st != NAV_OK) {
    if (open_st == NAV_ERR_PARSE)
      say(msg, msg_size, "%s", why); /* a FIFO, device or directory */
    else
      say(msg, msg_size, "cannot open the scene file");
    return open_st;
  }
  fclose(f);
  struct fy_parse_cfg cfg;
  memset(&cfg, 0, sizeof cfg);
  cfg.flags = (enum fy_parse_cfg_flags)(FYPCF_QUIET | FYPCF_DEFAULT_VERSION_1_2 | FYPCF_JSON_NONE);
  struct fy_document *fyd = fy_document_build_from_file(&cfg, path);
  if (!fyd) {
    say(msg, msg_size, "not a YAML document (navsim check %s says where)", path);
    return NAV_ERR_PARSE;
  }
  struct fy_node *root = fy_document_root(fyd);
  if (!root || !fy_node_is_mapping(root)) {
    fy_document_destroy(fyd);
    say(msg, msg_size, "the scene file's root is not a mapping");
    return NAV_ERR_PARSE;
  }
  nav_scene_doc *d = calloc(1, sizeof *d);
  char *p = strdup(path);
  if (!d || !p) {
    free(d);
    free(p);
    fy_document_destroy(fyd);
    return NAV_ERR_NO_MEMORY;
  }
  d->fyd = fyd;
  d->path = p;
  *out = d;
  return NAV_OK;
}

void nav_scene_doc_destroy(nav_scene_doc *doc) {
  if (!doc) return;
  fy_document_destroy(doc->fyd);
  free(doc->path);
  free(doc);
}

static bool key_char(char c) { return isalnum((unsigned char)c) || c == '_' || c == '-'; }

nav_status nav_scene_doc_set(nav_scene_doc *doc, const char *path, const char *value, char *msg, size_t msg_size) {
  if (msg && msg_size) msg[0] = '\0';
  if (!doc || !path || !value) return NAV_ERR_INVALID_ARG;
  struct fy_document *fyd = doc->fyd;
  struct fy_node *cur = fy_document_root(fyd);
  const char *p = path;
  if (!*p) {
    say(msg, msg_size, "empty path");
    return NAV_ERR_INVALID_ARG;
  }
  while (*p) {
    /* One key, then any [i] indices. */
    const char *k0 = p;
    while (key_char(*p)) ++p;
    const size_t klen = (size_t)(p - k0);
    if (klen == 0) {
      say(msg, msg_size, "%s: expected a key at \"%s\" (keys are letters, digits, _ and -, joined by dots)", path, k0);
      return NAV_ERR_INVALID_ARG;
    }
    int idx[8], nidx = 0;
    while (*p == '[') {
      char *end = NULL;
      const long v = strtol(p + 1, &end, 10);
      if (end == p + 1 || *end != ']' || v < 0 || v > 1000000 || nidx >= 8) {
        say(msg, msg_size, "%s: malformed index at \"%s\" (expected [N], N >= 0)", path, p);
        return NAV_ERR_INVALID_ARG;
      }
      idx[nidx++] = (int)v;
      p = end + 1;
    }
    const bool last = *p == '\0';
    if (!last && *p != '.') {
      say(msg, msg_size, "%s: unexpected \"%s\" (expected '.', '[' or the end)", path, p);
      return NAV_ERR_INVALID_ARG;
    }
    if (!last) ++p;
    if (!fy_node_is_mapping(cur)) {
      say(msg, msg_size, "%s: \"%.*s\" is looked up in a value that is not a mapping", path, (int)klen, k0);
      return NAV_ERR_INVALID_ARG;
    }
    struct fy_node_pair *pair = fy_node_mapping_lookup_pair_by_string(cur, k0, klen);
    const bool leaf = last && nidx == 0;
    if (!pair) {
      if (nidx > 0) {
        say(msg, msg_size, "%s: \"%.*s\" is not in the scene, so it has no item [%d]", path, (int)klen, k0, idx[0]);
        return NAV_ERR_INVALID_ARG;
      }
      struct fy_node *key = fy_node_create_scalar_copy(fyd, k0, klen);
      struct fy_node *val = leaf ? fy_node_create_scalar_copy(fyd, value, strlen(value)) : fy_node_create_mapping(fyd);
      if (!key || !val || fy_node_mapping_append(cur, key, val) != 0) return NAV_ERR_NO_MEMORY;
      if (leaf) return NAV_OK;
      cur = val;
      continue;
    }
    if (leaf) {
      struct fy_node *val = fy_node_create_scalar_copy(fyd, value, strlen(value));
      if (!val || fy_node_pair_set_value(pair, val) != 0) return NAV_ERR_NO_MEMORY;
      return NAV_OK;
    }
    cur = fy_node_pair_value(pair);
    for (int i = 0; i < nidx; ++i) {
      if (!fy_node_is_sequence(cur)) {
        say(msg, msg_size, "%s: \"%.*s\" is not a list, so it has no item [%d]", path, (int)klen, k0, idx[i]);
        return NAV_ERR_INVALID_ARG;
      }
      const int n = fy_node_sequence_item_count(cur);
      if (idx[i] >= n) {
        say(msg, msg_size, "%s: index [%d] out of range (\"%.*s\" has %d items)", path, idx[i], (int)klen, k0, n);
        return NAV_ERR_INVALID_ARG;
      }
      if (last && i == nidx - 1) {
        /* Replace the list item itself. */
        struct fy_node *val = fy_node_create_scalar_copy(fyd, value, strlen(value));
        struct fy_node *old = fy_node_sequence_get_by_index(cur, idx[i]);
        if (!val) return NAV_ERR_NO_MEMORY;
        if (fy_node_sequence_insert_after(cur, old, val) != 0) return NAV_ERR_NO_MEMORY;
        fy_node_free(fy_node_sequence_remove(cur, old));
        return NAV_OK;
      }
      cur = fy_node_sequence_get_by_index(cur, idx[i]);
    }
  }
  say(msg, msg_size, "%s: the path ends in a list or mapping", path);
  return NAV_ERR_INVALID_ARG;
}

nav_status nav_scene_doc_read(const nav_scene_doc *doc, nav_scene *out, nav_diag_fn report, void *user) {
  if (!doc || !out) return NAV_ERR_INVALID_ARG;
  char *text = fy_emit_document_to_string(doc->fyd, (enum fy_emitter_cfg_flags)(FYECF_MODE_BLOCK | FYECF_WIDTH_INF));
  if (!text) return NAV_ERR_NO_MEMORY;
  const nav_status st = nav_scene_read_string(text, strlen(text), doc->path, out, report, user);
  free(text);
  return st;
}

nav_status nav_scene_override_split(const char *text, char *path, size_t path_size, char *value, size_t value_size) {
  if (!text || !path || !value || !path_size || !value_size) return NAV_ERR_INVALID_ARG;
  const char *eq = strchr(text, '=');
  if (!eq || eq == text || eq[1] == '\0') return NAV_ERR_INVALID_ARG;
  const size_t pl = (size_t)(eq - text), vl = strlen(eq + 1);
  if (pl >= path_size || vl >= value_size) return NAV_ERR_INVALID_ARG;
  memcpy(path, text, pl);
  path[pl] = '\0';
  memcpy(value, eq + 1, vl + 1);
  return NAV_OK;
}
