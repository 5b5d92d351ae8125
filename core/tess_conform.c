/* tess_conform.c - T-junctions out of a welded tessellation (tess_conform.h): an edge of a
 * cell in one of its faces only is split, in every face that has it, at the cell's vertices
 * that lie inside it. */
#include "tess_conform.h"

#include <math.h>
#include <stdlib.h>

#include "grainpack/error.h"
#include "grow.h"

/* An undirected edge, lo < hi. */
typedef struct pair {
    uint32_t lo, hi;
} pair;

/* Vertex m inside edge (lo, hi), at t of the way from lo to hi. */
typedef struct split {
    uint32_t lo, hi, m;
    double t;
} split;

static int pair_cmp(const void *pa, const void *pb)
{
    const pair *a = pa, *b = pb;
    if (a->lo != b->lo)
        return a->lo < b->lo ? -1 : 1;
    return a->hi < b->hi ? -1 : a->hi > b->hi;
}

static int split_cmp(const void *pa, const void *pb)
{
    const split *a = pa, *b = pb;
    if (a->lo != b->lo)
        return a->lo < b->lo ? -1 : 1;
    if (a->hi != b->hi)
        return a->hi < b->hi ? -1 : 1;
    if (a->t != b->t)
        return a->t < b->t ? -1 : 1;
    return a->m < b->m ? -1 : a->m > b->m;
}

/* Where vertex m lies on edge (lo, hi): its parameter from lo when it is within tol of the
 * segment and more than tol from both ends, -1 otherwise. */
static double inside(const double *xyz, pair e, uint32_t m, double tol)
{
    const double *a = &xyz[3 * (size_t)e.lo], *b = &xyz[3 * (size_t)e.hi], *p = &xyz[3 * (size_t)m];
    double ab[3], ap[3], len2 = 0.0, dot = 0.0;
    for (int d = 0; d < 3; d++) {
        ab[d] = b[d] - a[d];
        ap[d] = p[d] - a[d];
        len2 += ab[d] * ab[d];
        dot += ab[d] * ap[d];
    }
    if (!(len2 > 0.0))
        return -1.0;
    double t = dot / len2, len = sqrt(len2), off2 = 0.0;
    if (t * len <= tol || (1.0 - t) * len <= tol)
        return -1.0;
    for (int d = 0; d < 3; d++)
        off2 += (ap[d] - t * ab[d]) * (ap[d] - t * ab[d]);
    return off2 <= tol * tol ? t : -1.0;
}

/* An antisymmetric hash of the directed edge u -> w (f(w, u) = -f(u, w), mod 2^64). A cell's
 * faces, each looped outward, pass every edge once each way when they conform, so their
 * sum is exactly 0; an edge in one face only leaves it (almost surely) non-zero. That
 * spares the sort of the edges of every cell but the few with a T-junction (it was 8 % of
 * a whole run's instructions). */
static uint64_t directed(uint32_t u, uint32_t w)
{
    uint64_t hu = (uint64_t)u * 0x9E3779B97F4A7C15u + 1u, hw = (uint64_t)w * 0x9E3779B97F4A7C15u + 1u;
    uint64_t ku = ((uint64_t)u ^ 0x5BD1E9955BD1E995u) * 0xC2B2AE3D27D4EB4Fu;
    uint64_t kw = ((uint64_t)w ^ 0x5BD1E9955BD1E995u) * 0xC2B2AE3D27D4EB4Fu;
    return hu * kw - hw * ku;
}

/* Whether cell i's faces pass some edge other than once each way. */
static int suspect(const tess_faces *tf, size_t i)
{
    uint64_t sum = 0;
    for (size_t k = tf->cstart[i]; k < tf->cstart[i + 1]; k++) {
        int64_t id = tf->cface[k];
        if (!id)
            continue;
        size_t f = (size_t)(id < 0 ? -id : id) - 1, a = tf->fvstart[f], m = tf->fvstart[f + 1] - a;
        uint64_t loop = 0;
        for (size_t j = 0; j < m; j++)
            loop += directed(tf->fverts[a + j], tf->fverts[a + (j + 1) % m]);
        sum += id > 0 ? loop : (uint64_t)0 - loop; /* the other cell's face, looped the other way */
    }
    return sum != 0;
}

/* Appends cell i's edges (one pair per face side) to *edges; returns their count or -1. */
static long cell_edges(const tess_faces *tf, size_t i, pair **edges, size_t *cap)
{
    size_t n = 0;
    for (size_t k = tf->cstart[i]; k < tf->cstart[i + 1]; k++) {
        int64_t id = tf->cface[k];
        if (!id)
            continue;
        size_t f = (size_t)(id < 0 ? -id : id) - 1, a = tf->fvstart[f], m = tf->fvstart[f + 1] - a;
        pair *grown = grow(*edges, cap, n + m, sizeof *grown);
        if (!grown)
            return -1;
        *edges = grown;
        for (size_t j = 0; j < m; j++) {
            uint32_t u = tf->fverts[a + j], w = tf->fverts[a + (j + 1) % m];
            (*edges)[n++] = u < w ? (pair){u, w} : (pair){w, u};
        }
    }
    return (long)n;
}

/* The splits of every cell's once-used edges, sorted and without repeats. */
static int find_splits(const tess_faces *tf, double tol, split **out, size_t *nout)
{
    pair *edges = NULL;
    split *splits = NULL;
    size_t cap_edges = 0, cap_splits = 0, n_splits = 0;
    int rc = 0;
    for (size_t i = 0; i < tf->ncells && !rc; i++) {
        if (!suspect(tf, i))
            continue;
        long n = cell_edges(tf, i, &edges, &cap_edges);
        if (n < 0) {
            rc = GP_ENOMEM;
            break;
        }
        if (n > 0) /* qsort's array must not be NULL, even empty */
            qsort(edges, (size_t)n, sizeof *edges, pair_cmp);
        size_t once = 0; /* the once-used edges, moved to the front */
        for (size_t k = 0, j; k < (size_t)n; k = j) {
            for (j = k + 1; j < (size_t)n && !pair_cmp(&edges[j], &edges[k]); j++)
                ;
            if (j - k == 1)
                edges[once++] = edges[k];
        }
        /* an edge in one face only is matched by a path of the cell's other once-used edges
           through the vertices inside it: those are the splits */
        for (size_t e = 0; e < once && !rc; e++)
            for (size_t g = 0; g < once; g++) {
                const uint32_t ends[2] = {edges[g].lo, edges[g].hi};
                for (int s = 0; s < 2; s++) {
                    double t = g == e ? -1.0 : inside(tf->xyz, edges[e], ends[s], tol);
                    if (t < 0.0)
                        continue;
                    split *grown = grow(splits, &cap_splits, n_splits + 1, sizeof *grown);
                    if (!grown) {
                        rc = GP_ENOMEM;
                        break;
                    }
                    splits = grown;
                    splits[n_splits++] = (split){edges[e].lo, edges[e].hi, ends[s], t};
                }
            }
    }
    free(edges);
    if (rc) {
        free(splits);
        return rc;
    }
    if (n_splits) /* none at all is the rule: splits is then NULL */
        qsort(splits, n_splits, sizeof *splits, split_cmp);
    size_t kept = 0;
    for (size_t k = 0; k < n_splits; k++)
        if (!kept || splits[k].lo != splits[kept - 1].lo || splits[k].hi != splits[kept - 1].hi ||
            splits[k].m != splits[kept - 1].m)
            splits[kept++] = splits[k];
    *out = splits;
    *nout = kept;
    return 0;
}

/* The first split of edge (lo, hi) in the sorted splits, and their count in *n. */
static const split *splits_of(const split *s, size_t ns, uint32_t u, uint32_t w, size_t *n)
{
    pair key = u < w ? (pair){u, w} : (pair){w, u};
    size_t lo = 0, hi = ns;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        pair at = {s[mid].lo, s[mid].hi};
        if (pair_cmp(&at, &key) < 0)
            lo = mid + 1;
        else
            hi = mid;
    }
    size_t end = lo;
    while (end < ns && s[end].lo == key.lo && s[end].hi == key.hi)
        end++;
    *n = end - lo;
    return s + lo;
}

long gp_tess_conform(tess_faces *tf, double tol)
{
    split *splits;
    size_t n_splits;
    int rc = find_splits(tf, tol, &splits, &n_splits);
    if (rc)
        return rc;
    if (!n_splits) {
        free(splits);
        return 0;
    }
    size_t total = 0, n;
    for (size_t f = 0; f < tf->nf; f++) {
        size_t a = tf->fvstart[f], m = tf->fvstart[f + 1] - a;
        for (size_t j = 0; j < m; j++) {
            splits_of(splits, n_splits, tf->fverts[a + j], tf->fverts[a + (j + 1) % m], &n);
            total += 1 + n;
        }
    }
    size_t *fvstart = malloc((tf->nf + 1) * sizeof *fvstart);
    uint32_t *fverts = malloc((total + 1) * sizeof *fverts);
    if (!fvstart || !fverts) {
        free(fvstart);
        free(fverts);
        free(splits);
        return GP_ENOMEM;
    }
    size_t at = 0;
    for (size_t f = 0; f < tf->nf; f++) {
        size_t a = tf->fvstart[f], m = tf->fvstart[f + 1] - a;
        fvstart[f] = at;
        for (size_t j = 0; j < m; j++) {
            uint32_t u = tf->fverts[a + j], w = tf->fverts[a + (j + 1) % m];
            const split *s = splits_of(splits, n_splits, u, w, &n);
            fverts[at++] = u;
            for (size_t k = 0; k < n; k++) /* in the order met going from u to w */
                fverts[at++] = s[u < w ? k : n - 1 - k].m;
        }
    }
    fvstart[tf->nf] = at;
    size_t before = tf->fvstart[tf->nf];
    free(tf->fvstart);
    free(tf->fverts);
    tf->fvstart = fvstart;
    tf->fverts = fverts;
    free(splits);
    return (long)(at - before);
}
