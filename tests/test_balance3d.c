/* test_balance3d.c - F and the balancing in 3D (geometry3d.h): F against a brute-force
 * regular triangulation of small packings (every quadruple of centres with no centre
 * nearer in power to its orthocentre than its four), and over the three laws of
 * docs/3d.md: F_max never rises, the spheres stay apart (1e-9 relative) and in the box,
 * the triangulation is left valid, and F returned is F measured again. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "grainpack/geometry3d.h"
#include "grainpack/spec.h"
#include "triangulation3d.h"

typedef struct law3 {
    const char *name;
    int seeds;
    double side;
    gp_spec spec;
} law3;

static law3 laws[3] = {
    {.name = "one radius", .seeds = 2, .side = 6.0},
    {.name = "bagi", .seeds = 3, .side = 2.6},
    {.name = "iron", .seeds = 3, .side = 50.0},
};

static int pack(const law3 *law, uint64_t seed, double side, gp_box *box, gp_packing3d *out)
{
    *box = (gp_box){side, side * 0.9, side * 1.1, 0};
    gp_pack3d_params p = {.box = box, .dist = &law->spec.dist, .joint = &law->spec.joint, .seed = seed};
    gp_error err;
    int rc = gp_pack3d(&p, NULL, out, &err);
    CHECK_MSG(rc == 0, "%s: %s", law->name, err.message);
    return rc;
}

/* ---- brute force ---- */

static double pw(const gp_sphere *s, const double o[3])
{
    double dx = o[0] - s->x, dy = o[1] - s->y, dz = o[2] - s->z;
    return dx * dx + dy * dy + dz * dz - s->R * s->R;
}

/* The point of equal power to the four spheres (solve 3x3 by Cramer); 0 when flat. */
static int orthocentre(const gp_sphere *s[4], double o[3])
{
    double A[3][3], b[3];
    for (int r = 0; r < 3; r++) {
        const gp_sphere *p = s[0], *q = s[r + 1];
        A[r][0] = 2 * (q->x - p->x);
        A[r][1] = 2 * (q->y - p->y);
        A[r][2] = 2 * (q->z - p->z);
        b[r] = (q->x * q->x + q->y * q->y + q->z * q->z - q->R * q->R) -
               (p->x * p->x + p->y * p->y + p->z * p->z - p->R * p->R);
    }
    double det = A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) - A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
                 A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
    if (fabs(det) < 1e-12)
        return 0;
    for (int c = 0; c < 3; c++) {
        double M[3][3];
        memcpy(M, A, sizeof M);
        for (int r = 0; r < 3; r++)
            M[r][c] = b[r];
        o[c] = (M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) - M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
                M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0])) / det;
    }
    return 1;
}

/* F of every centre from the brute-force triangulation: NAN unless the centre is off the
 * hull and every orthocentre of its tetrahedra lies in the box. */
static void brute_F(const gp_box *box, const gp_sphere *s, size_t n, double *F)
{
    uint8_t *adj = calloc(n * n, 1), *outside = calloc(n, 1), *hull = calloc(n, 1);
    for (size_t a = 0; a < n; a++)
        for (size_t b = a + 1; b < n; b++)
            for (size_t c = b + 1; c < n; c++) {
                /* hull facets: every other centre on one side of the plane (a, b, c) */
                double e1[3] = {s[b].x - s[a].x, s[b].y - s[a].y, s[b].z - s[a].z};
                double e2[3] = {s[c].x - s[a].x, s[c].y - s[a].y, s[c].z - s[a].z};
                double nr[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
                int pos = 0, neg = 0;
                for (size_t m = 0; m < n; m++) {
                    double d = nr[0] * (s[m].x - s[a].x) + nr[1] * (s[m].y - s[a].y) + nr[2] * (s[m].z - s[a].z);
                    pos += d > 1e-12;
                    neg += d < -1e-12;
                }
                if (!pos || !neg)
                    hull[a] = hull[b] = hull[c] = 1;
                for (size_t d = c + 1; d < n; d++) {
                    const gp_sphere *q[4] = {&s[a], &s[b], &s[c], &s[d]};
                    double o[3];
                    if (!orthocentre(q, o))
                        continue;
                    double w = pw(&s[a], o);
                    size_t m = 0;
                    while (m < n && (m == a || m == b || m == c || m == d || pw(&s[m], o) > w))
                        m++;
                    if (m < n)
                        continue;
                    size_t v[4] = {a, b, c, d};
                    int in = o[0] >= 0 && o[0] <= box->width && o[1] >= 0 && o[1] <= box->height && o[2] >= 0 &&
                             o[2] <= box->depth;
                    for (int i = 0; i < 4; i++) {
                        outside[v[i]] |= !in;
                        for (int j = 0; j < 4; j++)
                            adj[v[i] * n + v[j]] |= i != j;
                    }
                }
            }
    for (size_t i = 0; i < n; i++) {
        double lo = INFINITY, hi = -INFINITY;
        size_t degree = 0;
        for (size_t j = 0; j < n; j++) {
            if (!adj[i * n + j])
                continue;
            double dx = s[j].x - s[i].x, dy = s[j].y - s[i].y, dz = s[j].z - s[i].z;
            double h = sqrt(dx * dx + dy * dy + dz * dz) - s[i].R - s[j].R;
            lo = h < lo ? h : lo;
            hi = h > hi ? h : hi;
            degree++;
        }
        F[i] = hull[i] || outside[i] || degree < 4 ? NAN : (hi - lo) / s[i].R;
    }
    free(adj);
    free(outside);
    free(hull);
}

static void test_F_brute_force(void)
{
    size_t interior = 0, compared = 0;
    for (int seed = 1; seed <= 6; seed++) {
        gp_box box;
        gp_packing3d pk;
        const law3 *law = &laws[1 + seed % 2];
        if (pack(law, (uint64_t)seed, law == &laws[1] ? 2.0 : 36.0, &box, &pk))
            return;
        gp_rt3 *rt;
        gp_error err;
        CHECK(gp_rt3_build(pk.spheres, pk.count, NULL, &rt, &err) == 0);
        double *F = malloc(pk.count * sizeof *F), *G = malloc(pk.count * sizeof *G);
        gp_quality_stats st;
        CHECK(gp_quality3d(&box, rt, pk.spheres, pk.count, F, &st, NULL, &err) == 0);
        brute_F(&box, pk.spheres, pk.count, G);
        size_t agree = 0, n_in = 0;
        for (size_t i = 0; i < pk.count; i++) {
            n_in += !isnan(F[i]);
            agree += isnan(F[i]) ? isnan(G[i]) : fabs(F[i] - G[i]) <= 1e-12 * (1.0 + G[i]);
        }
        CHECK_MSG(agree == pk.count, "%s seed %d: F agrees at %zu of %zu centres", law->name, seed, agree, pk.count);
        CHECK(st.interior == n_in);
        interior += n_in;
        compared += pk.count;
        free(F);
        free(G);
        gp_rt3_free(rt);
        gp_packing3d_free(&pk);
    }
    CHECK_MSG(interior >= 20, "only %zu interior centres compared", interior);
    fprintf(stderr, "  F against brute force: %zu centres, %zu interior\n", compared, interior);
}

/* ---- balancing ---- */

static size_t overlaps(const gp_box *box, const gp_sphere *s, size_t n)
{
    size_t bad = 0;
    for (size_t i = 0; i < n; i++) {
        double R = s[i].R, t = 1e-9 * R;
        bad += s[i].x < R - t || s[i].x > box->width - R + t || s[i].y < R - t || s[i].y > box->height - R + t ||
               s[i].z < R - t || s[i].z > box->depth - R + t;
        for (size_t j = i + 1; j < n; j++) {
            double dx = s[i].x - s[j].x, dy = s[i].y - s[j].y, dz = s[i].z - s[j].z;
            double reach = (R + s[j].R) * (1.0 - 1e-9);
            bad += dx * dx + dy * dy + dz * dz < reach * reach;
        }
    }
    return bad;
}

static void check_balance(law3 *law, gp_balance_method method)
{
    for (int seed = 1; seed <= law->seeds; seed++) {
        gp_box box;
        gp_packing3d pk;
        if (pack(law, (uint64_t)seed, law->side, &box, &pk))
            return;
        gp_rt3 *rt;
        gp_error err;
        CHECK(gp_rt3_build(pk.spheres, pk.count, NULL, &rt, &err) == 0);
        gp_sphere *before = malloc(pk.count * sizeof *before);
        memcpy(before, pk.spheres, pk.count * sizeof *before);
        gp_balance_params params = {method, 40, 0.0, GP_RT_UPDATE_REBUILD};
        gp_balance_result res;
        int rc = gp_balance3d(&box, pk.spheres, pk.count, rt, &params, NULL, &res, &err);
        CHECK_MSG(rc == 0, "%s: %s", law->name, err.message);
        if (rc == 0) {
            CHECK_MSG(res.after.max <= res.before.max, "%s seed %d: F_max %.4f -> %.4f", law->name, seed,
                      res.before.max, res.after.max);
            CHECK(res.before.interior > 10 && res.sweeps >= 1);
            size_t bad = overlaps(&box, pk.spheres, pk.count), radii = 0, moved = 0;
            CHECK_MSG(bad == 0, "%s seed %d: %zu overlaps or spheres outside", law->name, seed, bad);
            for (size_t i = 0; i < pk.count; i++) {
                radii += pk.spheres[i].r != before[i].r || pk.spheres[i].R != before[i].R;
                moved += pk.spheres[i].x != before[i].x || pk.spheres[i].y != before[i].y ||
                         pk.spheres[i].z != before[i].z;
            }
            CHECK(radii == 0);
            CHECK_MSG(res.best_sweep == 0 || moved > 0, "%s: best sweep %u, nothing moved", law->name, res.best_sweep);
            /* the triangulation follows the spheres, and F is F measured again */
            CHECK(gp_rt3_is_valid(rt));
            double *F = malloc(pk.count * sizeof *F);
            gp_quality_stats st;
            CHECK(gp_quality3d(&box, rt, pk.spheres, pk.count, F, &st, NULL, &err) == 0);
            size_t same = 0;
            for (size_t i = 0; i < pk.count; i++)
                same += isnan(F[i]) ? isnan(res.F[i]) : F[i] == res.F[i];
            CHECK_MSG(same == pk.count, "%s: F of %zu of %zu centres as measured again", law->name, same, pk.count);
            CHECK(st.max == res.after.max && st.interior == res.after.interior);
            fprintf(stderr, "  %s %s seed %d: %zu spheres, F_max %.3f -> %.3f, mean %.3f -> %.3f, %u sweeps (%s)\n",
                    law->name, gp_balance_method_name(method), seed, pk.count, res.before.max, res.after.max,
                    res.before.mean, res.after.mean, res.sweeps, gp_balance_stop_name(res.stop));
            free(F);
            gp_balance_result_free(&res);
        }
        free(before);
        gp_rt3_free(rt);
        gp_packing3d_free(&pk);
    }
}

static void test_relocation(void)
{
    for (int i = 0; i < 3; i++)
        check_balance(&laws[i], GP_BALANCE_RELOCATION);
}

static void test_laplacian(void)
{
    for (int i = 1; i < 3; i++)
        check_balance(&laws[i], GP_BALANCE_LAPLACIAN);
}

int main(void)
{
    static const char *const specs[2] = {
        "{\"domain\": {\"width\": 10, \"height\": 10}, \"distribution\": {\"kind\": \"constant\", \"radius\": 0.5}}",
        "{\"domain\": {\"width\": 10, \"height\": 10}, \"distribution\": "
        "{\"kind\": \"uniform\", \"min\": 0.06, \"max\": 0.42}}"};
    gp_error err;
    for (int i = 0; i < 2; i++)
        if (gp_spec_parse(specs[i], strlen(specs[i]), NULL, &laws[i].spec, &err))
            return 1;
    if (gp_spec_load_file(GP_EXAMPLES_DIR "/iron.json", NULL, &laws[2].spec, &err))
        return 1;
    RUN(test_F_brute_force);
    RUN(test_relocation);
    RUN(test_laplacian);
    for (int i = 0; i < 3; i++)
        gp_spec_free(&laws[i].spec);
    return check_status();
}
