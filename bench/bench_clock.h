/* Clocks and order statistics shared by the benchmarks (bench/ only, never installed). */
#ifndef ANIMKIT_BENCH_CLOCK_H
#define ANIMKIT_BENCH_CLOCK_H

#include <stdlib.h>
#include <time.h>

static inline double bench_seconds(clockid_t clock) {
    struct timespec ts;
    clock_gettime(clock, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
/* Wall time. */
static inline double bench_wall_s(void) { return bench_seconds(CLOCK_MONOTONIC); }
/* CPU time of the calling thread: on a loaded machine, closer to what an idle core takes. */
static inline double bench_cpu_s(void) { return bench_seconds(CLOCK_THREAD_CPUTIME_ID); }
/* CPU time of all the process's threads. */
static inline double bench_proc_s(void) { return bench_seconds(CLOCK_PROCESS_CPUTIME_ID); }

static inline int bench_cmp_double(const void* a, const void* b) {
    const double x = *(const double*)a, y = *(const double*)b;
    return (x > y) - (x < y);
}
/* The p-quantile of v[0..n) (sorts v in place): v[round(p (n - 1))]; p = 0.5 is v[n / 2]. */
static inline double bench_percentile(double* v, size_t n, double p) {
    qsort(v, n, sizeof *v, bench_cmp_double);
    return v[(size_t)(p * (double)(n - 1) + 0.5)];
}

/* AK_BENCH_QUICK set (and not "0"): `make bench-quick`, which checks the benchmark pipeline; a
 * bench whose sizes are fixed may then run fewer rounds or leave out a slow part (and says so). */
static inline int bench_quick(void) {
    const char* q = getenv("AK_BENCH_QUICK");
    return q && *q && !(q[0] == '0' && q[1] == '\0');
}

#endif
