/* batch_jobs: two jobs of a batch manifest run through ak_batch_run_job, the way `animkit
 * batch` and the Python package's Dask layer run each line: a particle scene baked to glTF and
 * a skeleton rendered to PNG. Each prints its row; the second pass finds the outputs up to date
 * and skips them. A third line is bad on purpose: it becomes a row with an error. */
#include <stdio.h>
#include <string.h>

#include <animkit/batch.h>

int main(void) {
    static const char* const manifest[] = {
        "{\"kind\": \"bake\", \"inputs\": {\"scene\": \"preset:fountain\"},"
        " \"parameters\": {\"sim\": \"particles\", \"steps\": 60}, \"output\": \"batch/fountain.glb\"}",
        "{\"kind\": \"render\", \"inputs\": {\"model\": \"builtin:cylinder\"},"
        " \"parameters\": {\"size\": [160, 120]}, \"output\": \"batch/cylinder.png\"}",
        "{\"kind\": \"render\", \"inputs\": {\"model\": \"builtin:cylinder\"}, \"parameters\": {\"size\": [1, 1]},"
        " \"output\": \"batch/bad.png\"}",
    };
    static ak_batch_row row; /* about 18 KB */
    int failed = 0;
    for (int pass = 0; pass < 2; ++pass) {
        printf("pass %d\n", pass + 1);
        for (long k = 0; k < 3; ++k) {
            char name[32];
            snprintf(name, sizeof name, "manifest:%ld", k + 1);
            ak_batch_desc d = {.name = name, .index = k};
            ak_batch_run_job(manifest[k], strlen(manifest[k]), &d, &row);
            printf("  %s\n", row.json);
            failed += row.status == AK_BATCH_FAILED;
        }
    }
    /* the bad line fails in both passes; the others ran, then were skipped */
    return failed == 2 ? 0 : 1;
}
