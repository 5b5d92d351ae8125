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

/* Fills reply with a problem: status, type, the standard title of the status and a
 * printf-style detail. `instance` (the request path) may be NULL. */
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

/* Seconds a client is told to wait by a 503. */
#define GP_RETRY_AFTER_SECONDS 5

/* The problem for a spec the engine refused: 400 for GP_EPARSE, 422 for GP_EINVAL and
 * GP_ETOOBIG, with the extension members `pointer` (the JSON pointer of the field in the
 * submitted document) and `expected` (the validator's message), both repeated in
 * `detail`; 500 for anything else. */
void gp_problem_from_spec_error(gp_reply *reply, const char *instance, const gp_error *err);

#endif
