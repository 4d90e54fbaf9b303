#!/bin/sh
# navsim render --view for every view on the vendored tiny-gnss result (plus allan.csv and
# bench.csv, tradeoff.csv, and gnss-canyon's satellite files for sky and dop), a bad --view (exit 2), a missing directory (exit 1), and a scene file as input
# (run first, then rendered). Usage: render_views.sh NAVSIM DATA_DIR SCENE WORK_DIR
set -u
NAVSIM=$1
DATA=$2
SCENE=$3
WORK=$4
fail() { echo "render_views: FAILED: $*" >&2; exit 1; }
rm -rf "$WORK"
mkdir -p "$WORK" || fail "cannot create $WORK"
cp -r "$DATA/tiny-gnss" "$WORK/res" && cp "$DATA/allan.csv" "$DATA/bench.csv" "$DATA/tradeoff.csv" "$DATA"/gnss-canyon/*.csv "$WORK/res/" || fail "copy"
for v in 3d top map errors noise allan bench tradeoff sky dop; do
  "$NAVSIM" render "$WORK/res" --view $v --out "$WORK/$v.png" --size 400x300 || fail "--view $v exited $?"
  size=$(wc -c < "$WORK/$v.png") || fail "no $WORK/$v.png"
  [ "$size" -gt 3000 ] || fail "$v.png has only $size bytes"
done
# Playback movie through navsim render (options pass through to navview): PNG frames and .ogv.
"$NAVSIM" render "$WORK/res" --view 3d --out "$WORK/m.png" --size 240x160 --movie "$WORK/movie" --movie-frames 3 \
  || fail "--movie exited $?"
for i in 0000 0001 0002; do [ -s "$WORK/movie/frame_$i.png" ] || fail "movie frame $i missing"; done
[ ! -e "$WORK/movie/frame_0003.png" ] || fail "more movie frames than asked for"
[ "$(wc -c < "$WORK/movie/playback.ogv")" -gt 1000 ] || fail "playback.ogv missing or empty"
cmp -s "$WORK/movie/frame_0000.png" "$WORK/movie/frame_0002.png" && fail "movie frames do not move"
# Playback movie as one video file (issue 19): H.264 MP4 and VP9 WebM by ffmpeg, the asked size and
# duration (ffprobe), the follow camera; no .part left; bad combinations exit 2.
if command -v ffprobe >/dev/null 2>&1; then
  probe() { ffprobe -v error -select_streams v:0 -show_entries "$2" -of default=noprint_wrappers=1:nokey=1 "$1"; }
  "$NAVSIM" render "$WORK/res" --view 3d --movie "$WORK/play.mp4" --duration-s 2 --size 320x240 --follow \
    || fail "--movie play.mp4 exited $?"
  [ "$(probe "$WORK/play.mp4" stream=codec_name)" = h264 ] || fail "play.mp4 is not H.264"
  [ "$(probe "$WORK/play.mp4" stream=width)x$(probe "$WORK/play.mp4" stream=height)" = 320x240 ] || fail "play.mp4 size"
  d=$(probe "$WORK/play.mp4" format=duration)
  awk -v d="$d" 'BEGIN { exit !(d > 1.95 && d < 2.05) }' || fail "play.mp4 lasts $d s, expected 2"
  "$NAVSIM" render "$WORK/res" --movie "$WORK/play.webm" --duration-s 1 --size 320x240 || fail "--movie play.webm exited $?"
  [ "$(probe "$WORK/play.webm" stream=codec_name)" = vp9 ] || fail "play.webm is not VP9"
  [ ! -e "$WORK/play.mp4.part" ] && [ ! -e "$WORK/play.webm.part" ] || fail "a .part file was left"
  "$NAVSIM" render "$WORK/res" --view map --movie "$WORK/x.mp4" 2> "$WORK/err.txt"
  [ $? -eq 2 ] || fail "--view map --movie x.mp4: expected exit 2"
  grep -q "expected --view 3d" "$WORK/err.txt" || fail "no message for --view map --movie"
  "$NAVSIM" render "$WORK/res" --movie "$WORK/odd.mp4" --size 321x240 2> "$WORK/err.txt"
  [ $? -ne 0 ] || fail "odd width: expected a failure"
  grep -q "even width and height" "$WORK/err.txt" || fail "no message for an odd width"
  [ ! -e "$WORK/odd.mp4" ] && [ ! -e "$WORK/odd.mp4.part" ] || fail "odd.mp4 left behind"
else
  echo "render_views: ffprobe missing (Debian package ffmpeg): video movie checks skipped"
fi
# Default output name: RESULT_DIR/VIEW.png
"$NAVSIM" render "$WORK/res" --view map --size 300x200 || fail "default --out"
[ -s "$WORK/res/map.png" ] || fail "no RESULT_DIR/map.png"
"$NAVSIM" render "$WORK/res" --view nonsense --out "$WORK/x.png" 2> "$WORK/err.txt"
rc=$?
[ $rc -eq 2 ] || fail "bad --view: exit $rc, expected 2"
grep -q "expected 3d, top, map" "$WORK/err.txt" || fail "bad --view: no message"
# sky / dop of a result without gnss.constellation: exit 1, the missing file named.
cp -r "$DATA/tiny-gnss" "$WORK/nosat" || fail "copy nosat"
for v in sky dop; do
  "$NAVSIM" render "$WORK/nosat" --view $v --out "$WORK/x.png" 2> "$WORK/err.txt"
  rc=$?
  [ $rc -eq 1 ] || fail "--view $v without satellite files: exit $rc, expected 1"
  grep -q "gnss_" "$WORK/err.txt" || fail "--view $v without satellite files: no file named"
done
"$NAVSIM" render "$WORK/does-not-exist" --view 3d --out "$WORK/x.png" 2> /dev/null
rc=$?
[ $rc -eq 1 ] || fail "missing directory: exit $rc, expected 1"
# A scene file: navsim run into out/render-<stem> (relative to the working directory), then render.
(cd "$WORK" && "$NAVSIM" render "$SCENE" --view errors --out "$WORK/scene.png" --size 400x300) || fail "scene input"
[ -s "$WORK/scene.png" ] || fail "scene input: no image"
# navsim run wrote gnss.csv (fixes of run 0) and gnss_outages.csv for this INS/GNSS scene; no fix
# lies inside an outage.
R="$WORK/out/render-$(basename "$SCENE" .yaml)"
[ "$(head -1 "$R/gnss.csv")" = "t_s,lat_deg,lon_deg,h_m,pos_n_m,pos_e_m,pos_d_m,pos_sd_n_m,pos_sd_e_m,pos_sd_d_m" ] \
  || fail "gnss.csv header"
[ "$(wc -l < "$R/gnss.csv")" -gt 10 ] || fail "gnss.csv has too few fixes"
[ "$(wc -l < "$R/gnss_outages.csv")" -ge 2 ] || fail "gnss_outages.csv has no outage"
awk -F, 'NR == FNR { if (FNR > 1) { t0[FNR] = $1; t1[FNR] = $2; n = FNR } next }
         FNR > 1 { for (i = 2; i <= n; ++i) if ($1 >= t0[i] && $1 < t1[i]) { print "fix at " $1 " inside an outage"; bad = 1 } }
         END { exit bad }' "$R/gnss_outages.csv" "$R/gnss.csv" || fail "a GNSS fix lies inside an outage"
echo "render_views: passed"
