/**
 * @file nav_status.h
 * @brief Status codes returned by every fallible navcore function (style.md section 5).
 */
#ifndef NAV_STATUS_H
#define NAV_STATUS_H

#include "nav_export.h"

NAV_BEGIN_DECLS

/** Result of a fallible navcore call. NAV_OK is zero; everything else is an error. */
typedef enum nav_status {
  NAV_OK = 0,
  NAV_ERR_INVALID_ARG,  /**< an argument is NULL, out of its domain, or inconsistent */
  NAV_ERR_NO_MEMORY,    /**< an allocation failed or a size would overflow */
  NAV_ERR_OUT_OF_RANGE, /**< a value or time lies outside the supported range */
  NAV_ERR_NOT_CONVERGED,/**< an iteration did not reach its tolerance */
  NAV_ERR_NUMERIC,      /**< non-finite value, or a covariance that is not positive definite */
  NAV_ERR_STATE,        /**< functions called in the wrong order */
  NAV_ERR_CANCELLED,    /**< a run was cancelled through its progress callback or job handle */
  NAV_ERR_IO,           /**< file or stream error (navcore_io only) */
  NAV_ERR_PARSE         /**< malformed or invalid input file (navcore_io only) */
} nav_status;

/** @return a static, human-readable name for @p s (never NULL). Thread-safe. */
NAV_API const char *nav_status_str(nav_status s);

NAV_END_DECLS

#endif /* NAV_STATUS_H */
