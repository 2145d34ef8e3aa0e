/* The cost of one parallel section: the worker team (src/tasks.h, akp_run_tasks) beside
 * starting and joining fresh threads per call (what every job did before the team), on the
 * same empty and 100 us tasks, interleaved in one run. A simulation step has several parallel
 * phases, so this cost is paid several times per step. */
#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdio.h>

#include "bench_clock.h"
#include "tasks.h"

typedef struct spin_task {
    double seconds; /* busy time of the task */
    atomic_int* sink;
} spin_task;

static void* spin(void* arg) {
    spin_task* t = (spin_task*)arg;
    if (t->seconds > 0) {
        const double end = bench_cpu_s() + t->seconds;
        while (bench_cpu_s() < end) {
        }
    }
    atomic_fetch_add_explicit(t->sink, 1, memory_order_relaxed);
    return NULL;
}

static void run_fresh(void* (*fn)(void*), spin_task* tasks, uint32_t count) {
    pthread_t ids[AKP_TASKS_MAX];
    bool started[AKP_TASKS_MAX];
    for (uint32_t t = 1; t < count; ++t) started[t] = pthread_create(&ids[t], NULL, fn, &tasks[t]) == 0;
    fn(&tasks[0]);
    for (uint32_t t = 1; t < count; ++t) {
        if (started[t]) pthread_join(ids[t], NULL);
        else fn(&tasks[t]);
    }
}

/* Median wall microseconds per call over rounds of calls, team and fresh interleaved. */
static void measure(uint32_t count, double task_s, int calls, int rounds, double* team_us, double* fresh_us) {
    atomic_int sink;
    atomic_init(&sink, 0);
    spin_task tasks[AKP_TASKS_MAX];
    for (uint32_t t = 0; t < count; ++t) tasks[t] = (spin_task){task_s, &sink};
    double a[64], b[64];
    for (int r = 0; r < rounds; ++r) {
        double t0 = bench_wall_s();
        for (int c = 0; c < calls; ++c) akp_run_tasks(spin, tasks, sizeof(spin_task), count);
        double t1 = bench_wall_s();
        for (int c = 0; c < calls; ++c) run_fresh(spin, tasks, count);
        double t2 = bench_wall_s();
        a[r] = (t1 - t0) / calls * 1e6;
        b[r] = (t2 - t1) / calls * 1e6;
    }
    *team_us = bench_percentile(a, (size_t)rounds, 0.5);
    *fresh_us = bench_percentile(b, (size_t)rounds, 0.5);
}

int main(void) {
    const int quick = bench_quick();
    const int rounds = quick ? 3 : 15;
    printf("one parallel section: worker team vs fresh threads per call (median of %d rounds, wall)\n", rounds);
    printf("%-7s %-10s %14s %14s %10s\n", "tasks", "task", "team us/call", "fresh us/call", "fresh/team");
    const uint32_t counts[] = {2, 4, 8, 16};
    const double work[] = {0.0, 100e-6};
    for (size_t w = 0; w < 2; ++w)
        for (size_t k = 0; k < sizeof counts / sizeof counts[0]; ++k) {
            double team, fresh;
            measure(counts[k], work[w], work[w] > 0 ? 100 : 1000, rounds, &team, &fresh);
            printf("%-7u %-10s %14.2f %14.2f %9.2fx\n", counts[k], work[w] > 0 ? "100 us" : "empty", team, fresh,
                   fresh / team);
        }
    uint64_t team_runs = 0, fresh_runs = 0;
    akp_tasks_stats(&team_runs, &fresh_runs);
    printf("calls that ran on the team: %llu, that had to start threads: %llu\n", (unsigned long long)team_runs,
           (unsigned long long)fresh_runs);
    return 0;
}
