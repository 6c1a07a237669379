# Pressure sensors and wall loads (docs/sensors.md):
#   fluid_sensors_hydrostatic  cases/hydrostatic, dp = 10 mm, 0.5 s: the
#                              sensors on the left wall and the floor and the
#                              force and moment on each wall against still
#                              water (bands in tests/fluid/check_sensors.py);
#   fluid_sensors_dambreak     cases/dambreak, dp = 8 mm, 0.35 s: the
#                              right-wall sensor sees the impact when the
#                              front arrives, and its rows are time means;
#   fluid_impact_ensemble      the same impact in four realisations (jittered
#                              starts, bench/impact_ensemble.py): each one
#                              physical, the four distinct.
set(FS_DIR ${CMAKE_CURRENT_LIST_DIR})
set(FS_OUT ${CMAKE_BINARY_DIR}/test_out/fluid_sensors)
add_test(NAME fluid_sensors_hydrostatic
  COMMAND sh ${FS_DIR}/run_and_check.sh ${FS_OUT}/hydrostatic ${FS_DIR}/check_sensors.py
          --check hydrostatic --dp 0.01 --depth 0.3 --width 0.4
          -- ${CMAKE_BINARY_DIR}/bin/fluid_solver cases/hydrostatic/case.yml
             --set end_time=0.5 --set output.interval=0
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
add_test(NAME fluid_sensors_dambreak
  COMMAND sh ${FS_DIR}/scripts/sensors_dambreak.sh ${CMAKE_BINARY_DIR}/bin/fluid_solver
          ${FS_OUT}/dambreak
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
add_test(NAME fluid_impact_ensemble
  COMMAND sh ${FS_DIR}/scripts/impact_ensemble.sh ${CMAKE_BINARY_DIR} ${FS_OUT}/ensemble
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(fluid_sensors_hydrostatic fluid_sensors_dambreak fluid_impact_ensemble
  PROPERTIES LABELS validation TIMEOUT 120 ENVIRONMENT "OMP_NUM_THREADS=1")
