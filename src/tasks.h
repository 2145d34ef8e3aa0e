/* The library's worker team: one persistent set of threads that every multithreaded job
 * (skinning, noise, the neighbour grid, particles, boids, crowds) hands its tasks to, instead
 * of creating and joining threads on every call. Internal; never installed. */
#ifndef ANIMKIT_TASKS_H
#define ANIMKIT_TASKS_H

#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* Builds without threads (WebAssembly/WASI) run every task on the calling thread. */
#if defined(__wasi__) && !defined(AKP_NO_THREADS)
#define AKP_NO_THREADS 1
#endif

/* Most tasks one call runs (the jobs cap thread_count at this). */
#define AKP_TASKS_MAX 64u

/* Run fn(tasks + t * size) for every t in [0, count), count <= AKP_TASKS_MAX, and return when
 * all have finished. Task 0 runs on the calling thread, the others on the team's workers, each
 * on its own thread (a task may therefore wait for another, as with a barrier, provided every
 * task runs: see the last case). The team is created on first use, grows to the largest count
 * asked for and lives until the process ends (a forked child starts a new one).
 * When the team is busy (a call from another thread meanwhile, or from inside a task) the call
 * starts fresh threads as the jobs used to; when those cannot all start, the calling thread
 * runs every task, one after another (so tasks that wait for each other must use
 * akp_team_begin instead). Results never depend on which of these happened, since each task's
 * work is fixed by its index. */
void akp_run_tasks(void* (*fn)(void*), void* tasks, size_t size, uint32_t count);

/* A job's O(n) input check (finite positions, valid indices) split over its threads: items
 * [0, n) in `parts` contiguous parts (capped at AKP_TASKS_MAX; a single part below
 * AKP_CHECK_SPLIT_MIN items, where starting a section costs more than the scan saves), part p
 * being [n p / parts, n (p + 1) / parts); check(ctx, b, e) returns 0 or the part's error code,
 * stored in results[p]. Returns the number of parts; the caller reduces the results in the
 * order its serial check would report them. */
#define AKP_CHECK_SPLIT_MIN 65536u
uint32_t akp_check_split(size_t n, uint32_t parts, int (*check)(const void* ctx, size_t b, size_t e), const void* ctx,
                         int results[AKP_TASKS_MAX]);

/* A team run split in two, for jobs whose calling thread leads the others through phases
 * (barriers between them) rather than running one task: akp_team_begin starts tasks 1 ..
 * count - 1, each on its own thread, all at the same time, and returns true; the caller then
 * does its share (task 0's) and calls akp_team_end, which returns when those tasks have
 * returned. When even one task cannot have its own thread, begin runs none, returns false, and
 * the caller does the whole job alone (end is then a no-op). The run lives on the caller's
 * stack between the two calls. */
typedef struct akp_team_run {
    uint32_t count;   /* tasks started by begin, task 0 included; 1 when begin returned false */
    double begin_s;   /* when begin started the tasks (profiling on) */
    bool on_team;     /* the persistent team ran them (else fresh threads) */
    /* fresh threads: the gate that holds them until all have started */
    pthread_t ids[AKP_TASKS_MAX];
    pthread_mutex_t gate_m;
    pthread_cond_t gate_cv;
    int gate;         /* 0 closed, 1 run, -1 abandon */
    void* (*fn)(void*);
    char* base;
    size_t size;
    struct akp_team_fresh {
        struct akp_team_run* run;
        uint32_t index;
    } fresh[AKP_TASKS_MAX];
    bool profiled;    /* its phases are recorded (akp_tasks_profile_step) */
    bool outer;       /* begun by a task of a profiled run (whose phase it is part of) */
} akp_team_run;
bool akp_team_begin(akp_team_run* run, void* (*fn)(void*), void* tasks, size_t size, uint32_t count);
void akp_team_end(akp_team_run* run);

/* A barrier for the tasks of one team run: the first to arrive spin up to AKP_BARRIER_SPIN pauses
 * (most meetings of busy threads end within microseconds), then sleep on a condition variable
 * (a descheduled partner on a loaded machine would make spinning burn its core); the last to
 * arrive bumps the generation and wakes the sleepers. Sequentially consistent atomics order
 * "bump, then look for sleepers" against "announce sleeping, then look at the generation", so
 * no wake-up is lost. size 1 makes wait a no-op. */
#define AKP_BARRIER_SPIN 512
typedef struct akp_barrier {
    pthread_mutex_t m;
    pthread_cond_t cv;
    atomic_uint arrived, generation, sleepers;
    uint32_t size;
} akp_barrier;
void akp_barrier_init(akp_barrier* b, uint32_t size);
void akp_barrier_wait(akp_barrier* b);
void akp_barrier_destroy(akp_barrier* b);

/* How many of the calls so far ran on the team and how many had to start threads of their own
 * (tests and benchmarks; counts since the process started). */
void akp_tasks_stats(uint64_t* out_team_runs, uint64_t* out_fresh_runs);

/* Where the time of the threaded jobs goes (benchmarks; off by default, when nothing is
 * measured): parallel sections run (team runs and akp_run_tasks calls with >= 2 tasks), the
 * caller's wall time inside them (from begin to the end of end), the part of that the caller
 * spent waiting in end for the other tasks (imbalance at the end of a section), and the time
 * threads spent waiting at barriers, summed over threads (imbalance between phases plus the
 * barrier's own cost). A job's serial part is its wall time minus section_seconds. Enabling
 * resets the counts. */
typedef struct akp_tasks_profile {
    uint64_t sections, barrier_waits;
    double section_seconds, caller_wait_seconds, barrier_wait_seconds;
} akp_tasks_profile;
void akp_tasks_profile_enable(bool on);
void akp_tasks_profile_read(akp_tasks_profile* out);

/* CPU time per phase (benchmarks; recorded while the profile is on). Every thread measures its
 * own CPU time (CLOCK_THREAD_CPUTIME_ID, so other processes on a loaded machine do not count)
 * from the start of its task to each barrier, between barriers, and from the last barrier to
 * the task's end; a phase is the work between two meetings of a run's threads. Phases are
 * numbered in order from akp_tasks_profile_step (a benchmark calls it before each step): the
 * caller's serial parts between parallel sections get a number too. Per phase, with w_t the CPU
 * seconds of thread t among T: serial_s = max w - mean of the other w (work no other thread
 * shared: a part only task 0 does, or the busiest thread's excess), parallel_s = sum w -
 * serial_s, critical_s = max w. A serial part between sections is all serial_s. Then
 * Amdahl predicts the step on N threads as sum(serial_s + parallel_s / N) and the critical path
 * at T threads is sum(critical_s), a time a machine with T free cores would need (less memory
 * bandwidth and wake-up costs). steady_serial_s is serial_s computed once from each task's CPU
 * seconds summed over the phase's runs instead of per run: an excess that moves from task to
 * task between runs (a thread slowed by another process, cache interference on a loaded machine)
 * cancels there, while one that stays with a task (a partition that gives it more work, a part
 * only task 0 does) remains; serial_s >= steady_serial_s, and the gap is the transient part.
 * Only runs begun by the thread that called enable or step are
 * split into phases (a run begun inside a task is part of that task's work); phases past
 * AKP_PHASES_MAX - 1 add up in the last slot. Enabling resets these too. */
#define AKP_PHASES_MAX 512u
typedef struct akp_phase_cpu {
    uint64_t runs;     /* times this phase ran */
    uint32_t threads;  /* threads in its last run; 1 for a serial part between sections */
    double serial_s, parallel_s, critical_s;
    double steady_serial_s; /* the persistent part of serial_s (above) */
} akp_phase_cpu;
void akp_tasks_profile_step(void);
/* The phases recorded so far, in order (at most cap); returns how many there are. */
size_t akp_tasks_profile_phases(akp_phase_cpu* out, size_t cap);

#endif
