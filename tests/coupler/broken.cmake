# The broken case files of tests/cases_broken (issue 20): every one through
# the coupler and the standalone solvers it concerns, exit status and the one
# line that names file, line and key (tests/cases_broken/MANIFEST).
add_test(NAME broken_case_files
         COMMAND /usr/bin/python3 ${CMAKE_SOURCE_DIR}/tests/cases_broken/run_broken.py
                 ${CMAKE_BINARY_DIR}/bin
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(broken_case_files PROPERTIES TIMEOUT 120 LABELS unit)
