# fluid_linsolve: unit test, and the PPE solver micro-benchmark (not a test:
# run by hand, see docs/ppe_solvers.md).
mps_add_test(test_linsolve SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_linsolve.c
  LIBS fluidcore LABELS unit TIMEOUT 60)
# Part of the test runs 2 OpenMP threads; with spinning barriers on a busy
# machine that can be 20-100x slower (docs/ppe_solvers.md), passive waiting not.
set_tests_properties(test_linsolve PROPERTIES ENVIRONMENT "OMP_WAIT_POLICY=passive")

add_executable(linsolve_bench ${CMAKE_SOURCE_DIR}/bench/linsolve_bench.c)
target_link_libraries(linsolve_bench PRIVATE fluidcore m)
set_target_properties(linsolve_bench PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bench)
