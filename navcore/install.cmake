# Installation of navcore (issue 24): the libraries (static, and shared with a SONAME following
# the version), the public headers under include/navcore, navsim, the CMake package
# (find_package(navcore): navcore::navcore, navcore::io, navcore::navcore_static,
# navcore::io_static) and the pkg-config files navcore.pc and navcore-io.pc.
# Included from navcore/CMakeLists.txt; the share data is installed by the top-level file.
if(NOT NAV_INSTALLABLE)
  return()
endif()
include(CMakePackageConfigHelpers)

# The shared libraries are linked from the objects of the static ones (compiled once, PIC, with
# hidden visibility: only the NAV_API functions of the public headers are exported).
add_library(navcore_shared SHARED $<TARGET_OBJECTS:navcore>)
target_include_directories(navcore_shared PUBLIC
  $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
  $<BUILD_INTERFACE:${CMAKE_CURRENT_BINARY_DIR}/include>
  $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
target_link_libraries(navcore_shared PRIVATE $<BUILD_INTERFACE:${NAV_LIBM}>)
add_library(navcore_io_shared SHARED $<TARGET_OBJECTS:navcore_io>)
target_link_libraries(navcore_io_shared PUBLIC navcore_shared
  PRIVATE PkgConfig::FYAML PkgConfig::EXPAT ${CMAKE_DL_LIBS} $<BUILD_INTERFACE:${NAV_LIBM}>)
set_target_properties(navcore_shared PROPERTIES OUTPUT_NAME navcore EXPORT_NAME navcore
  VERSION ${PROJECT_VERSION} SOVERSION ${PROJECT_VERSION_MAJOR})
set_target_properties(navcore_io_shared PROPERTIES OUTPUT_NAME navcore_io EXPORT_NAME io
  VERSION ${PROJECT_VERSION} SOVERSION ${PROJECT_VERSION_MAJOR})
# Build RUNPATH as installed (none): see navsim in navcore/CMakeLists.txt. Nothing in the build tree
# loads these two; they are used once installed (tests/install).
set_target_properties(navcore_shared navcore_io_shared PROPERTIES BUILD_WITH_INSTALL_RPATH ON)
set_target_properties(navcore PROPERTIES EXPORT_NAME navcore_static)
set_target_properties(navcore_io PROPERTIES EXPORT_NAME io_static)
# A symbol the shared libraries use but do not find (e.g. a hidden one) fails the link here, not
# in a user's program.
target_link_options(navcore_shared PRIVATE -Wl,--no-undefined)
target_link_options(navcore_io_shared PRIVATE -Wl,--no-undefined)
# With NAV_LTO the objects are fat LTO objects (navcore/CMakeLists.txt): the shared libraries link
# their machine code, without LTO code generation.
if(NAV_LTO_ACTIVE)
  target_link_options(navcore_shared PRIVATE $<${_nav_lto_configs}:-fno-lto>)
  target_link_options(navcore_io_shared PRIVATE $<${_nav_lto_configs}:-fno-lto>)
endif()

install(TARGETS navcore_shared navcore_io_shared EXPORT navcoreTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT lib NAMELINK_COMPONENT dev)
install(TARGETS navcore navcore_io EXPORT navcoreTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev)
# Public headers only: navcore/include/navcore/*.h (private ones are *_internal.h under src/).
install(DIRECTORY include/navcore DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT dev
  FILES_MATCHING PATTERN "*.h")
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/include/navcore/nav_version.h
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/navcore COMPONENT dev)

set(NAV_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/navcore)
install(EXPORT navcoreTargets NAMESPACE navcore:: DESTINATION ${NAV_CMAKE_DIR} COMPONENT dev)
configure_package_config_file(install/navcoreConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/navcoreConfig.cmake INSTALL_DESTINATION ${NAV_CMAKE_DIR}
  PATH_VARS CMAKE_INSTALL_INCLUDEDIR)
# 0.x: a new minor version may change the API, so only the same major.minor is compatible.
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/navcoreConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/navcoreConfig.cmake
              ${CMAKE_CURRENT_BINARY_DIR}/navcoreConfigVersion.cmake
  DESTINATION ${NAV_CMAKE_DIR} COMPONENT dev)

# pkg-config: the prefix is the one actually installed to (cmake --install --prefix P, or /usr
# in the Debian packages), so the files are written at install time.
foreach(_pc navcore navcore-io)
  install(CODE "
    set(NAV_PC_PREFIX \"\${CMAKE_INSTALL_PREFIX}\")
    set(NAV_PC_LIBDIR \"${CMAKE_INSTALL_LIBDIR}\")
    set(NAV_PC_INCLUDEDIR \"${CMAKE_INSTALL_INCLUDEDIR}\")
    set(NAV_PC_VERSION \"${PROJECT_VERSION}\")
    set(NAV_PC_DESCRIPTION \"${PROJECT_DESCRIPTION}\")
    configure_file(\"${CMAKE_CURRENT_SOURCE_DIR}/install/${_pc}.pc.in\"
      \"\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_LIBDIR}/pkgconfig/${_pc}.pc\" @ONLY)
    list(APPEND CMAKE_INSTALL_MANIFEST_FILES
      \"\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_LIBDIR}/pkgconfig/${_pc}.pc\")
    " COMPONENT dev)
endforeach()

install(TARGETS navsim RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT tools)
# navsim's helper programs (navsim/exec_helper.h), found by navsim in ../libexec/navcore.
foreach(_helper navsim_serve navsim_mpi)
  if(TARGET ${_helper})
    install(TARGETS ${_helper} RUNTIME DESTINATION ${CMAKE_INSTALL_LIBEXECDIR}/navcore COMPONENT tools)
  endif()
endforeach()

# Man pages navsim.1 and navsim-COMMAND.1, generated with help2man from `navsim [COMMAND] --help`
# each time navsim is linked (the test install_man checks that they agree with --help).
find_program(NAV_HELP2MAN help2man)
if(NAV_HELP2MAN)
  add_custom_command(OUTPUT ${CMAKE_CURRENT_BINARY_DIR}/man/navsim.1.gz
    COMMAND sh ${PROJECT_SOURCE_DIR}/packaging/help2man-pages.sh $<TARGET_FILE:navsim>
            ${CMAKE_CURRENT_BINARY_DIR}/man ${PROJECT_VERSION}
            "simulate inertial and integrated navigation systems from scene files" navview navstudio
    DEPENDS navsim ${PROJECT_SOURCE_DIR}/packaging/help2man-pages.sh
    COMMENT "Generating the navsim man pages (help2man)" VERBATIM)
  add_custom_target(navsim_man ALL DEPENDS ${CMAKE_CURRENT_BINARY_DIR}/man/navsim.1.gz)
  install(DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}/man/ DESTINATION ${CMAKE_INSTALL_MANDIR}/man1
    COMPONENT tools FILES_MATCHING PATTERN "navsim*.1.gz" PATTERN wrap EXCLUDE)
else()
  message(WARNING "help2man not found (Debian: help2man): the navsim man pages are not built")
endif()
