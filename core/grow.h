/* grow.h - growing arrays (internal to core/): the one place that picks a larger
 * capacity and reallocates, checking capacity * element size for overflow. */
#ifndef GRAINPACK_CORE_GROW_H
#define GRAINPACK_CORE_GROW_H

#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

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

#endif
