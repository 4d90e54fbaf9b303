/*
 * Configuration of navsim serve: documented defaults and a "key = value" file (docs/web-server.md
 * lists every key). Blank lines and lines starting with '#' are ignored; an unknown key or a value
 * out of its range is an error with the file and line.
 */
#define _POSIX_C_SOURCE 200809L
#include "serve_internal.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

serve_config serve_config_default(void) {
  serve_config c;
  memset(&c, 0, sizeof c);
  snprintf(c.bind, sizeof c.bind, "127.0.0.1");
  c.port = 8080;
  const char *tmp = getenv("TMPDIR");
  snprintf(c.data_dir, sizeof c.data_dir, "%s/navsim-serve-%ld", tmp && tmp[0] == '/' ? tmp : "/tmp",
           (long)getuid());
  c.max_body_bytes = 1L << 20;
  c.max_connections = 128;
  c.max_connections_per_client = 32;
  c.connection_timeout_s = 30;
  c.max_streams = 64;
  c.max_streams_per_client = 4;
  const long cores = sysconf(_SC_NPROCESSORS_ONLN);
  c.max_parallel_jobs = cores > 1 ? (int)(cores < 64 ? cores : 64) : 1;
  c.max_queued_jobs = 16;
  c.max_jobs_per_client = 3;
  c.job_threads = 1;
  c.job_cpu_s = 60;
  c.job_wall_s = 300;
  c.job_memory_mb = 2048;
  c.job_output_mb = 256;
  c.job_open_files = 64;
  c.max_runs = 1000;
  c.max_imu_samples = 5e7;
  c.result_max_age_s = 3600;
  c.disk_quota_mb = 4096;
  c.retry_after_s = 10;
  c.estimate_cpu_s = 10;
  c.max_parallel_estimates = 2;
  c.estimate_cache_entries = 64;
  c.slurm = 0;
  c.slurm_max_runs = 100000;
  c.slurm_tasks = 1;
  c.slurm_time_min = 60;
  snprintf(c.slurm_mpi, sizeof c.slurm_mpi, "pmix");
  return c;
}

typedef enum kind { K_INT, K_LONG, K_DOUBLE, K_STR } kind;

typedef struct key_def {
  const char *key;
  kind k;
  size_t off;
  size_t size; /* K_STR: capacity */
  double lo, hi;
} key_def;

#define OFF(f) offsetof(serve_config, f)
static const key_def k_keys[] = {
    {"bind", K_STR, OFF(bind), sizeof(((serve_config *)0)->bind), 0, 0},
    {"port", K_INT, OFF(port), 0, 0, 65535},
    {"data_dir", K_STR, OFF(data_dir), SERVE_PATH_MAX, 0, 0},
    {"studio_dir", K_STR, OFF(studio_dir), SERVE_PATH_MAX, 0, 0},
    {"allowed_origin", K_STR, OFF(allowed_origin), sizeof(((serve_config *)0)->allowed_origin), 0, 0},
    {"max_body_bytes", K_LONG, OFF(max_body_bytes), 0, 1024, 16 << 20},
    {"max_connections", K_INT, OFF(max_connections), 0, 4, 10000},
    {"max_connections_per_client", K_INT, OFF(max_connections_per_client), 0, 1, 10000},
    {"connection_timeout_s", K_INT, OFF(connection_timeout_s), 0, 1, 3600},
    {"max_event_streams", K_INT, OFF(max_streams), 0, 1, 10000},
    {"max_event_streams_per_client", K_INT, OFF(max_streams_per_client), 0, 1, 10000},
    {"max_parallel_jobs", K_INT, OFF(max_parallel_jobs), 0, 1, 256},
    {"max_queued_jobs", K_INT, OFF(max_queued_jobs), 0, 0, 100000},
    {"max_jobs_per_client", K_INT, OFF(max_jobs_per_client), 0, 1, 100000},
    {"job_threads", K_INT, OFF(job_threads), 0, 1, 256},
    {"job_cpu_s", K_LONG, OFF(job_cpu_s), 0, 1, 86400},
    {"job_wall_s", K_LONG, OFF(job_wall_s), 0, 1, 86400 * 7},
    {"job_memory_mb", K_LONG, OFF(job_memory_mb), 0, 64, 1 << 20},
    {"job_output_mb", K_LONG, OFF(job_output_mb), 0, 1, 1 << 20},
    {"job_open_files", K_LONG, OFF(job_open_files), 0, 16, 65536},
    {"max_runs", K_LONG, OFF(max_runs), 0, 1, NAV_SCENE_MAX_RUNS},
    {"max_imu_samples", K_DOUBLE, OFF(max_imu_samples), 0, 1, 1e15},
    {"result_max_age_s", K_LONG, OFF(result_max_age_s), 0, 1, 86400L * 365},
    {"disk_quota_mb", K_LONG, OFF(disk_quota_mb), 0, 1, 1L << 30},
    {"retry_after_s", K_INT, OFF(retry_after_s), 0, 1, 86400},
    {"estimate_cpu_s", K_LONG, OFF(estimate_cpu_s), 0, 1, 3600},
    {"max_parallel_estimates", K_INT, OFF(max_parallel_estimates), 0, 1, 256},
    {"estimate_cache_entries", K_INT, OFF(estimate_cache_entries), 0, 0, 1024},
    {"slurm", K_INT, OFF(slurm), 0, 0, 1},
    {"slurm_max_runs", K_LONG, OFF(slurm_max_runs), 0, 1, NAV_SCENE_MAX_RUNS},
    {"slurm_tasks", K_INT, OFF(slurm_tasks), 0, 1, 100000},
    {"slurm_time_min", K_LONG, OFF(slurm_time_min), 0, 1, 525600},
    {"slurm_partition", K_STR, OFF(slurm_partition), sizeof(((serve_config *)0)->slurm_partition), 0, 0},
    {"slurm_mpi", K_STR, OFF(slurm_mpi), sizeof(((serve_config *)0)->slurm_mpi), 0, 0},
    {"slurm_bin_dir", K_STR, OFF(slurm_bin_dir), SERVE_PATH_MAX, 0, 0},
};

static char *trim(char *s) {
  while (*s && isspace((unsigned char)*s))
    ++s;
  size_t n = strlen(s);
  while (n > 0 && isspace((unsigned char)s[n - 1]))
    s[--n] = '\0';
  return s;
}

static bool set_value(const key_def *k, const char *v, serve_config *c, char *why, size_t why_size) {
  char *base = (char *)c + k->off;
  if (k->k == K_STR) {
    if (strlen(v) >= k->size) {
      snprintf(why, why_size, "%s: the value is longer than %zu bytes", k->key, k->size - 1);
      return false;
    }
    snprintf(base, k->size, "%s", v);
    return true;
  }
  errno = 0;
  char *end = NULL;
  const double d = strtod(v, &end);
  if (errno != 0 || end == v || *end != '\0' || !isfinite(d) || d < k->lo || d > k->hi ||
      (k->k != K_DOUBLE && d != floor(d))) {
    snprintf(why, why_size, "%s: expected %s in [%.15g, %.15g], got \"%s\"", k->key,
             k->k == K_DOUBLE ? "a number" : "an integer", k->lo, k->hi, v);
    return false;
  }
  if (k->k == K_INT)
    *(int *)(void *)base = (int)d;
  else if (k->k == K_LONG)
    *(long *)(void *)base = (long)d;
  else
    *(double *)(void *)base = d;
  return true;
}

bool serve_config_read(const char *path, serve_config *c) {
  FILE *f = fopen(path, "r");
  if (!f) {
    fprintf(stderr, "%s: error: cannot read the configuration file: %s\n", path, strerror(errno));
    return false;
  }
  char line[2048];
  int lineno = 0;
  bool ok = true;
  while (fgets(line, sizeof line, f)) {
    ++lineno;
    char *s = trim(line);
    if (*s == '\0' || *s == '#') continue;
    char *eq = strchr(s, '=');
    if (!eq) {
      fprintf(stderr, "%s:%d: error: expected \"key = value\", got \"%s\"\n", path, lineno, s);
      ok = false;
      continue;
    }
    *eq = '\0';
    const char *key = trim(s), *value = trim(eq + 1);
    const key_def *k = NULL;
    for (size_t i = 0; i < sizeof k_keys / sizeof k_keys[0]; ++i)
      if (strcmp(k_keys[i].key, key) == 0) k = &k_keys[i];
    if (!k) {
      fprintf(stderr, "%s:%d: error: unknown key \"%s\" (docs/web-server.md lists the keys)\n", path, lineno,
              key);
      ok = false;
      continue;
    }
    char why[512];
    if (!set_value(k, value, c, why, sizeof why)) {
      fprintf(stderr, "%s:%d: error: %s\n", path, lineno, why);
      ok = false;
    }
  }
  fclose(f);
  return ok;
}
