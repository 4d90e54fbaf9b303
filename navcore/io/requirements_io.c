/*
 * Requirement verdicts in result files and on the terminal (nav_results.h): the "requirements"
 * list of summary.json and the lines of the terminal summary, shared by navsim run, replay,
 * estimate, select and sweep.
 */
#include <math.h>
#include <stdio.h>

#include "navcore/nav_results.h"

static void json_str(FILE *f, const char *s) {
  fputc('"', f);
  for (const unsigned char *p = (const unsigned char *)(s ? s : ""); *p; ++p) {
    if (*p == '"' || *p == '\\') fprintf(f, "\\%c", *p);
    else if (*p < 0x20) fprintf(f, "\\u%04x", *p);
    else fputc(*p, f);
  }
  fputc('"', f);
}

static void json_num(FILE *f, double v) {
  if (isfinite(v)) fprintf(f, "%.17g", v);
  else fputs("null", f);
}

nav_status nav_requirements_write_json(FILE *f, const nav_requirement_verdict *v, int count, int indent) {
  if (!f || count < 0 || (count > 0 && !v)) return NAV_ERR_INVALID_ARG;
  if (count == 0) {
    fputs("[]", f);
    return ferror(f) ? NAV_ERR_IO : NAV_OK;
  }
  fputs("[\n", f);
  for (int i = 0; i < count; ++i) {
    const nav_requirement_verdict *q = &v[i];
    fprintf(f, "%*s{\"id\": ", indent + 2, "");
    json_str(f, q->id);
    fprintf(f, ", \"metric\": \"%s\", \"statistic\": \"%s\", \"limit\": ", nav_req_metric_name(q->metric),
            nav_req_statistic_name(q->statistic));
    json_num(f, q->limit);
    fprintf(f, ", \"unit\": \"%s\", \"value\": ", nav_req_unit_name(q->unit));
    json_num(f, q->value);
    fprintf(f, ", \"pass\": %s, \"samples\": %ld", q->pass ? "true" : "false", q->samples);
    /* Only for a verdict without a value (added keys; evaluated verdicts keep their bytes). */
    if (!q->evaluated) {
      fputs(", \"evaluated\": false, \"reason\": ", f);
      json_str(f, nav_req_na_reason_text(q->na_reason));
    }
    if (q->statistic == NAV_REQ_AT_TIME) {
      fputs(", \"time_s\": ", f);
      json_num(f, q->at_time_s);
    }
    if (q->statistic == NAV_REQ_OUTAGE_END) {
      fputs(", \"outages\": [", f);
      for (int j = 0; j < q->outage_count && j < NAV_REQ_MAX_OUTAGES; ++j) {
        fputs(j ? ", {\"t0_s\": " : "{\"t0_s\": ", f);
        json_num(f, q->outage_t0_s[j]);
        fputs(", \"t1_s\": ", f);
        json_num(f, q->outage_t1_s[j]);
        fputs(", \"t_s\": ", f);
        json_num(f, q->outage_end_t_s[j]);
        fputs(", \"value\": ", f);
        json_num(f, q->outage_value[j]);
        fputs("}", f);
      }
      fputs("]", f);
    }
    fprintf(f, "}%s\n", i + 1 < count ? "," : "");
  }
  fprintf(f, "%*s]", indent, "");
  return ferror(f) ? NAV_ERR_IO : NAV_OK;
}

void nav_requirements_print(FILE *f, const nav_requirement_verdict *v, int count) {
  nav_requirements_print_at(f, v, count, 0.0);
}

/* A time of a verdict as printed: "%g" as always without an offset; with one (a recorded file's
 * time base, seconds of week) "%.3f", which keeps the milliseconds that "%g" would round off. */
static const char *time_text(char *buf, size_t cap, double t_s, double off) {
  if (off != 0.0) snprintf(buf, cap, "%.3f", t_s + off);
  else snprintf(buf, cap, "%g", t_s);
  return buf;
}

void nav_requirements_print_at(FILE *f, const nav_requirement_verdict *v, int count, double t_offset_s) {
  if (!f || count <= 0 || !v) return;
  const double off = t_offset_s;
  char t1[64], t2[64], t3[64];
  int pass = 0, na = 0;
  for (int i = 0; i < count; ++i) {
    pass += v[i].pass ? 1 : 0;
    na += v[i].evaluated ? 0 : 1;
  }
  if (na > 0) fprintf(f, "requirements %d of %d pass, %d not evaluated\n", pass, count, na);
  else fprintf(f, "requirements %d of %d pass\n", pass, count);
  for (int i = 0; i < count; ++i) {
    const nav_requirement_verdict *q = &v[i];
    const char *u = nav_req_unit_name(q->unit);
    fprintf(f, "  %s  %-20s %s %s", !q->evaluated ? "N/A " : q->pass ? "PASS" : "FAIL",
            q->id, nav_req_metric_name(q->metric), nav_req_statistic_name(q->statistic));
    if (q->statistic == NAV_REQ_AT_TIME && q->evaluated)
      fprintf(f, " (t = %s s)", time_text(t1, sizeof t1, q->at_time_s, off));
    if (q->evaluated) fprintf(f, " = %.4g %s %s %.4g %s\n", q->value, u, q->pass ? "<=" : ">", q->limit, u);
    else if (q->na_reason == NAV_REQ_NA_TIME_OUTSIDE)
      fprintf(f, ": not evaluated: t = %s s lies outside the run's epochs [%s, %s] s (limit %.4g %s)\n",
              time_text(t1, sizeof t1, q->at_time_s, off), time_text(t2, sizeof t2, q->span_t0_s, off),
              time_text(t3, sizeof t3, q->span_t1_s, off), q->limit, u);
    else
      fprintf(f, ": not evaluated: %s (limit %.4g %s)\n",
              q->na_reason != NAV_REQ_NA_NONE ? nav_req_na_reason_text(q->na_reason) : "no data", q->limit, u);
    if (q->statistic == NAV_REQ_OUTAGE_END)
      for (int j = 0; j < q->outage_count && j < NAV_REQ_MAX_OUTAGES; ++j) {
        time_text(t1, sizeof t1, q->outage_t0_s[j], off);
        time_text(t2, sizeof t2, q->outage_t1_s[j], off);
        if (isnan(q->outage_value[j])) fprintf(f, "        outage [%s, %s) s: no output epoch inside\n", t1, t2);
        else fprintf(f, "        outage [%s, %s) s: %.4g %s at t = %s s\n", t1, t2, q->outage_value[j], u,
                     time_text(t3, sizeof t3, q->outage_end_t_s[j], off));
      }
  }
}
