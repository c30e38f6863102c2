/* lightbody.c -- view frustum and intersection body B (lightbody.h). B is
 * kept as a list of convex faces, clipped plane by plane (Sutherland-Hodgman
 * per face, the cut closed by a cap polygon), as Wimmer & Scherzer's LiSPSM
 * reference does (course §3.2.1 cites it for the construction). */
#include "resources/views/lightbody.h"

#define MAX_VERTS 32 /* per face: 4, plus one per clipping plane at most */
#define MAX_FACES 24 /* 6, plus one cap per clipping plane */

typedef struct Poly { int n; dvec3 v[MAX_VERTS]; } Poly;
typedef struct Body { int nf; Poly f[MAX_FACES]; } Body;

ViewFrustum view_frustum(const Camera *cam)
{
    ViewFrustum f;
    f.eye = d3_from(cam->position);
    f.fwd = d3_normalize_or(d3_sub(d3_from(cam->target), f.eye), d3(0, 0, -1));
    f.right = d3_normalize_or(d3_cross(f.fwd, d3_from(cam->up)), d3(1, 0, 0));
    f.up = d3_cross(f.right, f.fwd);
    f.tan_y = tan(0.5 * cam->fov_y_rad);
    f.tan_x = f.tan_y * (double)cam->width / (double)cam->height;
    f.near = cam->near_dist;
    f.far = cam->far_dist;
    return f;
}

dvec3 frustum_point(const ViewFrustum *f, double sx, double sy, double d)
{
    dvec3 dir = d3_add(f->fwd, d3_add(d3_scale(f->right, sx * f->tan_x), d3_scale(f->up, sy * f->tan_y)));
    return d3_madd(f->eye, dir, d);
}

static void quad(Poly *p, dvec3 a, dvec3 b, dvec3 c, dvec3 d)
{
    p->n = 4;
    p->v[0] = a; p->v[1] = b; p->v[2] = c; p->v[3] = d;
}

/* The slice as six quads (orientation does not matter to the clipper). */
static void slice_body(const ViewFrustum *f, double d0, double d1, Body *b)
{
    dvec3 c[8];
    for (int k = 0; k < 8; k++) c[k] = frustum_point(f, k & 1 ? 1 : -1, k & 2 ? 1 : -1, k & 4 ? d1 : d0);
    b->nf = 6;
    quad(&b->f[0], c[0], c[1], c[3], c[2]); /* near */
    quad(&b->f[1], c[4], c[5], c[7], c[6]); /* far */
    quad(&b->f[2], c[0], c[1], c[5], c[4]); /* bottom */
    quad(&b->f[3], c[2], c[3], c[7], c[6]); /* top */
    quad(&b->f[4], c[0], c[2], c[6], c[4]); /* left */
    quad(&b->f[5], c[1], c[3], c[7], c[5]); /* right */
}

/* Keep the part of p with n.x + d >= 0; crossing points go to cut[]. */
static void clip_poly(Poly *p, dvec3 n, double d, dvec3 *cut, int *ncut)
{
    Poly out = {0};
    for (int i = 0; i < p->n; i++) {
        dvec3 a = p->v[i], b = p->v[(i + 1) % p->n];
        double da = d3_dot(n, a) + d, db = d3_dot(n, b) + d;
        if (da >= 0.0 && out.n < MAX_VERTS) out.v[out.n++] = a;
        if ((da >= 0.0) != (db >= 0.0)) {
            dvec3 x = d3_add(a, d3_scale(d3_sub(b, a), da / (da - db))); /* da != db here */
            if (out.n < MAX_VERTS) out.v[out.n++] = x;
            if (*ncut < MAX_VERTS * 2) cut[(*ncut)++] = x;
        }
    }
    *p = out.n >= 3 ? out : (Poly){0};
}

/* Order the cut points by angle around their centroid: the cap face. */
static void cap_face(dvec3 n, const dvec3 *pts, int k, Poly *cap)
{
    dvec3 c = d3(0, 0, 0);
    for (int i = 0; i < k; i++) c = d3_add(c, pts[i]);
    c = d3_scale(c, 1.0 / k);
    dvec3 e1 = d3_normalize_or(d3_cross(n, fabs(n.x) < 0.9 ? d3(1, 0, 0) : d3(0, 1, 0)), d3(0, 0, 1));
    dvec3 e2 = d3_cross(n, e1);
    double ang[MAX_VERTS * 2];
    int idx[MAX_VERTS * 2];
    for (int i = 0; i < k; i++) {
        dvec3 r = d3_sub(pts[i], c);
        ang[i] = atan2(d3_dot(r, e2), d3_dot(r, e1));
        idx[i] = i;
    }
    for (int i = 1; i < k; i++) /* insertion sort: k is small */
        for (int j = i; j > 0 && ang[idx[j]] < ang[idx[j - 1]]; j--) {
            int t = idx[j];
            idx[j] = idx[j - 1];
            idx[j - 1] = t;
        }
    cap->n = 0;
    for (int i = 0; i < k && cap->n < MAX_VERTS; i++) cap->v[cap->n++] = pts[idx[i]];
}

static void clip_body(Body *b, BodyPlane pl)
{
    dvec3 cut[MAX_VERTS * 2];
    int ncut = 0, nf = 0;
    for (int i = 0; i < b->nf; i++) {
        clip_poly(&b->f[i], pl.n, pl.d, cut, &ncut);
        if (b->f[i].n) b->f[nf++] = b->f[i];
    }
    b->nf = nf;
    if (ncut >= 3 && b->nf < MAX_FACES) cap_face(pl.n, cut, ncut, &b->f[b->nf++]);
}

/* The scene's bounds grown by 1e-6 of its extent, as six kept half-spaces. */
static void box_planes(const Scene *scene, BodyPlane *box)
{
    double grow = 1e-6 * scene_extent(scene);
    dvec3 lo = d3_from(scene->bounds_min), hi = d3_from(scene->bounds_max);
    box[0] = (BodyPlane){d3(1, 0, 0), -lo.x + grow};
    box[1] = (BodyPlane){d3(-1, 0, 0), hi.x + grow};
    box[2] = (BodyPlane){d3(0, 1, 0), -lo.y + grow};
    box[3] = (BodyPlane){d3(0, -1, 0), hi.y + grow};
    box[4] = (BodyPlane){d3(0, 0, 1), -lo.z + grow};
    box[5] = (BodyPlane){d3(0, 0, -1), hi.z + grow};
}

FrustumFace frustum_face(const ViewFrustum *f, int face)
{
    Body b;
    slice_body(f, f->near, f->far, &b);
    const Poly *p = &b.f[face];
    FrustumFace ff;
    dvec3 centre = d3_scale(d3_add(frustum_point(f, 0, 0, f->near), frustum_point(f, 0, 0, f->far)), 0.5);
    ff.n = d3_normalize_or(d3_cross(d3_sub(p->v[1], p->v[0]), d3_sub(p->v[2], p->v[0])), f->fwd);
    if (d3_dot(ff.n, d3_sub(centre, p->v[0])) > 0.0) ff.n = d3_scale(ff.n, -1); /* outward */
    ff.d = -d3_dot(ff.n, p->v[0]);
    for (int k = 0; k < 4; k++) ff.corner[k] = p->v[k];
    /* slice_body's side quads list a near edge (corners 0, 1) and a far edge (2, 3) */
    bool side = face >= FRUSTUM_BOTTOM;
    ff.near_mid = d3_scale(d3_add(p->v[0], side ? p->v[1] : p->v[2]), 0.5);
    ff.far_mid = d3_scale(d3_add(side ? p->v[2] : p->v[0], side ? p->v[3] : p->v[2]), 0.5);
    return ff;
}

int frustum_face_prism(const FrustumFace *ff, bool point, dvec3 light, BodyPlane *out)
{
    dvec3 c = d3_scale(d3_add(d3_add(ff->corner[0], ff->corner[1]), d3_add(ff->corner[2], ff->corner[3])), 0.25);
    int n = 0;
    for (int k = 0; k < 4; k++) {
        dvec3 a = ff->corner[k], b = ff->corner[(k + 1) % 4];
        dvec3 along = point ? d3_sub(a, light) : light;
        dvec3 nrm = d3_normalize_or(d3_cross(d3_sub(b, a), along), d3(0, 0, 0));
        if (d3_len(nrm) == 0.0) continue; /* an edge along the light's rays bounds nothing */
        if (d3_dot(nrm, d3_sub(c, a)) < 0.0) nrm = d3_scale(nrm, -1); /* keep the face's side */
        out[n++] = (BodyPlane){nrm, -d3_dot(nrm, a)};
    }
    return n;
}

int body_points(const ViewFrustum *f, double d0, double d1, const Scene *scene, const BodyPlane *extra, int n_extra,
                dvec3 *out, int max_out)
{
    Body b;
    slice_body(f, d0, d1, &b);
    BodyPlane box[6];
    box_planes(scene, box);
    for (int k = 0; k < 6 && b.nf; k++) clip_body(&b, box[k]);
    for (int k = 0; k < n_extra && b.nf; k++) clip_body(&b, extra[k]);
    int n = 0;
    for (int i = 0; i < b.nf; i++)
        for (int j = 0; j < b.f[i].n && n < max_out; j++) out[n++] = b.f[i].v[j];
    return n;
}

int spot_cone_planes(const Light *light, BodyPlane *out)
{
    dvec3 c = d3_from(light->position), a = d3_normalize_or(d3_from(light->direction), d3(0, -1, 0));
    dvec3 e1 = d3_normalize_or(d3_cross(a, fabs(a.y) < 0.99 ? d3(0, 1, 0) : d3(1, 0, 0)), d3(1, 0, 0));
    dvec3 e2 = d3_cross(e1, a);
    double t = tan(fmin(light->cone_half_rad, 89.0 * M_PI / 180.0));
    /* side planes of the pyramid circumscribing the cone: n = a t - e (inward) */
    const dvec3 e[4] = {e1, d3_scale(e1, -1), e2, d3_scale(e2, -1)};
    for (int k = 0; k < 4; k++) {
        dvec3 n = d3_sub(d3_scale(a, t), e[k]);
        out[k] = (BodyPlane){n, -d3_dot(n, c)};
    }
    out[4] = (BodyPlane){a, -d3_dot(a, c)}; /* in front of the light */
    return 5;
}
