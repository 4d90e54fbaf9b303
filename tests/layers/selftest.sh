#!/bin/sh
# Self-test of check_layers.sh, so the layering test cannot pass by checking nothing: the fixture
# tree fixtures/bad breaks every rule once (a private header of a lower layer, an upward include,
# a private header of a peer, a file in no layer, a program finding its own path outside the
# paths file (which itself may), a CMake file changing another folder's target,
# on one line and over two) and must be rejected with exactly the lines of its expected.txt;
# fixtures/good keeps every rule and must pass; fixtures/badmap declares an upward dependency
# and must be refused as a wrong map (exit 2).
set -u
here="$(cd "$(dirname "$0")" && pwd)"
check="$here/check_layers.sh"
fx="$here/fixtures"
status=0
out="$(sh "$check" "$fx/bad" "$fx/bad/layers.map")"; rc=$?
if [ "$rc" -ne 1 ]; then echo "selftest: fixtures/bad: exit $rc, expected 1"; status=1; fi
if [ "$out" != "$(cat "$fx/bad/expected.txt")" ]; then
  echo "selftest: fixtures/bad: the violations differ from expected.txt:"
  printf '%s\n' "$out" | diff "$fx/bad/expected.txt" - ; status=1
fi
out="$(sh "$check" "$fx/good" "$fx/good/layers.map")"; rc=$?
if [ "$rc" -ne 0 ] || [ -n "$out" ]; then echo "selftest: fixtures/good: exit $rc, expected 0 and no output: $out"; status=1; fi
sh "$check" "$fx/badmap" "$fx/badmap/layers.map" >/dev/null 2>&1; rc=$?
if [ "$rc" -ne 2 ]; then echo "selftest: fixtures/badmap: exit $rc, expected 2 (a map with an upward dependency)"; status=1; fi
[ "$status" -eq 0 ] && echo "selftest: the checker rejects all $(wc -l < "$fx/bad/expected.txt") planted violations, passes the clean tree, refuses the upward map"
exit "$status"
