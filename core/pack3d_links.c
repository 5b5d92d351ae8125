/* pack3d_links.c - the triangles a new sphere adds to the 3D front (docs/3d.md §3): the
 * pairs of its links (the nearest spheres and walls within the link gap) that are linked
 * to each other too. */
#include <math.h>
#include <string.h>

#include "pack3d_internal.h"

/* A link of the new sphere: a sphere id or a wall, the gap to it, and a copy of the
 * sphere's centre and packing radius (the pair tests below read them O(links^2) times). */
typedef struct link {
    int32_t id;
    double gap;
    double x, y, z, R;
} link;

/* The gap between the packing sphere (p, R) and wall w. */
static double wall_gap(const p3_packer *pk, double x, double y, double z, double R, int w)
{
    const double side[3] = {pk->box->width, pk->box->height, pk->box->depth};
    const double p[3] = {x, y, z};
    double d = w % 2 ? side[w / 2] - p[w / 2] : p[w / 2];
    return d - R;
}

/* The squared distance of two centres. */
static inline double dist2(double ax, double ay, double az, double bx, double by, double bz)
{
    double dx = ax - bx, dy = ay - by, dz = az - bz;
    return dx * dx + dy * dy + dz * dz;
}

/* The largest centre distance at which spheres of packing radii a and b are linked: their
 * radii and the link gap P3_LINK_GAP times the larger radius. */
static inline double link_reach(const p3_packer *pk, double a, double b)
{
    return a + b + pk->gap * (a > b ? a : b);
}

/* Inserts l among the n links kept, sorted by gap (after those of an equal gap), at most
 * P3_LINKS; returns the new count. */
static int keep_nearest(link *links, int n, const link *l)
{
    if (n == P3_LINKS && !(l->gap < links[n - 1].gap))
        return n;
    int i = n < P3_LINKS ? n++ : n - 1;
    while (i > 0 && links[i - 1].gap > l->gap) {
        links[i] = links[i - 1];
        i--;
    }
    links[i] = *l;
    return n;
}

/* Appends the walls linked with sphere s after the n links, returns the new count. A
 * periodic axis has no walls. */
static int gather_walls(const p3_packer *pk, const gp_sphere *s, link *links, int n)
{
    for (int w = 0; w < P3_WALLS; w++) {
        if (p3_periodic_axis(pk->box, w / 2))
            continue;
        double gap = wall_gap(pk, s->x, s->y, s->z, s->R, w);
        if (gap < pk->gap * pk->R_max)
            links[n++] = (link){P3_WALL(w), gap, 0.0, 0.0, 0.0, 0.0};
    }
    return n;
}

/* gather() on a periodic box: the grid's cells modulo the box, each sphere at its image
 * nearest c (so that the links' centres, relative to c and to each other, are those of
 * the images that touch: GP_PACK_MIN_PERIOD_RADII keeps them within half a side). */
static int gather_periodic(const p3_packer *pk, int32_t c, link *links)
{
    const gp_sphere *s = &pk->spheres[c];
    const p3_grid *grid = &pk->grid;
    const double p[3] = {s->x, s->y, s->z};
    int32_t lo[3], count[3];
    p3_grid_span(grid, pk->box->periodic, p, s->R + pk->R_max + pk->gap * pk->R_max, lo, count);
    int n = 0;
    for (int32_t k = lo[2]; k < lo[2] + count[2]; k++)
        for (int32_t j = lo[1]; j < lo[1] + count[1]; j++)
            for (int32_t i = lo[0]; i < lo[0] + count[0]; i++) {
                int32_t q = p3_grid_cell(grid, p3_wrap_cell(i, grid->n[0]), p3_wrap_cell(j, grid->n[1]),
                                         p3_wrap_cell(k, grid->n[2]));
                for (; q != P3_NONE; q = grid->next[q]) {
                    const gp_sphere *o = &pk->spheres[q];
                    double d[3] = {o->x - s->x, o->y - s->y, o->z - s->z};
                    p3_min_image(pk->box, d);
                    double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2], reach = link_reach(pk, s->R, o->R);
                    if (d2 < reach * reach && q != c) {
                        link l = {q, sqrt(d2) - s->R - o->R, s->x + d[0], s->y + d[1], s->z + d[2], o->R};
                        n = keep_nearest(links, n, &l);
                    }
                }
            }
    return gather_walls(pk, s, links, n);
}

/* The spheres linked with c, nearest first (at most P3_LINKS; of equal gaps, the first met
 * in the grid's order), then the walls. (Skipping the cells of the range beyond the reach
 * cost more than it saved: 14 325 -> 15 378 instructions a sphere, one radius.) */
static int gather(const p3_packer *pk, int32_t c, link *links)
{
    if (pk->box->periodic)
        return gather_periodic(pk, c, links);
    const gp_sphere *s = &pk->spheres[c];
    const p3_grid *grid = &pk->grid;
    double query = s->R + pk->R_max + pk->gap * pk->R_max;
    int32_t lo[3], hi[3];
    p3_grid_range(grid, s->x, s->y, s->z, query, lo, hi);
    /* every link's reach is within the query's (rounding is monotone), and four spheres
     * in five of the range are beyond it: they are turned away before their own reach */
    double query2 = query * query;
    int n = 0;
    for (int32_t k = lo[2]; k <= hi[2]; k++) {
        for (int32_t j = lo[1]; j <= hi[1]; j++) {
            const int32_t *row = p3_grid_row(grid, j, k);
            for (int32_t i = lo[0]; i <= hi[0]; i++) {
                for (int32_t q = row[i]; q != P3_NONE; q = grid->next[q]) {
                    const gp_sphere *o = &pk->spheres[q];
                    double d2 = dist2(s->x, s->y, s->z, o->x, o->y, o->z);
                    if (!(d2 < query2))
                        continue;
                    double reach = link_reach(pk, s->R, o->R);
                    if (d2 < reach * reach && q != c) {
                        link l = {q, sqrt(d2) - s->R - o->R, o->x, o->y, o->z, o->R};
                        n = keep_nearest(links, n, &l);
                    }
                }
            }
        }
    }
    return gather_walls(pk, s, links, n);
}

/* The bit masks adj[] of the links within the link gap of each other (walls across an
 * axis never). The first ns links are the spheres, the walls follow (gather). */
static void adjacency(const p3_packer *pk, const link *links, int ns, int n, uint32_t *adj)
{
    for (int i = 0; i < n; i++)
        adj[i] = 0;
    double wall_reach = pk->gap * pk->R_max;
    for (int i = 0; i < ns; i++) {
        const link *a = &links[i];
        for (int j = i + 1; j < ns; j++) {
            const link *b = &links[j];
            double reach = link_reach(pk, a->R, b->R);
            if (dist2(a->x, a->y, a->z, b->x, b->y, b->z) < reach * reach) {
                adj[i] |= 1u << j;
                adj[j] |= 1u << i;
            }
        }
        for (int w = ns; w < n; w++)
            if (wall_gap(pk, a->x, a->y, a->z, a->R, P3_WALL_INDEX(links[w].id)) < wall_reach) {
                adj[i] |= 1u << w;
                adj[w] |= 1u << i;
            }
    }
    for (int v = ns; v < n; v++)
        for (int w = v + 1; w < n; w++)
            if (P3_WALL_INDEX(links[v].id) / 2 != P3_WALL_INDEX(links[w].id) / 2) {
                adj[v] |= 1u << w;
                adj[w] |= 1u << v;
            }
}

/* For each link, its index among the members of triangle `parent` (-1 when it is not
 * one): the new triangle (c, a, b) of two members has the third behind it. */
static void parent_members(const p3_packer *pk, int32_t parent, const link *links, int n, int8_t *member)
{
    for (int i = 0; i < n; i++) {
        member[i] = -1;
        for (int k = 0; parent != P3_NONE && k < 3; k++)
            if (pk->fr.tris[parent].m[k] == links[i].id)
                member[i] = (int8_t)k;
    }
}

/* The links on each side of the plane of c and spheres a and b that are linked to a, b
 * and c (tetrahedra c a b s), given as the bit mask `common` over links[] and their
 * centres relative to c's in rel[]: side[0] one below the plane (or P3_NONE), side[1] one
 * above. */
static void closing_spheres(const double (*rel)[3], int a, int b, const link *links, uint32_t common,
                            int32_t side[2])
{
    side[0] = side[1] = P3_NONE;
    const double *u = rel[a], *v = rel[b];
    double nrm[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    for (; common; common &= common - 1) {
        int k = __builtin_ctz(common);
        double o = nrm[0] * rel[k][0] + nrm[1] * rel[k][1] + nrm[2] * rel[k][2];
        if (o != 0.0)
            side[o > 0.0] = links[k].id;
        if (side[0] != P3_NONE && side[1] != P3_NONE)
            return; /* closed: which spheres close it does not matter */
    }
}

int p3_link(p3_packer *pk, int32_t c, int32_t parent)
{
    link links[P3_LINKS + P3_WALLS];
    uint32_t adj[P3_LINKS + P3_WALLS]; /* bit masks over links[] */
    int8_t member[P3_LINKS + P3_WALLS];
    int n = gather(pk, c, links), ns = 0;
    double rel[P3_LINKS][3]; /* the spheres' centres relative to c's */
    const gp_sphere *sc = &pk->spheres[c];
    while (ns < n && !P3_IS_WALL(links[ns].id)) {
        rel[ns][0] = links[ns].x - sc->x;
        rel[ns][1] = links[ns].y - sc->y;
        rel[ns][2] = links[ns].z - sc->z;
        ns++;
    }
    uint32_t spheres = (1u << ns) - 1; /* bit mask over links[] */
    adjacency(pk, links, ns, n, adj);
    parent_members(pk, parent, links, n, member);
    int32_t pm[3] = {P3_NONE, P3_NONE, P3_NONE}; /* a copy: a push below may move the pool */
    if (parent != P3_NONE)
        memcpy(pm, pk->fr.tris[parent].m, sizeof pm);
    for (int i = 0; i < n; i++)
        for (uint32_t later = adj[i] & ~((2u << i) - 1); later; later &= later - 1) {
            int j = __builtin_ctz(later);
            int32_t a = links[i].id, b = links[j].id, behind = P3_NONE;
            if (member[i] >= 0 && member[j] >= 0 && pm[3 - member[i] - member[j]] >= 0)
                behind = pm[3 - member[i] - member[j]];
            if (!P3_IS_WALL(a) && !P3_IS_WALL(b)) {
                int32_t side[2];
                closing_spheres((const double(*)[3])rel, i, j, links, adj[i] & adj[j] & spheres, side);
                if (side[0] != P3_NONE && side[1] != P3_NONE)
                    continue; /* a tetrahedron on either side: closed (docs/3d.md §3) */
                if (behind == P3_NONE)
                    behind = side[0] != P3_NONE ? side[0] : side[1];
            }
            int32_t m[3] = {c, a, b};
            if (p3_front_push(&pk->fr, m, behind, p3_key(pk, m)))
                return GP_ENOMEM;
        }
    return 0;
}
