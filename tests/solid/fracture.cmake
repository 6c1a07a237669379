# Brittle fracture and contact of the MPS solid (paper section 4.4, case 5.2):
# the unit test (threshold, surface, contact force, no-fracture identity, the
# collision case at dp = 0.05 and 0.025 to 1 s), the program on the case, and
# bad input. docs/fracture.md has the full runs.
mps_add_test(test_solid_fracture SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_solid_fracture.c
  LIBS solidcore LABELS unit TIMEOUT 60)
target_include_directories(test_solid_fracture PRIVATE ${CMAKE_SOURCE_DIR}/tests)

set(FRACTURE_BIN $<TARGET_FILE:solid_solver>)
set(FRACTURE_OUT ${CMAKE_BINARY_DIR}/tests/solid_out/fracture)
set(FRACTURE_CASE cases/fracture_collision/case.yml)

# The program on the case, coarse and short: snapshots carry body and surface,
# probes.csv the fracture columns, summary.json the fracture counters.
add_test(NAME solid_fracture_cli
  COMMAND sh -c "rm -rf \"$0\" && \"$1\" \"$2\" --out \"$0\" --quiet --set dp=0.05 --set end_time=0.1 && grep -v '^#' \"$0/probes.csv\" | head -1 | grep -q 'momentum_x,momentum_y,min_gap,broken_bonds,surface_particles' && grep -q '\"fracture\"' \"$0/summary.json\" && grep -q '\"contact\": \"all\"' \"$0/summary.json\" && test -f \"$0/solid_000010.h5\""
    ${FRACTURE_OUT}/cli ${FRACTURE_BIN} ${FRACTURE_CASE}
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(solid_fracture_cli PROPERTIES TIMEOUT 30 LABELS integration)

function(fracture_bad name pattern)
  add_test(NAME solid_fracture_bad_${name}
    COMMAND sh ${CMAKE_SOURCE_DIR}/tests/expect_fail.sh "${pattern}" ${FRACTURE_BIN}
      ${FRACTURE_CASE} --out ${FRACTURE_OUT}/bad --quiet ${ARGN}
    WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
  set_tests_properties(solid_fracture_bad_${name} PROPERTIES TIMEOUT 20 LABELS integration)
endfunction()
fracture_bad(eps_zero "--set solid\\.eps_max=0: solid\\.eps_max = 0: must be > 0"
  --set solid.eps_max=0)
fracture_bad(contact "--set solid\\.contact=maybe: solid\\.contact = maybe: must be one of all, bodies, none"
  --set solid.contact=maybe)
fracture_bad(model "case\\.yml:[0-9]+: solid\\.eps_max = 0\\.2: fracture and contact are in the mps model only"
  --set solid.model=tlsph)
