# Every program's --version names the revision of the tree it was built
# from, as `git describe` says now (the build refreshes it; before, it was
# fixed at configure time and went stale after a commit). Outside a git
# checkout the revision is "unknown".
execute_process(COMMAND git describe --always --dirty --tags
  WORKING_DIRECTORY ${SRC} OUTPUT_VARIABLE want
  OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
if(NOT want)
  set(want "unknown")
endif()
# An edit after the build (a doc, say) makes the tree dirty but the binary
# is still the tree's: compare the revision without the -dirty mark.
string(REGEX REPLACE "-dirty$" "" want "${want}")
foreach(prog fluid_solver solid_solver coupler)
  execute_process(COMMAND ${BIN}/${prog} --version
    OUTPUT_VARIABLE got RESULT_VARIABLE rc OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${prog} --version exited ${rc}")
  endif()
  if(NOT got MATCHES "^${prog} [0-9.]+ \\(git ${want}(-dirty)?\\)$")
    message(FATAL_ERROR "${prog} --version says '${got}', the tree is at '${want}': rebuild")
  endif()
  message(STATUS "${got}")
endforeach()
