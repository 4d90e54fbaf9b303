/*
 * Bounded work (issue 25, "Bounded work"): every reader refuses what is not a regular file at
 * once (a FIFO as scene, IMU, GNSS, reference, GPX/KML/motion definition, catalog and result
 * file: exit 2 and a message, never a blocked process), navview never aborts on a bad or huge
 * result, and run / estimate / check predict the output size and memory of a scene and refuse
 * beyond the documented limits before any work.
 *
 * Each command runs in its own process group under a deadline: a command that hangs (a FIFO
 * opened for reading blocks until a writer comes) is killed and fails the test instead of
 * blocking it. NAVSIM_EXE, NAVVIEW_EXE (viewer builds), NAV_SOURCE_DIR, NAV_TEST_DATA_DIR and
 * NAV_TEST_WORK_DIR come from the build.
 */
#define _GNU_SOURCE
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "navsim_cli.h"

#define WORK NAV_TEST_WORK_DIR
#define SCENE NAV_SOURCE_DIR "/scenes/paper-parametric.yaml"
#define REPLAY NAV_TEST_DATA_DIR "/replay"

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define NAV_UNDER_SANITIZER 1
#else
#define NAV_UNDER_SANITIZER 0
#endif

/* A refusal is a stat and a message: well under a second. The deadline only decides that a
 * command hangs (a blocked FIFO never returns); sanitizer builds start slower. */
static const double k_refusal_deadline_s = NAV_UNDER_SANITIZER ? 10.0 : 1.0;

typedef struct outcome {
  int code;   /* exit code, -1 when killed by a signal */
  int signal; /* terminating signal, else 0 */
  double wall_s;
  long maxrss_kb; /* peak resident size of the command (sh -c exec's it) */
  char err[65536];
} outcome;

/* Run "sh -c CMD" in WORK with stdout/stderr captured, as its own process group; kill the group
 * and fail after @p deadline_s. @p mem_limit_bytes > 0 sets RLIMIT_AS in the child. */
static void run_timed(const char *cmd, double deadline_s, long mem_limit_bytes, outcome *o) {
  memset(o, 0, sizeof *o);
  struct timespec t0, t1;
  clock_gettime(CLOCK_MONOTONIC, &t0);
  const pid_t pid = fork();
  assert_true(pid >= 0);
  if (pid == 0) {
    setpgid(0, 0);
    if (chdir(WORK) != 0) _exit(126);
    const int out = open(WORK "/stdout.txt", O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = open(WORK "/stderr.txt", O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (out < 0 || err < 0) _exit(126);
    dup2(out, 1);
    dup2(err, 2);
    if (mem_limit_bytes > 0 && !NAV_UNDER_SANITIZER) {
      struct rlimit rl = {(rlim_t)mem_limit_bytes, (rlim_t)mem_limit_bytes};
      setrlimit(RLIMIT_AS, &rl);
    }
    execl("/bin/sh", "sh", "-c", cmd, (char *)NULL);
    _exit(127);
  }
  setpgid(pid, pid);
  int status = 0;
  struct rusage ru;
  memset(&ru, 0, sizeof ru);
  for (;;) {
    const pid_t w = wait4(pid, &status, WNOHANG, &ru);
    if (w == pid) break;
    assert_true(w == 0);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    const double el = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    if (el > deadline_s) {
      kill(-pid, SIGKILL);
      waitpid(pid, &status, 0);
      fail_msg("%s: no answer after %.1f s (hang)", cmd, deadline_s);
    }
    usleep(1000);
  }
  clock_gettime(CLOCK_MONOTONIC, &t1);
  o->wall_s = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
  /* sh -c exec's the last command, so the status is the command's own. */
  o->code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  o->signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
  o->maxrss_kb = ru.ru_maxrss;
  nav_test_slurp(WORK "/stderr.txt", o->err, sizeof o->err);
}

/* @p cmd (arguments after the executable) must exit with @p code within the refusal deadline
 * and say @p fragment on stderr. */
static void expect_refusal(const char *exe, const char *args, int code, const char *fragment) {
  char cmd[8192];
  snprintf(cmd, sizeof cmd, "exec '%s' %s", exe, args);
  outcome o;
  run_timed(cmd, k_refusal_deadline_s, 0, &o);
  if (o.signal) fail_msg("%s: killed by signal %d\n%s", args, o.signal, o.err);
  if (o.code != code) fail_msg("%s: exit %d, expected %d\n%s", args, o.code, code, o.err);
  if (!strstr(o.err, fragment)) fail_msg("%s: stderr lacks \"%s\":\n%s", args, fragment, o.err);
}

static void make_fifo(const char *path) {
  unlink(path);
  if (mkfifo(path, 0644) != 0) fail_msg("mkfifo %s: %s", path, strerror(errno));
}

static int setup(void **state) {
  (void)state;
  return nav_test_fresh_dir(WORK);
}

#define FIFO_MSG "it is a FIFO (named pipe), not a regular file"

/* A FIFO as the scene of every command that reads one: exit 2 at once, never a blocked open. */
static void test_fifo_scene(void **state) {
  (void)state;
  make_fifo(WORK "/scene.yaml");
  static const char *const cmds[] = {"check scene.yaml",
                                     "run scene.yaml --out r --quiet",
                                     "estimate scene.yaml --quiet",
                                     "budget scene.yaml --quiet",
                                     "allan scene.yaml --quiet",
                                     "select scene.yaml --out sel --quiet",
                                     "sweep scene.yaml --param imu.rate_hz=100:100:200 --out sw --quiet",
                                     "replay --imu " REPLAY "/IMU-100195-100245.txt --truth " REPLAY
                                     "/truth-100195-100245-20Hz.nav --scene scene.yaml --quiet"};
  for (size_t i = 0; i < sizeof cmds / sizeof cmds[0]; ++i)
    expect_refusal(NAVSIM_EXE, cmds[i], 2, "scene.yaml: error: cannot read the file: " FIFO_MSG);
  /* A directory and a device are refused the same way; /dev/zero never ends. */
  expect_refusal(NAVSIM_EXE, "check .", 2,
                 ".: error: cannot read the file: it is a directory, not a regular file");
  expect_refusal(NAVSIM_EXE, "check /dev/zero", 2, "it is a character device, not a regular file");
  unlink(WORK "/scene.yaml");
}

/* A FIFO in each file slot of replay: exit 2, the message names the kind of file. */
static void test_fifo_replay_files(void **state) {
  (void)state;
  make_fifo(WORK "/rec.fifo");
  const char *imu = REPLAY "/IMU-100195-100245.txt", *gnss = REPLAY "/GNSS-100195-100245.txt",
             *truth = REPLAY "/truth-100195-100245-20Hz.nav";
  char args[4096];
  snprintf(args, sizeof args, "replay --imu rec.fifo --gnss %s --truth %s --quiet", gnss, truth);
  expect_refusal(NAVSIM_EXE, args, 2, "rec.fifo: error: cannot read the IMU file: " FIFO_MSG);
  snprintf(args, sizeof args, "replay --imu %s --gnss rec.fifo --truth %s --quiet", imu, truth);
  expect_refusal(NAVSIM_EXE, args, 2, "rec.fifo: error: cannot read the GNSS file: " FIFO_MSG);
  snprintf(args, sizeof args, "replay --imu %s --gnss %s --truth rec.fifo --quiet", imu, gnss);
  expect_refusal(NAVSIM_EXE, args, 2, "rec.fifo: error: cannot read the .nav file: " FIFO_MSG);
  unlink(WORK "/rec.fifo");
}

/* A FIFO given to import, whatever the format: exit 2, no scene written. */
static void test_fifo_import(void **state) {
  (void)state;
  make_fifo(WORK "/track.gpx");
  static const char *const cmds[] = {
      "import track.gpx --out s.yaml", "import track.gpx --format gpx --out s.yaml",
      "import track.gpx --format kml --out s.yaml", "import track.gpx --format motion_def --out s.yaml"};
  for (size_t i = 0; i < sizeof cmds / sizeof cmds[0]; ++i) {
    expect_refusal(NAVSIM_EXE, cmds[i], 2, "track.gpx: error: cannot read the file: " FIFO_MSG);
    assert_false(nav_test_is_file(WORK "/s.yaml"));
  }
  unlink(WORK "/track.gpx");
}

/* A FIFO as the IMU catalog (NAV_RESOURCES_DIR): catalog, allan --imu and a scene naming a part. */
static void test_fifo_catalog(void **state) {
  (void)state;
  assert_int_equal(system("rm -rf '" WORK "/res' && cp -r '" NAV_SOURCE_DIR "/resources' '" WORK "/res'"), 0);
  make_fifo(WORK "/res/imu_catalog.csv");
  char args[4096];
  snprintf(args, sizeof args, "catalog --imu");
  char cmd[8192];
  static const char *const cmds[] = {"catalog --imu", "allan --imu ADIS16465 --duration 10 --quiet"};
  for (size_t i = 0; i < sizeof cmds / sizeof cmds[0]; ++i) {
    snprintf(cmd, sizeof cmd, "NAV_RESOURCES_DIR='%s/res' '%s' %s", WORK, NAVSIM_EXE, cmds[i]);
    outcome o;
    run_timed(cmd, k_refusal_deadline_s, 0, &o);
    if (o.code != 2) fail_msg("%s: exit %d, expected 2\n%s", cmds[i], o.code, o.err);
    if (!strstr(o.err, "imu_catalog.csv: error: cannot read the file: " FIFO_MSG))
      fail_msg("%s:\n%s", cmds[i], o.err);
  }
  (void)args;
  assert_int_equal(system("rm -rf '" WORK "/res'"), 0);
}

/* A FIFO in place of a result file: render, report and export refuse at once (exit 2); navview
 * itself refuses with a message (exit 1, its unreadable-result code). */
static void test_fifo_result_files(void **state) {
  (void)state;
  outcome o;
  run_timed("exec '" NAVSIM_EXE "' run '" SCENE "' --out fres --quiet --ideal", 120.0, 0, &o);
  assert_int_equal(o.code, 0);
  static const char *const files[] = {"truth.csv", "nav.csv", "errors.csv", "summary.json"};
  for (size_t i = 0; i < sizeof files / sizeof files[0]; ++i) {
    assert_int_equal(system("rm -rf '" WORK "/r2' && cp -r '" WORK "/fres' '" WORK "/r2'"), 0);
    char path[4096], msg[512], args[512];
    snprintf(path, sizeof path, "%s/r2/%s", WORK, files[i]);
    make_fifo(path);
    snprintf(msg, sizeof msg, "r2/%s: error: cannot read the file: " FIFO_MSG, files[i]);
    expect_refusal(NAVSIM_EXE, "render r2 --view errors", 2, msg);
    expect_refusal(NAVSIM_EXE, "report r2", 2, msg);
    if (strcmp(files[i], "truth.csv") == 0 || strcmp(files[i], "nav.csv") == 0)
      expect_refusal(NAVSIM_EXE, "export r2", 2, msg);
#ifdef NAVVIEW_EXE
    /* navview needs an X server only to draw: the refusal comes before. */
    snprintf(args, sizeof args, "r2 --view errors --png r2.png");
    expect_refusal(NAVVIEW_EXE, args, 1, msg);
#endif
    (void)args;
  }
  make_fifo(WORK "/lone.fifo");
  expect_refusal(NAVSIM_EXE, "render lone.fifo", 2, "lone.fifo: error: cannot read the file: " FIFO_MSG);
}

/* paper-parametric (flat Earth: the closed forms alone) over @p duration_s with output at the IMU
 * rate (100 Hz), as WORK/NAME. */
static void write_long_scene(const char *name, int duration_s) {
  char cmd[8192];
  snprintf(
      cmd, sizeof cmd,
      "sed 's/^  duration_s: 20$/  duration_s: %d/; s/^  rate_hz: 10$/  rate_hz: 100/' '%s' > '%s/%s' && "
      "grep -q '^  duration_s: %d$' '%s/%s'",
      duration_s, SCENE, WORK, name, duration_s, WORK, name);
  assert_int_equal(system(cmd), 0);
}

/* navsim estimate streams its rows like run: its peak memory does not grow with the output
 * epochs (it held about 410 bytes per epoch: 2 001 and 100 001 epochs differed by 40 MB). */
static void test_estimate_memory_does_not_grow(void **state) {
  (void)state;
  write_long_scene("short.yaml", 20);
  write_long_scene("long.yaml", 1000);
  outcome a, b;
  run_timed("exec '" NAVSIM_EXE "' estimate short.yaml --out est-short --quiet", 120.0, 0, &a);
  if (a.code != 0) fail_msg("estimate short.yaml: exit %d\n%s", a.code, a.err);
  run_timed("exec '" NAVSIM_EXE "' estimate long.yaml --out est-long --quiet", 120.0, 0, &b);
  if (b.code != 0) fail_msg("estimate long.yaml: exit %d\n%s", b.code, b.err);
  size_t rows = 0;
  {
    FILE *f = fopen(WORK "/est-long/estimate.csv", "r");
    assert_non_null(f);
    int c;
    while ((c = fgetc(f)) != EOF)
      rows += c == '\n';
    fclose(f);
  }
  assert_int_equal(rows, 100002); /* header and 100 001 output epochs */
  printf("navsim estimate peak RSS: %ld KiB at 2 001 epochs, %ld KiB at 100 001 epochs\n", a.maxrss_kb,
         b.maxrss_kb);
  /* 98 000 more epochs at the former 410 bytes each would add 40 MB; the batches are constant. */
  if (b.maxrss_kb - a.maxrss_kb > 16 * 1024)
    fail_msg("estimate memory grows with the epochs: %ld KiB -> %ld KiB", a.maxrss_kb, b.maxrss_kb);
  assert_int_equal(system("rm -rf '" WORK "/est-short' '" WORK "/est-long'"), 0);
}

/* Nothing named NAME or .NAME.tmp-* in WORK. */
static void assert_no_result(const char *name) {
  char cmd[8192];
  snprintf(cmd, sizeof cmd, "cd '%s' && ! ls -a | grep -q -e '^%s$' -e '^\\.%s\\.tmp-'", WORK, name, name);
  if (system(cmd) != 0) fail_msg("a refused command left %s (or its temporary) in %s", name, WORK);
}

/* A scene that passes check with 2e9 IMU samples at full output rate (1e7 s at 200 Hz): navsim
 * run wrote 130 MB/s into it with no estimate or cap. Now check warns with the prediction, and
 * run and estimate refuse at once (exit 2, the figures, the limit, what to change), unless
 * --allow-large. */
static void test_output_size_refused_before_work(void **state) {
  (void)state;
  char cmd[8192];
  snprintf(cmd, sizeof cmd,
           "sed 's/^  duration_s: 20$/  duration_s: 10000000/; s/^  rate_hz: 10$/  rate_hz: 200/; "
           "s/^  rate_hz: 100$/  rate_hz: 200/' '%s' > '%s/huge.yaml'",
           SCENE, WORK);
  assert_int_equal(system(cmd), 0);
  static const char *const figures = "2000000001 output epochs from 2000000000 IMU samples";
  outcome o;
  run_timed("exec '" NAVSIM_EXE "' check huge.yaml", k_refusal_deadline_s, 0, &o);
  if (o.code != 0) fail_msg("check: exit %d\n%s", o.code, o.err);
  nav_test_assert_matches(o.err,
                          "^huge.yaml: warning: output.rate_hz: navsim run would write up to 2 TB of result "
                          "files \\(2000000001 output epochs from 2000000000 IMU samples, in truth.csv, "
                          "nav.csv, errors.csv\\), above the limit of 2.15 GB \\(2 GiB\\): lower "
                          "output.rate_hz or trajectory.duration_s, or give --allow-large$");
  expect_refusal(NAVSIM_EXE, "run huge.yaml --out big", 2, figures);
  /* --kml adds tracks.csv and reads the tracks back whole. */
  expect_refusal(NAVSIM_EXE, "run huge.yaml --out big --kml", 2,
                 "in truth.csv, nav.csv, errors.csv, tracks.csv)");
  expect_refusal(
      NAVSIM_EXE, "run huge.yaml --out big --kml", 2,
      "huge.yaml: error: navsim run would need about 128 GB of memory (statistics, --kml tracks, for "
      "2000000001 output epochs), above the limit of 4.29 GB (4 GiB)");
  assert_no_result("big");
  expect_refusal(
      NAVSIM_EXE, "estimate huge.yaml --out bigest", 2,
      "huge.yaml: error: output.rate_hz: navsim estimate would write up to 2.75 TB of result files "
      "(2000000001 output epochs from 2000000000 IMU samples, in estimate.csv)");
  assert_no_result("bigest");
  /* --allow-large goes ahead: the run is under way when it is interrupted (exit 130, nothing left). */
  run_timed("exec timeout -s INT --preserve-status 2 '" NAVSIM_EXE
            "' run huge.yaml --out big --allow-large --quiet",
            60.0, 0, &o);
  if (o.code != 130)
    fail_msg("run --allow-large: exit %d, expected 130 (interrupted while running)\n%s", o.code, o.err);
  assert_null(strstr(o.err, "error:"));
  assert_no_result("big");
}

/* The memory of navsim run is predicted too: the RTS smoother keeps one record per output and
 * GNSS epoch of every run in flight (7.5 KiB measured at 18 states). */
static void test_memory_refused_before_work(void **state) {
  (void)state;
  char cmd[8192];
  snprintf(cmd, sizeof cmd,
           "sed 's/^  duration_s: 1800$/  duration_s: 6000/; s/^  rate_hz: 5$/  rate_hz: 100/; "
           "s/^  frame: ned$/  frame: ned\\n  smoother: true/' '%s/scenes/ship.yaml' > '%s/smooth.yaml' && "
           "grep -q '^  smoother: true$' '%s/smooth.yaml'",
           NAV_SOURCE_DIR, WORK, WORK);
  assert_int_equal(system(cmd), 0);
  expect_refusal(
      NAVSIM_EXE, "run smooth.yaml --threads 1 --out sm", 2,
      "smooth.yaml: error: navsim run would need about 5.28 GB of memory (statistics, shared reference, "
      "RTS smoother records of 1 run(s) in flight, for 600001 output epochs), above the limit of 4.29 GB "
      "(4 GiB)");
  assert_no_result("sm");
}

#ifdef NAVVIEW_EXE
static const char *const k_track_header = "t_s,lat_deg,lon_deg,h_m,pos_n_m,pos_e_m,pos_d_m,vel_n_mps,vel_e_"
                                          "mps,vel_d_mps,roll_deg,pitch_deg,yaw_deg\n";
static const char *const k_errors_header = "t_s,pos_err_n_m,pos_err_e_m,pos_err_d_m,pos_err_h_m,pos_err_v_m,"
                                           "vel_err_n_mps,vel_err_e_mps,vel_err_d_mps,"
                                           "vel_err_mps,att_err_rad,roll_err_deg,pitch_err_deg,yaw_err_deg\n";

/* A result directory of @p rows epochs at 200 Hz (truth = nav, a circle), errors.csv with a
 * sine and one spike of 5 m at a third of the run (the peak a decimation must not lose). */
static void write_result(const char *dir, long rows) {
  char path[4096];
  assert_int_equal(nav_test_fresh_dir(dir), 0);
  FILE *f[3];
  static const char *const names[3] = {"truth.csv", "nav.csv", "errors.csv"};
  for (int k = 0; k < 3; ++k) {
    snprintf(path, sizeof path, "%s/%s", dir, names[k]);
    f[k] = fopen(path, "w");
    assert_non_null(f[k]);
    fputs(k < 2 ? k_track_header : k_errors_header, f[k]);
  }
  for (long i = 0; i < rows; ++i) {
    const double t = 0.005 * (double)i, a = 0.01 * t;
    const double n = 1000.0 * sin(a), e = 1000.0 * (1.0 - cos(a));
    for (int k = 0; k < 2; ++k)
      fprintf(f[k], "%.3f,%.9f,%.9f,100,%.4f,%.4f,-100,%.4f,%.4f,0,0.1,-0.2,%.5f\n", t, 45.0 + n / 111e3,
              6.0 + e / 78e3, n, e, 10.0 * cos(a), 10.0 * sin(a), fmod(a * 57.29577951308232, 360.0));
    const double er = 0.5 * sin(t / 7.0) + (i == rows / 3 ? 5.0 : 0.0);
    fprintf(f[2], "%.3f,%.5f,%.5f,%.5f,%.5f,%.5f,0,0,0,0,%.7f,%.5f,%.5f,%.5f\n", t, er, -0.7 * er, 0.3 * er,
            fabs(er) * 1.2, fabs(0.3 * er), 1e-4 * fabs(er), 1e-3 * er, 2e-3 * er, 3e-3 * er);
  }
  for (int k = 0; k < 3; ++k)
    assert_int_equal(fclose(f[k]), 0);
}

static long file_size(const char *path) {
  struct stat st;
  return stat(path, &st) == 0 ? (long)st.st_size : -1;
}

/* navview never aborts on a bad or huge result (the reported std::length_error and
 * std::bad_alloc aborts): a directory as truth.csv, an 8e6-epoch errors.csv (6.4 GB, made as a
 * sparse file: the size is refused before anything is read), and a real one just over the
 * documented 256 MiB limit; each an exit 1 with a message, under a 2 GiB address-space limit. */
static void test_navview_bad_and_huge_results(void **state) {
  (void)state;
  const long mem = 2048L * 1024 * 1024;
  outcome o;
  write_result(WORK "/small", 2000);
  assert_int_equal(system("rm -f '" WORK "/small/truth.csv' && mkdir '" WORK "/small/truth.csv'"), 0);
  run_timed("exec '" NAVVIEW_EXE "' small --view errors --png small.png", 60.0, mem, &o);
  if (o.signal || o.code != 1)
    fail_msg("truth.csv a directory: exit %d signal %d\n%s", o.code, o.signal, o.err);
  assert_non_null(
      strstr(o.err, "small/truth.csv: error: cannot read the file: it is a directory, not a regular file"));
  expect_refusal(NAVSIM_EXE, "render small --view errors", 2,
                 "small/truth.csv: error: cannot read the file: it is a directory, not a regular file");

  /* 8e6 epochs of errors.csv at about 800 bytes a row: a sparse file of that size. */
  write_result(WORK "/huge", 2000);
  const int fd = open(WORK "/huge/errors.csv", O_WRONLY | O_TRUNC);
  assert_true(fd >= 0);
  assert_int_equal(ftruncate(fd, (off_t)8000000 * 800), 0);
  close(fd);
  run_timed("exec '" NAVVIEW_EXE "' huge --view errors --png huge.png", 60.0, mem, &o);
  if (o.signal || o.code != 1)
    fail_msg("8e6-epoch errors.csv: exit %d signal %d\n%s", o.code, o.signal, o.err);
  nav_test_assert_matches(
      o.err, "huge/errors.csv: error: the file is too large \\(6400000000 bytes\\); navview reads "
             "result files of up to 268435456 bytes \\(256 MiB\\): write the run with a lower "
             "output.rate_hz or a shorter duration");

  /* Real rows just over the limit: refused the same way, and quickly (nothing parsed). */
  write_result(WORK "/over", 2000);
  {
    FILE *f = fopen(WORK "/over/errors.csv", "w");
    assert_non_null(f);
    fputs(k_errors_header, f);
    static char block[1 << 16];
    size_t used = 0;
    long i = 0;
    long total = 0;
    while (total <= (256L << 20)) {
      const int n =
          snprintf(block + used, sizeof block - used, "%ld.000,0.5,0.1,0.1,0.5,0.1,0,0,0,0,0,0,0,0\n", i++);
      if ((size_t)n >= sizeof block - used) {
        assert_int_equal(fwrite(block, 1, used, f), used);
        total += (long)used;
        used = 0;
        --i;
        continue;
      }
      used += (size_t)n;
    }
    assert_int_equal(fclose(f), 0);
  }
  assert_true(file_size(WORK "/over/errors.csv") > (256L << 20));
  run_timed("exec '" NAVVIEW_EXE "' over --view errors --png over.png", 60.0, mem, &o);
  if (o.signal || o.code != 1)
    fail_msg("errors.csv over the limit: exit %d signal %d\n%s", o.code, o.signal, o.err);
  assert_non_null(strstr(o.err, "over/errors.csv: error: the file is too large"));
  assert_false(nav_test_is_file(WORK "/over.png"));
  assert_int_equal(system("rm -rf '" WORK "/over' '" WORK "/huge'"), 0);
}

/* A large result within the limit renders its error charts (the PNG, spike included, was looked
 * at by a human; here it must exist). */
static void test_navview_large_result_renders(void **state) {
  (void)state;
  write_result(WORK "/large", 300000);
  outcome o;
  run_timed("exec '" NAVSIM_EXE "' render large --view errors --out large.png", 120.0, 0, &o);
  if (o.signal || o.code != 0) fail_msg("large result: exit %d signal %d\n%s", o.code, o.signal, o.err);
  assert_true(file_size(WORK "/large.png") > 2000);
  printf("navview --view errors of 300000 epochs (errors.csv %ld bytes): %.2f s\n",
         file_size(WORK "/large/errors.csv"), o.wall_s);
  assert_int_equal(system("rm -rf '" WORK "/large'"), 0);
}
#endif

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_fifo_scene),
      cmocka_unit_test(test_fifo_replay_files),
      cmocka_unit_test(test_fifo_import),
      cmocka_unit_test(test_fifo_catalog),
      cmocka_unit_test(test_fifo_result_files),
      cmocka_unit_test(test_estimate_memory_does_not_grow),
      cmocka_unit_test(test_output_size_refused_before_work),
      cmocka_unit_test(test_memory_refused_before_work),
#ifdef NAVVIEW_EXE
      cmocka_unit_test(test_navview_bad_and_huge_results),
      cmocka_unit_test(test_navview_large_result_renders),
#endif
  };
  return cmocka_run_group_tests(tests, setup, NULL);
}
