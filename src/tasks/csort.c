/* The stable counting sort over threads (src/csort.h). */
#include "csort.h"

static size_t chunk(const akp_csort* s, uint32_t part) { return (size_t)((uint64_t)s->n * part / s->parts); }

static uint32_t block_of(const akp_csort* s, uint32_t key) {
    return (uint32_t)((uint64_t)key * s->parts / s->buckets);
}

/* The first bucket of block b: the least k with k parts / buckets >= b. */
static uint32_t block_lo(const akp_csort* s, uint32_t b) {
    return (uint32_t)(((uint64_t)b * s->buckets + s->parts - 1) / s->parts);
}

void akp_csort_count(akp_csort* s, uint32_t part) {
    if (s->parts < 2) return;
    uint32_t* c = s->counts + (size_t)part * s->parts;
    for (uint32_t b = 0; b < s->parts; ++b) c[b] = 0;
    for (size_t i = chunk(s, part), e = chunk(s, part + 1); i < e; ++i) c[block_of(s, s->keys[i])]++;
}

void akp_csort_offsets(akp_csort* s) {
    s->start[s->buckets] = (uint32_t)s->n;
    if (s->parts < 2) return;
    uint32_t run = 0; /* block-major, part-minor */
    for (uint32_t b = 0; b < s->parts; ++b)
        for (uint32_t p = 0; p < s->parts; ++p) {
            uint32_t* c = &s->counts[(size_t)p * s->parts + b];
            const uint32_t k = *c;
            *c = run;
            run += k;
        }
}

void akp_csort_scatter(akp_csort* s, uint32_t part) {
    if (s->parts < 2) return;
    uint32_t cur[AKP_TASKS_MAX];
    for (uint32_t b = 0; b < s->parts; ++b) cur[b] = s->counts[(size_t)part * s->parts + b];
    uint32_t *idx = s->tmp, *key = s->tmp + s->n;
    for (size_t i = chunk(s, part), e = chunk(s, part + 1); i < e; ++i) {
        const uint32_t k = s->keys[i], a = cur[block_of(s, k)]++;
        idx[a] = (uint32_t)i;
        key[a] = k;
    }
}

void akp_csort_finish(akp_csort* s, uint32_t part) {
    const bool one = s->parts < 2;
    const uint32_t lo = one ? 0 : block_lo(s, part), hi = one ? s->buckets : block_lo(s, part + 1);
    /* this block's items: tmp[b0, b1) (in index order), or all of keys with one part */
    const size_t b0 = one ? 0 : s->counts[part];
    const size_t b1 = one ? s->n : part + 1 < s->parts ? s->counts[part + 1] : s->n;
    const uint32_t* idx = one ? NULL : s->tmp;
    const uint32_t* key = one ? s->keys : s->tmp + s->n;
    uint32_t* start = s->start;
    for (uint32_t k = lo; k < hi; ++k) start[k] = 0;
    for (size_t a = b0; a < b1; ++a) start[key[a]]++;
    uint32_t run = (uint32_t)b0;
    for (uint32_t k = lo; k < hi; ++k) {
        const uint32_t c = start[k];
        start[k] = run;
        run += c;
    }
    for (size_t a = b0; a < b1; ++a) s->order[start[key[a]]++] = idx ? idx[a] : (uint32_t)a;
    /* start[k] is now the end of bucket k: shift back to starts */
    if (hi > lo) {
        for (uint32_t k = hi - 1; k > lo; --k) start[k] = start[k - 1];
        start[lo] = (uint32_t)b0;
    }
}

typedef struct csort_task {
    akp_csort* s;
    uint32_t part;
    int step;
} csort_task;

static void* csort_thread(void* arg) {
    const csort_task* t = (const csort_task*)arg;
    if (t->step == 1) akp_csort_count(t->s, t->part);
    else if (t->step == 3) akp_csort_scatter(t->s, t->part);
    else akp_csort_finish(t->s, t->part);
    return NULL;
}

void akp_csort_run(akp_csort* s) {
    if (s->parts < 1) s->parts = 1;
    if (s->parts > AKP_TASKS_MAX) s->parts = AKP_TASKS_MAX;
    csort_task tasks[AKP_TASKS_MAX];
    for (uint32_t p = 0; p < s->parts; ++p) tasks[p] = (csort_task){s, p, 1};
    if (s->parts > 1) akp_run_tasks(csort_thread, tasks, sizeof tasks[0], s->parts);
    akp_csort_offsets(s);
    for (uint32_t p = 0; p < s->parts; ++p) tasks[p].step = 3;
    if (s->parts > 1) akp_run_tasks(csort_thread, tasks, sizeof tasks[0], s->parts);
    for (uint32_t p = 0; p < s->parts; ++p) tasks[p].step = 4;
    akp_run_tasks(csort_thread, tasks, sizeof tasks[0], s->parts);
}
