/* error.c - filling the caller's gp_error. */
#include "grainpack/error.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

void gp_error_clear(gp_error *err)
{
    if (err)
        memset(err, 0, sizeof *err);
}

int gp_error_set(gp_error *err, int code, const char *pointer, const char *fmt, ...)
{
    if (!err)
        return code;
    err->code = code;
    snprintf(err->pointer, sizeof err->pointer, "%s", pointer ? pointer : "");
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->message, sizeof err->message, fmt, ap);
    va_end(ap);
    return code;
}

const char *gp_strerror(int code)
{
    switch (code) {
    case GP_OK: return "success";
    case GP_ENOMEM: return "out of memory";
    case GP_EPARSE: return "malformed JSON";
    case GP_EINVAL: return "invalid input";
    case GP_ETOOBIG: return "too big";
    case GP_ECANCELED: return "canceled";
    case GP_EIO: return "input/output error";
    case GP_EGEOM: return "geometric invariant broken";
    case GP_EINTERNAL: return "internal error";
    default: return "unknown error";
    }
}
