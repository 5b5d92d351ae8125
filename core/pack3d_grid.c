/* pack3d_grid.c - the 3D packer's bucket grid: cells of side at least 2 R_max holding
 * lists of sphere ids, so that a position is tested against the spheres near it alone. */
#include <math.h>
#include <stdlib.h>

#include "grainpack/disk.h"
#include "grow.h"
#include "pack3d_internal.h"

int p3_grid_init(p3_grid *grid, const gp_box *box, double cell_min, size_t capacity)
{
    const double side[3] = {box->width, box->height, box->depth};
    double cells = 1.0;
    for (int a = 0; a < 3; a++) {
        double n = floor(side[a] / cell_min);
        if (n < 1.0)
            n = 1.0;
        cells *= n;
        if (!(cells <= P3_GRID_MAX_CELLS))
            return GP_ETOOBIG;
        grid->n[a] = (int32_t)n;
        grid->cell[a] = side[a] / n;
        grid->inv[a] = n / side[a];
    }
    size_t total = (size_t)cells;
    grid->head = malloc(total * sizeof *grid->head);
    grid->next = grow_realloc(NULL, capacity ? capacity : 1, sizeof *grid->next);
    if (!grid->head || !grid->next) {
        p3_grid_free(grid);
        return GP_ENOMEM;
    }
    for (size_t i = 0; i < total; i++)
        grid->head[i] = P3_NONE;
    return 0;
}

int p3_grid_reserve(p3_grid *grid, size_t capacity)
{
    int32_t *next = grow_realloc(grid->next, capacity, sizeof *next);
    if (!next)
        return GP_ENOMEM;
    grid->next = next;
    return 0;
}

void p3_grid_free(p3_grid *grid)
{
    free(grid->head);
    free(grid->next);
    grid->head = grid->next = NULL;
}

/* The cell index of coordinate v along axis a, clamped to the grid. */
static inline int32_t cell_of(const p3_grid *grid, int a, double v)
{
    double c = v * grid->inv[a];
    if (!(c >= 0.0))
        return 0;
    return c >= grid->n[a] ? grid->n[a] - 1 : (int32_t)c; /* truncation is floor here */
}

static inline size_t cell_index(const p3_grid *grid, int32_t i, int32_t j, int32_t k)
{
    return ((size_t)k * (size_t)grid->n[1] + (size_t)j) * (size_t)grid->n[0] + (size_t)i;
}

void p3_grid_insert(p3_grid *grid, int32_t id, double x, double y, double z)
{
    size_t c = cell_index(grid, cell_of(grid, 0, x), cell_of(grid, 1, y), cell_of(grid, 2, z));
    grid->next[id] = grid->head[c];
    grid->head[c] = id;
}

void p3_grid_range(const p3_grid *grid, double x, double y, double z, double reach, int32_t lo[3],
                   int32_t hi[3])
{
    const double p[3] = {x, y, z};
    for (int a = 0; a < 3; a++) {
        lo[a] = cell_of(grid, a, p[a] - reach);
        hi[a] = cell_of(grid, a, p[a] + reach);
    }
}

int p3_overlap(double ax, double ay, double az, double aR, const gp_sphere *b)
{
    double dx = ax - b->x, dy = ay - b->y, dz = az - b->z;
    double reach = (aR + b->R) * (1.0 - GP_CONTACT_RTOL);
    return dx * dx + dy * dy + dz * dz < reach * reach;
}

/* The first sphere of the cell list from `s` on that overlaps the ball (x, y, z, R), or
 * P3_NONE. reach2 is the square of the largest overlap distance, (R + R_max) (1 -
 * GP_CONTACT_RTOL): a sphere at least that far is not tested further (rounding is
 * monotone, so p3_overlap would say no), which spares the sum of radii most spheres of a
 * spread law would cost, and with one radius every sphere nearer overlaps. */
static inline int32_t list_first_overlap(const p3_grid *grid, const gp_sphere *spheres, int32_t s,
                                         double x, double y, double z, double R, double reach2)
{
    for (; s != P3_NONE; s = grid->next[s]) {
        const gp_sphere *b = &spheres[s];
        double dx = x - b->x, dy = y - b->y, dz = z - b->z;
        if (dx * dx + dy * dy + dz * dz < reach2 && p3_overlap(x, y, z, R, b))
            return s;
    }
    return P3_NONE;
}

/* The cell of the ball's centre is visited first: most positions tested are refused (nine
 * in ten while packing, docs/3d.md §5), and the sphere in the way is most often there.
 * Which sphere is returned changes nothing but the work: callers only ask whether one is. */
int32_t p3_grid_first_overlap(const p3_grid *grid, const gp_sphere *spheres, double x, double y,
                              double z, double R, double R_max)
{
    size_t home = cell_index(grid, cell_of(grid, 0, x), cell_of(grid, 1, y), cell_of(grid, 2, z));
    double reach = (R + R_max) * (1.0 - GP_CONTACT_RTOL), reach2 = reach * reach;
    int32_t s = list_first_overlap(grid, spheres, grid->head[home], x, y, z, R, reach2);
    if (s != P3_NONE)
        return s;
    int32_t lo[3], hi[3];
    p3_grid_range(grid, x, y, z, R + R_max, lo, hi);
    for (int32_t k = lo[2]; k <= hi[2]; k++)
        for (int32_t j = lo[1]; j <= hi[1]; j++) {
            const int32_t *row = p3_grid_row(grid, j, k);
            for (int32_t i = lo[0]; i <= hi[0]; i++)
                if (row + i != grid->head + home &&
                    (s = list_first_overlap(grid, spheres, row[i], x, y, z, R, reach2)) != P3_NONE)
                    return s;
        }
    return P3_NONE;
}
