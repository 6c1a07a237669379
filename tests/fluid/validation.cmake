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
# Bands of fluid_valid_dambreak (8 mm to T = 3.1), each a physical reading
# plus the measured spread. Spread: 1 and 2 threads, MPS_SIMD=sse2 and auto
# (AVX-512) differ by at most 0.7 mm in the front and 0.4 mm in the height
# (0.1-0.2 points of every error below), so the margins are what a change
# of the numerics may move (about a point), not noise. Measured on
# 2026-12-02 (this build; docs/fluid.md has the resolution study):
#  - front speed dZ/dT for T >= 1.4 within 3% of the measured 1.298: after
#    the release the front moves at the measured speed (-0.9%, +2.8%, +0.9%
#    at 8, 4, 2 mm in the study). Its slope is set by the front's sparse tip
#    particles, and how they are classified moves it by points: with the
#    spray left on the free surface (fluid.surface_scan_density 0.9, the
#    default since 2026-12-03) +2.2% (one thread) and +2.1% (two), -0.5%
#    before; at 4 mm +2.9% against +8.0% before (one thread). The band was
#    1.5% on the earlier build's -0.5% alone; 3% holds the measured spread
#    of these numerics changes and still catches Eq. 17's position 10% short
#    (-9.2%). The other measures below improved with that change.
#    On the fast side the band is 8% (2026-12-03, the density dead band):
#    the measure's noise is one-sided. Until T = 1.9 the front of runs with
#    the band at 0, 0.0001, 0.0002, 0.0003, 0.0005 and 0.001 n0 agrees to
#    0.1 mm; then the sheet's tip thins, and its leading particle either
#    leaves as spray (the front probe drops it and falls back 1-2 dp, once)
#    or stays. Read at the table points the six give +2.2, +6.8, +0.3, +0.5,
#    +6.0 and +0.0%: the runs whose tip stays read the sheet's own speed,
#    up to +7%. The slow side keeps 3%, which the fault above crosses;
#  - front against the measurements 17 ms later (--shift 0.2: the release
#    time of the experiment's diaphragm, docs/fluid.md): max 10% (measured
#    8.9%; 8.9% since the spray change), mean 3.5% (2.8%; 2.3%);
#  - front as measured: max 21% (19.4%; 18.0%), mean 13.5% (12.0%; 11.5%):
#    the lead gained in the release, which does not shrink with resolution;
#  - height at the left wall: max 11% (9.6%; 9.1%), mean 4.5% (3.4%; 2.7%):
#    it converges with dp (11, 7, 4% at 8, 4, 2 mm).
# What they catch (measured with the fault in place): the pressure gradient
# of Eq. 19 10% weak moves the height to 14.0% / 5.5% and the shifted front
# mean to 4.5%; Eq. 17's position 10% short moves the speed to -9.2%. The old
# bands (25/15% front, 10% speed, 18/10% height) passed both.
add_test(NAME fluid_valid_dambreak
  COMMAND ${FV_RUN} ${FV_OUT}/dambreak ${FV_DIR}/check_dambreak.py
          --max-front-err 0.21 --mean-front-err 0.135 --speed-err 0.03 --speed-err-high 0.08
          --max-height-err 0.11 --mean-height-err 0.045
          --shift 0.2 --shifted-max-err 0.10 --shifted-mean-err 0.035
          -- ${FV_SOLVER} cases/dambreak/case.yml --set dp=0.008 --set end_time=0.27
             --set output.interval=0
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
  fluid_ppe_scaling fluid_pressure_flicker fluid_still_water_10s
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
