/* navsim schema: the JSON Schema of scene files (nav_schema.h). */
#ifndef NAVSIM_SCHEMA_CMD_H
#define NAVSIM_SCHEMA_CMD_H

/**
 * Run `navsim schema ARGS` (argv holds the arguments after "schema").
 * @return the process exit code: 0 success; 1 out of memory or a write error; 2 invalid command line.
 */
int navsim_schema(int argc, char **argv);

#endif /* NAVSIM_SCHEMA_CMD_H */
