/* lightimage.h -- summed-area tables of a textured rect light's emission
 * image and of its square, as a keyed resource: the mean colour and the
 * colour variance E[c^2] - E[c]^2 (Donnelly & Lauritzen's moments, which
 * seed 001 §3 cites for the light image's variance) of any rectangle of the
 * light in O(1), with pixels cut by the rectangle's edges counted by area,
 * exactly as the reference's area sampling weighs them (scene/light.c).
 *
 * Light coordinates: u in [0, 1] along the light's right = up x direction,
 * v in [0, 1] along its up; image row 0 is the v = 1 edge. */
#ifndef SL_LIGHTIMAGE_H
#define SL_LIGHTIMAGE_H
#include "resources/resources.h"
#include "scene/scene.h"

typedef struct LightImageSat {
    int width, height;  /* of the emission image, pixels */
    double *sum, *sum2; /* (width + 1) x (height + 1) x 3: integrals of c and c^2 from the image's top-left */
    double peak;        /* largest channel value in the image (>= 0): variances are given in units of peak^2 */
} LightImageSat;

/* The tables of light `light_index`, which must be a LIGHT_TEXTURED_RECT. */
const LightImageSat *res_light_image_sat(ResourceManager *rm, const Scene *scene, int light_index, Error *err);

/* Mean colour of the light over [u0, u1] x [v0, v1] (u0 < u1, v0 < v1), and
 * the mean over R, G, B of the colour variance there divided by peak^2 (0
 * for a black image), in [0, 0.25] like a visibility variance. */
void light_image_box(const LightImageSat *t, double u0, double u1, double v0, double v1, double mean[3],
                     double *variance);

#endif
