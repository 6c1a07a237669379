# Output and command-line helpers (mps_h5, mps_probes, mps_json, mps_cli,
# mps_timer, mps_progress) and the neighbour search / kernel constants.
mps_add_test(test_h5 SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_h5.c LABELS unit TIMEOUT 30)
# The test reads the snapshots back through the HDF5 C API.
target_include_directories(test_h5 PRIVATE ${HDF5_INCLUDE_DIRS})
target_compile_definitions(test_h5 PRIVATE ${HDF5_DEFINITIONS})
target_link_libraries(test_h5 PRIVATE ${HDF5_C_LIBRARIES})

mps_add_test(test_probes_json_cli SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_probes_json_cli.c
  LABELS unit TIMEOUT 30)
mps_add_test(test_nbr SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_nbr.c LABELS unit TIMEOUT 30)
# its AVX-512 comparisons alone: SKIPPED where the CPU has no AVX-512
add_test(NAME test_nbr_avx512 COMMAND test_nbr avx512 WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(test_nbr_avx512 PROPERTIES TIMEOUT 30 LABELS unit SKIP_RETURN_CODE 77)

# --version of every program names the tree's current git revision.
add_test(NAME version_git_rev
  COMMAND ${CMAKE_COMMAND} -DSRC=${CMAKE_SOURCE_DIR} -DBIN=$<TARGET_FILE_DIR:fluid_solver>
          -P ${CMAKE_CURRENT_LIST_DIR}/scripts/check_version.cmake)
set_tests_properties(version_git_rev PROPERTIES LABELS unit TIMEOUT 30)
