/* libFuzzer target for the implicit skinning cache file: ak_skin_implicit_read_file
 * (src/skin/implicit.c) on the input written to a temporary file, with the key the input
 * claims (bytes 8..15), so the fuzzer gets past the key check. A file that reads must give an
 * object that deforms without a crash and without NaN (identity palette and one turned joint).
 * Built and run by scripts/fuzz.sh:
 *     scripts/fuzz.sh 60 implicit_cache
 * Any crash, leak or sanitizer report is a bug. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <animkit/skin.h>

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    char path[64];
    snprintf(path, sizeof path, "/tmp/fuzz_implicit_%ld.akis", (long)getpid());
    FILE* f = fopen(path, "wb");
    if (!f) return 0;
    fwrite(data, 1, size, f);
    fclose(f);
    uint64_t key = 0;
    if (size >= 16)
        for (int i = 7; i >= 0; --i) key = (key << 8) | data[8 + i];
    ak_skin_implicit* o = NULL;
    ak_result r = ak_skin_implicit_read_file(path, key, NULL, &o);
    remove(path);
    if (r != AK_OK) {
        if (o) abort();
        return 0;
    }
    /* the object's joint count is at most 65535 (the reader checks): a palette that long fits */
    size_t n = ak_skin_implicit_vertex_count(o), jc = 65535;
    if (n > 100000) {
        ak_skin_implicit_destroy(o);
        return 0;
    }
    ak_mat4* pal = malloc(jc * sizeof *pal);
    ak_vec3* out = malloc(n * sizeof *out);
    size_t ss = ak_skin_implicit_scratch_size(o, jc);
    unsigned char* scratch = malloc(ss);
    if (pal && out && scratch) {
        for (size_t k = 0; k < jc; ++k) pal[k] = ak_mat4_identity();
        for (int pass = 0; pass < 2; ++pass) {
            if (pass == 1) pal[1 % jc] = ak_mat4_from_quat(ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), 1.2f));
            ak_skin_implicit_job job = {.implicit = o, .palette = {pal, jc}, .scratch = {scratch, ss},
                                        .out_positions = {out, n}, .iterations = 4, .relax_rounds = 1};
            if (ak_skin_implicit_run(&job) == AK_OK)
                for (size_t v = 0; v < n; ++v)
                    if (!ak_vec3_is_finite(out[v])) abort();
        }
    }
    free(pal), free(out), free(scratch);
    ak_skin_implicit_destroy(o);
    return 0;
}
