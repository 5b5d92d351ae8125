/* mesh_pairs.c - a hash map keyed by unordered pairs of point or node indices: segments
 * met twice, the mid-edge node of an edge. */
#include <stdlib.h>
#include <string.h>

#include "grainpack/error.h"
#include "mesh_internal.h"

static uint64_t pair_key(int32_t a, int32_t b)
{
    if (a > b) {
        int32_t t = a;
        a = b;
        b = t;
    }
    return ((uint64_t)(uint32_t)a << 32) | (uint32_t)b;
}

/* A multiplicative hash (Knuth): pairs of nearby indices spread over the table. */
static size_t slot_of(uint64_t key, size_t cap)
{
    return (size_t)((key * 0x9E3779B97F4A7C15ull) >> 17) & (cap - 1);
}

static int alloc_table(gp_pair_map *m, size_t cap)
{
    m->keys = malloc(cap * sizeof *m->keys);
    m->values = malloc(cap * sizeof *m->values);
    if (!m->keys || !m->values) {
        free(m->keys);
        free(m->values);
        m->keys = NULL;
        m->values = NULL;
        return GP_ENOMEM;
    }
    memset(m->keys, 0xff, cap * sizeof *m->keys); /* every key GP_PAIR_EMPTY */
    m->cap = cap;
    m->count = 0;
    return 0;
}

int gp_pair_map_init(gp_pair_map *m, size_t expected)
{
    memset(m, 0, sizeof *m);
    size_t cap = 64;
    while (cap < 2 * expected)
        cap *= 2;
    return alloc_table(m, cap);
}

void gp_pair_map_free(gp_pair_map *m)
{
    free(m->keys);
    free(m->values);
    memset(m, 0, sizeof *m);
}

static int64_t *find(gp_pair_map *m, uint64_t key, int *found)
{
    size_t i = slot_of(key, m->cap);
    while (m->keys[i] != GP_PAIR_EMPTY && m->keys[i] != key)
        i = (i + 1) & (m->cap - 1);
    *found = m->keys[i] == key;
    if (!*found)
        m->keys[i] = key;
    return &m->values[i];
}

/* Doubles the table (kept at most half full, so that probes stay short). */
static int grow_table(gp_pair_map *m)
{
    gp_pair_map old = *m;
    if (alloc_table(m, 2 * old.cap)) {
        *m = old;
        return GP_ENOMEM;
    }
    for (size_t i = 0; i < old.cap; i++) {
        if (old.keys[i] == GP_PAIR_EMPTY)
            continue;
        int found;
        *find(m, old.keys[i], &found) = old.values[i];
        m->count++;
    }
    gp_pair_map_free(&old);
    return 0;
}

int64_t *gp_pair_map_get(gp_pair_map *m, int32_t a, int32_t b, int64_t fresh, int *found)
{
    if (2 * (m->count + 1) > m->cap && grow_table(m))
        return NULL;
    int64_t *value = find(m, pair_key(a, b), found);
    if (!*found) {
        *value = fresh;
        m->count++;
    }
    return value;
}

const int64_t *gp_pair_map_find(const gp_pair_map *m, int32_t a, int32_t b)
{
    uint64_t key = pair_key(a, b);
    size_t i = slot_of(key, m->cap);
    while (m->keys[i] != GP_PAIR_EMPTY) {
        if (m->keys[i] == key)
            return &m->values[i];
        i = (i + 1) & (m->cap - 1);
    }
    return NULL;
}
