/* navsim render and navsim report: figures of a result directory through the viewer program
 * (navview), and an HTML page with the figures, the summary tables and the requirement verdicts.
 * navsim stays free of VTK: both run navview as a child process (under xvfb-run when there is no
 * DISPLAY). */
#ifndef NAVSIM_REPORT_CMD_H
#define NAVSIM_REPORT_CMD_H

/**
 * `navsim render RESULT_DIR|SCENE [--view 3d|top|map|errors|noise|allan|bench] [--out FILE.png]
 * [--size WxH] [--time T_S] [navview options]`. A SCENE (a file) is run first (navsim run, into
 * out/render-<file stem>). @return navview's exit code (0, 1, 2), 2 for a bad command line.
 */
int navsim_render(int argc, char **argv);

/**
 * `navsim report RESULT_DIR [--out DIR|FILE.html] [--size WxH]`: renders every figure the
 * directory supports and writes a self-contained HTML page (figures embedded as data: URIs and
 * also kept as PNG files next to it). Atomic: the page is written to a temporary name and renamed.
 * @return 0 success; 1 a figure or the page could not be written; 2 bad command line.
 */
int navsim_report(int argc, char **argv);

#endif /* NAVSIM_REPORT_CMD_H */
