# Every command in README.md and docs/*.md runs as written from the
# repository root (tests/docs/doc_commands.py: what counts as a command, what
# is never run and why). ctest runs the short version: the long runs of the
# docs shortened by its table SHORT (MPS_DOC_TEST_SHORT=1); unset, they run
# in full (hours).
add_test(NAME doc_commands
         COMMAND ${CMAKE_COMMAND} -E env MPS_DOC_TEST_SHORT=1
                 /usr/bin/python3 tests/docs/doc_commands.py ${CMAKE_BINARY_DIR}
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(doc_commands PROPERTIES TIMEOUT 1200 LABELS docs)
