/* test_cache.c -- the reference cache: a second run reads the cache (its
 * record says so) and gets identical values; corrupt or truncated entries are
 * detected, reported and recomputed. */
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "fixtures.h"
#include "resources/refcache.h"
#include "test.h"

static const char *const scene_text =
    "return {\n"
    "  camera = { position = {0, 3, 5}, target = {0, 0.4, 0}, width = 64, height = 48 },\n"
    "  lights = { { type = 'sphere', position = {1, 4, 1}, radius = 0.5 } },\n"
    "  objects = { { shape = 'plane', size = {8, 8} }, { shape = 'sphere', radius = 0.5, translate = {0, 0.8, 0} } },\n"
    "}\n";

/* Open a fresh lab (as a new process would) and fetch the reference. */
static bool fetch(const char *cache, Image *copy, RefInfo *info)
{
    Error err;
    Lab *lab = fixture_lab("cache.lua", scene_text);
    if (!lab) return false;
    RefRequest rq = {0, {MEASURE_VISIBILITY, 64, SAMPLING_R2, 1, false}, cache};
    const Reference *ref = res_reference(lab_resources(lab), lab_scene(lab), &rq, info, &err);
    bool ok = ref && image_init(copy, ref->value.width, ref->value.height, ref->value.channels, &err);
    if (ok) memcpy(copy->data, ref->value.data, image_count(copy) * sizeof(float));
    else printf("    %s\n", err.msg);
    lab_close(lab);
    return ok;
}

static bool same(const Image *a, const Image *b)
{
    return image_count(a) == image_count(b) && memcmp(a->data, b->data, image_count(a) * sizeof(float)) == 0;
}

static void flip_byte(const char *path, long offset)
{
    FILE *fp = fopen(path, "r+b");
    if (!fp) return;
    fseek(fp, offset, SEEK_SET);
    int c = fgetc(fp);
    fseek(fp, offset, SEEK_SET);
    fputc(c ^ 0x5a, fp);
    fclose(fp);
}

static long file_size(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 ? (long)st.st_size : -1;
}

TEST(test_cache_second_run_reads_it_and_corruption_is_recomputed)
{
    char cache[1024];
    snprintf(cache, sizeof cache, "%s/cache", test_tmpdir());
    Image first = {0}, again = {0};
    RefInfo info;
    CHECK(fetch(cache, &first, &info));
    CHECK_MSG(info.origin == REF_COMPUTED, "first run: %s", ref_origin_name(info.origin));
    char path[1024];
    snprintf(path, sizeof path, "%s", info.cache_path);
    long size = file_size(path);
    CHECK_MSG(size > 0, "no cache file at %s", path);

    CHECK(fetch(cache, &again, &info));
    CHECK_MSG(info.origin == REF_CACHE_HIT, "second run: %s", ref_origin_name(info.origin));
    CHECK(same(&first, &again));
    image_free(&again);

    const long offsets[] = {0, 20, size / 2, size - 3}; /* magic, header, payload, checksum */
    for (int i = 0; i < 4; i++) {
        flip_byte(path, offsets[i]);
        CHECK(fetch(cache, &again, &info));
        CHECK_MSG(info.origin == REF_CACHE_CORRUPT_RECOMPUTED, "byte %ld flipped: %s", offsets[i],
                  ref_origin_name(info.origin));
        CHECK_MSG(strstr(info.cache_note, "corrupt"), "note: %s", info.cache_note);
        CHECK(same(&first, &again));
        image_free(&again);
    }
    CHECK(truncate(path, size / 3) == 0);
    CHECK(fetch(cache, &again, &info));
    CHECK(info.origin == REF_CACHE_CORRUPT_RECOMPUTED && same(&first, &again));
    image_free(&again);
    CHECK(fetch(cache, &again, &info)); /* the recomputed entry was written back */
    CHECK(info.origin == REF_CACHE_HIT && same(&first, &again));
    image_free(&again);
    image_free(&first);
}

/* A shared light-sample set (--sample-set shared) is its own cache entry:
 * another key than the per-view-sample set's, read back as shared with the
 * same values, which differ from the per-view-sample set's. */
TEST(test_cache_keeps_the_shared_sample_set_apart)
{
    char cache[1024];
    snprintf(cache, sizeof cache, "%s/cache-shared", test_tmpdir());
    Error err;
    RefInfo info[3];
    Image value[3] = {{0}, {0}, {0}};
    bool shared[3] = {false, true, true}, read_shared[3] = {false, false, false};
    for (int k = 0; k < 3; k++) { /* a fresh lab each: the third reads the second's file */
        Lab *lab = fixture_lab("cache.lua", scene_text);
        CHECK(lab);
        RefRequest rq = {0, {MEASURE_VISIBILITY, 64, SAMPLING_R2, 1, shared[k]}, cache};
        const Reference *ref = res_reference(lab_resources(lab), lab_scene(lab), &rq, &info[k], &err);
        CHECK(ref && image_init(&value[k], ref->value.width, ref->value.height, ref->value.channels, &err));
        memcpy(value[k].data, ref->value.data, image_count(&value[k]) * sizeof(float));
        read_shared[k] = ref->params.shared_set;
        lab_close(lab);
    }
    CHECK(info[0].key != info[1].key && info[1].key == info[2].key);
    CHECK(info[2].origin == REF_CACHE_HIT && read_shared[2] && !read_shared[0]);
    CHECK(same(&value[1], &value[2]) && !same(&value[0], &value[1]));
    for (int k = 0; k < 3; k++) image_free(&value[k]);
}
