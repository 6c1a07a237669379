# Case files (common/mps_case*.c): parsing, validation, --set, resolved YAML.
mps_add_test(test_case SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_case.c LABELS unit TIMEOUT 30)
# The tank frame's motion (common/mps_motion.c): Eq. 55, derivatives, the
# table's spline, the body acceleration against a free particle, errors.
mps_add_test(test_motion SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_motion.c LABELS unit TIMEOUT 30)
