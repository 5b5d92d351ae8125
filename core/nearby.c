/* nearby.c - the disks near the positions a balancing sweep tries: a cell-sorted copy of
 * the disks plus the lists of those moved since (see nearby.h). */
#include "nearby.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grainpack/error.h"
#include "grow.h"

/* A grid of about one cell per disk or fewer, as the packer's. */
#define CELLS_PER_DISK 8

static int grow_gathered(nearby *nb, size_t need);

/* Room for `need` gathered disks; 0 or GP_ENOMEM. Inline: a gathering asks once a row
 * and once a moved disk, and the room is nearly always there. */
static inline int reserve(nearby *nb, size_t need)
{
    return need <= nb->gcap ? 0 : grow_gathered(nb, need);
}

int nearby_init(nearby *nb, const gp_domain *domain, const gp_disk *disks, size_t n, double R_max)
{
    memset(nb, 0, sizeof *nb);
    if (n > (size_t)INT32_MAX)
        return GP_ETOOBIG;
    /* (cells of R_max instead: a tenth fewer disks read in a gathering, but as many more
     * rows, and more cells for settled.h to read: no faster) */
    int rc = gp_grid_init(&nb->grid, domain, R_max, n, CELLS_PER_DISK * n + 1024);
    if (rc)
        return rc;
    nb->R_max = R_max;
    size_t m = n ? n : 1;
    nb->n = n;
    nb->start = malloc((nb->grid.ncells + 1) * sizeof *nb->start);
    nb->sorted = malloc(m * sizeof *nb->sorted);
    nb->entry = malloc(m * sizeof *nb->entry);
    if (!nb->start || !nb->sorted || !nb->entry || reserve(nb, 64)) {
        nearby_free(nb);
        return GP_ENOMEM;
    }
    nearby_sort(nb, disks);
    return 0;
}

void nearby_sort(nearby *nb, const gp_disk *disks)
{
    gp_grid *g = &nb->grid;
    memset(g->head, 0xff, g->ncells * sizeof *g->head); /* the lists: all GP_GRID_NONE */
    /* a counting sort: start[c + 1] counts cell c, then the running sums place each disk */
    memset(nb->start, 0, (g->ncells + 1) * sizeof *nb->start);
    for (size_t i = 0; i < nb->n; i++)
        nb->start[gp_grid_cell(g, disks[i].x, disks[i].y) + 1]++;
    for (size_t c = 0; c < g->ncells; c++)
        nb->start[c + 1] += nb->start[c];
    for (size_t i = 0; i < nb->n; i++) {
        uint32_t e = nb->start[gp_grid_cell(g, disks[i].x, disks[i].y)]++;
        nb->sorted[e] = (nearby_entry){disks[i].x, disks[i].y, disks[i].R, (int64_t)i};
        nb->entry[i] = e;
    }
    /* each start[c] has moved on to the start of cell c + 1: shift back */
    memmove(nb->start + 1, nb->start, g->ncells * sizeof *nb->start);
    nb->start[0] = 0;
}

size_t nearby_prefetch_cells(const nearby *nb, double x, double y)
{
    const gp_grid *g = &nb->grid;
    size_t c = gp_grid_cell(g, x, y);
    for (int row = -1; row <= 1; row++) {
        size_t first = c + (size_t)((ptrdiff_t)row * g->stride) - 1;
        __builtin_prefetch(&nb->start[first]);
        __builtin_prefetch(&nb->start[first + 3]);
        __builtin_prefetch(&g->head[first]);
        __builtin_prefetch(&g->head[first + 3]);
    }
    return c;
}

void nearby_prefetch_entries(const nearby *nb, double x, double y)
{
    const gp_grid *g = &nb->grid;
    size_t c = gp_grid_cell(g, x, y);
    for (int row = -1; row <= 1; row++) {
        size_t first = c + (size_t)((ptrdiff_t)row * g->stride) - 1;
        const nearby_entry *e = nb->sorted + nb->start[first], *end = nb->sorted + nb->start[first + 3];
        /* two entries a cache line */
        for (; e < end; e += 2)
            __builtin_prefetch(e);
    }
}

void nearby_move(nearby *nb, const gp_disk *disks, int32_t id, double old_x, double old_y)
{
    nearby_entry *e = &nb->sorted[nb->entry[id]];
    if (isinf(e->x))
        gp_grid_remove(&nb->grid, id, old_x, old_y);
    else
        e->x = INFINITY; /* out of reach of every box: never gathered again */
    gp_grid_insert(&nb->grid, id, disks[id].x, disks[id].y);
}

/* reserve when the room is not there. */
static int grow_gathered(nearby *nb, size_t need)
{
    size_t cap = grow_capacity(nb->gcap, need);
    double *gx = cap ? grow_realloc(nb->gx, cap, sizeof *gx) : NULL;
    if (gx)
        nb->gx = gx;
    double *gy = gx ? grow_realloc(nb->gy, cap, sizeof *gy) : NULL;
    if (gy)
        nb->gy = gy;
    double *gr2 = gy ? grow_realloc(nb->gr2, cap, sizeof *gr2) : NULL;
    if (!gr2)
        return GP_ENOMEM;
    nb->gr2 = gr2;
    nb->gcap = cap;
    return 0;
}

/* The square of the distance under which a disk of radius Rq overlaps one of radius R:
 * gp_grid_first_overlap's predicate, (R + Rq)(1 - GP_CONTACT_RTOL). */
static double overlap_reach2(double Rq, double R)
{
    double reach = (Rq + R) * (1.0 - GP_CONTACT_RTOL);
    return reach * reach;
}

/* Appends a disk of radius Rq to the gathered ones when `keep` (room reserved): written
 * either way, counted only if kept, so that the loops around it have no branch to
 * mispredict. Its radius waits in gr2 for nearby_gather to turn it into the reach, once
 * the disks read but not kept are out of the way. */
static void keep_if(nearby *nb, double x, double y, double Rq, int keep)
{
    nb->gx[nb->gn] = x;
    nb->gy[nb->gn] = y;
    nb->gr2[nb->gn] = Rq;
    nb->gn += (size_t)keep;
}

/* Whether a disk of radius Rq at (x, y) is closer than R + Rq to the gathering's box. */
static int near_box(const nearby *nb, double x, double y, double Rq, double R)
{
    return nearby_box_reaches(nb->x0, nb->y0, nb->x1, nb->y1, x, y, Rq, R);
}

int nearby_gather(nearby *nb, const gp_disk *disks, int32_t id, double R, double x0, double y0,
                  double x1, double y1, double margin)
{
    const gp_grid *g = &nb->grid;
    nb->x0 = x0 - margin;
    nb->y0 = y0 - margin;
    nb->x1 = x1 + margin;
    nb->y1 = y1 + margin;
    nb->gn = 0;
    nb->gR = R;
    nb->blocker = SIZE_MAX;
    /* a disk that overlaps a disk of radius R in the box has its centre within
     * R + R_max of the box */
    double reach = R + nb->R_max;
    int32_t ix0, iy0, ix1, iy1;
    gp_grid_coords(g, nb->x0 - reach, nb->y0 - reach, &ix0, &iy0);
    gp_grid_coords(g, nb->x1 + reach, nb->y1 + reach, &ix1, &iy1);
    for (int32_t iy = iy0; iy <= iy1; iy++) {
        size_t first = gp_grid_index(g, ix0, iy), last = gp_grid_index(g, ix1, iy);
        uint32_t lo = nb->start[first], hi = nb->start[last + 1];
        if (reserve(nb, nb->gn + (hi - lo)))
            return GP_ENOMEM;
        for (const nearby_entry *e = nb->sorted + lo; e < nb->sorted + hi; e++)
            keep_if(nb, e->x, e->y, e->R, near_box(nb, e->x, e->y, e->R, R) & (e->id != id));
        for (size_t c = first; c <= last; c++)
            for (int32_t j = g->head[c]; j != GP_GRID_NONE; j = g->next[j]) {
                if (reserve(nb, nb->gn + 1))
                    return GP_ENOMEM;
                keep_if(nb, disks[j].x, disks[j].y, disks[j].R, near_box(nb, disks[j].x, disks[j].y, disks[j].R, R) & (j != id));
            }
    }
    for (size_t k = 0; k < nb->gn; k++)
        nb->gr2[k] = overlap_reach2(nb->gr2[k], R);
    return 0;
}

/* gp_grid_first_overlap's predicate: the centres closer than (R + Rq)(1 - GP_CONTACT_RTOL). */
static int overlaps(double dx, double dy, double Rq, double R)
{
    return !(dx * dx + dy * dy >= overlap_reach2(Rq, R));
}

/* nearby_is_clear_in_box's loop over the gathered disks runs two at a time in the x86-64
 * baseline's SSE2, four at a time with AVX2: built both ways where GCC can, the loader
 * picks the one the processor runs. The same operations on each disk either way (AVX2
 * alone brings no fused multiply-add), so the same answers. */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define CLEAR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define CLEAR_CLONES
#endif

CLEAR_CLONES int nearby_is_clear_in_box(nearby *nb, double x, double y)
{
    const double *gx = nb->gx, *gy = nb->gy, *gr2 = nb->gr2;
    size_t n = nb->gn;
    /* the disk that blocked the last position blocks most of the next ones (a
     * blocked centre tries twenty positions on one line) */
    if (nb->blocker < n) {
        size_t k = nb->blocker;
        double dx = gx[k] - x, dy = gy[k] - y;
        if (dx * dx + dy * dy < gr2[k])
            return 0;
    }
    /* every disk, without a branch: the loop runs two disks at a time */
    long hits = 0;
    for (size_t k = 0; k < n; k++) {
        double dx = gx[k] - x, dy = gy[k] - y;
        hits += dx * dx + dy * dy < gr2[k];
    }
    if (hits == 0)
        return 1;
    for (size_t k = 0; k < n; k++) {
        double dx = gx[k] - x, dy = gy[k] - y;
        if (dx * dx + dy * dy < gr2[k]) {
            nb->blocker = k;
            break;
        }
    }
    return 0;
}

int nearby_is_clear(nearby *nb, const gp_disk *disks, int32_t id, double R, double x, double y)
{
    if (nearby_in_box(nb, x, y, R))
        return nearby_is_clear_in_box(nb, x, y);
    /* outside the box: the cells within R + R_max of (x, y) */
    const gp_grid *g = &nb->grid;
    double reach = R + nb->R_max;
    int32_t ix0, iy0, ix1, iy1;
    gp_grid_coords(g, x - reach, y - reach, &ix0, &iy0);
    gp_grid_coords(g, x + reach, y + reach, &ix1, &iy1);
    for (int32_t iy = iy0; iy <= iy1; iy++) {
        size_t first = gp_grid_index(g, ix0, iy), last = gp_grid_index(g, ix1, iy);
        for (const nearby_entry *e = nb->sorted + nb->start[first]; e < nb->sorted + nb->start[last + 1]; e++)
            if (e->id != id && overlaps(e->x - x, e->y - y, e->R, R))
                return 0;
        for (size_t c = first; c <= last; c++)
            for (int32_t j = g->head[c]; j != GP_GRID_NONE; j = g->next[j])
                if (j != id && overlaps(disks[j].x - x, disks[j].y - y, disks[j].R, R))
                    return 0;
    }
    return 1;
}

void nearby_free(nearby *nb)
{
    gp_grid_free(&nb->grid);
    free(nb->start);
    free(nb->sorted);
    free(nb->entry);
    free(nb->gx);
    free(nb->gy);
    free(nb->gr2);
    memset(nb, 0, sizeof *nb);
}
