/* Cloth: the same hanging cloth with XPBD, plain PBD and mass-spring.
 * Prints the settled stretch of each at several substep counts: XPBD's stays put, PBD's does not,
 * and the spring solver blows up until its step is small enough. */
#include <stdio.h>
#include <stdlib.h>

#include <animkit/animkit.h>

enum { W = 10, H = 10 };

/* Mean stretch of the columns after 3 s, or -1 when the run blew up. */
static float settle(ak_cloth_solver solver, uint32_t substeps) {
    uint32_t pins[W];
    for (uint32_t i = 0; i < W; ++i) pins[i] = i; /* the top row */
    ak_cloth_desc desc = {
        .solver = solver,
        .grid_width = W, .grid_height = H, .spacing = 0.05f,
        .grid_axis_v = {0, -1, 0},                /* hanging down */
        .pins = {pins, W},
        .stretch_stiffness = 50.0f,               /* N/m: a stretchy knit */
        .area_density = 0.5f,
        .bending = AK_CLOTH_BEND_NONE,
        .pbd_stiffness = 0.1f,
    };
    ak_cloth* cloth = NULL;
    if (ak_cloth_create(&desc, NULL, &cloth) != AK_OK) return -1.0f;
    const size_t n = ak_cloth_vertex_count(cloth);
    ak_vec3* x = malloc(n * sizeof *x);
    ak_vec3* v = calloc(n, sizeof *v);
    ak_cloth_rest_positions(cloth, (ak_vec3_span){x, n});
    ak_cloth_step_job job = {
        .cloth = cloth, .dt = 1.0f / 60.0f, .substeps = substeps, .iterations = 4,
        .gravity = {0, -9.81f, 0}, .damping = 4.0f,
        .positions = {x, n}, .velocities = {v, n},
    };
    const size_t size = ak_cloth_step_scratch_size(&job);
    job.scratch = (ak_u8_span){malloc(size), size};
    float stretch = -1.0f;
    ak_result r = AK_OK;
    for (int f = 0; f < 180 && r == AK_OK; ++f) r = ak_cloth_step_run(&job);
    if (r == AK_OK) {
        double sum = 0.0;
        for (uint32_t j = 0; j + 1 < H; ++j)
            for (uint32_t i = 0; i < W; ++i) sum += ak_vec3_distance(x[j * W + i], x[(j + 1) * W + i]) / 0.05f - 1.0f;
        stretch = (float)(sum / ((H - 1) * W));
    }
    free(job.scratch.ptr);
    free(x);
    free(v);
    ak_cloth_destroy(cloth);
    return stretch;
}

int main(void) {
    const char* names[3] = {"XPBD", "PBD", "mass-spring"};
    const ak_cloth_solver solvers[3] = {AK_CLOTH_XPBD, AK_CLOTH_PBD, AK_CLOTH_SPRINGS};
    const uint32_t substeps[4] = {2, 5, 20, 80};
    printf("settled mean stretch of a hanging 10 x 10 cloth (k = 50 N/m), 1/60 s frames\n");
    printf("%-12s", "substeps");
    for (int s = 0; s < 4; ++s) printf("%10u", substeps[s]);
    printf("\n");
    for (int k = 0; k < 3; ++k) {
        printf("%-12s", names[k]);
        for (int s = 0; s < 4; ++s) {
            const float st = settle(solvers[k], substeps[s]);
            if (st < 0.0f) printf("%10s", "blow-up");
            else printf("%9.2f%%", 100.0 * (double)st);
        }
        printf("\n");
    }
    return 0;
}
