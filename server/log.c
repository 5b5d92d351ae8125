/* log.c - timestamps and the daemon's line-per-event log on standard error. */
#include "log.h"

#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <time.h>

/* Set by the fuzzer, whose millions of requests would each write a line. */
static atomic_int silenced;

void gp_log_silence(int on)
{
    atomic_store(&silenced, on);
}

void gp_timestamp_now(char *out)
{
    struct timespec ts;
    struct tm tm;
    clock_gettime(CLOCK_REALTIME, &ts);
    gmtime_r(&ts.tv_sec, &tm);
    /* strftime, then the milliseconds: the year is bounded, so 32 bytes always suffice */
    size_t n = strftime(out, GP_TIMESTAMP_SIZE, "%Y-%m-%dT%H:%M:%S", &tm);
    snprintf(out + n, GP_TIMESTAMP_SIZE - n, ".%03dZ", (int)(ts.tv_nsec / 1000000));
}

double gp_monotonic_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

void gp_log(const char *fmt, ...)
{
    char stamp[GP_TIMESTAMP_SIZE], line[1024];
    if (atomic_load(&silenced))
        return;
    gp_timestamp_now(stamp);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    fprintf(stderr, "%s %s\n", stamp, line);
}
