# Validation of the fluid on the issue's two cases (docs/fluid.md), short
# enough for ctest (about 40 s in all on one core, Release):
#   fluid_valid_hydrostatic  cases/hydrostatic, dp = 10 mm, 2 s: bottom
#                            pressure within 3% of rho g h, max speed below
#                            1% of sqrt(g h), no particle out;
#   fluid_valid_dambreak     cases/dambreak, dp = 8 mm, to T = 3: front and
#                            height vs Martin & Moyce (tolerances justified in
#                            tests/fluid/check_dambreak.py and docs/fluid.md);
#   fluid_stable_dambreak    cases/dambreak, dp = 8 mm, 2 s (the water hits
#                            the right wall and sloshes back): finishes, no
#                            particle out, speeds finite;
#   fluid_ppe_scaling        cases/dambreak at 8 and 2 mm to 0.05 s: the PPE
#                            iterations stay flat with the default solver
#                            (tests/fluid/check_ppe_scaling.py).
set(FV_DIR ${CMAKE_CURRENT_LIST_DIR})
set(FV_OUT ${CMAKE_BINARY_DIR}/test_out/fluid_validation)
set(FV_RUN sh ${FV_DIR}/run_and_check.sh)
set(FV_SOLVER ${CMAKE_BINARY_DIR}/bin/fluid_solver)

# fluid_valid_hydrostatic: the bottom pressure against rho g (h - dp/2) (P = 0
# at the surface particles' centres, dp/2 below the water line: -1.67% of
# rho g h at 10 mm) within 0.5%: measured mean -0.05%, worst -0.08% over the
# 2 s (the MPS pressure noise), identical with 1 and 2 threads and with
# MPS_SIMD=sse2 (2026-12-02). A 3% band around rho g h (before) let a 1.3%
# error of the physics through.
add_test(NAME fluid_valid_hydrostatic
  COMMAND ${FV_RUN} ${FV_OUT}/hydrostatic ${FV_DIR}/check_hydrostatic.py --t-end 2
          --surface-dp 0.01 --p-tol 0.005
          -- ${FV_SOLVER} cases/hydrostatic/case.yml --set output.interval=0
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
# fluid_valid_dambreak: the 8 mm dam break to T = 3.1 in eight realisations,
# the case's lattice and seven jittered by 1e-3 dp (seeds 1-7, one thread:
# tests/fluid/scripts/dambreak_ensemble.sh), against Martin & Moyce; the
# bands hold the eight's means. One run is one draw (2026-12-03: a single
# run's speed band -3/+8% had 2 of 16 realisations outside it), and the mean
# of eight moves by sd / sqrt(8). Each band is a physical reading, then the
# mean (sd) of 32 realisations (2026-12-07, e172511, one thread; seeds 0-31)
# and how far the eight's mean sits from the band in its standard errors,
# then the faults (32 realisations each, the fault in place):
#  - front speed dZ/dT for T >= 1.4 within -3% / +8% of the measured 1.298:
#    after the release the front moves at the measured speed. +2.36% (2.15):
#    7.0 SE from -3%, 7.4 from +8%. Eq. 17's position 10% short reads
#    -6.14% (4.2 SE beyond -3%), Eq. 16's gravity 10% weak -4.24%. The fast
#    side is wider: the sheet's tip either leaves as spray (the front probe
#    falls back 1-2 dp) or stays and reads the sheet's own speed (docs/fluid.md);
#  - front against the measurements 17 ms later (--shift 0.2: the release
#    time of the experiment's diaphragm, docs/fluid.md): max 10% (8.89%, the
#    same in every realisation: the first point), mean 3.5% (2.31%, sd 0.28:
#    12 SE). Eq. 17's fault reads 3.80% (2.8 SE beyond), Eq. 16's 3.94%;
#  - front as measured: max 21% (17.90%, sd 0.34), mean 13.5% (11.21%, sd
#    0.55): the lead gained in the release, which does not shrink with
#    resolution;
#  - height at the left wall: max 11% (6.72%, sd 0.62), mean 3.6% (3.09%, sd
#    0.21: 6.9 SE); it converges with dp (11, 7, 4% at 8, 4, 2 mm in one run
#    each). 3.6% of the column's 0.146 m is 5 mm, two thirds of a spacing.
#    The pressure gradient of Eq. 19 10% weak reads 11.52% / 4.33% (sd 1.28
#    / 0.53): the mean's band catches it 3.9 SE out, the max's would not.
#    The band was 3.2% against a mean of 2.41% (sd 0.42, 16 realisations,
#    2026-12-03); the tank's walls slipping in Eq. 10 (caa798f, the default
#    since 2026-12-04; found by bisecting 16 realisations) moved the mean to
#    3.10% and halved its spread, 1 mm of the column's height, and left the
#    band 1.5 SE above it; the walls fixed read 3.14% (sd 0.94) on this
#    build, the clamp after one solve 3.08% (sd 0.11).
# Measured with tests/fluid/check_dambreak.py on 32 realisations:
#   OMP_NUM_THREADS=1 sh tests/fluid/scripts/dambreak_ensemble.sh build/bin/fluid_solver /tmp/dbe 32
add_test(NAME fluid_valid_dambreak
  COMMAND sh ${FV_DIR}/scripts/dambreak_ensemble.sh ${FV_SOLVER} ${FV_OUT}/dambreak 8
          --max-front-err 0.21 --mean-front-err 0.135 --speed-err 0.03 --speed-err-high 0.08
          --max-height-err 0.11 --mean-height-err 0.036
          --shift 0.2 --shifted-max-err 0.10 --shifted-mean-err 0.035
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
add_test(NAME fluid_stable_dambreak
  COMMAND ${FV_RUN} ${FV_OUT}/dambreak_2s ${FV_DIR}/check_stable.py --t-end 2
          -- ${FV_SOLVER} cases/dambreak/case.yml --set dp=0.008 --set end_time=2
             --set output.interval=0
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
add_test(NAME fluid_ppe_scaling
  COMMAND /usr/bin/python3 ${FV_DIR}/check_ppe_scaling.py ${FV_SOLVER} ${FV_OUT}/ppe_scaling
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
# The pressure of the 8 mm dam break must not flicker, whatever the output
# times, and the output times must not change the run (docs/pressure.md).
add_test(NAME fluid_pressure_flicker
  COMMAND sh ${FV_DIR}/scripts/flicker.sh ${FV_SOLVER} ${FV_OUT}/flicker
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
# fluid_ppe_terms: fluid_solver --dump-ppe's record of the PPE rhs's four
# parts and bench/ppe_terms.py's pressure of each: in still water they sum to
# the hydrostatic pressure and the density and divergence parts are small; on
# the 8 mm dam break the record reproduces the step log's count at P <= 0
# (the bands and their reasons in the script; docs/pressure.md, "The two
# halves of the mixed source").
add_test(NAME fluid_ppe_terms
  COMMAND /usr/bin/python3 ${FV_DIR}/test_ppe_terms.py ${FV_SOLVER} ${FV_OUT}/ppe_terms
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(fluid_ppe_terms PROPERTIES TIMEOUT 120)
# fluid_pressure_flicker_steps: the defaults (the tank's walls slipping in
# Eq. 10, fluid.divergence_walls = slip, docs/pressure.md, "Walls that slip
# in Eq. 10") on the 8 mm dam break to 0.3 s: the PPE rows at P <= 0 per step
# after 0.05 s at most 2.8% on average and at most 35 steps over 5%.
# Measured (2026-12-04, one thread): 1.79% and 15 steps; with the walls fixed
# (the default before) 3.92% and 69. Both bands sit about halfway.
add_test(NAME fluid_pressure_flicker_steps
  COMMAND ${FV_RUN} ${FV_OUT}/flicker_steps ${FV_DIR}/check_step_log.py
          --max-mean-share 0.028 --max-steps-over 0.05 35
          -- ${FV_SOLVER} cases/dambreak/case.yml --set dp=0.008 --set end_time=0.3
             --set output.interval=0 --set fluid.step_log=true
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
# fluid_dambreak_flicker_realisations: the 4 mm dam break to 0.3 s (snapshots
# every 0.02 s) in 16 jittered realisations (bench/flicker_ensemble.py, one
# thread), with the water holding no tension (fluid.tension_solves = 8, the
# default since 2026-12-06; docs/pressure.md, "Water that holds no tension")
# and close pairs read at half a spacing in Eq. 10 (fluid.divergence_floor,
# the default since 2026-12-07; "Pairs closer than half a spacing"): none of
# them with a snapshot after 0.05 s with more than 5% of the interior fluid
# at P = 0, the issue's target. Measured (2026-12-07, forty-third session,
# seeds 1-96): none of 96, the worst 3.1%; seeds 1-16 at most 2.9%, seed 16
# 2.6%. Without the floor (the forty-first and forty-second sessions' build)
# 1 of 96, seed 16 at 29.0%: a pair a long step brought to 0.32 dp at the
# right wall's foot asked for 290 kPa and threw a particle out at 26.9 m/s,
# whose CFL step held the flow in tension; that build allowed one such
# realisation here. The band is the target, 2.1 points above the worst of
# the 16 on this build; a floor missing from Eq. 10 fails it through seed 16.
# With the clamp after one solve 20 of 96 over 5% (5.1-10.8%), 7 of them
# among seeds 1-16, and fluid_ppe_terms checks the release directly.
add_test(NAME fluid_dambreak_flicker_realisations
  COMMAND sh -c "rm -rf '${FV_OUT}/flicker_realisations' && /usr/bin/python3 bench/flicker_ensemble.py --build '${CMAKE_BINARY_DIR}' --runs 16 --out '${FV_OUT}/flicker_realisations' --max-worst 5"
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
# fluid_dambreak_flicker_realisations_clamp: the same 16 realisations with the
# clamp after one solve (fluid.tension_solves = 0, the paper's 4.3 and the
# default before 2026-12-06): no snapshot after 0.05 s with more than 12% of
# the interior fluid at P = 0. The rules of Eq. 23's reference step and the
# free surface show in this flicker as they do not with the water holding no
# tension (docs/testing.md), so the clamp's test stays. On the fortieth
# session's build seeds 1-16 read at most 9.9% (seed 9; 96 seeds: at most
# 10.8%). Measured (2026-12-06, thirty-seventh session's build) over seeds 1-32: with fluid.kappa_step_decay_expansion 0.99 (the default) 4
# of 32 realisations have a snapshot over 5%, at 5.7-8.8%, none over 10%; with
# it off (0) 13 of 32, 7 of them at 13.7-49.9% (seed 12's 49.9% is most of the
# pool at P = 0 for a step); seeds 1-16 alone: 3 at 8.1-8.8% against 4 at
# 6.8-49.9%. The band sits between the two: 3 points above the worst with the
# setting, 1.7 below the smallest of the seven. Seeds 1-8 (this test's seeds
# before) were a good draw for the setting off: none over 5% there.
add_test(NAME fluid_dambreak_flicker_realisations_clamp
  COMMAND sh -c "rm -rf '${FV_OUT}/flicker_realisations_clamp' && /usr/bin/python3 bench/flicker_ensemble.py --build '${CMAKE_BINARY_DIR}' --runs 16 --out '${FV_OUT}/flicker_realisations_clamp' --set fluid.tension_solves=0 --max-worst 12"
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
# fluid_pressure_flicker_laplacian: the option pair of docs/pressure.md, "The
# divergence on the Laplacian's stencil" (fluid.divergence_stencil =
# laplacian, fluid.density_weight = quadratic), on the 8 mm dam break to 0.3 s:
# the PPE rows at P <= 0 per step after 0.05 s (the step log) at most 2.5% on
# average and at most 5 steps over 5%. Measured (2026-12-04, one thread):
# 1.43% and 1 step (worst 5.9%); the defaults 3.92% and 69 steps, the
# divergence on the gradient's stencil alone (fluid.density_weight quadratic)
# 3.01% and 45. The mean's band sits between; the count's holds the
# impact's one step with room for a build's other rounding.
add_test(NAME fluid_pressure_flicker_laplacian
  COMMAND ${FV_RUN} ${FV_OUT}/flicker_laplacian ${FV_DIR}/check_step_log.py
          --max-mean-share 0.025 --max-steps-over 0.05 5
          -- ${FV_SOLVER} cases/dambreak/case.yml --set dp=0.008 --set end_time=0.3
             --set output.interval=0 --set fluid.step_log=true
             --set fluid.divergence_stencil=laplacian --set fluid.density_weight=quadratic
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
# fluid_still_water_laplacian_10s: the same pair holds still water for 10 s,
# the bands of fluid_still_water_10s. Measured (2026-12-04): largest speed
# 9.1e-4 m/s (it grows from 1.6e-4 at 2 s and levels off after 7 s), bottom
# pressure 2893.5 Pa, std 0.5 Pa. The divergence on the Laplacian's stencil
# with Eq. 7's weight fails: 0.07-0.77 m/s after 5-6 s, whether Eq. 23 goes
# to the pressure or (a trial) to the positions, with the dead band at
# 0.0005 or 0.001 or kappa at 0.005 or 0.02.
add_test(NAME fluid_still_water_laplacian_10s
  COMMAND ${FV_RUN} ${FV_OUT}/still_laplacian_10s ${FV_DIR}/check_hydrostatic.py --t-end 10
          --surface-dp 0.01 --p-tol 0.005
          -- ${FV_SOLVER} cases/hydrostatic/case.yml --set end_time=10 --set output.interval=0
             --set fluid.divergence_stencil=laplacian --set fluid.density_weight=quadratic
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
# fluid_still_water_10s: still water for 10 s with Eq. 23's density error
# from the quadratic weight (fluid.density_weight = quadratic): the same
# bands as fluid_valid_hydrostatic (bottom pressure within 0.5% of rho g
# (h - dp/2), speeds under 1% of sqrt(g h) = 0.017 m/s) held for 10 s.
# Measured (2026-12-03): bottom pressure -0.01% mean, -0.07% worst; largest
# speed 2.8e-4 m/s; volume +0.01% (bench/water_volume.py). The paper's
# weight (the default) fails both after 3 s: the lattice pairs up, the water
# expands 2.4% and the bottom pressure reads +1.3% (mean), speeds reach
# 0.65 m/s (docs/pressure.md, "Still water, 10 s").
add_test(NAME fluid_still_water_10s
  COMMAND ${FV_RUN} ${FV_OUT}/still_10s ${FV_DIR}/check_hydrostatic.py --t-end 10
          --surface-dp 0.01 --p-tol 0.005
          -- ${FV_SOLVER} cases/hydrostatic/case.yml --set end_time=10 --set output.interval=0
             --set fluid.density_weight=quadratic
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
# fluid_still_water_default_10s, fluid_still_water_short_steps: the same
# bands with the defaults, Eq. 7's weight and fluid.density_dead_band 0.0005,
# at the case's 1 ms steps for 10 s and at 0.2 ms steps (a correction rate of
# 50/s, the fine runs' regime) for 4 s, the pressure judged after 0.5 s there
# (leaving the hydrostatic guess rings to +3% for 0.06 s at that step).
# Measured (2026-12-03, band 0.0005): 1 ms, bottom pressure -0.06% mean,
# -0.07% worst, std 0.14 Pa, largest speed 1.2e-3 m/s (at 0.01 s), under
# 1e-4 m/s after 1 s; 0.2 ms, -0.05% mean and worst after 0.5 s, std
# 0.03 Pa, largest speed 3.2e-3 m/s (0.01 s), 2.7e-4 after 1 s; volume
# -0.01% in 10 s at either step (bench/water_volume.py). With the band at 0
# (Eq. 23 as printed) both fail: at 1 ms the water moves at 0.26 m/s by
# 7.8 s and its bottom pressure reads +1.2% on average; at 0.2 ms 0.85 m/s,
# +1.7% (docs/pressure.md, "A sixth remedy").
add_test(NAME fluid_still_water_default_10s
  COMMAND ${FV_RUN} ${FV_OUT}/still_default_10s ${FV_DIR}/check_hydrostatic.py --t-end 10
          --surface-dp 0.01 --p-tol 0.005
          -- ${FV_SOLVER} cases/hydrostatic/case.yml --set end_time=10 --set output.interval=0
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
add_test(NAME fluid_still_water_short_steps
  COMMAND ${FV_RUN} ${FV_OUT}/still_short_steps ${FV_DIR}/check_hydrostatic.py --t-end 4
          --surface-dp 0.01 --p-tol 0.005 --t-start 0.5
          -- ${FV_SOLVER} cases/hydrostatic/case.yml --set end_time=4 --set output.interval=0
             --set fluid.dt_max=2e-4
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(fluid_valid_hydrostatic fluid_valid_dambreak fluid_stable_dambreak
  fluid_ppe_scaling fluid_pressure_flicker fluid_pressure_flicker_steps
  fluid_dambreak_flicker_realisations
  fluid_pressure_flicker_laplacian
  fluid_still_water_laplacian_10s fluid_still_water_10s
  fluid_still_water_default_10s fluid_still_water_short_steps
  PROPERTIES LABELS validation TIMEOUT 180 ENVIRONMENT "OMP_NUM_THREADS=1")

# Standalone runs bind their OpenMP threads to CPUs unless the user (or the
# coupler) set OMP_PLACES / OMP_PROC_BIND (common/mps_omp.h).
add_test(NAME fluid_cpu_binding
  COMMAND ${CMAKE_COMMAND} -DSOLVER=${FV_SOLVER} -DOUT=${FV_OUT}/binding
          -P ${FV_DIR}/scripts/check_binding.cmake
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(fluid_cpu_binding PROPERTIES LABELS integration TIMEOUT 60)
add_test(NAME fluid_simd_paths
  COMMAND ${CMAKE_COMMAND} -DSOLVER=${FV_SOLVER} -DOUT=${FV_OUT}/simd
          -P ${FV_DIR}/scripts/check_simd.cmake
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(fluid_simd_paths PROPERTIES LABELS integration TIMEOUT 60)
