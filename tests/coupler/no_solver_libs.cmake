# The coupler links neither solver library (issue 22): each solver validates
# its own case keys (PROTOCOL.md 8), so the coupler needs none of their code.
# Checked on what the build records as the coupler's link libraries and on
# the symbols in the binary (no symbol a solver library defines), so a call
# into a solver's code cannot come back unnoticed.
file(GENERATE OUTPUT ${CMAKE_BINARY_DIR}/coupler_link_libraries.txt
     CONTENT "$<TARGET_PROPERTY:coupler,LINK_LIBRARIES>\n")
add_test(NAME coupler_no_solver_libs
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/no_solver_libs.py
                 $<TARGET_FILE:coupler> ${CMAKE_BINARY_DIR}/coupler_link_libraries.txt
                 $<TARGET_FILE:fluidcore> $<TARGET_FILE:solidcore>)
set_tests_properties(coupler_no_solver_libs PROPERTIES TIMEOUT 60 LABELS unit)
