#!/bin/sh
# Run a render test on the X server of $DISPLAY when there is one (scripts/test starts a single
# Xvfb for the whole suite), else under its own xvfb-run. Per-test "xvfb-run -a" was flaky on
# the loaded 2-core machine: a client sometimes found no server ("bad X server connection").
if [ -n "$DISPLAY" ]; then
  exec "$@"
fi
exec xvfb-run -a -s "-screen 0 800x600x24" "$@"
