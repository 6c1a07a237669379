# A fake solid (rigid plate on a prescribed path) so the coupling is tested
# without solid physics.
add_executable(fake_solid ${CMAKE_CURRENT_LIST_DIR}/fake_solid.c)
target_link_libraries(fake_solid PRIVATE mpsproto solidcore)
set_target_properties(fake_solid PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bin)

# Integration tests of the coupler (three processes) and its failure handling.
foreach(t plate_force body_loads moving_plate solid_crash solid_hang hello_deadline ready_deadline fluid_killed solid_killed
          interrupt fluid_fails wrong_version wrong_role result_echo solver_input_error fake_case_error probe_name_clash summary_unwritable cpu_placement
          stranger run_dir_private external_key no_rollback implicit_fake)
  add_test(NAME coupler_${t}
           COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/test_coupler.py
                   ${CMAKE_BINARY_DIR}/bin ${t}
           WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
  set_tests_properties(coupler_${t} PROPERTIES TIMEOUT 180 LABELS integration
                       SKIP_RETURN_CODE 77)
endforeach()
# The deadline tests time the coupler against its settings (1.75-3.5 s for a
# 2 s deadline, test_coupler.py): under -j2 beside another test in the ASan
# build (and a loaded machine) the exit came 4.3-5.5 s after the hang, the
# sanitizers' process teardown sharing two cores; alone they take 2.1 s.
set_tests_properties(coupler_solid_hang coupler_hello_deadline coupler_ready_deadline
                     PROPERTIES RUN_SERIAL TRUE)
