/* silhouette.c -- welded edge adjacency and possible silhouette edges for the
 * light's centre (see silhouette.h). Welding uses an open-addressing hash
 * table, edges a counting sort by their lower vertex, so the build is linear
 * in the triangles (a sphere: 26 ns per triangle at 1k triangles, 36 at 100k,
 * 120 at 1M, where the welding table's probes miss the cache). */
#include "resources/geometry/silhouette.h"
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/array.h"
#include "core/hash.h"
#include "core/mat4.h"

/* ---- welding ----------------------------------------------------------------- */

static uint32_t float_bits(float f)
{
    f += 0.0f; /* -0 -> +0 */
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

static uint64_t position_hash(vec3 p)
{
    uint64_t h = hash_u32(float_bits(p.x));
    h = h * 0x9E3779B97F4A7C15ull ^ hash_u32(float_bits(p.y));
    return h * 0x9E3779B97F4A7C15ull ^ hash_u32(float_bits(p.z));
}

static bool same_position(vec3 a, vec3 b)
{
    return float_bits(a.x) == float_bits(b.x) && float_bits(a.y) == float_bits(b.y) && float_bits(a.z) == float_bits(b.z);
}

/* Table size: a power of two at least twice n. */
static size_t table_size(size_t n)
{
    size_t s = 16;
    while (s < 2 * n) s *= 2;
    return s;
}

/* weld[v] = the first vertex with v's position. */
static bool weld_positions(const Mesh *m, uint32_t *weld)
{
    size_t size = table_size((size_t)m->num_vertices), mask = size - 1;
    int32_t *slot = malloc(size * sizeof *slot);
    if (!slot) return false;
    memset(slot, 0xff, size * sizeof *slot); /* -1: empty */
    for (int v = 0; v < m->num_vertices; v++) {
        size_t i = (size_t)position_hash(m->positions[v]) & mask;
        while (slot[i] >= 0 && !same_position(m->positions[slot[i]], m->positions[v])) i = (i + 1) & mask;
        if (slot[i] < 0) slot[i] = v;
        weld[v] = (uint32_t)slot[i];
    }
    free(slot);
    return true;
}

/* ---- edges ------------------------------------------------------------------- */

/* One undirected welded edge lo < hi and what its triangles say about it. */
typedef struct EdgeSlot {
    uint32_t lo, hi;
    int32_t triangles;
    int32_t dir_sum;      /* sum of +1 (lo -> hi) / -1: 0 on a consistently oriented shared edge */
    int32_t back_sum;     /* minus the same, over triangles whose back faces the centre */
    int32_t signed_sum;   /* over every triangle, times its facing (+1, -1, 0) */
} EdgeSlot;

/* The edges grouped by their lower welded vertex (a counting sort of the
 * triangles' edges): bucket lo is slot[start[lo]] .. slot[start[lo + 1]),
 * room for every edge end that names lo as the lower vertex, of which
 * used[lo] are taken. Triangles near in index order use vertices near in
 * memory, so the buckets they touch are near too: linear and cache-friendly
 * where a hash table's probes miss the cache at every edge. */
typedef struct EdgeTable {
    EdgeSlot *slot;  /* 3 per triangle at most, zeroed */
    uint32_t *start; /* num_vertices + 1 */
    uint32_t *used;  /* num_vertices, zeroed */
    size_t size;     /* slots in use or free: start[num_vertices] */
} EdgeTable;

static EdgeSlot *edge_find(EdgeTable *t, uint32_t a, uint32_t b)
{
    uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
    EdgeSlot *bucket = t->slot + t->start[lo];
    for (uint32_t i = 0; i < t->used[lo]; i++)
        if (bucket[i].hi == hi) return &bucket[i];
    EdgeSlot *e = &bucket[t->used[lo]++];
    e->lo = lo;
    e->hi = hi;
    return e;
}

/* Which side of triangle (a, b, c) the homogeneous point L is on: the sign of
 * n . (L.xyz - L.w a) with n = (b - a) x (c - a) (double). 0: degenerate
 * (n = 0, *degenerate set) or edge-on. */
static int facing(vec3 a, vec3 b, vec3 c, const double L[4], bool *degenerate)
{
    dvec3 da = d3_from(a), n = d3_cross(d3_sub(d3_from(b), da), d3_sub(d3_from(c), da));
    *degenerate = n.x == 0.0 && n.y == 0.0 && n.z == 0.0;
    double s = n.x * (L[0] - L[3] * da.x) + n.y * (L[1] - L[3] * da.y) + n.z * (L[2] - L[3] * da.z);
    return s > 0.0 ? 1 : s < 0.0 ? -1 : 0;
}

typedef struct ObjectBuild {
    const Mesh *mesh;
    uint32_t *weld;
    EdgeTable edges;
    int8_t *facing; /* per triangle; 2: degenerate, skipped */
} ObjectBuild;

/* Each triangle's facing (2: degenerate) and the buckets' sizes. */
static void classify_triangles(ObjectBuild *ob, const double L[4], SilObject *so)
{
    const Mesh *m = ob->mesh;
    for (int t = 0; t < m->num_triangles; t++) {
        const uint32_t *ix = &m->indices[3 * t];
        uint32_t w[3] = {ob->weld[ix[0]], ob->weld[ix[1]], ob->weld[ix[2]]};
        bool degenerate;
        int f = facing(m->positions[ix[0]], m->positions[ix[1]], m->positions[ix[2]], L, &degenerate);
        if (degenerate || w[0] == w[1] || w[1] == w[2] || w[2] == w[0]) {
            ob->facing[t] = 2;
            so->degenerate++;
            continue;
        }
        ob->facing[t] = (int8_t)f;
        so->grazing += f == 0;
        for (int k = 0; k < 3; k++) ob->edges.start[w[k] < w[(k + 1) % 3] ? w[k] : w[(k + 1) % 3]]++;
    }
    uint32_t at = 0; /* counts to bucket starts: < 3 * num_triangles < 2^32 */
    for (int v = 0; v <= m->num_vertices; v++) {
        uint32_t n = ob->edges.start[v];
        ob->edges.start[v] = at;
        at += n;
    }
    ob->edges.size = at;
}

static void count_edges(ObjectBuild *ob)
{
    const Mesh *m = ob->mesh;
    for (int t = 0; t < m->num_triangles; t++) {
        int f = ob->facing[t];
        if (f == 2) continue;
        const uint32_t *ix = &m->indices[3 * t];
        uint32_t w[3] = {ob->weld[ix[0]], ob->weld[ix[1]], ob->weld[ix[2]]};
        for (int k = 0; k < 3; k++) {
            uint32_t a = w[k], b = w[(k + 1) % 3];
            EdgeSlot *e = edge_find(&ob->edges, a, b);
            int dir = a < b ? 1 : -1;
            e->triangles++;
            e->dir_sum += dir;
            e->back_sum -= f < 0 ? dir : 0;
            e->signed_sum += f * dir;
        }
    }
}

/* Classify every edge, set the triangle weights and append the silhouette
 * edges of this object. */
static bool collect(ObjectBuild *ob, SilRule rule, SilObject *so, Silhouette *sil, int *cap)
{
    EdgeTable *t = &ob->edges;
    for (size_t i = 0; i < t->size; i++) {
        const EdgeSlot *e = &t->slot[i];
        if (!e->triangles) continue;
        so->edges++;
        so->open_edges += e->triangles == 1;
        so->nonmanifold_edges += e->triangles > 2;
        so->misoriented_edges += e->triangles == 2 && e->dir_sum != 0;
    }
    so->closed = so->open_edges == 0 && so->nonmanifold_edges == 0 && so->misoriented_edges == 0;
    bool shell = so->nonmanifold_edges == 0 && so->misoriented_edges == 0 && so->open_edges * SIL_SHELL_OPEN < so->edges;
    bool dark = so->closed || (rule == SIL_SHELLS_DARK_SIDE && shell);
    for (int k = 0; k < ob->mesh->num_triangles; k++) {
        int f = ob->facing[k];
        so->weight[k] = (int8_t)(f == 2 ? 0 : dark ? -(f < 0) : f);
    }
    const vec3 *pos = ob->mesh->positions;
    for (size_t i = 0; i < t->size; i++) {
        const EdgeSlot *e = &t->slot[i];
        int m = dark ? e->back_sum : e->signed_sum;
        if (!e->triangles || m == 0) continue;
        SilEdge *edges = array_room(sil->edges, sil->num_edges, cap, sizeof *edges, 256);
        if (!edges) return false;
        sil->edges = edges;
        sil->edges[sil->num_edges++] = m > 0 ? (SilEdge){pos[e->lo], pos[e->hi], m, so->object}
                                             : (SilEdge){pos[e->hi], pos[e->lo], -m, so->object};
        so->silhouette_edges++;
    }
    return true;
}

static bool build_object(const Mesh *m, const double L[4], SilRule rule, SilObject *so, Silhouette *sil, int *cap)
{
    size_t nv = (size_t)m->num_vertices, nt = (size_t)m->num_triangles;
    ObjectBuild ob = {m, malloc(sizeof(uint32_t) * nv), {NULL, calloc(nv + 1, sizeof(uint32_t)),
                      calloc(nv + 1, sizeof(uint32_t)), 0}, malloc(nt + 1)};
    so->weight = malloc(nt + 1);
    bool ok = ob.weld && ob.edges.start && ob.edges.used && ob.facing && so->weight && weld_positions(m, ob.weld);
    if (ok) classify_triangles(&ob, L, so);
    ok = ok && (ob.edges.slot = calloc(ob.edges.size + 1, sizeof *ob.edges.slot)) != NULL;
    if (ok) count_edges(&ob);
    ok = ok && collect(&ob, rule, so, sil, cap);
    free(ob.weld);
    free(ob.edges.slot);
    free(ob.edges.start);
    free(ob.edges.used);
    free(ob.facing);
    return ok;
}

/* ---- the resource -------------------------------------------------------------- */

static void light_centre(const Light *l, double L[4])
{
    bool directional = l->kind == LIGHT_DIRECTIONAL;
    vec3 p = directional ? v3_scale(l->direction, -1.0f) : l->position;
    L[0] = p.x;
    L[1] = p.y;
    L[2] = p.z;
    L[3] = directional ? 0.0 : 1.0;
}

void silhouette_free(Silhouette *sil)
{
    if (!sil) return;
    for (int i = 0; i < sil->num_objects; i++) free(sil->objects[i].weight);
    free(sil->objects);
    free(sil->edges);
    free(sil);
}

Silhouette *silhouette_build(const Scene *scene, int light_index, Error *err)
{
    double L[4];
    light_centre(&scene->lights[light_index], L);
    return silhouette_build_point(scene, L, SIL_BERGERON, err);
}

Silhouette *silhouette_build_point(const Scene *scene, const double L[4], SilRule rule, Error *err)
{
    Silhouette *sil = calloc(1, sizeof *sil);
    if (!sil || !(sil->objects = calloc((size_t)scene->num_objects + 1, sizeof *sil->objects))) {
        free(sil);
        error_set(err, "out of memory for the silhouette of %d objects", scene->num_objects);
        return NULL;
    }
    memcpy(sil->light, L, sizeof sil->light);
    int cap = 0;
    for (int o = 0; o < scene->num_objects; o++) {
        const Object *ob = &scene->objects[o];
        if (!ob->caster || ob->mesh.num_triangles == 0) continue;
        SilObject *so = &sil->objects[sil->num_objects++];
        so->object = o;
        so->triangles = ob->mesh.num_triangles;
        if (!build_object(&ob->mesh, sil->light, rule, so, sil, &cap)) {
            silhouette_free(sil);
            error_set(err, "out of memory for the edge adjacency of object '%s' (%d triangles)", ob->name,
                      ob->mesh.num_triangles);
            return NULL;
        }
    }
    return sil;
}

/* printf at out + *used, advancing *used (at most to n). */
static void append(char *out, size_t n, size_t *used, const char *fmt, ...) __attribute__((format(printf, 4, 5)));
static void append(char *out, size_t n, size_t *used, const char *fmt, ...)
{
    if (*used >= n) return;
    va_list ap;
    va_start(ap, fmt);
    int k = vsnprintf(out + *used, n - *used, fmt, ap);
    va_end(ap);
    *used = k < 0 ? n : *used + (size_t)k < n ? *used + (size_t)k : n;
}

void silhouette_report(const Silhouette *sil, const Scene *scene, char *out, size_t n)
{
    size_t used = 0;
    out[0] = '\0';
    for (int i = 0; i < sil->num_objects; i++) {
        const SilObject *so = &sil->objects[i];
        if (so->closed && so->degenerate == 0) continue;
        static const char *const what[3] = {"open", "non-manifold", "misoriented"};
        const long counts[3] = {so->open_edges, so->nonmanifold_edges, so->misoriented_edges};
        int parts = 0;
        append(out, n, &used, "%s'%s':", used ? "; " : "", scene->objects[so->object].name);
        for (int k = 0; k < 3; k++)
            if (counts[k]) append(out, n, &used, "%s %ld %s", parts++ ? "," : "", counts[k], what[k]);
        if (parts) append(out, n, &used, " edges");
        if (so->degenerate) append(out, n, &used, "%s %d zero-area triangles skipped", parts ? "," : "", so->degenerate);
    }
}

static size_t sil_bytes(const void *res)
{
    const Silhouette *s = res;
    size_t b = sizeof *s + (size_t)s->num_objects * sizeof *s->objects + (size_t)s->num_edges * sizeof *s->edges;
    for (int i = 0; i < s->num_objects; i++) b += (size_t)s->objects[i].triangles;
    return b;
}

static void sil_destroy(void *res) { silhouette_free(res); }

static const ResourceKind kind_silhouette = {"silhouette", sil_bytes, sil_destroy, RES_FRAME};

typedef struct SilArgs { const Scene *scene; const double *L; SilRule rule; } SilArgs;

static void *build_sil(const void *args, Error *err)
{
    const SilArgs *a = args;
    return silhouette_build_point(a->scene, a->L, a->rule, err);
}

const Silhouette *res_silhouette(ResourceManager *rm, const Scene *scene, int light_index, Error *err)
{
    double L[4];
    light_centre(&scene->lights[light_index], L);
    char desc[160];
    snprintf(desc, sizeof desc, "casters, centre of light %d", light_index + 1);
    return res_silhouette_point(rm, scene, L, SIL_BERGERON, desc, err);
}

const Silhouette *res_silhouette_point(ResourceManager *rm, const Scene *scene, const double L[4], SilRule rule,
                                       const char *desc, Error *err)
{
    Hasher h;
    hash_init(&h);
    hash_str(&h, "silhouette 1");
    hash_u64(&h, scene->hash_casters);
    for (int k = 0; k < 4; k++) hash_f64(&h, L[k]);
    if (rule != SIL_BERGERON) hash_u64(&h, (uint64_t)rule); /* the centre's resource keeps its key */
    uint64_t key = hash_final(&h);
    SilArgs a = {scene, L, rule};
    Silhouette *sil = rm_acquire(rm, &kind_silhouette, key, desc, build_sil, &a, err);
    if (!sil) return NULL;
    sil->key = key;
    char report[512];
    silhouette_report(sil, scene, report, sizeof report);
    if (report[0]) rm_log_note(rm, kind_silhouette.name, key, report); /* the objects that are not closed, by name */
    return sil;
}
