#include "mps_simd.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int simd_wide_found, simd_wide, simd_env_bad;
static char simd_env[64];

/* Before main, so that the loops that ask never race on the answer. */
__attribute__((constructor)) static void simd_init(void)
{
    const char *env = getenv("MPS_SIMD");
    const int portable = env && !strcmp(env, "sse2");
    simd_env_bad = env && *env && !portable && strcmp(env, "auto") != 0;
    if (simd_env_bad)
        snprintf(simd_env, sizeof simd_env, "%s", env);
#ifdef MPS_HAVE_WIDE
    __builtin_cpu_init(); /* constructors may run before libgcc's own */
    simd_wide_found = __builtin_cpu_supports("avx512f") && !portable;
#else
    (void)portable;
#endif
    simd_wide = simd_wide_found;
}

enum mps_status mps_simd_check_env(struct mps_err *err)
{
    if (!simd_env_bad)
        return MPS_OK;
    return mps_err_set(err, MPS_EINPUT,
                       "environment: MPS_SIMD=%s: unknown value (sse2 for the portable paths, "
                       "auto or unset for the fastest the CPU has)", simd_env);
}

int mps_simd_wide(void) { return simd_wide; }

void mps_simd_set_wide(int on) { simd_wide = on ? simd_wide_found : 0; }
