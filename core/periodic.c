/* periodic.c - the ghost layer of a periodic domain (docs/method.md §5.1). */
#include "periodic.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grainpack/error.h"
#include "grow.h"

int periodic_append(void **all, size_t *cap, size_t *count, size_t n, const void *item, size_t size,
                    int32_t **from, size_t *from_cap, int32_t origin)
{
    void *grown = grow(*all, cap, *count + 1, size);
    if (!grown)
        return GP_ENOMEM;
    *all = grown;
    int32_t *grown_from = grow(*from, from_cap, *count - n + 1, sizeof *grown_from);
    if (!grown_from)
        return GP_ENOMEM;
    *from = grown_from;
    memcpy((char *)grown + *count * size, item, size);
    grown_from[*count - n] = origin;
    ++*count;
    return 0;
}

int periodic_images(const gp_domain *domain, const gp_disk *disks, size_t n, double margin,
                    gp_disk **out, int32_t **origin, size_t *n_out)
{
    double W = domain->width, H = domain->height;
    int kx = (domain->periodic & GP_PERIODIC_X) ? 1 : 0, ky = (domain->periodic & GP_PERIODIC_Y) ? 1 : 0;
    size_t cap = n + n / 2 + 16, m = n;
    gp_disk *all = malloc(cap * sizeof *all);
    int32_t *from = malloc((cap - n) * sizeof *from);
    size_t from_cap = cap - n;
    if (!all || !from)
        goto oom;
    memcpy(all, disks, n * sizeof *all);
    for (size_t i = 0; i < n; i++) {
        for (int sx = -kx; sx <= kx; sx++) {
            for (int sy = -ky; sy <= ky; sy++) {
                double x = disks[i].x + sx * W, y = disks[i].y + sy * H;
                if ((sx == 0 && sy == 0) || (kx && !(x >= -margin && x < W + margin)) ||
                    (ky && !(y >= -margin && y < H + margin)))
                    continue;
                gp_disk image = disks[i];
                image.x = x;
                image.y = y;
                void *a = all;
                int rc = periodic_append(&a, &cap, &m, n, &image, sizeof image, &from, &from_cap, (int32_t)i);
                all = a;
                if (rc)
                    goto oom;
            }
        }
    }
    *out = all;
    *origin = from;
    *n_out = m;
    return 0;
oom:
    free(all);
    free(from);
    return GP_ENOMEM;
}

double periodic_last_margin(const gp_domain *domain)
{
    double period = (domain->periodic & GP_PERIODIC_X) ? domain->width : domain->height;
    if ((domain->periodic & GP_PERIODIC_Y) && domain->height < period)
        period = domain->height;
    return period;
}

double periodic_first_margin(const gp_domain *domain, double R_max)
{
    double margin = PERIODIC_MARGIN_RADII * R_max, last = periodic_last_margin(domain);
    return margin < last ? margin : last;
}

/* The ghosts of each disk in one array, and each ghost's shift in periods. */
static int index_ghosts(periodic_layer *L, const gp_domain *domain)
{
    size_t ghosts = L->m - L->n;
    L->ghost_start = calloc(L->n + 1, sizeof *L->ghost_start);
    L->ghost_ids = malloc((ghosts ? ghosts : 1) * sizeof *L->ghost_ids);
    L->shift = malloc((ghosts ? 2 * ghosts : 1) * sizeof *L->shift);
    if (!L->ghost_start || !L->ghost_ids || !L->shift)
        return GP_ENOMEM;
    for (size_t k = 0; k < ghosts; k++) {
        const gp_disk *g = &L->all[L->n + k], *d = &L->all[L->origin[k]];
        L->shift[2 * k] = (int8_t)((domain->periodic & GP_PERIODIC_X) ? lround((g->x - d->x) / domain->width) : 0);
        L->shift[2 * k + 1] = (int8_t)((domain->periodic & GP_PERIODIC_Y) ? lround((g->y - d->y) / domain->height) : 0);
        L->ghost_start[L->origin[k] + 1]++;
    }
    for (size_t i = 0; i < L->n; i++)
        L->ghost_start[i + 1] += L->ghost_start[i];
    /* a disk's ghosts follow it in periodic_images: filled in order, start[i] moves on
     * to start[i + 1], then back */
    for (size_t k = 0; k < ghosts; k++)
        L->ghost_ids[L->ghost_start[L->origin[k]]++] = (int32_t)(L->n + k);
    for (size_t i = L->n; i > 0; i--)
        L->ghost_start[i] = L->ghost_start[i - 1];
    L->ghost_start[0] = 0;
    return 0;
}

int periodic_layer_build(periodic_layer *L, const gp_domain *domain, const gp_disk *disks, size_t n,
                         double margin, const gp_progress *progress, gp_error *err)
{
    memset(L, 0, sizeof *L);
    L->n = n;
    L->margin = margin;
    int rc;
    if (periodic_images(domain, disks, n, margin, &L->all, &L->origin, &L->m) ||
        index_ghosts(L, domain)) {
        rc = gp_error_set(err, GP_ENOMEM, NULL, "out of memory for the periodic images");
        goto fail;
    }
    if ((rc = gp_rt_build(L->all, L->m, progress, &L->rt, err)))
        goto fail;
    return 0;
fail:
    periodic_layer_free(L);
    return rc;
}

void periodic_ghost_place(const periodic_layer *L, const gp_domain *domain, int32_t g)
{
    size_t k = (size_t)g - L->n;
    const gp_disk *d = &L->all[L->origin[k]];
    L->all[g].x = d->x + L->shift[2 * k] * domain->width;
    L->all[g].y = d->y + L->shift[2 * k + 1] * domain->height;
}

void periodic_layer_free(periodic_layer *L)
{
    gp_rt_free(L->rt);
    free(L->all);
    free(L->origin);
    free(L->shift);
    free(L->ghost_start);
    free(L->ghost_ids);
    memset(L, 0, sizeof *L);
}

int periodic_too_small(gp_error *err)
{
    return gp_error_set(err, GP_EGEOM, NULL,
                        "a periodic cell reaches beyond a whole period of images: the domain is "
                        "too small for its largest void");
}
