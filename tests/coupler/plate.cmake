# The coupled dam break on an elastic plate at a coarse spacing (6 mm: the
# plate is 2 particles thick) to 0.4 s: the plate must deflect downstream with
# its first peak near the published band (0.041-0.049 m at 0.22-0.26 s, eleven
# methods). Band for this resolution: a 2-row plate has 0.75 of the bending
# stiffness of b^3/12 (more deflection) and the coarse water front is blunter
# (less impulse), so the check allows about 25% either side of the published
# band, 0.031-0.061 m, and 0.18-0.32 s for the time of the peak. The run goes
# on to 1.5 s, through the phase where water surrounds the plate: the plate
# must stay within 5 cm after 0.5 s (the references stay within 2-3 cm; with
# the MPS solid undamped the spin mode tore the plate at 1.05 s, 21 cm).
# The plate's force probes (solid.probes) must agree with the coupler's
# solid_fx, solid_fy row by row (body_load_check.py).
add_test(NAME coupled_dambreak_plate_coarse
         COMMAND sh -c "${CMAKE_BINARY_DIR}/bin/coupler cases/dambreak_elastic_plate/case.yml --out ${CMAKE_BINARY_DIR}/test_out/plate6 --quiet --set dp=0.006 --set end_time=1.5 && /usr/bin/python3 bench/plate_compare.py ${CMAKE_BINARY_DIR}/test_out/plate6 --tmax 1.0 --peak-band 0.031 0.061 --peak-time 0.18 0.32 --max-after 0.5 0.05 && /usr/bin/python3 tests/coupler/body_load_check.py ${CMAKE_BINARY_DIR}/test_out/plate6"
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(coupled_dambreak_plate_coarse PROPERTIES TIMEOUT 300 LABELS validation)

# The same plate at 3 mm to 0.75 s, through the run-up's collapse onto the
# plate (0.5-0.7 s): the water must stay in the tank and the plate within
# 5 cm. A density correction too weak at this resolution's short steps
# (fluid.kappa_dt = 5e-4 s, once the default) let the water expand over the
# walls (1756 of 4656 particles by 0.67 s) and the plate swing to 7 cm,
# which the 6 mm test above did not see (its steps are twice as long). The
# runs with Eq. 23 as printed lose 8-9 particles (one or two threads, before
# and after the flicker work); the band, 40, is 1% of the water.
add_test(NAME coupled_dambreak_plate_3mm
         COMMAND sh -c "${CMAKE_BINARY_DIR}/bin/coupler cases/dambreak_elastic_plate/case.yml --out ${CMAKE_BINARY_DIR}/test_out/plate3 --quiet --set dp=0.003 --set end_time=0.75 --set output.interval=0 && /usr/bin/python3 bench/plate_compare.py ${CMAKE_BINARY_DIR}/test_out/plate3 --tmax 0.75 --max-after 0.5 0.05 && /usr/bin/python3 -c \"import json,sys; n=json.load(open(sys.argv[1]))['lost_particles']; print('lost particles', n); sys.exit(n > 40)\" ${CMAKE_BINARY_DIR}/test_out/plate3/fluid_summary.json"
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(coupled_dambreak_plate_3mm PROPERTIES TIMEOUT 600 LABELS validation)

# The elastic gate (issue 6) at a coarse spacing with each solid model to 0.2 s:
# the gate must open downstream (the free end moves right and up).
foreach(model mps tlsph)
  add_test(NAME coupled_elastic_gate_${model}
           COMMAND sh -c "${CMAKE_BINARY_DIR}/bin/coupler cases/elastic_gate/case.yml --out ${CMAKE_BINARY_DIR}/test_out/gate_${model} --quiet --set dp=0.0025 --set end_time=0.2 --solid 'solid_solver --model ${model}' && /usr/bin/python3 tests/coupler/gate_check.py ${CMAKE_BINARY_DIR}/test_out/gate_${model}"
           WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
  set_tests_properties(coupled_elastic_gate_${model} PROPERTIES TIMEOUT 300 LABELS validation)
endforeach()

# A third-party solid (Python, proto/PROTOCOL.md only) in a coupled run.
add_test(NAME coupled_python_modal_solid
         COMMAND sh -c "${CMAKE_BINARY_DIR}/bin/coupler tests/coupler/plate_in_water.yml --out ${CMAKE_BINARY_DIR}/test_out/pymodal --quiet --set end_time=0.3 --solid '/usr/bin/python3 solid_solver/python/modal_beam_solid.py' && /usr/bin/python3 tests/coupler/modal_check.py ${CMAKE_BINARY_DIR}/test_out/pymodal"
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(coupled_python_modal_solid PROPERTIES TIMEOUT 120 LABELS integration)
