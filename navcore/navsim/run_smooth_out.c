/* navsim run with navigation.smoother: the smoothed CSV files of run 0 (run_smooth_out.h). */
#include "run_smooth_out.h"

#include <stdio.h>
#include <stdlib.h>

struct navsim_run_smooth {
  FILE *f[2]; /* nav_smoothed.csv, smoothed_errors.csv */
};

static const char *k_names[2] = {"nav_smoothed.csv", "smoothed_errors.csv"};
static const nav_csv_table k_tables[2] = {NAV_CSV_NAV_SMOOTHED, NAV_CSV_ERRORS};

nav_status navsim_run_smooth_begin(nav_resultdir *rd, navsim_run_smooth **out) {
  if (!rd || !out) return NAV_ERR_INVALID_ARG;
  *out = NULL;
  navsim_run_smooth *o = calloc(1, sizeof *o);
  if (!o) return NAV_ERR_NO_MEMORY;
  for (int i = 0; i < 2; ++i) {
    const char *file = nav_resultdir_file(rd, k_names[i]);
    o->f[i] = file ? fopen(file, "w") : NULL;
    if (!o->f[i] || nav_csv_write_header(o->f[i], k_tables[i]) != NAV_OK) {
      navsim_run_smooth_abort(o);
      return NAV_ERR_IO;
    }
  }
  *out = o;
  return NAV_OK;
}

nav_status navsim_run_smooth_record(navsim_run_smooth *o, const nav_sim_record *r) {
  if (!o || !r) return NAV_ERR_INVALID_ARG;
  for (int i = 0; i < 2; ++i) {
    const nav_status st = nav_csv_write_row(o->f[i], k_tables[i], r);
    if (st != NAV_OK) return st;
  }
  return NAV_OK;
}

nav_status navsim_run_smooth_end(navsim_run_smooth *o) {
  if (!o) return NAV_OK;
  nav_status st = NAV_OK;
  for (int i = 0; i < 2; ++i) {
    if (!o->f[i]) continue;
    if (ferror(o->f[i]) != 0) st = NAV_ERR_IO;
    if (fclose(o->f[i]) != 0) st = NAV_ERR_IO;
    o->f[i] = NULL;
  }
  free(o);
  return st;
}

void navsim_run_smooth_abort(navsim_run_smooth *o) {
  if (!o) return;
  for (int i = 0; i < 2; ++i)
    if (o->f[i]) fclose(o->f[i]);
  free(o);
}

void navsim_run_smooth_print(const nav_sim_summary *sum) {
  if (!sum || !sum->has_smoothed) return;
  const nav_sim_stats *f = &sum->stats_forward_out, *s = &sum->stats_smoothed;
  printf("smoothed   RTS smoother at the output epochs (%lld values, forward -> smoothed RMS): horizontal %.3e -> "
         "%.3e m, vertical %.3e -> %.3e m, velocity %.3e -> %.3e m/s, attitude %.3e -> %.3e rad; "
         "%.1f MiB per run\n",
         (long long)sum->smoothed_epochs, f->pos_err_h_m.rms, s->pos_err_h_m.rms, f->pos_err_v_m.rms,
         s->pos_err_v_m.rms, f->vel_err_mps.rms, s->vel_err_mps.rms, f->att_err_rad.rms, s->att_err_rad.rms,
         (double)sum->smoother_bytes_max / (1024.0 * 1024.0));
}
