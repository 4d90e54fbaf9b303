/* navsim: running a companion program with its output in a log file (child_run.h). */
#define _POSIX_C_SOURCE 200809L
#include "child_run.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "cli_util.h"
#include "navcore/nav_paths.h"

bool navsim_run_logged(char *const argv[], const char *log_path, double timeout_s, int *exit_code) {
  *exit_code = 127;
  fflush(stdout);
  fflush(stderr);
  const double t0 = navsim_now_s();
  const pid_t pid = fork();
  if (pid < 0) return false;
  if (pid == 0) {
    const int fd = open(log_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      dup2(fd, STDOUT_FILENO);
      dup2(fd, STDERR_FILENO);
      close(fd);
    }
    execvp(argv[0], argv);
    fprintf(stderr, "cannot start %s: %s\n", argv[0], strerror(errno));
    _exit(127);
  }
  int status = 0;
  bool killed = false;
  for (;;) {
    const pid_t w = waitpid(pid, &status, WNOHANG);
    if (w == pid) break;
    if (w < 0 && errno != EINTR) return false;
    if (timeout_s > 0 && navsim_now_s() - t0 > timeout_s && !killed) {
      kill(pid, SIGKILL);
      killed = true;
    }
    const struct timespec ts = {0, 20 * 1000 * 1000};
    nanosleep(&ts, NULL);
  }
  *exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

const char *navsim_navview_exe(void) {
  static char path[4096];
  return nav_paths_program("navview", path, sizeof path) ? path : NULL;
}

bool navsim_have_display(void) {
  const char *d = getenv("DISPLAY");
  return d && d[0];
}
