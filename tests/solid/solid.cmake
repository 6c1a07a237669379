# Solid solver tests: unit (operators, model, stability, conservation),
# integration (the program: outputs, bad input) and validation (cantilever).
set(SOLID_TEST_DIR ${CMAKE_CURRENT_LIST_DIR})
foreach(t operators model stability conservation damping stress refine)
  mps_add_test(test_solid_${t} SOURCES ${SOLID_TEST_DIR}/test_solid_${t}.c LIBS solidcore
    LABELS unit TIMEOUT 60)
  target_include_directories(test_solid_${t} PRIVATE ${CMAKE_SOURCE_DIR}/tests)
endforeach()

set(SOLID_BIN $<TARGET_FILE:solid_solver>)
set(SOLID_OUT ${CMAKE_BINARY_DIR}/tests/solid_out)
set(SOLID_CASES tests/solid/cases)

# The program end to end on a small block: snapshots, XDMF, probes, summary.
add_test(NAME solid_cli_outputs
  COMMAND sh -c "rm -rf \"$0\" && \"$1\" tests/solid/cases/block.yml --out \"$0\" --quiet && /usr/bin/python3 tests/solid/check_outputs.py \"$0\""
    ${SOLID_OUT}/block ${SOLID_BIN}
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(solid_cli_outputs PROPERTIES TIMEOUT 30 LABELS integration)

# Bad input: one line naming file, line and key; non-zero exit.
function(solid_bad name pattern)
  add_test(NAME solid_bad_${name}
    COMMAND sh ${CMAKE_SOURCE_DIR}/tests/expect_fail.sh "${pattern}" ${SOLID_BIN} ${ARGN}
      --out ${SOLID_OUT}/bad --quiet
    WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
  set_tests_properties(solid_bad_${name} PROPERTIES TIMEOUT 20 LABELS integration)
endfunction()
solid_bad(E_zero "bad_E_zero\\.yml:[0-9]+: solid\\.bodies\\.0\\.E = 0\\.0: must be > 0"
  ${SOLID_CASES}/bad_E_zero.yml)
solid_bad(nu_half "bad_nu_half\\.yml:[0-9]+: solid\\.bodies\\.0\\.nu = 0\\.5: must be in \\(-1, 0\\.5\\)"
  ${SOLID_CASES}/bad_nu_half.yml)
solid_bad(nu_low "bad_nu_low\\.yml:[0-9]+: solid\\.bodies\\.0\\.nu = -1\\.2: must be in \\(-1, 0\\.5\\)"
  ${SOLID_CASES}/bad_nu_low.yml)
solid_bad(clamp_empty "bad_clamp_empty\\.yml:[0-9]+: solid\\.clamps\\.0\\.x0 = 0\\.5: empty clamp"
  ${SOLID_CASES}/bad_clamp_empty.yml)
solid_bad(clamp_body "bad_clamp_body\\.yml:[0-9]+: solid\\.clamps\\.0\\.body = blok: no body of that name"
  ${SOLID_CASES}/bad_clamp_body.yml)
solid_bad(body_empty "bad_body_empty\\.yml:[0-9]+: solid\\.bodies\\.0\\.y1 = 0\\.005: body 'block' holds no particle"
  ${SOLID_CASES}/bad_body_empty.yml)
solid_bad(courant "bad_courant\\.yml:[0-9]+: solid\\.courant = 1\\.5: must be in \\(0, 1\\]"
  ${SOLID_CASES}/bad_courant.yml)
solid_bad(set_E "--set solid\\.bodies\\.0\\.E=-1: solid\\.bodies\\.0\\.E = -1: must be > 0"
  ${SOLID_CASES}/block.yml --set solid.bodies.0.E=-1)
solid_bad(model "--model nosuch: unknown solid model \\(known: mps"
  ${SOLID_CASES}/block.yml --model nosuch)

# Cantilever beam (paper 5.1) at b/dp = 5 over two periods (1.7 s). The 5
# particle rows have a second moment sum dp y^2 = 0.96 b^3/12, which predicts
# f -2.0% from 1.277 Hz (f ~ sqrt(EI)) and a deflection discrepancy of -4.2%
# from 47.09 cm (1/EI; the paper allows 5.07%). Measured -2.08% and -4.02%,
# the same with 1 and 2 threads (the MPS solid's step is bit-identical for
# any thread count, test_solid_model). Bands: 0.5 points around the predicted
# f, 0.7 around the predicted deflection (the lattice's other discrete
# errors: the surface bonds' weights, the clamp). Before: f within 2.5%,
# deflection within 5.07%, which a plane-strain lambda in place of the
# plane-stress one passed by 0.7 points.
add_test(NAME solid_cantilever_b5
  COMMAND sh -c "rm -rf \"$0\" && \"$1\" cases/cantilever_beam/case.yml --out \"$0\" --quiet && /usr/bin/python3 tests/solid/cantilever_check.py \"$0/probes.csv\" --freq-range -2.5 -1.5 --defl-max -3.5 --defl-min -4.9 --min-periods 2"
    ${SOLID_OUT}/cantilever_b5 ${SOLID_BIN}
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(solid_cantilever_b5 PROPERTIES TIMEOUT 60 LABELS validation)

# solid.plane_factor multiplies E in both 2D planes: the same cantilever with
# 1.15 against Eq. 53-54 with 1.15 E keeps its bands. The frequency band is
# the one above (measured -2.23% against -2.08% without the factor: the
# swing is 14% smaller, so a little less geometric softening); the deflection
# band goes to -5.2% for the same reason (-4.67% against -4.02%). Without
# the factor applied the run reads -8.7% and -19.6% there.
add_test(NAME solid_cantilever_plane_factor
  COMMAND sh -c "rm -rf \"$0\" && \"$1\" cases/cantilever_beam/case.yml --out \"$0\" --quiet --set solid.plane_factor=1.15 && /usr/bin/python3 tests/solid/cantilever_check.py \"$0/probes.csv\" --modulus-factor 1.15 --freq-range -2.5 -1.5 --defl-max -3.5 --defl-min -5.2 --min-periods 2"
    ${SOLID_OUT}/cantilever_plane_factor ${SOLID_BIN}
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(solid_cantilever_plane_factor PROPERTIES TIMEOUT 60 LABELS validation)

# The 2-D finite-element reference of the plate at rest (bench/plate_fe.py,
# Q9 elements, numpy alone as on CI): a slender cantilever against
# Euler-Bernoulli + shear, the self-weight buckling load against Greenhill's
# 7.837 E I / L^3, and the thick plate's mesh convergence (nx = 4 vs 8).
add_test(NAME plate_fe_reference COMMAND /usr/bin/python3 tests/solid/plate_fe_check.py
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(plate_fe_reference PROPERTIES TIMEOUT 60 LABELS unit)

# The 3D model of the sloshing plate that sets the cases' solid.plane_factor
# (bench/plate_3d_stiffness.py, numpy alone): the element against beam
# theory, plane strain reproduced, the real plate between the planes and
# stiffening as it bends (the bands: tests/solid/plate_3d_check.py).
add_test(NAME plate_3d_stiffness COMMAND /usr/bin/python3 tests/solid/plate_3d_check.py
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(plate_3d_stiffness PROPERTIES TIMEOUT 300 LABELS unit)
