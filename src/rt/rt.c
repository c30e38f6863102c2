/* rt.c -- the Embree device and triangle BVHs (see rt.h). Scenes are built
 * with RTC_SCENE_FLAG_ROBUST (watertight traversal: a ground truth must not
 * leak light through shared edges) and high build quality. */
#include "rt/rt.h"
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct RtScene {
    RTCScene scene;
    int *object_of_geom; /* geometry id -> object index */
    int num_geoms;
    size_t bytes;
};

static RTCDevice device;
static int device_threads;
static pthread_mutex_t device_lock = PTHREAD_MUTEX_INITIALIZER;
static char device_error[512];

static void on_embree_error(void *user, enum RTCError code, const char *msg)
{
    (void)user;
    snprintf(device_error, sizeof device_error, "Embree error %d: %s", (int)code, msg ? msg : "");
}

void rt_set_threads(int threads) { device_threads = threads; }

static RTCDevice get_device(Error *err)
{
    pthread_mutex_lock(&device_lock);
    if (!device) {
        char cfg[64] = "";
        if (device_threads > 0) snprintf(cfg, sizeof cfg, "threads=%d", device_threads);
        device = rtcNewDevice(cfg);
        if (device) rtcSetDeviceErrorFunction(device, on_embree_error, NULL);
    }
    pthread_mutex_unlock(&device_lock);
    if (!device) error_set(err, "cannot create the Embree device (error %d)", (int)rtcGetDeviceError(NULL));
    return device;
}

RTCDevice rt_device(Error *err) { return get_device(err); }

static bool add_mesh(RtScene *rs, RTCDevice dev, const Mesh *m, Error *err)
{
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    float *vb = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, sizeof(float) * 3,
                                        (size_t)m->num_vertices);
    unsigned *ib = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, sizeof(unsigned) * 3,
                                           (size_t)m->num_triangles);
    if (!vb || !ib) {
        rtcReleaseGeometry(g);
        return error_set(err, "Embree could not allocate a mesh of %d triangles: %s", m->num_triangles, device_error);
    }
    memcpy(vb, m->positions, sizeof(float) * 3 * (size_t)m->num_vertices);
    memcpy(ib, m->indices, sizeof(unsigned) * 3 * (size_t)m->num_triangles);
    rtcCommitGeometry(g);
    rtcAttachGeometry(rs->scene, g);
    rtcReleaseGeometry(g);
    rs->bytes += sizeof(float) * 3 * (size_t)m->num_vertices + sizeof(unsigned) * 3 * (size_t)m->num_triangles;
    return true;
}

/* Rough BVH footprint: Embree does not report it; ~ 64 bytes per triangle. */
#define BVH_BYTES_PER_TRIANGLE 64

RtScene *rt_scene_create(const Scene *scene, RtGeometrySet set, Error *err)
{
    RTCDevice dev = get_device(err);
    if (!dev) return NULL;
    RtScene *rs = calloc(1, sizeof *rs);
    if (rs) rs->object_of_geom = calloc((size_t)scene->num_objects + 1, sizeof(int));
    if (!rs || !rs->object_of_geom) {
        free(rs);
        error_set(err, "out of memory");
        return NULL;
    }
    rs->scene = rtcNewScene(dev);
    rtcSetSceneFlags(rs->scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(rs->scene, RTC_BUILD_QUALITY_HIGH);
    for (int i = 0; i < scene->num_objects; i++) {
        const Object *o = &scene->objects[i];
        if (set == RT_CASTERS && !o->caster) continue;
        if (!add_mesh(rs, dev, &o->mesh, err)) {
            rt_scene_release(rs);
            return NULL;
        }
        rs->object_of_geom[rs->num_geoms++] = i;
        rs->bytes += BVH_BYTES_PER_TRIANGLE * (size_t)o->mesh.num_triangles;
    }
    rtcCommitScene(rs->scene);
    return rs;
}

void rt_scene_release(RtScene *rs)
{
    if (!rs) return;
    rtcReleaseScene(rs->scene);
    free(rs->object_of_geom);
    free(rs);
}

RTCScene rt_scene_handle(const RtScene *rs) { return rs->scene; }
size_t rt_scene_bytes(const RtScene *rs) { return rs->bytes; }

int rt_scene_object(const RtScene *rs, unsigned geom_id)
{
    return geom_id < (unsigned)rs->num_geoms ? rs->object_of_geom[geom_id] : -1;
}

