/* Text buffers, JSON strings, files and ids of navsim serve (serve_internal.h). */
#define _GNU_SOURCE
#include "serve_internal.h"

#include <errno.h>
#include <fcntl.h>
#include <ftw.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

void sb_free(sbuf *b) {
  free(b->s);
  b->s = NULL;
  b->len = b->cap = 0;
}

static bool sb_reserve(sbuf *b, size_t extra) {
  if (b->failed) return false;
  if (b->len + extra + 1 <= b->cap) return true;
  size_t cap = b->cap ? b->cap : 256;
  while (cap < b->len + extra + 1)
    cap *= 2;
  char *s = realloc(b->s, cap);
  if (!s) {
    b->failed = true;
    return false;
  }
  b->s = s;
  b->cap = cap;
  return true;
}

void sb_add(sbuf *b, const char *text, size_t n) {
  if (!sb_reserve(b, n)) return;
  memcpy(b->s + b->len, text, n);
  b->len += n;
  b->s[b->len] = '\0';
}

void sb_puts(sbuf *b, const char *text) {
  sb_add(b, text, strlen(text));
}

void sb_printf(sbuf *b, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  char small[256];
  const int n = vsnprintf(small, sizeof small, fmt, ap);
  va_end(ap);
  if (n < 0) {
    b->failed = true;
    return;
  }
  if ((size_t)n < sizeof small) {
    sb_add(b, small, (size_t)n);
    return;
  }
  if (!sb_reserve(b, (size_t)n)) return;
  va_start(ap, fmt);
  vsnprintf(b->s + b->len, (size_t)n + 1, fmt, ap);
  va_end(ap);
  b->len += (size_t)n;
}

/* Length of the valid UTF-8 sequence at p (1..4), 0 when invalid (overlong, surrogate, > U+10FFFF). */
static int utf8_len(const unsigned char *p) {
  const unsigned c = p[0];
  if (c < 0x80) return 1;
  int n;
  unsigned min, cp;
  if ((c & 0xE0) == 0xC0) {
    n = 2;
    cp = c & 0x1F;
    min = 0x80;
  } else if ((c & 0xF0) == 0xE0) {
    n = 3;
    cp = c & 0x0F;
    min = 0x800;
  } else if ((c & 0xF8) == 0xF0) {
    n = 4;
    cp = c & 0x07;
    min = 0x10000;
  } else {
    return 0;
  }
  for (int i = 1; i < n; ++i) {
    if ((p[i] & 0xC0) != 0x80) return 0;
    cp = (cp << 6) | (p[i] & 0x3F);
  }
  if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return 0;
  return n;
}

void sb_json_str(sbuf *b, const char *text) {
  sb_add(b, "\"", 1);
  const unsigned char *p = (const unsigned char *)(text ? text : "");
  while (*p) {
    const unsigned c = *p;
    if (c == '"' || c == '\\') {
      const char esc[2] = {'\\', (char)c};
      sb_add(b, esc, 2);
      ++p;
    } else if (c < 0x20 || c == 0x7F) {
      sb_printf(b, "\\u%04x", c);
      ++p;
    } else if (c < 0x80) {
      sb_add(b, (const char *)p, 1);
      ++p;
    } else {
      const int n = utf8_len(p);
      if (n == 0) {
        sb_puts(b, "\\ufffd");
        ++p;
      } else {
        sb_add(b, (const char *)p, (size_t)n);
        p += n;
      }
    }
  }
  sb_add(b, "\"", 1);
}

void sb_json_num(sbuf *b, double v) {
  if (!isfinite(v))
    sb_puts(b, "null");
  else
    sb_printf(b, "%.17g", v);
}

char *sb_take(sbuf *b, size_t *len) {
  if (b->failed || !sb_reserve(b, 0)) {
    sb_free(b);
    return NULL;
  }
  char *s = b->s;
  if (len) *len = b->len;
  b->s = NULL;
  b->len = b->cap = 0;
  return s;
}

char *serve_read_file(const char *path, size_t max, size_t *len) {
  const int fd = open(path, O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) return NULL;
  struct stat st;
  char *buf = NULL;
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || (size_t)st.st_size > max) goto cleanup;
  buf = malloc((size_t)st.st_size + 1);
  if (!buf) goto cleanup;
  size_t got = 0;
  while (got < (size_t)st.st_size) {
    const ssize_t r = read(fd, buf + got, (size_t)st.st_size - got);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) break;
    got += (size_t)r;
  }
  buf[got] = '\0';
  if (len) *len = got;
cleanup:
  close(fd);
  return buf;
}

static int remove_one(const char *path, const struct stat *sb, int flag, struct FTW *ftw) {
  (void)sb;
  (void)ftw;
  if (flag == FTW_DP)
    rmdir(path);
  else
    unlink(path);
  return 0;
}

void serve_remove_tree(const char *path) {
  nftw(path, remove_one, 16, FTW_DEPTH | FTW_PHYS);
}

static _Thread_local double g_tree_bytes;

static int count_one(const char *path, const struct stat *sb, int flag, struct FTW *ftw) {
  (void)path;
  (void)ftw;
  if (flag == FTW_F) g_tree_bytes += (double)sb->st_blocks * 512.0;
  return 0;
}

double serve_tree_bytes(const char *path) {
  g_tree_bytes = 0.0;
  nftw(path, count_one, 16, FTW_PHYS);
  return g_tree_bytes;
}

bool serve_random_id(char out[33]) {
  unsigned char r[16];
  size_t got = 0;
  while (got < sizeof r) {
    const ssize_t n = getrandom(r + got, sizeof r - got, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    got += (size_t)n;
  }
  static const char hex[] = "0123456789abcdef";
  for (int i = 0; i < 16; ++i) {
    out[2 * i] = hex[r[i] >> 4];
    out[2 * i + 1] = hex[r[i] & 15];
  }
  out[32] = '\0';
  return true;
}

bool serve_is_id(const char *s) {
  if (!s) return false;
  for (int i = 0; i < 32; ++i)
    if (!((s[i] >= '0' && s[i] <= '9') || (s[i] >= 'a' && s[i] <= 'f'))) return false;
  return s[32] == '\0';
}

double serve_now_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
