/**
 * @file nav_test_table.h
 * @brief A result CSV (mc_stats.csv, estimate.csv, gnss_dop.csv, ...) read into memory for the
 *        statistical scenario tests: the header's column names and the numeric rows (empty cells
 *        read as 0), and the Wilson-Hilferty chi-square quantile their bands use.
 *
 * Include after <cmocka.h> and navsim_cli.h.
 */
#ifndef NAV_TEST_TABLE_H
#define NAV_TEST_TABLE_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The chi-square quantile over its degrees of freedom, chi2_k(z) / k, by Wilson-Hilferty: @p z is
 * the standard normal quantile (e.g. 2.576 for the upper 99.5 %). */
static inline double nav_chi2_over_k(double k, double z) {
  const double a = 2.0 / (9.0 * k);
  const double c = 1.0 - a + z * sqrt(a);
  return c * c * c;
}

typedef struct nav_table {
  int ncol, nrow;
  char names[64][48];
  double *v; /* [nrow][ncol] */
} nav_table;

/* Read @p path (a header line, then rows of numbers); fails the test when it cannot. */
static inline void nav_table_read(const char *path, nav_table *t) {
  char *text = nav_test_slurp_alloc(path);
  if (!text) fail_msg("cannot read %s", path);
  memset(t, 0, sizeof *t);
  char *line = strtok(text, "\n");
  assert_non_null(line);
  for (char *p = line; t->ncol < 64;) {
    char *c = strchr(p, ',');
    const size_t len = c ? (size_t)(c - p) : strlen(p);
    snprintf(t->names[t->ncol], sizeof t->names[0], "%.*s", (int)(len < 47 ? len : 47), p);
    t->ncol++;
    if (!c) break;
    p = c + 1;
  }
  size_t cap = 1024;
  t->v = malloc(cap * (size_t)t->ncol * sizeof *t->v);
  assert_non_null(t->v);
  for (line = strtok(NULL, "\n"); line; line = strtok(NULL, "\n")) {
    if ((size_t)t->nrow == cap) {
      cap *= 2;
      t->v = realloc(t->v, cap * (size_t)t->ncol * sizeof *t->v);
      assert_non_null(t->v);
    }
    char *p = line;
    for (int c = 0; c < t->ncol; ++c) {
      char *end = NULL;
      t->v[(size_t)t->nrow * (size_t)t->ncol + (size_t)c] = strtod(p, &end);
      p = end && *end == ',' ? end + 1 : end;
    }
    t->nrow++;
  }
  free(text);
}

/* Index of the column @p name; fails the test when there is none. */
static inline int nav_table_col(const nav_table *t, const char *name) {
  for (int c = 0; c < t->ncol; ++c)
    if (!strcmp(t->names[c], name)) return c;
  fail_msg("no column %s", name);
  return -1;
}

static inline double nav_table_at(const nav_table *t, int row, int c) {
  return t->v[(size_t)row * (size_t)t->ncol + (size_t)c];
}

/* Row whose t_s is @p time_s (to 1e-6 s), or -1. */
static inline int nav_table_row_at(const nav_table *t, double time_s) {
  const int c = nav_table_col(t, "t_s");
  for (int r = 0; r < t->nrow; ++r)
    if (fabs(nav_table_at(t, r, c) - time_s) < 1e-6) return r;
  return -1;
}

#endif /* NAV_TEST_TABLE_H */
