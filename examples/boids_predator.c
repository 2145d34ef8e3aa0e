/* Boids: 2000 birds (7 topological neighbours, 270-degree view) split into flocks that flee a
 * predator chasing them around a rock no bird ever enters. Prints the order parameter, the
 * smallest distance, neighbours per bird and obstacle contacts every second of simulated time. */
#include <animkit/boids.h>
#include <stdio.h>
#include <stdlib.h>

int main(void) {
    enum { N = 2000, STEPS = 300 };
    ak_boids_species species[2] = {
        {.max_speed = 4, .max_force = 10, .separation_weight = 1.5f, .separation_radius = 1,
         .alignment_weight = 1.5f, .alignment_radius = 2.5f, .cohesion_weight = 0.6f, .cohesion_radius = 2.5f,
         .view_angle = 270, .k_nearest = 7, .avoid_weight = 6, .avoid_distance = 2,
         .flee_mask = 1u << 1, .flee_weight = 3, .flee_radius = 5},
        {.max_speed = 4.5f, .max_force = 6, .separation_weight = 1, .separation_radius = 3,
         .pursue_mask = 1u << 0, .pursue_weight = 1, .pursue_radius = 10, .avoid_weight = 6, .avoid_distance = 2},
    };
    ak_boids_obstacle rock = {.kind = AK_BOIDS_SPHERE, .center = {0, 0, 0}, .radius = 3};
    ak_boids_params params = {.species = species, .species_count = 2, .obstacles = &rock, .obstacle_count = 1,
                              .bounds_min = {-15, -15, -15}, .bounds_max = {15, 15, 15}, .bounds_margin = 3};
    ak_vec3* pos = malloc(4 * N * sizeof(ak_vec3));
    uint8_t* kind = calloc(N, 1);
    if (!pos || !kind) return 1;
    ak_vec3 *vel = pos + N, *pos2 = pos + 2 * N, *vel2 = pos + 3 * N;
    ak_rng rng = ak_rng_make(42);
    for (int i = 0; i < N; ++i) {
        do {
            pos[i] = ak_vec3_make(ak_rng_range(&rng, -12, 12), ak_rng_range(&rng, -12, 12), ak_rng_range(&rng, -12, 12));
        } while (ak_vec3_length(pos[i]) < 3.5f);
        vel[i] = ak_vec3_scale(ak_vec3_normalize(ak_vec3_make(ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1),
                                                              ak_rng_range(&rng, -1, 1))), 2);
    }
    kind[0] = 1; /* the predator */
    uint64_t interactions = 0;
    uint32_t contacts = 0;
    ak_boids_step_job job = {.params = &params, .species = {kind, N}, .dt = 1.0f / 30.0f, .thread_count = 2,
                             .out_interaction_count = &interactions, .out_contact_count = &contacts};
    job.positions = (ak_vec3_cspan){pos, N};
    const size_t bytes = ak_boids_step_scratch_size(&job);
    uint8_t* scratch = malloc(bytes);
    uint8_t* mscratch = malloc(ak_boids_min_distance_scratch_size(N));
    if (!scratch || !mscratch) return 1;
    job.scratch = (ak_u8_span){scratch, bytes};
    printf("time  order  min-dist  neighbours  contacts\n");
    for (int s = 0; s < STEPS; ++s) {
        job.positions = (ak_vec3_cspan){pos, N};
        job.velocities = (ak_vec3_cspan){vel, N};
        job.out_positions = (ak_vec3_span){pos2, N};
        job.out_velocities = (ak_vec3_span){vel2, N};
        job.step_index = (uint64_t)s;
        ak_result r = ak_boids_step_run(&job);
        if (r != AK_OK) {
            fprintf(stderr, "step: %s\n", ak_result_string(r));
            return 1;
        }
        ak_vec3* t = pos;
        pos = pos2;
        pos2 = t;
        t = vel;
        vel = vel2;
        vel2 = t;
        if ((s + 1) % 30 == 0) {
            float dmin = 0;
            ak_boids_min_distance((ak_vec3_cspan){pos, N},
                                  (ak_u8_span){mscratch, ak_boids_min_distance_scratch_size(N)}, &dmin);
            printf("%4.1f  %.3f  %.3f     %.1f        %u\n", (s + 1) * job.dt,
                   (double)ak_boids_order((ak_vec3_cspan){vel + 1, N - 1}), (double)dmin,
                   (double)interactions / N, contacts);
        }
        for (int i = 0; i < N; ++i)
            if (ak_vec3_length(pos[i]) < rock.radius) {
                fprintf(stderr, "bird %d inside the rock\n", i);
                return 1;
            }
    }
    free(pos < pos2 ? pos : pos2);
    free(kind);
    free(scratch);
    free(mscratch);
    return 0;
}
