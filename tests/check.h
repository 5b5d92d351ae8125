/* check.h - the few assertion macros the test programs share. A failed check prints
 * where and why and marks the program failed; the program goes on so that one run shows
 * every failure. main() returns check_status(). */
#ifndef GRAINPACK_TESTS_CHECK_H
#define GRAINPACK_TESTS_CHECK_H

#include <math.h>
#include <stdio.h>
#include <string.h>

static int check_failures;

#define CHECK(cond)                                                                          \
    do {                                                                                     \
        if (!(cond)) {                                                                       \
            fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond);       \
            check_failures++;                                                                \
        }                                                                                    \
    } while (0)

#define CHECK_MSG(cond, ...)                                                                 \
    do {                                                                                     \
        if (!(cond)) {                                                                       \
            fprintf(stderr, "%s:%d: check failed: %s: ", __FILE__, __LINE__, #cond);       \
            fprintf(stderr, __VA_ARGS__);                                                    \
            fputc('\n', stderr);                                                             \
            check_failures++;                                                                \
        }                                                                                    \
    } while (0)

#define CHECK_NEAR(a, b, tol)                                                                \
    CHECK_MSG(fabs((double)(a) - (double)(b)) <= (tol), "%.17g vs %.17g (tolerance %g)",     \
              (double)(a), (double)(b), (double)(tol))

#define CHECK_STR(a, b) CHECK_MSG(strcmp((a), (b)) == 0, "\"%s\" vs \"%s\"", (a), (b))

#define RUN(test)                                                                            \
    do {                                                                                     \
        int before = check_failures;                                                         \
        test();                                                                              \
        fprintf(stderr, "%s %s\n", check_failures == before ? "ok  " : "FAIL", #test);      \
    } while (0)

static inline int check_status(void)
{
    if (check_failures)
        fprintf(stderr, "%d check(s) failed\n", check_failures);
    return check_failures ? 1 : 0;
}

#endif
