#!/bin/sh
# navsim replay's output files, seen from the system calls (issue 23 item 2): each CSV file is
# written in large blocks (at most one write call per 64 KiB of file, plus two; with the 4 KiB
# buffer glibc kept when no buffer was given, the 50 s slice took 32 calls for nav.csv alone), its
# write-back is started (sync_file_range) before the result is committed, and every file and the
# directory are fsynced before the rename that puts the result in place.
# usage: replay_io_syscalls.sh NAVSIM SOURCE_DIR WORK_DIR      (exit 77: strace not available)
set -eu
NAVSIM=$1 SRC=$2 WORK=$3
command -v strace >/dev/null 2>&1 || { echo "strace not found: skipped"; exit 77; }
D=$SRC/tests/data/replay
rm -rf "$WORK" && mkdir -p "$WORK"
# First without strace (in a sanitizer build LeakSanitizer checks this run; it cannot work under
# ptrace, so it is off for the traced run), then traced, replacing the first result (--force) as
# the bench does.
"$NAVSIM" replay --imu "$D/IMU-100195-100245.txt" --gnss "$D/GNSS-100195-100245.txt" \
  --truth "$D/truth-100195-100245-20Hz.nav" --scene "$SRC/tests/data/replay/long-drive.yaml" \
  --out "$WORK/out" --quiet
ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
export ASAN_OPTIONS
strace -f -qq -o "$WORK/trace.txt" -e trace=openat,write,sync_file_range,fsync,rename,renameat2 \
  "$NAVSIM" replay --imu "$D/IMU-100195-100245.txt" --gnss "$D/GNSS-100195-100245.txt" \
  --truth "$D/truth-100195-100245-20Hz.nav" --scene "$SRC/tests/data/replay/long-drive.yaml" \
  --out "$WORK/out" --force --quiet
test -s "$WORK/out/nav.csv" || { echo "FAIL: no nav.csv"; exit 1; }
# strace -f splits a call that another thread interrupts into "PID call(args <unfinished ...>" and
# later "PID <... call resumed>rest": join each pair into one line, at the place the call ended
# (navsim fsyncs and unlinks a result's files on two threads).
awk '
  / <unfinished \.\.\.>$/        { l = $0; sub(/ <unfinished \.\.\.>$/, "", l); pend[$1] = l; next }
  /^[0-9]+ +<\.\.\. [a-z0-9_]+ resumed>/ { r = $0; sub(/^[0-9]+ +<\.\.\. [a-z0-9_]+ resumed>/, "", r)
                                    print pend[$1] r; delete pend[$1]; next }
  { print }' "$WORK/trace.txt" > "$WORK/trace-joined.txt"
# Per file (named by the path its descriptor was opened with): write calls, sync_file_range calls
# and fsyncs; and whether any fsync came after the rename. The write counts go to writes.txt.
awk '
  / openat\(/ && /= [0-9]+$/ { match($0, /"[^"]*"/); p = substr($0, RSTART + 1, RLENGTH - 2);
                              n = split(p, a, "/"); fd = $NF; name[fd] = a[n]; next }
  / write\(/                 { split($0, a, /[(,]/); f = a[2]; if (f in name) w[name[f]]++; next }
  / sync_file_range\(/       { split($0, a, /[(,]/); f = a[2]; if (f in name) s[name[f]]++; next }
  / fsync\(/                 { split($0, a, /[()]/); f = a[2]; if (f in name) { fs[name[f]]++; if (renamed) late = 1 }; next }
  / rename(at2)?\(/          { renamed = 1 }
  END {
    bad = 0
    for (i = 1; i <= 3; ++i) {
      c = (i == 1 ? "truth.csv" : i == 2 ? "nav.csv" : "errors.csv")
      printf "%s: %d write calls, %d sync_file_range, %d fsync\n", c, w[c], s[c], fs[c]
      if (s[c] < 1 || fs[c] < 1) bad = 1
      lim[c] = w[c]
    }
    if (fs["summary.json"] < 1) { print "FAIL: summary.json not fsynced"; bad = 1 }
    if (!renamed || late) { print "FAIL: an fsync after the rename, or no rename"; bad = 1 }
    for (c in lim) printf "%s %d\n", c, lim[c] > "/dev/stderr"
    exit bad
  }' "$WORK/trace-joined.txt" 2> "$WORK/writes.txt" || { echo "FAIL: see $WORK/trace.txt"; exit 1; }
# The write calls against the file sizes.
while read -r f n; do
  size=$(wc -c < "$WORK/out/$f")
  max=$((size / 65536 + 2))
  if [ "$n" -gt "$max" ]; then echo "FAIL: $f ($size bytes) written in $n calls (at most $max)"; exit 1; fi
done < "$WORK/writes.txt"
echo "ok"
