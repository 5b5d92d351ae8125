/* json_values.h - a spec and a result's statistics as jansson values, for the programs
 * built with the library (the service's job documents, the JSON writer). Not installed:
 * no third-party type appears in the public headers; a program outside this tree gets
 * the same text from gp_write_json. */
#ifndef GRAINPACK_CORE_JSON_VALUES_H
#define GRAINPACK_CORE_JSON_VALUES_H

#include <jansson.h>

#include "grainpack/pipeline.h"
#include "grainpack/spec.h"

/* The statistics of a result as a new JSON object (caller owns the reference; NULL when
 * out of memory): count, densities, radii, the per-bin target-versus-achieved table with
 * chi-square, and how the front went. Timings are not included (they are not
 * reproducible); the caller adds them where it wants them. */
json_t *gp_statistics_json(const gp_spec *spec, const gp_result *result);

/* The spec as JSON inputs, every default made explicit (seed, joint, front, the stages'
 * options, picture): parsed again it gives the same spec. Returns a new reference the
 * caller owns, or NULL when out of memory. */
json_t *gp_spec_json(const gp_spec *spec);

#endif
