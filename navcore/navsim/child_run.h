/* navsim: running a companion program (navview) with its output in a log file. */
#ifndef NAVSIM_CHILD_RUN_H
#define NAVSIM_CHILD_RUN_H

#include <stdbool.h>

/** Run argv (argv[0] looked up on PATH when it has no slash) with stdout and stderr into
 *  @p log_path, killed after @p timeout_s seconds (0: no limit). *exit_code: its exit code, -1
 *  when it did not exit normally, 127 when it could not start. @return true when it exited 0. */
bool navsim_run_logged(char *const argv[], const char *log_path, double timeout_s, int *exit_code);

/** The navview program of this installation or build tree, or NULL (nav_paths_program). */
const char *navsim_navview_exe(void);

/** Whether an X display is set ($DISPLAY non-empty); without one navview runs under xvfb-run. */
bool navsim_have_display(void);

#endif /* NAVSIM_CHILD_RUN_H */
