/* Minimal test helpers: each check prints what failed with file:line and the
 * values, and counts failures; main returns test_summary(). */
#ifndef TEST_UTIL_H
#define TEST_UTIL_H

#include <math.h>
#include <stdio.h>

static int test_failures = 0;
static int test_checks = 0;

#define CHECK(cond)                                                                  \
    do {                                                                             \
        test_checks++;                                                               \
        if (!(cond)) {                                                               \
            test_failures++;                                                         \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond); \
        }                                                                            \
    } while (0)

/* |a - b| <= tol */
#define CHECK_NEAR(a, b, tol)                                                            \
    do {                                                                                 \
        test_checks++;                                                                   \
        double a_ = (a), b_ = (b), t_ = (tol);                                           \
        if (!(fabs(a_ - b_) <= t_)) {                                                    \
            test_failures++;                                                             \
            fprintf(stderr, "%s:%d: CHECK_NEAR failed: %s = %.12g, %s = %.12g, tol %.3g\n", \
                    __FILE__, __LINE__, #a, a_, #b, b_, t_);                             \
        }                                                                                \
    } while (0)

/* Exit status of a test whose subject is missing here (ctest: SKIP_RETURN_CODE
 * 77, reported as Skipped, never as Passed). */
#define TEST_SKIPPED 77

static inline int test_summary(const char *name)
{
    printf("%s: %d checks, %d failed\n", name, test_checks, test_failures);
    return test_failures ? 1 : 0;
}

#endif
