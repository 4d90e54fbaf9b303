#!/bin/sh
# navsim render --view map --tiles (issue 19 item 2): the test's own tiles around Turin
# (navview_make_test_tiles) as an MBTiles file, an XYZ directory and an XYZ URL served by a local
# python3 http.server; the same picture from all three, the URL's disk cache (filled, then used
# with the server gone), the offline message, and bad sources: exit 2 with a clear message and no
# picture written.
# Usage: render_tiles.sh NAVSIM MAKE_TILES WORK_DIR
set -u
NAVSIM=$1
MAKE=$2
WORK=$3
fail() { echo "render_tiles: FAILED: $*" >&2; [ -n "${SRV:-}" ] && kill "$SRV" 2>/dev/null; exit 1; }
rm -rf "$WORK"
mkdir -p "$WORK/res" || fail "cannot create $WORK"
"$MAKE" "$WORK/t" 45.0703 7.6869 14 16 1500 || fail "making the tiles"
# A result directory: a 1 km drive east through the middle of the tiles.
awk 'BEGIN {
  print "t_s,lat_deg,lon_deg,h_m,pos_n_m,pos_e_m,pos_d_m,vel_n_mps,vel_e_mps,vel_d_mps,roll_deg,pitch_deg,yaw_deg"
  for (i = 0; i <= 20; ++i)
    printf "%d,45.0703,%.7f,250,0,%.3f,0,0,10,0,0,0,90\n", 5 * i, 7.6805 + i * 0.000635, 50 * i - 500
}' > "$WORK/res/truth.csv"
cp "$WORK/res/truth.csv" "$WORK/res/nav.csv"
ATTR="© navview test tiles"
render() { # OUT [options...]: the map 1.5 km across at 640x400
  out=$1
  shift
  "$NAVSIM" render "$WORK/res" --view map --map-span 1.5 --map-center 45.0703,7.6869 --size 640x400 --out "$out" "$@"
}
render "$WORK/mbtiles.png" --tiles "$WORK/t/tiles.mbtiles" || fail "MBTiles render exited $?"
render "$WORK/xyz.png" --tiles "$WORK/t/xyz" --tiles-attribution "$ATTR" || fail "XYZ render exited $?"
cmp -s "$WORK/mbtiles.png" "$WORK/xyz.png" || fail "the XYZ directory gives another picture than the MBTiles file"
render "$WORK/plain.png" || fail "render without tiles exited $?"
cmp -s "$WORK/mbtiles.png" "$WORK/plain.png" && fail "--tiles changed nothing"

# Bad sources: exit 2, the source and what is wrong on stderr, no picture.
printf 'not a database\n' > "$WORK/bad.mbtiles"
bad() { # WHAT EXPECTED_TEXT SOURCE
  rm -f "$WORK/bad.png"
  render "$WORK/bad.png" --tiles "$3" 2> "$WORK/err.txt"
  rc=$?
  [ $rc -eq 2 ] || fail "$1: exit $rc, expected 2"
  grep -q "$2" "$WORK/err.txt" || fail "$1: no '$2' in: $(cat "$WORK/err.txt")"
  [ ! -e "$WORK/bad.png" ] || fail "$1: a picture was written"
  echo "render_tiles: $1 -> exit 2: $(cat "$WORK/err.txt")"
}
bad "corrupt MBTiles" "bad.mbtiles: error: not an MBTiles file" "$WORK/bad.mbtiles"
bad "missing file" "no-such.mbtiles: error: no such file or directory" "$WORK/no-such.mbtiles"
bad "template without {y}" "needs {z}, {x} and {y}" "$WORK/t/xyz/{z}/{x}.png"
bad "URL without {x}" "needs {z}, {x} and {y}" "http://127.0.0.1:9/{z}/{y}.png"

# The URL source: a local HTTP server (port chosen by the system) serving the XYZ directory.
python3 -u -m http.server 0 --bind 127.0.0.1 --directory "$WORK/t/xyz" > "$WORK/http.log" 2>&1 &
SRV=$!
PORT=
for i in $(seq 1 50); do
  PORT=$(sed -n 's/.*port \([0-9][0-9]*\).*/\1/p' "$WORK/http.log" | head -n 1)
  [ -n "$PORT" ] && break
  sleep 0.1
done
[ -n "$PORT" ] || fail "the HTTP server did not start: $(cat "$WORK/http.log")"
URL="http://127.0.0.1:$PORT/{z}/{x}/{y}.png"
export NAVVIEW_TILE_CACHE="$WORK/cache"
render "$WORK/url.png" --tiles "$URL" --tiles-attribution "$ATTR" 2> "$WORK/url-err.txt" || fail "URL render exited $?"
cmp -s "$WORK/mbtiles.png" "$WORK/url.png" || fail "the URL gives another picture than the MBTiles file"
fetched=$(grep -c '"GET /16/[^"]*" 200' "$WORK/http.log")
cached=$(find "$WORK/cache" -name '*.png' | wc -l)
echo "render_tiles: URL: $fetched tiles fetched, $cached in the cache"
[ "$fetched" -ge 4 ] || fail "only $fetched tiles fetched"
[ "$cached" -eq "$fetched" ] || fail "$fetched tiles fetched but $cached cached"
kill "$SRV"
wait "$SRV" 2>/dev/null
SRV=
# Server gone: the cache alone gives the same picture, with no message.
render "$WORK/url-cached.png" --tiles "$URL" --tiles-attribution "$ATTR" 2> "$WORK/cached-err.txt" ||
  fail "cached URL render exited $?"
cmp -s "$WORK/mbtiles.png" "$WORK/url-cached.png" || fail "the cached tiles give another picture"
! grep -q "warning" "$WORK/cached-err.txt" || fail "warnings with a full cache: $(cat "$WORK/cached-err.txt")"
# One cached tile removed, server gone: drawn without it, exit 0, the offline message on stderr.
rm "$(find "$WORK/cache" -name '*.png' | sort | head -n 1)"
render "$WORK/url-offline.png" --tiles "$URL" --tiles-attribution "$ATTR" 2> "$WORK/offline-err.txt" ||
  fail "offline URL render exited $?"
grep -q "cannot reach the tile server" "$WORK/offline-err.txt" || fail "no offline message: $(cat "$WORK/offline-err.txt")"
cmp -s "$WORK/mbtiles.png" "$WORK/url-offline.png" && fail "a tile missing offline was still drawn"
echo "render_tiles: offline -> $(cat "$WORK/offline-err.txt")"
echo "render_tiles: all passed"
