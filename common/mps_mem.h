/* Growing work arrays in batches. */
#ifndef MPS_MEM_H
#define MPS_MEM_H

#include <stdlib.h>

/* realloc(p, count * elem) that keeps the old block on failure and raises
 * *fail instead, so a batch of arrays can be grown and checked once. */
static inline void *mps_realloc_or_flag(void *p, size_t count, size_t elem, int *fail)
{
    void *q = realloc(p, (count ? count : 1) * elem);
    if (!q)
        *fail = 1;
    return q ? q : p;
}

#endif
