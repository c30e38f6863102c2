/* peeled.c -- depth-peeled layers of a shadow map as keyed resources (peeled.h). */
#include "resources/maps/peeled.h"
#include <stdio.h>
#include "core/hash.h"

static const ResourceKind kind_peeled_layer = {"peeled_layer", shadowmap_bytes, shadowmap_free, RES_FRAME};

typedef struct PeelArgs {
    const Scene *scene;
    const ShadowMap *under; /* layer k - 1 */
    uint64_t key;
} PeelArgs;

static void *build_layer(const void *args, Error *err)
{
    const PeelArgs *a = args;
    return shadowmap_render_behind(a->scene, a->under, a->key, err);
}

const ShadowMap *res_peeled_layer(ResourceManager *rm, const Scene *scene, const ShadowMap *map, int k, Error *err)
{
    if (k < 0 || k >= PEELED_MAX_LAYERS) {
        error_set(err, "peeled layer %d outside [0, %d]", k, PEELED_MAX_LAYERS - 1);
        return NULL;
    }
    if (map->spec.layer != MAP_LAYER_FIRST) {
        error_set(err, "peeled layers start from a map's first layer");
        return NULL;
    }
    if (k == 0) return map;
    const ShadowMap *under = res_peeled_layer(rm, scene, map, k - 1, err);
    if (!under) return NULL;
    Hasher h;
    hash_init(&h);
    hash_str(&h, "peeled layer");
    hash_u64(&h, map->key);
    hash_u64(&h, (uint64_t)k);
    PeelArgs a = {scene, under, hash_final(&h)};
    char desc[160], mk[17];
    hash_hex(map->key, mk);
    snprintf(desc, sizeof desc, "layer %d of map %s (%d x %d^2), peeled behind layer %d", k, mk, map->num_faces,
             map->res, k - 1);
    return rm_acquire(rm, &kind_peeled_layer, a.key, desc, build_layer, &a, err);
}
