# Bad input to the fluid solver and to the coupler: one clear line naming the
# file/key and the problem, and a non-zero exit (tests/expect_fail.sh).
function(fluid_expect_fail name pattern)
  add_test(NAME ${name}
           COMMAND sh ${CMAKE_SOURCE_DIR}/tests/expect_fail.sh "${pattern}" ${ARGN}
           WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
  set_tests_properties(${name} PROPERTIES TIMEOUT 30 LABELS unit)
endfunction()

set(FS ${CMAKE_BINARY_DIR}/bin/fluid_solver)
set(DB cases/dambreak/case.yml)
set(OUT --out ${CMAKE_BINARY_DIR}/test_out/bad_input)
fluid_expect_fail(fluid_bad_missing_file "cases/no_such_case.yml: cannot open: No such file"
                  ${FS} cases/no_such_case.yml ${OUT})
fluid_expect_fail(fluid_bad_unknown_key "--set fluid.rhoo=1: fluid.rhoo = 1: unknown key; did you mean fluid.rho"
                  ${FS} ${DB} ${OUT} --set fluid.rhoo=1)
fluid_expect_fail(fluid_bad_negative_dp "dp = -0.004: must be > 0"
                  ${FS} ${DB} ${OUT} --set dp=-0.004)
fluid_expect_fail(fluid_bad_block_outside "fluid.blocks.0.x1 = 0.7: the water block lies outside the tank"
                  ${FS} ${DB} ${OUT} --set fluid.blocks.0.x1=0.7)
fluid_expect_fail(fluid_bad_end_time_zero "end_time = 0: must be in \\(0, 10000\\]"
                  ${FS} ${DB} ${OUT} --set end_time=0)
fluid_expect_fail(fluid_bad_cfl "fluid.dt_min = 0.01: the CFL condition \\(Eq. 52\\) needs dt <="
                  ${FS} ${DB} ${OUT} --set fluid.dt_min=0.01 --set fluid.dt_max=0.02)
fluid_expect_fail(fluid_bad_coarse_cell "fluid.ppe_coarse_cell = 0.5: must be in \\[1, 100\\]"
                  ${FS} ${DB} ${OUT} --set fluid.ppe_coarse_cell=0.5)
fluid_expect_fail(fluid_bad_unknown_key_in_file "tests/fluid/bad_key.yml:6: fluid.bogus = 1: unknown key"
                  ${FS} tests/fluid/bad_key.yml ${OUT})
# --dump-ppe N (the PPE of the N-th step, docs/output.md): a step number or nothing;
# it read 'abc' as step 0 and wrote an empty system, exit 0
fluid_expect_fail(fluid_bad_dump_ppe_step "--dump-ppe '12x': not a step number"
                  ${FS} ${DB} ${OUT} --dump-ppe 12x)
# releasing the rows under tension needs the clamp it replaces (fluid.tension_solves)
fluid_expect_fail(fluid_bad_tension_without_clamp "fluid.tension_solves: 2 more solves .* fluid.clamp_negative is false"
                  ${FS} ${DB} ${OUT} --set fluid.clamp_negative=false --set fluid.tension_solves=2)
# ... but without the clamp and without the key, the default's re-solves are
# off, not refused: the run goes, and its step log shows no re-solve
add_test(NAME fluid_no_clamp_no_tension_solves
  COMMAND sh -c "rm -rf '${CMAKE_BINARY_DIR}/test_out/no_clamp' && '${FS}' ${DB} --out '${CMAKE_BINARY_DIR}/test_out/no_clamp' --quiet --set dp=0.008 --set end_time=0.02 --set output.interval=0 --set fluid.step_log=true --set fluid.clamp_negative=false && /usr/bin/python3 -c \"import csv, sys; r = list(csv.DictReader(l for l in open(sys.argv[1]) if not l.startswith('#'))); s = sum(int(x['tension_solves']) for x in r); print(len(r), 'steps,', s, 're-solves'); sys.exit(not (len(r) > 5 and s == 0))\" '${CMAKE_BINARY_DIR}/test_out/no_clamp/fluid_steps.csv'"
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(fluid_no_clamp_no_tension_solves PROPERTIES TIMEOUT 60 LABELS unit)
fluid_expect_fail(coupler_bad_negative_dp "coupler: .*dp = -0.004: must be > 0"
                  ${CMAKE_BINARY_DIR}/bin/coupler ${DB} ${OUT} --set dp=-0.004)
fluid_expect_fail(coupler_bad_no_scene "neither a fluid .* nor a solid"
                  ${CMAKE_BINARY_DIR}/bin/coupler tests/fluid/empty_case.yml ${OUT})
# a cross-key error is caught by the coupler itself and names the --set, not the
# resolved copy the solvers read
fluid_expect_fail(coupler_bad_block_outside "coupler: --set fluid.blocks.0.x1=0.7: fluid.blocks.0.x1 = 0.7: the water block lies outside the tank"
                  ${CMAKE_BINARY_DIR}/bin/coupler ${DB} ${OUT} --set fluid.blocks.0.x1=0.7)
# An unknown MPS_SIMD (a misspelt request for the portable paths) is refused
# by every program, the coupler first.
fluid_expect_fail(coupler_bad_simd_env "coupler: environment: MPS_SIMD=sse4: unknown value"
                  ${CMAKE_COMMAND} -E env MPS_SIMD=sse4 ${CMAKE_BINARY_DIR}/bin/coupler ${DB} ${OUT}
                  --set dp=0.01 --set end_time=0.001)
fluid_expect_fail(fluid_bad_simd_env "fluid_solver: environment: MPS_SIMD=sse4: unknown value"
                  ${CMAKE_COMMAND} -E env MPS_SIMD=sse4 ${FS} ${DB} ${OUT}
                  --set dp=0.01 --set end_time=0.001)
# No silent choices (issue 23): --out is required (no ./out to mix runs in),
# and an option naming a solver the case does not need is refused.
fluid_expect_fail(coupler_bad_no_out "^coupler: missing --out DIR"
                  ${CMAKE_BINARY_DIR}/bin/coupler ${DB})
fluid_expect_fail(fluid_bad_no_out "^fluid_solver: missing --out DIR"
                  ${FS} ${DB})
fluid_expect_fail(coupler_bad_solid_without_solid "coupler: --solid solid_solver: cases/dambreak/case.yml has no solid \\(solid.bodies\\)"
                  ${CMAKE_BINARY_DIR}/bin/coupler ${DB} ${OUT} --solid solid_solver)
fluid_expect_fail(coupler_bad_fluid_without_fluid "coupler: --fluid fluid_solver: cases/cantilever_beam/case.yml has no fluid"
                  ${CMAKE_BINARY_DIR}/bin/coupler cases/cantilever_beam/case.yml ${OUT} --fluid fluid_solver)
fluid_expect_fail(coupler_bad_external_unneeded "coupler: --external solid: cases/dambreak/case.yml has no solid"
                  ${CMAKE_BINARY_DIR}/bin/coupler ${DB} ${OUT} --external solid)
# The side walls' Stokes layers must be thin against the breadth: layers that
# filled it (a breadth of 1e-300 m) made an infinite inertia and a PPE with a
# non-finite residual, reported as a solver failure.
fluid_expect_fail(fluid_bad_side_walls_thick_layers
                  "^fluid_solver: input: fluid.side_walls.breadth = 0.005 m: the side walls' boundary layers, delta = sqrt\\(2 nu / omega\\) = 0.00512 m at a period of 1.64656 s, fill it; the model holds while delta < breadth / 2$"
                  ${FS} cases/sloshing_low/case.yml ${OUT} --quiet --set dp=0.004
                  --set end_time=0.01 --set fluid.side_walls.breadth=0.005)
