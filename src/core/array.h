/* array.h -- room for one more element in a doubling array, the growth
 * every list of the engine uses (resource entries and events, set-up
 * triangles, stability jobs and rows). */
#ifndef SL_ARRAY_H
#define SL_ARRAY_H
#include <limits.h>
#include <stdlib.h>

/* `data` holds `count` elements of `size` bytes in room for *cap. Returns
 * data while count < *cap, else data reallocated to twice *cap (`initial`
 * when empty) with *cap updated; NULL when out of memory, data then
 * untouched and still the caller's. */
static inline void *array_room(void *data, int count, int *cap, size_t size, int initial)
{
    if (count < *cap) return data;
    if (*cap > INT_MAX / 2) return NULL;
    int n = *cap > 0 ? 2 * *cap : initial;
    void *p = realloc(data, size * (size_t)n);
    if (p) *cap = n;
    return p;
}

#endif
