# Checkpoint and restart (docs/restart.md, issue 19): a run to T against the
# same run stopped at its checkpoint after STOP and restarted from the one at
# HALF (so the rows and snapshots between HALF and STOP are rewritten, not
# repeated). Every probes.csv row, every field of every snapshot and the XDMF
# index must be bit-identical (tests/common/restart_check.py). Coarse and
# short: a few seconds each (6-23 s under a load of 8 in Release; the
# coupled ones are left out of CI's sanitizer run, .ci/run).
set(RS_CHECK /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/restart_check.py)
set(RS_OUT ${CMAKE_BINARY_DIR}/test_out/restart)

# the fluid alone: dam break at dp = 10 mm to 0.2 s (the front runs over the
# dry floor, the Verlet list is rebuilt many times), checkpoints every 0.05 s
add_test(NAME restart_fluid_dambreak
  COMMAND ${RS_CHECK} ${RS_OUT}/fluid 0.1 0.15 $<TARGET_FILE:fluid_solver>
          cases/dambreak/case.yml --set dp=0.01 --set end_time=0.2 --set output.interval=0.05
          --set output.checkpoint_interval=0.05
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
# the solid alone: the fracture collision at dp = 25 mm to 0.4 s, restarted
# at 0.2 s with 3 bonds broken and the bodies in contact (--require)
add_test(NAME restart_solid_fracture
  COMMAND ${RS_CHECK} ${RS_OUT}/solid 0.2 0.3 $<TARGET_FILE:solid_solver>
          cases/fracture_collision/case.yml --set dp=0.025 --set end_time=0.4
          --set output.interval=0.05 --set output.checkpoint_interval=0.1
          --require broken_bonds
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(restart_fluid_dambreak restart_solid_fracture PROPERTIES
  TIMEOUT 60 LABELS integration)
# coupled (explicit scheme): the dam break on the elastic plate at 6 mm to
# 0.2 s (the water reaches the plate at about 0.12 s), checkpoints every
# 0.05 s; every process restarts from its own checkpoint of the same number
add_test(NAME restart_coupled_plate
  COMMAND ${RS_CHECK} ${RS_OUT}/plate 0.1 0.15 $<TARGET_FILE:coupler>
          cases/dambreak_elastic_plate/case.yml --set dp=0.006 --set end_time=0.2
          --set output.interval=0.05 --set output.checkpoint_interval=0.05
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
# the same run with the coupler killed (SIGKILL) once a checkpoint at or
# after 0.1 s exists: both solvers must exit by themselves within 10 s (they
# do in about 0.1 s), and a plain --restart must finish the run bit for bit
add_test(NAME restart_coupled_plate_kill
  COMMAND ${RS_CHECK} ${RS_OUT}/plate_kill 0.1 kill $<TARGET_FILE:coupler>
          cases/dambreak_elastic_plate/case.yml --set dp=0.006 --set end_time=0.2
          --set output.interval=0.05 --set output.checkpoint_interval=0.05
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
# the same with the pressure options of docs/pressure.md ("Spray and
# tension"): fluid.kappa_step_decay carries the last step's reference step
# from one step to the next, so the checkpoint must hold it. Restarted from
# the checkpoint at 0.1303 s, in the steps after the impact (0.128 s) where
# the CFL step drops and the decay is acting: a restart that forgot it fails
# here (probes differ from row 66), at 0.1 s it would not be seen. Ends at
# 0.19 s so that the checkpoint restarted from is still among the last two.
add_test(NAME restart_coupled_plate_pressure_options
  COMMAND ${RS_CHECK} ${RS_OUT}/plate_popt 0.131 0.16 $<TARGET_FILE:coupler>
          cases/dambreak_elastic_plate/case.yml --set dp=0.006 --set end_time=0.19
          --set output.interval=0.05 --set output.checkpoint_interval=0.0325
          --set fluid.kappa_step_decay=0.95 --set fluid.surface_scan_density=0.9
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
# coupled with the TLSPH solid: the elastic gate at 2.5 mm to 0.08 s
add_test(NAME restart_coupled_gate_tlsph
  COMMAND ${RS_CHECK} ${RS_OUT}/gate 0.04 0.06 $<TARGET_FILE:coupler>
          cases/elastic_gate/case.yml --set dp=0.0025 --set end_time=0.08
          --set output.interval=0.02 --set output.checkpoint_interval=0.02
          --solid "solid_solver --model tlsph"
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(restart_coupled_plate restart_coupled_plate_kill restart_coupled_gate_tlsph
  restart_coupled_plate_pressure_options PROPERTIES TIMEOUT 120 LABELS integration)
# coupled with the Python modal solid (its own checkpoint format): the plate in
# water of the coupler tests to 0.2 s, restarted at 0.1 s
add_test(NAME restart_coupled_python_solid
  COMMAND ${RS_CHECK} ${RS_OUT}/python 0.1 0.15 $<TARGET_FILE:coupler>
          tests/coupler/plate_in_water.yml --set end_time=0.2 --set output.interval=0.05
          --set output.checkpoint_interval=0.05
          --solid "/usr/bin/python3 solid_solver/python/modal_beam_solid.py"
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(restart_coupled_python_solid PROPERTIES TIMEOUT 120 LABELS integration)

# Implicit coupling (coupling.scheme: implicit): the plate of
# restart_coupled_plate, with the iteration log on, so iterations.csv (every
# iteration's change, displacement from the initial interface and factor)
# and summary.json's iteration counts must match too. After a restart the
# coupler's history must be the checkpoint's: the displacement reference
# (READY then reports the positions at the restart), the predictor's last
# step, Aitken's factor, IQN-ILS's columns of the last `reuse` steps and the
# counters. reuse 8, not the default 2: before the impact a step makes a
# column only when it takes 3 iterations, and at 2 none is left at 0.1 s
# (the test then passed with the columns not restored: checked); at 8 the
# step after the restart uses one. Probe rows every 3 ms, so
# the checkpoint at 0.1 s falls inside a probe interval (the load integral
# and the mean iterations of the row are carried over). Each fails with that part
# of the history not restored (docs/restart.md, "Proof"). 2-3 s per run here.
# Aitken runs the default solid predictor (the last step's loads come back from
# the checkpoint), IQN-ILS the extrapolating one (the last step's start and
# length come back), so each predictor's part of the history is proven.
set(predictor_aitken solid)
set(predictor_iqn_ils extrapolate)
foreach(accel aitken iqn_ils)
  add_test(NAME restart_coupled_plate_implicit_${accel}
    COMMAND ${RS_CHECK} ${RS_OUT}/plate_implicit_${accel} 0.1 0.15 $<TARGET_FILE:coupler>
            cases/dambreak_elastic_plate/case.yml --set dp=0.006 --set end_time=0.2
            --set output.interval=0.05 --set output.checkpoint_interval=0.05
            --set coupling.scheme=implicit --set coupling.implicit.acceleration=${accel}
            --set coupling.implicit.reuse=8 --set coupling.implicit.log=true
            --set coupling.implicit.predictor=${predictor_${accel}}
            --set output.probe_interval=0.003
    WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
endforeach()
# the Python modal solid under implicit coupling (its rollback, and its
# checkpoint rewritten by each iteration of the step, PROTOCOL.md 6): at the
# tolerance 0.01 the checkpoint step ending at 0.05 s takes two iterations
# (at the default 0.1 every checkpoint step takes one, and a solid numbering
# each iteration's checkpoint as a new one passes: checked with the
# extrapolating predictor; the solid predictor sends the solid two ADVANCEs
# in every step, its prediction and the first iteration)
add_test(NAME restart_coupled_python_solid_implicit
  COMMAND ${RS_CHECK} ${RS_OUT}/python_implicit 0.1 0.15 $<TARGET_FILE:coupler>
          tests/coupler/plate_in_water.yml --set end_time=0.2 --set output.interval=0.05
          --set output.checkpoint_interval=0.05 --set coupling.scheme=implicit
          --set coupling.implicit.log=true --set coupling.implicit.tolerance=0.01
          --solid "/usr/bin/python3 solid_solver/python/modal_beam_solid.py"
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(restart_coupled_plate_implicit_aitken restart_coupled_plate_implicit_iqn_ils
  restart_coupled_python_solid_implicit PROPERTIES TIMEOUT 120 LABELS integration)
# a coupler checkpoint of an implicit run without the implicit history (as
# builds before it wrote them: tests/common/ckpt_cut.py) is refused with one
# line, exit 2, before any solver starts
add_test(NAME restart_bad_implicit_no_history
  COMMAND sh -c "rm -rf \"$1\" && \"$0\" tests/coupler/plate_in_water.yml --out \"$1\" --quiet --set end_time=0.1 --set output.interval=0 --set coupling.scheme=implicit --set output.checkpoint_interval=0.05 --stop-at 0.05 && /usr/bin/python3 tests/common/ckpt_cut.py \"$1\"/checkpoint/coupler_000001.ckpt coupler && sh tests/expect_fail.sh 'coupler_000001.ckpt: holds no history of the implicit coupling' \"$0\" --restart \"$1\""
          $<TARGET_FILE:coupler> ${RS_OUT}/implicit_old
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(restart_bad_implicit_no_history PROPERTIES TIMEOUT 60 LABELS integration)
# a solver's checkpoint damaged (one bit of solid_000001.ckpt flipped): the
# solid answers ERROR "input: ...", and the coupler must keep that status
# (exit 2, its line "coupler: input: solid solver: input: ..."), as for any
# input error of a solver that is not one of its case keys
add_test(NAME restart_bad_solver_checkpoint_damaged
  COMMAND sh -c "rm -rf \"$1\" && \"$0\" tests/coupler/plate_in_water.yml --out \"$1\" --quiet --set end_time=0.1 --set output.interval=0 --set output.checkpoint_interval=0.05 --stop-at 0.05 && /usr/bin/python3 -c \"import sys; p = sys.argv[1]; b = bytearray(open(p, 'rb').read()); b[200] ^= 1; open(p, 'wb').write(b)\" \"$1\"/checkpoint/solid_000001.ckpt && { \"$0\" --restart \"$1\" 2>\"$1.err\"; rc=$?; test $rc -eq 2 && grep -q '^coupler: input: solid solver: input: .*solid_000001.ckpt: checkpoint damaged' \"$1.err\"; }"
          $<TARGET_FILE:coupler> ${RS_OUT}/solver_damaged
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(restart_bad_solver_checkpoint_damaged PROPERTIES TIMEOUT 60 LABELS integration)
# the same without the last step's loads, which the solid predictor (the
# default coupling.implicit.predictor) starts the next step from: cut after
# the acceleration's last block, as builds before the predictor wrote it
add_test(NAME restart_bad_implicit_no_loads
  COMMAND sh -c "rm -rf \"$1\" && \"$0\" tests/coupler/plate_in_water.yml --out \"$1\" --quiet --set end_time=0.1 --set output.interval=0 --set coupling.scheme=implicit --set output.checkpoint_interval=0.05 --stop-at 0.05 && /usr/bin/python3 tests/common/ckpt_cut.py \"$1\"/checkpoint/coupler_000001.ckpt accel.W && sh tests/expect_fail.sh 'coupler_000001.ckpt: holds no loads of the last step for the solid predictor' \"$0\" --restart \"$1\""
          $<TARGET_FILE:coupler> ${RS_OUT}/implicit_no_loads
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(restart_bad_implicit_no_loads PROPERTIES TIMEOUT 60 LABELS integration)

mps_add_test(test_ckpt SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_ckpt.c LABELS unit TIMEOUT 30)

# A solver checkpoint of a build with one particle field fewer (the fluid's
# held rows, ppe_held, 2026-12-07; the solid's rotation rate, omega, stands
# for any of its fields): refused, naming the file and the block, coupled
# (the solver's CONFIG restart) and alone (--restart). who: the line's start,
# the program that prints it; solver: fluid or solid, whose checkpoint is cut;
# block: the block dropped, the next block named in its place
function(restart_older_build name program who solver block)
  add_test(NAME restart_bad_${name}_checkpoint_older_build
    COMMAND sh -c "o=\"$1\"; shift; rm -rf \"$o\" && \"$0\" \"$@\" --out \"$o\" --quiet --set end_time=0.1 --set output.interval=0 --set output.checkpoint_interval=0.05 --stop-at 0.05 && /usr/bin/python3 tests/common/ckpt_cut.py \"$o\"/checkpoint/${solver}_000001.ckpt ${block} --only && { \"$0\" --restart \"$o\" 2>\"$o.err\"; rc=$?; test $rc -eq 2 && grep -q \"^${who}: .*${solver}_000001.ckpt: checkpoint: block '.*' where '${block}' should be\" \"$o.err\"; }"
            ${program} ${RS_OUT}/${name}_older ${ARGN}
    WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
  set_tests_properties(restart_bad_${name}_checkpoint_older_build PROPERTIES TIMEOUT 60
    LABELS integration)
endfunction()
restart_older_build(fluid $<TARGET_FILE:coupler> "coupler: input: fluid solver: input"
                    fluid ppe_held tests/coupler/plate_in_water.yml)
restart_older_build(fluid_alone $<TARGET_FILE:fluid_solver> "fluid_solver: input"
                    fluid ppe_held cases/dambreak/case.yml --set dp=0.02)
restart_older_build(solid $<TARGET_FILE:coupler> "coupler: input: solid solver: input"
                    solid omega tests/coupler/plate_in_water.yml)
restart_older_build(solid_alone $<TARGET_FILE:solid_solver> solid_solver
                    solid omega cases/fracture_collision/case.yml --set dp=0.025)

# A restart with other arithmetic than its checkpoint's (another thread count
# for the fluid, its portable paths, a checkpoint of a build that recorded
# none) goes on and says so in one note line and summary.json; with the
# same arithmetic it says nothing and is the run bit for bit; the solid,
# whose run no thread count or path changes, says nothing either and is the
# run with one thread and with the portable paths (docs/restart.md, "Other
# arithmetic"). The solid's case is the fracture collision at 10 mm, 5000
# particles: above SOLID_MPS_OMP_MIN (4096), so that its loops run on both
# threads, and restarted at 0.1 s before its bonds break (0.15-0.16 s) and
# its bodies touch (about 9 s in Release under a load of 2; left out of CI's
# sanitizer run, .ci/run)
add_test(NAME restart_arith_fluid
  COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/restart_arith.py ${RS_OUT}/arith_fluid
          0.1 fluid yes $<TARGET_FILE:fluid_solver> cases/dambreak/case.yml --set dp=0.01
          --set end_time=0.2 --set output.interval=0.05 --set output.checkpoint_interval=0.05
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
add_test(NAME restart_arith_solid
  COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/restart_arith.py ${RS_OUT}/arith_solid
          0.1 solid no $<TARGET_FILE:solid_solver> cases/fracture_collision/case.yml
          --set dp=0.01 --set end_time=0.2 --set output.interval=0.05
          --set output.checkpoint_interval=0.05
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
# coupled: the fluid's note reaches the user through the coupler, and its
# summary records it
add_test(NAME restart_arith_coupled
  COMMAND sh -c "o=\"$1\"; rm -rf \"$o\" && OMP_NUM_THREADS=2 \"$0\" tests/coupler/plate_in_water.yml --out \"$o\" --quiet --set end_time=0.1 --set output.interval=0 --set output.checkpoint_interval=0.05 --stop-at 0.05 && OMP_NUM_THREADS=1 \"$0\" --restart \"$o\" --quiet 2>\"$o.err\" && grep -q '^fluid_solver: note: .*fluid_000001.ckpt was written with other arithmetic (threads 2 -> 1' \"$o.err\" && grep -q '\"arith_differs\": *\"threads 2 -> 1\"' \"$o\"/fluid_summary.json"
          $<TARGET_FILE:coupler> ${RS_OUT}/arith_coupled
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(restart_arith_fluid restart_arith_solid restart_arith_coupled PROPERTIES
  TIMEOUT 120 LABELS integration)

# Bad restarts: one clear line, exit 2 (tests/expect_fail.sh)
set(RS_FAIL sh ${CMAKE_SOURCE_DIR}/tests/expect_fail.sh)
function(restart_bad name pattern)
  add_test(NAME restart_bad_${name} COMMAND ${RS_FAIL} "${pattern}" ${ARGN}
           WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
  set_tests_properties(restart_bad_${name} PROPERTIES TIMEOUT 30 LABELS integration)
endfunction()
restart_bad(no_checkpoint "no checkpoints" $<TARGET_FILE:fluid_solver>
            --restart ${RS_OUT}/no_such_run)
restart_bad(case_file "takes no case file" $<TARGET_FILE:solid_solver>
            --restart ${RS_OUT}/solid/cut cases/fracture_collision/case.yml)
restart_bad(set_other "a restart takes only --set end_time" $<TARGET_FILE:coupler>
            --restart ${RS_OUT}/plate/cut --set dp=0.01)
restart_bad(from_alone "--from needs --restart" $<TARGET_FILE:fluid_solver>
            cases/dambreak/case.yml --out ${RS_OUT}/bad --from 0.1)
# a solid without caps=checkpoint is refused when the case asks for checkpoints
# (its own and the fluid's lines follow the coupler's: grep, not expect_fail)
add_test(NAME restart_refuses_solid_without_checkpoint
  COMMAND sh -c "\"$0\" tests/coupler/plate_in_water.yml --out \"$1\" --quiet --solid fake_solid --set output.checkpoint_interval=0.1 2>\"$1.err\"; rc=$?; test $rc -eq 2 && grep -q '^coupler: input: .*this solid solver cannot checkpoint (its HELLO declares no caps=checkpoint)' \"$1.err\""
          $<TARGET_FILE:coupler> ${RS_OUT}/nockpt
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(restart_refuses_solid_without_checkpoint PROPERTIES TIMEOUT 60
  LABELS integration)
