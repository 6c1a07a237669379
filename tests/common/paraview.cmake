# ParaView opens every kind of output the project writes, with both of its
# XDMF readers, at every time; WarpByVector and a Calculator run on the
# vectors and one frame renders (tests/paraview/run_pv_check.py). SKIPPED
# where pvbatch or Xvfb is missing (Debian: paraview python3-paraview xvfb).
add_test(NAME paraview_reads_outputs
         COMMAND /usr/bin/python3 tests/paraview/run_pv_check.py ${CMAKE_BINARY_DIR}
                 ${CMAKE_BINARY_DIR}/test_out/paraview
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(paraview_reads_outputs PROPERTIES TIMEOUT 600 LABELS paraview
                     SKIP_RETURN_CODE 77)
