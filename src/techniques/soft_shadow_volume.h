/* soft_shadow_volume.h -- for tests of the wedge family (soft_shadow_volume.c):
 * with `on`, the runs prepared after the call sum every silhouette edge at
 * every sample (the O(samples x edges) loop the wedge lists replace), so a
 * test can compare the lists' images with it bit for bit. */
#ifndef SL_SOFT_SHADOW_VOLUME_H
#define SL_SOFT_SHADOW_VOLUME_H
#include <stdbool.h>

void ssv_set_all_edges(bool on);

/* The last prepared run's (with lists) wedges reaching the camera's near plane (over its
 * patches): how many, how many of them were cut there (the others go to
 * every sample), and the (lit candidate, such wedge) pairs summed before
 * the cut (every sample) and after it. */
typedef struct SsvNearStats {
    long reaching, cut, before, after;
} SsvNearStats;
SsvNearStats ssv_near_stats(void);

#endif
