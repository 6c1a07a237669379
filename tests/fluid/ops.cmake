# MPS operators (common/mps_ops.c) on fields with known derivatives, regular
# and perturbed lattices; one fluid step against known answers.
mps_add_test(test_fluid_ops SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_ops.c
  LIBS fluidcore LABELS unit TIMEOUT 60)
mps_add_test(test_fluid_step SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_fluid_step.c
  LIBS fluidcore LABELS unit TIMEOUT 60)
set_tests_properties(test_fluid_step PROPERTIES ENVIRONMENT "OMP_NUM_THREADS=1")
