/*
 * navsim serve: the HTTP side (libmicrohttpd, thread per connection). Routes, the checks every
 * request passes (Host, Origin, method, body type and size), static files of the studio from the
 * fixed list in its manifest.txt, server-sent events of a run's progress, and start-up and
 * shutdown. docs/web-server.md documents the API.
 */
#define _GNU_SOURCE
#include "navserve.h"
#include "serve_internal.h"

#include <arpa/inet.h>
#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <microhttpd.h>
#include <netinet/in.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include "navcore/nav_paths.h"
#include "navcore/nav_size_limits.h"
#ifdef NAVSERVE_HAVE_SCHEMA
#include "navcore/nav_schema.h"
#endif

const char *serve_tmp_dir(void);

#define CSP "default-src 'self'; frame-ancestors 'none'"

typedef struct static_file {
  char *url; /* without the leading '/' */
  char *path;
  const char *type;
} static_file;

static struct {
  serve_config cfg;
  int port;
  char hosts[6][300]; /* accepted Host header values */
  int n_hosts;
  char *imu_json, *gnss_json, *schema_json;
  serve_library lib;
  static_file *files;
  int n_files;
  char studio_dir[SERVE_PATH_MAX];
  char studio_why[SERVE_PATH_MAX + 128];
} S;

/* Per-request state: the body as it streams in. */
typedef struct req {
  sbuf body;
  size_t discarded;
  bool too_large;
  bool answered; /* a response was queued at the first call */
} req;

/* ------------------------------------------------------------------ responses */

static void common_headers(struct MHD_Response *r, bool api) {
  MHD_add_response_header(r, "Content-Security-Policy", CSP);
  MHD_add_response_header(r, "X-Content-Type-Options", "nosniff");
  MHD_add_response_header(r, "X-Frame-Options", "DENY");
  MHD_add_response_header(r, "Referrer-Policy", "no-referrer");
  MHD_add_response_header(r, "Cache-Control", api ? "no-store" : "no-cache");
}

static enum MHD_Result send_buf(struct MHD_Connection *c, unsigned status, const char *type, char *body,
                                size_t len, bool take) {
  struct MHD_Response *r =
      MHD_create_response_from_buffer(len, body, take ? MHD_RESPMEM_MUST_FREE : MHD_RESPMEM_PERSISTENT);
  if (!r) {
    if (take) free(body);
    return MHD_NO;
  }
  MHD_add_response_header(r, "Content-Type", type);
  common_headers(r, true);
  if (status == 429 || status == 503) {
    char s[32];
    snprintf(s, sizeof s, "%d", S.cfg.retry_after_s);
    MHD_add_response_header(r, "Retry-After", s);
  }
  if (status == 405) MHD_add_response_header(r, "Allow", "GET, HEAD, POST, DELETE");
  const enum MHD_Result ret = MHD_queue_response(c, status, r);
  MHD_destroy_response(r);
  return ret;
}

static enum MHD_Result send_json(struct MHD_Connection *c, unsigned status, char *body, size_t len) {
  if (!body) return send_buf(c, 500, "application/json", "{\"error\":\"out of memory\"}\n", 26, false);
  return send_buf(c, status, "application/json", body, len, true);
}

static enum MHD_Result send_static_json(struct MHD_Connection *c, unsigned status, const char *body) {
  return send_buf(c, status, "application/json", (char *)body, strlen(body), false);
}

/* {"error": MSG} */
static enum MHD_Result send_error(struct MHD_Connection *c, unsigned status, const char *msg) {
  sbuf b = {0};
  sb_puts(&b, "{\"error\":");
  sb_json_str(&b, msg);
  sb_puts(&b, "}\n");
  size_t len = 0;
  char *s = sb_take(&b, &len);
  return send_json(c, status, s, len);
}

static enum MHD_Result send_405(struct MHD_Connection *c, const char *allow) {
  char msg[128];
  snprintf(msg, sizeof msg, "method not allowed here; allowed: %s", allow);
  sbuf b = {0};
  sb_puts(&b, "{\"error\":");
  sb_json_str(&b, msg);
  sb_puts(&b, "}\n");
  size_t len = 0;
  char *s = sb_take(&b, &len);
  if (!s) return MHD_NO;
  struct MHD_Response *r = MHD_create_response_from_buffer(len, s, MHD_RESPMEM_MUST_FREE);
  if (!r) {
    free(s);
    return MHD_NO;
  }
  MHD_add_response_header(r, "Content-Type", "application/json");
  MHD_add_response_header(r, "Allow", allow);
  common_headers(r, true);
  const enum MHD_Result ret = MHD_queue_response(c, 405, r);
  MHD_destroy_response(r);
  return ret;
}

static const char *content_type(const char *name) {
  const char *dot = strrchr(name, '.');
  if (!dot) return "application/octet-stream";
  static const char *const map[][2] = {
      {".html", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"},
      {".mjs", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},
      {".json", "application/json"},
      {".geojson", "application/geo+json"},
      {".png", "image/png"},
      {".svg", "image/svg+xml"},
      {".ico", "image/x-icon"},
      {".txt", "text/plain; charset=utf-8"},
      {".csv", "text/csv; charset=utf-8"},
      {".kml", "application/vnd.google-earth.kml+xml"},
      {".yaml", "application/yaml"},
      {".zip", "application/zip"},
      {".woff2", "font/woff2"},
      {".map", "application/json"},
  };
  for (size_t i = 0; i < sizeof map / sizeof map[0]; ++i)
    if (strcmp(dot, map[i][0]) == 0) return map[i][1];
  return "application/octet-stream";
}

/* A file the server chose by a fixed list (never a path taken from the URL). */
static enum MHD_Result send_file(struct MHD_Connection *c, const char *path, const char *name,
                                 bool attachment, bool api) {
  const int fd = open(path, O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  struct stat sb;
  if (fd < 0 || fstat(fd, &sb) != 0 || !S_ISREG(sb.st_mode)) {
    if (fd >= 0) close(fd);
    return send_error(c, 404, "no such file");
  }
  struct MHD_Response *r = MHD_create_response_from_fd((uint64_t)sb.st_size, fd);
  if (!r) {
    close(fd);
    return MHD_NO;
  }
  MHD_add_response_header(r, "Content-Type", content_type(name));
  common_headers(r, api);
  if (attachment) {
    char disp[256];
    snprintf(disp, sizeof disp, "attachment; filename=\"%s\"", name);
    MHD_add_response_header(r, "Content-Disposition", disp);
  }
  const enum MHD_Result ret = MHD_queue_response(c, 200, r);
  MHD_destroy_response(r);
  return ret;
}

/* ------------------------------------------------------------------ request checks */

static void client_of(struct MHD_Connection *c, char *out, size_t size) {
  snprintf(out, size, "?");
  const union MHD_ConnectionInfo *ci = MHD_get_connection_info(c, MHD_CONNECTION_INFO_CLIENT_ADDRESS);
  if (!ci || !ci->client_addr) return;
  const struct sockaddr *sa = ci->client_addr;
  if (sa->sa_family == AF_INET)
    inet_ntop(AF_INET, &((const struct sockaddr_in *)(const void *)sa)->sin_addr, out, (socklen_t)size);
  else if (sa->sa_family == AF_INET6)
    inet_ntop(AF_INET6, &((const struct sockaddr_in6 *)(const void *)sa)->sin6_addr, out, (socklen_t)size);
}

static bool host_ok(const char *host) {
  if (!host) return true; /* HTTP/1.0 without Host: MHD's strict mode refuses HTTP/1.1 without it */
  for (int i = 0; i < S.n_hosts; ++i)
    if (strcasecmp(host, S.hosts[i]) == 0) return true;
  return false;
}

static bool origin_ok(const char *origin, const char *host) {
  if (!origin) return true;
  if (S.cfg.allowed_origin[0] && strcmp(origin, S.cfg.allowed_origin) == 0) return true;
  if (!host || strncmp(origin, "http://", 7) != 0) return false;
  return strcasecmp(origin + 7, host) == 0;
}

static bool body_type_ok(const char *type) {
  if (!type) return false;
  static const char *const ok[] = {"application/json", "application/yaml", "application/x-yaml", "text/yaml",
                                   "text/x-yaml"};
  size_t n = strcspn(type, ";");
  while (n > 0 && isspace((unsigned char)type[n - 1]))
    --n;
  for (size_t i = 0; i < sizeof ok / sizeof ok[0]; ++i)
    if (strlen(ok[i]) == n && strncasecmp(type, ok[i], n) == 0) return true;
  return false;
}

/* ------------------------------------------------------------------ the API */

static const char *hdr(struct MHD_Connection *c, const char *name) {
  return MHD_lookup_connection_value(c, MHD_HEADER_KIND, name);
}

/*
 * The limits a run of @p sc with @p runs Monte Carlo runs is held to before it is queued. False
 * with the field to change (@p path) and why (@p msg) when it is beyond them; otherwise *slurm
 * (a campaign for Slurm) and the predicted bytes of its result files.
 */
static bool run_limits(nav_scene *sc, long runs, bool *slurm, double *predicted, char *path, size_t path_size,
                       char *msg, size_t msg_size) {
  /* Campaigns above the local limit go to Slurm when it is configured (up to slurm_max_runs). */
  *slurm = S.cfg.slurm && runs > S.cfg.max_runs && runs <= S.cfg.slurm_max_runs;
  if (runs > S.cfg.max_runs && !*slurm) {
    snprintf(path, path_size, "simulation.runs");
    snprintf(msg, msg_size, "%ld Monte Carlo runs asked; this server runs at most %ld (%s)", runs,
             S.cfg.slurm ? S.cfg.slurm_max_runs : S.cfg.max_runs,
             S.cfg.slurm ? "slurm_max_runs" : "max_runs");
    return false;
  }
  sc->simulation.runs = runs;
  const double samples = sc->trajectory.duration_s * sc->imu.rate_hz * (double)runs;
  if (!*slurm && !(samples <= S.cfg.max_imu_samples)) {
    snprintf(path, path_size, "trajectory.duration_s");
    snprintf(msg, msg_size,
             "duration x IMU rate x runs = %.4g IMU samples; this server simulates at most %.4g "
             "(max_imu_samples): shorten trajectory.duration_s, lower imu.rate_hz or the runs",
             samples, S.cfg.max_imu_samples);
    return false;
  }
  nav_size_prediction pred;
  nav_predict_run(sc, false, S.cfg.job_threads, true, &pred);
  const double mib = 1024.0 * 1024.0;
  *predicted = pred.output_bytes;
  if (pred.output_bytes > (double)S.cfg.job_output_mb * mib) {
    snprintf(path, path_size, "output.rate_hz");
    snprintf(msg, msg_size,
             "the result files would take up to %.0f MiB (%s); this server keeps at most %ld MiB a run "
             "(job_output_mb): lower output.rate_hz or shorten the trajectory",
             pred.output_bytes / mib, pred.files, S.cfg.job_output_mb);
    return false;
  }
  if (!*slurm && pred.memory_bytes > (double)S.cfg.job_memory_mb * mib * 0.5) {
    snprintf(path, path_size, "simulation.runs");
    snprintf(msg, msg_size,
             "the run would need about %.0f MiB of memory (%s); this server allows %ld MiB a run",
             pred.memory_bytes / mib, pred.memory, S.cfg.job_memory_mb);
    return false;
  }
  return true;
}

static enum MHD_Result api_validate(struct MHD_Connection *c, const req *r) {
  serve_diags *d = malloc(sizeof *d);
  if (!d) return send_error(c, 500, "out of memory");
  nav_scene *sc = malloc(sizeof *sc);
  const bool ok = sc && serve_scene_check(r->body.s ? r->body.s : "", r->body.len, serve_tmp_dir(), sc, d);
  enum MHD_Result ret;
  char path[64], msg[512];
  double predicted = 0.0;
  bool slurm = false;
  if (ok && run_limits(sc, sc->simulation.runs, &slurm, &predicted, path, sizeof path, msg, sizeof msg)) {
    ret = send_static_json(c, 200, "{\"ok\":true}\n");
  } else if (ok) {
    /* Valid, but a run as it stands is beyond this server's limits: said as a warning (POST
     * /api/runs would answer 422 with the same text). */
    sbuf b = {0};
    sb_puts(&b, "{\"ok\":true,\"warnings\":[{\"path\":");
    sb_json_str(&b, path);
    sb_puts(&b, ",\"message\":");
    sb_json_str(&b, msg);
    sb_puts(&b, "}]}\n");
    size_t len = 0;
    char *j = sb_take(&b, &len);
    ret = send_json(c, 200, j, len);
  } else {
    size_t len = 0;
    char *j = serve_diags_json(d, "the scene is not valid", &len);
    ret = send_json(c, 422, j, len);
  }
  free(sc);
  free(d);
  return ret;
}

static enum MHD_Result limit_error(struct MHD_Connection *c, const char *path, const char *msg) {
  serve_diags *d = calloc(1, sizeof *d);
  if (!d) return send_error(c, 500, "out of memory");
  d->n = 1;
  snprintf(d->d[0].path, sizeof d->d[0].path, "%s", path);
  snprintf(d->d[0].message, sizeof d->d[0].message, "%s", msg);
  size_t len = 0;
  char *j = serve_diags_json(d, msg, &len);
  free(d);
  return send_json(c, 422, j, len);
}

static enum MHD_Result api_post_run(struct MHD_Connection *c, const req *r) {
  const char *runs_arg = MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "runs");
  long runs = 0;
  if (runs_arg) {
    char *end = NULL;
    errno = 0;
    const long v = strtol(runs_arg, &end, 10);
    if (!runs_arg[0] || !isdigit((unsigned char)runs_arg[0]) || *end || errno || v < 1)
      return send_error(c, 400, "runs: expected a positive integer");
    runs = v;
  }
  nav_scene *sc = malloc(sizeof *sc);
  serve_diags *d = malloc(sizeof *d);
  enum MHD_Result ret;
  char msg[512];
  if (!sc || !d) {
    ret = send_error(c, 500, "out of memory");
    goto cleanup;
  }
  if (!serve_scene_check(r->body.s ? r->body.s : "", r->body.len, serve_tmp_dir(), sc, d)) {
    size_t len = 0;
    char *j = serve_diags_json(d, "the scene is not valid", &len);
    ret = send_json(c, 422, j, len);
    goto cleanup;
  }
  if (runs == 0) runs = sc->simulation.runs;
  double predicted = 0.0;
  bool slurm = false;
  char path[64];
  if (!run_limits(sc, runs, &slurm, &predicted, path, sizeof path, msg, sizeof msg)) {
    ret = limit_error(c, path, msg);
    goto cleanup;
  }
  char client[64], id[33];
  client_of(c, client, sizeof client);
  const submit_rc rc = serve_jobs_submit(client, r->body.s ? r->body.s : "", r->body.len, sc, slurm, runs,
                                         predicted + 1e6, id);
  if (rc == SUBMIT_CLIENT_BUSY) {
    snprintf(msg, sizeof msg, "you have %d runs queued or running (max_jobs_per_client); try again later",
             S.cfg.max_jobs_per_client);
    ret = send_error(c, 429, msg);
  } else if (rc == SUBMIT_QUEUE_FULL) {
    ret = send_error(c, 429, "the queue of runs is full; try again later");
  } else if (rc == SUBMIT_NO_SPACE) {
    ret = send_error(c, 503, "the server has no room for more results now (disk_quota_mb); try again later");
  } else if (rc != SUBMIT_OK) {
    ret = send_error(c, 503, "the server cannot accept the run now");
  } else {
    char body[128], loc[64];
    snprintf(body, sizeof body, "{\"id\":\"%s\",\"state\":\"queued\"}\n", id);
    snprintf(loc, sizeof loc, "/api/runs/%s", id);
    char *b = strdup(body);
    struct MHD_Response *resp =
        b ? MHD_create_response_from_buffer(strlen(b), b, MHD_RESPMEM_MUST_FREE) : NULL;
    if (!resp) {
      free(b);
      ret = MHD_NO;
    } else {
      MHD_add_response_header(resp, "Content-Type", "application/json");
      MHD_add_response_header(resp, "Location", loc);
      common_headers(resp, true);
      ret = MHD_queue_response(c, 202, resp);
      MHD_destroy_response(resp);
    }
  }
cleanup:
  free(sc);
  free(d);
  return ret;
}

static enum MHD_Result api_estimate(struct MHD_Connection *c, const req *r) {
  serve_diags *d = malloc(sizeof *d);
  if (!d) return send_error(c, 500, "out of memory");
  const char *text = r->body.s ? r->body.s : "";
  serve_check_enter();
  const bool valid = serve_scene_check(text, r->body.len, serve_tmp_dir(), NULL, d);
  serve_check_leave();
  if (!valid) {
    size_t len = 0;
    char *j = serve_diags_json(d, "the scene is not valid", &len);
    free(d);
    return send_json(c, 422, j, len);
  }
  free(d);
  char *json = NULL, why[1024];
  size_t len = 0;
  const estimate_rc rc = serve_estimate(text, r->body.len, &json, &len, why, sizeof why);
  if (rc == EST_BUSY) return send_error(c, 429, "the server is computing other estimates; try again shortly");
  if (rc != EST_OK) return send_error(c, 422, why);
  return send_json(c, 200, json, len);
}

/* Server-sent events of one run. */
typedef struct stream {
  job *j;
  unsigned long seq;
  bool ended;
  char client[64];
  char buf[8192];
  size_t off, len;
  double heartbeat_s;
} stream;

static ssize_t stream_read(void *cls, uint64_t pos, char *out, size_t max) {
  (void)pos;
  stream *s = cls;
  if (s->off == s->len) {
    if (s->ended) return MHD_CONTENT_READER_END_OF_STREAM;
    bool final = false;
    s->off = 0;
    s->len = serve_job_event(s->j, &s->seq, s->heartbeat_s, s->buf, sizeof s->buf, &final);
    if (s->len == 0) {
      /* Nothing changed: a comment line keeps the connection (and any proxy) alive. */
      s->len = (size_t)snprintf(s->buf, sizeof s->buf, ": keep-alive\n\n");
    }
    if (final) s->ended = true;
  }
  const size_t n = s->len - s->off < max ? s->len - s->off : max;
  memcpy(out, s->buf + s->off, n);
  s->off += n;
  return (ssize_t)n;
}

static void stream_free(void *cls) {
  stream *s = cls;
  serve_streams_leave(s->client);
  serve_job_release(s->j);
  free(s);
}

static enum MHD_Result api_events(struct MHD_Connection *c, const char *id) {
  stream *s = calloc(1, sizeof *s);
  if (!s) return send_error(c, 500, "out of memory");
  client_of(c, s->client, sizeof s->client);
  s->j = serve_job_acquire(id);
  if (!s->j) {
    free(s);
    return send_error(c, 404, "no such run");
  }
  if (!serve_streams_enter(s->client)) {
    serve_job_release(s->j);
    free(s);
    char msg[160];
    snprintf(msg, sizeof msg,
             "too many event streams open (max_event_streams_per_client %d, max_event_streams %d)",
             S.cfg.max_streams_per_client, S.cfg.max_streams);
    return send_error(c, 429, msg);
  }
  s->seq = ULONG_MAX;
  s->heartbeat_s = S.cfg.connection_timeout_s / 2.0 < 15.0 ? S.cfg.connection_timeout_s / 2.0 : 15.0;
  struct MHD_Response *r =
      MHD_create_response_from_callback(MHD_SIZE_UNKNOWN, 4096, stream_read, s, stream_free);
  if (!r) {
    stream_free(s);
    return MHD_NO;
  }
  MHD_add_response_header(r, "Content-Type", "text/event-stream");
  MHD_add_response_header(r, "X-Accel-Buffering", "no");
  common_headers(r, true);
  const enum MHD_Result ret = MHD_queue_response(c, 200, r);
  MHD_destroy_response(r);
  return ret;
}

static enum MHD_Result api_runs(struct MHD_Connection *c, const char *method, const char *rest) {
  /* rest: "ID", "ID/events" or "ID/files/NAME" */
  char id[33];
  const size_t n = strcspn(rest, "/");
  if (n != 32) return send_error(c, 400, "invalid run id: expected 32 lower-case hex digits");
  memcpy(id, rest, 32);
  id[32] = '\0';
  if (!serve_is_id(id)) return send_error(c, 400, "invalid run id: expected 32 lower-case hex digits");
  const char *tail = rest + 32;
  const bool get = strcmp(method, "GET") == 0 || strcmp(method, "HEAD") == 0;
  if (tail[0] == '\0') {
    if (get) {
      size_t len = 0;
      char *j = serve_job_json(id, &len);
      return j ? send_json(c, 200, j, len)
               : send_error(c, 404, "no such run (unknown, or its results expired)");
    }
    if (strcmp(method, "DELETE") == 0) {
      size_t len = 0;
      bool was_finished = false;
      char *j = serve_job_cancel(id, &len, &was_finished);
      if (!j) return send_error(c, 404, "no such run (unknown, or its results expired)");
      if (was_finished) {
        free(j);
        return send_error(c, 409, "the run has already finished");
      }
      return send_json(c, 202, j, len);
    }
    return send_405(c, "GET, HEAD, DELETE");
  }
  if (strcmp(tail, "/events") == 0) return get ? api_events(c, id) : send_405(c, "GET");
  if (strncmp(tail, "/files/", 7) == 0) {
    if (!get) return send_405(c, "GET, HEAD");
    const char *name = tail + 7;
    char path[SERVE_PATH_MAX + 128];
    switch (serve_job_file(id, name, path, sizeof path)) {
    case FILE_NO_JOB: return send_error(c, 404, "no such run (unknown, or its results expired)");
    case FILE_NOT_DONE: return send_error(c, 409, "the run has not finished yet");
    case FILE_MISSING: return send_error(c, 404, "no such result file for this run");
    case FILE_OK: break;
    }
    return send_file(c, path, name, strcmp(name, "summary.json") != 0, true);
  }
  return send_error(c, 404, "no such resource");
}

static enum MHD_Result api_limits(struct MHD_Connection *c) {
  sbuf b = {0};
  const serve_config *g = &S.cfg;
  sb_printf(&b,
            "{\"max_body_bytes\":%ld,\"max_runs\":%ld,\"max_imu_samples\":%.17g,\"job_cpu_s\":%ld,\"job_wall_"
            "s\":%ld,"
            "\"job_output_mb\":%ld,\"job_memory_mb\":%ld,\"max_jobs_per_client\":%d,\"max_queued_jobs\":%d,"
            "\"max_parallel_jobs\":%d,\"max_event_streams_per_client\":%d,\"result_max_age_s\":%ld,"
            "\"estimate_cpu_s\":%ld,\"result_files\":[",
            g->max_body_bytes, g->max_runs, g->max_imu_samples, g->job_cpu_s, g->job_wall_s, g->job_output_mb,
            g->job_memory_mb, g->max_jobs_per_client, g->max_queued_jobs, g->max_parallel_jobs,
            g->max_streams_per_client, g->result_max_age_s, g->estimate_cpu_s);
  for (int i = 0; i < serve_n_result_files; ++i)
    sb_printf(&b, "%s\"%s\"", i ? "," : "", serve_result_files[i]);
  sb_puts(&b, "]}\n");
  size_t len = 0;
  char *s = sb_take(&b, &len);
  return send_json(c, 200, s, len);
}

static enum MHD_Result route_api(struct MHD_Connection *c, const char *method, const char *url,
                                 const req *r) {
  const bool get = strcmp(method, "GET") == 0 || strcmp(method, "HEAD") == 0;
  const bool post = strcmp(method, "POST") == 0;
  const char *p = url + 5; /* after "/api/" */
  if (strcmp(p, "catalog/imu") == 0 || strcmp(p, "catalog/gnss") == 0) {
    if (!get) return send_405(c, "GET, HEAD");
    const char *j = p[8] == 'i' ? S.imu_json : S.gnss_json;
    return send_static_json(c, 200, j);
  }
  if (strcmp(p, "schema") == 0) {
    if (!get) return send_405(c, "GET, HEAD");
    if (!S.schema_json)
      return send_error(c, 503,
                        "the scene JSON Schema is not available in this build (nav_schema_json is missing)");
    return send_buf(c, 200, "application/schema+json", S.schema_json, strlen(S.schema_json), false);
  }
  if (strcmp(p, "limits") == 0) return get ? api_limits(c) : send_405(c, "GET, HEAD");
  if (strcmp(p, "scenes") == 0) return get ? send_static_json(c, 200, S.lib.json) : send_405(c, "GET, HEAD");
  if (strncmp(p, "scenes/", 7) == 0) {
    if (!get) return send_405(c, "GET, HEAD");
    for (int i = 0; i < S.lib.n; ++i)
      if (strcmp(S.lib.e[i].name, p + 7) == 0)
        return send_file(c, S.lib.e[i].path, "scene.yaml", false, true);
    return send_error(c, 404, "no such scene in the library (GET /api/scenes lists them)");
  }
  if (strcmp(p, "validate") == 0 || strcmp(p, "runs") == 0) {
    if (!post) return send_405(c, "POST");
    serve_check_enter();
    const enum MHD_Result ret = p[0] == 'v' ? api_validate(c, r) : api_post_run(c, r);
    serve_check_leave();
    return ret;
  }
  if (strcmp(p, "estimate") == 0) return post ? api_estimate(c, r) : send_405(c, "POST");
  if (strncmp(p, "runs/", 5) == 0) return api_runs(c, method, p + 5);
  return send_error(c, 404, "no such API resource");
}

static enum MHD_Result route_static(struct MHD_Connection *c, const char *method, const char *url) {
  if (strcmp(method, "GET") != 0 && strcmp(method, "HEAD") != 0) return send_405(c, "GET, HEAD");
  const char *name = strcmp(url, "/") == 0 ? "index.html" : url + 1;
  for (int i = 0; i < S.n_files; ++i)
    if (strcmp(S.files[i].url, name) == 0) return send_file(c, S.files[i].path, S.files[i].url, false, false);
  if (S.n_files == 0 && strcmp(url, "/") == 0) return send_error(c, 404, S.studio_why);
  return send_error(c, 404, "not found");
}

static bool is_body_route(const char *url) {
  return strcmp(url, "/api/validate") == 0 || strcmp(url, "/api/estimate") == 0 ||
         strcmp(url, "/api/runs") == 0;
}

static enum MHD_Result handler(void *cls, struct MHD_Connection *c, const char *url, const char *method,
                               const char *version, const char *upload_data, size_t *upload_data_size,
                               void **con_cls) {
  (void)cls;
  (void)version;
  req *r = *con_cls;
  if (!r) {
    r = calloc(1, sizeof *r);
    if (!r) return MHD_NO;
    *con_cls = r;
    /* Checks that need no body: answered at once (MHD then closes the connection when a body
     * was announced and not read). */
    const char *host = hdr(c, "Host");
    if (!host_ok(host)) {
      r->answered = true;
      return send_error(c, 403, "unknown Host (this server answers for its own address only)");
    }
    if (!origin_ok(hdr(c, "Origin"), host)) {
      r->answered = true;
      return send_error(c, 403, "cross-origin request refused (same origin only)");
    }
    if (strcmp(method, "POST") == 0 && is_body_route(url)) {
      if (!body_type_ok(hdr(c, "Content-Type"))) {
        r->answered = true;
        return send_error(
            c, 415, "the body must be a scene: Content-Type application/yaml, text/yaml or application/json");
      }
      const char *cl = hdr(c, "Content-Length");
      if (cl && strtod(cl, NULL) > (double)S.cfg.max_body_bytes) {
        r->answered = true;
        char msg[128];
        snprintf(msg, sizeof msg, "the body is larger than %ld bytes (max_body_bytes)", S.cfg.max_body_bytes);
        return send_error(c, 413, msg);
      }
    }
    return MHD_YES;
  }
  if (*upload_data_size > 0) {
    /* The body streams in: kept up to the cap, the rest counted and dropped; a sender that goes
     * on far beyond the cap is disconnected. */
    if (!r->answered && !r->too_large && r->body.len + *upload_data_size <= (size_t)S.cfg.max_body_bytes) {
      sb_add(&r->body, upload_data, *upload_data_size);
      if (r->body.failed) return MHD_NO;
    } else {
      r->too_large = true;
      r->discarded += *upload_data_size;
      if (r->discarded > 4 * (size_t)S.cfg.max_body_bytes) return MHD_NO;
    }
    *upload_data_size = 0;
    return MHD_YES;
  }
  if (r->answered) return MHD_YES;
  r->answered = true;
  if (r->too_large) {
    char msg[128];
    snprintf(msg, sizeof msg, "the body is larger than %ld bytes (max_body_bytes)", S.cfg.max_body_bytes);
    return send_error(c, 413, msg);
  }
  if (strncmp(url, "/api/", 5) == 0) return route_api(c, method, url, r);
  if (strcmp(url, "/api") == 0) return send_error(c, 404, "no such API resource");
  return route_static(c, method, url);
}

/* Percent-decoding of the URL and query values in place, except %00: a NUL would cut the text
 * short ("/index.html%00.png" read as "/index.html"), so it stays as the three characters. */
static size_t unescape(void *cls, struct MHD_Connection *c, char *s) {
  (void)cls;
  (void)c;
  char *w = s;
  for (const char *r = s; *r;) {
    if (r[0] == '%' && isxdigit((unsigned char)r[1]) && isxdigit((unsigned char)r[2])) {
      const char hex[3] = {r[1], r[2], '\0'};
      const long v = strtol(hex, NULL, 16);
      if (v != 0) {
        *w++ = (char)v;
        r += 3;
        continue;
      }
    }
    *w++ = *r++;
  }
  *w = '\0';
  return (size_t)(w - s);
}

static void completed(void *cls, struct MHD_Connection *c, void **con_cls,
                      enum MHD_RequestTerminationCode toe) {
  (void)cls;
  (void)c;
  (void)toe;
  req *r = *con_cls;
  if (!r) return;
  sb_free(&r->body);
  free(r);
  *con_cls = NULL;
}

/* ------------------------------------------------------------------ start-up */

static bool manifest_name_ok(const char *s) {
  const size_t n = strlen(s);
  if (n == 0 || n > 400 || s[0] == '/' || s[n - 1] == '/') return false;
  for (size_t i = 0; i < n; ++i) {
    const char ch = s[i];
    if (!(isalnum((unsigned char)ch) || ch == '.' || ch == '-' || ch == '_' || ch == '/')) return false;
    /* No empty, "." or ".." component, and no hidden file. */
    if ((i == 0 || s[i - 1] == '/') && (ch == '.' || ch == '/')) return false;
  }
  return strncmp(s, "api/", 4) != 0 && strcmp(s, "api") != 0;
}

static bool load_manifest(const char *dir) {
  char path[SERVE_PATH_MAX + 32];
  snprintf(path, sizeof path, "%s/manifest.txt", dir);
  size_t len = 0;
  char *text = serve_read_file(path, 1u << 20, &len);
  if (!text) {
    snprintf(S.studio_why, sizeof S.studio_why, "the studio is not installed: %s cannot be read", path);
    return false;
  }
  int cap = 0;
  for (char *line = strtok(text, "\r\n"); line; line = strtok(NULL, "\r\n")) {
    while (*line == ' ' || *line == '\t')
      ++line;
    size_t n = strlen(line);
    while (n > 0 && (line[n - 1] == ' ' || line[n - 1] == '\t'))
      line[--n] = '\0';
    if (n == 0 || line[0] == '#') continue;
    if (!manifest_name_ok(line)) {
      fprintf(stderr, "navsim serve: %s: warning: \"%s\" is not a plain relative file name; not served\n",
              path, line);
      continue;
    }
    char fp[SERVE_PATH_MAX + 512];
    snprintf(fp, sizeof fp, "%s/%s", dir, line);
    struct stat sb;
    if (lstat(fp, &sb) != 0 || !S_ISREG(sb.st_mode)) {
      fprintf(stderr, "navsim serve: %s: warning: \"%s\" is not a regular file; not served\n", path, line);
      continue;
    }
    if (S.n_files == cap) {
      cap = cap ? 2 * cap : 64;
      static_file *p = realloc(S.files, (size_t)cap * sizeof *p);
      if (!p) break;
      S.files = p;
    }
    static_file *f = &S.files[S.n_files];
    f->url = strdup(line);
    f->path = strdup(fp);
    f->type = content_type(line);
    if (!f->url || !f->path) break;
    ++S.n_files;
    if (S.n_files >= 10000) break;
  }
  free(text);
  return S.n_files > 0;
}

/* The studio bundle: --studio-dir / studio_dir, else <share>/studio (installed), else the build
 * tree's web/studio (<build>/share/navcore/../../web/studio). */
static void find_studio(void) {
  char share[SERVE_PATH_MAX];
  if (S.cfg.studio_dir[0]) {
    snprintf(S.studio_dir, sizeof S.studio_dir, "%s", S.cfg.studio_dir);
    load_manifest(S.studio_dir);
    return;
  }
  snprintf(S.studio_why, sizeof S.studio_why, "the studio is not installed (no manifest.txt found)");
  if (!nav_paths_share_dir(share, sizeof share)) return;
  const char *cands[2] = {"%s/studio", "%s/../../web/studio"};
  for (int i = 0; i < 2; ++i) {
    char d[SERVE_PATH_MAX];
    if (snprintf(d, sizeof d, cands[i], share) >= (int)sizeof d) continue;
    char m[SERVE_PATH_MAX + 16];
    snprintf(m, sizeof m, "%s/manifest.txt", d);
    if (access(m, R_OK) == 0) {
      snprintf(S.studio_dir, sizeof S.studio_dir, "%s", d);
      load_manifest(d);
      return;
    }
  }
}

static const char *k_usage =
    "usage: navsim serve [--bind ADDR] [--port N] [--data-dir DIR] [--config FILE] [--studio-dir DIR]\n"
    "\n"
    "Serve the browser studio and the JSON API of the web variant (docs/web-server.md). Every\n"
    "simulation runs in its own process (navsim run), limited in CPU time, memory, file sizes and\n"
    "open files, in its own directory DIR/jobs/<id>/; results expire by age under a disk quota.\n"
    "The first line on stdout is \"listening on http://HOST:PORT/\". SIGINT or SIGTERM stops the\n"
    "server: no new connections, running jobs are cancelled (their process groups ended), exit 0.\n"
    "\n"
    "options:\n"
    "  --bind ADDR      address to listen on (default 127.0.0.1; a reverse proxy adds TLS)\n"
    "  --port N         TCP port (default 8080; 0: any free port, printed on the first line)\n"
    "  --data-dir DIR   job directories and temporary files (default $TMPDIR/navsim-serve-UID)\n"
    "  --config FILE    limits and settings, \"key = value\" lines (docs/web-server.md lists\n"
    "                   the keys and their defaults); the options above override the file\n"
    "  --studio-dir DIR the studio bundle: DIR/manifest.txt lists the files served (default:\n"
    "                   <share>/studio, or web/studio of the build tree)\n"
    "  -h, --help       print this help\n"
    "\n"
    "exit codes: 0 stopped by SIGINT/SIGTERM; 1 cannot start (address in use, data directory);\n"
    "            2 invalid options or configuration\n";

static bool parse_port(const char *v, int *out) {
  char *end = NULL;
  errno = 0;
  const long p = strtol(v, &end, 10);
  if (!v[0] || *end || errno || p < 0 || p > 65535) return false;
  *out = (int)p;
  return true;
}

int navserve_main(int argc, char **argv) {
  const char *bind_arg = NULL, *data_dir = NULL, *config = NULL, *studio = NULL;
  int port = -1;
  for (int i = 0; i < argc; ++i) {
    const char *a = argv[i];
    if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
      fputs(k_usage, stdout);
      return 0;
    }
    const bool known = strcmp(a, "--bind") == 0 || strcmp(a, "--port") == 0 || strcmp(a, "--data-dir") == 0 ||
                       strcmp(a, "--config") == 0 || strcmp(a, "--studio-dir") == 0;
    if (!known) {
      fprintf(stderr, "navsim serve: unknown option \"%s\" (see navsim serve --help)\n", a);
      return 2;
    }
    if (i + 1 >= argc) {
      fprintf(stderr, "navsim serve: %s needs a value\n", a);
      return 2;
    }
    const char *v = argv[++i];
    if (strcmp(a, "--bind") == 0)
      bind_arg = v;
    else if (strcmp(a, "--data-dir") == 0)
      data_dir = v;
    else if (strcmp(a, "--config") == 0)
      config = v;
    else if (strcmp(a, "--studio-dir") == 0)
      studio = v;
    else if (!parse_port(v, &port)) {
      fprintf(stderr, "navsim serve: --port: expected an integer in [0, 65535], got \"%s\"\n", v);
      return 2;
    }
  }
  serve_config cfg = serve_config_default();
  if (config && !serve_config_read(config, &cfg)) return 2;
  if (bind_arg) snprintf(cfg.bind, sizeof cfg.bind, "%s", bind_arg);
  if (port >= 0) cfg.port = port;
  if (data_dir) snprintf(cfg.data_dir, sizeof cfg.data_dir, "%s", data_dir);
  if (studio) snprintf(cfg.studio_dir, sizeof cfg.studio_dir, "%s", studio);
  if (cfg.max_streams_per_client > cfg.max_streams) cfg.max_streams_per_client = cfg.max_streams;
  S.cfg = cfg;
  serve_checks_init(cfg.max_parallel_jobs + 2);

  /* The address: a numeric IPv4 or IPv6 literal. */
  struct sockaddr_in sa4;
  struct sockaddr_in6 sa6;
  memset(&sa4, 0, sizeof sa4);
  memset(&sa6, 0, sizeof sa6);
  bool v6 = false;
  if (inet_pton(AF_INET, cfg.bind, &sa4.sin_addr) == 1) {
    sa4.sin_family = AF_INET;
    sa4.sin_port = htons((uint16_t)cfg.port);
  } else if (inet_pton(AF_INET6, cfg.bind, &sa6.sin6_addr) == 1) {
    v6 = true;
    sa6.sin6_family = AF_INET6;
    sa6.sin6_port = htons((uint16_t)cfg.port);
  } else {
    fprintf(stderr, "navsim serve: --bind: expected a numeric IPv4 or IPv6 address, got \"%s\"\n", cfg.bind);
    return 2;
  }

  /* SIGINT and SIGTERM are taken by sigwait() below: blocked in every thread started from here. */
  sigset_t stop_set;
  sigemptyset(&stop_set);
  sigaddset(&stop_set, SIGINT);
  sigaddset(&stop_set, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop_set, NULL);
  signal(SIGPIPE, SIG_IGN);
  umask(077); /* job directories and results are private to this user */

  int rc = 1;
  int lsock = -1;
  struct MHD_Daemon *d = NULL;
  char why[SERVE_PATH_MAX + 256];
  if (!serve_jobs_start(&cfg, why, sizeof why)) {
    fprintf(stderr, "navsim serve: %s\n", why);
    goto cleanup;
  }
  if (!serve_catalogs_load(&S.imu_json, &S.gnss_json, why, sizeof why) ||
      !serve_library_load(&S.lib, serve_tmp_dir(), why, sizeof why)) {
    fprintf(stderr, "navsim serve: %s\n", why);
    goto cleanup;
  }
#ifdef NAVSERVE_HAVE_SCHEMA
  S.schema_json = nav_schema_json();
#endif
  find_studio();
  if (S.n_files == 0) fprintf(stderr, "navsim serve: warning: %s; serving the API only\n", S.studio_why);

  /* The listening socket is made here, so that its port (of --port 0) and the Host values this
   * server answers to (a defence against DNS rebinding) are known before any request arrives. */
  lsock = socket(v6 ? AF_INET6 : AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  const int one = 1;
  if (lsock >= 0) (void)setsockopt(lsock, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  const struct sockaddr *sa =
      v6 ? (const struct sockaddr *)(const void *)&sa6 : (const struct sockaddr *)(const void *)&sa4;
  if (lsock < 0 || bind(lsock, sa, v6 ? sizeof sa6 : sizeof sa4) != 0 || listen(lsock, 128) != 0) {
    fprintf(stderr, "navsim serve: cannot listen on %s port %d: %s\n", cfg.bind, cfg.port, strerror(errno));
    goto cleanup;
  }
  struct sockaddr_storage bound;
  socklen_t blen = sizeof bound;
  if (getsockname(lsock, (struct sockaddr *)(void *)&bound, &blen) != 0) goto cleanup;
  S.port = ntohs(v6 ? ((struct sockaddr_in6 *)(void *)&bound)->sin6_port
                    : ((struct sockaddr_in *)(void *)&bound)->sin_port);
  const char *fmt = v6 ? "[%s]:%d" : "%s:%d";
  snprintf(S.hosts[S.n_hosts++], sizeof S.hosts[0], fmt, cfg.bind, S.port);
  snprintf(S.hosts[S.n_hosts++], sizeof S.hosts[0], "localhost:%d", S.port);
  snprintf(S.hosts[S.n_hosts++], sizeof S.hosts[0], "127.0.0.1:%d", S.port);
  snprintf(S.hosts[S.n_hosts++], sizeof S.hosts[0], "[::1]:%d", S.port);
  if (cfg.allowed_origin[0]) {
    const char *h = strstr(cfg.allowed_origin, "://");
    snprintf(S.hosts[S.n_hosts++], sizeof S.hosts[0], "%s", h ? h + 3 : cfg.allowed_origin);
  }
  const unsigned flags = MHD_USE_THREAD_PER_CONNECTION | MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_POLL |
                         MHD_USE_ITC | (v6 ? MHD_USE_IPv6 : 0);
  d = MHD_start_daemon(
      flags, (uint16_t)S.port, NULL, NULL, handler, NULL, MHD_OPTION_LISTEN_SOCKET, lsock,
      MHD_OPTION_CONNECTION_LIMIT, (unsigned)cfg.max_connections, MHD_OPTION_PER_IP_CONNECTION_LIMIT,
      (unsigned)cfg.max_connections_per_client, MHD_OPTION_CONNECTION_TIMEOUT,
      (unsigned)cfg.connection_timeout_s, MHD_OPTION_CONNECTION_MEMORY_LIMIT, (size_t)(64 * 1024),
      MHD_OPTION_NOTIFY_COMPLETED, completed, NULL, MHD_OPTION_UNESCAPE_CALLBACK, unescape, NULL,
      MHD_OPTION_STRICT_FOR_CLIENT, (int)1, MHD_OPTION_THREAD_STACK_SIZE, (size_t)(2u << 20), MHD_OPTION_END);
  if (!d) {
    fprintf(stderr, "navsim serve: cannot start the HTTP server on %s port %d\n", cfg.bind, S.port);
    goto cleanup;
  }
  printf(v6 ? "listening on http://[%s]:%d/\n" : "listening on http://%s:%d/\n", cfg.bind, S.port);
  fflush(stdout);

  int sig = 0;
  while (sigwait(&stop_set, &sig) != 0) {
  }
  fprintf(stderr, "navsim serve: signal %d: stopping (running jobs are cancelled)\n", sig);
  (void)MHD_quiesce_daemon(d); /* no new connections (the socket comes back to us: closed below) */
  rc = 0;

cleanup:
  serve_jobs_stop(); /* cancels jobs; event streams see the stop and end */
  if (d) MHD_stop_daemon(d);
  if (lsock >= 0) close(lsock);
  for (int i = 0; i < S.n_files; ++i) {
    free(S.files[i].url);
    free(S.files[i].path);
  }
  free(S.files);
  free(S.imu_json);
  free(S.gnss_json);
  free(S.schema_json);
  serve_library_free(&S.lib);
  if (rc == 0) fprintf(stderr, "navsim serve: stopped\n");
  return rc;
}
