/*
 * --out never deletes what navsim did not write (issue 25): every command that writes a result
 * directory (run, estimate, budget, select, sweep, replay, allan, tradeoff) is given as --out an unrelated
 * folder with notes and a sub-folder, a file, a symbolic link to a folder, and the folder that
 * holds its own inputs. Each must exit 2 with a message that says what is there, and leave every
 * pre-existing file byte-identical and nothing new beside it (a canary tree is snapshotted before
 * and compared after). A previous result directory is still replaced, also after render, report
 * or export added files to it; --force moves the old content aside (nothing deleted); scene
 * names cannot lead a default directory outside out/.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <dirent.h>
#include <glob.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "nav_test.h"
#include "navsim_cli.h"

#define SCENE NAV_SOURCE_DIR "/scenes/paper-parametric.yaml"
#define REPLAY NAV_TEST_DATA_DIR "/replay"
#define RECORDED NAV_TEST_DATA_DIR "/recorded"
#define WORK NAV_TEST_WORK_DIR
#define navsim(cwd, args) nav_test_run_cli(NAVSIM_EXE, WORK, (cwd), (args))

/* ---- snapshots of a tree: every entry with its type, size and content (FNV-1a) -------------- */

typedef struct snap {
  char *text;
  size_t len, cap;
} snap;

static void snap_add(snap *s, const char *line) {
  const size_t n = strlen(line);
  if (s->len + n + 1 > s->cap) {
    s->cap = (s->len + n + 1) * 2 + 4096;
    s->text = realloc(s->text, s->cap);
    assert_non_null(s->text);
  }
  memcpy(s->text + s->len, line, n + 1);
  s->len += n;
}

static uint64_t fnv_file(const char *path) {
  FILE *f = fopen(path, "rb");
  if (!f) return 0;
  uint64_t h = 1469598103934665603ull;
  int c;
  while ((c = fgetc(f)) != EOF) h = (h ^ (uint64_t)(unsigned char)c) * 1099511628211ull;
  fclose(f);
  return h;
}

static int cmp_names(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }

/* Entries of @p dir (sorted), recursively, without following links. */
static void snap_tree(snap *s, const char *dir, const char *rel) {
  DIR *d = opendir(dir);
  if (!d) return;
  char *names[512];
  int n = 0;
  struct dirent *e;
  while ((e = readdir(d)) != NULL && n < 512)
    if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) names[n++] = strdup(e->d_name);
  closedir(d);
  qsort(names, (size_t)n, sizeof *names, cmp_names);
  for (int i = 0; i < n; ++i) {
    char path[4096], r[4096], line[8400];
    snprintf(path, sizeof path, "%s/%s", dir, names[i]);
    snprintf(r, sizeof r, "%s%s", rel, names[i]);
    struct stat st;
    if (lstat(path, &st) != 0) continue;
    if (S_ISLNK(st.st_mode)) {
      char target[4096] = "";
      const ssize_t k = readlink(path, target, sizeof target - 1);
      if (k > 0) target[k] = '\0';
      snprintf(line, sizeof line, "L %s -> %s\n", r, target);
      snap_add(s, line);
    } else if (S_ISDIR(st.st_mode)) {
      snprintf(line, sizeof line, "D %s\n", r);
      snap_add(s, line);
      char sub[4100];
      snprintf(sub, sizeof sub, "%s/", r);
      snap_tree(s, path, sub);
    } else {
      snprintf(line, sizeof line, "F %s %lld %016llx\n", r, (long long)st.st_size,
               (unsigned long long)fnv_file(path));
      snap_add(s, line);
    }
    free(names[i]);
  }
}

static char *snapshot(const char *dir) {
  snap s = {NULL, 0, 0};
  snap_add(&s, "");
  snap_tree(&s, dir, "");
  return s.text;
}

/* ---- fixtures ----------------------------------------------------------------------------- */

static void sh(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static void sh(const char *fmt, ...) {
  char cmd[8192];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(cmd, sizeof cmd, fmt, ap);
  va_end(ap);
  if (system(cmd) != 0) fail_msg("command failed: %s", cmd);
}

/* A canary tree in CASE: the target T (a folder of notes with a sub-folder, a file, a link to a
 * folder of notes, or the folder of the command's inputs) and a bystander folder. */
typedef enum target_kind { T_FOLDER, T_FILE, T_LINK, T_INPUTS } target_kind;
static const char *const k_kind_name[] = {"an unrelated folder", "a file", "a symbolic link to a folder",
                                          "the folder of the inputs"};

static void make_case(const char *cs, target_kind kind) {
  sh("rm -rf '%s' && mkdir -p '%s/bystander'", cs, cs);
  sh("printf 'keep me\\n' > '%s/bystander/notes.txt'", cs);
  switch (kind) {
  case T_FOLDER:
    sh("mkdir -p '%s/T/sub' && printf 'precious\\n' > '%s/T/notes.txt' && printf 'deep\\n' > '%s/T/sub/deep.txt'", cs,
       cs, cs);
    break;
  case T_FILE:
    sh("printf 'a file, not a folder\\n' > '%s/T'", cs);
    break;
  case T_LINK:
    sh("mkdir -p '%s/linked' && printf 'behind the link\\n' > '%s/linked/a.txt' && ln -s linked '%s/T'", cs, cs, cs);
    break;
  case T_INPUTS:
    sh("mkdir -p '%s/T' && cp '" SCENE "' '%s/T/scene.yaml' && cp '" REPLAY "/IMU-100195-100245.txt' '" REPLAY
       "/GNSS-100195-100245.txt' '%s/T/' && cp '" RECORDED "/adis16465-truth-116454-116754.nav' '%s/T/truth.nav'",
       cs, cs, cs, cs);
    break;
  }
}

/* The command line of CMD writing into CASE/T, its inputs in CASE/T for T_INPUTS. */
static void command_line(char *buf, size_t cap, const char *cmd, const char *cs, target_kind kind) {
  char scene[4200];
  snprintf(scene, sizeof scene, "'%s%s'", kind == T_INPUTS ? cs : SCENE, kind == T_INPUTS ? "/T/scene.yaml" : "");
  if (!strcmp(cmd, "replay")) {
    if (kind == T_INPUTS)
      snprintf(buf, cap, "replay --imu '%s/T/IMU-100195-100245.txt' --gnss '%s/T/GNSS-100195-100245.txt' --truth "
               "'%s/T/truth.nav' --out '%s/T' --quiet", cs, cs, cs, cs);
    else
      snprintf(buf, cap, "replay --imu '" REPLAY "/IMU-100195-100245.txt' --truth '" RECORDED
               "/adis16465-truth-116454-116754.nav' --out '%s/T' --quiet", cs);
  } else if (!strcmp(cmd, "allan")) {
    if (kind == T_INPUTS)
      snprintf(buf, cap, "allan %s --duration 30 --out '%s/T' --quiet", scene, cs);
    else
      snprintf(buf, cap, "allan --imu ADIS16465-1 --duration 30 --out '%s/T' --quiet", cs);
  } else if (!strcmp(cmd, "select")) {
    snprintf(buf, cap, "select %s --imus ADIS16465-1 --out '%s/T' --quiet", scene, cs);
  } else if (!strcmp(cmd, "sweep")) {
    snprintf(buf, cap, "sweep %s --param simulation.seed=1:2:2 --predict --out '%s/T' --quiet", scene, cs);
  } else {
    snprintf(buf, cap, "%s %s --out '%s/T' --quiet", cmd, scene, cs);
  }
}

static const char *const k_commands[] = {"run", "estimate", "budget", "select", "sweep", "replay", "allan", "tradeoff"};

static int setup(void **state) {
  (void)state;
  return nav_test_fresh_dir(WORK);
}

/* ---- tests -------------------------------------------------------------------------------- */

static void test_every_command_refuses_what_is_not_its_own(void **state) {
  (void)state;
  for (size_t c = 0; c < sizeof k_commands / sizeof *k_commands; ++c) {
    for (int k = T_FOLDER; k <= T_INPUTS; ++k) {
      char cs[1024], line[9000];
      snprintf(cs, sizeof cs, WORK "/%s-%d", k_commands[c], k);
      make_case(cs, (target_kind)k);
      char *before = snapshot(cs);
      command_line(line, sizeof line, k_commands[c], cs, (target_kind)k);
      nav_cli_result *r = navsim(cs, line);
      char *after = snapshot(cs);
      if (r->code != 2)
        fail_msg("navsim %s --out %s: exit %d, expected 2\nstderr: %s", k_commands[c], k_kind_name[k], r->code,
                 r->err);
      if (strcmp(before, after) != 0)
        fail_msg("navsim %s --out %s changed the tree:\nbefore:\n%s\nafter:\n%s", k_commands[c], k_kind_name[k],
                 before, after);
      /* The message says what is there and how to proceed. */
      nav_test_assert_matches(r->err, "--out: .*(is a file|symbolic link|not a navsim result directory)");
      nav_test_assert_matches(r->err, "another --out|--force");
      free(before);
      free(after);
    }
  }
}

static void test_previous_result_replaced_even_with_exported_files(void **state) {
  (void)state;
  const char *cs = WORK "/replace";
  sh("rm -rf '%s' && mkdir -p '%s'", cs, cs);
  assert_int_equal(navsim(cs, "run '" SCENE "' --out R --quiet --seed 3")->code, 0);
  assert_true(nav_test_is_file(WORK "/replace/R/.navsim-result"));
  /* export adds tracks.kml / tracks.csv and lists them in the manifest. */
  assert_int_equal(navsim(cs, "export R")->code, 0);
  assert_true(nav_test_is_file(WORK "/replace/R/tracks.kml"));
  char manifest[4096];
  nav_test_slurp(WORK "/replace/R/.navsim-result", manifest, sizeof manifest);
  nav_test_assert_matches(manifest, "^tracks\\.kml$");
  nav_test_assert_matches(manifest, "^truth\\.csv$");
  nav_cli_result *r = navsim(cs, "run '" SCENE "' --out R --quiet --seed 4");
  assert_int_equal(r->code, 0);
  assert_false(nav_test_is_file(WORK "/replace/R/tracks.kml"));
  assert_true(nav_test_is_file(WORK "/replace/R/summary.json"));
  /* Nothing but R in the folder: no temporary, no aside copy. */
  char *tree = snapshot(cs);
  assert_null(strstr(tree, ".tmp-"));
  assert_null(strstr(tree, ".old-"));
  free(tree);
  /* A note the user put into a result directory makes it the user's: refused, note kept. */
  nav_test_write_file(WORK "/replace/R", "my-notes.txt", "mine\n");
  r = navsim(cs, "run '" SCENE "' --out R --quiet --seed 5");
  assert_int_equal(r->code, 2);
  nav_test_assert_matches(r->err, "navsim result directory, but it also holds .*my-notes\\.txt");
  assert_true(nav_test_is_file(WORK "/replace/R/my-notes.txt"));
  /* An empty directory is replaced (nothing to lose). */
  sh("mkdir -p '%s/E'", cs);
  assert_int_equal(navsim(cs, "estimate '" SCENE "' --out E --quiet")->code, 0);
  assert_true(nav_test_is_file(WORK "/replace/E/estimate.json"));
}

/* The one entry CASE/T.old-* (fails when there is none or several). */
static void aside_path(const char *cs, char *out, size_t cap) {
  char pat[1200];
  snprintf(pat, sizeof pat, "%s/T.old-*", cs);
  glob_t g;
  if (glob(pat, 0, NULL, &g) != 0 || g.gl_pathc != 1) fail_msg("expected one %s", pat);
  snprintf(out, cap, "%s", g.gl_pathv[0]);
  globfree(&g);
}

static void test_force_moves_aside_never_deletes(void **state) {
  (void)state;
  const char *cs = WORK "/force";
  for (int k = T_FOLDER; k <= T_LINK; ++k) {
    make_case(cs, (target_kind)k);
    char *by_before = snapshot(WORK "/force/bystander");
    char t_before[256] = "";
    struct stat st;
    assert_int_equal(lstat(WORK "/force/T", &st), 0);
    char *tree_before = S_ISDIR(st.st_mode) ? snapshot(WORK "/force/T") : NULL;
    if (S_ISLNK(st.st_mode)) assert_true(readlink(WORK "/force/T", t_before, sizeof t_before - 1) > 0);
    const uint64_t h_before = S_ISREG(st.st_mode) ? fnv_file(WORK "/force/T") : 0;
    nav_cli_result *r = navsim(cs, "run '" SCENE "' --out T --quiet --force");
    assert_int_equal(r->code, 0);
    nav_test_assert_matches(r->err, "moved aside to \".*T\\.old-[0-9]{8}T[0-9]{6}\"");
    assert_true(nav_test_is_file(WORK "/force/T/summary.json"));
    char aside[1300];
    aside_path(cs, aside, sizeof aside);
    if (tree_before) {
      char *tree_after = snapshot(aside);
      assert_string_equal(tree_before, tree_after);
      free(tree_after);
    } else if (t_before[0]) {
      char t_after[256] = "";
      assert_true(readlink(aside, t_after, sizeof t_after - 1) > 0);
      assert_string_equal(t_before, t_after);
      char *linked = snapshot(WORK "/force/linked");
      assert_non_null(strstr(linked, "F a.txt "));
      free(linked);
    } else {
      assert_true(fnv_file(aside) == h_before);
    }
    char *by_after = snapshot(WORK "/force/bystander");
    assert_string_equal(by_before, by_after);
    free(by_before);
    free(by_after);
    free(tree_before);
  }
}

static void test_names_and_paths(void **state) {
  (void)state;
  const char *cs = WORK "/names";
  sh("rm -rf '%s' && mkdir -p '%s/a/b/cwd'", cs, cs);
  /* A scene named to climb out of out/: estimate and budget clean the name as run does. */
  sh("sed 's|^name: .*|name: ../../../../victim|' '" SCENE "' > '%s/a/b/cwd/climb.yaml'", cs);
  assert_int_equal(system("grep -q '^name: ../../../../victim' '" WORK "/names/a/b/cwd/climb.yaml'"), 0);
  const char *const cmds[] = {"estimate", "budget", "run"};
  for (int i = 0; i < 3; ++i) {
    char line[256];
    snprintf(line, sizeof line, "%s climb.yaml --quiet", cmds[i]);
    nav_cli_result *r = navsim(WORK "/names/a/b/cwd", line);
    assert_int_equal(r->code, 0);
  }
  char *tree = snapshot(cs);
  /* Nothing named after the scene outside out/ (the name climbs to CASE itself). */
  assert_null(strstr(tree, "D victim"));
  assert_null(strstr(tree, "/victim"));
  assert_non_null(strstr(tree, "D a/b/cwd/out/.._.._.._.._victim-estimate\n"));
  assert_non_null(strstr(tree, "D a/b/cwd/out/.._.._.._.._victim-budget\n"));
  free(tree);
  /* An empty --out says so. */
  nav_cli_result *r = navsim(cs, "run '" SCENE "' --out '' --quiet");
  assert_int_equal(r->code, 2);
  nav_test_assert_matches(r->err, "empty name");
  /* A 250-character name works (its temporary name stays within NAME_MAX). */
  char name[251];
  memset(name, 'n', 250);
  name[250] = '\0';
  char line[600];
  snprintf(line, sizeof line, "run '" SCENE "' --out %s --quiet", name);
  r = navsim(cs, line);
  if (r->code != 0) fail_msg("--out of 250 characters: exit %d: %s", r->code, r->err);
  char path[700];
  snprintf(path, sizeof path, "%s/%s/summary.json", cs, name);
  assert_true(nav_test_is_file(path));
  /* report --out an existing file: exit 2, the file untouched. */
  nav_test_write_file(cs, "page", "not a directory\n");
  snprintf(line, sizeof line, "report %s --out page", name);
  r = navsim(cs, line);
  assert_int_equal(r->code, 2);
  nav_test_assert_matches(r->err, "is a file, not a directory");
  char page[64];
  nav_test_slurp(WORK "/names/page", page, sizeof page);
  assert_string_equal(page, "not a directory\n");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_every_command_refuses_what_is_not_its_own),
      cmocka_unit_test(test_previous_result_replaced_even_with_exported_files),
      cmocka_unit_test(test_force_moves_aside_never_deletes),
      cmocka_unit_test(test_names_and_paths),
  };
  return cmocka_run_group_tests(tests, setup, NULL);
}
