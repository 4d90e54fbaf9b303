/*
 * navsim schema: print the JSON Schema (draft 2020-12) of scene files on stdout. The schema is
 * generated from the table the scene reader itself walks (nav_schema_json), so a file valid under
 * it passes every per-key check of `navsim check` (types, units, bounds, enums, unknown keys); the
 * cross-key rules (one way of giving a waypoint, feasibility of a script, ...) are the reader's.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli_util.h"
#include "schema_cmd.h"
#include "navcore/nav_schema.h"

static const char *k_usage_schema =
    "usage: navsim schema\n"
    "\n"
    "Print the JSON Schema (draft 2020-12) of scene files on stdout.\n"
    "\n"
    "Every key of the scene format is listed with its type, a one-line \"description\", its\n"
    "\"default\", its bounds (\"minimum\", \"maximum\", \"exclusiveMinimum\") and choices (\"enum\").\n"
    "Numeric keys carry two extra keywords: \"x-unit\", the unit as written in a scene (deg/h, m,\n"
    "s, ...), and \"x-si-scale\", the factor from that unit to SI. Mappings list their keys under\n"
    "\"properties\" and reject others (\"additionalProperties\": false), as `navsim check` does.\n"
    "A scene file is YAML; validate the JSON it maps to (YAML 1.2 numbers and booleans).\n"
    "\n"
    "options:\n"
    "  -h, --help       print this help\n"
    "\n"
    "exit codes: 0 success, 1 out of memory or write error, 2 invalid command line\n";

int navsim_schema(int argc, char **argv) {
  for (int i = 0; i < argc; ++i) {
    if (navsim_is_help(argv[i])) {
      fputs(k_usage_schema, stdout);
      return 0;
    }
    fprintf(stderr, "navsim schema: unexpected argument \"%s\"\n%s", argv[i], k_usage_schema);
    return 2;
  }
  char *json = nav_schema_json();
  if (json == NULL) {
    fprintf(stderr, "navsim schema: out of memory\n");
    return 1;
  }
  const size_t n = strlen(json);
  const int rc = fwrite(json, 1, n, stdout) == n && fflush(stdout) == 0 ? 0 : 1;
  if (rc != 0) fprintf(stderr, "navsim schema: cannot write the schema to stdout\n");
  free(json);
  return rc;
}
