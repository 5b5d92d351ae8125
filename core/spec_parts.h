/* spec_parts.h - the parts of the spec parser (spec.c) that the 3D spec (spec3d.c) shares:
 * JSON pointers, member checks, numbers, the radius law, the joint, the seed (internal to
 * core/). Each sets v->err with the JSON pointer of the field at fault. */
#ifndef GRAINPACK_CORE_SPEC_PARTS_H
#define GRAINPACK_CORE_SPEC_PARTS_H

#include <jansson.h>
#include <stddef.h>
#include <stdint.h>

#include "grainpack/balance.h"
#include "grainpack/distribution.h"
#include "grainpack/error.h"
#include "grainpack/joint.h"
#include "grainpack/laguerre.h"
#include "grainpack/spec.h"

typedef struct validator {
    gp_error *err;
    size_t max_disks, max_bins, max_elements;
} validator;

/* Appends "/" + key (escaped per RFC 6901) to base, into out (GP_ERROR_POINTER_MAX bytes). */
void spec_pointer_key(char *out, const char *base, const char *key);
/* Rejects members of obj not in the NULL-terminated list `allowed`. */
int spec_check_members(validator *v, const json_t *obj, const char *base, const char *const *allowed,
                       const char *expected_list);
/* The object member `key` of parent (its pointer into ptr): *out NULL when absent and not
 * required. */
int spec_get_object(validator *v, const json_t *parent, const char *base, const char *key, int required,
                    const json_t **out, char *ptr);
/* Reads a required finite number that must be > lower (or >= lower when `inclusive`). */
int spec_get_number(validator *v, const json_t *obj, const char *base, const char *key, double lower,
                    int inclusive, double *out);
/* "periodic" of a domain (axes 2) or a box (axes 3) object `obj` whose pointer is base:
 * true, false, absent or an array of distinct axis names; *out gets bit 1 << k per
 * periodic axis k. */
int spec_parse_periodic(validator *v, const json_t *obj, const char *base, int axes, unsigned *out);
/* "distribution" (required; not yet prepared), "joint" (optional), "seed" (optional). */
int spec_parse_distribution(validator *v, const json_t *inputs, const char *base, gp_distribution *d);
int spec_parse_joint(validator *v, const json_t *inputs, const char *base, gp_joint *j);
int spec_parse_seed(validator *v, const json_t *inputs, const char *base, uint64_t *seed);
/* "balance" {"method", "max_iterations", "max_step"} and "laguerre" {"shrink",
 * "flush_boundary"} (both optional): *enabled is set to 1 when the block is there, and the
 * parameters filled with its fields and the defaults. */
int spec_parse_balance(validator *v, const json_t *inputs, const char *base, int *enabled,
                       gp_balance_params *balance);
int spec_parse_laguerre(validator *v, const json_t *inputs, const char *base, int *enabled,
                        gp_laguerre_params *laguerre);
/* Parses the text as JSON (GP_EPARSE when it is not) and hands the root to `parse` with
 * a validator for `limits` (NULL: the defaults). Returns what `parse` returns; the
 * caller frees `spec` on failure. */
int spec_parse_text(const char *text, size_t len, const gp_spec_limits *limits, gp_error *err,
                    int (*parse)(validator *v, const json_t *root, void *spec), void *spec);
/* Reads the file at path and parses it with `parse` (GP_EIO when it cannot be read). */
int spec_load_file(const char *path, const gp_spec_limits *limits, gp_error *err,
                   int (*parse)(const char *text, size_t len, const gp_spec_limits *limits,
                                void *spec, gp_error *err),
                   void *spec);
/* The JSON pointer of the field giving the law's smallest radius, into out. */
void spec_smallest_radius_pointer(const char *base, const gp_distribution *dist, char *out);

#endif
