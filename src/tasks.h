/* The library's worker team: one persistent set of threads that every multithreaded job
 * (skinning, noise, the neighbour grid, particles, boids, crowds) hands its tasks to, instead
 * of creating and joining threads on every call. Internal; never installed. */
#ifndef ANIMKIT_TASKS_H
#define ANIMKIT_TASKS_H

#include <stddef.h>
#include <stdint.h>

/* Most tasks one call runs (the jobs cap thread_count at this). */
#define AKP_TASKS_MAX 64u

/* Run fn(tasks + t * size) for every t in [0, count), count <= AKP_TASKS_MAX, and return when
 * all have finished. Task 0 runs on the calling thread, the others on the team's workers, each
 * on its own thread (a task may therefore wait for another, as with a barrier, provided every
 * task runs: see the last case). The team is created on first use, grows to the largest count
 * asked for and lives until the process ends (a forked child starts a new one).
 * When the team is busy (a call from another thread meanwhile, or from inside a task) the call
 * starts fresh threads as the jobs used to; a task whose thread cannot start runs on the
 * calling thread after task 0. Results never depend on which of these happened, since each
 * task's work is fixed by its index. */
void akp_run_tasks(void* (*fn)(void*), void* tasks, size_t size, uint32_t count);

/* How many of the calls so far ran on the team and how many had to start threads of their own
 * (tests and benchmarks; counts since the process started). */
void akp_tasks_stats(uint64_t* out_team_runs, uint64_t* out_fresh_runs);

#endif
