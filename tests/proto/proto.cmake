# Protocol tests: the codec alone, the ZeroMQ link, and the C <-> Python
# cross-check that shows PROTOCOL.md is enough to talk to us.
find_package(Threads REQUIRED)
set(PROTO_TEST_DIR ${CMAKE_CURRENT_LIST_DIR})

mps_add_test(proto_codec
  SOURCES ${PROTO_TEST_DIR}/test_proto_codec.c ${PROTO_TEST_DIR}/proto_samples.c
  LIBS mpsproto LABELS unit TIMEOUT 30)
target_include_directories(proto_codec PRIVATE ${CMAKE_SOURCE_DIR}/tests ${PROTO_TEST_DIR})

# The same tests through the byte-swapping path a big-endian host would take.
mps_add_test(proto_codec_swap
  SOURCES ${PROTO_TEST_DIR}/test_proto_codec.c ${PROTO_TEST_DIR}/proto_samples.c
          ${CMAKE_SOURCE_DIR}/proto/proto_msg.c
  LIBS m LABELS unit TIMEOUT 30)
target_include_directories(proto_codec_swap PRIVATE ${CMAKE_SOURCE_DIR}/tests ${PROTO_TEST_DIR}
  ${CMAKE_SOURCE_DIR}/proto)
target_compile_definitions(proto_codec_swap PRIVATE PROTO_TEST_SWAP)

mps_add_test(proto_link
  SOURCES ${PROTO_TEST_DIR}/test_proto_link.c ${PROTO_TEST_DIR}/proto_samples.c
  LIBS mpsproto Threads::Threads LABELS unit TIMEOUT 30)
target_include_directories(proto_link PRIVATE ${CMAKE_SOURCE_DIR}/tests ${PROTO_TEST_DIR})

# proto_dump: writes the samples as frame files and checks files written by
# another encoder (PROTOCOL.md appendix A).
add_executable(proto_dump ${PROTO_TEST_DIR}/proto_dump.c ${PROTO_TEST_DIR}/proto_samples.c)
target_link_libraries(proto_dump PRIVATE mpsproto)
target_include_directories(proto_dump PRIVATE ${PROTO_TEST_DIR})
set_target_properties(proto_dump PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)

add_test(NAME proto_python_codec
  COMMAND /usr/bin/python3 ${PROTO_TEST_DIR}/test_python_codec.py $<TARGET_FILE:proto_dump>
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(proto_python_codec PROPERTIES TIMEOUT 60 LABELS unit
  SKIP_RETURN_CODE 77 ENVIRONMENT "PYTHONPATH=${CMAKE_SOURCE_DIR}/proto/python")

# CURVE key files and a CURVE link (PROTOCOL.md section 10).
mps_add_test(proto_key
  SOURCES ${PROTO_TEST_DIR}/test_proto_key.c
  LIBS mpsproto LABELS unit TIMEOUT 30)
target_include_directories(proto_key PRIVATE ${CMAKE_SOURCE_DIR}/tests)
