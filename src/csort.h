/* A stable counting sort split over threads (internal): the boids' dense layout and the fluid's
 * cell sort put n items into bucket order with it. The result is the one stable order (items of
 * a bucket in increasing index), so it never depends on the number of parts.
 *
 * Two levels, every pass O(n / parts) per part: (1) each part counts its chunk of the items
 * (part p: [n p / parts, n (p + 1) / parts)) per coarse block of buckets (block b: the buckets
 * k with k parts / buckets == b); (2) one thread turns the parts x parts counts into offsets;
 * (3) each part copies its chunk's (index, key) pairs to tmp, block-major and chunk-minor, so
 * that each block's items are contiguous and still in index order; (4) each part sorts one
 * block's items into its buckets' range (a plain counting sort over buckets / parts buckets,
 * which stay in cache). Parts meet between the steps (a barrier, or separate akp_run_tasks
 * calls: akp_csort_run). With one part, steps 1 and 3 do nothing and 4 reads the keys. */
#ifndef ANIMKIT_CSORT_H
#define ANIMKIT_CSORT_H

#include <stddef.h>
#include <stdint.h>

#include "tasks.h"

typedef struct akp_csort {
    const uint32_t* keys; /* [n], each < buckets */
    size_t n;             /* < 2^32 */
    uint32_t buckets;     /* >= 1 */
    uint32_t parts;       /* 1 .. AKP_TASKS_MAX */
    uint32_t* order;      /* [n] out: the items by bucket, then index */
    uint32_t* start;      /* [buckets + 1] out: bucket k is order[start[k] .. start[k + 1]) */
    uint32_t* tmp;        /* [2 n] scratch (parts > 1) */
    uint32_t counts[AKP_TASKS_MAX * AKP_TASKS_MAX]; /* [part][block] counts, then offsets */
} akp_csort;

void akp_csort_count(akp_csort* s, uint32_t part);   /* step 1, for each part */
void akp_csort_offsets(akp_csort* s);                /* step 2, once */
void akp_csort_scatter(akp_csort* s, uint32_t part); /* step 3, for each part */
void akp_csort_finish(akp_csort* s, uint32_t part);  /* step 4, for each part */
/* All four steps, the parts on the worker team (akp_run_tasks). */
void akp_csort_run(akp_csort* s);

#endif
