# Installed share data and bash completion (issue 24). Included from the top-level
# CMakeLists.txt; each folder installs its own targets.
#
#   cmake --install build --prefix P     P/bin, P/lib, P/include/navcore, P/share/navcore, man, ...
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
              ${PROJECT_SOURCE_DIR}/tests/data/recorded/README.md
  DESTINATION ${NAV_SHARE_DEST}/tests/data/recorded COMPONENT tools)
install(FILES ${PROJECT_SOURCE_DIR}/packaging/navsim.bash-completion
  DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions RENAME navsim COMPONENT tools)
