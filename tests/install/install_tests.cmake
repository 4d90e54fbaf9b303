# Install, package and man-page tests (issue 24): tests/install/install_test.sh. The plain build
# only (NAV_INSTALLABLE): one installed tree made by the fixture install_setup serves the tree,
# consumer and man tests; the Debian package test makes its own with cpack.
if(NAV_INSTALLABLE)
  set(_nav_inst ${CMAKE_CURRENT_SOURCE_DIR}/install/install_test.sh)
  set(_nav_work ${PROJECT_BINARY_DIR}/install-test)
  add_test(NAME install_setup COMMAND sh ${_nav_inst} setup ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR} ${_nav_work} ${PROJECT_VERSION})
  set_tests_properties(install_setup PROPERTIES FIXTURES_SETUP nav_install LABELS install TIMEOUT 300)
  foreach(_m tree cmake pkgconfig man)
    add_test(NAME install_${_m} COMMAND sh ${_nav_inst} ${_m} ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR} ${_nav_work} ${PROJECT_VERSION})
    set_tests_properties(install_${_m} PROPERTIES FIXTURES_REQUIRED nav_install LABELS install TIMEOUT 300)
  endforeach()
  add_test(NAME install_deb COMMAND sh ${_nav_inst} deb ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR} ${PROJECT_BINARY_DIR}/install-test-deb ${PROJECT_VERSION})
  set_tests_properties(install_deb PROPERTIES LABELS install TIMEOUT 600)
  # cpack runs the build tree's install scripts again: not at the same time as install_setup.
  set_tests_properties(install_deb PROPERTIES RESOURCE_LOCK nav_install_tree)
  set_tests_properties(install_setup PROPERTIES RESOURCE_LOCK nav_install_tree)
endif()
