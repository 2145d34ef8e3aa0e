/* core_allocator_rng: the shared pieces every module uses. A counting allocator passed to
 * ak_clip_build (every byte it hands out comes back at ak_clip_destroy), result codes and
 * diagnostics from a clip that fails its checks, and the seeded random number generator
 * (same seed, same numbers; a sample mean and variance against the uniform law's 1/2 and 1/12). */
#include <animkit/clip.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Counts live bytes and calls. Each block carries a 16-byte header holding its size, so the
 * memory handed out stays 16-byte aligned as ak_allocator requires. */
typedef struct counter {
    size_t live, peak, calls;
} counter;

static void* count_alloc(size_t size, void* user) {
    counter* c = user;
    unsigned char* p = malloc(size + 16);
    if (!p) return NULL;
    memcpy(p, &size, sizeof size);
    c->live += size, c->calls += 1;
    if (c->live > c->peak) c->peak = c->live;
    return p + 16;
}

static void count_free(void* ptr, void* user) {
    counter* c = user;
    unsigned char* p = (unsigned char*)ptr - 16;
    size_t size;
    memcpy(&size, p, sizeof size);
    c->live -= size;
    free(p);
}

int main(void) {
    printf("animkit %s, %d result codes\n", ak_version_string(), (int)AK_RESULT_COUNT);

    /* A two-key rotation clip built through the counting allocator. */
    counter c = {0};
    ak_allocator alloc = {count_alloc, count_free, &c};
    const float times[2] = {0.0f, 1.0f};
    const float rot[8] = {0, 0, 0, 1, 0, 0.7071068f, 0, 0.7071068f};
    ak_raw_channel ch = {.target = AK_CHANNEL_ROTATION, .index = 0, .key_count = 2, .times = times, .values = rot};
    ak_raw_clip raw = {.name = "turn", .channels = &ch, .channel_count = 1, .joint_count = 1};
    ak_clip* clip = NULL;
    ak_diag diag;
    ak_result r = ak_clip_build(&raw, &alloc, &clip, &diag);
    printf("build: %s; %zu allocation%s, %zu bytes live\n", ak_result_name(r), c.calls, c.calls == 1 ? "" : "s", c.live);
    ak_clip_destroy(clip);
    printf("after destroy: %zu bytes live (peak %zu)\n", c.live, c.peak);
    if (r != AK_OK || c.live != 0) return 1;

    /* The same channel with its keys at one time: the build refuses and says where. */
    const float same[2] = {0.5f, 0.5f};
    ch.times = same;
    r = ak_clip_build(&raw, &alloc, &clip, &diag);
    printf("duplicate key times: %s (%s)\n  diag: %s\n", ak_result_name(r), ak_result_string(r), diag.message);
    if (r == AK_OK || clip != NULL || c.live != 0) return 1;

    /* Random numbers: reproducible from the seed, uniform on [0, 1). */
    ak_rng a = ak_rng_make(42), b = ak_rng_make(42);
    int same_seq = 1;
    for (int i = 0; i < 1000; ++i) same_seq &= ak_rng_u32(&a) == ak_rng_u32(&b);
    ak_rng g = ak_rng_make(7);
    const int n = 200000;
    double sum = 0.0, sum_sq = 0.0;
    for (int i = 0; i < n; ++i) {
        double x = ak_rng_float(&g);
        sum += x, sum_sq += x * x;
    }
    double mean = sum / n, var = sum_sq / n - mean * mean;
    printf("seed 42 twice: %s; %d floats of seed 7: mean %.4f (1/2), variance %.4f (1/12 = %.4f)\n",
           same_seq ? "same sequence" : "DIFFERENT", n, mean, var, 1.0 / 12.0);
    printf("range [-2, 3): %.4f %.4f %.4f\n", (double)ak_rng_range(&g, -2, 3), (double)ak_rng_range(&g, -2, 3),
           (double)ak_rng_range(&g, -2, 3));
    return same_seq && mean > 0.49 && mean < 0.51 && var > 0.08 && var < 0.087 ? 0 : 1;
}
