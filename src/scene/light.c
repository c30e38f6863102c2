/* light.c -- light sampling and light-facing classification for the
 * ground-truth reference. Sphere lights are sampled uniformly in the cone of
 * directions they subtend (seed 000 §2: s = |D_c ∩ D| / |D|, the visible
 * fraction of the light's solid angle); rectangles and disks uniformly in area
 * (course Eq. 1.4: the visible fraction of the light's area). */
#include "scene/light.h"
#include <math.h>

#define PI_F 3.14159265358979323846f

static const char *const class_names[SAMPLE_CLASS_COUNT] = {
    "background", "lit_candidate", "backfacing", "outside_light", "not_receiver"};

const char *sample_class_name(SampleClass c) { return class_names[c]; }

bool light_is_delta(const Light *light)
{
    return light->kind == LIGHT_POINT || light->kind == LIGHT_SPOT || light->kind == LIGHT_DIRECTIONAL;
}

static vec3 rect_right(const Light *l) { return v3_cross(l->up, l->direction); }

static LightSample toward_point(vec3 p, vec3 q)
{
    LightSample s;
    vec3 d = v3_sub(q, p);
    s.dist = v3_len(d);
    s.dir_world = v3_normalize_or(d, v3(0, 1, 0));
    s.vis_weight = v3(1, 1, 1);
    s.irradiance = v3(0, 0, 0);
    return s;
}

static vec3 radiance(const Light *l) { return v3_scale(l->color, l->intensity); }

/* Point and spot: intensity I [W/sr] gives I / r^2 (guarded at r = 0). */
static LightSample sample_point(const Light *l, vec3 p)
{
    LightSample s = toward_point(p, l->position);
    float r2 = fmaxf(s.dist * s.dist, 1e-30f);
    s.irradiance = v3_scale(radiance(l), 1.0f / r2);
    return s;
}

static LightSample sample_directional(const Light *l)
{
    LightSample s;
    s.dir_world = v3_scale(l->direction, -1.0f);
    s.dist = INFINITY;
    s.vis_weight = v3(1, 1, 1);
    s.irradiance = radiance(l);
    return s;
}

/* Uniform direction in the cone toward a sphere of radius R at distance d.
 * 1 - cos(theta_max) is computed as sin^2 / (1 + cos) to stay exact when
 * R -> 0 (stiff case: R = 1e-6 must converge to the point light). */
static LightSample sample_sphere(const Light *l, vec3 p, float u, float v)
{
    vec3 to_c = v3_sub(l->position, p);
    float d = v3_len(to_c), R = l->radius;
    vec3 w = v3_normalize_or(to_c, v3(0, 1, 0));
    float one_minus_cos_max = 2.0f; /* inside the sphere: the whole sphere of directions */
    if (d > R) {
        float sin2_max = (R / d) * (R / d);
        one_minus_cos_max = sin2_max / (1.0f + sqrtf(fmaxf(0.0f, 1.0f - sin2_max)));
    }
    float a = u * one_minus_cos_max; /* 1 - cos(theta) */
    float cos_t = 1.0f - a, sin_t = sqrtf(fmaxf(0.0f, a * (2.0f - a)));
    float phi = 2.0f * PI_F * v;
    vec3 t, b;
    v3_basis(w, &t, &b);
    LightSample s;
    s.dir_world = v3_add(v3_scale(w, cos_t), v3_add(v3_scale(t, sin_t * cosf(phi)), v3_scale(b, sin_t * sinf(phi))));
    /* Nearest intersection with the sphere along dir (far one when inside). */
    float disc = sqrtf(fmaxf(0.0f, R * R - d * d * sin_t * sin_t));
    s.dist = d > R ? d * cos_t - disc : d * cos_t + disc;
    s.dist = fmaxf(s.dist, 0.0f);
    s.vis_weight = v3(1, 1, 1);
    s.irradiance = v3_scale(radiance(l), 2.0f * PI_F * one_minus_cos_max); /* L_e / pdf_omega */
    return s;
}

/* Area lights: L_e cos_q * area / r^2 (one-sided, emitting along +direction). */
static LightSample area_sample(const Light *l, vec3 p, vec3 q, float area, vec3 emission)
{
    LightSample s = toward_point(p, q);
    float cos_q = fmaxf(0.0f, -v3_dot(l->direction, s.dir_world));
    float r2 = fmaxf(s.dist * s.dist, 1e-30f);
    s.irradiance = v3_scale(emission, cos_q * area / r2);
    return s;
}

static vec3 emission_lookup(const Light *l, float u, float v)
{
    const Image *im = &l->emission;
    int x = (int)fminf(u * (float)im->width, (float)(im->width - 1));
    int y = (int)fminf((1.0f - v) * (float)im->height, (float)(im->height - 1));
    const float *px = image_px(im, x < 0 ? 0 : x, y < 0 ? 0 : y);
    return im->channels >= 3 ? v3(px[0], px[1], px[2]) : v3(px[0], px[0], px[0]);
}

static vec3 rect_point(const Light *l, float u, float v)
{
    vec3 q = v3_madd(l->position, rect_right(l), (u - 0.5f) * l->width);
    return v3_madd(q, l->up, (v - 0.5f) * l->height);
}

vec3 light_sample_colour(const Light *l, float u, float v)
{
    return l->kind == LIGHT_TEXTURED_RECT ? emission_lookup(l, u, v) : v3(1, 1, 1);
}

static LightSample sample_rect(const Light *l, vec3 p, float u, float v)
{
    vec3 e = radiance(l);
    if (l->kind != LIGHT_TEXTURED_RECT) return area_sample(l, p, rect_point(l, u, v), l->width * l->height, e);
    vec3 tex = light_sample_colour(l, u, v);
    LightSample s = area_sample(l, p, rect_point(l, u, v), l->width * l->height, v3_mul(e, tex));
    s.vis_weight = tex;
    return s;
}

/* Shirley-Chiu concentric map of the unit square onto the unit disk. */
static void concentric_disk(float u, float v, float *x, float *y)
{
    float a = 2.0f * u - 1.0f, b = 2.0f * v - 1.0f;
    if (a == 0.0f && b == 0.0f) { *x = *y = 0.0f; return; }
    float r, phi;
    if (fabsf(a) > fabsf(b)) { r = a; phi = (PI_F / 4.0f) * (b / a); }
    else { r = b; phi = (PI_F / 2.0f) - (PI_F / 4.0f) * (a / b); }
    *x = r * cosf(phi);
    *y = r * sinf(phi);
}

static LightSample sample_disk(const Light *l, vec3 p, float u, float v)
{
    float x, y;
    vec3 t, b;
    concentric_disk(u, v, &x, &y);
    v3_basis(l->direction, &t, &b);
    vec3 q = v3_add(l->position, v3_scale(v3_add(v3_scale(t, x), v3_scale(b, y)), l->radius));
    return area_sample(l, p, q, PI_F * l->radius * l->radius, radiance(l));
}

bool light_plane_axes(const Light *l, vec3 *centre, vec3 *e1, vec3 *e2)
{
    *centre = l->position;
    if (l->kind == LIGHT_RECT || l->kind == LIGHT_TEXTURED_RECT) {
        *e1 = rect_right(l);
        *e2 = l->up;
        return true;
    }
    if (l->kind == LIGHT_DISK) {
        v3_basis(l->direction, e1, e2);
        return true;
    }
    return false;
}

void light_plane_point(const Light *l, float u, float v, double st[2])
{
    if (l->kind == LIGHT_DISK) {
        float x, y;
        concentric_disk(u, v, &x, &y);
        st[0] = (double)x * l->radius;
        st[1] = (double)y * l->radius;
        return;
    }
    st[0] = ((double)u - 0.5) * l->width; /* rect_point's offsets */
    st[1] = ((double)v - 0.5) * l->height;
}

void light_bitmask_visibility(const vec3 *colour, const uint64_t *kept, const uint64_t *blocked, int n, int nc,
                              float *out)
{
    double all[3] = {0, 0, 0}, lit[3] = {0, 0, 0};
    for (int i = 0; i < n; i++) {
        uint64_t bit = 1ull << (i % 64);
        if (!(kept[i / 64] & bit)) continue;
        const float w[3] = {colour[i].x, colour[i].y, colour[i].z};
        bool unblocked = !(blocked[i / 64] & bit);
        for (int c = 0; c < nc; c++) {
            all[c] += w[c];
            lit[c] += unblocked ? w[c] : 0.0;
        }
    }
    for (int c = 0; c < nc; c++) out[c] = all[c] > 0.0 ? (float)(lit[c] / all[c]) : 1.0f;
}

LightSample light_sample(const Light *l, vec3 p, float u, float v)
{
    switch (l->kind) {
    case LIGHT_POINT:
    case LIGHT_SPOT: return sample_point(l, p);
    case LIGHT_DIRECTIONAL: return sample_directional(l);
    case LIGHT_SPHERE: return sample_sphere(l, p, u, v);
    case LIGHT_RECT:
    case LIGHT_TEXTURED_RECT: return sample_rect(l, p, u, v);
    case LIGHT_DISK: return sample_disk(l, p, u, v);
    }
    return sample_point(l, p);
}

LightSample light_sample_center(const Light *l, vec3 p)
{
    if (l->kind == LIGHT_DIRECTIONAL) return sample_directional(l);
    LightSample s = toward_point(p, l->position);
    s.irradiance = v3(0, 0, 0); /* the centre is a visibility probe, not an estimator */
    return s;
}

/* The light's sample highest above the tangent plane of (p, n): the
 * direction of a sphere light's cone nearest n (angle min(alpha, theta_max)
 * from the axis, turned toward n), the rectangle's corner or the disk's rim
 * point on n's side. */
LightSample light_sample_highest(const Light *l, vec3 p, vec3 n)
{
    switch (l->kind) {
    case LIGHT_SPHERE: {
        vec3 w = v3_normalize_or(v3_sub(l->position, p), n), t, b;
        float d = v3_len(v3_sub(l->position, p)), R = l->radius, one_minus_cos_max = 2.0f;
        if (d > R) one_minus_cos_max = (R / d) * (R / d) / (1.0f + sqrtf(fmaxf(0.0f, 1.0f - (R / d) * (R / d))));
        v3_basis(w, &t, &b);
        float phi = atan2f(v3_dot(n, b), v3_dot(n, t)); /* sample_sphere's azimuth, in (-pi, pi] */
        float u = fminf(1.0f - v3_dot(n, w), one_minus_cos_max) / one_minus_cos_max;
        return sample_sphere(l, p, u, (phi < 0.0f ? phi + 2.0f * PI_F : phi) / (2.0f * PI_F));
    }
    case LIGHT_RECT:
    case LIGHT_TEXTURED_RECT:
        return sample_rect(l, p, v3_dot(n, rect_right(l)) > 0.0f ? 1.0f : 0.0f, v3_dot(n, l->up) > 0.0f ? 1.0f : 0.0f);
    case LIGHT_DISK: {
        vec3 t, b;
        v3_basis(l->direction, &t, &b);
        vec3 in_plane = v3_normalize_or(v3_sub(n, v3_scale(l->direction, v3_dot(n, l->direction))), t);
        return area_sample(l, p, v3_madd(l->position, in_plane, l->radius), PI_F * l->radius * l->radius, radiance(l));
    }
    default: return light_sample(l, p, 0.5f, 0.5f);
    }
}

/* Height of the light's centre above p's tangent plane, n . (c - p), and
 * the half-extent of its points along n: every light point q has
 * n . (q - p) within centre +- half_extent, both bounds reached. A sphere
 * light's extent is its radius, which also bounds the cone of directions it
 * subtends from p (|n . w| < sin(theta_max) = R / d iff |n . (c - p)| < R);
 * a disk's is R sin(angle between n and its axis); a rectangle's the sum of
 * its half sides' projections. Delta lights have none (a directional light's
 * "centre" is its direction toward the light). */
static void height_above_plane(const Light *l, vec3 p, vec3 n, float *centre, float *half_extent)
{
    *centre = v3_dot(n, v3_sub(l->position, p));
    *half_extent = 0.0f;
    switch (l->kind) {
    case LIGHT_SPHERE: *half_extent = l->radius; break;
    case LIGHT_DISK: {
        float c = v3_dot(n, l->direction);
        *half_extent = l->radius * sqrtf(fmaxf(0.0f, 1.0f - c * c));
        break;
    }
    case LIGHT_RECT:
    case LIGHT_TEXTURED_RECT:
        *half_extent = 0.5f * (l->width * fabsf(v3_dot(n, rect_right(l))) + l->height * fabsf(v3_dot(n, l->up)));
        break;
    case LIGHT_DIRECTIONAL: *centre = -v3_dot(n, l->direction); break;
    default: break;
    }
}

bool light_crosses_horizon(const Light *l, vec3 p, vec3 n)
{
    float centre, half_extent;
    height_above_plane(l, p, n, &centre, &half_extent);
    return centre - half_extent < 0.0f && centre + half_extent > 0.0f;
}

SampleClass light_classify(const Light *l, vec3 p, vec3 n)
{
    if (l->kind == LIGHT_SPOT) {
        vec3 axis_to_p = v3_normalize_or(v3_sub(p, l->position), l->direction);
        if (v3_dot(axis_to_p, l->direction) < cosf(l->cone_half_rad)) return SAMPLE_OUTSIDE_LIGHT;
    }
    bool one_sided = l->kind == LIGHT_RECT || l->kind == LIGHT_TEXTURED_RECT || l->kind == LIGHT_DISK;
    if (one_sided && v3_dot(v3_sub(p, l->position), l->direction) <= 0.0f) return SAMPLE_OUTSIDE_LIGHT;
    if (l->kind == LIGHT_SPHERE && v3_len(v3_sub(p, l->position)) <= l->radius) return SAMPLE_LIT_CANDIDATE;
    float centre, half_extent;
    height_above_plane(l, p, n, &centre, &half_extent);
    return centre + half_extent > 0.0f ? SAMPLE_LIT_CANDIDATE : SAMPLE_BACKFACING;
}
