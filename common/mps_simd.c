#include "mps_simd.h"

#include <stdlib.h>
#include <string.h>

static int simd_wide_found, simd_wide;

/* Before main, so that the loops that ask never race on the answer. */
__attribute__((constructor)) static void simd_init(void)
{
#ifdef MPS_HAVE_WIDE
    const char *env = getenv("MPS_SIMD");
    __builtin_cpu_init(); /* constructors may run before libgcc's own */
    simd_wide_found = __builtin_cpu_supports("avx512f") && !(env && !strcmp(env, "sse2"));
#endif
    simd_wide = simd_wide_found;
}

int mps_simd_wide(void) { return simd_wide; }

void mps_simd_set_wide(int on) { simd_wide = on ? simd_wide_found : 0; }
