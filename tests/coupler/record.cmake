# The files of a run say what ran (issue 23): the solid command and model
# in case_resolved.yml and every snapshot's /config, the run.* record in
# them, probes.csv and summary.json; fluid snapshots without the solid's
# particles, every particle once in scene.xmf; the Python solid's HDF5
# snapshots in scene.xmf; particles lost over a wall said on the terminal.
foreach(what tlsph python lost)
  add_test(NAME coupler_record_${what}
           COMMAND sh -c "rm -rf \"$0\" && /usr/bin/python3 tests/coupler/record_check.py \"$1\" \"$0\" ${what}"
                   ${CMAKE_BINARY_DIR}/test_out/record_${what} ${CMAKE_BINARY_DIR}
           WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
  set_tests_properties(coupler_record_${what} PROPERTIES TIMEOUT 300 LABELS integration)
endforeach()
