/* log.h - one line per event on standard error, with a UTC timestamp: the daemon's log.
 * Lines are written with a single stdio call, so lines from several threads never mix. */
#ifndef GRAINPACKD_LOG_H
#define GRAINPACKD_LOG_H

#include <stddef.h>

/* Writes "2026-11-21T05:34:00.123Z <message>\n" to stderr. */
void gp_log(const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 1, 2)))
#endif
    ;

/* Drops every line from now on (on = 1) or writes them again (0): for the HTTP fuzzer. */
void gp_log_silence(int on);

/* Writes the current UTC time as RFC 3339 with milliseconds ("2026-11-21T05:34:00.123Z")
 * into out (at least GP_TIMESTAMP_SIZE bytes). */
#define GP_TIMESTAMP_SIZE 32
void gp_timestamp_now(char *out);

/* Seconds on the monotonic clock (for durations only). */
double gp_monotonic_seconds(void);

#endif
