/* counters.c -- the registry of per-thread work counters (see counters.h).
 * A thread's block is registered the first time it takes part in a
 * snapshot's OpenMP region; a pthread key's destructor folds the block of a
 * thread that exits into `retired`, so no sum ever shrinks. */
#include "core/counters.h"
#include <pthread.h>
#include <stdlib.h>

_Thread_local WorkThread work_thread __attribute__((tls_model("initial-exec")));

static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_once_t key_once = PTHREAD_ONCE_INIT;
static pthread_key_t exit_key;
static WorkThread **threads; /* registered blocks */
static int num_threads, cap_threads;
static WorkCounters retired; /* blocks of threads that have exited */

void work_add(WorkCounters *a, const WorkCounters *b)
{
    a->texel_fetches += b->texel_fetches;
    a->texel_bytes += b->texel_bytes;
    a->ray_calls += b->ray_calls;
    a->rays += b->rays;
    a->triangles += b->triangles;
    a->fragments += b->fragments;
    a->edges += b->edges;
    a->influence += b->influence;
    a->micropatches += b->micropatches;
}

WorkCounters work_diff(const WorkCounters *later, const WorkCounters *earlier)
{
    return (WorkCounters){later->texel_fetches - earlier->texel_fetches, later->texel_bytes - earlier->texel_bytes,
                          later->ray_calls - earlier->ray_calls,         later->rays - earlier->rays,
                          later->triangles - earlier->triangles,         later->fragments - earlier->fragments,
                          later->edges - earlier->edges,
                          later->influence - earlier->influence,
                          later->micropatches - earlier->micropatches};
}

static void on_thread_exit(void *block)
{
    WorkThread *t = block;
    pthread_mutex_lock(&lock);
    work_add(&retired, &t->c);
    for (int i = 0; i < num_threads; i++) {
        if (threads[i] != t) continue;
        threads[i] = threads[--num_threads];
        break;
    }
    pthread_mutex_unlock(&lock);
}

static void make_key(void) { pthread_key_create(&exit_key, on_thread_exit); }

/* Registers this thread's block once; a block that cannot be registered (out
 * of memory) is retried at the next snapshot. */
static void register_self(void)
{
    if (work_thread.registered) return;
    pthread_once(&key_once, make_key);
    pthread_mutex_lock(&lock);
    if (num_threads == cap_threads) {
        int cap = cap_threads ? 2 * cap_threads : 64;
        WorkThread **n = realloc(threads, sizeof *n * (size_t)cap);
        if (n) {
            threads = n;
            cap_threads = cap;
        }
    }
    if (num_threads < cap_threads) {
        threads[num_threads++] = &work_thread;
        work_thread.registered = true;
    }
    pthread_mutex_unlock(&lock);
    if (work_thread.registered) pthread_setspecific(exit_key, &work_thread);
}

void work_snapshot(WorkCounters *total)
{
#pragma omp parallel
    register_self();
    pthread_mutex_lock(&lock);
    *total = retired;
    for (int i = 0; i < num_threads; i++) work_add(total, &threads[i]->c);
    pthread_mutex_unlock(&lock);
}
