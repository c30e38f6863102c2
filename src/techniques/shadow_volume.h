/* shadow_volume.h -- the hard volume's counts for other techniques: the
 * integration constant of soft shadow volumes (course §5.3.2) is the number
 * of volumes of a point of the light each view sample is in. */
#ifndef SL_SHADOW_VOLUME_H
#define SL_SHADOW_VOLUME_H
#include "raster/raster.h"
#include "resources/geometry/silhouette.h"
#include "techniques/technique.h"

/* z-fail (Carmack's reverse) counts of the infinite volume of `sil`'s point,
 * per view sample (count[s] > 0: s is in that many volumes), each sample
 * tested at its point moved toward the camera by offset_scale ray offsets
 * (shadow_volume's `offset_scale`); `fill` receives the pass's fill. */
bool shadow_volume_zfail_counts(const TechContext *ctx, const Silhouette *sil, double offset_scale, int32_t *count,
                                RasterStats *fill, Error *err);

#endif
