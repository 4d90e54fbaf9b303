/*
 * Output size and memory of a scene, predicted before any work, and the documented limits that
 * navsim check, run and estimate and navsim serve hold them to. One place for the limits.
 */
#ifndef NAV_SIZE_LIMITS_H
#define NAV_SIZE_LIMITS_H

#include <stdbool.h>
#include <stdint.h>

#include "nav_export.h"
#include "nav_scene.h"

/** Result files of one command: at most 2 GiB (the predicted upper bound of their bytes). */
#define NAV_MAX_OUTPUT_BYTES (2.0 * 1024 * 1024 * 1024)
/** Memory of one command that grows with the scene: at most 4 GiB (predicted). */
#define NAV_MAX_MEMORY_BYTES (4.0 * 1024 * 1024 * 1024)
/** Bytes of one CSV field at most: "%.17g" of a double (24 characters) and its separator. */
#define NAV_CSV_FIELD_MAX_BYTES 25

/* The --help text of the limits (run, estimate, check). */
#define NAV_LIMITS_HELP                                                                                   \
  "limits: before any work the result files and memory are predicted from the scene (output epochs\n"        \
  "  x columns x 25 bytes a field at most, per file written; smoother records, shared reference and\n"       \
  "  statistics). Above 2 GiB of result files or 4 GiB of memory the command refuses (exit 2) with\n"        \
  "  the figures and what to change (output.rate_hz, trajectory.duration_s, simulation.runs);\n"             \
  "  --allow-large goes ahead anyway. navsim check warns about such scenes.\n"

/** The prediction for one command and scene. */
typedef struct nav_size_prediction {
  int64_t imu_samples;   /**< IMU samples of one run */
  int64_t output_epochs; /**< rows of each per-epoch CSV */
  double output_bytes;   /**< upper bound of the result files [bytes] */
  double memory_bytes;   /**< memory that grows with the scene [bytes] */
  char files[256];       /**< what is counted, e.g. "truth.csv, nav.csv, errors.csv (40 columns)" */
  char memory[256];      /**< what the memory is, e.g. "RTS smoother records of 2 runs in flight" */
} nav_size_prediction;

/** navsim run of @p sc (after --runs / --ideal / --threads; @p kml: --kml, tracks.kml/.csv). */
NAV_API void nav_predict_run(const nav_scene *sc, bool ideal, long threads, bool kml, nav_size_prediction *out);

/** Add the files of navsim run --export kfgins (kfgins_out.h) to a nav_predict_run() prediction. */
NAV_API void nav_predict_add_kfgins(const nav_scene *sc, nav_size_prediction *p);

/** navsim estimate of @p sc: estimate.csv with @p csv_columns columns, streamed. */
NAV_API void nav_predict_estimate(const nav_scene *sc, int csv_columns, nav_size_prediction *out);

/**
 * Hold @p p to the limits. Above them: with @p allow_large nothing is said and 0 is returned;
 * otherwise "SCENE: error: ..." (or "warning" when @p warn_only) with the predicted figures, the
 * limit and what to change is printed, and 2 is returned (0 when @p warn_only).
 */
NAV_API int nav_size_check(const char *cmd, const char *scene_path, const nav_size_prediction *p,
                      bool allow_large, bool warn_only);

#endif /* NAV_SIZE_LIMITS_H */
