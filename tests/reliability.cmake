# Reliability tests (issue 10): fuzz-input replay, hostile inputs, kill during write,
# cancellation storm, determinism, numerical guards. Included from tests/CMakeLists.txt.

# Every seed and regression input of the fuzz targets, replayed through the target code in
# the normal build (and, under NAV_SANITIZE, with ASan + UBSan) without libFuzzer.
set(NAV_FUZZ_DIR ${PROJECT_SOURCE_DIR}/tests/fuzz)
set(NAV_FUZZ_INPUTS_fuzz_scene ${PROJECT_SOURCE_DIR}/scenes ${NAV_TEST_DATA_DIR}/scenes ${NAV_TEST_DATA_DIR}/hostile)
set(NAV_FUZZ_INPUTS_fuzz_check ${NAV_FUZZ_INPUTS_fuzz_scene})
set(NAV_FUZZ_INPUTS_fuzz_recorded ${NAV_TEST_DATA_DIR}/replay ${NAV_TEST_DATA_DIR}/recorded
    ${NAV_TEST_DATA_DIR}/hostile/recorded)
set(NAV_FUZZ_INPUTS_fuzz_motiondef ${PROJECT_SOURCE_DIR}/resources/motion_defs)
set(NAV_FUZZ_INPUTS_fuzz_track_import ${NAV_TEST_DATA_DIR}/tracks ${NAV_TEST_DATA_DIR}/hostile/tracks)
set(NAV_FUZZ_INPUTS_fuzz_rinex ${NAV_TEST_DATA_DIR}/rinex)
set(NAV_FUZZ_TARGETS fuzz_scene fuzz_check fuzz_recorded fuzz_motiondef fuzz_rinex)
if(EXISTS ${PROJECT_SOURCE_DIR}/navcore/io/track_import.c)
  list(APPEND NAV_FUZZ_TARGETS fuzz_track_import)
endif()
foreach(t ${NAV_FUZZ_TARGETS})
  add_executable(${t}_replay ${NAV_FUZZ_DIR}/${t}.c ${NAV_FUZZ_DIR}/replay_main.c)
  target_link_libraries(${t}_replay PRIVATE navcore_io navcore)
  target_compile_options(${t}_replay PRIVATE -ffp-contract=off)
  nav_warnings(${t}_replay)
  set(inputs ${NAV_FUZZ_INPUTS_${t}})
  if(EXISTS ${NAV_FUZZ_DIR}/corpus/${t})
    list(APPEND inputs ${NAV_FUZZ_DIR}/corpus/${t})
  endif()
  add_test(NAME ${t}_replay COMMAND ${t}_replay ${inputs})
  # Relative file references of the scene seeds resolve as in tests/data/scenes.
  set_tests_properties(${t}_replay PROPERTIES LABELS "unit;fuzz" TIMEOUT 600
                       WORKING_DIRECTORY ${NAV_TEST_DATA_DIR}/scenes)
endforeach()

# Hostile inputs through the navsim executable (tests/data/hostile/expected.tsv).
nav_add_cmocka_test(test_navsim_hostile SOURCES scenario/test_navsim_hostile.c LABELS scenario)
target_compile_definitions(test_navsim_hostile PRIVATE
  NAVSIM_EXE="$<TARGET_FILE:navsim>" NAV_TEST_WORK_DIR="${CMAKE_CURRENT_BINARY_DIR}/navsim_hostile")
add_dependencies(test_navsim_hostile navsim)

# Bounded work (issue 25): readers refuse FIFOs, devices and directories at once; navview never
# aborts on a bad or huge result; output size and memory predicted and capped before a run.
nav_add_cmocka_test(test_navsim_bounded SOURCES scenario/test_navsim_bounded.c LABELS scenario)
target_compile_definitions(test_navsim_bounded PRIVATE
  NAVSIM_EXE="$<TARGET_FILE:navsim>" NAV_TEST_WORK_DIR="${CMAKE_CURRENT_BINARY_DIR}/navsim_bounded")
add_dependencies(test_navsim_bounded navsim)
if(TARGET navview_app AND NOT NAV_SANITIZE)
  target_compile_definitions(test_navsim_bounded PRIVATE NAVVIEW_EXE="$<TARGET_FILE:navview_app>")
  add_dependencies(test_navsim_bounded navview_app)
  set_tests_properties(test_navsim_bounded PROPERTIES RESOURCE_LOCK xvfb)
endif()

# Numerical guards of the filter in hard cases (P symmetric positive definite, or NAV_ERR_NUMERIC).
nav_add_cmocka_test(test_filter_hard SOURCES unit/test_filter_hard.c LIBS navcore_io LABELS unit scenario)

# Cancellation storm: 1000 start/cancel cycles of Monte Carlo runs at random moments.
nav_add_cmocka_test(test_cancel_storm SOURCES unit/test_cancel_storm.c LIBS navcore_io LABELS unit scenario)
find_package(Threads REQUIRED)
target_link_libraries(test_cancel_storm PRIVATE Threads::Threads)

# No lost data and determinism: SIGKILL / SIGINT during navsim run and during scene saves;
# byte-identical results for repeated runs and thread counts 1, 2, 8.
add_executable(scene_save_loop scenario/scene_save_loop.c)
target_link_libraries(scene_save_loop PRIVATE navcore_io navcore)
nav_warnings(scene_save_loop)
nav_add_cmocka_test(test_navsim_durability SOURCES scenario/test_navsim_durability.c LIBS navcore_io LABELS scenario)
target_compile_definitions(test_navsim_durability PRIVATE
  NAVSIM_EXE="$<TARGET_FILE:navsim>" SCENE_SAVE_EXE="$<TARGET_FILE:scene_save_loop>"
  NAV_TEST_WORK_DIR="${CMAKE_CURRENT_BINARY_DIR}/navsim_durability")
add_dependencies(test_navsim_durability navsim scene_save_loop)

# Issue 25, errors where the input is: sweep grid values named by their --param and checked
# before any point is computed, import validated before it writes, replay values that would make
# the filter non-finite at FILE:LINE:COL.
nav_add_cmocka_test(test_navsim_input_errors SOURCES scenario/test_navsim_input_errors.c LABELS scenario)
target_compile_definitions(test_navsim_input_errors PRIVATE
  NAVSIM_EXE="$<TARGET_FILE:navsim>" NAV_TEST_WORK_DIR="${CMAKE_CURRENT_BINARY_DIR}/navsim_input_errors")
add_dependencies(test_navsim_input_errors navsim)
