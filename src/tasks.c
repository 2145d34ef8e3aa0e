/* The persistent worker team behind akp_run_tasks (tasks.h).
 *
 * Each worker i (1 .. AKP_TASKS_MAX - 1) sleeps on its own semaphore. A call takes the team
 * (a trylock: a second caller, or a task calling in again, does not wait but starts threads of
 * its own), publishes the job, posts the semaphores of workers 1 .. count - 1 only, runs task 0
 * itself and sleeps on the done semaphore, which the last worker to finish posts. Creating a
 * thread costs 20-60 us; a semaphore wake costs a few us, which is what a simulation step
 * with several parallel phases per step pays per phase. */
#include "tasks.h"

#include <string.h>
#include <time.h>

/* ---- CPU time per phase (tasks.h, akp_tasks_profile_step) ---------------------------------- */

static _Thread_local bool prof_owner;     /* this thread enabled the profile / marks the steps */
static _Thread_local double prof_outside; /* the owner's CPU time when its serial part started */
static _Thread_local bool prof_stepping;  /* the owner has marked a step since enabling */
static akp_phase_cpu prof_phases[AKP_PHASES_MAX];
static double prof_acc[AKP_PHASES_MAX][AKP_TASKS_MAX]; /* per phase and task: CPU seconds over its runs */
static uint32_t prof_phase;                /* the next phase's number; written by one thread at a time */

static double cpu_s(void) {
    struct timespec ts;
#ifdef CLOCK_THREAD_CPUTIME_ID
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
#else
    clock_gettime(CLOCK_MONOTONIC, &ts); /* one thread anyway */
#endif
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* work[t]: task t's CPU seconds in this run of the phase (threads of them) */
static void phase_add(uint32_t threads, double serial, double parallel, double critical, const double* work) {
    const uint32_t slot = prof_phase < AKP_PHASES_MAX ? prof_phase : AKP_PHASES_MAX - 1;
    akp_phase_cpu* p = &prof_phases[slot];
    if (prof_phase < AKP_PHASES_MAX) ++prof_phase;
    p->runs++;
    p->threads = threads;
    p->serial_s += serial, p->parallel_s += parallel, p->critical_s += critical;
    for (uint32_t t = 0; t < threads && t < AKP_TASKS_MAX; ++t) prof_acc[slot][t] += work[t];
}

/* The owner's serial part since its last section (or step mark) ends here. */
static void serial_done(void) {
    const double c = cpu_s(), w = c - prof_outside;
    phase_add(1, w, 0.0, w, &w);
    prof_outside = c;
}

#ifndef AKP_NO_THREADS
#include <sched.h>
#include <semaphore.h>
#include <unistd.h>

typedef struct team_job {
    void* (*fn)(void*);
    char* base;
    size_t size;
    bool profiled;
} team_job;

static pthread_mutex_t team_lock = PTHREAD_MUTEX_INITIALIZER; /* held by the caller for one run */
static pthread_once_t team_once = PTHREAD_ONCE_INIT;
static sem_t worker_go[AKP_TASKS_MAX];
static sem_t team_done;
static uint32_t worker_count; /* workers started: indices 1 .. worker_count; under team_lock */
static team_job job;          /* written under team_lock before the posts, read after a wait */
static atomic_uint pending;
static atomic_ullong team_runs, fresh_runs;

/* profiling (akp_tasks_profile_enable) */
static atomic_bool profiling;
static atomic_ullong prof_sections, prof_barrier_waits, prof_section_ns, prof_caller_wait_ns, prof_barrier_ns;

static double now_s(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void prof_add(atomic_ullong* counter, double seconds) {
    atomic_fetch_add_explicit(counter, (unsigned long long)(seconds * 1e9 + 0.5), memory_order_relaxed);
}

/* CPU time per phase: the tasks' side */
static _Thread_local bool prof_in_run;    /* this thread runs a task of a profiled run */
static _Thread_local uint32_t prof_index; /* its task index there */
static _Thread_local double prof_start;   /* CPU time when its current phase started */
static double prof_work[AKP_TASKS_MAX];   /* per task: CPU seconds of the phase that ends */

/* The phase whose tasks recorded prof_work[0 .. threads) has ended (every thread is at the
 * meeting, so nobody writes prof_work meanwhile). */
static void phase_done(uint32_t threads) {
    double sum = 0.0, max = 0.0;
    for (uint32_t t = 0; t < threads; ++t) {
        sum += prof_work[t];
        if (prof_work[t] > max) max = prof_work[t];
    }
    double serial = threads > 1 ? max - (sum - max) / (double)(threads - 1) : sum;
    if (serial < 0.0) serial = 0.0;
    phase_add(threads, serial, sum - serial, max, prof_work);
}

static void task_enter(bool profiled, uint32_t index) {
    prof_in_run = profiled;
    if (!profiled) return;
    prof_index = index;
    prof_start = cpu_s();
}

static void task_leave(void) {
    if (!prof_in_run) return;
    prof_work[prof_index] = cpu_s() - prof_start;
    prof_in_run = false;
}

/* Take the semaphore, polling it `spins` times before sleeping: a job's next parallel phase
 * usually follows within microseconds, and a futex wake-up costs about 10 us. Each poll yields
 * the core (sched_yield), so a poller never holds a core another runnable thread needs (other
 * processes' included: ctest runs tests side by side). Polling only pays when every thread of
 * the run has a core, so runs larger than the CPU count poll 0 times (bench_tasks: 4 tasks on
 * 2 cores polling took 79 us a section against 18 without). */
#define TEAM_SPIN 200
static atomic_int spin_count; /* TEAM_SPIN or 0, set by each run from its size */
static long cpu_count = 1;

static void take(sem_t* sem) {
    const int spins = atomic_load_explicit(&spin_count, memory_order_relaxed);
    for (int k = 0; k < spins; ++k) {
        if (sem_trywait(sem) == 0) return;
        sched_yield();
    }
    while (sem_wait(sem) != 0) {
    }
}

static void* worker_main(void* arg) {
    const uint32_t index = (uint32_t)(uintptr_t)arg;
    for (;;) {
        take(&worker_go[index]);
        task_enter(job.profiled, index);
        job.fn(job.base + index * job.size);
        task_leave();
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
    cpu_count = sysconf(_SC_NPROCESSORS_ONLN);
    if (cpu_count < 1) cpu_count = 1;
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

static void* fresh_main(void* arg) {
    const struct akp_team_fresh* f = (const struct akp_team_fresh*)arg;
    akp_team_run* run = f->run;
    pthread_mutex_lock(&run->gate_m);
    while (run->gate == 0) pthread_cond_wait(&run->gate_cv, &run->gate_m);
    const int go = run->gate;
    pthread_mutex_unlock(&run->gate_m);
    if (go > 0) {
        task_enter(run->profiled, f->index);
        run->fn(run->base + f->index * run->size);
        task_leave();
    }
    return NULL;
}

static void open_gate(akp_team_run* run, int value) {
    pthread_mutex_lock(&run->gate_m);
    run->gate = value;
    pthread_cond_broadcast(&run->gate_cv);
    pthread_mutex_unlock(&run->gate_m);
}

/* Tasks 1 .. count - 1 on fresh threads held at a gate until every one has started. */
static bool begin_fresh(akp_team_run* run) {
    if (pthread_mutex_init(&run->gate_m, NULL) != 0) return false;
    if (pthread_cond_init(&run->gate_cv, NULL) != 0) {
        pthread_mutex_destroy(&run->gate_m);
        return false;
    }
    run->gate = 0;
    uint32_t started = 1;
    for (uint32_t t = 1; t < run->count; ++t) {
        run->fresh[t] = (struct akp_team_fresh){run, t};
        if (pthread_create(&run->ids[t], NULL, fresh_main, &run->fresh[t]) != 0) break;
        ++started;
    }
    const bool all = started == run->count;
    open_gate(run, all ? 1 : -1);
    if (all) return true;
    for (uint32_t t = 1; t < started; ++t) pthread_join(run->ids[t], NULL);
    pthread_cond_destroy(&run->gate_cv);
    pthread_mutex_destroy(&run->gate_m);
    return false;
}

bool akp_team_begin(akp_team_run* run, void* (*fn)(void*), void* tasks, size_t size, uint32_t count) {
    run->count = 1;
    run->on_team = false;
    run->profiled = false;
    if (count > AKP_TASKS_MAX || count < 2) return false;
    run->begin_s = atomic_load_explicit(&profiling, memory_order_relaxed) ? now_s() : 0.0;
    run->profiled = run->begin_s > 0.0 && prof_owner && !prof_in_run;
    run->outer = prof_in_run;
    run->fn = fn, run->base = (char*)tasks, run->size = size, run->count = count;
    pthread_once(&team_once, team_init);
    if (pthread_mutex_trylock(&team_lock) == 0) {
        if (team_grow(count)) {
            job = (team_job){fn, (char*)tasks, size, run->profiled};
            atomic_store_explicit(&spin_count, (long)count <= cpu_count ? TEAM_SPIN : 0, memory_order_relaxed);
            atomic_store_explicit(&pending, count - 1u, memory_order_release);
            for (uint32_t t = 1; t < count; ++t) sem_post(&worker_go[t]); /* a post orders the writes above */
            run->on_team = true;
            atomic_fetch_add_explicit(&team_runs, 1u, memory_order_relaxed);
            if (run->profiled) serial_done(), task_enter(true, 0);
            prof_in_run = run->profiled; /* a run inside a task: its barriers are not the outer run's */
            return true;
        }
        pthread_mutex_unlock(&team_lock);
    }
    /* the team is busy (another caller, or a task calling in) or cannot grow */
    atomic_fetch_add_explicit(&fresh_runs, 1u, memory_order_relaxed);
    if (run->profiled) serial_done(); /* before the threads start: they may reach a barrier first */
    if (begin_fresh(run)) {
        if (run->profiled) task_enter(true, 0);
        prof_in_run = run->profiled;
        return true;
    }
    run->count = 1;
    run->profiled = false;
    return false;
}

void akp_team_end(akp_team_run* run) {
    if (run->count < 2) return;
    if (run->profiled) task_leave();
    const double wait_s = run->begin_s > 0.0 ? now_s() : 0.0;
    if (run->on_team) {
        take(&team_done);
        pthread_mutex_unlock(&team_lock);
    } else {
        for (uint32_t t = 1; t < run->count; ++t) pthread_join(run->ids[t], NULL);
        pthread_cond_destroy(&run->gate_cv);
        pthread_mutex_destroy(&run->gate_m);
    }
    if (run->begin_s > 0.0) {
        const double end_s = now_s();
        atomic_fetch_add_explicit(&prof_sections, 1u, memory_order_relaxed);
        prof_add(&prof_section_ns, end_s - run->begin_s);
        prof_add(&prof_caller_wait_ns, end_s - wait_s);
    }
    if (run->profiled) {
        phase_done(run->count);
        prof_outside = cpu_s();
        run->profiled = false;
    }
    prof_in_run = run->outer; /* back in the outer task's phase (its CPU clock ran on) */
    run->count = 1;
}

void akp_run_tasks(void* (*fn)(void*), void* tasks, size_t size, uint32_t count) {
    char* base = (char*)tasks;
    if (count > AKP_TASKS_MAX) count = AKP_TASKS_MAX;
    akp_team_run run;
    if (akp_team_begin(&run, fn, tasks, size, count)) {
        fn(base);
        akp_team_end(&run);
        return;
    }
    for (uint32_t t = 0; t < count; ++t) fn(base + t * size); /* alone: one after another */
}

/* ---- barrier ------------------------------------------------------------------------------ */

static void cpu_relax(void) {
#if defined(__x86_64__) || defined(__i386__)
    __asm__ __volatile__("pause");
#endif
}

void akp_barrier_init(akp_barrier* b, uint32_t size) {
    pthread_mutex_init(&b->m, NULL);
    pthread_cond_init(&b->cv, NULL);
    atomic_init(&b->arrived, 0u);
    atomic_init(&b->generation, 0u);
    atomic_init(&b->sleepers, 0u);
    b->size = size ? size : 1u;
}

static void barrier_wait(akp_barrier* b);

void akp_barrier_wait(akp_barrier* b) {
    if (b->size <= 1) return;
    if (!atomic_load_explicit(&profiling, memory_order_relaxed)) {
        barrier_wait(b);
        return;
    }
    const double t0 = now_s();
    barrier_wait(b);
    atomic_fetch_add_explicit(&prof_barrier_waits, 1u, memory_order_relaxed);
    prof_add(&prof_barrier_ns, now_s() - t0);
}

static void barrier_wait(akp_barrier* b) {
    const unsigned g = atomic_load(&b->generation);
    if (prof_in_run) prof_work[prof_index] = cpu_s() - prof_start; /* before arriving: see phase_done */
    if (atomic_fetch_add(&b->arrived, 1) + 1 == b->size) {
        if (prof_in_run) phase_done(b->size), prof_start = cpu_s();
        atomic_store(&b->arrived, 0);
        atomic_fetch_add(&b->generation, 1);
        if (atomic_load(&b->sleepers)) {
            pthread_mutex_lock(&b->m);
            pthread_cond_broadcast(&b->cv);
            pthread_mutex_unlock(&b->m);
        }
        return;
    }
    for (int k = 0; k < AKP_BARRIER_SPIN; ++k) {
        if (atomic_load_explicit(&b->generation, memory_order_acquire) != g) {
            if (prof_in_run) prof_start = cpu_s();
            return;
        }
        cpu_relax();
    }
    pthread_mutex_lock(&b->m);
    atomic_fetch_add(&b->sleepers, 1);
    while (atomic_load(&b->generation) == g) pthread_cond_wait(&b->cv, &b->m);
    atomic_fetch_sub(&b->sleepers, 1);
    pthread_mutex_unlock(&b->m);
    if (prof_in_run) prof_start = cpu_s();
}

void akp_barrier_destroy(akp_barrier* b) {
    pthread_cond_destroy(&b->cv);
    pthread_mutex_destroy(&b->m);
}

#else /* AKP_NO_THREADS: one thread (the WebAssembly build); every job runs on the caller */

static atomic_bool profiling;
static atomic_ullong team_runs, fresh_runs;
static atomic_ullong prof_sections, prof_barrier_waits, prof_section_ns, prof_caller_wait_ns, prof_barrier_ns;

bool akp_team_begin(akp_team_run* run, void* (*fn)(void*), void* tasks, size_t size, uint32_t count) {
    (void)fn, (void)tasks, (void)size, (void)count;
    run->count = 1;
    run->on_team = false;
    return false;
}

void akp_team_end(akp_team_run* run) { (void)run; }

void akp_run_tasks(void* (*fn)(void*), void* tasks, size_t size, uint32_t count) {
    if (count > AKP_TASKS_MAX) count = AKP_TASKS_MAX;
    for (uint32_t t = 0; t < count; ++t) fn((char*)tasks + t * size);
}

void akp_barrier_init(akp_barrier* b, uint32_t size) {
    (void)size;
    b->size = 1; /* never more than one thread meets here */
}

void akp_barrier_wait(akp_barrier* b) { (void)b; }

void akp_barrier_destroy(akp_barrier* b) { (void)b; }

#endif

void akp_tasks_stats(uint64_t* out_team_runs, uint64_t* out_fresh_runs) {
    if (out_team_runs) *out_team_runs = atomic_load_explicit(&team_runs, memory_order_relaxed);
    if (out_fresh_runs) *out_fresh_runs = atomic_load_explicit(&fresh_runs, memory_order_relaxed);
}

void akp_tasks_profile_step(void) {
    if (!atomic_load_explicit(&profiling, memory_order_relaxed)) return;
    if (prof_owner && prof_stepping) serial_done(); /* the last step's serial tail */
    prof_owner = prof_stepping = true;
    prof_phase = 0;
    prof_outside = cpu_s();
}

size_t akp_tasks_profile_phases(akp_phase_cpu* out, size_t cap) {
    if (prof_owner && atomic_load_explicit(&profiling, memory_order_relaxed)) {
        const uint32_t keep = prof_phase;
        serial_done(); /* the serial tail so far, in the phase after the last one */
        prof_phase = keep;
    }
    size_t n = 0;
    while (n < AKP_PHASES_MAX && prof_phases[n].runs) ++n;
    for (size_t i = 0; i < n && i < cap; ++i) {
        out[i] = prof_phases[i];
        /* the busiest task over all runs beyond the others' mean over all runs */
        const uint32_t T = out[i].threads < AKP_TASKS_MAX ? out[i].threads : AKP_TASKS_MAX;
        double sum = 0.0, max = 0.0;
        for (uint32_t t = 0; t < T; ++t) {
            sum += prof_acc[i][t];
            if (prof_acc[i][t] > max) max = prof_acc[i][t];
        }
        double steady = T > 1 ? max - (sum - max) / (double)(T - 1) : sum;
        out[i].steady_serial_s = steady > 0.0 ? steady : 0.0;
    }
    return n;
}

void akp_tasks_profile_enable(bool on) {
    memset(prof_phases, 0, sizeof prof_phases);
    memset(prof_acc, 0, sizeof prof_acc);
    prof_phase = 0;
    prof_owner = on;
    prof_stepping = false;
    prof_outside = cpu_s();
    atomic_store(&prof_sections, 0u);
    atomic_store(&prof_barrier_waits, 0u);
    atomic_store(&prof_section_ns, 0u);
    atomic_store(&prof_caller_wait_ns, 0u);
    atomic_store(&prof_barrier_ns, 0u);
    atomic_store(&profiling, on);
}

void akp_tasks_profile_read(akp_tasks_profile* out) {
    out->sections = atomic_load(&prof_sections);
    out->barrier_waits = atomic_load(&prof_barrier_waits);
    out->section_seconds = 1e-9 * (double)atomic_load(&prof_section_ns);
    out->caller_wait_seconds = 1e-9 * (double)atomic_load(&prof_caller_wait_ns);
    out->barrier_wait_seconds = 1e-9 * (double)atomic_load(&prof_barrier_ns);
}

/* akp_check_split: one task per part */
typedef struct check_task {
    int (*check)(const void*, size_t, size_t);
    const void* ctx;
    size_t b, e;
    int r;
} check_task;

static void* check_task_run(void* arg) {
    check_task* t = (check_task*)arg;
    t->r = t->check(t->ctx, t->b, t->e);
    return NULL;
}

uint32_t akp_check_split(size_t n, uint32_t parts, int (*check)(const void* ctx, size_t b, size_t e), const void* ctx,
                         int results[AKP_TASKS_MAX]) {
    if (parts == 0 || n < AKP_CHECK_SPLIT_MIN) parts = 1;
    if (parts > AKP_TASKS_MAX) parts = AKP_TASKS_MAX;
    check_task tasks[AKP_TASKS_MAX];
    for (uint32_t p = 0; p < parts; ++p) tasks[p] = (check_task){check, ctx, n * p / parts, n * (p + 1) / parts, 0};
    if (parts == 1) check_task_run(&tasks[0]);
    else akp_run_tasks(check_task_run, tasks, sizeof tasks[0], parts);
    for (uint32_t p = 0; p < parts; ++p) results[p] = tasks[p].r;
    return parts;
}
