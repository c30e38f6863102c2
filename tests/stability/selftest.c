/* selftest.c -- the stability suite's own test binary (make test builds it
 * with ASan + UBSan). First it proves the harness catches what it claims to:
 * techniques that are not in the registry and misbehave on purpose (NaN,
 * out of range, crash, hang, heap overflow, leak, wrong limits, a blurred
 * hard shadow, refusals, a float32 limit reached only in f32 arithmetic)
 * must each give the failed row, and light kinds a technique does not handle
 * must give "not applicable". Then it runs the matrix in quick
 * mode for `hard` and the engine's input cases, under the sanitizers.
 * Prints "harness: N passed, N failed", then "sanitized: N passed, N failed". */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "cli/cli.h"
#include "lab/stability.h"

/* ---- techniques that misbehave on purpose ------------------------------------ */

typedef enum Misbehaviour {
    OK_HALF, GIVES_NAN, GIVES_1_5, CRASHES, HANGS, OVERFLOWS, LEAKS, REFUSES, ALWAYS_LIT, ALWAYS_DARK,
    NAN_UNLESS_CAPPED, /* 0.5 while map_res is at most STAB_QUICK_TEXELS, else NaN */
    NAN_NEAR_88,       /* 0.5, but NaN while gain is in (80, 90): exp overflowing float32 */
    NAN_NEAR_88_IN_F32,/* the same, only with precision = f32 (its default is f64) */
    BLURRED_HARD,      /* `hard` blurred by a (2 BLUR_PX + 1)^2 box over the view grid */
    SPARSE_LIT,        /* 0 but 0.6 on every 40th sample: a lit share over 1% with a mean under 0.02 */
    MISBEHAVIOUR_COUNT
} Misbehaviour;

#define BLUR_PX 2

static Misbehaviour current;
static const char *fake_name = "fake"; /* the first fake's name: known limits match techniques by name */
static bool claims_map;                /* the fake declares a shadow_map resource */

/* `hard` with its defaults on every lit candidate, then each one the mean of
 * the lit candidates in the box around it: a fixed penumbra that ignores
 * the light's size. */
static float *blurred_hard(const TechContext *ctx, Error *err)
{
    const Technique *hard = tech_find("hard", err);
    double params[TECH_MAX_PARAMS];
    void *hs = NULL;
    if (!hard) return NULL;
    tech_params_default(hard, params);
    TechContext hctx = *ctx;
    hctx.params = params;
    int w = ctx->vs->width, h = ctx->vs->height, nc = ctx->channels;
    float *v = malloc(sizeof *v * (size_t)ctx->vs->count * (size_t)nc);
    float *out = malloc(sizeof *out * (size_t)ctx->vs->count * (size_t)nc);
    if (!v || !out || !hard->prepare(&hctx, &hs, err)) {
        free(v);
        free(out);
        return NULL;
    }
    hard->evaluate(hs, &hctx, 0, ctx->vs->count, v);
    hard->release(hs);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < nc; c++) {
                double sum = 0;
                int n = 0;
                for (int t = y - BLUR_PX; t <= y + BLUR_PX; t++)
                    for (int u = x - BLUR_PX; u <= x + BLUR_PX; u++) {
                        if (t < 0 || t >= h || u < 0 || u >= w || ctx->cls[t * w + u] != SAMPLE_LIT_CANDIDATE) continue;
                        sum += v[(size_t)(t * w + u) * (size_t)nc + (size_t)c];
                        n++;
                    }
                out[(size_t)(y * w + x) * (size_t)nc + (size_t)c] = n ? (float)(sum / n) : 1.0f;
            }
    free(v);
    return out;
}

static bool fake_prepare(const TechContext *ctx, void **state, Error *err)
{
    *state = NULL;
    if (current == BLURRED_HARD) return (*state = blurred_hard(ctx, err)) != NULL;
    if (current == REFUSES) return error_set(err, "this technique refuses every scene");
    if (current == HANGS)
        for (volatile int spin = 1; spin;) {
        }
    if (current == LEAKS) {
        void *volatile lost = malloc(4096); /* never freed: LeakSanitizer's report at exit */
        (void)lost;
    }
    return true;
}

static void fake_evaluate(const void *state, const TechContext *ctx, int begin, int end, float *out)
{
    const float *blurred = state;
    static const float values[MISBEHAVIOUR_COUNT] = {
        [OK_HALF] = 0.5f, [GIVES_1_5] = 1.5f, [ALWAYS_LIT] = 1.0f, [ALWAYS_DARK] = 0.0f,
        [NAN_UNLESS_CAPPED] = 0.5f, [NAN_NEAR_88] = 0.5f, [NAN_NEAR_88_IN_F32] = 0.5f};
    bool capped = ctx->params[2] <= STAB_QUICK_TEXELS, near_88 = ctx->params[3] > 80 && ctx->params[3] < 90;
    bool f32 = ctx->params[4] == 1.0;
    for (int s = begin; s < end; s++) {
        bool nan = current == GIVES_NAN || (current == NAN_UNLESS_CAPPED && !capped) ||
                   (current == NAN_NEAR_88 && near_88) || (current == NAN_NEAR_88_IN_F32 && near_88 && f32);
        float v = nan ? NAN : current == SPARSE_LIT ? (s % 40 ? 0.0f : 0.6f) : values[current];
        if (current == CRASHES) raise(SIGSEGV);
        if (current == OVERFLOWS) {
            volatile char *p = malloc(8);
            p[8] = 1; /* one past the end: AddressSanitizer's report */
            free((void *)p);
        }
        for (int c = 0; c < ctx->channels; c++)
            out[(size_t)(s - begin) * (size_t)ctx->channels + (size_t)c] =
                blurred ? blurred[(size_t)s * (size_t)ctx->channels + (size_t)c] : v;
    }
}

static const char *const fake_precisions[] = {"f64", "f32", NULL};
static const ParamDesc fake_params[] = {
    {"weight", PARAM_FLOAT, 0.5, 0.0, 1.0, "", "a float parameter", NULL},
    {"taps", PARAM_INT, 4, 1, 64, "texels", "an int parameter", NULL},
    {"map_res", PARAM_INT, 1024, 1, 4096, "texels", "a map resolution (capped in quick runs)", NULL},
    {"gain", PARAM_FLOAT, 1, 0, 100, "", "an exponent, probed at float32's limits", NULL},
    {"precision", PARAM_ENUM, 0, 0, 1, "", "arithmetic of the maps", fake_precisions},
};
static const char *const no_resources[] = {NULL};
static const char *const map_resources[] = {"shadow_map", NULL};

static Technique fake(const char *name, unsigned lights)
{
    return (Technique){.name = name, .family = "test", .source = "selftest", .summary = "misbehaves on purpose",
                       .params = fake_params, .num_params = 5, .resources = claims_map ? map_resources : no_resources, .rgb = true,
                       .lights = lights, .prepare = fake_prepare, .evaluate = fake_evaluate, .release = free};
}

/* ---- running one case ---------------------------------------------------------- */

static int passed, failed;

typedef struct Collected { StabResult rows[64]; int n; } Collected;

static void collect(const StabResult *r, void *user)
{
    Collected *c = user;
    if (c->n < 64) c->rows[c->n++] = *r;
}

static void report(const char *name, bool ok, const Collected *c)
{
    printf("%s %s\n", ok ? "ok  " : "FAIL", name);
    for (int i = 0; !ok && i < c->n; i++)
        printf("    %s %s %s[%s] prep %.6f s: %s\n", stab_status_name(c->rows[i].status), c->rows[i].technique,
               c->rows[i].case_name, c->rows[i].light, c->rows[i].prep_seconds, c->rows[i].detail);
    fflush(stdout);
    ok ? passed++ : failed++;
}

/* `copies` fake techniques, two runs at once. */
static Collected run(Misbehaviour m, unsigned lights, const char *only, int copies)
{
    current = m;
    Technique t[2] = {fake(fake_name, lights), fake("fake2", lights)};
    const Technique *list[2] = {&t[0], &t[1]};
    char work[] = "/tmp/shadowlab-selftest-XXXXXX";
    Collected c = {.n = 0};
    if (!mkdtemp(work)) return c;
    StabOptions o = {.quick = true, .timeout_s = 5.0, .threads = 1, .only = only, .work_dir = work, .jobs = 2};
    Error err;
    if (!stab_run(list, copies, false, &o, collect, &c, &err)) printf("    stab_run: %s\n", err.msg);
    rmdir(work);
    return c;
}

/* Every row of the run has `status` and its detail contains `word`. */
static void expect(const char *name, Misbehaviour m, unsigned lights, const char *only, StabStatus status,
                   const char *word)
{
    Collected c = run(m, lights, only, 1);
    bool ok = c.n > 0;
    for (int i = 0; ok && i < c.n; i++)
        ok = c.rows[i].status == status && (!word || strstr(c.rows[i].detail, word));
    report(name, ok, &c);
    if (!ok) printf("    expected %s with '%s'\n", stab_status_name(status), word ? word : "");
}

/* Two techniques on one case: each light kind's rows come from one shared
 * preparation (the same prep_seconds, to the bit) and each ran on its own. */
static void expect_shared_preparation(void)
{
    Collected c = run(OK_HALF, LIGHTS_ALL, "contact", 2);
    bool ok = c.n == 4;
    for (int i = 0; ok && i < c.n; i++)
        for (int k = 0; k < c.n; k++)
            if (!strcmp(c.rows[i].light, c.rows[k].light))
                ok = ok && c.rows[i].status == STAB_PASS && c.rows[i].prep_seconds == c.rows[k].prep_seconds &&
                     c.rows[i].prep_seconds > 0 && (i == k || strcmp(c.rows[i].technique, c.rows[k].technique));
    report("harness_runs_share_the_case_preparation", ok, &c);
}

/* --case with a list and an exclusion: "contact,coplanar,!contact" runs
 * coplanar_caster alone; "!a" alone keeps everything else. */
static void expect_case_filter(void)
{
    Collected c = run(OK_HALF, LIGHTS_ALL, "contact,coplanar,!contact", 1);
    bool ok = c.n > 0;
    for (int i = 0; ok && i < c.n; i++) ok = !strcmp(c.rows[i].case_name, "coplanar_caster");
    report("harness_case_filter_takes_a_list_and_exclusions", ok, &c);
}

static void selftests(void)
{
    const unsigned all = LIGHTS_ALL, spot = LIGHT_BIT(LIGHT_SPOT);
    expect("harness_passes_a_well_behaved_technique", OK_HALF, all, "contact", STAB_PASS, NULL);
    expect("harness_counts_nan_outputs", GIVES_NAN, all, "contact", STAB_FAIL, "non-finite");
    expect("harness_counts_out_of_range_outputs", GIVES_1_5, all, "contact", STAB_FAIL, "out-of-range");
    expect("harness_reports_a_crash", CRASHES, all, "contact", STAB_FAIL, "crashed");
    expect("harness_reports_a_hang", HANGS, all, "contact", STAB_FAIL, "no result within");
    expect("harness_reports_a_sanitizer_error", OVERFLOWS, all, "contact", STAB_FAIL, "sanitizer report");
    expect("harness_reports_a_leak", LEAKS, all, "contact", STAB_FAIL, "LeakSanitizer");
    expect("harness_fails_an_unexpected_refusal", REFUSES, all, "contact", STAB_FAIL, "refuses every scene");
    expect("harness_allows_a_refusal_where_documented", REFUSES, all, "light_inside_occluder", STAB_PASS, "allowed");
    expect("harness_checks_the_hard_limit", ALWAYS_LIT, LIGHT_BIT(LIGHT_SPHERE), "light_size_1e-6", STAB_FAIL,
           "over the hard shadow's band");
    expect("harness_marks_unhandled_lights_not_applicable", OK_HALF, spot, "light_size_1e-6", STAB_NOT_APPLICABLE,
           "handles spot");
    expect("harness_params_at_bounds_render", OK_HALF, all, "param_taps_m", STAB_PASS, "taps = ");
    expect("harness_params_outside_are_refused_with_range", OK_HALF, all, "param_weight_above", STAB_PASS, NULL);
    expect("harness_nonfinite_params_are_refused", OK_HALF, all, "param_taps_nonfinite", STAB_PASS, NULL);
    expect("harness_quick_merges_a_parameters_probes", OK_HALF, all, "param_taps", STAB_PASS, "taps = 64");
    expect("harness_merged_probes_name_the_failing_one", GIVES_NAN, all, "param_weight", STAB_FAIL, "min: ");
    expect("harness_quick_caps_map_sizes", NAN_UNLESS_CAPPED, all, "contact", STAB_PASS, NULL);
    expect("harness_quick_probes_the_cap_itself", NAN_UNLESS_CAPPED, all, "param_map_res", STAB_FAIL, "max: ");
    expect("harness_probes_float32_exp_limits", NAN_NEAR_88, all, "param_gain_at_88", STAB_FAIL, "non-finite");
    expect("harness_quick_probes_float32_exp_limits", NAN_NEAR_88, all, "param_gain", STAB_FAIL, "at_88.72: ");
    expect("harness_float32_probes_run_in_f32", NAN_NEAR_88_IN_F32, all, "param_gain_at_88", STAB_FAIL, "non-finite");
    expect("harness_checks_the_umbra_limit", ALWAYS_LIT, LIGHT_BIT(LIGHT_POINT), "light_inside_occluder", STAB_FAIL,
           "leaks out of the closed box");
    /* Measured: band RMSE 0.242 (limit 0.2); over every lit sample it had
     * passed the limit's old form (MAE 0.018 <= 0.02, 0.25% misclassified). */
    expect("harness_checks_the_hard_limit_where_the_shadow_is", BLURRED_HARD, LIGHT_BIT(LIGHT_SPHERE),
           "light_size_1e-6", STAB_FAIL, "over the hard shadow's band");
    /* sm under a one-sided area light misses that limit in both its
     * quantities for a stated reason (stability_cases.c): known, and a
     * failure once the limit holds or where it misses another set of
     * quantities; a technique no entry names is never known. */
    const unsigned rect = LIGHT_BIT(LIGHT_RECT);
    fake_name = "sm";
    expect("harness_reports_a_known_limitation", ALWAYS_LIT, rect, "light_inside_occluder", STAB_KNOWN,
           "known limitation: a one-sided area light's map");
    expect("harness_fails_a_known_limitation_that_holds", ALWAYS_DARK, rect, "light_inside_occluder", STAB_FAIL,
           "meets the limit it is listed as missing");
    expect("harness_fails_a_known_limitation_missing_other_quantities", SPARSE_LIT, rect, "light_inside_occluder",
           STAB_FAIL, "misses umbra lit where its known-limit entry lists umbra leak and umbra lit");
    fake_name = "fake";
    claims_map = true; /* a map technique no entry names: once every one was known here */
    expect("harness_known_limitations_name_their_technique", ALWAYS_LIT, rect, "light_inside_occluder", STAB_FAIL,
           "leaks out of the closed box");
    claims_map = false;
    expect_shared_preparation();
    expect_case_filter();
}

/* The engine under the sanitizers on every extreme case: `hard` (the
 * ray-traced limit, little code of its own) and the input cases. The
 * registry's whole matrix runs from tests/run.sh, on the optimised build and
 * on shadowlab_san (every case but image_4096x4096). */
static int sanitized, sanitized_failed;

static void print_row(const StabResult *r, void *user)
{
    (void)user;
    printf("%-4s %-6s %-34s %-13s %6.2f s  %s\n", stab_status_name(r->status), r->technique, r->case_name, r->light,
           r->seconds, r->detail);
    fflush(stdout);
    if (r->status == STAB_PASS) sanitized++;
    else if (r->status == STAB_FAIL) sanitized_failed++;
}

int main(void)
{
    selftests();
    printf("harness: %d passed, %d failed\n", passed, failed);
    fflush(stdout);
    Error err;
    const Technique *hard = tech_find("hard", &err);
    char work[] = "/tmp/shadowlab-sanitized-XXXXXX";
    StabOptions o = {.quick = true, .threads = 1, .work_dir = work, .jobs = 2};
    bool ran = hard && mkdtemp(work) && stab_run(&hard, 1, true, &o, print_row, NULL, &err);
    if (!ran) printf("    %s\n", err.msg);
    rmdir(work);
    printf("sanitized: %d passed, %d failed\n", sanitized, sanitized_failed + !ran);
    return failed || sanitized_failed || !ran ? 1 : 0;
}
