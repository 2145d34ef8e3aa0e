/* animkit batch: run a manifest of jobs (JSON lines), or one shard of it, through the library's
 * ak_batch_run_job; one result row per job on stdout. docs/batch.md. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

static const char* const usage =
    "usage: animkit batch MANIFEST.jsonl [--shard I/N] [--out DIR] [--force]\n"
    "Run the jobs of MANIFEST (one JSON object a line: {\"kind\": \"retarget\"|\"bake\"|\"render\",\n"
    "\"inputs\": {...}, \"parameters\": {...}, \"output\": PATH}; docs/batch.md) and print one JSON row\n"
    "per job on stdout: inputs' FNV-1a 64 hashes, animkit version, parameters, seconds, error.\n"
    "A job whose output exists with a record (OUTPUT.batch.json) of the same inputs' hashes,\n"
    "parameters and version is skipped, so a re-run does only what is missing or stale.\n"
    "Blank lines are skipped; every other line is a job, numbered from 0.\n"
    "  --shard I/N  run the jobs whose number k has k % N == I (0 <= I < N <= 1000000): a Slurm\n"
    "               array task or Kubernetes indexed job passes its 0-based index as I\n"
    "  --out DIR    relative outputs go under DIR (default: the manifest's folder); relative\n"
    "               inputs are always taken from the manifest's folder\n"
    "  --force      run every job of the shard even when its output is up to date\n"
    "Exit status: 0 when every job ran or was skipped, 1 when a job failed (its row says why)\n"
    "or the manifest cannot be read, 2 on a usage error.\n";

/* "I/N" with 0 <= I < N <= 1000000. */
static bool parse_shard(const char* s, long* i, long* n) {
    const char* slash = strchr(s, '/');
    if (!slash || slash == s || (size_t)(slash - s) >= 16) return false;
    char left[16];
    memcpy(left, s, (size_t)(slash - s));
    left[slash - s] = '\0';
    return cli_parse_int(left, 0, 999999, i) && cli_parse_int(slash + 1, 1, 1000000, n) && *i < *n;
}

int cmd_batch(int argc, char** argv) {
    static const cli_opt opts[] = {{"--shard", NULL, true}, {"--out", NULL, true}, {"--force", NULL, false}};
    cli_args a;
    int rc = cli_parse("batch", argc, argv, opts, sizeof opts / sizeof opts[0], &a);
    if (rc) return rc;
    if (a.help) {
        fputs(usage, stdout);
        return CLI_OK;
    }
    if (a.pos_count != 1) return cli_usage("batch", "expected one MANIFEST.jsonl");
    long shard = 0, shards = 1;
    const char* sv = CLI_GET(&a, "--shard");
    if (sv && !parse_shard(sv, &shard, &shards))
        return cli_usage("batch", "--shard '%s' is not I/N with 0 <= I < N <= 1000000", sv);
    const char* manifest = a.pos[0];
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", manifest);
    char* slash = strrchr(dir, '/');
    if (slash)
        slash[slash == dir ? 1 : 0] = '\0';
    else
        dir[0] = '\0'; /* the current folder: paths as written */
    const char* out = CLI_GET(&a, "--out");
    FILE* f = fopen(manifest, "rb");
    if (!f) return cli_fail("batch", "%s: cannot open the manifest", manifest);
    ak_batch_row* row = malloc(sizeof *row);
    char* line = NULL;
    size_t cap = 0;
    if (!row) {
        fclose(f);
        return cli_fail("batch", "out of memory");
    }
    long index = 0, line_no = 0, ran = 0, skipped = 0, failed = 0;
    ssize_t got;
    while ((got = getline(&line, &cap, f)) >= 0) {
        ++line_no;
        size_t n = (size_t)got;
        while (n && (line[n - 1] == '\n' || line[n - 1] == '\r')) --n;
        size_t k = 0;
        while (k < n && (line[k] == ' ' || line[k] == '\t')) ++k;
        if (k == n) continue; /* blank */
        const long job = index++;
        if (!ak_batch_in_shard(job, shard, shards)) continue;
        char name[4200];
        snprintf(name, sizeof name, "%s:%ld", manifest, line_no);
        ak_batch_desc d = {.name = name, .input_dir = dir, .output_dir = out ? out : dir, .index = job,
                           .force = CLI_GET(&a, "--force") != NULL};
        ak_batch_run_job(line, n, &d, row);
        puts(row->json);
        fflush(stdout);
        if (row->status == AK_BATCH_RAN) {
            ++ran;
            cli_wrote(row->output, "job %ld in %.2f s", job, row->seconds);
        } else if (row->status == AK_BATCH_SKIPPED) {
            ++skipped;
        } else {
            ++failed;
            cli_fail("batch", "job %ld: %s", job, row->error);
        }
    }
    const bool read_error = ferror(f) != 0;
    free(line);
    free(row);
    fclose(f);
    if (read_error) return cli_fail("batch", "%s: read error after %ld jobs", manifest, index);
    if (!cli_quiet)
        fprintf(stderr, "batch: shard %ld/%ld of %s: %ld job%s, %ld ran, %ld skipped (up to date), %ld failed\n", shard,
                shards, manifest, ran + skipped + failed, cli_plural((size_t)(ran + skipped + failed)), ran, skipped,
                failed);
    return failed ? CLI_BAD_INPUT : CLI_OK;
}
