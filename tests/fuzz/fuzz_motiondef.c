/* libFuzzer target: the gnss-ins-sim motion-definition CSV importer (parse, map to segments,
 * plan the script). */
#include <stddef.h>
#include <stdint.h>

#include "navcore/nav_motiondef.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* The status is not what a fuzz target checks (GCC does not let (void) drop a nodiscard). */
#define NAV_FUZZ_IGNORE(call)        \
  do {                               \
    const nav_status ignored_ = call; \
    (void)ignored_;                  \
  } while (0)

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  static nav_scene scene;
  scene = nav_scene_default();
  scene.earth.model = NAV_EARTH_WGS84;
  NAV_FUZZ_IGNORE(nav_motiondef_read_string((const char *)data, size, "fuzz.csv", &scene, NULL, NULL));
  return 0;
}
