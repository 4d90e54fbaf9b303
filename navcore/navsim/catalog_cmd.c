/*
 * navsim catalog: print the sensor catalogs and the simulator model each row converts to.
 * The tables show the *model* values (what a run will use), in datasheet units for people and in
 * SI for --csv; the conversions themselves live in navcore_io (nav_catalog.h).
 */
#define _POSIX_C_SOURCE 200809L
#include "catalog_cmd.h"
#include "cli_util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "navcore/nav_catalog.h"
#include "navcore/nav_io.h"
#include "navcore/nav_paths.h"

enum { EXIT_OK = 0, EXIT_FAIL = 1, EXIT_INVALID = 2 };

#define PATH_CAP 4096

static const char *k_usage_catalog =
    "usage: navsim catalog [--imu | --gnss | --accel] [--csv] [--convention allan_peak|sigma_equals_b]\n"
    "\n"
    "List the IMU catalog (resources/imu_catalog.csv), the GNSS receiver catalog\n"
    "(resources/gnss_receivers.csv) and the accelerometer parts for arrays\n"
    "(resources/accel_catalog.csv) with the error model the simulator derives from each row\n"
    "(1-sigma per axis). Rows whose numbers could not be checked against a datasheet are\n"
    "marked \"NO\" in the verified column: check the datasheet before relying on them.\n"
    "\n"
    "options:\n"
    "  --imu             only the IMU catalog\n"
    "  --gnss            only the GNSS receiver catalog\n"
    "  --accel           only the accelerometer parts (array.catalog in scenes), with their sources\n"
    "  --csv             CSV on stdout in SI units (needs --imu, --gnss or --accel)\n"
    "  --convention C    bias instability B -> Gauss-Markov sigma for datasheet rows:\n"
    "                    allan_peak (default; sigma = B / 0.61736) or sigma_equals_b\n"
    "  -h, --help        print this help\n"
    "\n"
    "The catalogs are looked up in $NAV_RESOURCES_DIR, else <bin>/../share/navcore/resources\n"
    "(the build tree links <build>/share/navcore to the sources).\n"
    "\n"
    "exit codes: 0 success; 1 a catalog cannot be found or read; 2 invalid catalog or options\n";

bool navsim_find_resources_dir(char *buf, size_t size) {
  if (buf == NULL || size == 0) return false;
  buf[0] = '\0';
  return nav_paths_resources_dir(buf, size);
}

/* One CSV cell: quoted when it holds a comma, quote or leading/trailing blank. */
static void csv_text(FILE *f, const char *s) {
  const size_t n = strlen(s);
  const bool quote = strpbrk(s, ",\"\n\r") != NULL || (n > 0 && (s[0] == ' ' || s[n - 1] == ' '));
  if (!quote) {
    fputs(s, f);
    return;
  }
  fputc('"', f);
  for (; *s; ++s) {
    if (*s == '"') fputc('"', f);
    fputc(*s, f);
  }
  fputc('"', f);
}

/* A number cell, or an empty cell when the term is off. */
static void csv_num(FILE *f, bool on, double v) {
  fputc(',', f);
  if (on) fprintf(f, "%.10g", v);
}

/* A table cell in datasheet units, "-" when the term is off. */
static void col_num(bool on, double v, int width) {
  if (on)
    printf(" %*.*g", width, 4, v);
  else
    printf(" %*s", width, "-");
}

static const char *verified_label(nav_catalog_verification v) {
  return v == NAV_CATALOG_VERIFIED_NO ? "NO (unverified)" : nav_catalog_verification_name(v);
}

static int load(const char *dir, const char *file, const nav_catalog_options *opt, nav_catalog **cat,
                char *path, size_t path_size) {
  if (snprintf(path, path_size, "%s/%s", dir, file) >= (int)path_size) {
    fprintf(stderr, "navsim catalog: resources path too long\n");
    return EXIT_FAIL;
  }
  const nav_status st = nav_catalog_load(path, opt, cat, navsim_print_diag, NULL);
  if (st == NAV_OK) return EXIT_OK;
  if (st == NAV_ERR_PARSE) return EXIT_INVALID;
  if (st != NAV_ERR_IO) fprintf(stderr, "%s: error: %s\n", path, nav_status_str(st));
  return EXIT_FAIL;
}

static void imu_csv(const nav_catalog *cat) {
  printf("name,grade,gyro_arw_rad_per_sqrt_s,gyro_bias_gm_sd_rps,gyro_bias_gm_tau_s,gyro_bias_turn_on_sd_rps,"
         "gyro_scale_factor_sd,accel_vrw_mps_per_sqrt_s,accel_bias_gm_sd_mps2,accel_bias_gm_tau_s,"
         "accel_bias_turn_on_sd_mps2,accel_scale_factor_sd,misalignment_sd_rad,bias_model,cost_class,cost_band,verified,"
         "source\n");
  for (size_t i = 0; i < nav_catalog_count(cat); ++i) {
    const nav_catalog_imu_entry *e = nav_catalog_imu_at(cat, i);
    const nav_gyro_error_config *g = &e->config.gyro;
    const nav_accel_error_config *a = &e->config.accel;
    csv_text(stdout, e->name);
    fputc(',', stdout);
    csv_text(stdout, e->grade);
    csv_num(stdout, g->terms & NAV_IMU_TERM_NOISE, g->arw_rad_per_sqrt_s.x);
    csv_num(stdout, g->terms & NAV_IMU_TERM_BIAS_GM, g->bias_gm_sd_rps.x);
    csv_num(stdout, g->terms & NAV_IMU_TERM_BIAS_GM, g->bias_gm_tau_s.x);
    csv_num(stdout, g->terms & NAV_IMU_TERM_BIAS_TURN_ON, g->bias_turn_on_sd_rps.x);
    csv_num(stdout, g->terms & NAV_IMU_TERM_SCALE_FACTOR, g->scale_factor_sd.x);
    csv_num(stdout, a->terms & NAV_IMU_TERM_NOISE, a->vrw_mps_per_sqrt_s.x);
    csv_num(stdout, a->terms & NAV_IMU_TERM_BIAS_GM, a->bias_gm_sd_mps2.x);
    csv_num(stdout, a->terms & NAV_IMU_TERM_BIAS_GM, a->bias_gm_tau_s.x);
    csv_num(stdout, a->terms & NAV_IMU_TERM_BIAS_TURN_ON, a->bias_turn_on_sd_mps2.x);
    csv_num(stdout, a->terms & NAV_IMU_TERM_SCALE_FACTOR, a->scale_factor_sd.x);
    csv_num(stdout, g->terms & NAV_IMU_TERM_MISALIGNMENT, g->misalignment_sd_rad.m[0][1]);
    printf(",%s,%d,%s,", nav_catalog_bias_model_name(e->bias_model), e->cost_class, nav_catalog_cost_band(e->cost_class));
    csv_text(stdout, e->verified_text);
    fputc(',', stdout);
    csv_text(stdout, e->source);
    fputc('\n', stdout);
  }
}

static void gnss_csv(const nav_catalog *cat) {
  printf("mode,pos_sd_n_m,pos_sd_e_m,pos_sd_d_m,pos_tau_s,vel_sd_mps,update_rate_hz,cost_class,cost_band,verified,source\n");
  for (size_t i = 0; i < nav_catalog_count(cat); ++i) {
    const nav_catalog_gnss_entry *e = nav_catalog_gnss_at(cat, i);
    const nav_gnss_model_config *c = &e->config;
    csv_text(stdout, e->name);
    csv_num(stdout, true, c->pos_gm_sd_m.x);
    csv_num(stdout, true, c->pos_gm_sd_m.y);
    csv_num(stdout, true, c->pos_gm_sd_m.z);
    csv_num(stdout, true, c->pos_gm_tau_s.x);
    csv_num(stdout, c->terms & NAV_GNSS_TERM_VEL_WHITE, c->vel_sd_mps.x);
    csv_num(stdout, true, c->update_rate_hz);
    printf(",%d,%s,", e->cost_class, nav_catalog_cost_band(e->cost_class));
    csv_text(stdout, e->verified_text);
    fputc(',', stdout);
    csv_text(stdout, e->source);
    fputc('\n', stdout);
  }
}

/* Back to datasheet units for display only (the inverse factors of nav_sensors.h). */
#define RPS_TO_DPH (1.0 / nav_unit_deg_per_h_to_rps(1.0))
#define ARW_TO_DEG_PER_SQRT_H (1.0 / nav_unit_deg_per_sqrt_h_to_rad_per_sqrt_s(1.0))

static void imu_table(const nav_catalog *cat, const char *path, const nav_catalog_options *opt) {
  printf("IMU catalog %s: %zu entries\n", path, nav_catalog_count(cat));
  printf(
      "Model per axis, 1 sigma. Datasheet bias instability B of allan_min rows -> Gauss-Markov with %s\n"
      "(%s), T = tau_min / 1.8926 (tau_min %g s MEMS, %g s FOG/RLG/navigation) unless the row gives T.\n\n",
      nav_bi_convention_name(opt->convention),
      opt->convention == NAV_BI_ALLAN_PEAK ? "sigma = B / 0.61736" : "sigma = B", opt->default_tau_min_mems_s,
      opt->default_tau_min_nav_s);
  printf("%-40s %-34s |%9s %9s %7s %9s %7s |%9s %9s %7s %9s %7s |%7s  %-10s %-4s %s\n", "", "", "ARW", "GM bias",
         "T", "turn-on", "SF", "VRW", "GM bias", "T", "turn-on", "SF", "misal.", "bias", "cost", "verified");
  printf("%-40s %-34s |%9s %9s %7s %9s %7s |%9s %9s %7s %9s %7s |%7s  %-10s %-4s\n", "name", "grade", "deg/rt-h",
         "deg/h", "s", "deg/h", "ppm", "m/s/rt-h", "ug", "s", "mg", "ppm", "mrad", "model", "cls");
  for (size_t i = 0; i < nav_catalog_count(cat); ++i) {
    const nav_catalog_imu_entry *e = nav_catalog_imu_at(cat, i);
    const nav_gyro_error_config *g = &e->config.gyro;
    const nav_accel_error_config *a = &e->config.accel;
    printf("%-40.40s %-34.34s |", e->name, e->grade);
    col_num(g->terms & NAV_IMU_TERM_NOISE, g->arw_rad_per_sqrt_s.x * ARW_TO_DEG_PER_SQRT_H, 8);
    col_num(g->terms & NAV_IMU_TERM_BIAS_GM, g->bias_gm_sd_rps.x * RPS_TO_DPH, 9);
    col_num(g->terms & NAV_IMU_TERM_BIAS_GM, g->bias_gm_tau_s.x, 7);
    col_num(g->terms & NAV_IMU_TERM_BIAS_TURN_ON, g->bias_turn_on_sd_rps.x * RPS_TO_DPH, 9);
    col_num(g->terms & NAV_IMU_TERM_SCALE_FACTOR, g->scale_factor_sd.x * 1e6, 7);
    printf(" |");
    col_num(a->terms & NAV_IMU_TERM_NOISE, a->vrw_mps_per_sqrt_s.x * 60.0, 8);
    col_num(a->terms & NAV_IMU_TERM_BIAS_GM, a->bias_gm_sd_mps2.x / nav_unit_ug_to_mps2(1.0), 9);
    col_num(a->terms & NAV_IMU_TERM_BIAS_GM, a->bias_gm_tau_s.x, 7);
    col_num(a->terms & NAV_IMU_TERM_BIAS_TURN_ON, a->bias_turn_on_sd_mps2.x / nav_unit_mg_to_mps2(1.0), 9);
    col_num(a->terms & NAV_IMU_TERM_SCALE_FACTOR, a->scale_factor_sd.x * 1e6, 7);
    printf(" |");
    col_num(g->terms & NAV_IMU_TERM_MISALIGNMENT, g->misalignment_sd_rad.m[0][1] * 1e3, 6);
    printf("  %-10s %-4d %s\n", nav_catalog_bias_model_name(e->bias_model), e->cost_class, verified_label(e->verified));
  }
}

static void accel_csv(const nav_catalog *cat) {
  printf(
      "part,grade,range_g,bandwidth_hz,vrw_mps_per_sqrt_s,bias_gm_sd_mps2,bias_gm_tau_s,bias_turn_on_sd_mps2,"
      "scale_factor_sd,bias_model,cost_class,cost_band,verified,source\n");
  for (size_t i = 0; i < nav_catalog_count(cat); ++i) {
    const nav_catalog_accel_entry *e = nav_catalog_accel_at(cat, i);
    const nav_array_error_config *a = &e->config;
    csv_text(stdout, e->name);
    fputc(',', stdout);
    csv_text(stdout, e->grade);
    csv_num(stdout, e->given & NAV_CATALOG_ACCEL_HAS_RANGE, e->range_g);
    csv_num(stdout, e->given & NAV_CATALOG_ACCEL_HAS_BANDWIDTH, e->bandwidth_hz);
    csv_num(stdout, a->terms & NAV_IMU_TERM_NOISE, a->vrw_mps_per_sqrt_s);
    csv_num(stdout, a->terms & NAV_IMU_TERM_BIAS_GM, a->bias_gm_sd_mps2);
    csv_num(stdout, a->terms & NAV_IMU_TERM_BIAS_GM, a->bias_gm_tau_s);
    csv_num(stdout, a->terms & NAV_IMU_TERM_BIAS_TURN_ON, a->bias_turn_on_sd_mps2);
    csv_num(stdout, a->terms & NAV_IMU_TERM_SCALE_FACTOR, a->scale_factor_sd);
    printf(",%s,%d,%s,", nav_catalog_bias_model_name(e->bias_model), e->cost_class,
           nav_catalog_cost_band(e->cost_class));
    csv_text(stdout, e->verified_text);
    fputc(',', stdout);
    csv_text(stdout, e->source);
    fputc('\n', stdout);
  }
}

/* The accelerometer parts: datasheet figures as given, the model they become, and the source of
 * each row (the catalog's provenance is part of what a user chooses from). */
static void accel_table(const nav_catalog *cat, const char *path, const nav_catalog_options *opt) {
  printf("Accelerometer parts for arrays %s: %zu entries (array.catalog: NAME in a scene)\n", path,
         nav_catalog_count(cat));
  printf("Datasheet figures of one sensitive axis; model per sensor, 1 sigma: noise density = VRW, bias\n"
         "instability B -> Gauss-Markov with %s, T = tau_min / 1.8926 (tau_min %g s MEMS, %g s\n"
         "navigation grades), bias repeatability -> turn-on bias, scale factor -> per-run constant.\n\n",
         opt->convention == NAV_BI_ALLAN_PEAK ? "sigma = B / 0.61736" : "sigma = B",
         opt->default_tau_min_mems_s, opt->default_tau_min_nav_s);
  printf("%-28s %-28s |%6s %6s %9s %8s %8s %6s |%9s %7s  %-4s %s\n", "", "", "range", "bw", "noise", "bias",
         "bias rep", "SF", "GM bias", "T", "cost", "verified");
  printf("%-28s %-28s |%6s %6s %9s %8s %8s %6s |%9s %7s  %-4s\n", "part", "grade", "g", "Hz", "ug/rt-Hz",
         "ug", "mg", "ppm", "ug", "s", "cls");
  for (size_t i = 0; i < nav_catalog_count(cat); ++i) {
    const nav_catalog_accel_entry *e = nav_catalog_accel_at(cat, i);
    const nav_array_error_config *a = &e->config;
    printf("%-28.28s %-28.28s |", e->name, e->grade);
    col_num(e->given & NAV_CATALOG_ACCEL_HAS_RANGE, e->range_g, 5);
    col_num(e->given & NAV_CATALOG_ACCEL_HAS_BANDWIDTH, e->bandwidth_hz, 6);
    col_num(e->given & NAV_CATALOG_ACCEL_HAS_NOISE, e->noise_density_ug_per_sqrt_hz, 9);
    col_num(e->given & NAV_CATALOG_ACCEL_HAS_BIAS_INSTABILITY, e->bias_instability_ug, 8);
    col_num(e->given & NAV_CATALOG_ACCEL_HAS_BIAS_REPEAT, e->bias_repeatability_mg, 8);
    col_num(e->given & NAV_CATALOG_ACCEL_HAS_SCALE_FACTOR, e->scale_factor_ppm, 6);
    printf(" |");
    col_num(a->terms & NAV_IMU_TERM_BIAS_GM, a->bias_gm_sd_mps2 / nav_unit_ug_to_mps2(1.0), 9);
    col_num(a->terms & NAV_IMU_TERM_BIAS_GM, a->bias_gm_tau_s, 7);
    printf("  %-4d %s\n", e->cost_class, verified_label(e->verified));
  }
  printf("\nsources:\n");
  for (size_t i = 0; i < nav_catalog_count(cat); ++i) {
    const nav_catalog_accel_entry *e = nav_catalog_accel_at(cat, i);
    printf("  %s [line %d, verified: %s]: %s\n", e->name, e->line, e->verified_text, e->source);
  }
}

/* The cost-class legend under both tables. */
static void cost_legend(void) {
  printf("\ncost class (indicative unit-price band by grade, not a quote; resources/README.md):");
  for (int k = 1; k <= NAV_CATALOG_COST_CLASS_MAX; ++k) printf(" %d %s%s", k, nav_catalog_cost_band(k), k < 5 ? "," : "\n");
}

static void gnss_table(const nav_catalog *cat, const char *path) {
  printf("GNSS receiver catalog %s: %zu entries\n", path, nav_catalog_count(cat));
  printf("Position error per axis: first-order Gauss-Markov (tau 0 = white); velocity error white.\n\n");
  printf("%-58s %8s %8s %7s %8s %6s  %-4s %s\n", "", "pos N/E", "pos D", "tau", "vel", "rate", "cost", "verified");
  printf("%-58s %8s %8s %7s %8s %6s  %-4s\n", "mode", "m", "m", "s", "m/s", "Hz", "cls");
  for (size_t i = 0; i < nav_catalog_count(cat); ++i) {
    const nav_catalog_gnss_entry *e = nav_catalog_gnss_at(cat, i);
    const nav_gnss_model_config *c = &e->config;
    printf("%-58.58s", e->name);
    col_num(true, c->pos_gm_sd_m.x, 8);
    col_num(true, c->pos_gm_sd_m.z, 8);
    col_num(true, c->pos_gm_tau_s.x, 7);
    col_num(c->terms & NAV_GNSS_TERM_VEL_WHITE, c->vel_sd_mps.x, 8);
    col_num(true, c->update_rate_hz, 6);
    printf("  %-4d %s\n", e->cost_class, verified_label(e->verified));
  }
}

int navsim_catalog(int argc, char **argv, const char *resources_dir) {
  bool want_imu = false, want_gnss = false, want_accel = false, csv = false;
  nav_catalog_options opt = nav_catalog_options_default();
  for (int i = 0; i < argc; ++i) {
    const char *a = argv[i];
    if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
      fputs(k_usage_catalog, stdout);
      return EXIT_OK;
    } else if (strcmp(a, "--imu") == 0) {
      want_imu = true;
    } else if (strcmp(a, "--gnss") == 0) {
      want_gnss = true;
    } else if (strcmp(a, "--accel") == 0) {
      want_accel = true;
    } else if (strcmp(a, "--csv") == 0) {
      csv = true;
    } else if (strcmp(a, "--convention") == 0) {
      if (i + 1 >= argc) {
        fprintf(stderr, "navsim catalog: --convention needs a value\n%s", k_usage_catalog);
        return EXIT_INVALID;
      }
      const char *v = argv[++i];
      if (strcmp(v, "allan_peak") == 0)
        opt.convention = NAV_BI_ALLAN_PEAK;
      else if (strcmp(v, "sigma_equals_b") == 0)
        opt.convention = NAV_BI_SIGMA_EQUALS_B;
      else {
        fprintf(stderr, "navsim catalog: --convention: '%s' is neither allan_peak nor sigma_equals_b\n", v);
        return EXIT_INVALID;
      }
    } else {
      fprintf(stderr, "navsim catalog: unknown argument '%s'\n%s", a, k_usage_catalog);
      return EXIT_INVALID;
    }
  }
  if (!want_imu && !want_gnss && !want_accel) {
    if (csv) {
      fprintf(stderr,
              "navsim catalog: --csv needs --imu, --gnss or --accel (the tables have different columns)\n");
      return EXIT_INVALID;
    }
    want_imu = want_gnss = want_accel = true;
  }
  if ((int)want_imu + (int)want_gnss + (int)want_accel > 1 && csv) {
    fprintf(stderr, "navsim catalog: --csv prints one table: give one of --imu, --gnss and --accel\n");
    return EXIT_INVALID;
  }
  if (resources_dir == NULL) {
    fprintf(stderr,
            "navsim catalog: cannot find the resources directory; set NAV_RESOURCES_DIR to the directory "
            "holding imu_catalog.csv and gnss_receivers.csv\n");
    return EXIT_FAIL;
  }
  char path[PATH_CAP + 64];
  if (want_imu) {
    nav_catalog *cat = NULL;
    const int rc = load(resources_dir, "imu_catalog.csv", &opt, &cat, path, sizeof path);
    if (rc != EXIT_OK) return rc;
    if (csv)
      imu_csv(cat);
    else
      imu_table(cat, path, &opt);
    nav_catalog_destroy(cat);
  }
  if (want_gnss) {
    nav_catalog *cat = NULL;
    const int rc = load(resources_dir, "gnss_receivers.csv", &opt, &cat, path, sizeof path);
    if (rc != EXIT_OK) return rc;
    if (!csv && want_imu) printf("\n");
    if (csv)
      gnss_csv(cat);
    else
      gnss_table(cat, path);
    nav_catalog_destroy(cat);
  }
  if (want_accel) {
    nav_catalog *cat = NULL;
    const int rc = load(resources_dir, "accel_catalog.csv", &opt, &cat, path, sizeof path);
    if (rc != EXIT_OK) return rc;
    if (!csv && (want_imu || want_gnss)) printf("\n");
    if (csv)
      accel_csv(cat);
    else
      accel_table(cat, path, &opt);
    nav_catalog_destroy(cat);
  }
  if (!csv) cost_legend();
  if (fflush(stdout) != 0) {
    fprintf(stderr, "navsim catalog: cannot write the output\n");
    return EXIT_FAIL;
  }
  return EXIT_OK;
}
