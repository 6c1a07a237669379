# The broken case files of tests/cases_broken (issue 20): every one through
# the coupler and the standalone solvers it concerns, exit status and the one
# line that names file, line and key (tests/cases_broken/MANIFEST).
add_test(NAME broken_case_files
         COMMAND /usr/bin/python3 ${CMAKE_SOURCE_DIR}/tests/cases_broken/run_broken.py
                 ${CMAKE_BINARY_DIR}/bin
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(broken_case_files PROPERTIES TIMEOUT 120 LABELS unit)

# A layout dp does not divide runs, with a warning that names the key and
# what is built instead (coupler/scene_check.h, scene_check_lattice).
add_test(NAME coupler_lattice_warnings
         COMMAND /usr/bin/python3 ${CMAKE_SOURCE_DIR}/tests/coupler/lattice_warning_check.py
                 ${CMAKE_BINARY_DIR}/bin/coupler ${CMAKE_BINARY_DIR}/test_out/lattice_warnings
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(coupler_lattice_warnings PROPERTIES TIMEOUT 120 LABELS unit)
