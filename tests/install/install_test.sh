#!/bin/sh
# Install, package and man-page tests (issue 24), run by ctest (tests/install/install_tests.cmake).
# usage: install_test.sh MODE SOURCE_DIR BUILD_DIR WORK_DIR VERSION
#   setup      cmake --install BUILD_DIR --prefix WORK_DIR/prefix --strip (the fixture of the others)
#   tree       the installed files; no build or source path in the installed binaries; the
#              installed navsim, moved elsewhere with the source and build trees hidden, finds
#              its scenes and catalogs (check + run + catalog)
#   cmake      an external CMake project: find_package(navcore), navcore::io and io_static
#   pkgconfig  the same program built with pkg-config --cflags --libs navcore-io
#   man        every command of navsim --help has a man page; each page says what --help says
#   deb        cpack -G DEB; dpkg -x in a scratch root; navsim check + run from there; lintian
set -eu
mode=$1
src=$(cd "$2" && pwd -P)
build=$(cd "$3" && pwd -P)
work=$4
version=$5
prefix=$work/prefix
fail() { echo "FAIL: $*" >&2; exit 1; }
scene=car-figure-eight.yaml   # IMU from the catalog: the resources directory is needed too

# The figure the consumer prints, and navsim run's own report of it, must be a finite number.
check_consumer_line() { # LINE
  echo "$1"
  echo "$1" | grep -Eq "^navcore $version \\(headers $version\\): $scene: [0-9]+ run\\(s\\) of [0-9.]+ s, final horizontal error [0-9]+\\.[0-9]+ m$" ||
    fail "unexpected consumer output: $1"
}

case $mode in
setup)
  rm -rf "$work"
  mkdir -p "$work"
  cmake --install "$build" --prefix "$prefix" --strip > "$work/install.log" || { cat "$work/install.log"; fail "cmake --install"; }
  echo "installed into $prefix: $(grep -c Installing "$work/install.log") files"
  ;;

tree)
  [ -d "$prefix" ] || fail "no installed tree at $prefix (fixture install_setup)"
  libdir=$(cd "$prefix" && ls -d lib lib64 lib/*-linux-gnu 2>/dev/null | while read -r d; do [ -e "$prefix/$d/libnavcore.so" ] && echo "$d"; done | head -n 1)
  [ -n "$libdir" ] || fail "libnavcore.so not installed"
  for f in bin/navsim "$libdir/libnavcore.a" "$libdir/libnavcore_io.a" \
    "$libdir/libnavcore.so.$version" "$libdir/libnavcore_io.so.$version" \
    "$libdir/cmake/navcore/navcoreConfig.cmake" "$libdir/cmake/navcore/navcoreConfigVersion.cmake" \
    "$libdir/cmake/navcore/navcoreTargets.cmake" "$libdir/pkgconfig/navcore.pc" "$libdir/pkgconfig/navcore-io.pc" \
    include/navcore/nav_version.h include/navcore/nav_paths.h share/man/man1/navsim.1.gz \
    share/bash-completion/completions/navsim share/navcore/resources/imu_catalog.csv \
    share/navcore/resources/gnss_receivers.csv share/navcore/scenes/$scene; do
    [ -e "$prefix/$f" ] || fail "not installed: $f"
  done
  if [ -x "$build/viewer/navview" ]; then
    for f in bin/navview share/man/man1/navview.1.gz; do [ -e "$prefix/$f" ] || fail "not installed: $f"; done
  fi
  if [ -x "$build/editor/navstudio" ]; then
    for f in bin/navstudio share/man/man1/navstudio.1.gz share/applications/navstudio.desktop \
      share/icons/hicolor/scalable/apps/navstudio.svg; do
      [ -e "$prefix/$f" ] || fail "not installed: $f"
    done
  fi
  # navsim's helper programs (navcore/navsim/exec_helper.h) in libexec/navcore, where navsim finds them.
  helpers=""
  for h in navsim-serve navsim-mpi; do
    if [ -x "$build/navcore/$h" ]; then
      [ -x "$prefix/libexec/navcore/$h" ] || fail "not installed: libexec/navcore/$h"
      helpers="$helpers $h"
    fi
  done
  # No program or library, built or installed, may name a search directory the loader reads as
  # relative to the current one: an empty RUNPATH/RPATH entry (CMake leaves a trailing ':' in the
  # build tree for installed targets unless they are linked with their install RUNPATH) or a
  # relative path. A build-tree navsim started in a user's data folder would otherwise load a
  # libexpat.so.1 lying there.
  for f in "$build/navcore/navsim" "$build"/navcore/navsim-* "$build/viewer/navview" "$build/editor/navstudio" \
    "$build"/navcore/libnavcore*.so.* "$prefix"/bin/* "$prefix"/libexec/navcore/* "$prefix/$libdir"/libnavcore*.so.*; do
    [ -f "$f" ] || continue
    rp=$(readelf -d "$f" | sed -n 's/.*(R[UN]*PATH).*\[\(.*\)\]/\1/p')
    [ -z "$rp" ] && continue
    case ":$rp:" in *::*) fail "$f: RUNPATH '$rp' has an empty entry (the current directory)" ;; esac
    old_ifs=$IFS; IFS=:
    for d in $rp; do
      case "$d" in /*|'$ORIGIN'*) ;; *) IFS=$old_ifs; fail "$f: RUNPATH '$rp' has a relative entry '$d'" ;; esac
    done
    IFS=$old_ifs
  done
  # SONAME follows the version: libnavcore.so.MAJOR.
  major=${version%%.*}
  for l in navcore navcore_io; do
    so=$(readelf -d "$prefix/$libdir/lib$l.so.$version" | sed -n 's/.*(SONAME).*\[\(.*\)\]/\1/p')
    [ "$so" = "lib$l.so.$major" ] || fail "lib$l SONAME is '$so', expected lib$l.so.$major"
  done
  # Only the public headers, exactly navcore/include/navcore/*.h (+ the generated nav_version.h).
  (cd "$src/navcore/include/navcore" && ls *.h; echo nav_version.h) | sort > "$work/headers.expected"
  (cd "$prefix/include/navcore" && ls) | sort > "$work/headers.installed"
  diff "$work/headers.expected" "$work/headers.installed" || fail "installed headers differ from navcore/include/navcore"
  # Every function the installed headers declare with NAV_API is exported by the shared libraries.
  grep -ho 'NAV_API[^(]*\bnav_[a-z0-9_]*(' "$prefix"/include/navcore/*.h | grep -o 'nav_[a-z0-9_]*($' | tr -d '(' |
    sort -u > "$work/api.declared"
  nm -D --defined-only "$prefix/$libdir/libnavcore.so.$version" "$prefix/$libdir/libnavcore_io.so.$version" |
    awk '$2 == "T" || $2 == "i" { print $3 }' | sort -u > "$work/api.exported"
  [ "$(wc -l < "$work/api.declared")" -gt 100 ] || fail "too few NAV_API declarations found in the headers"
  comm -23 "$work/api.declared" "$work/api.exported" > "$work/api.missing"
  [ ! -s "$work/api.missing" ] || fail "declared but not exported: $(tr '\n' ' ' < "$work/api.missing")"
  # No compiled-in path of this machine's source or build tree in what runs.
  for f in "$prefix"/bin/* "$prefix/$libdir"/lib*.so.* $(for h in $helpers; do echo "$prefix/libexec/navcore/$h"; done); do
    [ -L "$f" ] && continue
    if strings -a "$f" | grep -F -e "$build" -e "$src" > "$work/paths.txt"; then
      fail "$f contains a build-machine path: $(head -n 3 "$work/paths.txt")"
    fi
  done
  # The installed tree, moved elsewhere, with the source and build trees hidden (a private mount
  # namespace with empty file systems over them) when this machine allows it.
  moved=$(mktemp -d "${TMPDIR:-/tmp}/navcore-moved.XXXXXX")
  trap 'rm -rf "$moved"' EXIT
  cp -a "$prefix" "$moved/usr"
  cat > "$moved/run.sh" <<RUN
set -eux
cd "$moved"
bin=$moved/usr/bin
\$bin/navsim check $moved/usr/share/navcore/scenes/*.yaml
\$bin/navsim catalog --imu > catalog.txt
grep -q "$moved/usr/share/navcore/resources/imu_catalog.csv" catalog.txt
\$bin/navsim run $moved/usr/share/navcore/scenes/$scene --out result --quiet
test -s result/summary.json
if ldd \$bin/navsim | grep -E 'libmicrohttpd|libmpi'; then echo "navsim links the server or MPI"; exit 1; fi
RUN
  case " $helpers " in
  *" navsim-serve "*) echo '$bin/navsim serve --help | grep -q "^usage: navsim serve "' >> "$moved/run.sh" ;;
  esac
  # navsim bench (libexec/navcore/navsim-bench) times the installed bin/navsim, not a build's.
  if [ -x "$prefix/libexec/navcore/navsim-bench" ]; then
    echo "\$bin/navsim bench --programs | grep -qx 'navsim: $moved/usr/bin/navsim'" >> "$moved/run.sh"
  fi
  cat >> "$moved/run.sh" <<RUN
echo "installed navsim (moved to $moved/usr): check, catalog, run and its helpers ($helpers ) passed"
RUN
  if unshare -m --propagation private true 2>/dev/null; then
    unshare -m --propagation private sh -c "mount -t tmpfs none '$build' && mount -t tmpfs none '$src' && sh '$moved/run.sh'" ||
      fail "the moved installed navsim failed with the source and build trees hidden"
    echo "(source tree $src and build tree $build were hidden)"
  else
    sh "$moved/run.sh" || fail "the moved installed navsim failed"
    echo "(no mount namespace here: the source and build trees stayed visible; the path scan above covers them)"
  fi
  ;;

cmake)
  [ -d "$prefix" ] || fail "no installed tree at $prefix (fixture install_setup)"
  rm -rf "$work/consumer-cmake"
  cmake -S "$src/tests/install/consumer" -B "$work/consumer-cmake" -DCMAKE_PREFIX_PATH="$prefix" \
    -DCMAKE_BUILD_TYPE=Release > "$work/consumer-cmake.log" 2>&1 || { cat "$work/consumer-cmake.log"; fail "configure with find_package(navcore)"; }
  cmake --build "$work/consumer-cmake" >> "$work/consumer-cmake.log" 2>&1 || { cat "$work/consumer-cmake.log"; fail "build against navcore::io"; }
  # Shared: the scene library is found relative to the loaded libnavcore_io.
  check_consumer_line "$(cd "$work" && "$work/consumer-cmake/consumer")"
  readelf -d "$work/consumer-cmake/consumer" | grep -q 'NEEDED.*libnavcore_io.so' || fail "consumer does not link libnavcore_io.so"
  # Static: nothing to find the installation from but the environment.
  check_consumer_line "$(cd "$work" && NAV_SHARE_DIR="$prefix/share/navcore" "$work/consumer-cmake/consumer_static")"
  if readelf -d "$work/consumer-cmake/consumer_static" | grep -q 'NEEDED.*libnavcore'; then
    fail "consumer_static links a shared navcore"
  fi
  ;;

pkgconfig)
  [ -d "$prefix" ] || fail "no installed tree at $prefix (fixture install_setup)"
  pcdir=$(dirname "$(find "$prefix" -name navcore.pc | head -n 1)")
  export PKG_CONFIG_PATH="$pcdir"
  [ "$(pkg-config --modversion navcore)" = "$version" ] || fail "pkg-config --modversion navcore"
  libdir=$(pkg-config --variable=libdir navcore)
  [ "$libdir" -ef "$pcdir/.." ] || fail "navcore.pc libdir $libdir is not the installed one"
  mkdir -p "$work/consumer-pc"
  # shellcheck disable=SC2046
  cc -std=c11 -o "$work/consumer-pc/consumer" "$src/tests/install/consumer/consumer.c" \
    $(pkg-config --cflags --libs navcore-io) -Wl,-rpath,"$libdir" || fail "cc with pkg-config navcore-io"
  check_consumer_line "$(cd "$work" && "$work/consumer-pc/consumer")"
  ;;

man)
  [ -d "$prefix" ] || fail "no installed tree at $prefix (fixture install_setup)"
  mandir=$prefix/share/man/man1
  # One page for navsim and one per command, nothing stale.
  cmds=$("$prefix/bin/navsim" --help | sed -n '/^commands:/,/^$/p' | sed -n 's/^  \([a-z][a-z0-9-]*\) .*/\1/p')
  [ -n "$cmds" ] || fail "no command list in navsim --help"
  expected="navsim.1.gz"
  for c in $cmds; do expected="$expected
navsim-$c.1.gz"; done
  printf '%s\n' "$expected" | sort > "$work/man.expected"
  (cd "$mandir" && ls navsim*.1.gz) | sort > "$work/man.installed"
  diff "$work/man.expected" "$work/man.installed" || fail "man pages differ from the commands of navsim --help"
  # Rendered text: synopsis and description, word by word, against --help.
  same() { # PAGE COMMAND...: the page's text from SYNOPSIS to SEE ALSO is the words of COMMAND --help
    page=$1
    shift
    "$@" --help 2>&1 | sed '1s/^usage://' | tr -s ' \t\n' '\n' | sed '/^$/d' > "$work/help.words"
    MANWIDTH=4000 man -E ascii -l "$mandir/$page.1.gz" 2>/dev/null | col -b |
      awk '/^SYNOPSIS/ { f = 1; next } /^SEE ALSO/ { f = 0 } /^[A-Z][A-Z ]*$/ { next } f' |
      tr -s ' \t\n' '\n' | sed '/^$/d' > "$work/man.words"
    [ -s "$work/man.words" ] || fail "$page.1.gz renders no text"
    diff "$work/help.words" "$work/man.words" > "$work/man.diff" ||
      fail "$page.1.gz disagrees with '$* --help': $(head -n 6 "$work/man.diff")"
  }
  same navsim "$prefix/bin/navsim"
  for c in $cmds; do
    same "navsim-$c" "$prefix/bin/navsim" "$c"
    MANWIDTH=4000 man -E ascii -l "$mandir/navsim.1.gz" | grep -q "^ *$c\\b" || fail "man navsim does not list $c"
  done
  if [ -x "$prefix/bin/navview" ]; then same navview "$prefix/bin/navview"; fi
  if [ -x "$prefix/bin/navstudio" ]; then
    # navstudio.1 is written: its SYNOPSIS is the usage line of navstudio --help.
    u=$(QT_QPA_PLATFORM=offscreen "$prefix/bin/navstudio" --help 2>/dev/null | sed -n '1s/^usage: //p' | tr -s ' ')
    m=$(MANWIDTH=4000 man -E ascii -l "$mandir/navstudio.1.gz" | col -b | awk '/^SYNOPSIS/ { f = 1; next } /^[A-Z]/ { f = 0 } f' | tr -s ' \n' ' ' | sed 's/^ //; s/ $//')
    [ -n "$u" ] && [ "$u" = "$m" ] || fail "navstudio.1 SYNOPSIS '$m' is not navstudio --help's usage '$u'"
  fi
  # bash completion offers every command.
  got=$(PATH="$prefix/bin:$PATH" bash -c ". '$prefix/share/bash-completion/completions/navsim'; COMP_WORDS=(navsim ''); COMP_CWORD=1; _navsim; echo \${COMPREPLY[*]}")
  for c in $cmds; do echo " $got " | grep -q " $c " || fail "bash completion does not offer $c (got: $got)"; done
  echo "man pages and completion agree with --help for: navsim" $cmds
  ;;

deb)
  rm -rf "$work"
  mkdir -p "$work/root"
  (cd "$build" && cpack -G DEB -B "$work/deb" > "$work/cpack.log" 2>&1) || { cat "$work/cpack.log"; fail "cpack -G DEB"; }
  ls "$work"/deb/*.deb > "$work/debs.txt" || fail "cpack made no .deb"
  for d in $(cat "$work/debs.txt"); do
    echo "$(basename "$d"): Depends: $(dpkg-deb -f "$d" Depends)"
    dpkg -x "$d" "$work/root"
  done
  [ -n "$(dpkg-deb -f "$(grep '/navsim_' "$work/debs.txt")" Depends)" ] || fail "the navsim package has no Depends (dpkg-shlibdeps)"
  root=$work/root
  (cd "$work" && "$root/usr/bin/navsim" check "$root"/usr/share/navcore/scenes/*.yaml) || fail "navsim check of the packaged scenes"
  (cd "$work" && "$root/usr/bin/navsim" run "$root/usr/share/navcore/scenes/$scene" --out "$work/result" --quiet) || fail "navsim run from the package"
  [ -s "$work/result/summary.json" ] || fail "no summary.json from the packaged navsim"
  command -v lintian >/dev/null 2>&1 || fail "lintian is not installed (Debian: lintian)"
  # lintian exits non-zero on an error tag (its default --fail-on error) or when it cannot run.
  lrc=0
  # shellcheck disable=SC2046
  lintian --tag-display-limit 0 $(cat "$work/debs.txt") > "$work/lintian.txt" 2>&1 || lrc=$?
  cat "$work/lintian.txt"
  if grep -q '^E: ' "$work/lintian.txt" || [ "$lrc" -ne 0 ]; then fail "lintian reports errors (exit $lrc)"; fi
  echo "packages extracted, navsim check + run passed, lintian: no errors"
  ;;
*)
  fail "unknown mode $mode"
  ;;
esac
