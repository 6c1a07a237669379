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

# Every number key at 0, +-1e300 and 1e-300 in each program: refused, run or
# failed with the solver's own message, never a hang, a signal or a protocol
# error (tests/cases_broken/sweep_numbers.py; 752 runs, about 70 s on 2 cores).
add_test(NAME broken_number_sweep
         COMMAND /usr/bin/python3 ${CMAKE_SOURCE_DIR}/tests/cases_broken/sweep_numbers.py
                 ${CMAKE_BINARY_DIR}/bin
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(broken_number_sweep PROPERTIES TIMEOUT 600 LABELS unit)
