/**
 * @file nav_test.h
 * @brief Double-precision assertions for cmocka (style.md section 10). cmocka 1.1.5 has no
 *        assert_double_equal and its assert_float_equal casts to float; use these instead.
 *        Each failure prints both values and the tolerance.
 *
 * Include after <cmocka.h>.
 */
#ifndef NAV_TEST_H
#define NAV_TEST_H

#include <math.h>
#include <stdio.h>

#include "navcore/nav_math.h"

/* |actual - expected| <= abs_tol (NaN never passes). */
#define assert_near(actual, expected, abs_tol)                                                      \
  do {                                                                                              \
    const double nav_a_ = (actual), nav_e_ = (expected), nav_t_ = (abs_tol);                        \
    if (!(fabs(nav_a_ - nav_e_) <= nav_t_))                                                         \
      fail_msg("%s = %.17g, expected %.17g +/- %.3g (diff %.3g)", #actual, nav_a_, nav_e_, nav_t_,  \
               nav_a_ - nav_e_);                                                                    \
  } while (0)

/* |actual - expected| <= rel_tol * |expected|. */
#define assert_rel_near(actual, expected, rel_tol)                                                  \
  do {                                                                                              \
    const double nav_a_ = (actual), nav_e_ = (expected), nav_t_ = (rel_tol);                        \
    if (!(fabs(nav_a_ - nav_e_) <= nav_t_ * fabs(nav_e_)))                                          \
      fail_msg("%s = %.17g, expected %.17g within relative %.3g (rel diff %.3g)", #actual, nav_a_,  \
               nav_e_, nav_t_, (nav_a_ - nav_e_) / nav_e_);                                         \
  } while (0)

/* Component-wise |a - e| <= tol. */
#define assert_vec3_near(actual, expected, abs_tol)                                                 \
  do {                                                                                              \
    const nav_vec3 nav_va_ = (actual), nav_ve_ = (expected);                                        \
    const double nav_vt_ = (abs_tol);                                                               \
    if (!(fabs(nav_va_.x - nav_ve_.x) <= nav_vt_ && fabs(nav_va_.y - nav_ve_.y) <= nav_vt_ &&       \
          fabs(nav_va_.z - nav_ve_.z) <= nav_vt_))                                                  \
      fail_msg("%s = (%.17g, %.17g, %.17g), expected (%.17g, %.17g, %.17g) +/- %.3g", #actual,      \
               nav_va_.x, nav_va_.y, nav_va_.z, nav_ve_.x, nav_ve_.y, nav_ve_.z, nav_vt_);          \
  } while (0)

/* Quaternions equal up to sign: min(|a - e|, |a + e|) <= tol component-wise. */
#define assert_quat_near(actual, expected, abs_tol)                                                 \
  do {                                                                                              \
    const nav_quat nav_qa_ = (actual), nav_qe_ = (expected);                                        \
    const double nav_qt_ = (abs_tol);                                                               \
    const double nav_dm_ = fmax(fmax(fabs(nav_qa_.w - nav_qe_.w), fabs(nav_qa_.x - nav_qe_.x)),     \
                                fmax(fabs(nav_qa_.y - nav_qe_.y), fabs(nav_qa_.z - nav_qe_.z)));    \
    const double nav_dp_ = fmax(fmax(fabs(nav_qa_.w + nav_qe_.w), fabs(nav_qa_.x + nav_qe_.x)),     \
                                fmax(fabs(nav_qa_.y + nav_qe_.y), fabs(nav_qa_.z + nav_qe_.z)));    \
    if (!(fmin(nav_dm_, nav_dp_) <= nav_qt_))                                                       \
      fail_msg("%s = [%.17g, %.17g, %.17g, %.17g], expected +/-[%.17g, %.17g, %.17g, %.17g] "     \
               "+/- %.3g",                                                                          \
               #actual, nav_qa_.w, nav_qa_.x, nav_qa_.y, nav_qa_.z, nav_qe_.w, nav_qe_.x, nav_qe_.y, \
               nav_qe_.z, nav_qt_);                                                                 \
  } while (0)

/* Component-wise matrix comparison. */
#define assert_mat3_near(actual, expected, abs_tol)                                                 \
  do {                                                                                              \
    const nav_mat3 nav_ma_ = (actual), nav_me_ = (expected);                                        \
    for (int nav_i_ = 0; nav_i_ < 3; ++nav_i_)                                                      \
      for (int nav_j_ = 0; nav_j_ < 3; ++nav_j_)                                                    \
        if (!(fabs(nav_ma_.m[nav_i_][nav_j_] - nav_me_.m[nav_i_][nav_j_]) <= (abs_tol)))            \
          fail_msg("%s[%d][%d] = %.17g, expected %.17g +/- %.3g", #actual, nav_i_, nav_j_,          \
                   nav_ma_.m[nav_i_][nav_j_], nav_me_.m[nav_i_][nav_j_], (double)(abs_tol));        \
  } while (0)

/* Print the seed of a property test so a failure can be reproduced. */
#define nav_test_print_seed(name, seed) \
  print_message("[ SEED     ] %s seed=%llu\n", (name), (unsigned long long)(seed))

#endif /* NAV_TEST_H */
