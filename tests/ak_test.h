/* Tiny test harness: one executable per module, one ctest entry each.
 *
 *     AK_TEST(quat_identity) { AK_CHECK_NEAR(ak_quat_norm(ak_quat_identity()), 1.0f, 1e-7); }
 *     int main(void) { AK_RUN(quat_identity); AK_RUN_SLOW(long_soak); return ak_test_finish(); }
 *
 * Every check prints file:line and both values when it fails. Each case prints "ok NAME
 * (seconds)" or "FAIL NAME". ak_test_finish() prints "N passed, N failed" (the line CI reads)
 * and returns the process exit code.
 *
 * Fast and slow cases: AK_RUN_SLOW marks a case that takes more than a few seconds (long
 * end-to-end runs, real assets at full length). The environment variable AK_TEST_SELECT picks
 * what runs: "fast" (the cases of AK_RUN only), "slow" (AK_RUN_SLOW only), unset or anything
 * else: all. tests/CMakeLists.txt registers every program as TEST (AK_TEST_SELECT=fast) and,
 * when its source holds AK_RUN_SLOW, also as TEST_slow (AK_TEST_SELECT=slow, ctest label
 * "slow"): `make test` runs ctest -LE slow (under a minute on 2 cores), .ci/run runs both.
 *
 * Under valgrind (.ci/run's memcheck stage, about 30 times slower) AK_TEST_SELECT=light runs the
 * fast cases except those marked AK_RUN_HEAVY (long runs of code that lighter cases of the same
 * program also run: they print "skip NAME (heavy)"), and AK_TEST_REPS(n, light_n) gives the
 * smaller count of a case's repetitions (random trials, not the length of a physical run). */
#ifndef ANIMKIT_TEST_H
#define ANIMKIT_TEST_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include <animkit/core.h>

static int ak_test_passed_ = 0, ak_test_failed_ = 0, ak_test_skipped_ = 0;
static int ak_test_cur_failed_ = 0;
static const char* ak_test_cur_name_ = "";

#define AK_TEST(name) static void ak_test_##name(void)

/* 0: run every case; 1: only AK_RUN (fast); 2: only AK_RUN_SLOW; 3: AK_RUN without the heavy
 * ones, fewer repetitions (light). */
static inline int ak_test_select_(void) {
    static int sel = -1;
    if (sel < 0) {
        const char* s = getenv("AK_TEST_SELECT");
        sel = !s ? 0 : strcmp(s, "fast") == 0 ? 1 : strcmp(s, "slow") == 0 ? 2 : strcmp(s, "light") == 0 ? 3 : 0;
    }
    return sel;
}

#define AK_TEST_REPS(n, light_n) (ak_test_select_() == 3 ? (light_n) : (n))

static inline double ak_test_now_(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

#define AK_RUN_AS_(name, slow)                                                             \
    do {                                                                                   \
        if (ak_test_select_() == ((slow) ? 1 : 2)) break;                                  \
        if ((slow) && ak_test_select_() == 3) break;                                       \
        ak_test_cur_failed_ = 0;                                                           \
        ak_test_cur_name_ = #name;                                                         \
        const double ak_t0_ = ak_test_now_();                                              \
        ak_test_##name();                                                                  \
        const double ak_dt_ = ak_test_now_() - ak_t0_;                                     \
        if (ak_test_cur_failed_) {                                                         \
            ++ak_test_failed_;                                                             \
            printf("FAIL %s (%.2f s)\n", #name, ak_dt_);                                   \
        } else {                                                                           \
            ++ak_test_passed_;                                                             \
            printf("ok   %s (%.2f s)\n", #name, ak_dt_);                                   \
        }                                                                                  \
        fflush(stdout);                                                                    \
    } while (0)

#define AK_RUN(name) AK_RUN_AS_(name, 0)
#define AK_RUN_HEAVY(name)                                                                 \
    do {                                                                                   \
        if (ak_test_select_() == 3) {                                                      \
            printf("skip %s (heavy: not under AK_TEST_SELECT=light)\n", #name);           \
            ++ak_test_skipped_;                                                            \
        } else {                                                                           \
            AK_RUN_AS_(name, 0);                                                           \
        }                                                                                  \
    } while (0)
#define AK_RUN_SLOW(name) AK_RUN_AS_(name, 1)

#define AK_FAIL_(...)                                                                      \
    do {                                                                                   \
        printf("  %s:%d: [%s] ", __FILE__, __LINE__, ak_test_cur_name_);                   \
        printf(__VA_ARGS__);                                                               \
        printf("\n");                                                                      \
        ak_test_cur_failed_ = 1;                                                           \
    } while (0)

#define AK_CHECK(cond)                                                                     \
    do {                                                                                   \
        if (!(cond)) AK_FAIL_("check failed: %s", #cond);                                  \
    } while (0)

#define AK_CHECK_MSG(cond, ...)                                                            \
    do {                                                                                   \
        if (!(cond)) AK_FAIL_(__VA_ARGS__);                                                \
    } while (0)

#define AK_CHECK_EQ(a, b)                                                                  \
    do {                                                                                   \
        long long ak_a_ = (long long)(a), ak_b_ = (long long)(b);                          \
        if (ak_a_ != ak_b_) AK_FAIL_("%s == %s: %lld vs %lld", #a, #b, ak_a_, ak_b_);      \
    } while (0)

/* |a - b| <= tol, and neither is NaN. */
#define AK_CHECK_NEAR(a, b, tol)                                                           \
    do {                                                                                   \
        double ak_a_ = (double)(a), ak_b_ = (double)(b), ak_t_ = (double)(tol);            \
        if (!(fabs(ak_a_ - ak_b_) <= ak_t_))                                               \
            AK_FAIL_("%s ~ %s: %.9g vs %.9g (diff %.3g > tol %.3g)", #a, #b, ak_a_, ak_b_,  \
                     fabs(ak_a_ - ak_b_), ak_t_);                                          \
    } while (0)

#define AK_CHECK_STREQ(a, b)                                                               \
    do {                                                                                   \
        const char *ak_a_ = (a), *ak_b_ = (b);                                             \
        if (!ak_a_ || !ak_b_ || strcmp(ak_a_, ak_b_) != 0)                                 \
            AK_FAIL_("%s == %s: \"%s\" vs \"%s\"", #a, #b, ak_a_ ? ak_a_ : "(null)",       \
                     ak_b_ ? ak_b_ : "(null)");                                            \
    } while (0)

/* Record a skipped part with its reason (printed as SKIP, counted separately). */
#define AK_SKIP(...)                                                                       \
    do {                                                                                   \
        printf("SKIP [%s] ", ak_test_cur_name_);                                           \
        printf(__VA_ARGS__);                                                               \
        printf("\n");                                                                      \
        ++ak_test_skipped_;                                                                \
    } while (0)

static inline int ak_test_finish(void) {
    printf("%d passed, %d failed, %d skipped\n", ak_test_passed_, ak_test_failed_, ak_test_skipped_);
    return ak_test_failed_ ? 1 : 0;
}

/* Counting allocator: blocks live now and ever made. fail_from > 0 makes allocation number
 * fail_from (1-based) and every later one return NULL; 0 never fails.
 *     ak_test_counter c = {.fail_from = 3};
 *     ak_allocator a = ak_test_counting_allocator(&c);   // the third allocation fails */
typedef struct ak_test_counter {
    int live, total, fail_from;
} ak_test_counter;
static inline void* ak_test_count_alloc(size_t size, void* user) {
    ak_test_counter* c = (ak_test_counter*)user;
    if (c->fail_from > 0 && c->total + 1 >= c->fail_from) return NULL;
    c->live++;
    c->total++;
    return malloc(size);
}
static inline void ak_test_count_free(void* p, void* user) {
    ((ak_test_counter*)user)->live--;
    free(p);
}
static inline ak_allocator ak_test_counting_allocator(ak_test_counter* c) {
    ak_allocator a = {ak_test_count_alloc, ak_test_count_free, c};
    return a;
}

/* Directory of the shared real assets: $ANIMKIT_ASSETS, else ../shared/assets relative to the
 * source tree (AK_SOURCE_DIR is defined by CMake), else NULL. */
static inline const char* ak_test_assets_dir(void) {
    struct stat st;
    const char* env = getenv("ANIMKIT_ASSETS");
    if (env && *env && stat(env, &st) == 0) return env;
#ifdef AK_SOURCE_DIR
    static char buf[1024];
    snprintf(buf, sizeof buf, "%s/../shared/assets", AK_SOURCE_DIR);
    if (stat(buf, &st) == 0) return buf;
#endif
    if (stat("../shared/assets", &st) == 0) return "../shared/assets";
    return NULL;
}

/* Full path of an asset (relative to the assets dir) into buf; NULL when absent. */
static inline const char* ak_test_asset(char* buf, size_t size, const char* rel) {
    const char* dir = ak_test_assets_dir();
    struct stat st;
    if (!dir) return NULL;
    snprintf(buf, size, "%s/%s", dir, rel);
    if (stat(buf, &st) != 0) return NULL;
    return buf;
}

#endif
