# docs/keys.md is what the three programs print for --keys (a key added or
# changed without the page fails here; tests/docs/keys_doc.py BUILD --write
# writes the page again).
add_test(NAME doc_keys
         COMMAND /usr/bin/python3 tests/docs/keys_doc.py ${CMAKE_BINARY_DIR}
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(doc_keys PROPERTIES TIMEOUT 120 LABELS docs)
