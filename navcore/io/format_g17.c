/* nav_format_g17 (nav_results.h): the CSV writers' exact "%.17g" fast path (fast_format.h) for
 * the programs that write their own rows (navsim estimate's estimate.csv). */
#include "fast_format.h"
#include "navcore/nav_results.h"

_Static_assert(NAV_FORMAT_G17_SIZE >= NAV_FMT_G17_SIZE, "nav_format_g17 buffer smaller than the formatter's");

int nav_format_g17(char *buf, double x) { return nav_fmt_g17(buf, x); }
