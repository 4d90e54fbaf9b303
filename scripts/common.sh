# Shared set-up for scripts/run and scripts/test: the one list of Debian packages, their
# installation (only what is missing), and the incremental build. Sourced, not executed.

# The single list of Debian 12 packages the project needs (toolchain.md section 1).
# xauth is only a Recommends of xvfb but xvfb-run needs it, so it is named explicitly.
NAV_PACKAGES=(
  build-essential cmake ninja-build pkg-config
  libcmocka-dev libfyaml-dev libgeographiclib-dev
  libmicrohttpd-dev libzip-dev python3 # navsim serve (web/server) and its tests (Python standard library)
  libexpat1-dev libxml2-utils       # GPX/KML import (expat); xmllint checks exported KML in tests
  libvtk9-dev fonts-dejavu-core
  xvfb xauth
  libvtk9-qt-dev qtbase5-dev        # navstudio (Qt5 + QVTKOpenGLNativeWidget; toolchain.md section 4)
  libopenmpi-dev openmpi-bin        # MPI Monte Carlo campaigns (issue 9)
  clang libfuzzer-14-dev            # libFuzzer targets (tests/fuzz)
  chromium                          # navsim report check (headless screenshot)
  python-cartopy-data gmt-gshhg-low # offline map background (coastlines, borders)
  help2man man-db bsdextrautils     # man pages from --help; tests render them (man, col)
  dpkg-dev file lintian             # cpack -G DEB (dpkg-shlibdeps, file) and its lintian test
  rtklib                            # rnx2rtkp: independent oracle of GNSS satellite positions and of the RINEX export (issue 22)
  python3-yaml python3-jsonschema   # scenes against `navsim schema` (issue 18, test_navsim_schema)
  libnetcdf-dev gmt-gshhg-high gmt-gshhg-full # map land/water, rivers, borders (GSHHG binned netCDF)
  libsqlite3-dev libcurl4-openssl-dev # map tile layer: MBTiles files (SQLite), XYZ URL tiles (libcurl)
  ffmpeg                            # movies of the 3D playback: H.264 (libx264) / VP9 (libvpx) encoder, ffprobe in tests
  python3-numpy                     # gnss-ins-sim as the bench's truth-generation peer (navsim bench --peer-gnss-ins-sim)
  strace                            # test_navsim_replay_io: the replay's writes and fsyncs seen from the system calls
)

NAV_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
NAV_BUILD="${NAV_BUILD_DIR:-$NAV_ROOT/build}"

nav_log() { printf '[navsim setup] %s\n' "$*" >&2; }

nav_ensure_packages() {
  local missing=() p
  for p in "${NAV_PACKAGES[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
      missing+=("$p")
    fi
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  local sudo=()
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null 2>&1 || { nav_log "need root or sudo to install: ${missing[*]}"; return 1; }
    sudo=(sudo)
  fi
  nav_log "installing missing Debian packages: ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  "${sudo[@]}" apt-get update -q >/dev/null
  "${sudo[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}" >/dev/null
}

# The browser studio (web/studio, built when node and npm are found) needs node >= 18 and npm:
# its packages come from the committed package-lock.json through `npm ci` at build time. A
# machine that has neither gets Debian's (node 18); one that has a newer node keeps it.
nav_ensure_node() {
  if command -v node >/dev/null 2>&1 && command -v npm >/dev/null 2>&1 &&
     [ "$(node -p 'process.versions.node.split(".")[0]' 2>/dev/null || echo 0)" -ge 18 ]; then
    return 0
  fi
  local sudo=()
  [ "$(id -u)" -ne 0 ] && sudo=(sudo)
  nav_log "installing node and npm (browser studio, map place names)"
  DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -q --no-install-recommends nodejs npm >/dev/null ||
    nav_log "node/npm not installed: the browser studio (NAV_BUILD_WEB) is left out"
}

# navstudio (editor/) is built when Qt5 and VTK's Qt support are installed, in the plain build
# only: not in the sanitizer builds (Qt and Mesa are outside our code) nor without the viewer.
nav_editor_args() {
  case " $* " in *NAV_SANITIZE=ON*|*NAV_TSAN=ON*|*NAV_BUILD_VIEWER=OFF*) return 0 ;; esac
  if compgen -G "/usr/lib/*/cmake/Qt5/Qt5Config.cmake" >/dev/null && [ -f /usr/include/vtk-9.1/QVTKOpenGLNativeWidget.h ]; then
    echo "-DNAV_BUILD_EDITOR=ON"
  fi
}

# Configure once, then build incrementally. Extra cmake arguments may be passed.
nav_build() {
  local editor
  editor="$(nav_editor_args "$@")"
  if [ ! -f "$NAV_BUILD/build.ninja" ]; then
    nav_log "configuring $NAV_BUILD"
    cmake -S "$NAV_ROOT" -B "$NAV_BUILD" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DNAV_WERROR=ON \
      -DNAV_BUILD_VIEWER=ON $editor "$@" >/dev/null
  elif [ -n "$editor" ] && ! grep -q '^NAV_BUILD_EDITOR:BOOL=ON' "$NAV_BUILD/CMakeCache.txt" 2>/dev/null; then
    nav_log "enabling navstudio in $NAV_BUILD"
    cmake "$NAV_BUILD" $editor >/dev/null
  fi
  cmake --build "$NAV_BUILD" -- -j"$(nproc)" >&2
}
