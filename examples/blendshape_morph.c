/* blendshape_morph: a sphere with two local morph targets ("bulge" and "pinch"), built into a
 * sparse set, animated by hand-made weight curves, applied before any skinning. Prints, per
 * frame, the weights, the enclosed volume and the top vertex; also shows expression transfer. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <animkit/blendshape.h>

enum { SLICES = 24, STACKS = 16, V = (STACKS - 1) * SLICES + 2, T = 2 * SLICES * (STACKS - 1), K = 2 };

static void sphere(ak_vec3* p, ak_vec3* n, uint32_t* idx) {
    size_t v = 0, t = 0;
    p[v] = n[v] = ak_vec3_make(0, 1, 0), ++v;
    for (int i = 1; i < STACKS; ++i)
        for (int j = 0; j < SLICES; ++j) {
            float th = AK_PI * (float)i / STACKS, ph = AK_TWO_PI * (float)j / SLICES;
            p[v] = n[v] = ak_vec3_make(sinf(th) * cosf(ph), cosf(th), sinf(th) * sinf(ph)), ++v;
        }
    p[v] = n[v] = ak_vec3_make(0, -1, 0), ++v;
    for (uint32_t j = 0; j < SLICES; ++j) idx[t++] = 0, idx[t++] = 1 + (j + 1) % SLICES, idx[t++] = 1 + j;
    for (uint32_t i = 0; i + 2 < STACKS; ++i)
        for (uint32_t j = 0; j < SLICES; ++j) {
            uint32_t a = 1 + i * SLICES + j, b = 1 + i * SLICES + (j + 1) % SLICES;
            idx[t++] = a, idx[t++] = b, idx[t++] = b + SLICES;
            idx[t++] = a, idx[t++] = b + SLICES, idx[t++] = a + SLICES;
        }
    for (uint32_t j = 0; j < SLICES; ++j) {
        uint32_t base = 1 + (STACKS - 2) * SLICES;
        idx[t++] = V - 1, idx[t++] = base + j, idx[t++] = base + (j + 1) % SLICES;
    }
}

int main(void) {
    static ak_vec3 pos[V], nrm[V], deltas[K * V], out[V], out_n[V], other[V];
    static uint32_t idx[3 * T];
    sphere(pos, nrm, idx);
    /* Target 0 bulges the top cap outwards, target 1 pinches the +X side inwards. */
    for (size_t i = 0; i < V; ++i) {
        deltas[i] = pos[i].y > 0.6f ? ak_vec3_scale(nrm[i], 0.4f * (pos[i].y - 0.6f) / 0.4f) : ak_vec3_zero();
        deltas[V + i] = pos[i].x > 0.7f ? ak_vec3_scale(nrm[i], -0.25f) : ak_vec3_zero();
    }
    ak_blendshape_set* set = NULL;
    ak_blendshape_set_desc desc = {.vertex_count = V, .target_count = K, .deltas = {deltas, K * V}};
    ak_result r = ak_blendshape_set_create(&desc, NULL, &set);
    if (r != AK_OK) {
        fprintf(stderr, "set: %s\n", ak_result_string(r));
        return 1;
    }
    printf("%d vertices; target 0 moves %zu (%s), target 1 moves %zu (%s)\n", V, ak_blendshape_set_moved_count(set, 0),
           ak_blendshape_set_target_is_sparse(set, 0) ? "sparse" : "dense", ak_blendshape_set_moved_count(set, 1),
           ak_blendshape_set_target_is_sparse(set, 1) ? "sparse" : "dense");
    printf("%6s %7s %7s %10s %9s\n", "t", "bulge", "pinch", "volume", "top y");
    for (int f = 0; f <= 12; ++f) {
        float t = (float)f / 12.0f;
        /* Weights as a clip's morph channel would give them (sampled elsewhere). */
        float w[K] = {0.5f - 0.5f * cosf(AK_TWO_PI * t), t};
        ak_blendshape_job job = {.set = set, .weights = AK_SPAN(w), .base_positions = {pos, V},
                                 .base_normals = {nrm, V}, .out_positions = {out, V}, .out_normals = {out_n, V}};
        if ((r = ak_blendshape_run(&job)) != AK_OK) {
            fprintf(stderr, "blend: %s\n", ak_result_string(r));
            return 1;
        }
        /* out / out_n would now go to the skinning job (blend shapes come first). */
        double vol = ak_volume_compute((ak_vec3_cspan){out, V}, (ak_u32_cspan){idx, 3 * T});
        printf("%6.3f %7.3f %7.3f %10.5f %9.5f\n", t, w[0], w[1], vol, out[0].y);
    }
    /* Expression transfer: the same deltas on a taller character with the same topology. */
    for (size_t i = 0; i < V; ++i) other[i] = ak_vec3_mul(pos[i], ak_vec3_make(0.8f, 1.5f, 0.8f));
    float w[K] = {1.0f, 0.0f};
    ak_blendshape_job job = {.set = set, .weights = AK_SPAN(w), .base_positions = {other, V},
                             .out_positions = {out, V}};
    if (ak_blendshape_run(&job) != AK_OK) return 1;
    printf("transfer: top of the taller base %.3f -> %.3f with full bulge\n", other[0].y, out[0].y);
    ak_blendshape_set_destroy(set);
    return 0;
}
