# Installed share data, bash completion, per-package documentation and the Debian packages
# (issue 24). Included from the top-level CMakeLists.txt; each folder installs its own targets.
#
#   cmake --install build --prefix P     P/bin, P/lib, P/include/navcore, P/share/navcore, man, ...
#   cd build && cpack -G DEB             libnavcore0, libnavcore-dev, navsim, navstudio (.deb)
include(GNUInstallDirs)
if(NOT NAV_INSTALLABLE)
  return()
endif()

# The share directory (nav_paths.h): <prefix>/share/navcore/{resources,scenes}. scenes/ refers to
# ../resources/motion_defs and ../tests/data/recorded (relative to the scene file), so those keep
# their place relative to scenes/.
set(NAV_SHARE_DEST ${CMAKE_INSTALL_DATADIR}/navcore)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/resources/ DESTINATION ${NAV_SHARE_DEST}/resources COMPONENT tools)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/scenes/ DESTINATION ${NAV_SHARE_DEST}/scenes COMPONENT tools
  FILES_MATCHING PATTERN "*.yaml")
install(FILES ${PROJECT_SOURCE_DIR}/tests/data/recorded/adis16465-truth-116454-116754.nav
              ${PROJECT_SOURCE_DIR}/tests/data/recorded/adis16465-gnss-posvel.txt
              ${PROJECT_SOURCE_DIR}/tests/data/recorded/README.md
  DESTINATION ${NAV_SHARE_DEST}/tests/data/recorded COMPONENT tools)
install(FILES ${PROJECT_SOURCE_DIR}/packaging/navsim.bash-completion
  DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions RENAME navsim COMPONENT tools)

# Debian package names of the install components.
set(NAV_DEB_lib libnavcore${PROJECT_VERSION_MAJOR})
set(NAV_DEB_dev libnavcore-dev)
set(NAV_DEB_tools navsim)
set(NAV_DEB_gui navstudio)
set(NAV_COMPONENTS lib dev tools)
if(NAV_BUILD_VIEWER OR NAV_BUILD_EDITOR)
  list(APPEND NAV_COMPONENTS gui)
endif()
set(NAV_MAINTAINER "navcore maintainers <maintainers@users.noreply.h-seed-7dd0b7eb.example>")

# /usr/share/doc/<package>/{copyright,changelog.gz} in every package (Debian policy 12.5, 12.7).
string(TIMESTAMP NAV_CHANGELOG_DATE "%a, %d %b %Y 00:00:00 +0000" UTC)
foreach(_c ${NAV_COMPONENTS})
  set(_pkg ${NAV_DEB_${_c}})
  set(_dir ${PROJECT_BINARY_DIR}/packaging/doc/${_pkg})
  file(MAKE_DIRECTORY ${_dir})
  file(WRITE ${_dir}/changelog
    "${_pkg} (${PROJECT_VERSION}) unstable; urgency=medium\n\n"
    "  * Release ${PROJECT_VERSION}, packaged with cpack (issue 24).\n\n"
    " -- ${NAV_MAINTAINER}  ${NAV_CHANGELOG_DATE}\n")
  add_custom_command(OUTPUT ${_dir}/changelog.gz
    COMMAND gzip -9nc ${_dir}/changelog > ${_dir}/changelog.gz
    DEPENDS ${_dir}/changelog)
  list(APPEND _nav_changelogs ${_dir}/changelog.gz)
  install(FILES ${_dir}/changelog.gz ${PROJECT_SOURCE_DIR}/packaging/copyright
    DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/${_pkg} COMPONENT ${_c})
endforeach()
add_custom_target(nav_package_docs ALL DEPENDS ${_nav_changelogs})

# CPack: one Debian package per component, Depends from dpkg-shlibdeps.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME navcore)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_CONTACT "${NAV_MAINTAINER}")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES ON)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_ALL ${NAV_COMPONENTS})
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_ENABLE_COMPONENT_DEPENDS ON)
set(CPACK_COMPONENT_DEV_DEPENDS lib)
foreach(_c ${NAV_COMPONENTS})
  string(TOUPPER ${_c} _C)
  set(CPACK_DEBIAN_${_C}_PACKAGE_NAME ${NAV_DEB_${_c}})
endforeach()
set(CPACK_DEBIAN_LIB_PACKAGE_SECTION libs)
set(CPACK_DEBIAN_DEV_PACKAGE_SECTION libdevel)
set(CPACK_DEBIAN_TOOLS_PACKAGE_SECTION science)
set(CPACK_DEBIAN_GUI_PACKAGE_SECTION science)
# The static libnavcore_io.a and navcore-io.pc need libfyaml and expat's development files.
set(CPACK_DEBIAN_DEV_PACKAGE_DEPENDS "libfyaml-dev, libexpat1-dev")
# navsim render/report run navview (GUI package) under xvfb-run when there is no display.
set(CPACK_DEBIAN_TOOLS_PACKAGE_SUGGESTS "${NAV_DEB_gui}, xvfb, xauth")
set(CPACK_DEBIAN_GUI_PACKAGE_DEPENDS "fonts-dejavu-core")
set(CPACK_DEBIAN_GUI_PACKAGE_RECOMMENDS "${NAV_DEB_tools}")
# CPack prepends CPACK_PACKAGE_DESCRIPTION_SUMMARY to each package's description unless it is
# CPack's default; each package has its own synopsis line below, so the default is kept.
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "${CMAKE_PROJECT_NAME} built using CMake")
# Description: a synopsis line, then the extended description (lines under 80 columns).
set(CPACK_DEBIAN_LIB_DESCRIPTION "navcore shared libraries: navigation simulation and scene I/O
libnavcore is a pure C11 library simulating strapdown inertial and INS/GNSS
navigation (trajectories, IMU and GNSS error models, Kalman filter, error
statistics); libnavcore_io reads and writes its scene files, results and
catalogs.")
set(CPACK_DEBIAN_DEV_DESCRIPTION "navcore development files: headers, static libraries, CMake and pkg-config
Public headers under /usr/include/navcore, libnavcore.a and libnavcore_io.a,
the CMake package (find_package(navcore): navcore::navcore, navcore::io) and
the pkg-config files navcore and navcore-io.")
set(CPACK_DEBIAN_TOOLS_DESCRIPTION "command-line simulator of inertial and integrated navigation systems
navsim validates scene files, simulates them (single runs and Monte Carlo),
estimates and budgets errors, replays recorded IMU/GNSS data, selects sensors
against requirements and sweeps scene parameters. Includes the scene library,
the IMU and GNSS receiver catalogs, manual pages and bash completion.")
set(CPACK_DEBIAN_GUI_DESCRIPTION "viewer and scenario editor for navsim
navview shows navsim results in 3D, on a map and as error charts (VTK);
navstudio edits scenes and previews their simulation (Qt 5 and VTK).")
# The library package: a shlibs file for dpkg-shlibdeps of packages linking it, and the ldconfig
# trigger (Debian policy 8.1.1) instead of maintainer scripts calling ldconfig.
set(_nav_ctl ${PROJECT_BINARY_DIR}/packaging/control/lib)
file(MAKE_DIRECTORY ${_nav_ctl})
file(WRITE ${_nav_ctl}/shlibs
  "libnavcore ${PROJECT_VERSION_MAJOR} ${NAV_DEB_lib} (>= ${PROJECT_VERSION})\n"
  "libnavcore_io ${PROJECT_VERSION_MAJOR} ${NAV_DEB_lib} (>= ${PROJECT_VERSION})\n")
file(WRITE ${_nav_ctl}/triggers "activate-noawait ldconfig\n")
set(CPACK_DEBIAN_LIB_PACKAGE_CONTROL_EXTRA "${_nav_ctl}/shlibs;${_nav_ctl}/triggers")
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
include(CPack)
