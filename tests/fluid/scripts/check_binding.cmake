# fluid_cpu_binding: a standalone run on 2 threads binds them to CPUs (the
# summary says so), and leaves the binding to OMP_PROC_BIND when it is set.
# usage: cmake -DSOLVER=... -DOUT=... -P check_binding.cmake (from the source root)
include(${CMAKE_CURRENT_LIST_DIR}/run_expect.cmake)
fluid_run_expect(bound ${OUT}/bound "\"cpu_binding\": \"2 threads bound to"
                 --unset=OMP_PLACES --unset=OMP_PROC_BIND OMP_NUM_THREADS=2)
fluid_run_expect(user ${OUT}/user "\"cpu_binding\": \"off: OMP_PLACES or OMP_PROC_BIND set\""
                 --unset=OMP_PLACES OMP_NUM_THREADS=2 OMP_PROC_BIND=close)
message(STATUS "cpu_binding: bound on 2 threads, left to OMP_PROC_BIND when set")
