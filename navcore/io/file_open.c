/* nav_io_fopen_regular (nav_io.h): the one way the readers open an input file. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "navcore/nav_io.h"

static const char *kind_of(mode_t m) {
  if (S_ISDIR(m)) return "a directory";
  if (S_ISFIFO(m)) return "a FIFO (named pipe)";
  if (S_ISCHR(m)) return "a character device";
  if (S_ISBLK(m)) return "a block device";
  if (S_ISSOCK(m)) return "a socket";
  return "not a regular file";
}

nav_status nav_io_fopen_regular(const char *path, FILE **out, char *why, size_t why_size) {
  if (why && why_size) why[0] = '\0';
  if (!path || !out) return NAV_ERR_INVALID_ARG;
  /* O_NONBLOCK: opening a FIFO that no process writes to returns at once instead of waiting for
   * a writer; the mode is cleared again below for the regular file that is kept. */
  const int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) {
    const int err = errno;
    char msg[256];
    if (strerror_r(err, msg, sizeof msg) != 0) snprintf(msg, sizeof msg, "error %d", err);
    if (why && why_size) snprintf(why, why_size, "cannot open the file: %s", msg);
    return NAV_ERR_IO;
  }
  struct stat sb;
  if (fstat(fd, &sb) != 0) {
    const int err = errno;
    if (why && why_size) snprintf(why, why_size, "cannot read the file: %s", strerror(err));
    close(fd);
    return NAV_ERR_IO;
  }
  if (!S_ISREG(sb.st_mode)) {
    const char *kind = kind_of(sb.st_mode);
    if (why && why_size) {
      if (S_ISDIR(sb.st_mode) || S_ISFIFO(sb.st_mode) || S_ISCHR(sb.st_mode) || S_ISBLK(sb.st_mode) ||
          S_ISSOCK(sb.st_mode))
        snprintf(why, why_size, "cannot read the file: it is %s, not a regular file", kind);
      else
        snprintf(why, why_size, "cannot read the file: %s", kind);
    }
    close(fd);
    return NAV_ERR_PARSE;
  }
  const int fl = fcntl(fd, F_GETFL);
  if (fl < 0 || fcntl(fd, F_SETFL, fl & ~O_NONBLOCK) != 0) {
    if (why && why_size) snprintf(why, why_size, "cannot read the file: %s", strerror(errno));
    close(fd);
    return NAV_ERR_IO;
  }
  FILE *f = fdopen(fd, "rb");
  if (!f) {
    if (why && why_size) snprintf(why, why_size, "cannot read the file: %s", strerror(errno));
    close(fd);
    return NAV_ERR_IO;
  }
  *out = f;
  return NAV_OK;
}
