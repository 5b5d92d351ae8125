/* io_tess.c - the unshrunk power polyhedra as a Neper tessellation (.tess, format 3.4 as
 * Neper 4 writes it; fields as Neper's documentation lists them): the cells' own vertices
 * welded into shared ones, one face per pair of grains (or per grain on a wall), edges
 * from the welded faces, a cube domain. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "grainpack/io3d.h"
#include "tess_conform.h"

#define NONE UINT32_MAX
/* The format version written: Neper 4.x writes and reads 3.4 (its documentation's field
 * list is the same). */
#define TESS_FORMAT "3.4"

/* The weld grid's cell side, in tol: cells far wider than tol, so that a vertex is
 * compared with the vertices of its own cell only, unless it lies within tol of a side
 * (one vertex in WELD_CELL_TOLS / 2 per axis); still far below the spacing of a cell's
 * vertices (some 1e-1 R against tol = GP_TESS_WELD_RTOL R), so cells hold one vertex. */
#define WELD_CELL_TOLS 256.0
/* Passes of gp_tess_conform before the faces are taken as not conforming: each pass splits
 * what the cells' own once-used edges show; one is the rule, a second when a split shows
 * another cell's missing vertex. */
#define CONFORM_PASSES 4

/* A hash of the weld grid's occupied buckets (side WELD_CELL_TOLS tol): key -> first vertex. */
typedef struct bucket {
    int64_t key[3];
    uint32_t head;
} bucket;

typedef struct tess {
    const gp_cells3d *c;
    double tol;
    /* welded vertices */
    size_t nv;
    double *xyz;       /* 3 per vertex */
    uint32_t *vnext;   /* next vertex in the same bucket */
    uint32_t *map;     /* cell vertex -> welded vertex */
    bucket *buckets;
    size_t nbuckets;   /* a power of two */
    /* faces */
    size_t nf;
    size_t *fvstart;   /* nf + 1 offsets into fverts and fedges */
    uint32_t *fverts;
    int64_t *fedges;   /* signed edge ids (1-based), edge k from vertex k to k + 1 */
    int32_t *fother;   /* the grain or wall across the face from its first cell */
    uint8_t *frefs;    /* polyhedra listing the face */
    int64_t *face_of;  /* cell face -> signed face id, 0 when it welded away */
    /* edges */
    size_t ne;
    uint32_t *ev;      /* 2 per edge, as first met */
    uint32_t *enext, *ehead;
} tess;

static void tess_free(tess *t)
{
    free(t->xyz);
    free(t->vnext);
    free(t->map);
    free(t->buckets);
    free(t->fvstart);
    free(t->fverts);
    free(t->fedges);
    free(t->fother);
    free(t->frefs);
    free(t->face_of);
    free(t->ev);
    free(t->enext);
    free(t->ehead);
}

static size_t bucket_slot(const tess *t, const int64_t k[3])
{
    uint64_t h = (uint64_t)k[0] * 0x9E3779B97F4A7C15u ^ (uint64_t)k[1] * 0xC2B2AE3D27D4EB4Fu ^
                 (uint64_t)k[2] * 0x165667B19E3779F9u;
    size_t s = (size_t)(h ^ (h >> 29)) & (t->nbuckets - 1);
    while (t->buckets[s].head != NONE &&
           (t->buckets[s].key[0] != k[0] || t->buckets[s].key[1] != k[1] || t->buckets[s].key[2] != k[2]))
        s = (s + 1) & (t->nbuckets - 1);
    return s;
}

/* The welded vertex within tol of p: an existing one in its bucket or in the neighbouring
 * buckets it lies within tol of, or a new. */
static uint32_t weld(tess *t, const double *p)
{
    double h = WELD_CELL_TOLS * t->tol;
    int64_t k[3];
    int lo[3], hi[3];
    for (int d = 0; d < 3; d++) {
        double cell = floor(p[d] / h);
        k[d] = (int64_t)cell;
        lo[d] = p[d] - cell * h <= t->tol ? -1 : 0;
        hi[d] = (cell + 1.0) * h - p[d] <= t->tol ? 1 : 0;
    }
    for (int dx = lo[0]; dx <= hi[0]; dx++)
        for (int dy = lo[1]; dy <= hi[1]; dy++)
            for (int dz = lo[2]; dz <= hi[2]; dz++) {
                int64_t q[3] = {k[0] + dx, k[1] + dy, k[2] + dz};
                for (uint32_t v = t->buckets[bucket_slot(t, q)].head; v != NONE; v = t->vnext[v]) {
                    const double *w = &t->xyz[3 * (size_t)v];
                    double ddx = w[0] - p[0], ddy = w[1] - p[1], ddz = w[2] - p[2];
                    if (ddx * ddx + ddy * ddy + ddz * ddz <= t->tol * t->tol)
                        return v;
                }
            }
    size_t s = bucket_slot(t, k);
    uint32_t v = (uint32_t)t->nv++;
    memcpy(&t->xyz[3 * (size_t)v], p, 3 * sizeof *p);
    t->vnext[v] = t->buckets[s].head;
    t->buckets[s] = (bucket){{k[0], k[1], k[2]}, v};
    return v;
}

/* The signed id of the edge a -> b, made when new. */
static int64_t edge(tess *t, uint32_t a, uint32_t b)
{
    uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
    for (uint32_t e = t->ehead[lo]; e != NONE; e = t->enext[e]) {
        uint32_t other = t->ev[2 * (size_t)e] == lo ? t->ev[2 * (size_t)e + 1] : t->ev[2 * (size_t)e];
        if (other == hi)
            return t->ev[2 * (size_t)e] == a ? (int64_t)e + 1 : -((int64_t)e + 1);
    }
    uint32_t e = (uint32_t)t->ne++;
    t->ev[2 * (size_t)e] = a;
    t->ev[2 * (size_t)e + 1] = b;
    t->enext[e] = t->ehead[lo];
    t->ehead[lo] = e;
    return (int64_t)e + 1;
}

/* The face of cell i towards grain nb < i, made when nb's cells were read. */
static int64_t face_from(const tess *t, size_t nb, size_t i)
{
    const gp_cells3d *c = t->c;
    for (size_t f = c->fstart[nb]; f < c->fstart[nb + 1]; f++)
        if (c->fneighbour[f] == (int32_t)i)
            return t->face_of[f];
    return 0;
}

/* Splits the faces' edges at the vertices inside them (tess_conform.h). Returns 0, or
 * GP_ENOMEM / GP_EGEOM with err set. */
static int conform(tess *t, gp_error *err)
{
    const gp_cells3d *c = t->c;
    tess_faces faces = {t->nf, t->fvstart, t->fverts, t->xyz, c->count, c->fstart, t->face_of};
    long added = 0;
    for (int pass = 0; pass <= CONFORM_PASSES; pass++) {
        added = gp_tess_conform(&faces, t->tol);
        t->fvstart = faces.fvstart; /* replaced when vertices were inserted */
        t->fverts = faces.fverts;
        if (added <= 0)
            break;
    }
    if (added < 0)
        return gp_error_set(err, (int)added, NULL, "out of memory for the tessellation");
    if (added > 0)
        return gp_error_set(err, GP_EGEOM, NULL, "the tessellation's faces stay non-conforming "
                            "after %d passes", CONFORM_PASSES + 1);
    return 0;
}

/* The edges of the welded faces, numbered as first met, and each face's signed edge ids. */
static int make_edges(tess *t, gp_error *err)
{
    size_t uses = t->fvstart[t->nf];
    int64_t *fedges = realloc(t->fedges, (uses + 1) * sizeof *fedges);
    if (fedges)
        t->fedges = fedges;
    uint32_t *ev = realloc(t->ev, 2 * (uses + 1) * sizeof *ev);
    if (ev)
        t->ev = ev;
    uint32_t *enext = realloc(t->enext, (uses + 1) * sizeof *enext);
    if (enext)
        t->enext = enext;
    if (!fedges || !ev || !enext)
        return gp_error_set(err, GP_ENOMEM, NULL, "out of memory for the tessellation");
    for (size_t f = 0; f < t->nf; f++) {
        size_t a = t->fvstart[f], n = t->fvstart[f + 1] - a;
        for (size_t k = 0; k < n; k++)
            t->fedges[a + k] = edge(t, t->fverts[a + k], t->fverts[a + (k + 1) % n]);
    }
    return 0;
}

static int build(tess *t, gp_error *err)
{
    const gp_cells3d *c = t->c;
    size_t nverts = c->vstart[c->count], nfaces = c->fstart[c->count], nfv = c->fvstart[nfaces];
    for (t->nbuckets = 16; t->nbuckets < 2 * nverts; t->nbuckets *= 2)
        ;
    t->xyz = malloc(3 * (nverts + 1) * sizeof *t->xyz);
    t->vnext = malloc((nverts + 1) * sizeof *t->vnext);
    t->map = malloc((nverts + 1) * sizeof *t->map);
    t->buckets = malloc(t->nbuckets * sizeof *t->buckets);
    t->fvstart = malloc((nfaces + 1) * sizeof *t->fvstart);
    t->fverts = malloc((nfv + 1) * sizeof *t->fverts);
    t->fedges = malloc((nfv + 1) * sizeof *t->fedges);
    t->fother = malloc((nfaces + 1) * sizeof *t->fother);
    t->frefs = calloc(nfaces + 1, sizeof *t->frefs);
    t->face_of = calloc(nfaces + 1, sizeof *t->face_of);
    t->ev = malloc(2 * (nfv + 1) * sizeof *t->ev);
    t->enext = malloc((nfv + 1) * sizeof *t->enext);
    t->ehead = malloc((nverts + 1) * sizeof *t->ehead);
    if (!t->xyz || !t->vnext || !t->map || !t->buckets || !t->fvstart || !t->fverts || !t->fedges ||
        !t->fother || !t->frefs || !t->face_of || !t->ev || !t->enext || !t->ehead)
        return gp_error_set(err, GP_ENOMEM, NULL, "out of memory for the tessellation");
    if (nverts >= NONE)
        return gp_error_set(err, GP_ETOOBIG, NULL, "too many vertices for the tessellation");
    for (size_t s = 0; s < t->nbuckets; s++)
        t->buckets[s].head = NONE;
    for (size_t k = 0; k < nverts; k++)
        t->map[k] = weld(t, &c->xyz[3 * k]);
    for (size_t v = 0; v < t->nv; v++)
        t->ehead[v] = NONE;

    t->fvstart[0] = 0;
    for (size_t i = 0; i < c->count; i++) {
        size_t faces = 0;
        for (size_t f = c->fstart[i]; f < c->fstart[i + 1]; f++) {
            int32_t nb = c->fneighbour[f];
            if (nb >= 0 && (size_t)nb < i) { /* made from nb's side: listed reversed */
                int64_t id = face_from(t, (size_t)nb, i);
                if (id > 0) {
                    t->face_of[f] = -id;
                    t->frefs[id - 1]++;
                    faces++;
                }
                continue;
            }
            size_t at = t->fvstart[t->nf], n = 0;
            for (size_t k = c->fvstart[f]; k < c->fvstart[f + 1]; k++) {
                uint32_t g = t->map[c->vstart[i] + c->fverts[k]];
                if (n == 0 || t->fverts[at + n - 1] != g)
                    t->fverts[at + n++] = g;
            }
            while (n > 1 && t->fverts[at + n - 1] == t->fverts[at])
                n--;
            if (n < 3)
                continue; /* welded into an edge or a point: not a face */
            t->fother[t->nf] = nb;
            t->frefs[t->nf] = 1;
            t->face_of[f] = (int64_t)++t->nf;
            t->fvstart[t->nf] = at + n;
            faces++;
        }
        if (faces < 4)
            return gp_error_set(err, GP_EGEOM, NULL, "the power cell of grain %zu welds into %zu faces",
                                i, faces);
    }
    for (size_t f = 0; f < t->nf; f++)
        if (t->frefs[f] != (GP_IS_WALL3D(t->fother[f]) ? 1 : 2))
            return gp_error_set(err, GP_EGEOM, NULL,
                                "the face between grains %d and %d is not in both cells",
                                (int)t->fother[f], (int)f);
    int rc = conform(t, err);
    return rc ? rc : make_edges(t, err);
}

/* The unit normal (Newell's) and the plane offset of welded face f. */
static void face_plane(const tess *t, size_t f, double n[3], double *d)
{
    double c[3] = {0, 0, 0};
    n[0] = n[1] = n[2] = 0.0;
    size_t a = t->fvstart[f], m = t->fvstart[f + 1] - a;
    for (size_t k = 0; k < m; k++) {
        const double *p = &t->xyz[3 * (size_t)t->fverts[a + k]];
        const double *q = &t->xyz[3 * (size_t)t->fverts[a + (k + 1) % m]];
        n[0] += (p[1] - q[1]) * (p[2] + q[2]);
        n[1] += (p[2] - q[2]) * (p[0] + q[0]);
        n[2] += (p[0] - q[0]) * (p[1] + q[1]);
        for (int j = 0; j < 3; j++)
            c[j] += p[j] / (double)m;
    }
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int j = 0; j < 3; j++)
        n[j] = len > 0.0 ? n[j] / len : 0.0;
    *d = n[0] * c[0] + n[1] * c[1] + n[2] * c[2];
}

static void numbers(gp_out *o, const double *v, int n)
{
    for (int k = 0; k < n; k++) {
        gp_out_char(o, ' ');
        gp_out_double(o, v[k]);
    }
}

static void cell_section(gp_out *o, const gp_sphere *s, size_t n)
{
    GP_OUT_LITERAL(o, " **cell\n  ");
    gp_out_uint(o, n);
    /* a Laguerre seed: power distance |x - c|^2 - R^2, the weight Neper's radius-like w */
    GP_OUT_LITERAL(o, "\n  *seed\n");
    for (size_t i = 0; i < n; i++) {
        GP_OUT_LITERAL(o, "   ");
        gp_out_uint(o, i + 1);
        const double v[4] = {s[i].x, s[i].y, s[i].z, s[i].R};
        numbers(o, v, 4);
        gp_out_char(o, '\n');
    }
}

static void topology(gp_out *o, const tess *t)
{
    const gp_cells3d *c = t->c;
    GP_OUT_LITERAL(o, " **vertex\n ");
    gp_out_uint(o, t->nv);
    gp_out_char(o, '\n');
    for (size_t v = 0; v < t->nv; v++) {
        GP_OUT_LITERAL(o, "  ");
        gp_out_uint(o, v + 1);
        numbers(o, &t->xyz[3 * v], 3);
        GP_OUT_LITERAL(o, " 0\n");
    }
    GP_OUT_LITERAL(o, " **edge\n ");
    gp_out_uint(o, t->ne);
    gp_out_char(o, '\n');
    for (size_t e = 0; e < t->ne; e++) {
        GP_OUT_LITERAL(o, "  ");
        gp_out_uint(o, e + 1);
        gp_out_char(o, ' ');
        gp_out_uint(o, (uint64_t)t->ev[2 * e] + 1);
        gp_out_char(o, ' ');
        gp_out_uint(o, (uint64_t)t->ev[2 * e + 1] + 1);
        GP_OUT_LITERAL(o, " 0\n");
    }
    GP_OUT_LITERAL(o, " **face\n ");
    gp_out_uint(o, t->nf);
    gp_out_char(o, '\n');
    for (size_t f = 0; f < t->nf; f++) {
        size_t a = t->fvstart[f], m = t->fvstart[f + 1] - a;
        GP_OUT_LITERAL(o, "  ");
        gp_out_uint(o, f + 1);
        gp_out_char(o, ' ');
        gp_out_uint(o, m);
        for (size_t k = 0; k < m; k++) {
            gp_out_char(o, ' ');
            gp_out_uint(o, (uint64_t)t->fverts[a + k] + 1);
        }
        GP_OUT_LITERAL(o, "\n   ");
        gp_out_uint(o, m);
        for (size_t k = 0; k < m; k++) {
            gp_out_char(o, ' ');
            gp_out_int(o, t->fedges[a + k]);
        }
        double n[3], d;
        face_plane(t, f, n, &d);
        GP_OUT_LITERAL(o, "\n  ");
        const double eq[4] = {d, n[0], n[1], n[2]};
        numbers(o, eq, 4);
        GP_OUT_LITERAL(o, "\n   0 0 0 0 0\n"); /* state, interpolation point: none (no regularization) */
    }
    GP_OUT_LITERAL(o, " **polyhedron\n ");
    gp_out_uint(o, c->count);
    gp_out_char(o, '\n');
    for (size_t i = 0; i < c->count; i++) {
        size_t faces = 0;
        for (size_t f = c->fstart[i]; f < c->fstart[i + 1]; f++)
            faces += t->face_of[f] != 0;
        GP_OUT_LITERAL(o, "  ");
        gp_out_uint(o, i + 1);
        gp_out_char(o, ' ');
        gp_out_uint(o, faces);
        for (size_t f = c->fstart[i]; f < c->fstart[i + 1]; f++)
            if (t->face_of[f]) {
                gp_out_char(o, ' ');
                gp_out_int(o, t->face_of[f]);
            }
        gp_out_char(o, '\n');
    }
}

/* The box's corners are numbered bx + 2 by + 4 bz (b the side, 0 or 1, along each axis). */
static const char AXIS[3] = {'x', 'y', 'z'};

/* Bits of the box planes a welded vertex lies on: 1 << (2 axis + side). */
static unsigned on_planes(const tess *t, const gp_box *box, uint32_t v)
{
    const double side[3] = {box->width, box->height, box->depth};
    unsigned bits = 0;
    for (int a = 0; a < 3; a++) {
        double x = t->xyz[3 * (size_t)v + (size_t)a];
        if (fabs(x) <= t->tol)
            bits |= 1u << (2 * a);
        if (fabs(x - side[a]) <= t->tol)
            bits |= 1u << (2 * a + 1);
    }
    return bits;
}

/* The domain's 12 edges: edge 4 a + 2 s + u runs along axis a between corners whose other
 * two axes (a + 1, a + 2 mod 3) are at sides s, u. */
static void edge_corners(int e, int corner[2], unsigned *planes)
{
    int a = e / 4, b = (a + 1) % 3, c = (a + 2) % 3, s = (e / 2) % 2, u = e % 2;
    int base = (s << b) | (u << c);
    corner[0] = base;
    corner[1] = base | (1 << a);
    *planes = (1u << (2 * b + s)) | (1u << (2 * c + u));
}

static void edge_label(gp_out *o, unsigned planes)
{
    for (int p = 0; p < 6; p++)
        if (planes & (1u << p)) {
            gp_out_char(o, AXIS[p / 2]);
            gp_out_char(o, (char)('0' + p % 2));
        }
}

static int domain(gp_out *o, const tess *t, const gp_box *box, gp_error *err)
{
    const double side[3] = {box->width, box->height, box->depth};
    GP_OUT_LITERAL(o, " **domain\n  *general\n   cube\n  *vertex\n   8\n");
    for (int corner = 0; corner < 8; corner++) {
        double p[3];
        for (int a = 0; a < 3; a++)
            p[a] = (corner >> a & 1) ? side[a] : 0.0;
        uint32_t found = NONE;
        for (uint32_t v = 0; v < t->nv && found == NONE; v++) {
            const double *w = &t->xyz[3 * (size_t)v];
            if (fabs(w[0] - p[0]) <= t->tol && fabs(w[1] - p[1]) <= t->tol && fabs(w[2] - p[2]) <= t->tol)
                found = v;
        }
        if (found == NONE)
            return gp_error_set(err, GP_EGEOM, NULL, "no cell vertex at the box's corner %d", corner);
        GP_OUT_LITERAL(o, "   ");
        gp_out_int(o, corner + 1);
        numbers(o, p, 3);
        gp_out_char(o, ' ');
        for (int a = 0; a < 3; a++) {
            gp_out_char(o, AXIS[a]);
            gp_out_char(o, (char)('0' + (corner >> a & 1)));
        }
        GP_OUT_LITERAL(o, "\n    1 ");
        gp_out_uint(o, (uint64_t)found + 1);
        gp_out_char(o, '\n');
    }
    GP_OUT_LITERAL(o, "  *edge\n   12\n");
    for (int e = 0; e < 12; e++) {
        int corner[2];
        unsigned planes;
        edge_corners(e, corner, &planes);
        GP_OUT_LITERAL(o, "   ");
        gp_out_int(o, e + 1);
        GP_OUT_LITERAL(o, " 2 ");
        gp_out_int(o, corner[0] + 1);
        gp_out_char(o, ' ');
        gp_out_int(o, corner[1] + 1);
        GP_OUT_LITERAL(o, "\n    ");
        edge_label(o, planes);
        size_t count = 0;
        for (size_t k = 0; k < t->ne; k++)
            count += (on_planes(t, box, t->ev[2 * k]) & on_planes(t, box, t->ev[2 * k + 1]) & planes) == planes;
        GP_OUT_LITERAL(o, "\n    ");
        gp_out_uint(o, count);
        for (size_t k = 0; k < t->ne; k++)
            if ((on_planes(t, box, t->ev[2 * k]) & on_planes(t, box, t->ev[2 * k + 1]) & planes) == planes) {
                gp_out_char(o, ' ');
                gp_out_uint(o, k + 1);
            }
        gp_out_char(o, '\n');
    }
    GP_OUT_LITERAL(o, "  *face\n   6\n");
    for (int k = 0; k < 6; k++) { /* face k = wall k (geometry3d.h): axis k / 2, side k % 2 */
        int a = k / 2, s = k % 2, b = (a + 1) % 3, c = (a + 2) % 3;
        /* corners counter-clockwise about the inward normal (Neper's domain faces) */
        int uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
        int corners[4];
        for (int j = 0; j < 4; j++) {
            int jj = s ? 3 - j : j;
            corners[j] = (s << a) | (uv[jj][0] << b) | (uv[jj][1] << c);
        }
        GP_OUT_LITERAL(o, "   ");
        gp_out_int(o, k + 1);
        GP_OUT_LITERAL(o, " 4");
        for (int j = 0; j < 4; j++) {
            gp_out_char(o, ' ');
            gp_out_int(o, corners[j] + 1);
        }
        GP_OUT_LITERAL(o, "\n    4");
        for (int j = 0; j < 4; j++) {
            int p = corners[j], q = corners[(j + 1) % 4];
            for (int e = 0; e < 12; e++) {
                int ec[2];
                unsigned planes;
                edge_corners(e, ec, &planes);
                if ((ec[0] == p && ec[1] == q) || (ec[0] == q && ec[1] == p)) {
                    gp_out_char(o, ' ');
                    gp_out_int(o, e + 1);
                }
            }
        }
        double eq[4] = {s ? -side[a] : 0.0, 0.0, 0.0, 0.0}; /* d a b c, the normal inward */
        eq[1 + a] = s ? -1.0 : 1.0;
        GP_OUT_LITERAL(o, "\n    plane\n    4");
        numbers(o, eq, 4);
        GP_OUT_LITERAL(o, "\n    ");
        gp_out_char(o, AXIS[a]);
        gp_out_char(o, (char)('0' + s));
        size_t count = 0;
        for (size_t f = 0; f < t->nf; f++)
            count += t->fother[f] == GP_WALL3D(k);
        GP_OUT_LITERAL(o, "\n    ");
        gp_out_uint(o, count);
        for (size_t f = 0; f < t->nf; f++)
            if (t->fother[f] == GP_WALL3D(k)) {
                gp_out_char(o, ' ');
                gp_out_uint(o, f + 1);
            }
        gp_out_char(o, '\n');
    }
    return 0;
}

int gp_write_tess(gp_out *out, const gp_box *box, const gp_sphere *spheres, const gp_cells3d *power,
                  gp_error *err)
{
    if (power->shrink != GP_SHRINK_NONE)
        return gp_error_set(err, GP_EINVAL, NULL, "a tessellation is of the unshrunk power cells");
    if (power->count == 0)
        return gp_error_set(err, GP_EINVAL, NULL, "no cells to write");
    double R_min = spheres[0].R;
    for (size_t i = 1; i < power->count; i++)
        R_min = fmin(R_min, spheres[i].R);
    tess t = {.c = power, .tol = GP_TESS_WELD_RTOL * R_min};
    int rc = build(&t, err);
    if (!rc) {
        GP_OUT_LITERAL(out, "***tess\n **format\n   " TESS_FORMAT "\n **general\n   3 standard\n");
        cell_section(out, spheres, power->count);
        topology(out, &t);
        rc = domain(out, &t, box, err);
    }
    tess_free(&t);
    if (rc)
        return rc;
    GP_OUT_LITERAL(out, "***end\n");
    return gp_out_flush(out);
}
