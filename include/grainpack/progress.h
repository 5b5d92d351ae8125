/* progress.h - how a long stage reports how far it got and learns that it must stop. */
#ifndef GRAINPACK_PROGRESS_H
#define GRAINPACK_PROGRESS_H

#ifdef __cplusplus
#include <atomic>
typedef std::atomic_int gp_cancel_flag;
#else
#include <stdatomic.h>
typedef atomic_int gp_cancel_flag;
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* Everything is optional: a NULL gp_progress, a NULL report or a NULL cancel all work.
 * Stages call report() from the thread that runs them, a few hundred times per second at
 * most, and read *cancel as often; a nonzero *cancel makes the stage return GP_ECANCELED. */
typedef struct gp_progress {
    void (*report)(void *ctx, const char *stage, double fraction); /* fraction in [0,1] */
    void *ctx;
    const gp_cancel_flag *cancel;
} gp_progress;

/* Whether the flag (NULL: none) is raised. A relaxed load: a stage only needs to see the
 * flag soon, not in any order with other memory. */
static inline int gp_canceled(const gp_cancel_flag *cancel)
{
#ifdef __cplusplus
    return cancel && cancel->load(std::memory_order_relaxed) != 0;
#else
    return cancel && atomic_load_explicit(cancel, memory_order_relaxed) != 0;
#endif
}

/* The flag of a progress (NULL for none). */
static inline const gp_cancel_flag *gp_progress_cancel(const gp_progress *progress)
{
    return progress ? progress->cancel : NULL;
}

#ifdef __cplusplus
}
#endif
#endif
