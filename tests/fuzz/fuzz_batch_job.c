/* libFuzzer target for batch manifest lines: ak_batch_job_parse (src/batch.c) on the input as
 * one job line. A parsed job must hold its documented invariants (a kind, a non-empty output
 * that fits, the paths its kind requires, parameters in range); a refused line must come with a
 * one-line message naming the job. Nothing is run (running would touch files). Built and run by
 * scripts/fuzz.sh:
 *     scripts/fuzz.sh 60 batch_job   (seeds: tests/fuzz/batch_job.seeds, batch_job.dict)
 * Any crash, leak or sanitizer report is a bug. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <animkit/batch.h>

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    ak_batch_job* job = malloc(sizeof *job);
    if (!job) return 0;
    ak_diag d;
    if (ak_batch_job_parse((const char*)data, size, "fuzz.jsonl:1", job, &d) == AK_OK) {
        if (job->kind == AK_BATCH_KIND_NONE || !job->output[0] || !memchr(job->output, 0, sizeof job->output)) abort();
        if (job->kind == AK_BATCH_RETARGET && (!job->source[0] || !job->target[0])) abort();
        if (job->kind == AK_BATCH_BAKE && !job->scene[0]) abort();
        if (job->kind == AK_BATCH_RENDER && !job->model[0]) abort();
        if (!(job->fps >= 1.0f && job->fps <= 1000.0f)) abort();
        if (job->width < 8 || job->width > 4096 || job->height < 8 || job->height > 4096) abort();
        if (job->steps < 0 || job->count < 0 || job->frame_every < 0) abort();
    } else if (strncmp(d.message, "fuzz.jsonl:1: ", 14) != 0 || strchr(d.message, '\n')) {
        abort();
    }
    free(job);
    return 0;
}
