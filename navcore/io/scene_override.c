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
  char *text; /* the source of a document loaded from memory (libfyaml points into it), or NULL */
  /* Nodes that nav_scene_doc_set created: they are not in the file, so a diagnostic about them
     has no place in it (see nav_scene_doc_read). */
  struct fy_node **created;
  size_t ncreated, capcreated;
};

/* Remember @p n as created by an override; false when out of memory. */
static bool remember(nav_scene_doc *doc, struct fy_node *n) {
  if (!n) return true;
  if (doc->ncreated == doc->capcreated) {
    const size_t cap = doc->capcreated ? 2 * doc->capcreated : 16;
    struct fy_node **c = realloc(doc->created, cap * sizeof *c);
    if (!c) return false;
    doc->created = c;
    doc->capcreated = cap;
  }
  doc->created[doc->ncreated++] = n;
  return true;
}

/* @p n is about to be freed: drop it (the list stays as long as the overrides, not the calls). */
static void forget(nav_scene_doc *doc, const struct fy_node *n) {
  for (size_t i = 0; i < doc->ncreated; ++i)
    if (doc->created[i] == n) {
      doc->created[i] = doc->created[--doc->ncreated];
      return;
    }
}

static bool was_created(const nav_scene_doc *doc, const struct fy_node *n) {
  for (size_t i = 0; i < doc->ncreated; ++i)
    if (doc->created[i] == n) return true;
  return false;
}

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

/* A parsed document with a mapping at its root becomes a nav_scene_doc named @p name. */
static nav_status doc_from(struct fy_document *fyd, const char *name, nav_scene_doc **out, char *msg,
                           size_t msg_size) {
  struct fy_node *root = fy_document_root(fyd);
  if (!root || !fy_node_is_mapping(root)) {
    fy_document_destroy(fyd);
    say(msg, msg_size, "the scene file's root is not a mapping");
    return NAV_ERR_PARSE;
  }
  nav_scene_doc *d = calloc(1, sizeof *d);
  char *p = strdup(name);
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

nav_status nav_scene_doc_load_string(const char *text, size_t len, const char *display_name,
                                     nav_scene_doc **out, char *msg, size_t msg_size) {
  if (msg && msg_size) msg[0] = '\0';
  if (!text || !display_name || !out) return NAV_ERR_INVALID_ARG;
  *out = NULL;
  /* libfyaml keeps pointers into its input: the document keeps its own copy */
  char *copy = malloc(len + 1);
  if (!copy) return NAV_ERR_NO_MEMORY;
  memcpy(copy, text, len);
  copy[len] = '\0';
  struct fy_parse_cfg cfg;
  memset(&cfg, 0, sizeof cfg);
  cfg.flags = (enum fy_parse_cfg_flags)(FYPCF_QUIET | FYPCF_DEFAULT_VERSION_1_2 | FYPCF_JSON_NONE);
  struct fy_document *fyd = fy_document_build_from_string(&cfg, copy, len);
  if (!fyd) {
    free(copy);
    say(msg, msg_size, "not a YAML document");
    return NAV_ERR_PARSE;
  }
  const nav_status st = doc_from(fyd, display_name, out, msg, msg_size);
  if (st != NAV_OK)
    free(copy);
  else
    (*out)->text = copy;
  return st;
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
  return doc_from(fyd, path, out, msg, msg_size);
}

void nav_scene_doc_destroy(nav_scene_doc *doc) {
  if (!doc) return;
  fy_document_destroy(doc->fyd);
  free(doc->text); /* after the document that points into it */
  free(doc->path);
  free(doc->created);
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
      if (!remember(doc, key) || !remember(doc, val)) return NAV_ERR_NO_MEMORY;
      if (leaf) return NAV_OK;
      cur = val;
      continue;
    }
    if (leaf) {
      struct fy_node *val = fy_node_create_scalar_copy(fyd, value, strlen(value));
      struct fy_node *prev = fy_node_pair_value(pair);
      if (!val || fy_node_pair_set_value(pair, val) != 0) return NAV_ERR_NO_MEMORY;
      forget(doc, prev);
      return remember(doc, val) ? NAV_OK : NAV_ERR_NO_MEMORY;
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
        forget(doc, old);
        fy_node_free(fy_node_sequence_remove(cur, old));
        return remember(doc, val) ? NAV_OK : NAV_ERR_NO_MEMORY;
      }
      cur = fy_node_sequence_get_by_index(cur, idx[i]);
    }
  }
  say(msg, msg_size, "%s: the path ends in a list or mapping", path);
  return NAV_ERR_INVALID_ARG;
}

/*
 * Places in the emitted document -> places in the scene file. The emitter writes every mapping and
 * list in block style and drops comments, so its lines are not the file's: the emitted text is
 * parsed again and walked together with the edited document (same shape), and each scalar (keys
 * included) gives one entry: where it is in the emitted text, and where it was in the file, or
 * that an override created it (not in the file at all).
 */
typedef struct place {
  int emit_line, emit_col; /* 1-based */
  int line, col;           /* 1-based; 0 for a node created by an override */
} place;

typedef struct place_map {
  place *p;
  size_t n, cap;
  bool oom;
} place_map;

static void place_add(place_map *m, struct fy_node *emitted, struct fy_node *orig, bool created) {
  struct fy_token *te = fy_node_get_scalar_token(emitted);
  const struct fy_mark *me = te ? fy_token_start_mark(te) : NULL;
  if (!me) return;
  int line = 0, col = 0;
  if (!created) {
    struct fy_token *to = fy_node_get_scalar_token(orig);
    const struct fy_mark *mo = to ? fy_token_start_mark(to) : NULL;
    if (!mo) return; /* no place known: the diagnostic keeps no place rather than a wrong one */
    line = mo->line + 1;
    col = mo->column + 1;
  }
  if (m->n == m->cap) {
    const size_t cap = m->cap ? 2 * m->cap : 256;
    place *q = realloc(m->p, cap * sizeof *q);
    if (!q) {
      m->oom = true;
      return;
    }
    m->p = q;
    m->cap = cap;
  }
  m->p[m->n++] = (place){me->line + 1, me->column + 1, line, col};
}

static void place_walk(const nav_scene_doc *doc, place_map *m, struct fy_node *emitted, struct fy_node *orig,
                       bool created, int depth) {
  if (!emitted || !orig || depth > 256 || m->oom) return;
  created = created || was_created(doc, orig);
  if (fy_node_is_scalar(emitted) && fy_node_is_scalar(orig)) {
    place_add(m, emitted, orig, created);
  } else if (fy_node_is_sequence(emitted) && fy_node_is_sequence(orig)) {
    void *ie = NULL, *io = NULL;
    struct fy_node *a, *b;
    while ((a = fy_node_sequence_iterate(emitted, &ie)) != NULL && (b = fy_node_sequence_iterate(orig, &io)) != NULL)
      place_walk(doc, m, a, b, created, depth + 1);
  } else if (fy_node_is_mapping(emitted) && fy_node_is_mapping(orig)) {
    void *ie = NULL, *io = NULL;
    struct fy_node_pair *a, *b;
    while ((a = fy_node_mapping_iterate(emitted, &ie)) != NULL && (b = fy_node_mapping_iterate(orig, &io)) != NULL) {
      place_walk(doc, m, fy_node_pair_key(a), fy_node_pair_key(b), created, depth + 1);
      place_walk(doc, m, fy_node_pair_value(a), fy_node_pair_value(b), created, depth + 1);
    }
  }
}

typedef struct place_relay {
  const place_map *m;
  nav_diag_fn report;
  void *user;
} place_relay;

/* A diagnostic at an emitted place, moved to the file's place: the entry at that exact place, else
   the last one on its line at or before its column, else the first one on its line. No entry: no
   place (line 0), never a line of the emitted text. */
static void relay_diag(void *user, const nav_diag *d) {
  const place_relay *r = user;
  nav_diag c = *d;
  if (d->line > 0) {
    const place *best = NULL;
    for (size_t i = 0; i < r->m->n; ++i) {
      const place *p = &r->m->p[i];
      if (p->emit_line != d->line) continue;
      if (p->emit_col == d->col) {
        best = p;
        break;
      }
      if (!best || (p->emit_col <= d->col && (best->emit_col > d->col || p->emit_col > best->emit_col)))
        best = p;
    }
    c.line = best ? best->line : 0;
    c.col = best ? best->col : 0;
  }
  if (r->report) r->report(r->user, &c);
}

nav_status nav_scene_doc_read(const nav_scene_doc *doc, nav_scene *out, nav_diag_fn report, void *user) {
  if (!doc || !out) return NAV_ERR_INVALID_ARG;
  char *text = fy_emit_document_to_string(doc->fyd, (enum fy_emitter_cfg_flags)(FYECF_MODE_BLOCK | FYECF_WIDTH_INF));
  if (!text) return NAV_ERR_NO_MEMORY;
  place_map m = {NULL, 0, 0, false};
  struct fy_parse_cfg cfg;
  memset(&cfg, 0, sizeof cfg);
  cfg.flags = (enum fy_parse_cfg_flags)(FYPCF_QUIET | FYPCF_DEFAULT_VERSION_1_2 | FYPCF_JSON_NONE);
  struct fy_document *emitted = fy_document_build_from_string(&cfg, text, strlen(text));
  if (emitted) place_walk(doc, &m, fy_document_root(emitted), fy_document_root(doc->fyd), false, 0);
  nav_status st = NAV_ERR_NO_MEMORY;
  if (emitted && !m.oom) {
    place_relay relay = {&m, report, user};
    st = nav_scene_read_string(text, strlen(text), doc->path, out, relay_diag, &relay);
  }
  fy_document_destroy(emitted);
  free(m.p);
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
