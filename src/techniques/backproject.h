/* backproject.h -- seed 000 §1.1 (Aszódi & Szirmay-Kalos): an elementary
 * caster, the part of a surface one shadow-map lexel sees, projected from
 * the receiver r back onto the shadow-map plane z = n, in the light's frame
 * (softmap.h: origin at the light's centre, z along the map's axis). Its
 * position and size are the paper's
 *     size = (r_z - n) / (r_z - c_z) * c_z / n,
 *     l_r  = (n - c_z) / (r_z - c_z) * r + size * l,
 * where l is the lexel on the plane (Eq. 4: l = c n / c_z). With q = r n / r_z,
 * the receiver's own lexel, the coefficients of r add up so that
 *     l_r - q = size * (l - q)      (the r terms: (n - c_z)/(r_z - c_z) + size n / r_z = n / r_z),
 * the form used here: it never subtracts two numbers that grow as c_z -> r_z.
 * Sizes and offsets are in lexels; the plane's lexel grid is the map's. */
#ifndef SL_BACKPROJECT_H
#define SL_BACKPROJECT_H
#include <math.h>
#include <stdbool.h>

/* The stiff case r_z - c_z -> 0 (contact, self-shadowing): a caster at the
 * receiver's depth or behind it cannot lie between r and the light (every
 * point of a segment from r to the light's plane z = 0 has depth < r_z), so
 * it is skipped; a caster closer than this fraction of r_z is held there,
 * so size stays finite (at most ~1e9 c_z / n lexels): it then covers the
 * whole neighbourhood, which is the right limit. */
#define BACKPROJECT_MIN_GAP 1e-9

typedef struct Backprojected {
    double size;   /* the caster's side seen from r, in lexels of the plane */
    double di, dj; /* l_r - q in lexels */
} Backprojected;

/* Caster at depth c_z whose lexel lies (di, dj) lexels from q, receiver at
 * depth r_z, plane at n (0 < n < r_z). false: it cannot occlude. */
static inline bool backproject(double r_z, double c_z, double n, double di, double dj, Backprojected *out)
{
    double gap = r_z - c_z;
    if (!(gap > 0.0) || !(c_z > 0.0)) return false;
    gap = fmax(gap, BACKPROJECT_MIN_GAP * r_z);
    out->size = (r_z - n) / gap * c_z / n;
    out->di = out->size * di;
    out->dj = out->size * dj;
    return true;
}

/* Assumption 1 of seed 000 §1.1: the plane n at which the light, seen from a
 * receiver at depth r_z, covers the K x K lexel neighbourhood. From r the
 * light (half-extent a in its plane z = 0) projects onto the plane z = n
 * with half-extent a (r_z - n) / r_z, i.e. a (r_z - n) / (r_z n) in tangent
 * units; setting that to the kernel's half-width h = K dx / 2 gives
 *     n = a r_z / (a + r_z h),
 * which is the paper's "n proportional to R" (n = 2R / (K dx)) when
 * r_z h >> a. The additive factor does not depend on n at all (planes z = 0
 * and z = n are parallel, so the projection from r between them is a
 * similarity that scales l_r - q, size and the light alike); the occlusion
 * bits do: n sets how many lexels the light's footprint D holds, here about
 * pi K^2 / 4. The kernel reaches (to half a lexel) every caster that can
 * occlude r and lies farther from the light than n. */
static inline double backproject_plane(double half_world, double r_z, double half_tangent)
{
    return half_world * r_z / (half_world + r_z * half_tangent);
}

#endif
