/* Tests for the worker team (src/tasks.h): every task runs once, on its own thread, the team is
 * reused across calls, and the busy cases (a second caller, a call from inside a task, a forked
 * child) still run every task. */
#include <pthread.h>
#include <stdatomic.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "ak_test.h"
#include "csort.h"
#include "tasks.h"

typedef struct probe {
    atomic_int* runs;     /* per task: times run */
    pthread_t thread;     /* the thread that ran it */
    uint32_t index;
    uint32_t count;
    atomic_uint* arrived; /* rendezvous: every task waits until all have arrived (bounded) */
    bool met;             /* all arrived before the deadline */
    int nested;           /* > 0: run a nested call of this many tasks */
    int nested_ok;
} probe;

static void* count_task(void* arg) {
    probe* p = (probe*)arg;
    atomic_fetch_add(&p->runs[p->index], 1);
    p->thread = pthread_self();
    return NULL;
}

/* A rendezvous that fails instead of hanging: it can only be met if every task runs at once. */
static void* meet_task(void* arg) {
    probe* p = (probe*)arg;
    p->thread = pthread_self();
    atomic_fetch_add(p->arrived, 1u);
    struct timespec t0;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (;;) {
        if (atomic_load(p->arrived) >= p->count) {
            p->met = true;
            break;
        }
        struct timespec t;
        clock_gettime(CLOCK_MONOTONIC, &t);
        if ((double)(t.tv_sec - t0.tv_sec) + 1e-9 * (double)(t.tv_nsec - t0.tv_nsec) > 10.0) break;
        sched_yield();
    }
    return NULL;
}

static void* nested_task(void* arg) {
    probe* p = (probe*)arg;
    atomic_int runs[8] = {0};
    probe inner[8];
    for (int i = 0; i < p->nested; ++i) inner[i] = (probe){.runs = runs, .index = (uint32_t)i};
    akp_run_tasks(count_task, inner, sizeof(probe), (uint32_t)p->nested);
    int ok = 1;
    for (int i = 0; i < p->nested; ++i) ok = ok && atomic_load(&runs[i]) == 1;
    p->nested_ok = ok;
    return NULL;
}

/* Runs count tasks that count themselves; checks each ran once and on distinct threads. */
static void run_counted(uint32_t count) {
    atomic_int runs[AKP_TASKS_MAX];
    probe tasks[AKP_TASKS_MAX];
    for (uint32_t i = 0; i < count; ++i) {
        atomic_init(&runs[i], 0);
        tasks[i] = (probe){.runs = runs, .index = i, .count = count};
    }
    akp_run_tasks(count_task, tasks, sizeof(probe), count);
    for (uint32_t i = 0; i < count; ++i) AK_CHECK_EQ(atomic_load(&runs[i]), 1);
    if (count > 0) AK_CHECK(pthread_equal(tasks[0].thread, pthread_self()));
    for (uint32_t i = 0; i < count; ++i)
        for (uint32_t j = i + 1; j < count; ++j) AK_CHECK(!pthread_equal(tasks[i].thread, tasks[j].thread));
}

AK_TEST(every_task_once_on_its_own_thread) {
    for (uint32_t count = 0; count <= 16; ++count) run_counted(count);
    run_counted(AKP_TASKS_MAX);
}

AK_TEST(tasks_run_at_the_same_time) {
    /* 8 tasks meet in a rendezvous: impossible if any ran after another finished */
    for (int round = 0; round < 20; ++round) {
        atomic_uint arrived;
        atomic_init(&arrived, 0u);
        probe tasks[8];
        for (uint32_t i = 0; i < 8; ++i) tasks[i] = (probe){.index = i, .count = 8, .arrived = &arrived};
        akp_run_tasks(meet_task, tasks, sizeof(probe), 8);
        for (uint32_t i = 0; i < 8; ++i) AK_CHECK(tasks[i].met);
    }
}

AK_TEST(team_is_reused) {
    uint64_t team0, fresh0, team1, fresh1;
    run_counted(4);
    akp_tasks_stats(&team0, &fresh0);
    for (int i = 0; i < 2000; ++i) run_counted(4);
    akp_tasks_stats(&team1, &fresh1);
    AK_CHECK_EQ(team1 - team0, 2000u);
    AK_CHECK_EQ(fresh1 - fresh0, 0u);
}

AK_TEST(nested_call_runs_every_task) {
    uint64_t fresh0, fresh1;
    akp_tasks_stats(NULL, &fresh0);
    probe tasks[4];
    for (uint32_t i = 0; i < 4; ++i) tasks[i] = (probe){.index = i, .nested = 3};
    akp_run_tasks(nested_task, tasks, sizeof(probe), 4);
    for (uint32_t i = 0; i < 4; ++i) AK_CHECK(tasks[i].nested_ok);
    akp_tasks_stats(NULL, &fresh1);
    AK_CHECK_EQ(fresh1 - fresh0, 4u); /* the team was busy: each inner call started threads */
}

static void* caller_thread(void* arg) {
    int* ok = (int*)arg;
    for (int i = 0; i < 300 && *ok; ++i) {
        atomic_int runs[6];
        probe tasks[6];
        for (uint32_t k = 0; k < 6; ++k) {
            atomic_init(&runs[k], 0);
            tasks[k] = (probe){.runs = runs, .index = k};
        }
        akp_run_tasks(count_task, tasks, sizeof(probe), 6);
        for (uint32_t k = 0; k < 6; ++k) *ok = *ok && atomic_load(&runs[k]) == 1;
    }
    return NULL;
}

AK_TEST(concurrent_callers) {
    pthread_t ids[3];
    int ok[3] = {1, 1, 1};
    for (int i = 0; i < 3; ++i) AK_CHECK_EQ(pthread_create(&ids[i], NULL, caller_thread, &ok[i]), 0);
    for (int i = 0; i < 3; ++i) pthread_join(ids[i], NULL);
    for (int i = 0; i < 3; ++i) AK_CHECK(ok[i]);
}

AK_TEST(forked_child_starts_a_new_team) {
    run_counted(4); /* the parent's team exists */
    pid_t pid = fork();
    AK_CHECK(pid >= 0);
    if (pid == 0) {
        atomic_uint arrived;
        atomic_init(&arrived, 0u);
        probe tasks[4];
        for (uint32_t i = 0; i < 4; ++i) tasks[i] = (probe){.index = i, .count = 4, .arrived = &arrived};
        akp_run_tasks(meet_task, tasks, sizeof(probe), 4);
        int met = 1;
        for (uint32_t i = 0; i < 4; ++i) met = met && tasks[i].met;
        _exit(met ? 0 : 3);
    }
    int status = 0;
    AK_CHECK_EQ(waitpid(pid, &status, 0), pid);
    AK_CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 0);
}

/* ---- akp_team_begin / akp_team_end with a barrier ------------------------------------------ */

typedef struct phased {
    akp_barrier* barrier;
    int* cells;      /* one per task */
    uint32_t index, count;
    int phases;
    int errors;
} phased;

/* Each phase every task writes its cell, meets the others, reads every cell, meets again: a
 * task that ran alone or late would read stale cells (or hang without the others: so the test
 * uses few phases and would time out rather than pass). */
static void* phased_task(void* arg) {
    phased* p = (phased*)arg;
    for (int ph = 0; ph < p->phases; ++ph) {
        p->cells[p->index] = ph * 100 + (int)p->index;
        akp_barrier_wait(p->barrier);
        for (uint32_t k = 0; k < p->count; ++k) p->errors += p->cells[k] != ph * 100 + (int)k;
        akp_barrier_wait(p->barrier);
    }
    return NULL;
}

static int run_phased(uint32_t count, int phases) {
    akp_barrier b;
    int cells[16];
    phased tasks[16];
    for (uint32_t t = 0; t < count; ++t) tasks[t] = (phased){&b, cells, t, count, phases, 0};
    akp_team_run run;
    int errors = 0;
    akp_barrier_init(&b, count);
    if (akp_team_begin(&run, phased_task, tasks, sizeof(phased), count)) {
        phased_task(&tasks[0]);
        akp_team_end(&run);
        for (uint32_t t = 0; t < count; ++t) errors += tasks[t].errors;
    } else {
        errors = -1; /* no threads at all: not expected here */
    }
    akp_barrier_destroy(&b);
    return errors;
}

AK_TEST(team_run_with_barriers) {
    for (uint32_t count = 2; count <= 8; ++count) AK_CHECK_EQ(run_phased(count, 300), 0);
    /* begin with fewer than two tasks runs nothing: the caller works alone */
    akp_team_run run;
    AK_CHECK(!akp_team_begin(&run, phased_task, NULL, sizeof(phased), 1));
    AK_CHECK_EQ(run.count, 1u);
    akp_team_end(&run); /* a no-op */
}

typedef struct nest_phased {
    int errors;
} nest_phased;

static void* nest_phased_task(void* arg) {
    ((nest_phased*)arg)->errors = run_phased(3, 100); /* the team is busy: fresh threads */
    return NULL;
}

AK_TEST(team_run_from_inside_a_task) {
    uint64_t fresh0, fresh1;
    akp_tasks_stats(NULL, &fresh0);
    nest_phased tasks[2] = {{-5}, {-5}};
    akp_run_tasks(nest_phased_task, tasks, sizeof(nest_phased), 2);
    AK_CHECK_EQ(tasks[0].errors, 0);
    AK_CHECK_EQ(tasks[1].errors, 0);
    akp_tasks_stats(NULL, &fresh1);
    AK_CHECK_EQ(fresh1 - fresh0, 2u);
}

static void* sleep_if_odd(void* arg) {
    probe* p = (probe*)arg;
    if (p->index & 1u) {
        struct timespec ts = {0, 2000000}; /* 2 ms */
        nanosleep(&ts, NULL);
    }
    return NULL;
}

AK_TEST(profile_counts_sections_waits_and_barriers) {
    akp_tasks_profile_enable(true);
    probe tasks[2] = {{.index = 0}, {.index = 1}};
    for (int i = 0; i < 10; ++i) akp_run_tasks(sleep_if_odd, tasks, sizeof(probe), 2);
    akp_tasks_profile pr;
    akp_tasks_profile_read(&pr);
    AK_CHECK_EQ(pr.sections, 10u);
    AK_CHECK(pr.caller_wait_seconds >= 10 * 0.0019); /* task 0 returns at once, then waits 2 ms */
    AK_CHECK(pr.section_seconds >= pr.caller_wait_seconds);
    AK_CHECK_EQ(pr.barrier_waits, 0u);
    AK_CHECK_EQ(run_phased(3, 50), 0);
    akp_tasks_profile_read(&pr);
    AK_CHECK_EQ(pr.sections, 11u);
    AK_CHECK_EQ(pr.barrier_waits, 3u * 50u * 2u);
    akp_tasks_profile_enable(false);
    for (int i = 0; i < 3; ++i) akp_run_tasks(sleep_if_odd, tasks, sizeof(probe), 2);
    akp_tasks_profile_read(&pr);
    AK_CHECK_EQ(pr.sections, 0u); /* enabling reset the counts; off counts nothing */
}

/* ---- CPU time per phase --------------------------------------------------------------------- */

static double thread_cpu_ms(void) {
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return 1e3 * (double)ts.tv_sec + 1e-6 * (double)ts.tv_nsec;
}

/* Burn `ms` of this thread's CPU time (CPU, not wall: a loaded machine only makes it slower). */
static void burn_cpu_ms(double ms) {
    const double until = thread_cpu_ms() + ms;
    volatile unsigned x = 1;
    while (thread_cpu_ms() < until) {
        for (int k = 0; k < 1000; ++k) x = x * 1664525u + 1013904223u;
    }
}

typedef struct burner {
    akp_barrier* barrier;
    uint32_t index;
    int nested_errors;
    double nested_ms; /* CPU time of task 1's nested job: imbalance of phase 1 */
} burner;

/* Phase 0: task 0 alone works 3 ms (a serial part inside the section); phase 1: every task 2 ms,
 * task 1 also running a phased job of its own (fresh threads, barriers that are not this run's:
 * part of its phase, not phases of their own). */
static void* burner_task(void* arg) {
    burner* b = (burner*)arg;
    if (b->index == 0) burn_cpu_ms(3.0);
    akp_barrier_wait(b->barrier);
    if (b->index == 1) {
        const double t0 = thread_cpu_ms();
        b->nested_errors = run_phased(2, 5);
        b->nested_ms = thread_cpu_ms() - t0;
    }
    burn_cpu_ms(2.0);
    return NULL;
}

AK_TEST(profile_cpu_time_per_phase) {
    enum { STEPS = 3, T = 3 };
    double nested_ms = 0.0;
    akp_tasks_profile_enable(true);
    for (int s = 0; s < STEPS; ++s) {
        akp_tasks_profile_step();
        burn_cpu_ms(1.5); /* serial, before the section */
        akp_barrier bar;
        akp_barrier_init(&bar, T);
        burner tasks[T];
        for (uint32_t t = 0; t < T; ++t) tasks[t] = (burner){&bar, t, 0, 0.0};
        akp_team_run run;
        AK_CHECK(akp_team_begin(&run, burner_task, tasks, sizeof(burner), T));
        burner_task(&tasks[0]);
        akp_team_end(&run);
        akp_barrier_destroy(&bar);
        AK_CHECK_EQ(tasks[1].nested_errors, 0);
        nested_ms += tasks[1].nested_ms;
        burn_cpu_ms(1.0); /* serial tail */
    }
    akp_phase_cpu ph[AKP_PHASES_MAX];
    const size_t n = akp_tasks_profile_phases(ph, AKP_PHASES_MAX);
    akp_tasks_profile_enable(false);
    AK_CHECK_EQ(n, 4u); /* serial, phase 0, phase 1, serial tail */
    if (n != 4) return;
    const double tol = 0.4 * STEPS; /* ms: clock reads, wake-ups, the barrier */
    AK_CHECK_EQ(ph[0].threads, 1u);
    AK_CHECK_EQ(ph[0].runs, (uint64_t)STEPS);
    AK_CHECK_NEAR(1e3 * ph[0].serial_s, 1.5 * STEPS, tol);
    AK_CHECK_EQ(ph[1].threads, (uint32_t)T);
    AK_CHECK_NEAR(1e3 * ph[1].serial_s, 3.0 * STEPS, tol);
    AK_CHECK_NEAR(1e3 * ph[1].parallel_s, 0.0, tol);
    AK_CHECK_NEAR(1e3 * ph[1].critical_s, 3.0 * STEPS, tol);
    /* phase 1: task 1's nested job is its excess over the others (w = 2, 2 + x, 2 ms) */
    AK_CHECK_NEAR(1e3 * ph[2].serial_s, nested_ms, tol);
    AK_CHECK_NEAR(1e3 * ph[2].parallel_s, 2.0 * T * STEPS, tol);
    AK_CHECK_NEAR(1e3 * ph[2].critical_s, 2.0 * STEPS + nested_ms, tol);
    AK_CHECK_EQ(ph[3].threads, 1u);
    AK_CHECK_NEAR(1e3 * ph[3].serial_s, 1.0 * STEPS, tol);
    /* off: nothing recorded, and enabling cleared the phases */
    akp_tasks_profile_step();
    AK_CHECK_EQ(akp_tasks_profile_phases(ph, AKP_PHASES_MAX), 0u);
}

/* Two tasks, one phase, one of them burning 1 ms more: the same task every step (a lasting
 * imbalance: steady_serial_s about the whole excess, as serial_s) or each task every other step
 * (a passing one, as another process slowing a thread: serial_s the same, steady_serial_s
 * about 0). */
typedef struct extra_burner {
    uint32_t index, heavy;
} extra_burner;

static void* extra_burner_task(void* arg) {
    const extra_burner* b = (const extra_burner*)arg;
    burn_cpu_ms(b->index == b->heavy ? 2.0 : 1.0);
    return NULL;
}

AK_TEST(profile_steady_serial_part) {
    enum { STEPS = 4 };
    for (int alternate = 0; alternate < 2; ++alternate) {
        akp_tasks_profile_enable(true);
        for (uint32_t s = 0; s < STEPS; ++s) {
            akp_tasks_profile_step();
            extra_burner tasks[2];
            for (uint32_t t = 0; t < 2; ++t) tasks[t] = (extra_burner){t, alternate ? s % 2 : 1};
            akp_run_tasks(extra_burner_task, tasks, sizeof(extra_burner), 2);
        }
        akp_phase_cpu ph[AKP_PHASES_MAX];
        const size_t n = akp_tasks_profile_phases(ph, AKP_PHASES_MAX);
        akp_tasks_profile_enable(false);
        AK_CHECK(n >= 2);
        if (n < 2) continue;
        const double tol = 0.3 * STEPS; /* ms */
        AK_CHECK_EQ(ph[1].threads, 2u);
        AK_CHECK_NEAR(1e3 * ph[1].serial_s, 1.0 * STEPS, tol);
        AK_CHECK_NEAR(1e3 * ph[1].steady_serial_s, alternate ? 0.0 : 1.0 * STEPS, tol);
        AK_CHECK(ph[1].steady_serial_s <= ph[1].serial_s);
        /* a serial part between sections is all steady */
        AK_CHECK_NEAR(ph[0].steady_serial_s, ph[0].serial_s, 1e-12);
    }
}

/* ---- akp_csort ------------------------------------------------------------------------------ */

typedef struct keyed {
    uint32_t key, index;
} keyed;

static int keyed_cmp(const void* a, const void* b) {
    const keyed *x = (const keyed*)a, *y = (const keyed*)b;
    if (x->key != y->key) return x->key < y->key ? -1 : 1;
    return x->index < y->index ? -1 : x->index > y->index; /* (key, index): the stable order */
}

/* Against qsort on (key, index) pairs, for bucket counts below, at and far above the part
 * count, empty inputs and one bucket, with 1 to 64 parts: the same order and bucket starts. */
AK_TEST(counting_sort_is_stable_and_split_free) {
    const size_t sizes[] = {0, 1, 7, 1000, 30011};
    const uint32_t buckets[] = {1, 3, 16, 1000, 200000};
    const uint32_t parts[] = {1, 2, 3, 5, 16, 64};
    uint32_t state = 12345u;
    for (size_t si = 0; si < sizeof sizes / sizeof sizes[0]; ++si)
        for (size_t bi = 0; bi < sizeof buckets / sizeof buckets[0]; ++bi) {
            const size_t n = sizes[si];
            const uint32_t B = buckets[bi];
            uint32_t* keys = malloc((n + 1) * sizeof(uint32_t));
            keyed* ref = malloc((n + 1) * sizeof(keyed));
            uint32_t* ref_start = calloc((size_t)B + 1, sizeof(uint32_t));
            for (size_t i = 0; i < n; ++i) {
                state = state * 1664525u + 1013904223u;
                /* clustered keys: many duplicates, some buckets empty */
                keys[i] = (uint32_t)((state >> 8) % B);
                if (state & 1u) keys[i] &= ~3u;
                if (keys[i] >= B) keys[i] = B - 1;
                ref[i] = (keyed){keys[i], (uint32_t)i};
                ref_start[keys[i] + 1]++;
            }
            for (uint32_t k = 0; k < B; ++k) ref_start[k + 1] += ref_start[k];
            qsort(ref, n, sizeof(keyed), keyed_cmp);
            for (size_t pi = 0; pi < sizeof parts / sizeof parts[0]; ++pi) {
                akp_csort* cs = malloc(sizeof *cs);
                uint32_t* order = malloc((n + 1) * sizeof(uint32_t));
                uint32_t* start = malloc(((size_t)B + 1) * sizeof(uint32_t));
                uint32_t* tmp = malloc((2 * n + 1) * sizeof(uint32_t));
                for (size_t i = 0; i < n; ++i) order[i] = 0xdeadbeefu;
                for (uint32_t k = 0; k <= B; ++k) start[k] = 0xdeadbeefu;
                *cs = (akp_csort){.keys = keys, .n = n, .buckets = B, .parts = parts[pi], .order = order,
                                  .start = start, .tmp = tmp};
                akp_csort_run(cs);
                size_t bad = 0;
                for (size_t i = 0; i < n; ++i) bad += order[i] != ref[i].index;
                for (uint32_t k = 0; k <= B; ++k) bad += start[k] != ref_start[k];
                AK_CHECK_MSG(bad == 0, "n %zu, %u buckets, %u parts: %zu wrong", n, B, parts[pi], bad);
                free(cs), free(order), free(start), free(tmp);
            }
            free(keys), free(ref), free(ref_start);
        }
}

int main(void) {
    AK_RUN(every_task_once_on_its_own_thread);
    AK_RUN(tasks_run_at_the_same_time);
    AK_RUN(team_is_reused);
    AK_RUN(nested_call_runs_every_task);
    AK_RUN(concurrent_callers);
    AK_RUN(forked_child_starts_a_new_team);
    AK_RUN(team_run_with_barriers);
    AK_RUN(team_run_from_inside_a_task);
    AK_RUN(profile_counts_sections_waits_and_barriers);
    AK_RUN(profile_cpu_time_per_phase);
    AK_RUN(profile_steady_serial_part);
    AK_RUN(counting_sort_is_stable_and_split_free);
    return ak_test_finish();
}
