/*
 * navsim run under MPI (issue 9 item 4): `mpirun -np K navsim run SCENE --runs N` gives the same
 * result directory, byte for byte, as the threaded run with the same seed, for 2 ranks x 1 thread
 * and for a hybrid 3 ranks x 2 threads (oversubscribed on this machine) and more ranks than runs;
 * the scene's requirement verdicts in summary.json cover every rank's runs; only rank 0 writes; a
 * failure on every rank, or on rank 0 alone, ends the job with an error instead of a hang.
 *
 * summary.json differs only in its "timing" line (wall time), which is left out of the comparison.
 * NAVSIM_EXE, MPIEXEC and NAV_TEST_WORK_DIR come from the build (tests/CMakeLists.txt).
 */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#define WORK NAV_TEST_WORK_DIR
#define MPIRUN "timeout 300 '" MPIEXEC "' --allow-run-as-root --oversubscribe"

static int sh(const char *fmt, ...) {
  char cmd[4096];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(cmd, sizeof cmd, fmt, ap);
  va_end(ap);
  const int st = system(cmd);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* Whole file, with the lines containing @p skip (if any) left out. */
static char *slurp(const char *path, const char *skip, size_t *len) {
  FILE *f = fopen(path, "rb");
  if (!f) fail_msg("cannot read %s", path);
  size_t cap = 1 << 16, n = 0;
  char *buf = malloc(cap);
  char line[8192];
  while (fgets(line, sizeof line, f)) {
    if (skip && strstr(line, skip)) continue;
    const size_t l = strlen(line);
    while (n + l + 1 > cap) buf = realloc(buf, cap *= 2);
    memcpy(buf + n, line, l);
    n += l;
  }
  fclose(f);
  buf[n] = '\0';
  *len = n;
  return buf;
}

/* Sorted names of the regular entries of @p dir (newline-separated). */
static void list_dir(const char *dir, char *out, size_t cap) {
  char cmd[1200];
  snprintf(cmd, sizeof cmd, "ls -A '%s' 2>/dev/null", dir);
  FILE *p = popen(cmd, "r");
  assert_non_null(p);
  const size_t n = fread(out, 1, cap - 1, p);
  out[n] = '\0';
  pclose(p);
}

/* Every file of @p a equals the file of the same name in @p b (summary.json: timing left out). */
static void assert_same_dirs(const char *a, const char *b) {
  char la[4096], lb[4096];
  list_dir(a, la, sizeof la);
  list_dir(b, lb, sizeof lb);
  assert_string_equal(la, lb);
  assert_non_null(strstr(la, "mc_stats.csv"));
  assert_non_null(strstr(la, "mc_final.csv"));
  int files = 0;
  for (char *name = strtok(la, "\n"); name; name = strtok(NULL, "\n")) {
    char pa[2048], pb[2048];
    snprintf(pa, sizeof pa, "%s/%s", a, name);
    snprintf(pb, sizeof pb, "%s/%s", b, name);
    const char *skip = strcmp(name, "summary.json") == 0 ? "\"timing\"" : NULL;
    size_t na = 0, nb = 0;
    char *da = slurp(pa, skip, &na), *db = slurp(pb, skip, &nb);
    if (na != nb || memcmp(da, db, na) != 0) fail_msg("%s differs from %s", pa, pb);
    free(da);
    free(db);
    ++files;
  }
  assert_true(files >= 6);
}

static int setup(void **state) {
  (void)state;
  if (sh("rm -rf '%s' && mkdir -p '%s'", WORK, WORK) != 0) return -1;
  /* The paper's parametric scene with initial errors drawn per run (free INS Monte Carlo). */
  return sh("cp '%s/scenes/paper-parametric.yaml' '%s/mc.yaml' && printf '%s' >> '%s/mc.yaml'", NAV_SOURCE_DIR, WORK,
            "\\ninitial_errors:\\n  position_m: [1, 2, 3]\\n  velocity_mps: [0.1, 0.1, 0.05]\\n"
            "  attitude_deg: [0.05, 0.05, 0.3]\\n",
            WORK) == 0
             ? 0
             : -1;
}

static void test_two_ranks_equal_threaded(void **state) {
  (void)state;
  assert_int_equal(sh("'%s' run '%s/mc.yaml' --runs 7 --threads 2 --quiet --out '%s/thr'", NAVSIM_EXE, WORK, WORK), 0);
  assert_int_equal(sh(MPIRUN " -np 2 '%s' run '%s/mc.yaml' --runs 7 --threads 1 --quiet --out '%s/mpi2/res'",
                      NAVSIM_EXE, WORK, WORK),
                   0);
  assert_same_dirs(WORK "/thr", WORK "/mpi2/res");
  /* Only rank 0 wrote, atomically: nothing else next to the result directory. */
  char l[1024];
  list_dir(WORK "/mpi2", l, sizeof l);
  assert_string_equal(l, "res\n");
}

static void test_hybrid_ranks_threads_equal_threaded(void **state) {
  (void)state;
  assert_int_equal(
      sh("'%s' run '%s/mc.yaml' --runs 7 --threads 1 --seed 99 --quiet --out '%s/thr99'", NAVSIM_EXE, WORK, WORK), 0);
  assert_int_equal(sh(MPIRUN " -np 3 '%s' run '%s/mc.yaml' --runs 7 --threads 2 --seed 99 --quiet --out '%s/mpi3'",
                      NAVSIM_EXE, WORK, WORK),
                   0);
  assert_same_dirs(WORK "/thr99", WORK "/mpi3");
}

/* More ranks than runs: rank 0 still runs run 0 (whose records it writes); a rank may have none. */
static void test_more_ranks_than_runs(void **state) {
  (void)state;
  assert_int_equal(sh("'%s' run '%s/mc.yaml' --runs 2 --threads 1 --quiet --out '%s/thr2'", NAVSIM_EXE, WORK, WORK), 0);
  assert_int_equal(
      sh(MPIRUN " -np 3 '%s' run '%s/mc.yaml' --runs 2 --threads 1 --quiet --out '%s/mpi3r2'", NAVSIM_EXE, WORK, WORK), 0);
  assert_same_dirs(WORK "/thr2", WORK "/mpi3r2");
}

/* INS/GNSS with outages: filter sigmas and NEES in mc_stats.csv, GNSS outputs of run 0. */
static void test_ins_gnss_two_ranks(void **state) {
  (void)state;
  const char *scene = NAV_SOURCE_DIR "/scenes/urban-drive.yaml";
  assert_int_equal(sh("'%s' run '%s' --runs 3 --threads 2 --quiet --out '%s/gthr'", NAVSIM_EXE, scene, WORK), 0);
  assert_int_equal(
      sh(MPIRUN " -np 2 '%s' run '%s' --runs 3 --threads 1 --quiet --out '%s/gmpi'", NAVSIM_EXE, scene, WORK), 0);
  assert_same_dirs(WORK "/gthr", WORK "/gmpi");
}

/* Every rank fails to read the scene: an error exit, not a hang (timeout 300 s). */
static void test_failure_ends_the_job(void **state) {
  (void)state;
  const int rc = sh(MPIRUN " -np 2 '%s' run '%s/missing.yaml' --quiet --out '%s/none' 2>/dev/null", NAVSIM_EXE, WORK,
                    WORK);
  assert_true(rc != 0 && rc != 124);
  char l[1024];
  list_dir(WORK "/none", l, sizeof l);
  assert_string_equal(l, "");
}

/* Rank 0 cannot create the result directory: the other ranks are released, the job ends with an
 * error and nothing is written. */
static void test_rank0_failure_releases_the_others(void **state) {
  (void)state;
  const int rc = sh(MPIRUN " -np 2 '%s' run '%s/mc.yaml' --runs 4 --quiet --out /proc/navsim-no-such-dir/x 2>/dev/null",
                    NAVSIM_EXE, WORK);
  assert_true(rc != 0 && rc != 124);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_two_ranks_equal_threaded),
      cmocka_unit_test(test_hybrid_ranks_threads_equal_threaded),
      cmocka_unit_test(test_more_ranks_than_runs),
      cmocka_unit_test(test_ins_gnss_two_ranks),
      cmocka_unit_test(test_failure_ends_the_job),
      cmocka_unit_test(test_rank0_failure_releases_the_others),
  };
  return cmocka_run_group_tests(tests, setup, NULL);
}
