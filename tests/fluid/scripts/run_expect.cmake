# fluid_run_expect(LABEL OUT WANT ENV...): runs a short standalone dam break
# (8 mm, 0.01 s, no snapshots) with cmake -E env ENV..., and fails unless it
# exits 0 and its summary.json contains the text WANT. Shared by the summary
# checks of this folder.
function(fluid_run_expect label out want)
  file(REMOVE_RECURSE ${out})
  execute_process(COMMAND ${CMAKE_COMMAND} -E env ${ARGN}
                          ${SOLVER} cases/dambreak/case.yml --out ${out} --quiet
                          --set dp=0.008 --set end_time=0.01 --set output.interval=0
                  RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "fluid_solver (${label}) exited ${rc}")
  endif()
  file(READ ${out}/summary.json summary)
  string(FIND "${summary}" "${want}" at)
  if(at LESS 0)
    message(FATAL_ERROR "${label}: summary.json lacks ${want}:\n${summary}")
  endif()
endfunction()
