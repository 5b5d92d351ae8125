/* pack_rule.c - the default front rule: the waiting rule's parameters that pack a law
 * densest, found by packing small pilot squares with each candidate (docs/method.md §3.5).
 * No one setting is densest on every law: wide continuous laws gain from letting a held
 * radius climb far, a few large radii among many small lose by it, and a law of mostly
 * large radii with a few small ones loses by waiting for the small ones at all. */
#include <math.h>
#include <string.h>

#include "grainpack/pack.h"

/* The candidates, the densest of which is kept (bench/RESULTS.md, the front's rules):
 * wait 4 levels for the smallest radius, the best or within 0.003 of it on most laws; 8,
 * a little denser on wide continuous laws such as Bagi's; 1, when a few large radii go
 * among many small ones; 8 levels for the 20% quantile, when the smallest radii are few and
 * far below the rest. The first wins ties. */
static const struct {
    uint32_t wait_levels;
    double alive_quantile;
} candidates[] = {{4, 0.0}, {8, 0.0}, {1, 0.0}, {8, 0.2}};

/* Pilot seeds: fixed, so that the choice is a function of the law alone. */
static const uint64_t pilot_seeds[] = {7771, 7772};

/* Packing density the pilot square is sized for: about what the rules reach. */
#define PILOT_FILL 0.82

int gp_pack_default_rule(const gp_distribution *dist, const gp_joint *joint,
                         const gp_progress *progress, uint32_t *wait_levels,
                         double *alive_quantile, gp_error *err)
{
    *wait_levels = candidates[0].wait_levels;
    *alive_quantile = candidates[0].alive_quantile;
    double r_min, r_max, R_min, R_max;
    gp_distribution_support(dist, &r_min, &r_max);
    gp_joint_packing_range(joint, r_min, r_max, &R_min, &R_max);
    /* one radius: a pocket that failed it takes nothing, the rules are all one */
    if (!(R_max > R_min))
        return 0;
    double mean_R2 = gp_distribution_mean_packing_r2(dist, joint);
    double side = sqrt(GP_PACK_PILOT_DISKS * M_PI * mean_R2 / PILOT_FILL);
    if (side < 4.0 * R_max)
        side = 4.0 * R_max;
    gp_domain pilot = {side, side, 0};
    /* the pilots honour the caller's cancel flag; their progress is not the job's */
    gp_progress quiet = {NULL, NULL, progress ? progress->cancel : NULL};
    double best = -1.0;
    for (size_t c = 0; c < sizeof candidates / sizeof candidates[0]; c++) {
        double fill = 0.0;
        for (size_t s = 0; s < sizeof pilot_seeds / sizeof pilot_seeds[0]; s++) {
            gp_pack_params params = {.domain = &pilot,
                                     .dist = dist,
                                     .joint = joint,
                                     .seed = pilot_seeds[s],
                                     .rule = GP_FRONT_WAIT,
                                     .wait_levels = candidates[c].wait_levels,
                                     .alive_quantile = candidates[c].alive_quantile};
            gp_packing pk;
            int rc = gp_pack(&params, &quiet, &pk, err);
            if (rc)
                return rc;
            fill += pk.fill_area;
            gp_packing_free(&pk);
        }
        if (fill > best) {
            best = fill;
            *wait_levels = candidates[c].wait_levels;
            *alive_quantile = candidates[c].alive_quantile;
        }
    }
    return 0;
}
