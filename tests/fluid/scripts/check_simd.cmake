# fluid_simd_paths: the summary names the vector paths a run took: AVX-512
# where the CPU has it (avx512f in /proc/cpuinfo) unless MPS_SIMD=sse2, which
# always gives the portable ones.
# usage: cmake -DSOLVER=... -DOUT=... -P check_simd.cmake (from the source root)
include(${CMAKE_CURRENT_LIST_DIR}/run_expect.cmake)
set(auto_paths portable)
if(EXISTS /proc/cpuinfo)
  file(READ /proc/cpuinfo cpuinfo)
  string(FIND "${cpuinfo}" " avx512f" at)
  if(at GREATER -1)
    set(auto_paths avx512)
  endif()
endif()
fluid_run_expect(auto ${OUT}/auto "\"simd_paths\": \"${auto_paths}\"" --unset=MPS_SIMD)
fluid_run_expect(sse2 ${OUT}/sse2 "\"simd_paths\": \"portable\"" MPS_SIMD=sse2)
message(STATUS "simd_paths: ${auto_paths} here, portable under MPS_SIMD=sse2")
