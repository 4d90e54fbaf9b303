/* libFuzzer target: the scene reader (YAML from memory, every field's validation). */
#include <stddef.h>
#include <stdint.h>

#include "navcore/nav_io.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* The status is not what a fuzz target checks (GCC does not let (void) drop a nodiscard). */
#define NAV_FUZZ_IGNORE(call)        \
  do {                               \
    const nav_status ignored_ = call; \
    (void)ignored_;                  \
  } while (0)

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  nav_scene scene;
  if (nav_scene_read_string((const char *)data, size, "fuzz.yaml", &scene, NULL, NULL) == NAV_OK)
    nav_scene_release(&scene); /* a recorded reference's control points */
  return 0;
}
