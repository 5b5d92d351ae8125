/* pack3d_laws.h - the reference laws of the 3D packer's property tests (one radius, the
 * uniform "3D Bagi" law, the iron histogram without joint) and the checks of a packing
 * that do not depend on its box (the radii are the law's draws, bounded work, the filled
 * volume, the bins pooled over seeds), shared by test_pack3d.c and test_pack3d_periodic.c. */
#ifndef GRAINPACK_TESTS_PACK3D_LAWS_H
#define GRAINPACK_TESTS_PACK3D_LAWS_H

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "grainpack/pack3d.h"
#include "grainpack/spec.h"
#include "pack3d_internal.h"

/* Bins of a law at most, and how far (standard errors) a pooled bin may be from its
 * expectation: 4 leaves a ~1e-4 chance of a false alarm per bin. */
#define LAW3_MAX_BINS 64
#define LAW3_MAX_Z 4.0

typedef struct law3 {
    const char *name;
    int seeds;          /* a law of one radius packs the same for every seed: a few suffice */
    gp_spec spec;       /* owns the law */
    double side;        /* box side */
    double min_density; /* floor over the seeds: ~0.03 under the lowest measured */
} law3;

static inline int load_law(law3 *law, const char *json)
{
    gp_error err;
    if (gp_spec_parse(json, strlen(json), NULL, &law->spec, &err)) {
        fprintf(stderr, "%s: %s\n", law->name, err.message);
        return -1;
    }
    return 0;
}

static inline int load_iron(law3 *law)
{
    gp_error err;
    if (gp_spec_load_file(GP_EXAMPLES_DIR "/iron.json", NULL, &law->spec, &err)) {
        fprintf(stderr, "iron: %s\n", err.message);
        return -1;
    }
    law->spec.joint = (gp_joint){0}; /* the radii alone: the 3D iron case has no joint */
    return 0;
}

/* The three laws' specs into laws[0..2] (their other fields set by the caller): 0 or -1. */
static inline int load_laws3(law3 laws[3])
{
    return load_law(&laws[0], "{\"domain\": {\"width\": 10, \"height\": 10}, \"distribution\": "
                              "{\"kind\": \"constant\", \"radius\": 0.5}}") ||
                   load_law(&laws[1], "{\"domain\": {\"width\": 10, \"height\": 10}, \"distribution\": "
                                      "{\"kind\": \"uniform\", \"min\": 0.06, \"max\": 0.42}}") ||
                   load_iron(&laws[2])
               ? -1
               : 0;
}

/* The radii are the law's draws in order (the seed's generator gives them again) and the
 * work is bounded (docs/3d.md §5: triangles per sphere, tries per triangle); returns the
 * packing density in `box`, checking the packer's filled volume. */
static inline double law3_check_packing(const char *name, int seed, const gp_pack3d_params *params,
                                        const gp_packing3d *out)
{
    gp_rng rng;
    gp_rng_seed(&rng, params->seed);
    size_t same = 0;
    for (size_t i = 0; i < out->count; i++)
        same += gp_distribution_sample(params->dist, &rng) == out->spheres[i].r &&
                out->spheres[i].r == out->spheres[i].R;
    CHECK_MSG(same == out->count, "%s seed %d: %zu of %zu radii are the draws", name, seed, same, out->count);
    size_t links = P3_LINKS + P3_WALLS;
    CHECK(out->triangles <= 1 + out->count * (links * (links - 1) / 2));
    CHECK(out->attempts <= out->triangles * P3_CLASSES + out->count);
    double volume = 0.0;
    for (size_t i = 0; i < out->count; i++)
        volume += 4.0 / 3.0 * M_PI * pow(out->spheres[i].R, 3);
    CHECK_NEAR(volume, out->fill_volume, 1e-9 * volume);
    const gp_box *box = params->box;
    return volume / (box->width * box->height * box->depth);
}

/* The radii of packings pooled by the law's bins. */
typedef struct law3_tally {
    gp_bin bins[LAW3_MAX_BINS];
    size_t nb;
    double counts[LAW3_MAX_BINS];
    size_t pooled;
} law3_tally;

static inline void law3_tally_init(law3_tally *t, const gp_distribution *dist)
{
    memset(t, 0, sizeof *t);
    t->nb = gp_distribution_report_bins(dist, t->bins, LAW3_MAX_BINS);
}

static inline void law3_tally_add(law3_tally *t, const gp_packing3d *out)
{
    for (size_t i = 0; i < out->count; i++)
        for (size_t b = 0; b < t->nb; b++)
            if (out->spheres[i].r >= t->bins[b].min && (out->spheres[i].r < t->bins[b].max || b + 1 == t->nb)) {
                t->counts[b]++;
                break;
            }
    t->pooled += out->count;
}

/* Checks every bin within LAW3_MAX_Z standard errors; returns the largest |z|. */
static inline double law3_tally_check(const law3_tally *t, const char *name)
{
    double max_z = 0.0;
    for (size_t b = 0; b < t->nb; b++) {
        double p = t->bins[b].p, expect = p * (double)t->pooled;
        double se = sqrt((double)t->pooled * p * (1.0 - p));
        double z = se > 0.0 ? (t->counts[b] - expect) / se : t->counts[b] - expect;
        CHECK_MSG(fabs(z) <= LAW3_MAX_Z, "%s bin %zu: %.0f of %zu, expected %.1f", name, b, t->counts[b],
                  t->pooled, expect);
        max_z = fmax(max_z, fabs(z));
    }
    return max_z;
}

#endif
