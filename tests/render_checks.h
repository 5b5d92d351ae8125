/* render_checks.h - a result written in memory by the library's writers, for the tests
 * that read the text back. */
#ifndef GRAINPACK_TESTS_RENDER_CHECKS_H
#define GRAINPACK_TESTS_RENDER_CHECKS_H

#include "check.h"
#include "grainpack/io.h"

/* The result in `format` as a malloc'd, NUL-terminated text (the caller frees it); its
 * length in *len when len is not NULL. */
static inline char *render_text(gp_format format, const gp_spec *spec, const gp_result *result,
                                size_t *len)
{
    gp_out out;
    CHECK(gp_out_init(&out, 0, NULL, NULL) == 0);
    CHECK(gp_write_result(&out, format, spec, result) == 0);
    gp_out_char(&out, '\0');
    CHECK(out.err == 0);
    if (len)
        *len = out.len - 1;
    return out.buf;
}

#endif
