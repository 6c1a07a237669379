# Implicit coupling (issue 18): the solvers' rollback, the acceleration
# schemes, and short runs of the hard cases (docs/hard_cases.md).

# The fluid repeats a step bit for bit from its checkpoint (two threads: the
# OpenMP reductions must not make a repeat differ).
add_test(NAME fluid_rollback
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/fluid_rollback.py ${CMAKE_BINARY_DIR}/bin
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(fluid_rollback PROPERTIES TIMEOUT 120 LABELS integration
                     ENVIRONMENT "OMP_NUM_THREADS=2;OMP_WAIT_POLICY=passive")

# Aitken and IQN-ILS on a linear model problem with a known fixed point; the
# interface vector (what the fluid is sent, convergence, best iterate).
foreach(t accel iter)
  mps_add_test(test_coupling_${t} SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_coupling_${t}.c
               LIBS couplercore LABELS unit TIMEOUT 30)
  target_include_directories(test_coupling_${t} PRIVATE ${CMAKE_SOURCE_DIR}/tests)
endforeach()

# The static deflection of a body under a hydrostatic load, any solid model
# (bench/solid_static_load.c; docs/hard_cases.md, the gate against
# Timoshenko beam theory). A bench program, not a test.
add_executable(solid_static_load ${CMAKE_SOURCE_DIR}/bench/solid_static_load.c)
target_link_libraries(solid_static_load PRIVATE solidcore m)
set_target_properties(solid_static_load PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bench)

# The light plate (cases/hard_light_plate) at 6 mm with rho_s = 10 kg/m3 (a
# hundredth of the water's), where the explicit scheme diverges at 0.28 s (the
# fluid's step collapses below dt_min as the plate, beyond its height, whips
# the water: docs/hard_cases.md; at rho_s = 25 it still reached 0.45 s, and
# at 50, which diverged at 0.34 s before the fluid's kappa_dt, too). The
# implicit run must reach 0.45 s (the first impact and its rebound) with the
# tip within the plate's height (8.4 cm; measured 3.5 cm) at no more than 10
# iterations per step on average (the issue's target; measured 7.3, 19 steps
# accepted at the limit of 20); the explicit run of the same case must not,
# which shows the check can fail.
set(LIGHT "${CMAKE_BINARY_DIR}/bin/coupler cases/hard_light_plate/case.yml --quiet --set dp=0.006 --set end_time=0.45 --set solid.bodies.0.rho=10 --set output.interval=0")
add_test(NAME coupled_light_plate_implicit
         COMMAND sh -c "${LIGHT} --out ${CMAKE_BINARY_DIR}/test_out/light_implicit; /usr/bin/python3 tests/coupler/hard_check.py ${CMAKE_BINARY_DIR}/test_out/light_implicit --end 0.45 --tip-bound 0.084 --max-iterations-mean 10"
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
add_test(NAME coupled_light_plate_explicit_unstable
         COMMAND sh -c "${LIGHT} --set coupling.scheme=explicit --out ${CMAKE_BINARY_DIR}/test_out/light_explicit; /usr/bin/python3 tests/coupler/hard_check.py ${CMAKE_BINARY_DIR}/test_out/light_explicit --end 0.45 --tip-bound 0.084 --expect-unstable"
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(coupled_light_plate_implicit coupled_light_plate_explicit_unstable
                     PROPERTIES TIMEOUT 300 LABELS validation)

# The plate at rest (cases/hard_plate_at_rest) at 6 mm, both schemes, to 2 s.
# At this spacing the plate is 2 particles thick: alone under the net
# hydrostatic load it bends 8.53 mm (bench/solid_static_load.c; beam theory
# 4.28 mm), and the fluid's loads are 16% above hydrostatic, the excess at
# the free surface (docs/hard_cases.md). Measured over 1-2 s: 11.9 mm
# (explicit), 12.5 mm (implicit), oscillating by 0.8-1.5 mm (standard
# deviation). The band, 8.5-14.5 mm, holds the plate at the static deflection
# its own bending and these loads give, with room for the oscillation; a plate
# that is not held (a coupling that loses the load) or that runs away leaves it.
foreach(scheme explicit implicit)
  add_test(NAME coupled_plate_at_rest_${scheme}
           COMMAND sh -c "${CMAKE_BINARY_DIR}/bin/coupler cases/hard_plate_at_rest/case.yml --quiet --set dp=0.006 --set end_time=2 --set output.interval=0 --set coupling.scheme=${scheme} --out ${CMAKE_BINARY_DIR}/test_out/rest_${scheme}; /usr/bin/python3 tests/coupler/hard_check.py ${CMAKE_BINARY_DIR}/test_out/rest_${scheme} --end 2 --tip-bound 0.03 --static 0.0085 0.0145 1 2"
           WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
  set_tests_properties(coupled_plate_at_rest_${scheme} PROPERTIES TIMEOUT 300 LABELS validation)
endforeach()
