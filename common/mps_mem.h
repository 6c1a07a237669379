/* Growing work arrays in batches; asking the cache for a span ahead. */
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

/* Asks the cache for the bytes [p, p + bytes), line by line, for reading.
 * Loops that stream a list or a matrix by rows call it a few rows ahead:
 * on this machine the hardware prefetcher left those streams to the loads
 * (docs/fluid_speed.md). */
static inline void mps_prefetch_span(const void *p, size_t bytes)
{
    for (const char *c = p, *e = c + bytes; c < e; c += 64) {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
        /* volatile asm, not __builtin_prefetch: GCC 12 deletes a loop whose
         * only statements are __builtin_prefetch (dead code to it), and did
         * so here silently, after a change of the callers' form: the 80k
         * dam break's viscous term went back from 4.2 to 6.3 ms per step */
        __asm__ volatile("prefetcht0 %0" : : "m"(*c));
#else
        __builtin_prefetch(c);
#endif
    }
}

#endif
