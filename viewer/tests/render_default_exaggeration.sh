#!/bin/sh
# Issue 19: "navsim render defaults to error x1 while the report's caption says x20". navsim render
# DIR --view 3d without --exaggerate must draw the attitude error exaggerated 20 times (the
# report's caption and navstudio's default): byte-identical to --exaggerate 20, different from
# --exaggerate 1 (so a default of 1 fails the first comparison).
# Usage: render_default_exaggeration.sh NAVSIM DATA_DIR WORK_DIR
set -u
NAVSIM=$1
DATA=$2
WORK=$3
fail() { echo "render_default_exaggeration: FAILED: $*" >&2; exit 1; }
rm -rf "$WORK"
mkdir -p "$WORK" || fail "cannot create $WORK"
cp -r "$DATA/tiny-gnss" "$WORK/res" || fail "copy"
for k in default 20 1; do
  opt=""
  [ "$k" = default ] || opt="--exaggerate $k"
  # shellcheck disable=SC2086
  "$NAVSIM" render "$WORK/res" --view 3d --size 480x360 $opt --out "$WORK/3d-$k.png" || fail "x$k exited $?"
  [ "$(wc -c < "$WORK/3d-$k.png")" -gt 3000 ] || fail "3d-$k.png missing or tiny"
done
cmp -s "$WORK/3d-1.png" "$WORK/3d-20.png" && fail "--exaggerate 1 and 20 draw the same picture: the test cannot tell them apart"
cmp -s "$WORK/3d-default.png" "$WORK/3d-20.png" || fail "the default differs from --exaggerate 20"
echo "render_default_exaggeration: the default picture equals --exaggerate 20 and differs from --exaggerate 1"
