# A fake solid (rigid plate on a prescribed path) so the coupling is tested
# without solid physics.
add_executable(fake_solid ${CMAKE_CURRENT_LIST_DIR}/fake_solid.c)
target_link_libraries(fake_solid PRIVATE mpsproto solidcore)
set_target_properties(fake_solid PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bin)
