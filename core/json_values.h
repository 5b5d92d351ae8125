/* json_values.h - a spec and a result's statistics as jansson values, and jansson values
 * written with shortest doubles, for the programs built with the library (the service's
 * job documents and replies, the JSON writer). Not installed: no third-party type
 * appears in the public headers; a program outside this tree gets the same text from
 * gp_write_result in GP_FORMAT_JSON. */
#ifndef GRAINPACK_CORE_JSON_VALUES_H
#define GRAINPACK_CORE_JSON_VALUES_H

#include <jansson.h>

#include "grainpack/geometry3d.h"
#include "grainpack/out.h"
#include "grainpack/pipeline.h"
#include "grainpack/spec.h"
#include "grainpack/spec3d.h"

/* The statistics of a result as a new JSON object (caller owns the reference; NULL when
 * out of memory): count, densities, radii, the per-bin target-versus-achieved table with
 * chi-square, and how the front went. Timings are not included (they are not
 * reproducible); the caller adds them where it wants them. Reads only the result's
 * summary (no per-grain array): a result read back from a store serves as well. */
json_t *gp_statistics_json(const gp_spec *spec, const gp_result *result);

/* The statistics' "distribution" object of st (its bins against the law, chi2, dof,
 * p_value, max_abs_z), for any process's statistics. A new reference, or NULL when out of
 * memory. */
json_t *gp_distribution_stats_json(const gp_pack_stats *st);

/* Writes a JSON value compactly, doubles in their shortest round-trip form (jansson's
 * own dump writes 17 digits, 0.059999999999999998 for 0.06). For small documents: the
 * statistics object, a job's status. */
void gp_out_json(gp_out *out, const json_t *value);

/* A grain's ,"F":value after balancing, null where F is undefined (NaN: centres on the
 * boundary, balance.h), as the 2D and 3D JSON writers write it. */
void gp_out_json_F(gp_out *out, double F);

/* The spec as JSON inputs, every default made explicit (seed, joint, front, the stages'
 * options, picture): parsed again it gives the same spec. Returns a new reference the
 * caller owns, or NULL when out of memory. */
json_t *gp_spec_json(const gp_spec *spec);

/* The same for a 3D spec: domain (with its depth, and "periodic" as a list of axes when
 * the box has any), distribution, joint, seed, the balance and laguerre blocks when asked
 * for, picture. */
json_t *gp_spec3d_json(const gp_spec3d *spec);

/* Parts of the above that the 3D writers share (NULL or *failed set when out of memory):
 * the achieved-versus-target table, an array of counts, the balance summary, a law and a
 * joint as the spec writes them. */
json_t *gp_json_bins(const gp_bin_stat *table, size_t nbins, int *failed);
json_t *gp_json_counts(const size_t *counts, size_t n, int *failed);
json_t *gp_json_balance(const gp_balance_result *b, int *failed);
json_t *gp_json_distribution(const gp_distribution *d, int *failed);
json_t *gp_json_joint(const gp_joint *j, int *failed);
/* The periodic axes among the first `naxes` (bit a: axis a) as the spec's list form:
 * ["x"], ["x", "z"], ... */
json_t *gp_json_periodic(unsigned periodic, int naxes, int *failed);
/* The polyhedra's statistics as the 3D JSON writes them under "cells" (count, shrink,
 * faces, vertices, volume, faces_per_cell, ...): reads cells->shrink and `stats` only, so
 * a summary decoded from the store serves as well. */
json_t *gp_json_cells3d(const gp_cells3d *cells, const gp_cell3d_stats *stats, int *failed);

#endif
