/* The CSV / JSON exporters of a run (result directories: resultdir.c). */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "fast_format.h"
#include "navcore/nav_filter.h"
#include "navcore/nav_recorded.h"
#include "navcore/nav_track.h"
#include "navcore/nav_io.h"
#include "navcore/nav_results.h"
#include "navcore/nav_version.h"

static const char *k_state_header =
    "t_s,lat_deg,lon_deg,h_m,pos_n_m,pos_e_m,pos_d_m,vel_n_mps,vel_e_mps,vel_d_mps,"
    "roll_deg,pitch_deg,yaw_deg\n";
static const char *k_error_header =
    "t_s,pos_err_n_m,pos_err_e_m,pos_err_d_m,pos_err_h_m,pos_err_v_m,vel_err_n_mps,vel_err_e_mps,"
    "vel_err_d_mps,vel_err_mps,att_err_rad,roll_err_deg,pitch_err_deg,yaw_err_deg\n";

static const char *k_smoothed_header =
    "t_s,lat_deg,lon_deg,h_m,pos_n_m,pos_e_m,pos_d_m,vel_n_mps,vel_e_mps,vel_d_mps,"
    "roll_deg,pitch_deg,yaw_deg,sd_n_m,sd_e_m,sd_d_m,fwd_sd_n_m,fwd_sd_e_m,fwd_sd_d_m,sd_yaw_deg,fwd_sd_yaw_deg\n";

nav_status nav_csv_write_header(FILE *f, nav_csv_table table) {
  if (!f) return NAV_ERR_INVALID_ARG;
  const char *h = table == NAV_CSV_ERRORS     ? k_error_header
                  : table == NAV_CSV_NAV_SMOOTHED ? k_smoothed_header
                                                  : k_state_header;
  return fputs(h, f) < 0 ? NAV_ERR_IO : NAV_OK;
}

/* One CSV row of numbers as printf("%.17g,...\n") would write it (fast_format.h: byte-identical,
 * several times faster than glibc's printf), in one fwrite. @return < 0 on an I/O error. */
static int write_numbers(FILE *f, const double *v, int n) {
  char row[24 * (NAV_FMT_G17_SIZE + 1)];
  size_t len = 0;
  for (int i = 0; i < n && i < 24; ++i) {
    len += (size_t)nav_fmt_g17(row + len, v[i]);
    row[len++] = i + 1 < n ? ',' : '\n';
  }
  return fwrite(row, 1, len, f) == len ? (int)len : -1;
}

/* One state row in the local-level view: geodetic position, curvilinear NED about the origin,
 * velocity in n, Euler angles of C_b_n. */
static int write_state(FILE *f, const nav_frame *fr, double t, nav_vec3 r, nav_vec3 v, nav_quat q,
                       const double *sd_s, const double *sd_f) {
  const nav_local_view w = nav_frame_view(fr, r, v, q);
  const nav_euler e = nav_quat_to_euler(w.q_b_n, NULL);
  const double vals[13] = {t,
                           w.pos.lat_rad * NAV_RAD2DEG,
                           w.pos.lon_rad * NAV_RAD2DEG,
                           w.pos.h_m,
                           w.r_ned_m.x,
                           w.r_ned_m.y,
                           w.r_ned_m.z,
                           w.v_n_mps.x,
                           w.v_n_mps.y,
                           w.v_n_mps.z,
                           e.roll_rad * NAV_RAD2DEG,
                           e.pitch_rad * NAV_RAD2DEG,
                           e.yaw_rad * NAV_RAD2DEG};
  if (!sd_s || !sd_f) return write_numbers(f, vals, 13);
  double all[21];
  memcpy(all, vals, sizeof vals);
  for (int k = 0; k < 3; ++k) {
    all[13 + k] = sd_s[NAV_FILTER_IDX_DR + k];
    all[16 + k] = sd_f[NAV_FILTER_IDX_DR + k];
  }
  all[19] = sd_s[NAV_FILTER_IDX_PHI + 2] * NAV_RAD2DEG;
  all[20] = sd_f[NAV_FILTER_IDX_PHI + 2] * NAV_RAD2DEG;
  return write_numbers(f, all, 21);
}

nav_status nav_csv_write_row(FILE *f, nav_csv_table table, const nav_sim_record *r) {
  if (!f || !r) return NAV_ERR_INVALID_ARG;
  int n = 0;
  switch (table) {
  case NAV_CSV_TRUTH:
    n = write_state(f, r->frame, r->truth->t_s, r->truth->r_fb_f_m, r->truth->v_fb_f_mps, r->truth->q_b_f, NULL,
                    NULL);
    break;
  case NAV_CSV_NAV:
    n = write_state(f, r->frame, r->nav->t_s, r->nav->r_fb_f_m, r->nav->v_fb_f_mps, r->nav->q_b_f, NULL, NULL);
    break;
  case NAV_CSV_NAV_SMOOTHED:
    if (!r->sd_smoothed || !r->sd_forward) return NAV_ERR_INVALID_ARG;
    n = write_state(f, r->frame, r->nav->t_s, r->nav->r_fb_f_m, r->nav->v_fb_f_mps, r->nav->q_b_f, r->sd_smoothed,
                    r->sd_forward);
    break;
  case NAV_CSV_ERRORS: {
    const nav_epoch_errors *e = r->err;
    const double v[14] = {e->t_s,
                          e->pos_err_n_m.x,
                          e->pos_err_n_m.y,
                          e->pos_err_n_m.z,
                          e->pos_err_h_m,
                          e->pos_err_v_m,
                          e->vel_err_n_mps.x,
                          e->vel_err_n_mps.y,
                          e->vel_err_n_mps.z,
                          e->vel_err_mps,
                          e->att_err_rad,
                          e->euler_err.roll_rad * NAV_RAD2DEG,
                          e->euler_err.pitch_rad * NAV_RAD2DEG,
                          e->euler_err.yaw_rad * NAV_RAD2DEG};
    n = write_numbers(f, v, 14);
    break;
  }
  default: return NAV_ERR_INVALID_ARG;
  }
  return n < 0 ? NAV_ERR_IO : NAV_OK;
}

void nav_json_write_string(FILE *f, const char *s) {
  fputc('"', f);
  for (const unsigned char *p = (const unsigned char *)(s ? s : ""); *p; ++p) {
    if (*p == '"' || *p == '\\')
      fprintf(f, "\\%c", *p);
    else if (*p < 0x20)
      fprintf(f, "\\u%04x", *p);
    else
      fputc(*p, f);
  }
  fputc('"', f);
}

/* JSON has no NaN/Inf: write null for them. */
static void json_number(FILE *f, double v) {
  if (isfinite(v)) {
    char buf[NAV_FMT_G17_SIZE];
    nav_fmt_g17(buf, v);
    fputs(buf, f);
  } else
    fputs("null", f);
}

static void json_stat(FILE *f, const char *name, nav_stat s, bool last) {
  fprintf(f, "    \"%s\": {\"rms\": ", name);
  json_number(f, s.rms);
  fputs(", \"max\": ", f);
  json_number(f, s.max);
  fputs(", \"p95\": ", f);
  json_number(f, s.p95);
  fprintf(f, "}%s\n", last ? "" : ",");
}

/* The five metrics of a nav_sim_stats block, in summary.json's order; @p last: no trailing comma. */
static void json_sim_stats(FILE *f, const nav_sim_stats *st, bool last) {
  json_stat(f, "pos_err_h_m", st->pos_err_h_m, false);
  json_stat(f, "pos_err_v_m", st->pos_err_v_m, false);
  json_stat(f, "vel_err_mps", st->vel_err_mps, false);
  json_stat(f, "att_err_rad", st->att_err_rad, false);
  json_stat(f, "yaw_err_rad", st->yaw_err_rad, last);
}

/* The lines of section @p key ("imu:", "gnss:") of the scene as the writer writes it (keys with
 * their units: datasheet units), as a JSON array of strings; [] when absent. */
static void write_section_lines(FILE *f, const char *yaml, const char *key) {
  fputc('[', f);
  const size_t kl = strlen(key);
  const char *p = yaml;
  while (p && *p && strncmp(p, key, kl) != 0) {
    p = strchr(p, '\n');
    if (p) ++p;
  }
  bool first = true;
  while (p && *p) {
    const char *e = strchr(p, '\n');
    const size_t n = e ? (size_t)(e - p) : strlen(p);
    if (!first && n > 0 && p[0] != ' ' && p[0] != '#') break; /* the next top-level key */
    if (n > 0) {
      char line[600];
      snprintf(line, sizeof line, "%.*s", (int)(n < sizeof line - 1 ? n : sizeof line - 1), p);
      fputs(first ? "\n      " : ",\n      ", f);
      nav_json_write_string(f, line);
      first = false;
    }
    p = e ? e + 1 : NULL;
  }
  fputc(']', f);
}

/* "setup": what produced the run (issue 18: the report states it): scheme, IMU (catalog name and
 * the error model as the scene writer writes it, in datasheet units), receiver (model, file or
 * none), the scene's outages, the lever arm. Seed and runs are at the top of summary.json. */
static void write_setup(FILE *f, const nav_scene *scene) {
  const bool aided =
      scene->navigation.scheme == NAV_SCHEME_INS_GNSS || scene->navigation.scheme == NAV_SCHEME_GYRO_FREE_GNSS;
  const bool array = scene->navigation.scheme == NAV_SCHEME_GYRO_FREE || scene->navigation.scheme == NAV_SCHEME_GYRO_FREE_GNSS;
  fprintf(f, "  \"setup\": {\"scheme\": \"%s\",\n    \"imu\": {\"catalog\": ", nav_nav_scheme_name(scene->navigation.scheme));
  nav_json_write_string(f, array ? "(accelerometer array)" : scene->imu.catalog);
  char *yaml = NULL;
  size_t len = 0;
  if (nav_scene_write_string(scene, &yaml, &len) != NAV_OK) yaml = NULL;
  fputs(", \"model_yaml\": ", f);
  write_section_lines(f, yaml, array ? "array:" : "imu:");
  fputs("},\n    \"receiver\": {\"source\": ", f);
  nav_json_write_string(f, !aided ? "none" : scene->gnss.file[0] ? "file" : "model");
  fputs(", \"catalog\": ", f);
  nav_json_write_string(f, aided ? scene->gnss.catalog : "");
  fputs(", \"model_yaml\": ", f);
  if (aided) write_section_lines(f, yaml, "gnss:");
  else fputs("[]", f);
  fputs("},\n    \"outages_s\": [", f);
  for (size_t i = 0; aided && i < scene->gnss.model.outage_count; ++i) {
    fputs(i ? ", [" : "[", f);
    json_number(f, scene->gnss.model.outages[i].t0_s);
    fputs(", ", f);
    json_number(f, scene->gnss.model.outages[i].t1_s);
    fputc(']', f);
  }
  fputs("],\n    \"lever_arm_b_m\": [", f);
  const nav_vec3 la = scene->gnss.model.r_ba_b_m;
  json_number(f, aided ? la.x : 0.0);
  fputs(", ", f);
  json_number(f, aided ? la.y : 0.0);
  fputs(", ", f);
  json_number(f, aided ? la.z : 0.0);
  fputs("]},\n", f);
  free(yaml);
}

nav_status nav_summary_write_json(const char *path, const nav_scene *scene, const nav_run_info *info,
                                  const nav_sim_summary *sum) {
  if (!path || !scene || !info || !sum) return NAV_ERR_INVALID_ARG;
  FILE *f = fopen(path, "w");
  if (!f) return NAV_ERR_IO;
  fprintf(f, "{\n  \"navsim_version\": \"%s\",\n  \"scene\": {\"name\": ", nav_version_string());
  nav_json_write_string(f, scene->name);
  fputs(", \"file\": ", f);
  nav_json_write_string(f, info->scene_file);
  fprintf(f, "},\n  \"seed\": %llu,\n  \"runs\": %ld,\n  \"ideal\": %s,\n", (unsigned long long)info->seed,
          sum->runs, info->ideal ? "true" : "false");
  fprintf(f,
          "  \"earth_model\": \"%s\",\n  \"gravity_model\": \"%s\",\n  \"algorithm\": \"%s\",\n"
          "  \"mechanization_frame\": \"%s\",\n  \"trajectory\": \"%s\",\n",
          nav_earth_model_name(scene->earth.model),
          scene->earth.model == NAV_EARTH_FLAT ? "uniform"
                                               : nav_gravity_model_name(scene->earth.gravity_model),
          nav_mech_algorithm_name(scene->navigation.algorithm),
          scene->earth.model == NAV_EARTH_FLAT ? "flat" : nav_mech_frame_name(scene->navigation.frame),
          nav_traj_type_name(scene->trajectory.type));
  fputs("  \"duration_s\": ", f);
  json_number(f, sum->duration_s);
  fputs(",\n  \"imu_rate_hz\": ", f);
  json_number(f, scene->imu.rate_hz);
  fputs(",\n  \"output_rate_hz\": ", f);
  json_number(f, scene->output.rate_hz);
  fprintf(f, ",\n  \"partial\": %s,\n", sum->partial ? "true" : "false");
  const double sps = info->wall_s > 0.0 ? (double)sum->imu_samples * (double)sum->runs / info->wall_s : 0.0;
  fputs("  \"timing\": {\"wall_s\": ", f);
  json_number(f, info->wall_s);
  fprintf(f, ", \"imu_samples\": %lld, \"imu_samples_per_s\": ", (long long)(sum->imu_samples * sum->runs));
  json_number(f, sps);
  fputs("},\n  \"final\": {\"t_s\": ", f);
  json_number(f, sum->final.t_s);
  fputs(", \"pos_err_h_m\": ", f);
  json_number(f, sum->final.pos_err_h_m);
  fputs(", \"pos_err_v_m\": ", f);
  json_number(f, sum->final.pos_err_v_m);
  fputs(", \"vel_err_mps\": ", f);
  json_number(f, sum->final.vel_err_mps);
  fputs(", \"att_err_rad\": ", f);
  json_number(f, sum->final.att_err_rad);
  fputs(", \"yaw_err_rad\": ", f);
  json_number(f, fabs(sum->final.euler_err.yaw_rad));
  fputs("},\n  \"final_rms_over_runs\": {\"pos_err_h_m\": ", f);
  json_number(f, sum->final_rms.pos_err_h_m);
  fputs(", \"pos_err_v_m\": ", f);
  json_number(f, sum->final_rms.pos_err_v_m);
  fputs(", \"vel_err_mps\": ", f);
  json_number(f, sum->final_rms.vel_err_mps);
  fputs(", \"att_err_rad\": ", f);
  json_number(f, sum->final_rms.att_err_rad);
  fprintf(f, "},\n  \"stats\": {\n    \"epochs\": %lld,\n    \"stride\": %lld,\n",
          (long long)sum->stats_epochs, (long long)sum->stats_stride);
  json_sim_stats(f, &sum->stats, true);
  if (sum->has_smoothed) {
    /* navigation.smoother: RTS-smoothed errors at the output epochs of every run, and the forward
     * filter's at the same epochs. */
    fprintf(f,
            "  },\n  \"stats_smoothed\": {\n    \"method\": \"Rauch-Tung-Striebel backward pass per run over "
            "the output and GNSS epochs (nav_smoother.h)\",\n    \"epochs\": %lld,\n    \"output_stride\": "
            "%lld,\n"
            "    \"smoother_bytes_max\": %zu,\n",
            (long long)sum->smoothed_epochs, (long long)sum->smoothed_stride, sum->smoother_bytes_max);
    json_sim_stats(f, &sum->stats_smoothed, false);
    fputs("    \"forward_same_epochs\": {\n", f);
    json_sim_stats(f, &sum->stats_forward_out, true);
    fputs("    }\n", f);
  }
  fputs("  },\n", f);
  if (scene->trajectory.type == NAV_TRAJ_RECORDED) {
    /* Residuals of the recorded reference's spline fit against its samples (issue 25): how far the
     * reference the run used is from the recorded data. Only for recorded trajectories. */
    const nav_recorded_fit_stats *fs = &scene->trajectory.recorded.fit;
    fputs("  \"recorded_fit\": {\"file\": ", f);
    nav_json_write_string(f, scene->trajectory.recorded.file);
    fprintf(f, ", \"samples\": %ld, \"pos_rms_m\": ", fs->samples);
    json_number(f, fs->pos_rms_m);
    fputs(", \"pos_h_rms_m\": ", f);
    json_number(f, fs->pos_h_rms_m);
    fputs(", \"pos_v_rms_m\": ", f);
    json_number(f, fs->pos_v_rms_m);
    fputs(", \"pos_max_m\": ", f);
    json_number(f, fs->pos_max_m);
    fputs(", \"pos_max_t_s\": ", f);
    json_number(f, fs->pos_max_t_s);
    fputs(",\n    \"vel_rms_mps\": ", f);
    json_number(f, fs->vel_rms_mps);
    fputs(", \"vel_max_mps\": ", f);
    json_number(f, fs->vel_max_mps);
    fputs(", \"vel_max_t_s\": ", f);
    json_number(f, fs->vel_max_t_s);
    fputs(", \"att_rms_deg\": ", f);
    json_number(f, fs->att_rms_rad * NAV_RAD2DEG);
    fputs(", \"att_max_deg\": ", f);
    json_number(f, fs->att_max_rad * NAV_RAD2DEG);
    fputs(", \"att_max_t_s\": ", f);
    json_number(f, fs->att_max_t_s);
    fputs(", \"max_gap_s\": ", f);
    json_number(f, fs->max_gap_s);
    fputs(", \"max_gap_t_s\": ", f);
    json_number(f, fs->max_gap_t_s);
    char w[1200];
    if (nav_track_warnings(&scene->trajectory.recorded, w, sizeof w) != 0) {
      /* Only when there is one: the model's dynamics against the samples (docs/recorded-fit.md). */
      fputs(",\n    \"warning\": ", f);
      nav_json_write_string(f, w);
    }
    fputs("},\n", f);
  }
  if (scene->gnss.file[0] != '\0') {
    /* gnss.file (docs/gnss-file.md): the fixes came from a file, not from the receiver model. */
    nav_ins_gnss_fix *fx = NULL;
    size_t nfx = 0, used = 0, with_vel = 0;
    double t0 = 0.0;
    if (nav_gnss_file_load(scene, &fx, &nfx, &t0, NULL) != NAV_OK) nfx = 0;
    for (size_t i = 0; i < nfx; ++i) {
      bool out = fx[i].t_s < 0.0 || fx[i].t_s > sum->duration_s;
      for (size_t k = 0; k < scene->gnss.model.outage_count && !out; ++k)
        out = fx[i].t_s >= scene->gnss.model.outages[k].t0_s && fx[i].t_s < scene->gnss.model.outages[k].t1_s;
      if (!out) used++;
      if (fx[i].has_vel) with_vel++;
    }
    free(fx);
    fputs("  \"gnss_source\": {\"kind\": \"file\", \"file\": ", f);
    nav_json_write_string(f, scene->gnss.file);
    fprintf(f, ", \"fixes\": %zu, \"fixes_with_velocity\": %zu, \"fixes_in_run_outside_outages\": %zu, "
               "\"t0_file_s\": ", nfx, with_vel, used);
    json_number(f, t0);
    fputs(", \"sigma\": \"the file's\"},\n", f);
  }
  write_setup(f, scene);
  fputs("  \"requirements\": ", f);
  if (nav_requirements_write_json(f, info->requirements, info->requirements ? info->n_requirements : 0, 2) !=
      NAV_OK)
    fputs("[]", f);
  fputs("\n}\n", f);
  const bool bad = ferror(f) != 0;
  if (fclose(f) != 0 || bad) return NAV_ERR_IO;
  return NAV_OK;
}
