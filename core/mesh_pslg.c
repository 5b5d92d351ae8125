/* mesh_pslg.c - the planar straight-line graph a mesh is built on: points, segments,
 * region seeds, in arrays that grow. */
#include <stdlib.h>
#include <string.h>

#include "mesh_cdt.h"
#include "mesh_internal.h"

int gp_mesh_reserve(void **array, size_t *cap, size_t need, size_t size)
{
    if (need <= *cap)
        return 0;
    size_t cap2 = *cap ? *cap : 64;
    while (cap2 < need)
        cap2 *= 2;
    void *grown = realloc(*array, cap2 * size);
    if (!grown)
        return GP_ENOMEM;
    *array = grown;
    *cap = cap2;
    return 0;
}

int32_t gp_pslg_point(gp_pslg *g, double x, double y)
{
    if (g->npoints >= (size_t)INT32_MAX / 2 ||
        gp_mesh_reserve((void **)&g->xy, &g->xy_cap, 2 * (g->npoints + 1), sizeof *g->xy))
        return -1;
    g->xy[2 * g->npoints] = x;
    g->xy[2 * g->npoints + 1] = y;
    return (int32_t)g->npoints++;
}

int gp_pslg_segment(gp_pslg *g, int32_t a, int32_t b, int protect)
{
    if (gp_mesh_reserve((void **)&g->seg, &g->seg_cap, 2 * (g->nsegs + 1), sizeof *g->seg) ||
        gp_mesh_reserve((void **)&g->seg_protected, &g->protected_cap, g->nsegs + 1,
                        sizeof *g->seg_protected))
        return GP_ENOMEM;
    g->seg[2 * g->nsegs] = a;
    g->seg[2 * g->nsegs + 1] = b;
    g->seg_protected[g->nsegs++] = (uint8_t)(protect != 0);
    return 0;
}

int gp_pslg_seed(gp_pslg *g, double x, double y, int32_t region)
{
    if (gp_mesh_reserve((void **)&g->seed_xy, &g->seed_xy_cap, 2 * (g->nseeds + 1), sizeof *g->seed_xy) ||
        gp_mesh_reserve((void **)&g->seed_region, &g->seed_region_cap, g->nseeds + 1,
                        sizeof *g->seed_region))
        return GP_ENOMEM;
    g->seed_xy[2 * g->nseeds] = x;
    g->seed_xy[2 * g->nseeds + 1] = y;
    g->seed_region[g->nseeds++] = region;
    return 0;
}

int gp_pslg_strip(gp_pslg *g, int32_t a0, int32_t a1, int32_t b0, int32_t b1)
{
    if (gp_mesh_reserve((void **)&g->strip_corners, &g->strip_cap, 4 * (g->nstrips + 1),
                        sizeof *g->strip_corners))
        return GP_ENOMEM;
    int32_t *c = g->strip_corners + 4 * g->nstrips++;
    c[0] = a0;
    c[1] = a1;
    c[2] = b0;
    c[3] = b1;
    return 0;
}

void gp_pslg_free(gp_pslg *g)
{
    free(g->strip_corners);
    free(g->xy);
    free(g->seg);
    free(g->seg_protected);
    free(g->seed_xy);
    free(g->seed_region);
    memset(g, 0, sizeof *g);
}
