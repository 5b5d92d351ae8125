/* periodic.c - the ghost layer of a periodic domain (docs/method.md §5.1). */
#include "periodic.h"

#include <stdlib.h>
#include <string.h>

#include "grainpack/error.h"
#include "grow.h"

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
                gp_disk *grown = grow(all, &cap, m + 1, sizeof *grown);
                if (!grown)
                    goto oom;
                all = grown;
                int32_t *grown_from = grow(from, &from_cap, m - n + 1, sizeof *grown_from);
                if (!grown_from)
                    goto oom;
                from = grown_from;
                all[m] = disks[i];
                all[m].x = x;
                all[m].y = y;
                from[m - n] = (int32_t)i;
                m++;
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
