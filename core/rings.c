/* rings.c - the rings of every vertex of a triangulation in one array, refreshed where an
 * update changed them (see rings.h). */
#include "rings.h"

#include <stdlib.h>
#include <string.h>

#include "grainpack/error.h"
#include "grow.h"

/* *ids (capacity *cap) with room for `need` entries; 0 or GP_ENOMEM (*ids unchanged). */
static int reserve(int32_t **ids, size_t *cap, size_t need)
{
    int32_t *grown = grow(*ids, cap, need, sizeof *grown);
    if (!grown)
        return GP_ENOMEM;
    *ids = grown;
    return 0;
}

/* Reads the ring of vertex i into ids[at ..], growing ids; returns its degree, or
 * (size_t)-1 when out of memory. */
static size_t read_ring(const gp_rt *rt, int32_t i, int32_t **ids, size_t *cap, size_t at,
                        uint8_t *hull)
{
    for (;;) {
        int on_hull;
        size_t degree = gp_rt_ring(rt, i, *ids + at, *cap - at, &on_hull);
        if (at + degree <= *cap) {
            *hull = (uint8_t)on_hull;
            return degree;
        }
        if (reserve(ids, cap, at + degree + degree))
            return (size_t)-1;
    }
}

/* Builds the next version in the spare arrays, the rings of the vertices with changed[i]
 * set read from rt and the others copied, then swaps it in. A tenth or so of the rings
 * change in a sweep: reading those one by one is cheaper than walking all of them. */
static int build(rings *r, const gp_rt *rt, const uint8_t *changed, const gp_cancel_flag *cancel)
{
    /* the next version is about as long as this one: room for it and a little more */
    if (reserve(&r->spare_ids, &r->spare_cap, r->start[r->n] + r->start[r->n] / 16 + 64))
        return GP_ENOMEM;
    size_t at = 0;
    for (size_t i = 0; i < r->n; i++) {
        if (i % GP_RT_RINGS_PER_CHECK == GP_RT_RINGS_PER_CHECK - 1 && gp_canceled(cancel))
            return GP_ECANCELED;
        r->spare_start[i] = at;
        size_t degree;
        if (changed[i]) {
            degree = read_ring(rt, (int32_t)i, &r->spare_ids, &r->spare_cap, at, &r->hull[i]);
            if (degree == (size_t)-1)
                return GP_ENOMEM;
        } else {
            degree = r->start[i + 1] - r->start[i];
            if (reserve(&r->spare_ids, &r->spare_cap, at + degree))
                return GP_ENOMEM;
            memcpy(r->spare_ids + at, r->ids + r->start[i], degree * sizeof *r->ids);
        }
        at += degree;
    }
    r->spare_start[r->n] = at;
    size_t *start = r->start;
    int32_t *ids = r->ids;
    size_t cap = r->cap;
    r->start = r->spare_start;
    r->ids = r->spare_ids;
    r->cap = r->spare_cap;
    r->spare_start = start;
    r->spare_ids = ids;
    r->spare_cap = cap;
    return 0;
}

int rings_init(rings *r, const gp_rt *rt, size_t n, const gp_progress *progress)
{
    memset(r, 0, sizeof *r);
    r->n = n;
    r->start = malloc((n + 1) * sizeof *r->start);
    r->spare_start = malloc((n + 1) * sizeof *r->spare_start);
    r->hull = malloc(n ? n : 1);
    int rc = !r->start || !r->spare_start || !r->hull ? GP_ENOMEM
                                                      : gp_rt_rings(rt, r->start, r->hull, &r->ids, progress);
    if (rc) {
        rings_free(r);
        return rc;
    }
    r->cap = r->start[n];
    return 0;
}

int rings_refresh(rings *r, const gp_rt *rt, const uint8_t *changed, const gp_cancel_flag *cancel)
{
    size_t i = 0;
    while (i < r->n && !changed[i])
        i++;
    return i == r->n ? 0 : build(r, rt, changed, cancel);
}

void rings_free(rings *r)
{
    free(r->start);
    free(r->ids);
    free(r->hull);
    free(r->spare_start);
    free(r->spare_ids);
    memset(r, 0, sizeof *r);
}
