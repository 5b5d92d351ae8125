/* test_settled.c - the record of the centres a balancing sweep may skip (core/settled.h): a
 * record holds exactly as long as no disk moved from or to a position from which it could
 * reach the recorded box, over the sweep it was made in and the next, and a forgotten
 * record never holds. */
#include <stdlib.h>

#include "check.h"
#include "grainpack/rng.h"
#include "nearby.h"
#include "settled.h"

#define DISKS 1500
#define MOVES_PER_SWEEP 40
#define SWEEPS 30

/* One logged move, to answer by brute force. */
typedef struct move {
    uint64_t sweep;
    int32_t id;
    double x0, y0, x1, y1;
} move;

/* A recorded centre: its box and when the record was made or last found to hold. */
typedef struct record {
    int32_t id;
    double box[4];
    size_t since; /* moves logged before it */
} record;

/* Whether some move after the record reaches its box: brute force over the log. */
static int moved_near_by_brute_force(const record *r, const move *moves, size_t nmoves, const gp_disk *d)
{
    double R = d[r->id].R;
    for (size_t k = r->since; k < nmoves; k++) {
        double Rq = d[moves[k].id].R;
        if (nearby_box_reaches(r->box[0], r->box[1], r->box[2], r->box[3], moves[k].x0, moves[k].y0, Rq, R) ||
            nearby_box_reaches(r->box[0], r->box[1], r->box[2], r->box[3], moves[k].x1, moves[k].y1, Rq, R))
            return 1;
    }
    return 0;
}

static void test_records_hold_until_a_move_reaches_their_box(void)
{
    gp_domain dom = {80.0, 60.0, 0};
    gp_disk *d = malloc(DISKS * sizeof *d);
    gp_rng rng;
    gp_rng_seed(&rng, 12);
    for (size_t i = 0; i < DISKS; i++)
        d[i] = (gp_disk){.x = 1.0 + 78.0 * gp_rng_uniform(&rng), .y = 1.0 + 58.0 * gp_rng_uniform(&rng),
                         .R = 0.2 + 0.8 * gp_rng_uniform(&rng)};
    nearby nb;
    CHECK(nearby_init(&nb, &dom, d, DISKS, 1.0) == 0);
    settled s;
    CHECK(settled_init(&s, &nb.grid, nb.R_max, DISKS) == 0);
    move *moves = malloc(SWEEPS * MOVES_PER_SWEEP * sizeof *moves);
    record *records = malloc(DISKS * sizeof *records);
    size_t nmoves = 0, nrecords = 0, held = 0, broken = 0, wrong = 0;
    for (uint64_t sweep = 0; sweep < SWEEPS; sweep++) {
        settled_sweep(&s);
        /* every record is asked about in each sweep, as a sweep visits every centre */
        size_t kept = 0;
        for (size_t r = 0; r < nrecords; r++) {
            int want = !moved_near_by_brute_force(&records[r], moves, nmoves, d);
            int got = settled_holds(&s, d, records[r].id, d[records[r].id].R);
            wrong += (got == SETTLED_STILL) != want;
            held += want;
            broken += !want;
            if (got == SETTLED_STILL) {
                records[r].since = nmoves;
                records[kept++] = records[r];
            }
        }
        nrecords = kept;
        /* new records on random centres (a centre recorded twice keeps the newer) */
        for (int k = 0; k < 20; k++) {
            int32_t id = (int32_t)(gp_rng_uniform(&rng) * DISKS);
            double half = d[id].R * gp_rng_uniform(&rng);
            record rec = {id, {d[id].x - half, d[id].y - half, d[id].x + half, d[id].y + half}, nmoves};
            settled_record(&s, id, SETTLED_STILL, rec.box[0], rec.box[1], rec.box[2], rec.box[3]);
            size_t r = 0;
            while (r < nrecords && records[r].id != id)
                r++;
            records[r] = rec;
            nrecords += r == nrecords;
        }
        /* moves of a few times a radius, anywhere */
        for (int k = 0; k < MOVES_PER_SWEEP; k++) {
            int32_t id = (int32_t)(gp_rng_uniform(&rng) * DISKS);
            move m = {sweep, id, d[id].x, d[id].y, 0.0, 0.0};
            m.x1 = d[id].x + 4.0 * (gp_rng_uniform(&rng) - 0.5);
            m.y1 = d[id].y + 4.0 * (gp_rng_uniform(&rng) - 0.5);
            m.x1 = m.x1 < 0.5 ? 0.5 : (m.x1 > 79.5 ? 79.5 : m.x1);
            m.y1 = m.y1 < 0.5 ? 0.5 : (m.y1 > 59.5 ? 59.5 : m.y1);
            d[id].x = m.x1;
            d[id].y = m.y1;
            CHECK(settled_moved(&s, id, m.x0, m.y0, m.x1, m.y1) == 0);
            moves[nmoves++] = m;
        }
    }
    CHECK(wrong == 0);
    /* both answers seen often, or the comparison meant nothing */
    CHECK(held > 100 && broken > 100);
    /* a forgotten record never holds, however little moved */
    settled_sweep(&s);
    for (size_t r = 0; r < nrecords; r++)
        settled_forget(&s, records[r].id);
    for (size_t r = 0; r < nrecords; r++)
        CHECK(settled_holds(&s, d, records[r].id, d[records[r].id].R) == SETTLED_UNKNOWN);
    free(records);
    free(moves);
    settled_free(&s);
    nearby_free(&nb);
    free(d);
}

int main(void)
{
    RUN(test_records_hold_until_a_move_reaches_their_box);
    return check_status();
}
