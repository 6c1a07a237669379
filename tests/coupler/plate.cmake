# The coupled dam break on an elastic plate at a coarse spacing (6 mm: the
# plate is 2 particles thick) to 1.5 s, against the eleven published methods
# (cases/dambreak_elastic_plate/walhorn2005.csv). Measured 2026-12-02 with the
# face loads (fluid.solid_load: face), 2 and 1 threads: first peak 4.70 /
# 4.70 cm at 0.226 s; RMS from Walhorn's FEM curve over [0, 0.5] s 0.63 /
# 0.61 cm (Eq. 50: 0.58), over [0, 0.85] s 1.20 / 0.80 cm (Eq. 50: 0.92);
# inside the envelope of the eleven curves 93 / 94% of [0, 0.85] s; largest
# |dx| after 0.5 s 2.21 cm. Bands:
#  - first peak inside the published band itself, 0.041-0.049 m at
#    0.22-0.26 s: the 2-row plate's 0.75 of the bending stiffness b^3/12 (more
#    deflection) and the coarse front's smaller impulse (less) cancel to
#    within it, as measured;
#  - RMS from the FEM curve over [0, 0.5] s (the run-up and the first
#    impact, before the flow turns chaotic) at most 0.9 cm: the published
#    methods there lie 0.51-1.17 cm from it, the two MPS ones 0.89 and 0.92.
#    Not over [0, 0.85] s: after 0.5 s two runs that differ only in the
#    thread count part by 0.4 cm RMS (1.20 and 0.80 cm), so a band there
#    measures chance (it was 1.2 cm until the face loads put the two-thread
#    run at 1.205);
#  - inside the envelope at least 70% of [0, 1] s (the lattice measured
#    93-94%; four realisations from jittered starts, fluid.jitter 1e-3 dp,
#    seeds 1-4, one thread, 2026-12-03: 93, 91, 81 and 91%: mean 89, sd 5.
#    After 0.5 s the flow is chaotic and realisations part, so the band sits
#    3.5 sd below their mean; it was 80%, one point under the third seed);
#  - |dx| below 3.5 cm after 0.5 s, when water surrounds the plate (the
#    references stay within 2-3 cm; with the MPS solid undamped the spin mode
#    tore the plate at 1.05 s, 21 cm).
# Before: 25% either side of the published band (0.031-0.061 m, 0.18-0.32 s),
# 5 cm after 0.5 s, no RMS or envelope: a 10% error in the loads passed.
# The plate's force probes (solid.probes) must agree with the coupler's
# solid_fx, solid_fy row by row (body_load_check.py).
add_test(NAME coupled_dambreak_plate_coarse
         COMMAND sh -c "${CMAKE_BINARY_DIR}/bin/coupler cases/dambreak_elastic_plate/case.yml --out ${CMAKE_BINARY_DIR}/test_out/plate6 --quiet --set dp=0.006 --set end_time=1.5 && /usr/bin/python3 bench/plate_compare.py ${CMAKE_BINARY_DIR}/test_out/plate6 --tmax 0.5 --peak-band 0.041 0.049 --peak-time 0.22 0.26 --rms-max 0.009 && /usr/bin/python3 bench/plate_compare.py ${CMAKE_BINARY_DIR}/test_out/plate6 --tmax 1.0 --inside-min 0.70 --max-after 0.5 0.035 && /usr/bin/python3 tests/coupler/body_load_check.py ${CMAKE_BINARY_DIR}/test_out/plate6"
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(coupled_dambreak_plate_coarse PROPERTIES TIMEOUT 300 LABELS validation)

# The pressure of issue 21 on the 6 mm plate (docs/pressure.md, "Spray and
# tension"), each part guarded by the measure it was made for:
#  - the spray left on the free surface (fluid.surface_scan_density = 0.9,
#    the default), 2 s: the mean interior share at P = 0 over the snapshots
#    and the 2 ms force rows within 15% of their 20 ms mean (bands and their
#    reasons in check_plate_flicker.py; every candidate scanned, as before,
#    fails both); the tip curve must stay with the references (peak band and
#    RMS of coupled_dambreak_plate_coarse);
#  - the option fluid.kappa_step_decay = 0.95, 1 s: steps with over 30% of
#    the PPE rows at P <= 0 (each right after a drop of the CFL step):
#    measured 2, without the option 19; the band, 6, between. Run with Eq. 3's
#    weight in the shifting, with which it was measured: with the case's smooth
#    weight the lattice start's column breaks up at 0.129-0.137 s instead of
#    0.100 s, 16 steps at 30-44% (docs/pressure.md, "The particle shifting's
#    weight"), which is not the decay's matter.
add_test(NAME coupled_plate_flicker_scan
         COMMAND sh -c "${CMAKE_BINARY_DIR}/bin/coupler cases/dambreak_elastic_plate/case.yml --out ${CMAKE_BINARY_DIR}/test_out/plate6_scan --quiet --set dp=0.006 --set end_time=2 && /usr/bin/python3 tests/coupler/check_plate_flicker.py ${CMAKE_BINARY_DIR}/test_out/plate6_scan && /usr/bin/python3 bench/plate_compare.py ${CMAKE_BINARY_DIR}/test_out/plate6_scan --tmax 0.5 --peak-band 0.041 0.049 --peak-time 0.22 0.26 --rms-max 0.009"
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
add_test(NAME coupled_plate_kappa_step_decay
         COMMAND sh -c "${CMAKE_BINARY_DIR}/bin/coupler cases/dambreak_elastic_plate/case.yml --out ${CMAKE_BINARY_DIR}/test_out/plate6_decay --quiet --set dp=0.006 --set end_time=1 --set output.interval=0 --set fluid.step_log=true --set fluid.kappa_step_decay=0.95 --set fluid.shifting_weight=mps && /usr/bin/python3 tests/fluid/check_step_log.py ${CMAKE_BINARY_DIR}/test_out/plate6_decay --max-steps-over 0.3 6"
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
#  - the option pair of docs/pressure.md, "The divergence on the Laplacian's
#    stencil" (fluid.divergence_stencil = laplacian, fluid.density_weight =
#    quadratic), 2 s: at least 85% of the 2 ms force rows within 15% of
#    their 20 ms mean, the tip as above. Measured (2026-12-04, lattice start,
#    two threads): 90% (RMS deviation 4.3 N/m), peak 4.41 cm, RMS 0.44 cm
#    over 0-0.5 s; the defaults 80% (6.3 N/m). Eight jittered starts of each
#    (bench/flicker_ensemble.py, one thread) in docs/pressure.md.
add_test(NAME coupled_plate_flicker_laplacian
         COMMAND sh -c "${CMAKE_BINARY_DIR}/bin/coupler cases/dambreak_elastic_plate/case.yml --out ${CMAKE_BINARY_DIR}/test_out/plate6_laplacian --quiet --set dp=0.006 --set end_time=2 --set fluid.divergence_stencil=laplacian --set fluid.density_weight=quadratic && /usr/bin/python3 tests/coupler/check_plate_flicker.py ${CMAKE_BINARY_DIR}/test_out/plate6_laplacian --min-within15 0.85 && /usr/bin/python3 bench/plate_compare.py ${CMAKE_BINARY_DIR}/test_out/plate6_laplacian --tmax 0.5 --peak-band 0.041 0.049 --peak-time 0.22 0.26 --rms-max 0.009"
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
#  - the default fluid.divergence_stencil = near_bodies (docs/pressure.md, "The
#    divergence near bodies"), 2 s: at least 84% of the 2 ms force rows within
#    15% of their 20 ms mean, the tip as above. Measured (2026-12-04): eight
#    jittered starts 87.3-90.6% (one thread), the lattice start 91% (two
#    threads); with Eq. 10 at re_n everywhere (gradient, the default before)
#    73.4-79.2%. 84% sits between, three points under the lowest realisation.
add_test(NAME coupled_plate_flicker_near_bodies
         COMMAND sh -c "${CMAKE_BINARY_DIR}/bin/coupler cases/dambreak_elastic_plate/case.yml --out ${CMAKE_BINARY_DIR}/test_out/plate6_near_bodies --quiet --set dp=0.006 --set end_time=2 && /usr/bin/python3 tests/coupler/check_plate_flicker.py ${CMAKE_BINARY_DIR}/test_out/plate6_near_bodies --min-within15 0.84 && /usr/bin/python3 bench/plate_compare.py ${CMAKE_BINARY_DIR}/test_out/plate6_near_bodies --tmax 0.5 --peak-band 0.041 0.049 --peak-time 0.22 0.26 --rms-max 0.009"
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(coupled_plate_flicker_scan coupled_plate_kappa_step_decay
                     coupled_plate_flicker_laplacian coupled_plate_flicker_near_bodies
                     PROPERTIES TIMEOUT 300 LABELS validation)

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

# The same plate at 3 mm to 2 s, the case as it is (solid.mps.damping 0.5):
# the plate must not breathe, its two faces moving together (the RMS of the
# difference of their x-velocities after 0.3 s at most 0.027 m/s), and the
# force rows within 15% of their 20 ms mean at least 50% (docs/pressure.md,
# "The plate's breathing"). Measured (2026-12-04, eight jittered starts, one
# thread; the lattice start, one and two threads, in brackets): with the
# case's 0.5 0.011-0.018 m/s (0.012, 0.018) and 53-68% (61%, 60%); with the
# 0.1 it had before 0.038-0.077 m/s (0.091) and 42-50% (46%), the water beside
# the plate flickering to P = 0. The breathing band sits 1.5 times over the
# highest good run and 1.4 times under the lowest bad one; the force band at
# the edge of the bad runs, so a return of the breathing fails the first.
add_test(NAME coupled_plate_3mm_breathing
         COMMAND sh -c "${CMAKE_BINARY_DIR}/bin/coupler cases/dambreak_elastic_plate/case.yml --out ${CMAKE_BINARY_DIR}/test_out/plate3_breathing --quiet --set dp=0.003 --set end_time=2 && /usr/bin/python3 tests/coupler/check_plate_flicker.py ${CMAKE_BINARY_DIR}/test_out/plate3_breathing --max-breathing 0.027 --min-within15 0.5"
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
# 150 s alone on two threads with the water holding no tension (the default
# since 2026-12-06: 1.36 times the clamp's time on the 6 mm plate); over 600 s
# once in a ctest -j2 beside the other 3 mm plate test (two threads too) and
# a one-thread run, the threads' spinning barriers oversubscribed; as the
# other 3 mm test, 900 s.
set_tests_properties(coupled_plate_3mm_breathing PROPERTIES TIMEOUT 900 LABELS validation)

# coupled_plate_3mm_shifting_weight: the case's shifting along the gradient of
# (1 - r/re)^2 (fluid.shifting_weight: smooth; docs/pressure.md, "The particle
# shifting's weight") at its own 3 mm to 2 s, two threads, and the same with
# Eq. 3's weight (mps, the solver's default): the 2 ms force rows within 15% of
# their 20 ms mean. Eight jittered realisations (one thread): smooth 70-78%,
# Eq. 3's 53-68%; the lattice start on two threads reads 75% and 60%. The band
# of 68% lies above every realisation with Eq. 3's weight, so the smooth weight
# lost (or scaled wrongly toward the singular one) fails the first run; the
# second must fail it, which keeps the band from being one no run misses.
# Both runs keep the clamp after one PPE solve (fluid.tension_solves=0), the
# PPE the band was measured with: with the water holding no tension (the
# default since 2026-12-06) the smooth weight's lattice start read 63% once
# (eight jittered realisations one thread each: 75.6 +- 0.9%, against
# 72.0 +- 1.8% with the clamp), and Eq. 3's weight was not measured so.
add_test(NAME coupled_plate_3mm_shifting_weight
         COMMAND sh -c "${CMAKE_BINARY_DIR}/bin/coupler cases/dambreak_elastic_plate/case.yml --out ${CMAKE_BINARY_DIR}/test_out/plate3_smooth --quiet --set dp=0.003 --set end_time=2 --set output.interval=0.02 --set fluid.tension_solves=0 && /usr/bin/python3 tests/coupler/check_plate_flicker.py ${CMAKE_BINARY_DIR}/test_out/plate3_smooth --min-within15 0.68 && ${CMAKE_BINARY_DIR}/bin/coupler cases/dambreak_elastic_plate/case.yml --out ${CMAKE_BINARY_DIR}/test_out/plate3_mpsweight --quiet --set dp=0.003 --set end_time=2 --set fluid.shifting_weight=mps --set fluid.tension_solves=0 && ! /usr/bin/python3 tests/coupler/check_plate_flicker.py ${CMAKE_BINARY_DIR}/test_out/plate3_mpsweight --min-within15 0.68"
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(coupled_plate_3mm_shifting_weight PROPERTIES TIMEOUT 900 LABELS validation
                     ENVIRONMENT "OMP_NUM_THREADS=2")

# The elastic gate (issue 6) at a coarse spacing with each solid model to 0.2 s:
# the gate opens downstream to its first peak and closes again (bands and
# their justification in tests/coupler/gate_check.py).
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

# bench/plate_force_ensemble.py's split of the plate force's deviation into
# what the realisations share and what each has of its own, on synthetic runs
# whose two parts are known (docs/pressure.md, "What a run without noise
# could reach").
add_test(NAME bench_force_ensemble_split
         COMMAND /usr/bin/python3 tests/coupler/test_force_ensemble.py
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(bench_force_ensemble_split PROPERTIES TIMEOUT 60)

# bench/interior_zero.py's reading of the water around a zero (loaded water
# or the air's pressure) on lattices whose pressure is known (docs/pressure.md,
# "What a run without noise could reach").
add_test(NAME bench_interior_zero_neighbours
         COMMAND /usr/bin/python3 tests/fluid/test_interior_zero.py
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(bench_interior_zero_neighbours PROPERTIES TIMEOUT 60)
