# Implicit coupling (issue 18): the solvers' rollback, the acceleration
# schemes, and short runs of the hard cases (docs/hard_cases.md).

# The fluid repeats a step bit for bit from its checkpoint (two threads: the
# OpenMP reductions must not make a repeat differ).
add_test(NAME fluid_rollback
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/fluid_rollback.py ${CMAKE_BINARY_DIR}/bin
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(fluid_rollback PROPERTIES TIMEOUT 120 LABELS integration
                     ENVIRONMENT "OMP_NUM_THREADS=2;OMP_WAIT_POLICY=passive")

# Aitken and IQN-ILS on a linear model problem with a known fixed point.
mps_add_test(test_coupling_accel SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_coupling_accel.c
             LIBS couplercore LABELS unit TIMEOUT 30)
target_include_directories(test_coupling_accel PRIVATE ${CMAKE_SOURCE_DIR}/tests)

# The static deflection of a body under a hydrostatic load, any solid model
# (bench/solid_static_load.c; docs/hard_cases.md, the gate against
# Timoshenko beam theory). A bench program, not a test.
add_executable(solid_static_load ${CMAKE_SOURCE_DIR}/bench/solid_static_load.c)
target_link_libraries(solid_static_load PRIVATE solidcore m)
set_target_properties(solid_static_load PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bench)
