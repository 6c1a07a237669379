# MPS operators (common/mps_ops.c) on fields with known derivatives, regular
# and perturbed lattices; one fluid step against known answers.
mps_add_test(test_fluid_ops SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_ops.c
  LIBS fluidcore LABELS unit TIMEOUT 60)
mps_add_test(test_fluid_step SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_fluid_step.c
  LIBS fluidcore LABELS unit TIMEOUT 60)
set_tests_properties(test_fluid_step PROPERTIES ENVIRONMENT "OMP_NUM_THREADS=1")
# The AVX-512 paths against the portable ones: SKIPPED where the CPU has no
# AVX-512 (there is then one path only, which the tests above cover).
foreach(t test_fluid_step test_fluid_ops)
  add_test(NAME ${t}_avx512 COMMAND ${t} avx512 WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
  set_tests_properties(${t}_avx512 PROPERTIES ENVIRONMENT "OMP_NUM_THREADS=1" TIMEOUT 60
    LABELS unit SKIP_RETURN_CODE 77)
endforeach()
# The same known answers on the portable paths (MPS_SIMD=sse2), which an
# AVX-512 machine otherwise runs only inside test_simd_paths.
add_test(NAME test_fluid_step_portable COMMAND test_fluid_step WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(test_fluid_step_portable PROPERTIES ENVIRONMENT "OMP_NUM_THREADS=1;MPS_SIMD=sse2"
  TIMEOUT 60 LABELS unit)
