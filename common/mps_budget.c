#include "mps_budget.h"

#include <unistd.h>

double mps_budget_physical_bytes(void)
{
    long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGESIZE);
    return pages > 0 && size > 0 ? (double)pages * (double)size : 0.0;
}

enum mps_status mps_budget_check(const struct mps_case *c, const char *key, const char *what,
                                 double particles, double bytes_each, struct mps_err *err)
{
    double need = particles * bytes_each, have = mps_budget_physical_bytes();
    if (have <= 0.0 || need <= have)
        return MPS_OK;
    const double gib = 1024.0 * 1024.0 * 1024.0;
    return mps_case_fail(c, err, key,
                         "the %s needs about %.3g particles, an estimated %.3g GiB of memory "
                         "(%.0f bytes each); this machine has %.3g GiB",
                         what, particles, need / gib, bytes_each, have / gib);
}
