#!/bin/sh
# navsim report end to end: render every figure of a small result directory (tiny-gnss plus an
# allan.csv and a bench.csv), write the HTML page, open it in headless Chromium and check that
# every <img> loaded (the page's load handler marks each image data-loaded="yes"/"no" from
# naturalWidth), that every figure PNG exists and is not trivial, and that a screenshot of the page
# is not blank. Usage: report_chromium.sh NAVSIM DATA_DIR WORK_DIR
set -u
NAVSIM=$1
DATA=$2
WORK=$3
fail() { echo "report_chromium: FAILED: $*" >&2; exit 1; }
CHROMIUM=$(command -v chromium || command -v chromium-browser || true)
if [ -z "$CHROMIUM" ]; then
  echo "report_chromium: skipped: chromium not found (install chromium)"
  exit 77
fi
rm -rf "$WORK"
mkdir -p "$WORK" || fail "cannot create $WORK"
cp -r "$DATA/tiny-gnss" "$WORK/res" && cp "$DATA/allan.csv" "$DATA/bench.csv" "$WORK/res/" || fail "cannot copy test data"

"$NAVSIM" report "$WORK/res" --out "$WORK/rep" --size 800x560 || fail "navsim report exited $?"
PAGE="$WORK/rep/report.html"
[ -s "$PAGE" ] || fail "no $PAGE"
n_fig=0
for f in 3d top map map-region errors noise allan bench; do
  png="$WORK/rep/$f.png"
  [ -f "$png" ] || fail "figure $png missing"
  size=$(wc -c < "$png")
  [ "$size" -gt 5000 ] || fail "figure $png has only $size bytes"
  n_fig=$((n_fig + 1))
done

# Headless Chromium: the DOM after the load event.
"$CHROMIUM" --headless --no-sandbox --disable-gpu --virtual-time-budget=10000 --dump-dom "file://$PAGE" \
  > "$WORK/dom.html" 2> "$WORK/chromium.log" || fail "chromium --dump-dom failed (see $WORK/chromium.log)"
n_img=$(grep -o '<img' "$WORK/dom.html" | wc -l)
n_yes=$(grep -o 'data-loaded="yes"' "$WORK/dom.html" | wc -l)
n_no=$(grep -o 'data-loaded="no"' "$WORK/dom.html" | wc -l)
echo "report_chromium: $n_fig figure files, $n_img <img> in the page, $n_yes loaded, $n_no not loaded"
[ "$n_img" -eq "$n_fig" ] || fail "the page has $n_img images, expected $n_fig"
[ "$n_yes" -eq "$n_img" ] || fail "only $n_yes of $n_img images loaded"
[ "$n_no" -eq 0 ] || fail "$n_no images did not load"
grep -q 'FAIL</td>' "$WORK/dom.html" || fail "the failed requirement v-max is not shown"
grep -q 'h-rms' "$WORK/dom.html" || fail "requirement h-rms missing"

# Screenshot: a blank page compresses to a few kB; the report with its figures to hundreds.
"$CHROMIUM" --headless --no-sandbox --disable-gpu --hide-scrollbars --window-size=1280,3000 \
  --virtual-time-budget=10000 --screenshot="$WORK/shot.png" "file://$PAGE" >> "$WORK/chromium.log" 2>&1 \
  || fail "chromium --screenshot failed (see $WORK/chromium.log)"
shot=$(wc -c < "$WORK/shot.png")
echo "report_chromium: screenshot $WORK/shot.png, $shot bytes"
[ "$shot" -gt 100000 ] || fail "screenshot is nearly blank ($shot bytes)"
echo "report_chromium: passed"
