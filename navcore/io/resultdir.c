/* Result directories: built under a hidden temporary name, renamed into place when complete, and
 * never replacing anything navsim did not write.
 *
 * Ownership. Every committed result directory holds a manifest, ".navsim-result": a header line
 * and the relative path of every file navsim wrote into it (tools that add files later, such as
 * navsim render, report and export, append theirs with nav_resultdir_record). An existing path
 * is replaced only when it is absent, an empty directory, or a directory whose manifest lists
 * every file in it. A symbolic link, a file, or a directory holding anything else is refused
 * (or, with NAV_RESULTDIR_FORCE, renamed aside to "PATH.old-YYYYmmddTHHMMSS": moved, never
 * deleted). Nothing behind a symbolic link is ever deleted, and a previous result is deleted
 * file by file from its manifest, so a file that appears in it meanwhile survives (the old
 * directory is then renamed aside instead of removed). */
#define _GNU_SOURCE /* renameat2 (RENAME_EXCHANGE) */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "navcore/nav_results.h"

#define PATH_CAP 4096
#define MANIFEST ".navsim-result"
#define MANIFEST_HEAD "navsim result directory 1"
/* At most this many bytes of the final name go into the temporary and aside names, so that a
 * final name of up to NAME_MAX (255) bytes still has temporaries within NAME_MAX. */
#define BASE_IN_TMP 200
#define MANIFEST_MAX_BYTES (4 << 20)
#define WALK_DEPTH_MAX 8

struct nav_resultdir {
  char final_dir[PATH_CAP];
  char tmp_dir[PATH_CAP];
  char file[PATH_CAP + 256];
  unsigned flags;
};

static void say(char *msg, size_t cap, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void say(char *msg, size_t cap, const char *fmt, ...) {
  if (!msg || cap == 0) return;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, cap, fmt, ap);
  va_end(ap);
}

/* mkdir -p of every parent of @p path (not the last component). */
static int make_parents(const char *path) {
  char buf[PATH_CAP];
  if (snprintf(buf, sizeof buf, "%s", path) >= (int)sizeof buf) return -1;
  for (char *p = buf + 1; *p; ++p) {
    if (*p != '/') continue;
    *p = '\0';
    if (mkdir(buf, 0777) != 0 && errno != EEXIST) return -1;
    *p = '/';
  }
  return 0;
}

static void fsync_path(const char *path) {
  const int fd = open(path, O_RDONLY | O_NOFOLLOW);
  if (fd >= 0) {
    (void)fsync(fd);
    close(fd);
  }
}

/* ---- files two at a time --------------------------------------------------------------------- */

/* A list of paths and an operation on each, shared by the calling thread and one more. fsync and
 * unlink of a result's files mostly wait: for the disk (ext4 commits concurrent fsyncs together)
 * and for the kernel to drop a file's cached pages. Two at a time take about half as long, which
 * is a few milliseconds at the end of every run that writes or replaces a result. */
typedef struct path_list {
  char **paths;
  int n, cap;
  bool failed; /* a path could not be added (out of memory) */
} path_list;

static void path_list_add(path_list *l, const char *path) {
  if (l->n == l->cap) {
    const int cap = l->cap ? 2 * l->cap : 16;
    char **g = realloc(l->paths, (size_t)cap * sizeof *g);
    if (!g) {
      l->failed = true;
      return;
    }
    l->paths = g;
    l->cap = cap;
  }
  char *c = strdup(path);
  if (!c) {
    l->failed = true;
    return;
  }
  l->paths[l->n++] = c;
}

static void path_list_free(path_list *l) {
  for (int i = 0; i < l->n; ++i)
    free(l->paths[i]);
  free(l->paths);
  memset(l, 0, sizeof *l);
}

typedef struct path_pool {
  const path_list *list;
  void (*op)(const char *path);
  atomic_int next;
  pthread_t th;
  bool two;
} path_pool;

static void *path_pool_work(void *arg) {
  path_pool *p = arg;
  for (int i = atomic_fetch_add(&p->next, 1); i < p->list->n; i = atomic_fetch_add(&p->next, 1))
    p->op(p->list->paths[i]);
  return NULL;
}

/* Start op on the paths of @p l on a second thread (when there are two or more); the caller may
 * do other work, then path_pool_finish() helps and waits. */
static void path_pool_start(path_pool *p, const path_list *l, void (*op)(const char *path)) {
  p->list = l;
  p->op = op;
  atomic_init(&p->next, 0);
  p->two = l->n >= 2 && pthread_create(&p->th, NULL, path_pool_work, p) == 0;
}

static void path_pool_finish(path_pool *p) {
  (void)path_pool_work(p);
  if (p->two) (void)pthread_join(p->th, NULL);
}

/* Unlink a regular file (never through a link). */
static void unlink_regular(const char *path) {
  struct stat st;
  if (lstat(path, &st) == 0 && S_ISREG(st.st_mode)) (void)unlink(path);
}

/* ---- manifest ------------------------------------------------------------------------------ */

typedef struct manifest {
  char *text;    /* the file, lines split in place */
  char **names;  /* sorted relative paths */
  int n;
} manifest;

static void manifest_free(manifest *m) {
  free(m->text);
  free(m->names);
  memset(m, 0, sizeof *m);
}

static int cmp_str(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }

static bool manifest_has(const manifest *m, const char *rel) {
  return m->n > 0 && bsearch(&rel, m->names, (size_t)m->n, sizeof *m->names, cmp_str) != NULL;
}

/* A relative path navsim could have written: no leading '/', no "." or ".." component. */
static bool safe_rel(const char *rel) {
  if (!*rel || rel[0] == '/') return false;
  for (const char *p = rel; *p;) {
    const char *e = strchr(p, '/');
    const size_t n = e ? (size_t)(e - p) : strlen(p);
    if (n == 0 || (n == 1 && p[0] == '.') || (n == 2 && p[0] == '.' && p[1] == '.')) return false;
    p += n + (e ? 1 : 0);
  }
  return true;
}

/* Read DIR/.navsim-result. @return 1 read, 0 no manifest (absent), -1 present but not ours
 * (not a regular file, unreadable, too large, or without the header line). */
static int manifest_read(const char *dir, manifest *m) {
  memset(m, 0, sizeof *m);
  char path[PATH_CAP];
  if (snprintf(path, sizeof path, "%s/%s", dir, MANIFEST) >= (int)sizeof path) return -1;
  struct stat st;
  if (lstat(path, &st) != 0) return errno == ENOENT ? 0 : -1;
  if (!S_ISREG(st.st_mode) || st.st_size > MANIFEST_MAX_BYTES) return -1;
  const int fd = open(path, O_RDONLY | O_NOFOLLOW | O_NONBLOCK);
  if (fd < 0) return -1;
  m->text = malloc((size_t)st.st_size + 1);
  size_t len = 0;
  if (m->text) {
    ssize_t r;
    while (len < (size_t)st.st_size && (r = read(fd, m->text + len, (size_t)st.st_size - len)) > 0) len += (size_t)r;
    m->text[len] = '\0';
  }
  close(fd);
  if (!m->text) return -1;
  const size_t head = strlen(MANIFEST_HEAD);
  if (strncmp(m->text, MANIFEST_HEAD, head) != 0 || (m->text[head] != '\n' && m->text[head] != '\0')) {
    manifest_free(m);
    return -1;
  }
  int cap = 0;
  for (char *p = m->text; *p; ++p) cap += *p == '\n';
  m->names = calloc((size_t)cap + 1, sizeof *m->names);
  if (!m->names) {
    manifest_free(m);
    return -1;
  }
  char *line = m->text + head + (m->text[head] ? 1 : 0);
  while (*line) {
    char *nl = strchr(line, '\n');
    if (nl) *nl = '\0';
    if (safe_rel(line)) m->names[m->n++] = line;
    if (!nl) break;
    line = nl + 1;
  }
  qsort(m->names, (size_t)m->n, sizeof *m->names, cmp_str);
  return 1;
}

/* ---- directory walks ----------------------------------------------------------------------- */

/* What a walk of an existing directory found that navsim did not write. */
typedef struct unknown_list {
  int count;
  char first[3][160];
} unknown_list;

static void unknown_add(unknown_list *u, const char *rel, bool is_dir) {
  if (u->count < 3) snprintf(u->first[u->count], sizeof u->first[0], "%.150s%s", rel, is_dir ? "/" : "");
  ++u->count;
}

/* Every entry below @p dir (relative prefix @p rel) that the manifest does not list: regular
 * files must be listed; directories are walked (never through links); anything else is unknown.
 * @return the number of regular files found that the manifest lists. */
static int walk_unknown(const char *dir, const char *rel, const manifest *m, unknown_list *u, int depth) {
  DIR *d = opendir(dir);
  if (!d) {
    unknown_add(u, *rel ? rel : ".", true);
    return 0;
  }
  int known = 0;
  struct dirent *e;
  char child[PATH_CAP], child_rel[PATH_CAP];
  while ((e = readdir(d)) != NULL) {
    if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
    if (!*rel && !strcmp(e->d_name, MANIFEST)) continue;
    if (snprintf(child, sizeof child, "%s/%s", dir, e->d_name) >= (int)sizeof child ||
        snprintf(child_rel, sizeof child_rel, "%s%s%s", rel, *rel ? "/" : "", e->d_name) >= (int)sizeof child_rel) {
      unknown_add(u, e->d_name, false);
      continue;
    }
    struct stat st;
    if (lstat(child, &st) != 0) {
      unknown_add(u, child_rel, false);
    } else if (S_ISREG(st.st_mode)) {
      if (manifest_has(m, child_rel))
        ++known;
      else
        unknown_add(u, child_rel, false);
    } else if (S_ISDIR(st.st_mode) && depth < WALK_DEPTH_MAX) {
      const int before = u->count;
      const int k = walk_unknown(child, child_rel, m, u, depth + 1);
      /* A directory with nothing navsim wrote in it is not navsim's either. */
      if (k == 0 && u->count == before) unknown_add(u, child_rel, true);
      known += k;
    } else {
      unknown_add(u, child_rel, S_ISDIR(st.st_mode));
    }
  }
  closedir(d);
  return known;
}

/* Delete the files of a previous result listed in its manifest (regular files only, never
 * through a link), the manifest, then the emptied directories. @return 0 when @p dir itself is
 * gone, -1 when something navsim did not write kept it. */
static int remove_listed(const char *dir, const manifest *m) {
  char p[PATH_CAP];
  struct stat st;
  path_list files;
  memset(&files, 0, sizeof files);
  for (int i = 0; i < m->n; ++i) {
    if (snprintf(p, sizeof p, "%s/%s", dir, m->names[i]) >= (int)sizeof p) continue;
    path_list_add(&files, p);
  }
  path_pool pool;
  path_pool_start(&pool, &files, unlink_regular);
  path_pool_finish(&pool);
  path_list_free(&files);
  /* (Out of memory for the list: the files not in it keep the directory, which is then renamed
   * aside, as for any file navsim did not write.) */
  /* Sub-directories of listed files, deepest first (longest paths first is enough: a parent is
   * a prefix of its children). */
  for (int pass = 0; pass < WALK_DEPTH_MAX; ++pass) {
    bool any = false;
    for (int i = 0; i < m->n; ++i) {
      if (snprintf(p, sizeof p, "%s/%s", dir, m->names[i]) >= (int)sizeof p) continue;
      for (char *s = strrchr(p, '/'); s && s > p + strlen(dir); s = strrchr(p, '/')) {
        *s = '\0';
        if (lstat(p, &st) == 0 && S_ISDIR(st.st_mode) && rmdir(p) == 0) any = true;
      }
    }
    if (!any) break;
  }
  if (snprintf(p, sizeof p, "%s/%s", dir, MANIFEST) < (int)sizeof p && lstat(p, &st) == 0 && S_ISREG(st.st_mode))
    (void)unlink(p);
  return rmdir(dir) == 0 ? 0 : -1;
}

/* Remove a temporary directory this process created (or one left by a dead navsim process under
 * the temporary naming pattern): regular files and sub-directories, never through a link. */
static int remove_tmp(const char *path, int depth) {
  struct stat st;
  if (lstat(path, &st) != 0) return -1;
  if (!S_ISDIR(st.st_mode)) return -1;
  manifest m;
  if (depth == 0 && manifest_read(path, &m) == 1) {
    /* A previous result swapped out by RENAME_EXCHANGE: delete only what its manifest lists. */
    const int r = remove_listed(path, &m);
    manifest_free(&m);
    return r;
  }
  DIR *d = opendir(path);
  if (!d) return -1;
  struct dirent *e;
  char child[PATH_CAP];
  while ((e = readdir(d)) != NULL) {
    if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
    if (snprintf(child, sizeof child, "%s/%s", path, e->d_name) >= (int)sizeof child) continue;
    if (lstat(child, &st) != 0) continue;
    if (S_ISDIR(st.st_mode)) {
      if (depth < WALK_DEPTH_MAX) (void)remove_tmp(child, depth + 1);
    } else {
      (void)unlink(child);
    }
  }
  closedir(d);
  return rmdir(path);
}

/* Split @p path (trailing slashes already removed) into its directory part (dir_len bytes,
 * including the slash; 0 = current directory) and base name. */
static const char *base_of(const char *path, int *dir_len) {
  const char *slash = strrchr(path, '/');
  *dir_len = slash ? (int)(slash - path) + 1 : 0;
  return slash ? slash + 1 : path;
}

/* Remove the temporaries ".BASE.tmp-PID-*" beside @p path left by a process PID that no longer
 * exists (killed while writing). A PID that is alive, even if reused by another program, keeps
 * its directory. */
static void remove_stale(const char *path) {
  int dir_len;
  const char *base = base_of(path, &dir_len);
  char dir[PATH_CAP], prefix[PATH_CAP], child[PATH_CAP];
  snprintf(dir, sizeof dir, "%.*s", dir_len > 0 ? dir_len : 1, dir_len > 0 ? path : ".");
  if (snprintf(prefix, sizeof prefix, ".%.*s.tmp-", BASE_IN_TMP, base) >= (int)sizeof prefix) return;
  const size_t np = strlen(prefix);
  DIR *d = opendir(dir);
  if (!d) return;
  struct dirent *e;
  while ((e = readdir(d)) != NULL) {
    if (strncmp(e->d_name, prefix, np) != 0) continue;
    char *end = NULL;
    const long pid = strtol(e->d_name + np, &end, 10);
    if (pid <= 0 || !end || *end != '-' || pid == (long)getpid()) continue;
    if (kill((pid_t)pid, 0) == 0 || errno != ESRCH) continue;
    if (snprintf(child, sizeof child, "%s/%s", dir, e->d_name) < (int)sizeof child) (void)remove_tmp(child, 0);
  }
  closedir(d);
}

/* ---- checks -------------------------------------------------------------------------------- */

/* Copy @p final_dir without trailing slashes. */
static bool clean_path(const char *final_dir, char *out, size_t cap) {
  size_t len = strlen(final_dir);
  while (len > 1 && final_dir[len - 1] == '/')
    --len;
  if (len >= cap) return false;
  memcpy(out, final_dir, len);
  out[len] = '\0';
  return true;
}

static const char *how_to(unsigned flags) {
  (void)flags;
  return "give another --out, or add --force to move it aside (nothing is deleted)";
}

/* Does @p path (trailing slashes removed) accept a result? NAV_OK: absent, an empty directory,
 * or a result directory whose every file navsim wrote; NAV_ERR_INVALID_ARG: something else is
 * there (@p msg says what); NAV_ERR_IO: it cannot be examined. */
static nav_status check_path(const char *path, char *msg, size_t cap) {
  struct stat st;
  if (lstat(path, &st) != 0) {
    if (errno == ENOENT) return NAV_OK;
    say(msg, cap, "\"%s\": cannot examine it: %s", path, strerror(errno));
    return NAV_ERR_IO;
  }
  if (S_ISLNK(st.st_mode)) {
    say(msg, cap,
        "\"%s\" is a symbolic link; navsim neither writes through a link nor deletes what it points "
        "to: give the directory itself or another --out, or add --force to move the link aside",
        path);
    return NAV_ERR_INVALID_ARG;
  }
  if (!S_ISDIR(st.st_mode)) {
    say(msg, cap, "\"%s\" is %s, not a result directory: %s", path,
        S_ISREG(st.st_mode) ? "a file" : "not a directory", how_to(0));
    return NAV_ERR_INVALID_ARG;
  }
  manifest m;
  const int have = manifest_read(path, &m);
  unknown_list u = {0};
  if (have < 0) {
    say(msg, cap, "\"%s\" holds a \"%s\" that navsim did not write: %s", path, MANIFEST, how_to(0));
    return NAV_ERR_INVALID_ARG;
  }
  (void)walk_unknown(path, "", &m, &u, 0);
  manifest_free(&m);
  if (u.count == 0) return NAV_OK;
  char list[600] = "";
  for (int i = 0; i < u.count && i < 3; ++i) {
    const size_t n = strlen(list);
    snprintf(list + n, sizeof list - n, "%s%s", i ? ", " : "", u.first[i]);
  }
  if (u.count > 3) {
    const size_t n = strlen(list);
    snprintf(list + n, sizeof list - n, " and %d more", u.count - 3);
  }
  if (have == 1)
    say(msg, cap, "\"%s\" is a navsim result directory, but it also holds what navsim did not write (%s): %s",
        path, list, how_to(0));
  else
    say(msg, cap, "\"%s\" is not a navsim result directory (it holds %s): %s", path, list, how_to(0));
  return NAV_ERR_INVALID_ARG;
}

nav_status nav_resultdir_check(const char *final_dir, char *msg, size_t msg_cap) {
  if (msg && msg_cap) msg[0] = '\0';
  char path[PATH_CAP];
  if (!final_dir || !*final_dir) {
    say(msg, msg_cap, "the result directory is an empty name: give a directory name");
    return NAV_ERR_INVALID_ARG;
  }
  if (!clean_path(final_dir, path, sizeof path)) {
    say(msg, msg_cap, "the result directory's name is longer than %d bytes", PATH_CAP - 1);
    return NAV_ERR_INVALID_ARG;
  }
  int dir_len;
  const char *base = base_of(path, &dir_len);
  if (!strcmp(base, ".") || !strcmp(base, "..") || !strcmp(path, "/")) {
    say(msg, msg_cap, "\"%s\" cannot be a result directory (it names a directory by . or ..): give a new name",
        final_dir);
    return NAV_ERR_INVALID_ARG;
  }
  if (strlen(base) > 255) {
    say(msg, msg_cap, "\"%s\": the last name is %zu bytes long, more than a file name may be (255)", final_dir,
        strlen(base));
    return NAV_ERR_INVALID_ARG;
  }
  return check_path(path, msg, msg_cap);
}

/* A free name "PATH.old-YYYYmmddTHHMMSS[-N]" beside @p path. */
static bool aside_name(const char *path, char *out, size_t cap) {
  int dir_len;
  const char *base = base_of(path, &dir_len);
  char stamp[32];
  const time_t now = time(NULL);
  struct tm tmv;
  if (!localtime_r(&now, &tmv) || strftime(stamp, sizeof stamp, "%Y%m%dT%H%M%S", &tmv) == 0)
    snprintf(stamp, sizeof stamp, "%ld", (long)now);
  struct stat st;
  for (int k = 0; k < 1000; ++k) {
    char suffix[16] = "";
    if (k) snprintf(suffix, sizeof suffix, "-%d", k);
    if (snprintf(out, cap, "%.*s%.*s.old-%s%s", dir_len, path, BASE_IN_TMP, base, stamp, suffix) >= (int)cap)
      return false;
    if (lstat(out, &st) != 0 && errno == ENOENT) return true;
  }
  return false;
}

/* ---- begin / commit ------------------------------------------------------------------------ */

nav_status nav_resultdir_open(const char *final_dir, unsigned flags, nav_resultdir **out, char *msg,
                              size_t msg_cap) {
  if (msg && msg_cap) msg[0] = '\0';
  if (!out) return NAV_ERR_INVALID_ARG;
  *out = NULL;
  nav_status st = nav_resultdir_check(final_dir, msg, msg_cap);
  if (st == NAV_ERR_INVALID_ARG && (flags & NAV_RESULTDIR_FORCE) && final_dir && *final_dir) {
    /* With FORCE, only a name navsim can never use is still refused. */
    char path[PATH_CAP];
    struct stat sb;
    if (clean_path(final_dir, path, sizeof path) && lstat(path, &sb) == 0) st = NAV_OK;
  }
  if (st != NAV_OK) return st;
  nav_resultdir *rd = calloc(1, sizeof *rd);
  if (!rd) return NAV_ERR_NO_MEMORY;
  rd->flags = flags;
  (void)clean_path(final_dir, rd->final_dir, sizeof rd->final_dir);
  int dir_len;
  const char *base = base_of(rd->final_dir, &dir_len);
  if (snprintf(rd->tmp_dir, sizeof rd->tmp_dir, "%.*s.%.*s.tmp-%ld-XXXXXX", dir_len, rd->final_dir, BASE_IN_TMP,
               base, (long)getpid()) >= (int)sizeof rd->tmp_dir) {
    say(msg, msg_cap, "\"%s\": the name is too long for a temporary beside it", final_dir);
    free(rd);
    return NAV_ERR_INVALID_ARG;
  }
  if (make_parents(rd->tmp_dir) != 0 || !mkdtemp(rd->tmp_dir)) {
    say(msg, msg_cap, "cannot create a directory beside \"%s\": %s", final_dir, strerror(errno));
    free(rd);
    return NAV_ERR_IO;
  }
  remove_stale(rd->final_dir);
  *out = rd;
  return NAV_OK;
}

nav_status nav_resultdir_begin(const char *final_dir, nav_resultdir **out) {
  return nav_resultdir_open(final_dir, 0, out, NULL, 0);
}

const char *nav_resultdir_file(nav_resultdir *rd, const char *file_name) {
  if (!rd || !file_name) return NULL;
  const int n = snprintf(rd->file, sizeof rd->file, "%s/%s", rd->tmp_dir, file_name);
  return (n < 0 || n >= (int)sizeof rd->file) ? NULL : rd->file;
}

/* Append the regular files below @p dir (relative prefix @p rel) to @p f, one a line, and them and
 * the directories below @p dir to @p sync (to be fsynced). */
static int list_files(FILE *f, const char *dir, const char *rel, int depth, path_list *sync) {
  DIR *d = opendir(dir);
  if (!d) return -1;
  struct dirent *e;
  char child[PATH_CAP], child_rel[PATH_CAP];
  int rc = 0;
  while ((e = readdir(d)) != NULL) {
    if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
    if (!*rel && !strcmp(e->d_name, MANIFEST)) continue;
    if (snprintf(child, sizeof child, "%s/%s", dir, e->d_name) >= (int)sizeof child ||
        snprintf(child_rel, sizeof child_rel, "%s%s%s", rel, *rel ? "/" : "", e->d_name) >= (int)sizeof child_rel)
      continue;
    struct stat st;
    if (lstat(child, &st) != 0) continue;
    if (S_ISREG(st.st_mode)) {
      path_list_add(sync, child);
      if (fprintf(f, "%s\n", child_rel) < 0) rc = -1;
    } else if (S_ISDIR(st.st_mode) && depth < WALK_DEPTH_MAX) {
      if (list_files(f, child, child_rel, depth + 1, sync) != 0) rc = -1;
      path_list_add(sync, child);
    }
  }
  closedir(d);
  return rc;
}

static nav_status write_manifest(const char *dir) {
  char path[PATH_CAP];
  if (snprintf(path, sizeof path, "%s/%s", dir, MANIFEST) >= (int)sizeof path) return NAV_ERR_IO;
  FILE *f = fopen(path, "wx");
  if (!f) return NAV_ERR_IO;
  int rc = fprintf(f, "%s\n", MANIFEST_HEAD) < 0 ? -1 : 0;
  path_list sync;
  memset(&sync, 0, sizeof sync);
  if (list_files(f, dir, "", 0, &sync) != 0 || sync.failed) rc = -1;
  /* The files and directories are made durable on a second thread while this one writes and
   * syncs the manifest; all of it before the result is renamed into place. */
  path_pool pool;
  path_pool_start(&pool, &sync, fsync_path);
  if (fflush(f) != 0 || fsync(fileno(f)) != 0) rc = -1;
  if (fclose(f) != 0) rc = -1;
  path_pool_finish(&pool);
  path_list_free(&sync);
  return rc == 0 ? NAV_OK : NAV_ERR_IO;
}

/* The previous content of the final name now lies at @p old (a directory that passed the
 * check, or anything under FORCE): remove it when navsim wrote all of it, else rename it aside. */
static void dispose_old(const char *old, const char *final_dir, bool was_ours, char *msg, size_t cap) {
  struct stat st;
  if (lstat(old, &st) != 0) return;
  if (was_ours && S_ISDIR(st.st_mode)) {
    manifest m;
    const int have = manifest_read(old, &m);
    int r = -1;
    if (have == 1)
      r = remove_listed(old, &m);
    else if (have == 0)
      r = rmdir(old); /* an empty directory */
    manifest_free(&m);
    if (r == 0) return;
  }
  char aside[PATH_CAP + 64];
  if (aside_name(final_dir, aside, sizeof aside) && rename(old, aside) == 0) {
    say(msg, cap, "the previous content of \"%s\" was moved aside to \"%s\"", final_dir, aside);
    return;
  }
  say(msg, cap, "the previous content of \"%s\" was kept at \"%s\"", final_dir, old);
}

nav_status nav_resultdir_commit_msg(nav_resultdir *rd, char *msg, size_t msg_cap) {
  if (msg && msg_cap) msg[0] = '\0';
  if (!rd) return NAV_ERR_INVALID_ARG;
  nav_status st = write_manifest(rd->tmp_dir);
  if (st != NAV_OK) {
    say(msg, msg_cap, "cannot write the manifest of \"%s\": %s", rd->final_dir, strerror(errno));
    (void)remove_tmp(rd->tmp_dir, 0);
    free(rd);
    return st;
  }
  fsync_path(rd->tmp_dir);
  /* Check again: the final name may have changed while the result was computed. */
  char why[1024];
  const nav_status chk = check_path(rd->final_dir, why, sizeof why);
  const bool force = (rd->flags & NAV_RESULTDIR_FORCE) != 0;
  if (chk != NAV_OK && !force) {
    /* Keep the result under a visible name rather than lose the work. */
    char kept[PATH_CAP + 64];
    if (snprintf(kept, sizeof kept, "%s.new-%ld", rd->final_dir, (long)getpid()) < (int)sizeof kept &&
        rename(rd->tmp_dir, kept) == 0)
      say(msg, msg_cap, "%s; the new result is in \"%s\"", why, kept);
    else
      say(msg, msg_cap, "%s; the new result is in \"%s\"", why, rd->tmp_dir);
    free(rd);
    return chk;
  }
  struct stat sb;
  const bool exists = lstat(rd->final_dir, &sb) == 0;
  const bool ours = chk == NAV_OK;
#ifdef RENAME_EXCHANGE
  /* Linux: swap the new directory with the previous result in one step, so the final name holds
     the old or the new result at every instant (a kill never leaves neither). The temporary name
     then holds the previous content, removed file by file from its manifest. */
  if (exists && ours && S_ISDIR(sb.st_mode) &&
      renameat2(AT_FDCWD, rd->tmp_dir, AT_FDCWD, rd->final_dir, RENAME_EXCHANGE) == 0) {
    dispose_old(rd->tmp_dir, rd->final_dir, true, msg, msg_cap);
    free(rd);
    return NAV_OK;
  }
#endif
  char old[PATH_CAP + 64];
  bool have_old = false;
  if (exists) {
    /* Move the previous content aside first; rename(2) cannot replace a non-empty directory. */
    if (ours) {
      snprintf(old, sizeof old, "%s.old-%ld", rd->tmp_dir, (long)getpid());
    } else if (!aside_name(rd->final_dir, old, sizeof old)) {
      say(msg, msg_cap, "cannot find a free name to move \"%s\" aside", rd->final_dir);
      st = NAV_ERR_IO;
      goto fail;
    }
    if (rename(rd->final_dir, old) != 0) {
      say(msg, msg_cap, "cannot move \"%s\" aside: %s", rd->final_dir, strerror(errno));
      st = NAV_ERR_IO;
      goto fail;
    }
    have_old = true;
  }
  if (rename(rd->tmp_dir, rd->final_dir) != 0) {
    say(msg, msg_cap, "cannot rename the result into \"%s\": %s", rd->final_dir, strerror(errno));
    st = NAV_ERR_IO;
    if (have_old) (void)rename(old, rd->final_dir);
    goto fail;
  }
  if (have_old) {
    if (ours)
      dispose_old(old, rd->final_dir, true, msg, msg_cap);
    else
      say(msg, msg_cap, "the previous content of \"%s\" was moved aside to \"%s\"", rd->final_dir, old);
  }
  free(rd);
  return NAV_OK;
fail:
  (void)remove_tmp(rd->tmp_dir, 0);
  free(rd);
  return st;
}

nav_status nav_resultdir_commit(nav_resultdir *rd) { return nav_resultdir_commit_msg(rd, NULL, 0); }

void nav_resultdir_abort(nav_resultdir *rd) {
  if (!rd) return;
  (void)remove_tmp(rd->tmp_dir, 0);
  free(rd);
}

nav_status nav_resultdir_record(const char *result_dir, const char *rel_path) {
  if (!result_dir || !rel_path || !safe_rel(rel_path) || strchr(rel_path, '\n')) return NAV_ERR_INVALID_ARG;
  char path[PATH_CAP];
  if (!clean_path(result_dir, path, sizeof path)) return NAV_ERR_INVALID_ARG;
  manifest m;
  const int have = manifest_read(path, &m);
  if (have != 1) {
    manifest_free(&m);
    return NAV_ERR_INVALID_ARG; /* not a navsim result directory: nothing to record */
  }
  const bool listed = manifest_has(&m, rel_path);
  manifest_free(&m);
  if (listed) return NAV_OK;
  char mp[PATH_CAP];
  if (snprintf(mp, sizeof mp, "%s/%s", path, MANIFEST) >= (int)sizeof mp) return NAV_ERR_IO;
  const int fd = open(mp, O_WRONLY | O_APPEND | O_NOFOLLOW);
  if (fd < 0) return NAV_ERR_IO;
  char line[PATH_CAP + 2];
  const int n = snprintf(line, sizeof line, "%s\n", rel_path);
  const bool ok = n > 0 && n < (int)sizeof line && write(fd, line, (size_t)n) == (ssize_t)n;
  close(fd);
  return ok ? NAV_OK : NAV_ERR_IO;
}
