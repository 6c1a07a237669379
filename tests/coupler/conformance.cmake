# Protocol conformance of every solid (tests/coupler/conformance.py plays the
# coupler's side of proto/PROTOCOL.md and checks the solid's answers).
set(CONFORMANCE /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/conformance.py)
set(CONFORMANCE_TOY "/usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/conformance_toy_solid.py")

foreach(model mps tlsph)
  add_test(NAME conformance_solid_${model}
           COMMAND ${CONFORMANCE} --solid "${CMAKE_BINARY_DIR}/bin/solid_solver --model ${model}"
           WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
endforeach()
# The MPS solid refined (solid.refine, solid_refine.h): the same conversation
# and rollback on the coupling lattice, the solid twice as fine behind it.
add_test(NAME conformance_solid_mps_refined
         COMMAND ${CONFORMANCE} --solid "${CMAKE_BINARY_DIR}/bin/solid_solver --model mps"
                 --set solid.refine=2
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
add_test(NAME conformance_solid_python
         COMMAND ${CONFORMANCE}
                 --solid "/usr/bin/python3 ${CMAKE_SOURCE_DIR}/solid_solver/python/modal_beam_solid.py"
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})

# The suite itself: a toy solid that follows the protocol passes, and each of
# its deliberate bugs is caught by the check named in the pattern.
add_test(NAME conformance_toy_solid
         COMMAND ${CONFORMANCE} --solid "${CONFORMANCE_TOY}"
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
add_test(NAME conformance_toy_solid_rollback
         COMMAND ${CONFORMANCE} --solid "${CONFORMANCE_TOY} --rollback"
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
foreach(case "step;;result\\.echo" "abort;;abort\\.exit" "silent;;malformed\\.bad_magic\\.error"
             "role;;hello\\.text" "repeat;;iteration_unasked\\.error"
             "norestore;--rollback;rollback\\.repeat" "casekey;;case_key\\.error")
  list(GET case 0 bug)
  list(GET case 1 flag)
  list(GET case 2 pattern)
  add_test(NAME conformance_catches_bug_${bug}
           COMMAND sh ${CMAKE_SOURCE_DIR}/tests/expect_fail.sh "checks failed .*${pattern}"
                   ${CONFORMANCE} --solid "${CONFORMANCE_TOY} ${flag} --bug ${bug}"
           WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
endforeach()

set_tests_properties(conformance_solid_mps conformance_solid_tlsph conformance_solid_python
                     conformance_solid_mps_refined
                     conformance_toy_solid conformance_toy_solid_rollback
                     conformance_catches_bug_step conformance_catches_bug_abort
                     conformance_catches_bug_silent conformance_catches_bug_role
                     conformance_catches_bug_repeat conformance_catches_bug_norestore
                     conformance_catches_bug_casekey
                     PROPERTIES TIMEOUT 60 LABELS integration ENVIRONMENT OMP_NUM_THREADS=1)

# A solid that says it honours a moving tank (accepts CONFIG motion) but
# ignores it must be caught by the physical check.
add_test(NAME conformance_catches_bug_motion
         COMMAND sh ${CMAKE_SOURCE_DIR}/tests/expect_fail.sh "checks failed .*motion\\.honoured"
                 ${CONFORMANCE} --solid "${CONFORMANCE_TOY} --bug motion"
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(conformance_catches_bug_motion
                     PROPERTIES TIMEOUT 60 LABELS integration ENVIRONMENT OMP_NUM_THREADS=1)
