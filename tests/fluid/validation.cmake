# Validation of the fluid on the issue's two cases (docs/fluid.md), short
# enough for ctest (about 40 s in all on one core, Release):
#   fluid_valid_hydrostatic  cases/hydrostatic, dp = 10 mm, 2 s: bottom
#                            pressure within 3% of rho g h, max speed below
#                            1% of sqrt(g h), no particle out;
#   fluid_valid_dambreak     cases/dambreak, dp = 8 mm, to T = 3: front and
#                            height vs Martin & Moyce (tolerances justified in
#                            tests/fluid/check_dambreak.py and docs/fluid.md);
#   fluid_stable_dambreak    cases/dambreak, dp = 8 mm, 2 s (the water hits
#                            the right wall and sloshes back): finishes, no
#                            particle out, speeds finite;
#   fluid_ppe_scaling        cases/dambreak at 8 and 2 mm to 0.05 s: the PPE
#                            iterations stay flat with the default solver
#                            (tests/fluid/check_ppe_scaling.py).
set(FV_DIR ${CMAKE_CURRENT_LIST_DIR})
set(FV_OUT ${CMAKE_BINARY_DIR}/test_out/fluid_validation)
set(FV_RUN sh ${FV_DIR}/run_and_check.sh)
set(FV_SOLVER ${CMAKE_BINARY_DIR}/bin/fluid_solver)

add_test(NAME fluid_valid_hydrostatic
  COMMAND ${FV_RUN} ${FV_OUT}/hydrostatic ${FV_DIR}/check_hydrostatic.py --t-end 2
          -- ${FV_SOLVER} cases/hydrostatic/case.yml --set output.interval=0
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
add_test(NAME fluid_valid_dambreak
  COMMAND ${FV_RUN} ${FV_OUT}/dambreak ${FV_DIR}/check_dambreak.py
          -- ${FV_SOLVER} cases/dambreak/case.yml --set dp=0.008 --set end_time=0.27
             --set output.interval=0
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
add_test(NAME fluid_stable_dambreak
  COMMAND ${FV_RUN} ${FV_OUT}/dambreak_2s ${FV_DIR}/check_stable.py --t-end 2
          -- ${FV_SOLVER} cases/dambreak/case.yml --set dp=0.008 --set end_time=2
             --set output.interval=0
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
add_test(NAME fluid_ppe_scaling
  COMMAND /usr/bin/python3 ${FV_DIR}/check_ppe_scaling.py ${FV_SOLVER} ${FV_OUT}/ppe_scaling
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
# The pressure of the 8 mm dam break must not flicker, whatever the output
# times, and the output times must not change the run (docs/pressure.md).
add_test(NAME fluid_pressure_flicker
  COMMAND sh ${FV_DIR}/scripts/flicker.sh ${FV_SOLVER} ${FV_OUT}/flicker
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(fluid_valid_hydrostatic fluid_valid_dambreak fluid_stable_dambreak
  fluid_ppe_scaling fluid_pressure_flicker
  PROPERTIES LABELS validation TIMEOUT 180 ENVIRONMENT "OMP_NUM_THREADS=1")

# Standalone runs bind their OpenMP threads to CPUs unless the user (or the
# coupler) set OMP_PLACES / OMP_PROC_BIND (common/mps_omp.h).
add_test(NAME fluid_cpu_binding
  COMMAND ${CMAKE_COMMAND} -DSOLVER=${FV_SOLVER} -DOUT=${FV_OUT}/binding
          -P ${FV_DIR}/scripts/check_binding.cmake
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(fluid_cpu_binding PROPERTIES LABELS integration TIMEOUT 60)
add_test(NAME fluid_simd_paths
  COMMAND ${CMAKE_COMMAND} -DSOLVER=${FV_SOLVER} -DOUT=${FV_OUT}/simd
          -P ${FV_DIR}/scripts/check_simd.cmake
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(fluid_simd_paths PROPERTIES LABELS integration TIMEOUT 60)
