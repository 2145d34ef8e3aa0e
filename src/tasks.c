/* The persistent worker team behind akp_run_tasks (tasks.h).
 *
 * Each worker i (1 .. AKP_TASKS_MAX - 1) sleeps on its own semaphore. A call takes the team
 * (a trylock: a second caller, or a task calling in again, does not wait but starts threads of
 * its own), publishes the job, posts the semaphores of workers 1 .. count - 1 only, runs task 0
 * itself and sleeps on the done semaphore, which the last worker to finish posts. Creating a
 * thread costs 20-60 us; a semaphore wake costs a few us, which is what a simulation step
 * with several parallel phases per step pays per phase. */
#include "tasks.h"

#include <pthread.h>
#include <semaphore.h>
#include <stdatomic.h>
#include <stdbool.h>

typedef struct team_job {
    void* (*fn)(void*);
    char* base;
    size_t size;
} team_job;

static pthread_mutex_t team_lock = PTHREAD_MUTEX_INITIALIZER; /* held by the caller for one run */
static pthread_once_t team_once = PTHREAD_ONCE_INIT;
static sem_t worker_go[AKP_TASKS_MAX];
static sem_t team_done;
static uint32_t worker_count; /* workers started: indices 1 .. worker_count; under team_lock */
static team_job job;          /* written under team_lock before the posts, read after a wait */
static atomic_uint pending;
static atomic_ullong team_runs, fresh_runs;

static void* worker_main(void* arg) {
    const uint32_t index = (uint32_t)(uintptr_t)arg;
    for (;;) {
        while (sem_wait(&worker_go[index]) != 0) {
        }
        job.fn(job.base + index * job.size);
        if (atomic_fetch_sub_explicit(&pending, 1u, memory_order_acq_rel) == 1u) sem_post(&team_done);
    }
    return NULL;
}

/* A forked child has only the thread that forked: no workers, and team_lock possibly held by a
 * thread that does not exist there. Start over. */
static void team_child_reset(void) {
    pthread_mutex_t fresh = PTHREAD_MUTEX_INITIALIZER;
    team_lock = fresh;
    for (uint32_t i = 1; i <= worker_count && i < AKP_TASKS_MAX; ++i) {
        sem_destroy(&worker_go[i]);
    }
    sem_destroy(&team_done);
    sem_init(&team_done, 0, 0);
    worker_count = 0;
}

static void team_init(void) {
    sem_init(&team_done, 0, 0);
    pthread_atfork(NULL, NULL, team_child_reset);
}

/* Grow the team to count - 1 workers; false when a thread cannot start (the ones that did
 * stay and serve later calls). */
static bool team_grow(uint32_t count) {
    while (worker_count + 1 < count) {
        const uint32_t i = worker_count + 1;
        if (sem_init(&worker_go[i], 0, 0) != 0) return false;
        pthread_attr_t attr;
        pthread_attr_init(&attr);
        pthread_attr_setdetachstate(&attr, PTHREAD_CREATE_DETACHED);
        pthread_t id;
        const int rc = pthread_create(&id, &attr, worker_main, (void*)(uintptr_t)i);
        pthread_attr_destroy(&attr);
        if (rc != 0) {
            sem_destroy(&worker_go[i]);
            return false;
        }
        worker_count = i;
    }
    return true;
}

static void run_fresh(void* (*fn)(void*), char* base, size_t size, uint32_t count) {
    pthread_t ids[AKP_TASKS_MAX];
    bool started[AKP_TASKS_MAX];
    for (uint32_t t = 1; t < count; ++t) started[t] = pthread_create(&ids[t], NULL, fn, base + t * size) == 0;
    fn(base);
    for (uint32_t t = 1; t < count; ++t) {
        if (started[t]) pthread_join(ids[t], NULL);
        else fn(base + t * size);
    }
}

void akp_run_tasks(void* (*fn)(void*), void* tasks, size_t size, uint32_t count) {
    char* base = (char*)tasks;
    if (count > AKP_TASKS_MAX) count = AKP_TASKS_MAX;
    if (count <= 1) {
        if (count == 1) fn(base);
        return;
    }
    pthread_once(&team_once, team_init);
    if (pthread_mutex_trylock(&team_lock) != 0) {
        atomic_fetch_add_explicit(&fresh_runs, 1u, memory_order_relaxed);
        run_fresh(fn, base, size, count);
        return;
    }
    if (!team_grow(count)) {
        pthread_mutex_unlock(&team_lock);
        atomic_fetch_add_explicit(&fresh_runs, 1u, memory_order_relaxed);
        run_fresh(fn, base, size, count);
        return;
    }
    job = (team_job){fn, base, size};
    atomic_store_explicit(&pending, count - 1u, memory_order_release);
    for (uint32_t t = 1; t < count; ++t) sem_post(&worker_go[t]); /* a post orders the writes above */
    fn(base);
    while (sem_wait(&team_done) != 0) {
    }
    atomic_fetch_add_explicit(&team_runs, 1u, memory_order_relaxed);
    pthread_mutex_unlock(&team_lock);
}

void akp_tasks_stats(uint64_t* out_team_runs, uint64_t* out_fresh_runs) {
    if (out_team_runs) *out_team_runs = atomic_load_explicit(&team_runs, memory_order_relaxed);
    if (out_fresh_runs) *out_fresh_runs = atomic_load_explicit(&fresh_runs, memory_order_relaxed);
}
