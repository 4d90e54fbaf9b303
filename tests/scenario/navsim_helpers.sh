#!/bin/sh
# navsim's helper programs (navcore/navsim/exec_helper.h): navsim itself neither links nor loads
# the server's libraries (libmicrohttpd, libzip, GnuTLS) or Open MPI; `navsim serve` runs through
# navsim-serve and `navsim run` under mpirun through navsim-mpi, which do load them; a navsim
# whose helper is missing says so (exit 1) instead of running without it.
# usage: navsim_helpers.sh NAVSIM SOURCE_DIR WORK_DIR SERVE(0|1) MPI(0|1) [MPIEXEC]
set -eu
NAVSIM=$1 SRC=$2 WORK=$3 SERVE=$4 MPI=$5 MPIEXEC=${6:-}
fail() { echo "FAIL: $*" >&2; exit 1; }
rm -rf "$WORK" && mkdir -p "$WORK"
heavy='libmicrohttpd|libzip|libgnutls|libmpi|libopen-rte|libopen-pal|libhwloc'

# 1. Linked: no heavy library among navsim's NEEDED entries (direct) nor in ldd (the closure).
readelf -d "$NAVSIM" | grep NEEDED > "$WORK/needed.txt"
! grep -E "$heavy" "$WORK/needed.txt" || fail "navsim links a library of the server or of MPI"
ldd "$NAVSIM" > "$WORK/ldd.txt"
! grep -E "$heavy" "$WORK/ldd.txt" || fail "navsim's ldd lists a library of the server or of MPI"
grep -q libfyaml "$WORK/ldd.txt" || fail "ldd of navsim did not list libfyaml (is the check looking at navsim?)"

# 2. Loaded (the dynamic loader's own log): --version and a one-run simulation load none of them.
loaded() { # LOG: the libraries the loader initialised
  grep 'calling init:' "$1" | sed 's/.*calling init: //' | sort -u
}
LD_DEBUG=libs LD_DEBUG_OUTPUT="$WORK/ld-version" "$NAVSIM" --version > "$WORK/version.txt"
grep -q '^navsim ' "$WORK/version.txt" || fail "navsim --version printed: $(cat "$WORK/version.txt")"
cat "$WORK"/ld-version.* | loaded /dev/stdin > "$WORK/loaded-version.txt"
grep -q libfyaml "$WORK/loaded-version.txt" || fail "LD_DEBUG=libs showed no libfyaml: the check would see nothing"
! grep -E "$heavy" "$WORK/loaded-version.txt" || fail "navsim --version loaded a library of the server or of MPI"
LD_DEBUG=libs LD_DEBUG_OUTPUT="$WORK/ld-run" "$NAVSIM" run "$SRC/scenes/car-figure-eight.yaml" --runs 1 \
  --out "$WORK/run" --quiet
test -s "$WORK/run/summary.json" || fail "navsim run wrote no summary.json"
cat "$WORK"/ld-run.* | loaded /dev/stdin > "$WORK/loaded-run.txt"
! grep -E "$heavy" "$WORK/loaded-run.txt" || fail "navsim run (no ranks) loaded a library of the server or of MPI"

# 3. navsim serve --help through navsim-serve: the server's usage, exit 0, libmicrohttpd loaded
#    by the helper (so the checks above look where the library would show).
if [ "$SERVE" = 1 ]; then
  LD_DEBUG=libs LD_DEBUG_OUTPUT="$WORK/ld-serve" "$NAVSIM" serve --help > "$WORK/serve-help.txt"
  grep -q '^usage: navsim serve ' "$WORK/serve-help.txt" || fail "navsim serve --help printed: $(head -n 3 "$WORK/serve-help.txt")"
  cat "$WORK"/ld-serve.* | loaded /dev/stdin > "$WORK/loaded-serve.txt"
  grep -q libmicrohttpd "$WORK/loaded-serve.txt" || fail "navsim serve --help did not load libmicrohttpd (no helper ran?)"
  # The helper alone refuses anything but `serve` (exit 2).
  rc=0; "$(dirname "$NAVSIM")/navsim-serve" run x.yaml 2> "$WORK/helper-direct.txt" || rc=$?
  [ "$rc" = 2 ] || fail "navsim-serve run: exit $rc, expected 2"
  grep -q 'navsim serve' "$WORK/helper-direct.txt" || fail "navsim-serve run: $(cat "$WORK/helper-direct.txt")"
fi

# 4. A navsim without its helpers beside it: a clear message naming the helper, exit 1, no crash.
mkdir -p "$WORK/alone"
cp "$NAVSIM" "$WORK/alone/navsim"
if [ "$SERVE" = 1 ]; then
  rc=0; "$WORK/alone/navsim" serve --help > /dev/null 2> "$WORK/alone-serve.txt" || rc=$?
  [ "$rc" = 1 ] || fail "navsim serve without navsim-serve: exit $rc, expected 1"
  grep -q 'navsim serve: the helper program navsim-serve is not installed' "$WORK/alone-serve.txt" ||
    fail "navsim serve without navsim-serve said: $(cat "$WORK/alone-serve.txt")"
fi
if [ "$MPI" = 1 ]; then
  # The launcher's environment alone decides (no MPI call happens before the exec).
  rc=0; OMPI_COMM_WORLD_SIZE=2 "$WORK/alone/navsim" run "$SRC/scenes/car-figure-eight.yaml" --out "$WORK/none" \
    --quiet 2> "$WORK/alone-mpi.txt" || rc=$?
  [ "$rc" = 1 ] || fail "navsim run under 2 ranks without navsim-mpi: exit $rc, expected 1"
  grep -q 'navsim run: the helper program navsim-mpi is not installed' "$WORK/alone-mpi.txt" ||
    fail "navsim run under 2 ranks without navsim-mpi said: $(cat "$WORK/alone-mpi.txt")"
  [ ! -e "$WORK/none" ] || fail "navsim run without navsim-mpi left $WORK/none"
fi

# 5. Under mpirun with 2 ranks: each rank is navsim-mpi (it loads libmpi), the result is written.
if [ "$MPI" = 1 ] && [ -n "$MPIEXEC" ]; then
  OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 LD_DEBUG=libs LD_DEBUG_OUTPUT="$WORK/ld-mpi" \
    timeout 300 "$MPIEXEC" --oversubscribe -np 2 "$NAVSIM" run "$SRC/scenes/car-figure-eight.yaml" --runs 4 \
    --threads 1 --out "$WORK/mpi" --quiet
  test -s "$WORK/mpi/summary.json" || fail "mpirun -np 2 navsim run wrote no summary.json"
  n=0
  for f in "$WORK"/ld-mpi.*; do
    loaded "$f" | grep -q 'libmpi\.so' && n=$((n + 1))
  done
  [ "$n" = 2 ] || fail "libmpi was loaded by $n processes under mpirun -np 2, expected 2 (the ranks)"
fi
echo "navsim helpers: navsim loads neither the server's libraries nor MPI; serve and mpirun go through the helpers"
