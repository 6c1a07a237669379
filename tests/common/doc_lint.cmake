# The pages are whole: one title each, relative links that resolve, no
# bench's progress lines pasted in (tests/docs/doc_lint.py says why).
add_test(NAME doc_lint
         COMMAND /usr/bin/python3 tests/docs/doc_lint.py
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(doc_lint PROPERTIES TIMEOUT 60 LABELS docs)
