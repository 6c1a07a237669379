# Each solver owns its case keys (issue 22, PROTOCOL.md 4 and 8): a key of
# the solid's section the coupler has never heard of is the solid's to judge.
# The Python solid has a key of its own (solid.modal_beam.courant): a bad
# value or a misspelt name comes back as a case error, which the coupler
# prints as its own (one line: where, key, value, problem) and exits 2; our
# MPS solid, which has no such key, refuses it the same way.
function(keys_expect_fail name pattern)
  add_test(NAME ${name}
           COMMAND sh ${CMAKE_SOURCE_DIR}/tests/expect_fail.sh "${pattern}"
                   ${CMAKE_BINARY_DIR}/bin/coupler ${ARGN}
                   --out ${CMAKE_BINARY_DIR}/test_out/keys_${name}
           WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
  set_tests_properties(${name} PROPERTIES TIMEOUT 60 LABELS unit)
endfunction()
set(PY_SOLID "/usr/bin/python3 solid_solver/python/modal_beam_solid.py")
keys_expect_fail(coupler_python_key_range
  "^coupler: --set solid.modal_beam.courant=2: solid.modal_beam.courant = 2: must be in \\(0, 1\\]$"
  tests/coupler/plate_in_water.yml --solid ${PY_SOLID} --set solid.modal_beam.courant=2)
keys_expect_fail(coupler_python_key_typo
  "^coupler: --set solid.modal_beam.couran=0.5: solid.modal_beam.couran = 0.5: unknown key; did you mean solid.modal_beam.courant\\?$"
  tests/coupler/plate_in_water.yml --solid ${PY_SOLID} --set solid.modal_beam.couran=0.5)
# in a file: the solid names the user's file and line (the resolved copy's
# origins), not the copy's
keys_expect_fail(coupler_python_key_line
  "^coupler: tests/coupler/modal_bad_key.yml:12: solid.modal_beam.courant = 1.5: must be in \\(0, 1\\]$"
  tests/coupler/modal_bad_key.yml --solid ${PY_SOLID})
keys_expect_fail(coupler_mps_refuses_python_key
  "^coupler: --set solid.modal_beam.courant=0.5: solid.modal_beam.courant = 0.5: unknown key$"
  tests/coupler/plate_in_water.yml --set solid.modal_beam.courant=0.5)
# Implicit coupling with fracture: the solid refuses rollback=on as a problem
# of the case's keys (it used to be the coupler's check, with this message).
keys_expect_fail(coupler_implicit_fracture
  "^coupler: --set coupling.scheme=implicit: coupling.scheme = implicit: implicit coupling cannot be used with fracture or contact \\(solid.eps_max, solid.contact\\): the interface would change within a step$"
  tests/coupler/plate_in_water.yml --set solid.eps_max=0.1 --set coupling.scheme=implicit)
# A solid whose stable step needs more sub-steps than an ADVANCE carries: our
# MPS solid refuses such a case itself (tests/cases_broken/MANIFEST), so the
# coupler's own check, which guards any solid, is tried on the Python one.
keys_expect_fail(coupler_python_stable_step
  "^coupler: tests/coupler/plate_in_water.yml: the solid's stable step [0-9.e+-]+ s needs [0-9.e+]+ sub-steps for a coupling step of 0.001 s, more than an ADVANCE carries \\(2147483647\\): check the solid's E, rho and dp$"
  tests/coupler/plate_in_water.yml --quiet --solid ${PY_SOLID} --set solid.bodies.0.E=1e30)
# A solid surface moving at 1e300 m/s: the fluid's CFL step overflowed to 0,
# which it offered the coupler and the protocol refused ("RESULT: dt = 0");
# now the fluid says its step is below fluid.dt_min, as for a flow too fast.
add_test(NAME coupler_solid_speed_overflow
  COMMAND sh ${CMAKE_SOURCE_DIR}/tests/expect_status.sh 1
          "^coupler: diverged: fluid solver: diverged: fluid step 0 s at t = 0.001 s is below fluid.dt_min = 1e-07 s: the flow, or a solid's surface in it, is too fast"
          ${CMAKE_BINARY_DIR}/bin/coupler cases/dambreak_elastic_plate/case.yml --quiet
          --set dp=0.006 --set solid.bodies.0.vx=1e300 --set end_time=0.01
          --out ${CMAKE_BINARY_DIR}/test_out/keys_solid_speed_overflow
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(coupler_solid_speed_overflow PROPERTIES TIMEOUT 60 LABELS unit)
