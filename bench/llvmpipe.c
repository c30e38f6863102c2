/* llvmpipe.c -- shadowlab's rasterizer and PCF against Mesa's llvmpipe (issue
 * 8, item 2), in one process, the same thread count on both sides
 * (LP_NUM_THREADS = OpenMP threads = N).
 *   depth: the same depth-only shadow map of the scene's casters (the
 *     engine's fitted light view, z_ndc in [0, 1], no culling, nearest test)
 *     at each --res: raster_depth against glDrawElements into a
 *     GL_DEPTH_COMPONENT32F target with an empty fragment shader; vertices
 *     stay in GL buffers (uploaded once), so both sides transform, clip,
 *     bin and fill.
 *   pcf: a K x K box PCF pass over the view samples at the scene's camera
 *     size (1920x1080 by default): the `pcf` technique's evaluation against
 *     a full-screen fragment shader with a depth-compare sampler
 *     (sampler2DShadow, GL_LEQUAL, nearest) reading the same map and the
 *     same positions and normals, with the same lookup (lifted by
 *     rt_ray_offset, constant bias in float32 depth steps).
 * One untimed warm-up round (shader JIT, page faults), then rounds that
 * alternate the two sides; the figure is the median of the per-round
 * ratios llvmpipe / shadowlab (> 1: shadowlab is faster). The last round's
 * outputs are compared: coverage and depth per texel, visibility per lit
 * sample. Rows go to DIR/llvmpipe_depth.csv and DIR/llvmpipe_pcf.csv.
 * Usage: llvmpipe [--res R]... [--pcf K]... [--pcf-map R] [--threads N]
 *                 [--repeat R] [-o DIR] SCENE... */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#if defined(__SSE2__)
#include <immintrin.h>
#endif
#include "bench.h"
#include "core/bufpool.h"
#include "core/timer.h"
#include "gl_context.h"

#define MAX_ITEMS 8
#define MAX_MESHES 64
/* A float32 depth step at the receiver times this is the PCF pass's bias
 * (smap.c's bias_steps; 2000 steps is ~2.4e-4 at z_ndc = 1). */
#define PCF_BIAS_STEPS 2000.0
#define DEPTH_TOLERANCE 1e-5 /* z_ndc: float32 transforms on one side, double on the other */

#define DEPTH_HEADER                                                                                              \
    "scene,triangles,res,llvmpipe_ms,shadowlab_ms,speedup,fill_ms,vs_fill,empty_ms,empty_vs_fill,store_fill_ms,"     \
    "stream_fill_ms,texels_covered,"                                                                            \
    "coverage_mismatch,"                                                                                          \
    "depth_mismatch,max_depth_diff,agree,renderer," BENCH_TAIL_HEADER "\n"
#define PCF_HEADER                                                                                              \
    "scene,width,height,map_res,K,candidates,llvmpipe_ms,shadowlab_ms,speedup,mae,samples_off,agree,renderer," \
    BENCH_TAIL_HEADER "\n"

typedef struct Options {
    BenchCommon c;
    int res[MAX_ITEMS], num_res, K[MAX_ITEMS], num_K;
    int pcf_map, width, height;
} Options;

/* The scene's casters: as the rasterizer reads them, and in GL buffers. */
typedef struct Casters {
    RasterMesh mesh[MAX_MESHES];
    int num_meshes;
    long triangles;
    GLuint vao, vbo, ibo, program;
    GLint u_clip;
} Casters;

/* ---- options ------------------------------------------------------------- */

static bool add_item(int *list, int *n, const char *v, int lo, int hi)
{
    return *n < MAX_ITEMS && bench_parse_int(v, lo, hi, &list[(*n)++]);
}

static int own_option(void *options, const char *a, const char *v)
{
    Options *o = options;
    bool ok = false;
    if (strcmp(a, "--res") == 0) ok = add_item(o->res, &o->num_res, v, 16, 8192);
    else if (strcmp(a, "--pcf") == 0) ok = add_item(o->K, &o->num_K, v, 1, 63);
    else if (strcmp(a, "--pcf-map") == 0) ok = bench_parse_int(v, 16, 8192, &o->pcf_map);
    return ok ? 2 : 0;
}

static bool parse_options(int argc, char **argv, Options *o)
{
    *o = (Options){.pcf_map = 2048, .width = 1920, .height = 1080};
    return bench_parse(argc, argv, 5, &o->c, own_option, o) && o->c.num_scenes > 0;
}

/* ---- the casters in both forms --------------------------------------------- */

static const char *const depth_vs =
    "#version 450 core\n"
    "layout(location = 0) in vec3 p_world;\n"
    "uniform mat4 clip_from_world;\n"
    "void main() { gl_Position = clip_from_world * vec4(p_world, 1.0); }\n";
static const char *const depth_fs = "#version 450 core\nvoid main() {}\n";

static bool casters_init(Casters *c, const Scene *sc, Error *err)
{
    memset(c, 0, sizeof *c);
    c->num_meshes = bench_casters(sc, c->mesh, MAX_MESHES, &c->triangles);
    if (c->num_meshes < 0) return error_set(err, "more than %d caster objects", MAX_MESHES);
    long verts = 0;
    for (int m = 0; m < c->num_meshes; m++) verts += c->mesh[m].num_vertices;
    uint32_t *idx = malloc(sizeof *idx * (size_t)(3 * c->triangles + 1));
    if (!idx) return error_set(err, "out of memory");
    glGenVertexArrays(1, &c->vao);
    glBindVertexArray(c->vao);
    glGenBuffers(1, &c->vbo);
    glBindBuffer(GL_ARRAY_BUFFER, c->vbo);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(sizeof(vec3) * (size_t)verts), NULL, GL_STATIC_DRAW);
    long vbase = 0, ibase = 0;
    for (int m = 0; m < c->num_meshes; m++) { /* one buffer: indices rebased per mesh */
        const RasterMesh *rm = &c->mesh[m];
        glBufferSubData(GL_ARRAY_BUFFER, (GLintptr)(sizeof(vec3) * (size_t)vbase),
                        (GLsizeiptr)(sizeof(vec3) * (size_t)rm->num_vertices), rm->positions);
        for (long k = 0; k < 3L * rm->num_triangles; k++) idx[ibase + k] = rm->indices[k] + (uint32_t)vbase;
        vbase += rm->num_vertices;
        ibase += 3L * rm->num_triangles;
    }
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(vec3), NULL);
    glEnableVertexAttribArray(0);
    glGenBuffers(1, &c->ibo);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, c->ibo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(sizeof *idx * (size_t)(3 * c->triangles)), idx, GL_STATIC_DRAW);
    free(idx);
    c->program = gl_program(depth_vs, depth_fs, err);
    if (!c->program) return false;
    c->u_clip = glGetUniformLocation(c->program, "clip_from_world");
    return gl_check("uploading the casters", err);
}

static void casters_free(Casters *c)
{
    glDeleteProgram(c->program);
    glDeleteBuffers(1, &c->vbo);
    glDeleteBuffers(1, &c->ibo);
    glDeleteVertexArrays(1, &c->vao);
}

/* mat4 is row-major doubles: GL takes it transposed, as floats. */
static void gl_matrix(const mat4 *m, float out[16])
{
    for (int r = 0; r < 4; r++)
        for (int k = 0; k < 4; k++) out[r * 4 + k] = (float)m->m[r][k];
}

/* ---- depth maps ---------------------------------------------------------- */

/* The per-round figures beside the two renders, in the order of the
 * medians write_depth_row takes after its first three. */
enum { ROUND_FILL, ROUND_VS_FILL, ROUND_EMPTY, ROUND_EMPTY_VS_FILL, ROUND_STORE, ROUND_STREAM, ROUND_COLUMNS };

typedef struct DepthRun {
    const Casters *c;
    const GlTarget *target;
    const RasterView *view;
    RasterOptions opt;
    DepthBuffer db;
    /* The memory-write limit, timed in the same rounds: the map's bytes
     * stored once by the same threads, with ordinary stores (store_s) and
     * with non-temporal ones (stream_s), the faster of the two the fill
     * (fill_s), and per round shadowlab's time over it; and the
     * rasterizer's own floor, a render of no triangles into a map of the
     * same size (empty: every tile stores its empty rows), over the fill;
     * round 0 is the warm-up. */
    float *fill;
    double *per_round; /* ROUND_COLUMNS blocks of max_rounds, column c of round k at c * max_rounds + k */
    DepthBuffer empty;
    int rounds, max_rounds;
} DepthRun;

static void gl_depth_draw(void *arg)
{
    const DepthRun *r = arg;
    float m[16];
    gl_matrix(&r->view->clip_from_world, m);
    glBindFramebuffer(GL_FRAMEBUFFER, r->target->fbo);
    glViewport(0, 0, r->target->width, r->target->height);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_CULL_FACE);
    glClearDepth(1.0);
    glClear(GL_DEPTH_BUFFER_BIT);
    glUseProgram(r->c->program);
    glUniformMatrix4fv(r->c->u_clip, 1, GL_TRUE, m);
    glBindVertexArray(r->c->vao);
    glDrawElements(GL_TRIANGLES, (GLsizei)(3 * r->c->triangles), GL_UNSIGNED_INT, NULL);
}

typedef struct DepthAgreement {
    long covered, coverage_mismatch, depth_mismatch;
    double max_diff;
} DepthAgreement;

/* GL's cleared 1.0 is the engine's +INFINITY (empty). */
static DepthAgreement compare_depth(const DepthBuffer *db, const float *gl_depth)
{
    DepthAgreement a = {0};
    for (size_t i = 0; i < (size_t)db->width * db->height; i++) {
        bool ours = isfinite(db->depth[i]), theirs = gl_depth[i] < 1.0f;
        a.covered += ours;
        if (ours != theirs) { a.coverage_mismatch++; continue; }
        if (!ours) continue;
        double d = fabs((double)db->depth[i] - gl_depth[i]);
        a.depth_mismatch += d > DEPTH_TOLERANCE;
        if (d > a.max_diff) a.max_diff = d;
    }
    return a;
}

/* Edge texels may go either way (float32 vertices on one side, doubles on the
 * other, and llvmpipe's own snapping); a thousandth of the map may differ. */
static bool depth_agrees(const DepthAgreement *a)
{
    double n = a->covered > 0 ? (double)a->covered : 1.0;
    return a->coverage_mismatch / n < 1e-3 && a->depth_mismatch / n < 1e-3;
}

/* Every texel of a map stored once (the empty value, +INFINITY) by the
 * OpenMP threads in a static split: with ordinary stores, which the
 * compiler turns into vector stores (each line is read for ownership
 * first), or, where `stream`, with non-temporal ones (the lines go to
 * memory unread, as the rasterizer stores maps over
 * RASTER_STREAM_MIN_BYTES). The faster of the two is what writing the
 * map's bytes costs at the least. d is on a cache line (bufpool_alloc);
 * each thread's part starts on one. */
static double fill_timed(float *d, size_t n, bool stream)
{
    double t0 = timer_now_s();
#pragma omp parallel
    {
        size_t nt = (size_t)omp_get_num_threads(), id = (size_t)omp_get_thread_num();
        size_t line = BUFPOOL_ALIGN / sizeof *d; /* floats per cache line */
        size_t lo = (n / line * id / nt) * line, hi = id + 1 == nt ? n : (n / line * (id + 1) / nt) * line, i = lo;
#if defined(__SSE2__)
        if (stream) {
            __m128 empty = _mm_set1_ps(INFINITY);
            for (; i + 4 <= hi; i += 4) _mm_stream_ps(d + i, empty);
            _mm_sfence();
        }
#endif
        for (; i < hi; i++) d[i] = INFINITY;
    }
    double s = timer_now_s() - t0;
    volatile float keep = d[n / 2]; /* the stores are read: not dead */
    (void)keep;
    return s;
}

/* Two renders of `num_meshes` meshes into db back to back, the second
 * timed (*s). */
static bool raster_twice_timed(const DepthRun *r, const RasterMesh *meshes, int num_meshes, DepthBuffer *db, double *s,
                               Error *err)
{
    bool ok = true;
    for (int k = 0; ok && k < 2; k++) {
        double t0 = timer_now_s();
        ok = raster_depth(meshes, num_meshes, r->view, &r->opt, db, NULL, err);
        *s = timer_now_s() - t0;
    }
    return ok;
}

/* One round: each side draws twice back to back and the second draw is
 * timed, so both run with warm caches and awake threads rather than
 * inheriting the other's cache state and sleeping worker pool; then the
 * fill of the map's bytes and the render of no triangles, the same way. */
static bool depth_round(void *run, double *gl_s, double *ours_s, Error *err)
{
    DepthRun *r = run;
    for (int k = 0; k < 2; k++) *gl_s = gl_timed(gl_depth_draw, r);
    bool ok = raster_twice_timed(r, r->c->mesh, r->c->num_meshes, &r->db, ours_s, err);
    double store_s = 0.0, stream_s = 0.0, empty_s = 0.0;
    size_t n = (size_t)r->db.width * r->db.height;
    for (int k = 0; k < 2; k++) store_s = fill_timed(r->fill, n, false);
    for (int k = 0; k < 2; k++) stream_s = fill_timed(r->fill, n, true);
    double fill_s = store_s < stream_s ? store_s : stream_s;
    ok = ok && raster_twice_timed(r, NULL, 0, &r->empty, &empty_s, err);
    if (r->rounds < r->max_rounds) {
        double *col = r->per_round + r->rounds++;
        int m = r->max_rounds;
        col[ROUND_FILL * m] = fill_s;
        col[ROUND_VS_FILL * m] = fill_s > 0.0 ? *ours_s / fill_s : INFINITY;
        col[ROUND_EMPTY * m] = empty_s;
        col[ROUND_EMPTY_VS_FILL * m] = fill_s > 0.0 ? empty_s / fill_s : INFINITY;
        col[ROUND_STORE * m] = store_s;
        col[ROUND_STREAM * m] = stream_s;
    }
    return ok && gl_check("the depth pass", err);
}

/* med: llvmpipe s, shadowlab s, their ratio, then the rounds' columns
 * (ROUND_FILL ...) from med + 3. */
static bool write_depth_row(const Options *o, const Scene *sc, const Casters *c, int res,
                            const double med[3 + ROUND_COLUMNS], const DepthAgreement *a, const char *renderer,
                            Error *err)
{
    const double *m = med + 3;
    char row[2048], tail[512], name[160], rend[300];
    bench_tail(tail, sizeof tail, o->c.threads);
    bench_csv_field(name, sizeof name, sc->name);
    bench_csv_field(rend, sizeof rend, renderer);
    snprintf(row, sizeof row, "%s,%ld,%d,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%ld,%ld,%ld,%.3g,%s,%s,%s\n",
             name, c->triangles, res, med[0] * 1e3, med[1] * 1e3, med[2], m[ROUND_FILL] * 1e3, m[ROUND_VS_FILL],
             m[ROUND_EMPTY] * 1e3, m[ROUND_EMPTY_VS_FILL], m[ROUND_STORE] * 1e3, m[ROUND_STREAM] * 1e3, a->covered,
             a->coverage_mismatch, a->depth_mismatch, a->max_diff, depth_agrees(a) ? "yes" : "no", rend, tail);
    char path[4096];
    snprintf(path, sizeof path, "%s/llvmpipe_depth.csv", o->c.dir);
    printf("  depth %5d^2: llvmpipe %8.2f ms, shadowlab %8.2f ms, speed-up %.2fx; fill %.2f ms (stores %.2f, "
           "non-temporal %.2f), shadowlab / fill %.2f, no triangles / fill %.2f; coverage off %ld, depth off %ld of %ld "
           "(max %.2g)%s\n",
           res, med[0] * 1e3, med[1] * 1e3, med[2], m[ROUND_FILL] * 1e3, m[ROUND_STORE] * 1e3,
           m[ROUND_STREAM] * 1e3, m[ROUND_VS_FILL], m[ROUND_EMPTY_VS_FILL], a->coverage_mismatch, a->depth_mismatch,
           a->covered, a->max_diff, depth_agrees(a) ? "" : "  MISMATCH");
    return bench_csv_append(path, DEPTH_HEADER, row, err);
}

static bool bench_depth(Lab *lab, const Casters *c, const GlContext *gl, const Options *o, int res, Error *err)
{
    const ShadowMap *map = bench_map(lab, res, err);
    if (!map) return false;
    DepthRun r = {.c = c, .view = &map->view.face[0].raster, .opt = {.depth = RASTER_DEPTH_NDC},
                  .max_rounds = o->c.repeat + 1};
    GlTarget target;
    if (!gl_target_init(&target, res, res, GL_DEPTH_COMPONENT32F, err)) return false;
    r.target = &target;
    float *gl_depth = malloc(sizeof *gl_depth * (size_t)res * res);
    r.fill = bufpool_alloc(sizeof *r.fill * (size_t)res * res);
    r.per_round = malloc(sizeof *r.per_round * ROUND_COLUMNS * (size_t)r.max_rounds);
    double med[3 + ROUND_COLUMNS];
    bool ok = (gl_depth && r.fill && r.per_round) || error_set(err, "out of memory");
    ok = ok && depth_buffer_init(&r.db, res, res, false, err) && depth_buffer_init(&r.empty, res, res, false, err) &&
         bench_paired(depth_round, &r, o->c.repeat, med, err);
    if (ok) {
        for (int c = 0; c < ROUND_COLUMNS; c++) /* round 0: the warm-up */
            med[3 + c] = r.rounds > 1 ? bench_median(r.per_round + c * r.max_rounds + 1, r.rounds - 1) : NAN;
        glBindFramebuffer(GL_FRAMEBUFFER, target.fbo);
        glPixelStorei(GL_PACK_ALIGNMENT, 4);
        glReadPixels(0, 0, res, res, GL_DEPTH_COMPONENT, GL_FLOAT, gl_depth);
        DepthAgreement a = compare_depth(&r.db, gl_depth);
        ok = gl_check("reading the depth back", err) &&
             write_depth_row(o, lab_scene(lab), c, res, med, &a, gl_context_renderer(gl), err);
    }
    free(gl_depth);
    bufpool_free(r.fill);
    free(r.per_round);
    depth_buffer_free(&r.db);
    depth_buffer_free(&r.empty);
    gl_target_free(&target);
    return ok;
}

/* ---- PCF ------------------------------------------------------------------ */

static const char *const pcf_vs =
    "#version 450 core\n"
    "void main() {\n" /* one triangle over the whole target */
    "  vec2 p = vec2((gl_VertexID & 1) * 4.0 - 1.0, (gl_VertexID >> 1) * 4.0 - 1.0);\n"
    "  gl_Position = vec4(p, 0.0, 1.0);\n"
    "}\n";
/* smap_receiver with depth = ndc, bias_steps = B and no other bias, then
 * pcf.c's filter_box: lift by rt_ray_offset, locate, K x K nearest taps from
 * floor(s - K/2 + 1/2), lit unless ref > stored (GL_LEQUAL passes ties). */
static const char *const pcf_fs =
    "#version 450 core\n"
    "uniform sampler2DShadow shadow_map;\n"
    "uniform sampler2D p_tex, n_tex;\n"
    "uniform mat4 clip_from_world;\n"
    "uniform float res, extent, bias_steps;\n"
    "uniform int K;\n"
    "out float visibility;\n"
    "const float FLT_EPS = 1.1920929e-7;\n"
    "void main() {\n"
    "  ivec2 px = ivec2(gl_FragCoord.xy);\n"
    "  vec4 n = texelFetch(n_tex, px, 0);\n"
    "  visibility = 1.0;\n"
    "  if (n.w == 0.0) return;\n" /* not a lit candidate */
    "  vec3 p = texelFetch(p_tex, px, 0).xyz;\n"
    "  float lift = 1e-5 * extent + 128.0 * FLT_EPS * max(max(abs(p.x), abs(p.y)), abs(p.z));\n"
    "  vec4 c = clip_from_world * vec4(p + n.xyz * lift, 1.0);\n"
    "  if (!(c.w > 0.0)) return;\n"
    "  vec3 q = c.xyz / c.w;\n"
    "  float s = (q.x + 1.0) * 0.5 * res, t = (q.y + 1.0) * 0.5 * res;\n"
    "  if (s < 0.0 || s >= res || t < 0.0 || t >= res || q.z < 0.0 || q.z > 1.0) return;\n"
    "  float ref = q.z - bias_steps * max(abs(q.z), 1.17549435e-38) * FLT_EPS;\n"
    "  int i0 = int(floor(s - 0.5 * float(K) + 0.5)), j0 = int(floor(t - 0.5 * float(K) + 0.5));\n"
    "  float lit = 0.0;\n"
    "  for (int j = 0; j < K; j++)\n"
    "    for (int i = 0; i < K; i++)\n"
    "      lit += texture(shadow_map, vec3((float(i0 + i) + 0.5) / res, (float(j0 + j) + 0.5) / res, ref));\n"
    "  visibility = lit / float(K * K);\n"
    "}\n";

typedef struct PcfGl {
    GLuint program, vao, map_tex, p_tex, n_tex;
    GlTarget target;
    GLint u_K;
} PcfGl;

static GLuint texture_2d(GLenum internal, int w, int h, GLenum format, GLenum type, const void *data, GLenum filter)
{
    GLuint tex;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexStorage2D(GL_TEXTURE_2D, 1, internal, w, h);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, format, type, data);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return tex;
}

/* Positions, and normals with w = 1 on the light's lit candidates. */
static bool upload_samples(PcfGl *g, const ViewSamples *vs, const uint8_t *cls, Error *err)
{
    float *p = malloc(sizeof *p * 4 * (size_t)vs->count), *n = malloc(sizeof *n * 4 * (size_t)vs->count);
    if (!p || !n) { free(p); free(n); return error_set(err, "out of memory"); }
    for (int s = 0; s < vs->count; s++) {
        vec3 a = vs->p_world[s], b = vs->n_geom_world[s];
        memcpy(p + 4 * s, (float[4]){a.x, a.y, a.z, 1.0f}, sizeof(float[4]));
        memcpy(n + 4 * s, (float[4]){b.x, b.y, b.z, cls[s] == SAMPLE_LIT_CANDIDATE}, sizeof(float[4]));
    }
    g->p_tex = texture_2d(GL_RGBA32F, vs->width, vs->height, GL_RGBA, GL_FLOAT, p, GL_NEAREST);
    g->n_tex = texture_2d(GL_RGBA32F, vs->width, vs->height, GL_RGBA, GL_FLOAT, n, GL_NEAREST);
    free(p);
    free(n);
    return gl_check("uploading the view samples", err);
}

static bool pcf_gl_init(PcfGl *g, const ShadowMap *map, const ViewSamples *vs, const uint8_t *cls, float extent,
                        Error *err)
{
    memset(g, 0, sizeof *g);
    g->program = gl_program(pcf_vs, pcf_fs, err);
    if (!g->program || !upload_samples(g, vs, cls, err)) return false;
    g->map_tex = texture_2d(GL_DEPTH_COMPONENT32F, map->res, map->res, GL_DEPTH_COMPONENT, GL_FLOAT, map->depth,
                            GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    glGenVertexArrays(1, &g->vao);
    float m[16];
    gl_matrix(&map->view.face[0].raster.clip_from_world, m);
    glUseProgram(g->program);
    glUniformMatrix4fv(glGetUniformLocation(g->program, "clip_from_world"), 1, GL_TRUE, m);
    glUniform1f(glGetUniformLocation(g->program, "res"), (float)map->res);
    glUniform1f(glGetUniformLocation(g->program, "extent"), extent);
    glUniform1f(glGetUniformLocation(g->program, "bias_steps"), (float)PCF_BIAS_STEPS);
    glUniform1i(glGetUniformLocation(g->program, "shadow_map"), 0);
    glUniform1i(glGetUniformLocation(g->program, "p_tex"), 1);
    glUniform1i(glGetUniformLocation(g->program, "n_tex"), 2);
    g->u_K = glGetUniformLocation(g->program, "K");
    return gl_target_init(&g->target, vs->width, vs->height, GL_R32F, err);
}

static void pcf_gl_free(PcfGl *g)
{
    GLuint tex[3] = {g->map_tex, g->p_tex, g->n_tex};
    glDeleteTextures(3, tex);
    glDeleteVertexArrays(1, &g->vao);
    glDeleteProgram(g->program);
    gl_target_free(&g->target);
}

typedef struct PcfRun {
    Lab *lab;
    PcfGl *g;
    int K;
    RenderRequest req;
    double params[TECH_MAX_PARAMS];
    RenderResult last;
} PcfRun;

static void gl_pcf_draw(void *arg)
{
    const PcfRun *r = arg;
    const PcfGl *g = r->g;
    glBindFramebuffer(GL_FRAMEBUFFER, g->target.fbo);
    glViewport(0, 0, g->target.width, g->target.height);
    glDisable(GL_DEPTH_TEST);
    glUseProgram(g->program);
    glUniform1i(g->u_K, r->K);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, g->map_tex);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, g->p_tex);
    glActiveTexture(GL_TEXTURE2);
    glBindTexture(GL_TEXTURE_2D, g->n_tex);
    glBindVertexArray(g->vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
}

static bool pcf_params(const Options *o, int K, double *params, const Technique **t, Error *err)
{
    char a[6][64];
    snprintf(a[0], sizeof a[0], "map_size=%d", o->pcf_map);
    snprintf(a[1], sizeof a[1], "K=%d", K);
    snprintf(a[2], sizeof a[2], "bias_steps=%g", PCF_BIAS_STEPS);
    snprintf(a[3], sizeof a[3], "slope_bias=0");
    snprintf(a[4], sizeof a[4], "depth=ndc");
    snprintf(a[5], sizeof a[5], "projection=perspective");
    if (!(*t = tech_find("pcf", err))) return false;
    tech_params_default(*t, params);
    for (int i = 0; i < 6; i++)
        if (!tech_param_parse(*t, a[i], params, err)) return false;
    return tech_param_parse(*t, "kernel=box", params, err);
}

/* The evaluation alone (eval_median_s of one timed evaluation); the
 * untimed first round builds the map and JITs the shader. */
static bool pcf_round(void *run, double *gl_s, double *ours_s, Error *err)
{
    PcfRun *r = run;
    *gl_s = gl_timed(gl_pcf_draw, r);
    render_result_free(&r->last);
    if (!lab_render(r->lab, &r->req, &r->last, err)) return false;
    *ours_s = r->last.eval_median_s;
    return gl_check("the PCF pass", err);
}

typedef struct PcfAgreement {
    long candidates, off;
    double mae;
} PcfAgreement;

/* A sample is off when more than one tap differs (a tap's s or t can round
 * across a texel edge in float32). */
static PcfAgreement compare_pcf(const Image *ours, const float *gl_vis, const uint8_t *cls, int K)
{
    PcfAgreement a = {0};
    double sum = 0.0;
    for (long s = 0; s < (long)ours->width * ours->height; s++) {
        if (cls[s] != SAMPLE_LIT_CANDIDATE) continue;
        double d = fabs((double)ours->data[s * ours->channels] - gl_vis[s]);
        a.candidates++;
        sum += d;
        a.off += d > 1.5 / (K * K);
    }
    a.mae = a.candidates ? sum / a.candidates : 0.0;
    return a;
}

static bool pcf_agrees(const PcfAgreement *a) { return a->off <= a->candidates / 1000 && a->mae < 1e-3; }

static bool write_pcf_row(const Options *o, const Scene *sc, int K, const double med[3], const PcfAgreement *a,
                          const char *renderer, Error *err)
{
    char row[2048], tail[512], name[160], rend[300], path[4096];
    bench_tail(tail, sizeof tail, o->c.threads);
    bench_csv_field(name, sizeof name, sc->name);
    bench_csv_field(rend, sizeof rend, renderer);
    snprintf(row, sizeof row, "%s,%d,%d,%d,%d,%ld,%.3f,%.3f,%.3f,%.3g,%ld,%s,%s,%s\n", name, sc->camera.width,
             sc->camera.height, o->pcf_map, K, a->candidates, med[0] * 1e3, med[1] * 1e3, med[2], a->mae, a->off,
             pcf_agrees(a) ? "yes" : "no", rend, tail);
    printf("  pcf K=%2d at %dx%d: llvmpipe %8.2f ms, shadowlab %8.2f ms, speed-up %.2fx; MAE %.2g, %ld of %ld off%s\n",
           K, sc->camera.width, sc->camera.height, med[0] * 1e3, med[1] * 1e3, med[2], a->mae, a->off, a->candidates,
           pcf_agrees(a) ? "" : "  MISMATCH");
    snprintf(path, sizeof path, "%s/llvmpipe_pcf.csv", o->c.dir);
    return bench_csv_append(path, PCF_HEADER, row, err);
}

static bool bench_pcf_K(PcfRun *r, const Options *o, const uint8_t *cls, const char *renderer, Error *err)
{
    double med[3];
    if (!bench_paired(pcf_round, r, o->c.repeat, med, err)) return false;
    const Scene *sc = lab_scene(r->lab);
    float *gl_vis = malloc(sizeof *gl_vis * (size_t)sc->camera.width * sc->camera.height);
    if (!gl_vis) return error_set(err, "out of memory");
    glBindFramebuffer(GL_FRAMEBUFFER, r->g->target.fbo);
    glReadPixels(0, 0, r->g->target.width, r->g->target.height, GL_RED, GL_FLOAT, gl_vis);
    PcfAgreement a = compare_pcf(&r->last.visibility, gl_vis, cls, r->K);
    free(gl_vis);
    return gl_check("reading the PCF pass back", err) && write_pcf_row(o, sc, r->K, med, &a, renderer, err);
}

static bool bench_pcf(Lab *lab, const GlContext *gl, const Options *o, Error *err)
{
    ResourceManager *rm = lab_resources(lab);
    const Scene *sc = lab_scene(lab);
    const ViewSamples *vs = res_view_samples(rm, sc, err);
    const uint8_t *cls = vs ? res_classes(rm, sc, 0, err) : NULL;
    const ShadowMap *map = cls ? bench_map(lab, o->pcf_map, err) : NULL;
    PcfGl g;
    if (!map || !pcf_gl_init(&g, map, vs, cls, scene_extent(sc), err)) return false;
    bool ok = true;
    for (int k = 0; ok && k < o->num_K; k++) {
        PcfRun r = {.lab = lab, .g = &g, .K = o->K[k]};
        const Technique *t;
        ok = pcf_params(o, o->K[k], r.params, &t, err);
        r.req = (RenderRequest){.tech = t, .params = r.params, .light_index = 0, .repeat = 1};
        ok = ok && bench_pcf_K(&r, o, cls, gl_context_renderer(gl), err);
        render_result_free(&r.last);
    }
    pcf_gl_free(&g);
    return ok;
}

/* ---- driver ---------------------------------------------------------------- */

static bool bench_scene(const char *path, const GlContext *gl, const Options *o, Error *err)
{
    char w[64], h[64];
    snprintf(w, sizeof w, "camera.width=%d", o->width);
    snprintf(h, sizeof h, "camera.height=%d", o->height);
    const char *ov[] = {w, h};
    Lab *lab = lab_open(path, ov, 2, err);
    if (!lab) return false;
    Casters c;
    bool ok = casters_init(&c, lab_scene(lab), err);
    if (ok) printf("%s: %ld caster triangles, %d threads (LP_NUM_THREADS=%d)\n", lab_scene(lab)->name, c.triangles,
                   o->c.threads, o->c.threads);
    for (int i = 0; ok && i < o->num_res; i++) ok = bench_depth(lab, &c, gl, o, o->res[i], err);
    if (ok && o->num_K > 0) ok = bench_pcf(lab, gl, o, err);
    casters_free(&c);
    lab_close(lab);
    return ok;
}

int main(int argc, char **argv)
{
    Options o;
    if (!parse_options(argc, argv, &o))
        return bench_usage("llvmpipe [--res R]... [--pcf K]... [--pcf-map R] [--threads N] [--repeat R] [-o DIR] SCENE...");
    char n[16];
    snprintf(n, sizeof n, "%d", o.c.threads);
    setenv("LP_NUM_THREADS", n, 1); /* read by llvmpipe when the context is created */
    omp_set_num_threads(o.c.threads);
    rt_set_threads(o.c.threads);
    Error err;
    GlContext *gl = gl_context_open(&err);
    bool ok = gl != NULL;
    if (ok) printf("llvmpipe bench: %s\n", gl_context_renderer(gl));
    for (int i = 0; ok && i < o.c.num_scenes; i++) ok = bench_scene(o.c.scenes[i], gl, &o, &err);
    gl_context_close(gl);
    return ok ? 0 : bench_fail("llvmpipe", &err);
}
