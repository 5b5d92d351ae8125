/* pack3d_front.c - the 3D packer's front (docs/3d.md §3-4): a pool of triangles queued
 * by key (first pushed first within a key), and per radius class a stack of the
 * triangles that failed for that class, kept for smaller radii. */
#include <stdlib.h>
#include <string.h>

#include "grow.h"
#include "pack3d_internal.h"

void p3_front_init(p3_front *fr)
{
    memset(fr, 0, sizeof *fr);
    fr->free_list = P3_NONE;
    for (int k = 0; k < P3_CLASSES; k++)
        fr->retry[k] = P3_NONE;
}

void p3_front_free(p3_front *fr)
{
    free(fr->tris);
    free(fr->head);
    free(fr->tail);
    p3_front_init(fr);
}

/* Room for keys up to `key`: 0 or GP_ENOMEM. */
static int reserve_key(p3_front *fr, uint32_t key)
{
    if (key < fr->nkeys)
        return 0;
    size_t n = grow_capacity(fr->nkeys, (size_t)key + 1);
    int32_t *head = n ? grow_realloc(fr->head, n, sizeof *head) : NULL;
    if (!head)
        return GP_ENOMEM;
    fr->head = head;
    int32_t *tail = grow_realloc(fr->tail, n, sizeof *tail);
    if (!tail)
        return GP_ENOMEM;
    fr->tail = tail;
    for (size_t k = fr->nkeys; k < n; k++)
        fr->head[k] = fr->tail[k] = P3_NONE;
    fr->nkeys = n;
    return 0;
}

/* Appends triangle t to its key's FIFO. */
static void enqueue(p3_front *fr, int32_t t)
{
    uint32_t key = fr->tris[t].key;
    fr->tris[t].next = P3_NONE;
    if (fr->tail[key] == P3_NONE)
        fr->head[key] = t;
    else
        fr->tris[fr->tail[key]].next = t;
    fr->tail[key] = t;
    if (key < fr->low)
        fr->low = key;
    fr->waiting++;
}

int p3_front_push(p3_front *fr, const int32_t m[3], int32_t behind, uint32_t key)
{
    if (reserve_key(fr, key))
        return GP_ENOMEM;
    int32_t t = fr->free_list;
    if (t != P3_NONE) {
        fr->free_list = fr->tris[t].next;
    } else {
        if (fr->count >= (size_t)INT32_MAX)
            return GP_ENOMEM;
        p3_tri *tris = grow(fr->tris, &fr->capacity, fr->count + 1, sizeof *tris);
        if (!tris)
            return GP_ENOMEM;
        fr->tris = tris;
        t = (int32_t)fr->count++;
    }
    p3_tri *tri = &fr->tris[t];
    memcpy(tri->m, m, sizeof tri->m);
    tri->behind = behind;
    tri->key = key;
    enqueue(fr, t);
    fr->made++;
    return 0;
}

void p3_front_requeue(p3_front *fr, int32_t t)
{
    enqueue(fr, t);
}

int32_t p3_front_pop(p3_front *fr)
{
    if (!fr->waiting)
        return P3_NONE;
    while (fr->head[fr->low] == P3_NONE)
        fr->low++;
    int32_t t = fr->head[fr->low];
    fr->head[fr->low] = fr->tris[t].next;
    if (fr->head[fr->low] == P3_NONE)
        fr->tail[fr->low] = P3_NONE;
    fr->waiting--;
    return t;
}

void p3_front_retry(p3_front *fr, int32_t t, int cls)
{
    fr->tris[t].next = fr->retry[cls];
    fr->retry[cls] = t;
    fr->retrying |= 1u << cls;
}

int32_t p3_front_pop_retry(p3_front *fr, int cls)
{
    uint32_t above = fr->retrying & ~((2u << cls) - 1);
    if (!above)
        return P3_NONE;
    int k = 31 - __builtin_clz(above); /* the largest class first */
    int32_t t = fr->retry[k];
    fr->retry[k] = fr->tris[t].next;
    if (fr->retry[k] == P3_NONE)
        fr->retrying &= ~(1u << k);
    return t;
}

void p3_front_release(p3_front *fr, int32_t t)
{
    fr->tris[t].next = fr->free_list;
    fr->free_list = t;
}
