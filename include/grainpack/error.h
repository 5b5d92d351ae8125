/* error.h - the one error type of libgrainpack: a negative code plus a message that names
 * the offending field by JSON pointer where there is one. */
#ifndef GRAINPACK_ERROR_H
#define GRAINPACK_ERROR_H

#include "grainpack/api.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Every fallible function returns 0 or one of these. */
enum gp_status {
    GP_OK = 0,
    GP_ENOMEM = -1,    /* allocation failed */
    GP_EPARSE = -2,    /* the input is not well-formed JSON */
    GP_EINVAL = -3,    /* well-formed but invalid: a field is missing, of the wrong type or out of range */
    GP_ETOOBIG = -4,   /* the job would exceed a configured cap (expected disks, bins, ...) */
    GP_ECANCELED = -5, /* the caller's cancel flag was raised */
    GP_EIO = -6,       /* reading or writing a file or stream failed */
    GP_EGEOM = -7,     /* a geometric invariant broke (a bug, or degenerate input) */
    GP_EINTERNAL = -8  /* an internal guard tripped; the message says which */
};

#define GP_ERROR_POINTER_MAX 160
#define GP_ERROR_MESSAGE_MAX 320

/* Filled by the function that fails; owned by the caller (usually on its stack). */
typedef struct gp_error {
    int code;                             /* one of enum gp_status */
    char pointer[GP_ERROR_POINTER_MAX];   /* JSON pointer of the field at fault, "" if none */
    char message[GP_ERROR_MESSAGE_MAX];   /* what was expected and what was found */
} gp_error;

/* Clears err (no-op on NULL). */
GP_API void gp_error_clear(gp_error *err);

/* Records code, pointer (may be NULL) and a printf-style message in err (no-op on NULL);
 * returns code so that a caller can write `return gp_error_set(err, GP_EINVAL, ...)`. */
GP_API int gp_error_set(gp_error *err, int code, const char *pointer, const char *fmt, ...)
       #if defined(__GNUC__)
           __attribute__((format(printf, 4, 5)))
       #endif
           ;

/* A short constant English name for a code ("invalid input", ...). */
GP_API const char *gp_strerror(int code);

#ifdef __cplusplus
}
#endif
#endif
