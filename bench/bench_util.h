/* bench_util.h - what the benchmark programs of bench/ share: a clock read in seconds and
 * the exit on a library error. Header-only, as each program is one file. */
#ifndef GRAINPACK_BENCH_UTIL_H
#define GRAINPACK_BENCH_UTIL_H

#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "grainpack/error.h"

/* Clock `id` in seconds: CLOCK_MONOTONIC for wall time, CLOCK_PROCESS_CPUTIME_ID for the
 * process's CPU time (comparable on a loaded machine). */
static inline double bench_seconds(clockid_t id)
{
    struct timespec ts;
    clock_gettime(id, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* Wall time in seconds. */
static inline double bench_now(void)
{
    return bench_seconds(CLOCK_MONOTONIC);
}

/* Says what failed and why, and ends the program. */
static inline void bench_die(const char *what, const gp_error *err)
{
    fprintf(stderr, "%s: %s\n", what, err->message);
    exit(1);
}

#endif
