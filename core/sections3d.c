/* sections3d.c - the arrays of a stored 3D result read window by window for the 3D
 * writers (writer3d.h): spheres, F and the polyhedra of a few hundred grains at a time,
 * checked as they are read, so that a download holds a window, never the result. */
#include <stdlib.h>
#include <string.h>

#include "sections.h"
#include "writer3d.h"

typedef struct source3d {
    const gp_result3d *summary; /* counts and totals */
    gp_section_read_fn read;
    void *ctx;
    size_t window;
    gp_sphere *spheres; /* window each */
    double *F, *volume;
    uint32_t *sizes;    /* two per cell: vertices, faces */
    size_t *vstart, *fstart; /* window + 1 */
    uint32_t *face_sizes;
    size_t face_sizes_cap;
    size_t *fvstart;    /* faces + 1 */
    size_t fvstart_cap;
    uint32_t *fverts;
    size_t fverts_cap;
    int32_t *fneighbour;
    size_t fneighbour_cap;
    double *xyz;
    size_t xyz_cap;     /* vertices */
    gp_cells3d cells;   /* the window's view of the arrays above */
    /* where cell `cursor` starts among the vertices, faces and face vertices: a pass reads
     * the cells in order, so the next window starts where the last one ended */
    size_t cursor, vertex_at, face_at, fv_at;
} source3d;

/* Makes room for n elements of `size` bytes in *buf (capacity *cap). */
static int reserve(void *bufp, size_t *cap, size_t n, size_t size)
{
    void **buf = bufp;
    if (n <= *cap && *buf)
        return 0;
    void *grown = realloc(*buf, (n ? n : 1) * size);
    if (!grown)
        return GP_ENOMEM;
    *buf = grown;
    *cap = n;
    return 0;
}

/* Reads the sizes of cells first .. first + n - 1 (at the cursor's vertex and face) into
 * the window's vstart, fstart and fvstart, checked against the summary's totals and each
 * face against its cell (a corrupt store must not size a buffer or an index). */
static int read_sizes(source3d *s, size_t first, size_t n)
{
    const gp_cell3d_stats *cs = &s->summary->cell_stats;
    int rc = s->read(s->ctx, GP_SECTION_CELL3D_SIZES, 8 * (uint64_t)first, s->sizes, 8 * n);
    if (rc)
        return rc;
    s->vstart[0] = s->fstart[0] = 0;
    for (size_t j = 0; j < n; j++) {
        s->vstart[j + 1] = s->vstart[j] + s->sizes[2 * j];
        s->fstart[j + 1] = s->fstart[j] + s->sizes[2 * j + 1];
    }
    size_t nf = s->fstart[n];
    if (s->vstart[n] > cs->vertices - s->vertex_at || nf > cs->faces - s->face_at)
        return GP_EPARSE;
    if ((rc = reserve(&s->face_sizes, &s->face_sizes_cap, nf, sizeof *s->face_sizes)) ||
        (rc = reserve(&s->fvstart, &s->fvstart_cap, nf + 1, sizeof *s->fvstart)))
        return rc;
    if (nf && (rc = s->read(s->ctx, GP_SECTION_CELL3D_FACE_SIZES, 4 * (uint64_t)s->face_at,
                            s->face_sizes, 4 * nf)))
        return rc;
    s->fvstart[0] = 0;
    for (size_t j = 0; j < n; j++)
        for (size_t f = s->fstart[j]; f < s->fstart[j + 1]; f++) {
            if (s->face_sizes[f] > s->sizes[2 * j])
                return GP_EPARSE; /* a face with more vertices than its cell */
            s->fvstart[f + 1] = s->fvstart[f] + s->face_sizes[f];
        }
    return 0;
}

/* Moves the cursor to cell `first`: where the last window ended, or a sum over the sizes
 * from the start (never on the writers' own order of reads). */
static int locate(source3d *s, size_t first)
{
    if (first == s->cursor)
        return 0;
    s->cursor = s->vertex_at = s->face_at = s->fv_at = 0;
    while (s->cursor < first) {
        size_t n = first - s->cursor < s->window ? first - s->cursor : s->window;
        int rc = read_sizes(s, s->cursor, n);
        if (rc)
            return rc;
        s->cursor += n;
        s->vertex_at += s->vstart[n];
        s->face_at += s->fstart[n];
        s->fv_at += s->fvstart[s->fstart[n]];
    }
    return 0;
}

/* Whether the window's face vertices index their cells' vertices and its neighbours are
 * grains or walls. */
static int cells_in_range(const source3d *s, unsigned needs, size_t n)
{
    const gp_cells3d *c = &s->cells;
    size_t grains = s->summary->packing.count;
    for (size_t j = 0; j < n; j++)
        for (size_t f = c->fstart[j]; f < c->fstart[j + 1]; f++) {
            if (needs & GP_W3_NEIGHBOURS) {
                int32_t nb = c->fneighbour[f];
                if (nb < GP_WALL3D(5) || (nb >= 0 && (size_t)nb >= grains))
                    return 0;
            }
            if (needs & GP_W3_FACES)
                for (size_t k = c->fvstart[f]; k < c->fvstart[f + 1]; k++)
                    if (c->fverts[k] >= c->vstart[j + 1] - c->vstart[j])
                        return 0;
        }
    return 1;
}

static int load_cells(source3d *s, unsigned needs, size_t first, size_t n, gp_window3d *win)
{
    int rc = locate(s, first);
    if (rc || (rc = read_sizes(s, first, n)))
        return rc;
    size_t nv = s->vstart[n], nf = s->fstart[n], nfv = s->fvstart[nf];
    gp_cells3d *c = &s->cells;
    *c = (gp_cells3d){.count = n, .shrink = s->summary->cells.shrink, .vstart = s->vstart,
                      .fstart = s->fstart,
                      .power_volume_sum = s->summary->cells.power_volume_sum};
    if ((needs & GP_W3_FACES) &&
        !(rc = reserve(&s->fverts, &s->fverts_cap, nfv, sizeof *s->fverts)) &&
        !(rc = s->read(s->ctx, GP_SECTION_CELL3D_FACE_VERTICES, 4 * (uint64_t)s->fv_at, s->fverts,
                       4 * nfv))) {
        c->fvstart = s->fvstart;
        c->fverts = s->fverts;
    }
    if (!rc && (needs & GP_W3_NEIGHBOURS) &&
        !(rc = reserve(&s->fneighbour, &s->fneighbour_cap, nf, sizeof *s->fneighbour)) &&
        !(rc = s->read(s->ctx, GP_SECTION_CELL3D_FACE_NEIGHBOURS, 4 * (uint64_t)s->face_at,
                       s->fneighbour, 4 * nf)))
        c->fneighbour = s->fneighbour;
    if (!rc && (needs & GP_W3_XYZ) && !(rc = reserve(&s->xyz, &s->xyz_cap, 3 * nv, sizeof *s->xyz)) &&
        !(rc = s->read(s->ctx, GP_SECTION_CELL3D_XYZ, 24 * (uint64_t)s->vertex_at, s->xyz, 24 * nv)))
        c->xyz = s->xyz;
    if (!rc && (needs & GP_W3_VOLUME) &&
        !(rc = s->read(s->ctx, GP_SECTION_CELL3D_VOLUME, 8 * (uint64_t)first, s->volume, 8 * n)))
        c->volume = s->volume;
    if (!rc && !cells_in_range(s, needs, n))
        rc = GP_EPARSE;
    if (rc)
        return rc;
    win->cells = c;
    win->vertex_base = s->vertex_at;
    s->cursor = first + n;
    s->vertex_at += nv;
    s->face_at += nf;
    s->fv_at += nfv;
    return 0;
}

static int load(void *ctx, unsigned needs, size_t first, gp_window3d *win)
{
    source3d *s = ctx;
    const gp_result3d *r = s->summary;
    size_t total = r->packing.count;
    if (first >= total)
        return GP_EINVAL;
    size_t n = total - first < s->window ? total - first : s->window;
    *win = (gp_window3d){.first = first, .count = n};
    int rc = 0;
    if ((needs & GP_W3_SPHERES) &&
        !(rc = s->read(s->ctx, GP_SECTION_SPHERES, 40 * (uint64_t)first, s->spheres, 40 * n)))
        win->spheres = s->spheres;
    if (!rc && (needs & GP_W3_F) && r->has_balance &&
        !(rc = s->read(s->ctx, GP_SECTION_F, 8 * (uint64_t)first, s->F, 8 * n)))
        win->F = s->F;
    if (!rc && (needs & ~(GP_W3_SPHERES | GP_W3_F)) && r->has_cells)
        rc = load_cells(s, needs, first, n, win);
    return rc;
}

static void drop(void *ctx)
{
    source3d *s = ctx;
    free(s->spheres);
    free(s->F);
    free(s->volume);
    free(s->sizes);
    free(s->vstart);
    free(s->fstart);
    free(s->face_sizes);
    free(s->fvstart);
    free(s->fverts);
    free(s->fneighbour);
    free(s->xyz);
    free(s);
}

int gp_sections_source3d(const gp_result3d *summary, gp_section_read_fn read, void *ctx,
                         size_t window, gp_source3d *out)
{
    source3d *s = calloc(1, sizeof *s);
    if (!s)
        return GP_ENOMEM;
    *s = (source3d){.summary = summary, .read = read, .ctx = ctx,
                    .window = window ? window : GP_SECTIONS_WINDOW_CELLS3D};
    size_t w = s->window;
    if (!(s->spheres = malloc(w * sizeof *s->spheres)) || !(s->F = malloc(w * sizeof *s->F)) ||
        !(s->volume = malloc(w * sizeof *s->volume)) || !(s->sizes = malloc(2 * w * sizeof *s->sizes)) ||
        !(s->vstart = malloc((w + 1) * sizeof *s->vstart)) ||
        !(s->fstart = malloc((w + 1) * sizeof *s->fstart))) {
        drop(s);
        return GP_ENOMEM;
    }
    *out = (gp_source3d){load, s, drop};
    return 0;
}
