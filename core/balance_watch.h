/* balance_watch.h - the stopping rules of the balancing sweeps (docs/method.md §4.5),
 * shared by the 2D and 3D balancers (balance.c, balance3d.c; internal to core/): which
 * structure is the best seen, whether the sweeps stalled or a relocation is steady, and
 * whether the job was canceled. */
#ifndef GRAINPACK_CORE_BALANCE_WATCH_H
#define GRAINPACK_CORE_BALANCE_WATCH_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/balance.h"

/* What the rules remember: the best structure's F (the one returned), the lowest F_max and
 * mean seen (even in two different structures: they tell whether the sweeps still make
 * progress), the lowest mean after each of the last sweeps (round robin), the sweep that
 * last lowered F_max, and the sweeps in a row without progress. */
typedef struct balance_watch {
    gp_quality_stats best;
    double lowest_max, lowest_mean;
    double lowest_means[GP_BALANCE_STEADY_SWEEPS];
    uint32_t lowered_max, stall;
} balance_watch;

static inline void balance_watch_start(balance_watch *w, const gp_quality_stats *before)
{
    w->best = *before;
    w->lowest_max = before->max;
    w->lowest_mean = before->mean;
    w->lowest_means[0] = w->lowest_mean;
    w->lowered_max = 0;
    w->stall = 0;
}

/* Whether structure `a` is better than `best`: a lower F_max (the report's figure),
 * else as low an F_max and a lower mean. Differences below GP_BALANCE_QUALITY_TOL do not
 * count, so that a structure that only wanders does not look like progress. */
static inline int balance_improves(const gp_quality_stats *a, const gp_quality_stats *best)
{
    if (a->max < best->max - GP_BALANCE_QUALITY_TOL)
        return 1;
    return a->max <= best->max && a->mean < best->mean - GP_BALANCE_QUALITY_TOL;
}

/* Whether a relocation is steady (GP_BALANCE_STEADY_MIN_INTERIOR): F_max not lowered for
 * GP_BALANCE_STEADY_SWEEPS sweeps, and `lowest_mean`, the lowest mean F seen, less than
 * GP_BALANCE_STEADY_RTOL below `lowest_before`, the lowest seen GP_BALANCE_STEADY_SWEEPS
 * sweeps ago. */
static inline int balance_steady(gp_balance_method method, size_t interior, uint32_t since_lowered_max,
                                 double lowest_before, double lowest_mean)
{
    return method == GP_BALANCE_RELOCATION && interior >= GP_BALANCE_STEADY_MIN_INTERIOR &&
           since_lowered_max >= GP_BALANCE_STEADY_SWEEPS &&
           lowest_before - lowest_mean < GP_BALANCE_STEADY_RTOL * lowest_mean;
}

/* After sweep number `sweeps` (from 1) left the structure measured `now`: sets *better
 * when it is the new best (w->best is then now), and returns the stop the rules call
 * for, or -1 to sweep on. */
static inline int balance_watch_sweep(balance_watch *w, gp_balance_method method, uint32_t sweeps,
                                      const gp_quality_stats *now, int *better)
{
    *better = balance_improves(now, &w->best);
    if (*better)
        w->best = *now;
    int lower_max = now->max < w->lowest_max - GP_BALANCE_QUALITY_TOL;
    int lower_mean = now->mean < w->lowest_mean - GP_BALANCE_QUALITY_TOL;
    w->lowered_max = lower_max ? sweeps : w->lowered_max;
    w->lowest_max = now->max < w->lowest_max ? now->max : w->lowest_max;
    w->lowest_mean = now->mean < w->lowest_mean ? now->mean : w->lowest_mean;
    /* the slot of the sweep GP_BALANCE_STEADY_SWEEPS ago, overwritten below */
    double *slot = &w->lowest_means[sweeps % GP_BALANCE_STEADY_SWEEPS];
    if (sweeps >= GP_BALANCE_STEADY_SWEEPS &&
        balance_steady(method, now->interior, sweeps - w->lowered_max, *slot, w->lowest_mean))
        return GP_BALANCE_STOP_STEADY;
    *slot = w->lowest_mean;
    if (lower_max || lower_mean)
        w->stall = 0;
    else if (++w->stall >= GP_BALANCE_STALL_SWEEPS)
        return GP_BALANCE_STOP_STALLED;
    return -1;
}

/* Between sweeps and every so many centres: GP_ECANCELED (with err) when the cancel flag of
 * `progress` (may be NULL) is raised, else reports `fraction` of stage "balance" and 0. */
static inline int balance_report(const gp_progress *progress, double fraction, gp_error *err)
{
    if (!progress)
        return 0;
    if (gp_canceled(progress->cancel))
        return gp_error_set(err, GP_ECANCELED, NULL, "balancing canceled");
    if (progress->report)
        progress->report(progress->ctx, "balance", fraction);
    return 0;
}

/* balance_watch_sweep for the sweep `out` just counted: records in `out` the best sweep
 * (when *better) and the stop called for; returns whether the sweeps end here. */
static inline int balance_watch_record(balance_watch *w, gp_balance_method method, gp_balance_result *out,
                                       const gp_quality_stats *now, int *better)
{
    int stop = balance_watch_sweep(w, method, out->sweeps, now, better);
    if (*better)
        out->best_sweep = out->sweeps;
    if (stop >= 0)
        out->stop = (gp_balance_stop)stop;
    return stop >= 0;
}

#endif
