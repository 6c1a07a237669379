# fluid_cpu_binding: a standalone run on 2 threads binds them to CPUs (the
# summary says so), and leaves the binding to OMP_PROC_BIND when it is set.
# usage: cmake -DSOLVER=... -DOUT=... -P check_binding.cmake (from the source root)
foreach(mode bound user)
  set(out ${OUT}/${mode})
  file(REMOVE_RECURSE ${out})
  if(mode STREQUAL "bound")
    set(envs OMP_NUM_THREADS=2)
    set(want "\"cpu_binding\": \"2 threads bound to")
  else()
    set(envs OMP_NUM_THREADS=2 OMP_PROC_BIND=close)
    set(want "\"cpu_binding\": \"off: OMP_PLACES or OMP_PROC_BIND set\"")
  endif()
  execute_process(COMMAND ${CMAKE_COMMAND} -E env --unset=OMP_PLACES --unset=OMP_PROC_BIND ${envs}
                          ${SOLVER} cases/dambreak/case.yml --out ${out} --quiet
                          --set dp=0.008 --set end_time=0.01 --set output.interval=0
                  RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "fluid_solver (${mode}) exited ${rc}")
  endif()
  file(READ ${out}/summary.json summary)
  string(FIND "${summary}" "${want}" at)
  if(at LESS 0)
    message(FATAL_ERROR "${mode}: summary.json lacks ${want}:\n${summary}")
  endif()
endforeach()
message(STATUS "cpu_binding: bound on 2 threads, left to OMP_PROC_BIND when set")
