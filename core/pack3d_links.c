/* pack3d_links.c - the triangles a new sphere adds to the 3D front (docs/3d.md §3): the
 * pairs of its links (the nearest spheres and walls within the link gap) that are linked
 * to each other too. */
#include <math.h>

#include "pack3d_internal.h"

/* A link of the new sphere: a sphere id or a wall, and the gap to it. */
typedef struct link {
    int32_t id;
    double gap;
} link;

/* The gap between sphere s's packing sphere and wall w. */
static double wall_gap(const p3_packer *pk, const gp_sphere *s, int w)
{
    const double side[3] = {pk->box->width, pk->box->height, pk->box->depth};
    const double p[3] = {s->x, s->y, s->z};
    double d = w % 2 ? side[w / 2] - p[w / 2] : p[w / 2];
    return d - s->R;
}

static double dist2(const gp_sphere *a, const gp_sphere *b)
{
    double dx = a->x - b->x, dy = a->y - b->y, dz = a->z - b->z;
    return dx * dx + dy * dy + dz * dz;
}

/* The largest centre distance at which spheres a and b are linked: their radii and the
 * link gap P3_LINK_GAP times the larger radius. */
static double link_reach(const p3_packer *pk, const gp_sphere *a, const gp_sphere *b)
{
    return a->R + b->R + pk->gap * (a->R > b->R ? a->R : b->R);
}

/* Inserts (id, gap) among the n links kept, sorted by gap, at most P3_LINKS; returns the
 * new count. */
static int keep_nearest(link *links, int n, int32_t id, double gap)
{
    if (n == P3_LINKS && !(gap < links[n - 1].gap))
        return n;
    int i = n < P3_LINKS ? n++ : n - 1;
    while (i > 0 && links[i - 1].gap > gap) {
        links[i] = links[i - 1];
        i--;
    }
    links[i] = (link){id, gap};
    return n;
}

/* The spheres linked with c, nearest first (at most P3_LINKS), then the walls. */
static int gather(const p3_packer *pk, int32_t c, link *links)
{
    const gp_sphere *s = &pk->spheres[c];
    int32_t lo[3], hi[3];
    p3_grid_range(&pk->grid, s->x, s->y, s->z, s->R + pk->R_max + pk->gap * pk->R_max, lo, hi);
    int n = 0;
    for (int32_t k = lo[2]; k <= hi[2]; k++)
        for (int32_t j = lo[1]; j <= hi[1]; j++)
            for (int32_t i = lo[0]; i <= hi[0]; i++)
                for (int32_t q = p3_grid_cell(&pk->grid, i, j, k); q != P3_NONE; q = pk->grid.next[q]) {
                    if (q == c)
                        continue;
                    const gp_sphere *o = &pk->spheres[q];
                    double d2 = dist2(s, o), reach = link_reach(pk, s, o);
                    if (d2 < reach * reach)
                        n = keep_nearest(links, n, q, sqrt(d2) - s->R - o->R);
                }
    for (int w = 0; w < P3_WALLS; w++) {
        double gap = wall_gap(pk, s, w);
        if (gap < pk->gap * pk->R_max)
            links[n++] = (link){P3_WALL(w), gap};
    }
    return n;
}

/* Whether links a and b are within the link gap of each other. */
static int linked(const p3_packer *pk, int32_t a, int32_t b)
{
    if (P3_IS_WALL(a) && P3_IS_WALL(b))
        return P3_WALL_INDEX(a) / 2 != P3_WALL_INDEX(b) / 2; /* walls across an axis never */
    if (P3_IS_WALL(a))
        return wall_gap(pk, &pk->spheres[b], P3_WALL_INDEX(a)) < pk->gap * pk->R_max;
    if (P3_IS_WALL(b))
        return wall_gap(pk, &pk->spheres[a], P3_WALL_INDEX(b)) < pk->gap * pk->R_max;
    const gp_sphere *sa = &pk->spheres[a], *sb = &pk->spheres[b];
    double reach = link_reach(pk, sa, sb);
    return dist2(sa, sb) < reach * reach;
}

/* The member of triangle `parent` that is neither a nor b, when it is a sphere (the side
 * of the new triangle (c, a, b) the tetrahedron fills); P3_NONE otherwise. */
static int32_t behind_of(const p3_packer *pk, int32_t parent, int32_t a, int32_t b)
{
    if (parent == P3_NONE)
        return P3_NONE;
    const int32_t *m = pk->fr.tris[parent].m;
    int32_t third = P3_NONE;
    int hits = 0;
    for (int i = 0; i < 3; i++) {
        if (m[i] == a || m[i] == b)
            hits++;
        else
            third = m[i];
    }
    return hits == 2 && third >= 0 ? third : P3_NONE;
}

/* The links on each side of the plane of c and spheres a and b that are linked to a, b
 * and c (tetrahedra c a b s), given as the bit mask `common` over links[]: side[0] one
 * below the plane (or P3_NONE), side[1] one above. */
static void closing_spheres(const p3_packer *pk, int32_t c, int32_t a, int32_t b, const link *links,
                            uint32_t common, int32_t side[2])
{
    side[0] = side[1] = P3_NONE;
    const gp_sphere *sc = &pk->spheres[c], *sa = &pk->spheres[a], *sb = &pk->spheres[b];
    double u[3] = {sa->x - sc->x, sa->y - sc->y, sa->z - sc->z};
    double v[3] = {sb->x - sc->x, sb->y - sc->y, sb->z - sc->z};
    double nrm[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    for (; common; common &= common - 1) {
        const gp_sphere *s = &pk->spheres[links[__builtin_ctz(common)].id];
        double o = nrm[0] * (s->x - sc->x) + nrm[1] * (s->y - sc->y) + nrm[2] * (s->z - sc->z);
        if (o != 0.0)
            side[o > 0.0] = links[__builtin_ctz(common)].id;
    }
}

int p3_link(p3_packer *pk, int32_t c, int32_t parent)
{
    link links[P3_LINKS + P3_WALLS];
    uint32_t adj[P3_LINKS + P3_WALLS] = {0}, spheres = 0; /* bit masks over links[] */
    int n = gather(pk, c, links);
    for (int i = 0; i < n; i++) {
        if (!P3_IS_WALL(links[i].id))
            spheres |= 1u << i;
        for (int j = i + 1; j < n; j++)
            if (linked(pk, links[i].id, links[j].id)) {
                adj[i] |= 1u << j;
                adj[j] |= 1u << i;
            }
    }
    for (int i = 0; i < n; i++)
        for (uint32_t later = adj[i] & ~((2u << i) - 1); later; later &= later - 1) {
            int j = __builtin_ctz(later);
            int32_t a = links[i].id, b = links[j].id;
            int32_t behind = behind_of(pk, parent, a, b);
            if (!P3_IS_WALL(a) && !P3_IS_WALL(b)) {
                int32_t side[2];
                closing_spheres(pk, c, a, b, links, adj[i] & adj[j] & spheres, side);
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
