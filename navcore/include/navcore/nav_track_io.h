/**
 * @file nav_track_io.h
 * @brief navcore_io: reading recorded reference files (trajectory.type recorded) into
 *        nav_track_sample arrays for nav_track_fit() (nav_track.h).
 *
 * Scene files load them when read (scene_traj_io.c):
 *
 *   trajectory:
 *     type: recorded
 *     recorded:
 *       file: PATH            # relative to the scene file's directory, or absolute
 *       format: kf_gins_nav   # the only format so far
 *       start_s: 116454       # optional window, file time base [s]
 *       end_s: 116754
 *       knot_rate_hz: 4       # B-spline knots per second (default 4)
 *       pos_sd_m: 0.01        # fit weights (defaults 0.01 m, 0.01 m/s)
 *       vel_sd_mps: 0.01
 */
#ifndef NAV_TRACK_IO_H
#define NAV_TRACK_IO_H

#include <stddef.h>

#include "nav_export.h"
#include "nav_io.h"
#include "nav_scene.h"
#include "nav_status.h"
#include "nav_track.h"

NAV_BEGIN_DECLS

/**
 * navcore_io: read the samples of a recorded file.
 *
 * Lines: blank lines and lines whose first non-blank character is '#' are skipped; CR-LF line
 * ends are accepted. Every other line is one sample in the columns of @p format; each field
 * must be a finite number, |lat| <= 90 deg, lon in [-360, 360] deg, |roll| <= 180 deg, |pitch|
 * <= 90 deg, yaw in [-360, 360] deg, times strictly increasing. Angles become radians here.
 * Only samples with start_s <= t <= end_s are kept when @p window has the corresponding bit.
 * Consecutive kept samples must agree with their velocities: the displacement dr (local NED)
 * and the trapezoid of the recorded velocities v_avg dt may differ by at most
 * 1 m + 100 m/s^2 x dt^2 / 4 (the trapezoid rule's bound for accelerations up to 10 g, plus the
 * position noise of a reference); a larger jump is reported at the later sample's latitude.
 *
 * Every problem is one nav_diag FILE:LINE:COL (COL the 1-based byte column of the offending
 * field, or of the end of the line for a missing field), with @p field_path as its path
 * ("trajectory.recorded.file"); at most NAV_DIAG_MAX_PER_FILE per file.
 *
 * @param[out] out    heap array of the samples (free() it); NULL when none; written on NAV_OK
 * @param[out] count  number of samples; written on NAV_OK
 * @return NAV_OK; NAV_ERR_IO (cannot open or read); NAV_ERR_PARSE (at least one diagnostic);
 *         NAV_ERR_INVALID_ARG (NULL, unknown format); NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_track_read_file(const char *path, nav_recorded_format format,
                                                     unsigned window, double start_s, double end_s,
                                                     const char *field_path, nav_track_sample **out,
                                                     size_t *count, nav_diag_fn report, void *user);

/** As nav_track_read_file(), from memory; @p display_name is the FILE of diagnostics. */
NAV_API NAV_NODISCARD nav_status nav_track_read_string(const char *text, size_t len, const char *display_name,
                                                       nav_recorded_format format, unsigned window,
                                                       double start_s, double end_s, const char *field_path,
                                                       nav_track_sample **out, size_t *count,
                                                       nav_diag_fn report, void *user);

NAV_END_DECLS

#endif /* NAV_TRACK_IO_H */
