/*
 * The fast paths of navsim replay against the plain ones (issue 23 item 2): the IMU file read once
 * into memory on two threads (nav_rec_imu_array_load) against the streaming reader, record by
 * record and message by message; and the replay with the IMU array, the read-ahead thread and the
 * scoring thread (callbacks_on_worker) against the replay that does everything on the calling
 * thread: the same summary, bit for bit, and the same callbacks in the same order.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "nav_test.h"
#include "navcore/nav_io.h"
#include "navcore/nav_recorded.h"

#define REPLAY_DIR NAV_TEST_DATA_DIR "/replay/"
#define SLICE_IMU REPLAY_DIR "IMU-100195-100245.txt"
#define SLICE_GNSS REPLAY_DIR "GNSS-100195-100245.txt"
#define SLICE_TRUTH REPLAY_DIR "truth-100195-100245-20Hz.nav"
#define SLICE_SCENE REPLAY_DIR "long-drive.yaml"

/* Larger than the size from which the loader splits the file (4 MiB). */
#define BIG_LINES 48000

static void temp_path(char *buf, size_t size, const char *name) {
  snprintf(buf, size, "/tmp/test_replay_fast.%ld.%s", (long)getpid(), name);
}

/* The whole of a text file, NUL-terminated (malloc'd). */
static char *slurp(const char *path) {
  FILE *f = fopen(path, "rb");
  assert_non_null(f);
  assert_int_equal(fseek(f, 0, SEEK_END), 0);
  const long n = ftell(f);
  assert_true(n >= 0);
  rewind(f);
  char *t = malloc((size_t)n + 1);
  assert_non_null(t);
  assert_int_equal(fread(t, 1, (size_t)n, f), (size_t)n);
  t[n] = '\0';
  fclose(f);
  return t;
}

static void write_text(const char *path, const char *text, size_t len) {
  FILE *f = fopen(path, "wb");
  assert_non_null(f);
  assert_int_equal(fwrite(text, 1, len, f), len);
  assert_int_equal(fclose(f), 0);
}

/*
 * A synthetic IMU file of @p lines records at 200 Hz with comment and blank lines sprinkled in
 * (some with leading blanks), numbers in the spellings of real files (exponents, signs, 13 and 9
 * significant digits). @p last_newline: end the last line with '\n'. Returned text is malloc'd.
 */
static char *make_imu_text(int lines, bool last_newline, size_t *len) {
  const size_t cap = (size_t)lines * 160 + 1024;
  char *t = malloc(cap);
  assert_non_null(t);
  size_t n = 0;
  n += (size_t)snprintf(t + n, cap - n, "# synthetic IMU file: t, dtheta x/y/z, dvel x/y/z\n");
  uint64_t x = 0x9E3779B97F4A7C15ull;
  for (int i = 0; i < lines; ++i) {
    if (i % 997 == 5) n += (size_t)snprintf(t + n, cap - n, "  # a comment inside the data\n");
    if (i % 1511 == 7) n += (size_t)snprintf(t + n, cap - n, "\n");
    double v[6];
    for (int k = 0; k < 6; ++k) {
      x ^= x << 13;
      x ^= x >> 7;
      x ^= x << 17;
      v[k] = ((double)(x >> 11) / 9007199254740992.0 - 0.5) * (k < 3 ? 2e-5 : 2e-1);
    }
    const double ts = 100000.0 + 0.005 * (double)(i + 1);
    if (i % 3 == 0)
      n += (size_t)snprintf(t + n, cap - n, "%.6f %.12e %.12e %.12e %.12e %.12e %.12e", ts, v[0], v[1], v[2],
                            v[3], v[4], v[5]);
    else
      n += (size_t)snprintf(t + n, cap - n, "%.6f\t%.9g %+.9g %.9g %.9E %.9g %.9g", ts, v[0], v[1], v[2],
                            v[3], v[4], v[5]);
    if (i + 1 < lines || last_newline) t[n++] = '\n';
  }
  t[n] = '\0';
  *len = n;
  return t;
}

/* Every record of @p path through the streaming reader. */
typedef struct seq_read {
  nav_imu_increment *rec;
  size_t n;
  long cut_line, last_line;
} seq_read;

static seq_read read_sequential(const char *path, size_t cap) {
  seq_read s = {malloc(cap * sizeof(nav_imu_increment)), 0, 0, 0};
  assert_non_null(s.rec);
  nav_rec_reader *r = NULL;
  assert_int_equal(nav_rec_reader_open(path, NAV_REC_IMU, &r, NULL), NAV_OK);
  for (bool got = true; got;) {
    nav_imu_increment m;
    assert_int_equal(nav_rec_read_imu(r, &m, &got), NAV_OK);
    if (got) {
      assert_true(s.n < cap);
      s.rec[s.n++] = m;
      s.last_line = nav_rec_reader_line(r);
    }
  }
  s.cut_line = nav_rec_reader_cut_line(r);
  nav_rec_reader_destroy(r);
  return s;
}

static bool same_bits(double a, double b) {
  return memcmp(&a, &b, sizeof a) == 0;
}

static void assert_same_records(const nav_rec_imu_array *arr, const nav_imu_increment *b, size_t n) {
  for (size_t i = 0; i < n; ++i) {
    const nav_imu_increment *a = nav_rec_imu_array_at(arr, i);
    const double va[8] = {
        a->t_s,        a->dt_s,       a->dtheta_b_rad.x, a->dtheta_b_rad.y, a->dtheta_b_rad.z,
        a->dv_b_mps.x, a->dv_b_mps.y, a->dv_b_mps.z};
    const double vb[8] = {
        b[i].t_s,        b[i].dt_s,       b[i].dtheta_b_rad.x, b[i].dtheta_b_rad.y, b[i].dtheta_b_rad.z,
        b[i].dv_b_mps.x, b[i].dv_b_mps.y, b[i].dv_b_mps.z};
    for (int k = 0; k < 8; ++k)
      if (!same_bits(va[k], vb[k])) fail_msg("record %zu, value %d: %.17g != %.17g", i, k, va[k], vb[k]);
    if (a->k != b[i].k) fail_msg("record %zu: index %lld != %lld", i, (long long)a->k, (long long)b[i].k);
  }
}

/* The array loader gives the streaming reader's records, indices, intervals and cut line, for a
 * file split on two threads (with and without a last line end) and a small one read whole. */
static void test_imu_array_matches_reader(void **state) {
  (void)state;
  const int sizes[3] = {BIG_LINES, BIG_LINES + 1, 300};
  for (int c = 0; c < 3; ++c) {
    const bool last_nl = c != 1;
    size_t len = 0;
    char *text = make_imu_text(sizes[c], last_nl, &len);
    char path[256];
    temp_path(path, sizeof path, "imu.txt");
    write_text(path, text, len);
    if (c < 2) assert_true(len > 4u * 1024u * 1024u);
    const seq_read s = read_sequential(path, (size_t)sizes[c] + 1);
    nav_rec_imu_array a;
    memset(&a, 0, sizeof a);
    nav_diag d;
    memset(&d, 0, sizeof d);
    assert_int_equal(nav_rec_imu_array_load(path, (size_t)1 << 30, &a, &d), NAV_OK);
    assert_int_equal(a.count, (size_t)sizes[c]);
    assert_int_equal(a.count, s.n);
    assert_same_records(&a, s.rec, s.n);
    if (c < 2) assert_true(a.part_count[1] > 0); /* split on two threads */
    assert_int_equal(a.cut_line, s.cut_line);
    assert_int_equal(a.last_record_line, s.last_line);
    if (last_nl)
      assert_int_equal(a.cut_line, 0);
    else
      assert_true(a.cut_line > 0);
    print_message("  %d lines, %zu bytes: %zu records, cut line %ld, as the streaming reader\n", sizes[c],
                  len, a.count, a.cut_line);
    nav_rec_imu_array_free(&a);
    assert_null(a.part[0]);
    free(s.rec);
    free(text);
    unlink(path);
  }
}

static void assert_same_diag(const nav_diag *a, const nav_diag *b) {
  assert_string_equal(a->file, b->file);
  assert_int_equal(a->line, b->line);
  assert_int_equal(a->col, b->col);
  assert_string_equal(a->path, b->path);
  assert_string_equal(a->message, b->message);
}

/* Byte offset of the line start the loader splits at: past the first '\n' at or after size / 2. */
static size_t split_of(const char *text, size_t len) {
  const char *nl = memchr(text + len / 2, '\n', len - len / 2);
  assert_non_null(nl);
  return (size_t)(nl - text) + 1;
}

/* Errors anywhere (first half, second half, time not increasing across the split) are those of
 * nav_rec_check_file(): the same status, FILE:LINE:COL, column name and message. */
static void test_imu_array_errors_match_check(void **state) {
  (void)state;
  size_t len = 0;
  char *base = make_imu_text(BIG_LINES, true, &len);
  const size_t split = split_of(base, len);
  char path[256];
  temp_path(path, sizeof path, "imu-bad.txt");
  for (int c = 0; c < 4; ++c) {
    char *t = malloc(len + 1);
    assert_non_null(t);
    memcpy(t, base, len + 1);
    const char *what = "";
    if (c == 0) {
      /* A letter in a number of the first half. */
      char *p = strchr(t + len / 4, '\n') + 1;
      p = strchr(p, ' ') + 3;
      *p = 'x';
      what = "bad number in the first half";
    } else if (c == 1) {
      /* A malformed number in the second half. */
      char *p = strchr(t + split + (len - split) / 2, '\n') + 1;
      p = strchr(p, ' ') + 1;
      p[0] = '9';
      p[1] = '.';
      what = "bad number in the second half";
    } else if (c == 2) {
      /* The first record of the second half repeats the time of the last of the first. */
      const char *prev = t + split - 2;
      while (*prev != '\n')
        --prev;
      ++prev;
      if (*prev == '#' || *prev == ' ' || *(t + split) == '#' || *(t + split) == ' ' ||
          *(t + split) == '\n') {
        free(t);
        continue; /* the split fell next to a comment line: nothing to do here */
      }
      memcpy(t + split, prev, 13); /* "100xxx.xxxxxx" */
      what = "time not increasing across the split";
    } else {
      /* A line without the last column in the second half. */
      char *p = strchr(t + len - len / 8, '\n') + 1;
      char *e = strchr(p, '\n');
      char *last = e;
      while (last[-1] != ' ' && last[-1] != '\t')
        --last;
      memset(last - 1, ' ', (size_t)(e - last + 1));
      what = "too few columns in the second half";
    }
    write_text(path, t, len);
    nav_diag dc, da;
    memset(&dc, 0, sizeof dc);
    memset(&da, 0, sizeof da);
    const nav_status sc = nav_rec_check_file(path, NAV_REC_IMU, NULL, &dc);
    nav_rec_imu_array a;
    memset(&a, 0, sizeof a);
    const nav_status sa = nav_rec_imu_array_load(path, (size_t)1 << 30, &a, &da);
    print_message("  %s: %s:%d:%d %s: %s\n", what, dc.file, dc.line, dc.col, dc.path, dc.message);
    assert_int_equal(sc, NAV_ERR_PARSE);
    assert_int_equal(sa, sc);
    assert_same_diag(&da, &dc);
    assert_null(a.part[0]);
    free(t);
  }
  unlink(path);
  free(base);
}

static void assert_same_stream(nav_rec_imu_stream *st, const seq_read *s) {
  for (size_t i = 0; i < s->n; ++i) {
    const nav_imu_increment *a = NULL;
    assert_int_equal(nav_rec_imu_stream_at(st, i, &a), NAV_OK);
    assert_non_null(a);
    nav_rec_imu_array one;
    memset(&one, 0, sizeof one);
    one.part[0] = (nav_imu_increment *)a;
    one.part_count[0] = 1;
    one.count = 1;
    assert_same_records(&one, &s->rec[i], 1);
  }
  const nav_imu_increment *past = (const nav_imu_increment *)&past;
  assert_int_equal(nav_rec_imu_stream_at(st, s->n, &past), NAV_OK);
  assert_null(past);
}

/* The IMU stream hands out the streaming reader's records, indices, intervals, count and cut line
 * while it reads the file on its thread (consumed at once, as the replay does, or after a wait). */
static void test_imu_stream_matches_reader(void **state) {
  (void)state;
  const int sizes[3] = {BIG_LINES, BIG_LINES + 1, 300};
  for (int c = 0; c < 3; ++c) {
    const bool last_nl = c != 1;
    size_t len = 0;
    char *text = make_imu_text(sizes[c], last_nl, &len);
    char path[256];
    temp_path(path, sizeof path, "imu-stream.txt");
    write_text(path, text, len);
    const seq_read s = read_sequential(path, (size_t)sizes[c] + 1);
    for (int wait = 0; wait < 2; ++wait) {
      nav_rec_imu_stream *st = NULL;
      nav_diag d;
      memset(&d, 0, sizeof d);
      assert_int_equal(nav_rec_imu_stream_start(path, (size_t)1 << 30, &st, &d), NAV_OK);
      assert_int_equal(nav_rec_imu_stream_file_bytes(st), len);
      size_t count = 0;
      long cut = -1, last = -1;
      if (wait) assert_int_equal(nav_rec_imu_stream_finish(st, &count, &cut, &last, &d), NAV_OK);
      assert_same_stream(st, &s);
      nav_status ps = NAV_ERR_STATE;
      size_t pc = 0;
      assert_true(nav_rec_imu_stream_poll(st, &ps, &pc));
      assert_int_equal(ps, NAV_OK);
      assert_int_equal(pc, s.n);
      assert_int_equal(nav_rec_imu_stream_finish(st, &count, &cut, &last, &d), NAV_OK);
      assert_int_equal(count, s.n);
      assert_int_equal(cut, s.cut_line);
      assert_int_equal(last, s.last_line);
      nav_rec_imu_stream_destroy(st);
    }
    print_message("  stream, %d lines: %zu records, cut line %ld, as the streaming reader\n", sizes[c], s.n,
                  s.cut_line);
    free(s.rec);
    free(text);
    unlink(path);
  }
  /* Destroyed while it still reads: the thread stops and everything is released (ASan, TSan). */
  size_t len = 0;
  char *text = make_imu_text(BIG_LINES, true, &len);
  char path[256];
  temp_path(path, sizeof path, "imu-stream-early.txt");
  write_text(path, text, len);
  nav_rec_imu_stream *st = NULL;
  assert_int_equal(nav_rec_imu_stream_start(path, (size_t)1 << 30, &st, NULL), NAV_OK);
  const nav_imu_increment *a = NULL;
  assert_int_equal(nav_rec_imu_stream_at(st, 0, &a), NAV_OK);
  assert_non_null(a);
  nav_rec_imu_stream_destroy(st);
  free(text);
  unlink(path);
  /* Larger than the limit: refused, as the array loader refuses it. */
  nav_diag d;
  memset(&d, 0, sizeof d);
  st = NULL;
  assert_int_equal(nav_rec_imu_stream_start(SLICE_IMU, 1000, &st, &d), NAV_ERR_OUT_OF_RANGE);
  assert_null(st);
  assert_non_null(strstr(d.message, "more than the 1000 to hold in memory"));
}

/* A bad record anywhere: the stream's verdict is nav_rec_check_file()'s (status, FILE:LINE:COL,
 * column, message), every later nav_rec_imu_stream_at() returns the status, and a replay on the
 * stream stops with it. */
static void test_imu_stream_errors_match_check(void **state) {
  (void)state;
  size_t len = 0;
  char *base = make_imu_text(BIG_LINES, true, &len);
  char path[256];
  temp_path(path, sizeof path, "imu-stream-bad.txt");
  const double where[3] = {0.1, 0.5, 0.97};
  for (int c = 0; c < 4; ++c) {
    char *t = malloc(len + 1);
    assert_non_null(t);
    memcpy(t, base, len + 1);
    if (c < 3) {
      char *p = strchr(t + (size_t)(where[c] * (double)len), '\n') + 1;
      p = strchr(p, ' ') + 3;
      *p = 'x';
    } else {
      /* The last record repeats the time of the one before. */
      char *e = t + len - 1;
      char *l1 = e;
      while (l1[-1] != '\n')
        --l1;
      char *l0 = l1 - 1;
      while (l0[-1] != '\n')
        --l0;
      memcpy(l1, l0, 13);
    }
    write_text(path, t, len);
    nav_diag dc, ds;
    memset(&dc, 0, sizeof dc);
    memset(&ds, 0, sizeof ds);
    const nav_status sc = nav_rec_check_file(path, NAV_REC_IMU, NULL, &dc);
    assert_int_equal(sc, NAV_ERR_PARSE);
    nav_rec_imu_stream *st = NULL;
    assert_int_equal(nav_rec_imu_stream_start(path, (size_t)1 << 30, &st, NULL), NAV_OK);
    assert_int_equal(nav_rec_imu_stream_finish(st, NULL, NULL, NULL, &ds), sc);
    assert_same_diag(&ds, &dc);
    const nav_imu_increment *a = NULL;
    assert_int_equal(nav_rec_imu_stream_at(st, 0, &a), sc);
    assert_true(nav_rec_imu_stream_poll(st, NULL, NULL));
    nav_rec_imu_stream_destroy(st);
    print_message("  stream: %s:%d:%d %s: %s\n", dc.file, dc.line, dc.col, dc.path, dc.message);
    free(t);
  }
  unlink(path);
  free(base);
}

/* A file above the limit is refused before any record is read (the caller streams it). */
static void test_imu_array_size_limit(void **state) {
  (void)state;
  nav_rec_imu_array a;
  memset(&a, 0, sizeof a);
  nav_diag d;
  memset(&d, 0, sizeof d);
  assert_int_equal(nav_rec_imu_array_load(SLICE_IMU, 1000, &a, &d), NAV_ERR_OUT_OF_RANGE);
  assert_null(a.part[0]);
  assert_non_null(strstr(d.message, "more than the 1000"));
  memset(&d, 0, sizeof d);
  assert_int_equal(nav_rec_imu_array_load(REPLAY_DIR "no-such-file.txt", 1000, &a, &d), NAV_ERR_IO);
  assert_non_null(strstr(d.message, "cannot open the IMU file"));
  nav_rec_imu_array_free(NULL);
}

/* ---------------------------------------------------------------- replay modes */

/* FNV-1a over the bytes of every callback argument, in call order. */
typedef struct trace {
  uint64_t h_rec, h_scored;
  long records, scored;
  long stop_after; /* record returns NAV_STOP at this call (0: never) */
} trace;

static void fnv(uint64_t *h, const void *p, size_t n) {
  const unsigned char *b = p;
  for (size_t i = 0; i < n; ++i) {
    *h ^= b[i];
    *h *= 1099511628211ull;
  }
}

static void fnv_doubles(uint64_t *h, const double *v, int n) {
  fnv(h, v, (size_t)n * sizeof *v);
}

static void hash_errors(uint64_t *h, const nav_epoch_errors *e) {
  const double v[14] = {
      e->t_s,         e->pos_err_n_m.x,      e->pos_err_n_m.y,       e->pos_err_n_m.z,    e->pos_err_h_m,
      e->pos_err_v_m, e->vel_err_n_mps.x,    e->vel_err_n_mps.y,     e->vel_err_n_mps.z,  e->vel_err_mps,
      e->att_err_rad, e->euler_err.roll_rad, e->euler_err.pitch_rad, e->euler_err.yaw_rad};
  fnv_doubles(h, v, 14);
}

static nav_callback_result on_record(void *user, const nav_replay_record *r) {
  trace *t = user;
  const nav_ins_state *s = r->nav;
  const double v[11] = {s->t_s,          s->r_fb_f_m.x,   s->r_fb_f_m.y,   s->r_fb_f_m.z,
                        s->v_fb_f_mps.x, s->v_fb_f_mps.y, s->v_fb_f_mps.z, s->q_b_f.w,
                        s->q_b_f.x,      s->q_b_f.y,      s->q_b_f.z};
  fnv_doubles(&t->h_rec, v, 11);
  if (r->ref) {
    const double w[7] = {r->ref->t_s,     r->ref->r_fb_f_m.x, r->ref->r_fb_f_m.y, r->ref->r_fb_f_m.z,
                         r->ref->q_b_f.w, r->ref->q_b_f.x,    r->ref->q_b_f.z};
    fnv_doubles(&t->h_rec, w, 7);
  }
  if (r->err) hash_errors(&t->h_rec, r->err);
  const unsigned char u = r->gnss_update ? 1 : 0;
  fnv(&t->h_rec, &u, 1);
  fnv(&t->h_rec, &r->frame->origin, sizeof r->frame->origin);
  t->records++;
  return t->stop_after > 0 && t->records == t->stop_after ? NAV_STOP : NAV_CONTINUE;
}

static void on_scored(void *user, const nav_epoch_errors *e) {
  trace *t = user;
  hash_errors(&t->h_scored, e);
  t->scored++;
}

static void hash_stats(uint64_t *h, const nav_replay_stats *s) {
  const nav_replay_stat *st[8] = {&s->pos_h_m,  &s->pos_v_m,   &s->vel_h_mps, &s->vel_v_mps,
                                  &s->roll_rad, &s->pitch_rad, &s->yaw_rad,   &s->att_rad};
  for (int i = 0; i < 8; ++i) {
    const double v[3] = {st[i]->rms, st[i]->max, st[i]->t_max_s};
    fnv_doubles(h, v, 3);
  }
  const double m[6] = {s->pos_mean_n_m.x,   s->pos_mean_n_m.y,   s->pos_mean_n_m.z,
                       s->vel_mean_n_mps.x, s->vel_mean_n_mps.y, s->vel_mean_n_mps.z};
  fnv_doubles(h, m, 6);
  fnv(h, &s->epochs, sizeof s->epochs);
}

/* Everything of a summary but padding, as one hash. */
static uint64_t hash_summary(const nav_replay_summary *s) {
  uint64_t h = 14695981039346656037ull;
  const long counts[14] = {s->imu_records,       s->imu_steps,      s->imu_gaps,     s->ref_rows,
                           s->ref_unmatched,     s->gnss_records,   s->gnss_applied, s->gnss_dropped,
                           s->gnss_before_start, s->gnss_unmatched, s->gap_count,    s->imu_cut_line,
                           s->gnss_cut_line,     s->ref_cut_line};
  fnv(&h, counts, sizeof counts);
  const unsigned char flags[3] = {s->free_ins, s->gnss_has_vel, s->partial};
  fnv(&h, flags, sizeof flags);
  const double v[9] = {s->t_first_s, s->t_last_s,   s->imu_dt_max_s, s->b_g_rps.x, s->b_g_rps.y,
                       s->b_g_rps.z, s->b_a_mps2.x, s->b_a_mps2.y,   s->b_a_mps2.z};
  fnv_doubles(&h, v, 9);
  hash_stats(&h, &s->stats);
  hash_stats(&h, &s->stats_output);
  hash_errors(&h, &s->final);
  for (long g = 0; g < s->gap_count && g < NAV_REPLAY_MAX_GAPS; ++g) {
    const nav_replay_gap *p = &s->gaps[g];
    const double w[5] = {p->t0_s, p->t1_s, p->pos_h_end_m, p->pos_v_end_m, p->pos_h_max_m};
    fnv_doubles(&h, w, 5);
    const unsigned char f[2] = {p->open, p->has_end_errors};
    fnv(&h, f, 2);
    hash_errors(&h, &p->end_errors);
  }
  return h;
}

typedef struct mode {
  const char *name;
  bool array, read_ahead, worker, stream;
} mode;

enum { N_MODES = 7 };
static const mode k_modes[N_MODES] = {{"calling thread only", false, false, false, false},
                                      {"read-ahead", false, true, false, false},
                                      {"IMU array", true, false, false, false},
                                      {"scoring thread", false, false, true, false},
                                      {"all, IMU array", true, true, true, false},
                                      {"IMU stream", false, false, false, true},
                                      {"all (navsim replay)", false, true, true, true}};

typedef struct outcome {
  nav_status st;
  uint64_t h_sum;
  trace tr;
  nav_replay_summary sum;
} outcome;

static outcome run_mode(const mode *m, const char *imu, const char *truth, bool outage, bool window,
                        long stop_after) {
  nav_scene *sc = malloc(sizeof *sc);
  assert_non_null(sc);
  assert_int_equal(nav_scene_read_file(SLICE_SCENE, sc, NULL, NULL), NAV_OK);
  nav_replay_config c = nav_replay_config_default();
  c.nav = nav_ins_gnss_config_from_scene(sc);
  free(sc);
  c.imu_path = imu;
  c.gnss_path = SLICE_GNSS;
  c.ref_path = truth;
  if (outage) {
    /* One gap that ends inside the run, one open at its end. */
    c.outage_count = 2;
    c.outages[0].t0_s = 100220.0;
    c.outages[0].t1_s = 100232.0;
    c.outages[1].t0_s = 100241.0;
    c.outages[1].t1_s = 100300.0;
  }
  if (window) {
    c.has_end = true;
    c.t_end_s = 100230.0;
  }
  c.read_ahead = m->read_ahead;
  c.callbacks_on_worker = m->worker;
  nav_rec_imu_array a;
  memset(&a, 0, sizeof a);
  if (m->array) {
    assert_int_equal(nav_rec_imu_array_load(imu, (size_t)1 << 30, &a, NULL), NAV_OK);
    c.imu = &a;
  }
  nav_rec_imu_stream *is = NULL;
  if (m->stream) {
    assert_int_equal(nav_rec_imu_stream_start(imu, (size_t)1 << 30, &is, NULL), NAV_OK);
    c.imu_stream = is;
  }
  outcome o;
  memset(&o, 0, sizeof o);
  o.tr.h_rec = o.tr.h_scored = 14695981039346656037ull;
  o.tr.stop_after = stop_after;
  c.record = on_record;
  c.scored = on_scored;
  c.user = &o.tr;
  nav_diag d;
  memset(&d, 0, sizeof d);
  o.st = nav_replay_run(&c, &o.sum, &d);
  if (o.st == NAV_OK || o.st == NAV_ERR_CANCELLED) o.h_sum = hash_summary(&o.sum);
  nav_rec_imu_array_free(&a);
  nav_rec_imu_stream_destroy(is);
  return o;
}

/* The 50 s slice with two outages, whole and cut at --end, and an IMU file whose last line has no
 * line end: the five ways of running give the same summary and callbacks, bit for bit. */
static void test_replay_modes_identical(void **state) {
  (void)state;
  /* The slice's IMU file without its last line end. */
  char *imu = slurp(SLICE_IMU);
  assert_non_null(imu);
  size_t n = strlen(imu);
  assert_true(n > 0 && imu[n - 1] == '\n');
  char cut[256];
  temp_path(cut, sizeof cut, "imu-cut.txt");
  write_text(cut, imu, n - 1);
  free(imu);
  const char *imus[2] = {SLICE_IMU, cut};
  for (int f = 0; f < 2; ++f)
    for (int w = 0; w < 2; ++w) {
      outcome ref = run_mode(&k_modes[0], imus[f], SLICE_TRUTH, true, w == 1, 0);
      assert_int_equal(ref.st, NAV_OK);
      assert_true(ref.tr.records > 100);
      assert_true(ref.tr.scored > 100);
      if (w == 0) assert_int_equal(ref.sum.gap_count, 2);
      /* The cut line counts only when the replay reads it. */
      if (f == 1 && w == 0) assert_true(ref.sum.imu_cut_line > 0);
      if (f == 1 && w == 1) assert_int_equal(ref.sum.imu_cut_line, 0);
      for (int m = 1; m < N_MODES; ++m) {
        const outcome o = run_mode(&k_modes[m], imus[f], SLICE_TRUTH, true, w == 1, 0);
        print_message("  %-22s %s%s: %ld records, %ld scored, gaps %ld, cut line %ld\n", k_modes[m].name,
                      f ? "cut IMU file" : "IMU file", w ? ", --end" : "", o.tr.records, o.tr.scored,
                      o.sum.gap_count, o.sum.imu_cut_line);
        assert_int_equal(o.st, NAV_OK);
        assert_true(o.h_sum == ref.h_sum);
        assert_int_equal(o.tr.records, ref.tr.records);
        assert_int_equal(o.tr.scored, ref.tr.scored);
        assert_true(o.tr.h_rec == ref.tr.h_rec);
        assert_true(o.tr.h_scored == ref.tr.h_scored);
      }
    }
  unlink(cut);
}

/* A NAV_STOP from the record callback cancels the run in every mode: a partial summary. On the
 * calling thread it stops at once; on the scoring thread the callbacks stop at the same record. */
static void test_replay_stop_from_record(void **state) {
  (void)state;
  for (int m = 0; m < N_MODES; ++m) {
    const outcome o = run_mode(&k_modes[m], SLICE_IMU, SLICE_TRUTH, false, false, 40);
    assert_int_equal(o.st, NAV_ERR_CANCELLED);
    assert_true(o.sum.partial);
    assert_int_equal(o.tr.records, 40);
    if (!k_modes[m].worker) assert_true(o.sum.t_last_s < 100199.0);
    print_message("  %-22s stopped at record 40: %ld IMU steps\n", k_modes[m].name, o.sum.imu_steps);
  }
}

/* A replay on an IMU stream whose file turns out bad stops with the parse status, also when the
 * bad record is far beyond the run's window (--end), which the run never reaches. */
static void test_replay_stream_stops_on_bad_record(void **state) {
  (void)state;
  char *imu = slurp(SLICE_IMU);
  assert_non_null(imu);
  const size_t n = strlen(imu);
  char *t = malloc(n + 128);
  assert_non_null(t);
  memcpy(t, imu, n);
  /* One more record after the last, with a letter in it. */
  const int k = snprintf(t + n, 128, "100300.000000 1e-6 2e-6 3e-6 0.1 0.2q 9.8\n");
  char path[256];
  temp_path(path, sizeof path, "imu-late-bad.txt");
  write_text(path, t, n + (size_t)k);
  free(t);
  free(imu);
  for (int w = 0; w < 2; ++w) {
    nav_scene *sc = malloc(sizeof *sc);
    assert_non_null(sc);
    assert_int_equal(nav_scene_read_file(SLICE_SCENE, sc, NULL, NULL), NAV_OK);
    nav_replay_config c = nav_replay_config_default();
    c.nav = nav_ins_gnss_config_from_scene(sc);
    free(sc);
    c.imu_path = path;
    c.gnss_path = SLICE_GNSS;
    c.ref_path = SLICE_TRUTH;
    c.callbacks_on_worker = true;
    if (w == 1) {
      c.has_end = true;
      c.t_end_s = 100200.0;
    }
    nav_rec_imu_stream *is = NULL;
    assert_int_equal(nav_rec_imu_stream_start(path, (size_t)1 << 30, &is, NULL), NAV_OK);
    c.imu_stream = is;
    nav_replay_summary s;
    nav_diag d;
    memset(&d, 0, sizeof d);
    const nav_status st = nav_replay_run(&c, &s, &d);
    nav_diag ds;
    memset(&ds, 0, sizeof ds);
    const nav_status ss = nav_rec_imu_stream_finish(is, NULL, NULL, NULL, &ds);
    assert_int_equal(ss, NAV_ERR_PARSE);
    assert_non_null(strstr(ds.message, "0.2q"));
    /* Whole file: the run meets the bad record and stops with its status. With --end the run may
       be over before the parser gets there (it ends normally) or not (it stops): either way the
       caller's verdict is the stream's (ss). */
    if (w == 0) assert_int_equal(st, NAV_ERR_PARSE);
    else assert_true(st == NAV_OK || st == NAV_ERR_PARSE);
    nav_rec_imu_stream_destroy(is);
  }
  unlink(path);
}

/* A malformed reference row is reported the same way with the read-ahead thread as without. */
static void test_replay_reference_error_read_ahead(void **state) {
  (void)state;
  char *truth = slurp(SLICE_TRUTH);
  assert_non_null(truth);
  /* Damage a row in the middle (its height). */
  char *p = truth + strlen(truth) / 2;
  p = strchr(p, '\n') + 1;
  for (int k = 0; k < 4; ++k)
    p = strchr(p, ' ') + 1;
  p[0] = 'z';
  char path[256];
  temp_path(path, sizeof path, "truth-bad.nav");
  write_text(path, truth, strlen(truth));
  free(truth);
  nav_diag d0;
  memset(&d0, 0, sizeof d0);
  for (int m = 0; m < N_MODES; ++m) {
    nav_scene *sc = malloc(sizeof *sc);
    assert_non_null(sc);
    assert_int_equal(nav_scene_read_file(SLICE_SCENE, sc, NULL, NULL), NAV_OK);
    nav_replay_config c = nav_replay_config_default();
    c.nav = nav_ins_gnss_config_from_scene(sc);
    free(sc);
    c.imu_path = SLICE_IMU;
    c.gnss_path = SLICE_GNSS;
    c.ref_path = path;
    c.read_ahead = k_modes[m].read_ahead;
    c.callbacks_on_worker = k_modes[m].worker;
    nav_rec_imu_stream *is = NULL;
    if (k_modes[m].stream) {
      assert_int_equal(nav_rec_imu_stream_start(SLICE_IMU, (size_t)1 << 30, &is, NULL), NAV_OK);
      c.imu_stream = is;
    }
    nav_replay_summary s;
    nav_diag d;
    memset(&d, 0, sizeof d);
    assert_int_equal(nav_replay_run(&c, &s, &d), NAV_ERR_PARSE);
    nav_rec_imu_stream_destroy(is);
    if (m == 0) {
      d0 = d;
      print_message("  %s:%d:%d %s: %s\n", d.file, d.line, d.col, d.path, d.message);
      assert_true(d.line > 400);
    } else {
      assert_same_diag(&d, &d0);
    }
  }
  unlink(path);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_imu_array_matches_reader),
      cmocka_unit_test(test_imu_array_errors_match_check),
      cmocka_unit_test(test_imu_array_size_limit),
      cmocka_unit_test(test_imu_stream_matches_reader),
      cmocka_unit_test(test_imu_stream_errors_match_check),
      cmocka_unit_test(test_replay_stream_stops_on_bad_record),
      cmocka_unit_test(test_replay_modes_identical),
      cmocka_unit_test(test_replay_stop_from_record),
      cmocka_unit_test(test_replay_reference_error_read_ahead),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
