/* problem.h - RFC 9457 problem details (application/problem+json): every error the API
 * answers goes through here, so that each one has a type, a title and a useful detail. */
#ifndef GRAINPACKD_PROBLEM_H
#define GRAINPACKD_PROBLEM_H

#include "grainpack/error.h"
#include "reply.h"

#define GP_PROBLEM_MEDIA_TYPE "application/problem+json"

/* Problem types. OGC API - Processes defines the first three; the others are ours. */
#define GP_PROBLEM_NO_SUCH_JOB "http://www.opengis.net/def/exceptions/ogcapi-processes-1/1.0/no-such-job"
#define GP_PROBLEM_RESULT_NOT_READY \
    "http://www.opengis.net/def/exceptions/ogcapi-processes-1/1.0/result-not-ready"
#define GP_PROBLEM_NO_SUCH_PROCESS \
    "http://www.opengis.net/def/exceptions/ogcapi-processes-1/1.0/no-such-process"
#define GP_PROBLEM_MALFORMED_JSON "urn:grainpack:problem:malformed-json"
#define GP_PROBLEM_INVALID_SPEC "urn:grainpack:problem:invalid-spec"
#define GP_PROBLEM_JOB_TOO_BIG "urn:grainpack:problem:job-too-big"
#define GP_PROBLEM_BODY_TOO_LARGE "urn:grainpack:problem:body-too-large"
#define GP_PROBLEM_UNSUPPORTED_MEDIA_TYPE "urn:grainpack:problem:unsupported-media-type"
#define GP_PROBLEM_NOT_ACCEPTABLE "urn:grainpack:problem:not-acceptable"
#define GP_PROBLEM_BAD_PARAMETER "urn:grainpack:problem:bad-parameter"
#define GP_PROBLEM_NOT_FOUND "urn:grainpack:problem:not-found"
#define GP_PROBLEM_METHOD_NOT_ALLOWED "urn:grainpack:problem:method-not-allowed"
#define GP_PROBLEM_JOB_FAILED "urn:grainpack:problem:job-failed"
#define GP_PROBLEM_JOB_DISMISSED "urn:grainpack:problem:job-dismissed"
#define GP_PROBLEM_QUEUE_FULL "urn:grainpack:problem:queue-full"
#define GP_PROBLEM_SHUTTING_DOWN "urn:grainpack:problem:shutting-down"
#define GP_PROBLEM_INTERNAL "urn:grainpack:problem:internal"
#define GP_PROBLEM_UNAUTHORIZED "urn:grainpack:problem:unauthorized"
#define GP_PROBLEM_FORBIDDEN "urn:grainpack:problem:forbidden"
#define GP_PROBLEM_TOO_MANY_JOBS "urn:grainpack:problem:too-many-jobs"
#define GP_PROBLEM_TOO_MANY_CONNECTIONS "urn:grainpack:problem:too-many-connections"
#define GP_PROBLEM_HEADERS_TOO_LARGE "urn:grainpack:problem:headers-too-large"
#define GP_PROBLEM_URI_TOO_LONG "urn:grainpack:problem:uri-too-long"
#define GP_PROBLEM_STORAGE_FULL "urn:grainpack:problem:storage-full"
#define GP_PROBLEM_STORAGE_UNWRITABLE "urn:grainpack:problem:storage-unwritable"
#define GP_PROBLEM_BAD_FRAMING "urn:grainpack:problem:bad-framing"
#define GP_PROBLEM_UNSUPPORTED_CODING "urn:grainpack:problem:unsupported-transfer-coding"
#define GP_PROBLEM_REQUEST_TIMEOUT "urn:grainpack:problem:request-timeout"

/* Fills reply with a problem: status, type, the standard title of the status and a
 * printf-style detail. `instance` (the request path) may be NULL. Text that came from
 * the request (a path, a parameter) may be any bytes: detail and instance are made valid
 * UTF-8 without control characters first (each offending byte becomes U+FFFD), so that
 * the body is always JSON. When memory runs out, the reply is gp_problem_out_of_memory's. */
void gp_problem(gp_reply *reply, unsigned status, const char *type, const char *instance,
                const char *detail_fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 5, 6)))
#endif
    ;

/* The answers several routes share: no such job (404), no such process (404), and the
 * store not answering (503 with Retry-After). */
void gp_problem_no_such_job(gp_reply *reply, const char *instance, const char *id);
void gp_problem_no_such_process(gp_reply *reply, const char *instance, const char *id);
void gp_problem_store_unavailable(gp_reply *reply, const char *instance);

/* The store refused a write (rc from store.h): 503 with Retry-After, saying whether the
 * disk is full (GP_SRV_EFULL), the database cannot be written (GP_SRV_EUNWRITABLE) or it
 * failed otherwise; `action` says what did not happen ("the job was not stored"). */
void gp_problem_store_error(gp_reply *reply, const char *instance, int rc, const char *action);

/* Makes reply a 503 problem (with Retry-After) saying that the service ran out of memory
 * while answering, from a static preformatted body: it allocates nothing, so that the
 * answer is still application/problem+json when building the real one failed. */
void gp_problem_out_of_memory(gp_reply *reply);

/* Copies text into out (size bytes, NUL-terminated, cut at a character boundary) as
 * valid UTF-8 without control characters: each offending byte becomes U+FFFD. */
void gp_text_sanitize(char *out, size_t size, const char *text);

/* Seconds a client is told to wait by a 503. */
#define GP_RETRY_AFTER_SECONDS 5

/* The problem for a spec the engine refused: 400 for GP_EPARSE, 422 for GP_EINVAL and
 * GP_ETOOBIG, with the extension members `pointer` (the JSON pointer of the field in the
 * submitted document) and `expected` (the validator's message), both repeated in
 * `detail`; 500 for anything else. */
void gp_problem_from_spec_error(gp_reply *reply, const char *instance, const gp_error *err);

#endif
