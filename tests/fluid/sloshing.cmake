# The moving tank frame in the fluid (issue 17, docs/sloshing.md), fluid alone:
#   fluid_tilt_fixed        tests/fluid/tilt_fixed.yml: a tank held at 5 degrees,
#                           viscous liquid, 2 s: surface level in the lab frame,
#                           pressure hydrostatic (tests/fluid/check_tilt.py);
#   fluid_sloshing_period   tests/fluid/sloshing_free.yml: the low-filling tank
#                           held at 1 degree from t = 0, 5.2 s: the first mode's
#                           period within 2% of Eq. 55
#                           (tests/fluid/check_sloshing_period.py);
#   fluid_sloshing_side_walls  the same with the side walls' drag (below).
# (validation.cmake's FV_ names, set here too: the includes run in file order)
set(FV_DIR ${CMAKE_CURRENT_LIST_DIR})
set(FV_OUT ${CMAKE_BINARY_DIR}/test_out/fluid_validation)
set(FV_RUN sh ${FV_DIR}/run_and_check.sh)
set(FV_SOLVER ${CMAKE_BINARY_DIR}/bin/fluid_solver)
add_test(NAME fluid_tilt_fixed
  COMMAND ${FV_RUN} ${FV_OUT}/tilt_fixed ${FV_DIR}/check_tilt.py
          -- ${FV_SOLVER} tests/fluid/tilt_fixed.yml
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
add_test(NAME fluid_sloshing_period
  COMMAND ${FV_RUN} ${FV_OUT}/sloshing_free ${FV_DIR}/check_sloshing_period.py
          -- ${FV_SOLVER} tests/fluid/sloshing_free.yml
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
# fluid_sloshing_side_walls: the same tank with fluid.side_walls (a breadth of
# 39 mm, the experiment's), to 2.6 s: its first mode decays faster than the
# run above by the Stokes layers' c / 2 = sqrt(2 nu omega) / (2 B), within
# 25%, its period is longer by the layers' inertia, sqrt(1 + delta / B),
# within 3%, and its bottom pressure is the same within 2%
# (tests/fluid/check_side_walls.py says why).
add_test(NAME fluid_sloshing_side_walls
  COMMAND ${FV_RUN} ${FV_OUT}/sloshing_side_walls ${FV_DIR}/check_side_walls.py
          --ref ${FV_OUT}/sloshing_free --breadth 0.039
          -- ${FV_SOLVER} tests/fluid/sloshing_free.yml --set end_time=2.6
          --set fluid.side_walls.breadth=0.039 --set fluid.side_walls.period=1.6466
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(fluid_sloshing_period PROPERTIES FIXTURES_SETUP sloshing_free)
set_tests_properties(fluid_sloshing_side_walls PROPERTIES FIXTURES_REQUIRED sloshing_free)
set_tests_properties(fluid_tilt_fixed fluid_sloshing_period fluid_sloshing_side_walls
  PROPERTIES LABELS validation TIMEOUT 180 ENVIRONMENT "OMP_NUM_THREADS=1")

# Bad motion input: one line naming file, line, key and problem, exit 2.
add_test(NAME fluid_motion_bad_pivot
  COMMAND sh ${CMAKE_SOURCE_DIR}/tests/expect_fail.sh
          "^fluid_solver: input: --set motion.pivot.x=abc: motion.pivot.x = abc: must be a number$"
          ${FV_SOLVER} cases/sloshing_low/case.yml --out ${FV_OUT}/bad_pivot --quiet
          --set motion.pivot.x=abc
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
add_test(NAME fluid_motion_no_pivot
  COMMAND sh ${CMAKE_SOURCE_DIR}/tests/expect_fail.sh
          "^fluid_solver: input: --set motion.kind=constant: motion.kind = constant: needs motion.pivot"
          ${FV_SOLVER} cases/hydrostatic/case.yml --out ${FV_OUT}/no_pivot --quiet
          --set motion.kind=constant
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
add_test(NAME fluid_side_walls_no_period
  COMMAND sh ${CMAKE_SOURCE_DIR}/tests/expect_fail.sh
          "^fluid_solver: input: --set fluid.side_walls.breadth=0.039: fluid.side_walls.breadth = 0.039: needs fluid.side_walls.period"
          ${FV_SOLVER} cases/dambreak/case.yml --out ${FV_OUT}/side_walls_no_period --quiet
          --set fluid.side_walls.breadth=0.039
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(fluid_motion_bad_pivot fluid_motion_no_pivot fluid_side_walls_no_period
  PROPERTIES LABELS integration TIMEOUT 30)
