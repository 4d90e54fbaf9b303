/* Status strings and the run-time version. */
#include "navcore/nav_status.h"
#include "navcore/nav_version.h"

const char *nav_status_str(nav_status s) {
  switch (s) {
  case NAV_OK: return "ok";
  case NAV_ERR_INVALID_ARG: return "invalid argument";
  case NAV_ERR_NO_MEMORY: return "out of memory";
  case NAV_ERR_OUT_OF_RANGE: return "out of range";
  case NAV_ERR_NOT_CONVERGED: return "not converged";
  case NAV_ERR_NUMERIC: return "numerical failure";
  case NAV_ERR_STATE: return "wrong call order";
  case NAV_ERR_CANCELLED: return "cancelled";
  case NAV_ERR_IO: return "i/o error";
  case NAV_ERR_PARSE: return "parse error";
  }
  return "unknown status";
}

long nav_version(void) { return NAV_VERSION; }

const char *nav_version_string(void) { return NAV_VERSION_STRING; }
