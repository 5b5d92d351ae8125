/* grow.h - growing arrays (internal to core/): the one place that picks a larger
 * capacity and reallocates, checking capacity * element size for overflow. */
#ifndef GRAINPACK_CORE_GROW_H
#define GRAINPACK_CORE_GROW_H

#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* The capacity an empty array first gets: no cost for a small job, and the doublings
 * after it soon make the reallocations rare. */
#define GROW_MIN_CAPACITY 16

/* realloc(array, n * size) for n >= 1, or NULL when n * size overflows or realloc fails;
 * the array is then untouched and still the caller's. */
static inline void *grow_realloc(void *array, size_t n, size_t size)
{
    if (n == 0 || (size && n > SIZE_MAX / size))
        return NULL;
    return realloc(array, n * size);
}

/* The capacity that holds `need` elements: `cap` (GROW_MIN_CAPACITY when 0) doubled until
 * it does, so that n appends cost O(n) copies in all; 0 when that overflows. */
static inline size_t grow_capacity(size_t cap, size_t need)
{
    size_t c = cap ? cap : GROW_MIN_CAPACITY;
    while (c < need) {
        if (c > SIZE_MAX / 2)
            return 0;
        c *= 2;
    }
    return c;
}

/* `array` (room for *cap elements of `size` bytes) with room for `need` elements: itself
 * when it has it, else a larger copy (grow_capacity) and *cap updated, or NULL when out of
 * memory (the array and *cap are then untouched). */
static inline void *grow(void *array, size_t *cap, size_t need, size_t size)
{
    if (array && need <= *cap)
        return array;
    size_t c = grow_capacity(*cap, need);
    void *grown = c ? grow_realloc(array, c, size) : NULL;
    if (grown)
        *cap = c;
    return grown;
}

/* The size of a cache line: arrays read at random indices (the packer's disks, the
 * front's nodes) start on one, so that a record no larger than a line never straddles
 * two (malloc aligns large blocks to 16 bytes only). */
#define GROW_CACHE_LINE 64

/* A fresh block for n >= 1 elements of `size` bytes starting on a GROW_CACHE_LINE
 * boundary, holding a copy of the first `used` elements of `array`, which is then freed
 * (NULL: nothing to copy). Returns the block (the caller's, for free or realloc), or
 * NULL when n * size overflows or memory is out (the array is then untouched and still
 * the caller's). */
static inline void *grow_aligned(void *array, size_t used, size_t n, size_t size)
{
    if (n == 0 || (size && n > (SIZE_MAX - GROW_CACHE_LINE) / size))
        return NULL;
    size_t bytes = (n * size + GROW_CACHE_LINE - 1) / GROW_CACHE_LINE * GROW_CACHE_LINE;
    void *block = aligned_alloc(GROW_CACHE_LINE, bytes); /* C11: bytes a multiple of the alignment */
    if (!block)
        return NULL;
    if (array && used)
        memcpy(block, array, used * size);
    free(array);
    return block;
}

#endif
