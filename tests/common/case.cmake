# Case files (common/mps_case*.c): parsing, validation, --set, resolved YAML.
mps_add_test(test_case SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_case.c LABELS unit TIMEOUT 30)
