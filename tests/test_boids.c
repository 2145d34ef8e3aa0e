/* Tests for boids: neighbour sets against an independent brute force, each rule against
 * hand-computed values, limits every step, the order parameter under alignment, the
 * separation bound from energy, obstacles never entered, determinism across threads and
 * between the grid and the naive path. */
#include <animkit/boids.h>
#include <stdlib.h>
#include <string.h>

#include "ak_test.h"

/* ---- helpers ---------------------------------------------------------------------------- */

typedef struct flock {
    size_t n;
    ak_vec3 *p, *v, *p2, *v2, *w;
    uint8_t* s;
    uint8_t* scratch;
    size_t scratch_size;
} flock;

static flock flock_make(size_t n) {
    flock f = {n, calloc(n, sizeof(ak_vec3)), calloc(n, sizeof(ak_vec3)), calloc(n, sizeof(ak_vec3)),
               calloc(n, sizeof(ak_vec3)), calloc(n, sizeof(ak_vec3)), calloc(n, 1), NULL, 0};
    return f;
}

static void flock_free(flock* f) {
    free(f->p);
    free(f->v);
    free(f->p2);
    free(f->v2);
    free(f->w);
    free(f->s);
    free(f->scratch);
}

static void flock_random(flock* f, uint64_t seed, float extent, float speed, bool planar) {
    ak_rng r = ak_rng_make(seed);
    for (size_t i = 0; i < f->n; ++i) {
        f->p[i] = ak_vec3_make(ak_rng_range(&r, -extent, extent), planar ? 0.0f : ak_rng_range(&r, -extent, extent),
                               ak_rng_range(&r, -extent, extent));
        f->v[i] = ak_vec3_make(ak_rng_range(&r, -speed, speed), planar ? 0.0f : ak_rng_range(&r, -speed, speed),
                               ak_rng_range(&r, -speed, speed));
    }
}

static ak_boids_step_job job_for(flock* f, const ak_boids_params* prm, float dt) {
    ak_boids_step_job j = {
        .params = prm,
        .positions = {f->p, f->n},
        .velocities = {f->v, f->n},
        .species = {f->s, f->n},
        .wander = {f->w, f->n},
        .dt = dt,
        .out_positions = {f->p2, f->n},
        .out_velocities = {f->v2, f->n},
    };
    const size_t need = ak_boids_step_scratch_size(&j);
    if (need > f->scratch_size) {
        free(f->scratch);
        f->scratch = malloc(need);
        f->scratch_size = need;
    }
    j.scratch = (ak_u8_span){f->scratch, f->scratch_size};
    return j;
}

static ak_result step(flock* f, const ak_boids_params* prm, float dt, uint32_t threads, bool naive, uint64_t k) {
    ak_boids_step_job j = job_for(f, prm, dt);
    j.thread_count = threads;
    j.use_naive = naive;
    j.step_index = k;
    j.seed = 7;
    ak_result r = ak_boids_step_run(&j);
    if (r == AK_OK) {
        memcpy(f->p, f->p2, f->n * sizeof(ak_vec3));
        memcpy(f->v, f->v2, f->n * sizeof(ak_vec3));
    }
    return r;
}

static double len3(ak_vec3 a) { return sqrt((double)a.x * a.x + (double)a.y * a.y + (double)a.z * a.z); }

/* ---- validity ---------------------------------------------------------------------------- */

/* Every coordinate of every agent, in the vector part of the check and in its tail: NaN,
 * infinities and magnitudes beyond 1e15 m are AK_ERR_BAD_DATA; +-1e15 itself is accepted. */
AK_TEST(validate_every_coordinate) {
    flock f = flock_make(41); /* 123 floats: 7 blocks of 16 and a tail of 11 */
    flock_random(&f, 3, 1.0f, 1.0f, false);
    ak_boids_species sp = {.separation_weight = 1};
    ak_boids_params prm = {.species = &sp, .species_count = 1};
    ak_boids_step_job j = job_for(&f, &prm, 0.1f);
    AK_CHECK_EQ(ak_boids_step_validate(&j), AK_OK);
    const float bad[5] = {NAN, INFINITY, -INFINITY, 1.0001e15f, -2e15f}, good[2] = {1e15f, -1e15f};
    int wrong = 0;
    for (int arr = 0; arr < 2; ++arr)
        for (size_t k = 0; k < 3 * f.n; ++k) {
            float* x = (float*)(void*)(arr ? f.v : f.p) + k;
            const float keep = *x;
            for (int b = 0; b < 5; ++b) {
                *x = bad[b];
                wrong += ak_boids_step_validate(&j) != AK_ERR_BAD_DATA;
            }
            for (int g = 0; g < 2; ++g) {
                *x = good[g];
                wrong += ak_boids_step_validate(&j) != AK_OK;
            }
            *x = keep;
        }
    AK_CHECK_EQ(wrong, 0);
    flock_free(&f);
}

/* ak_boids_step_run checks the agents' data on its threads when there are many (70,000 here,
 * two species, wander on): a bad species index, a non-finite or too large position, velocity
 * or wander offset at the start, either side of a part boundary or the end, on 1, 2 and 3
 * threads, gives what ak_boids_step_validate (the serial check) says, with nothing written;
 * a bad species anywhere wins over bad data anywhere (the serial check's order of rules), and
 * bad data wins over an output span too small. All data good, the step runs. */
AK_TEST(validation_scan_split_over_threads) {
    enum { N = 70000 };
    flock f = flock_make(N);
    flock_random(&f, 11, 20.0f, 1.0f, false);
    for (size_t i = 0; i < N; ++i) f.s[i] = (uint8_t)(i & 1u);
    ak_boids_species sp[2] = {{.separation_weight = 1, .wander_weight = 0.5f}, {.cohesion_weight = 1}};
    ak_boids_params prm = {.species = sp, .species_count = 2};
    ak_boids_step_job j = job_for(&f, &prm, 0.05f);
    AK_CHECK_EQ(ak_boids_step_validate(&j), AK_OK);
    /* the first agent, the last of a part and the first of the next (3 threads), the last of
     * the first part (2 threads), the last agent */
    const size_t at[5] = {0, N / 3 - 1, N / 3, N / 2 - 1, N - 1};
    const size_t bytes = N * sizeof(ak_vec3);
    memset(f.p2, 0x5a, bytes);
    memset(f.v2, 0xa5, bytes);
    ak_vec3* copy = malloc(2 * bytes);
    AK_CHECK(copy != NULL);
    if (!copy) return;
    memcpy(copy, f.p2, bytes);
    memcpy(copy + N, f.v2, bytes);
    int wrong = 0;
    for (uint32_t threads = 1; threads <= 3; ++threads) {
        j.thread_count = threads;
        for (size_t k = 0; k < 5; ++k)
            for (int what = 0; what < 6; ++what) {
                const size_t i = at[k], other = at[4 - k];
                const ak_vec3 keep_p = f.p[i], keep_v = f.v[i], keep_w = f.w[i];
                const uint8_t keep_s = f.s[other];
                ak_boids_step_job b = j;
                ak_result want = AK_ERR_BAD_DATA;
                if (what == 0) f.p[i].y = NAN;
                if (what == 1) f.v[i].z = INFINITY;
                if (what == 2) f.w[i].x = -2e15f;
                if (what == 3) f.s[other] = 2, want = AK_ERR_BAD_INDEX;
                if (what == 4) f.p[i].x = NAN, f.s[other] = 7, want = AK_ERR_BAD_INDEX;
                if (what == 5) f.v[i].x = NAN, b.out_velocities.count = N - 1;
                const ak_result v = ak_boids_step_validate(&b), r = ak_boids_step_run(&b);
                if (v != want || r != want || memcmp(copy, f.p2, bytes) != 0 || memcmp(copy + N, f.v2, bytes) != 0) {
                    ++wrong;
                    printf("  %u threads, agent %zu, case %d: validate %d, run %d, want %d\n", threads, i, what, (int)v,
                           (int)r, (int)want);
                }
                f.p[i] = keep_p, f.v[i] = keep_v, f.w[i] = keep_w, f.s[other] = keep_s;
            }
        AK_CHECK_EQ(ak_boids_step_run(&j), AK_OK);
        AK_CHECK(memcmp(copy, f.p2, bytes) != 0); /* it did write */
        memset(f.p2, 0x5a, bytes);
        memset(f.v2, 0xa5, bytes);
    }
    AK_CHECK_EQ(wrong, 0);
    free(copy);
    flock_free(&f);
}

AK_TEST(validate_rules) {
    ak_boids_step_job zero = {0};
    AK_CHECK_EQ(ak_boids_step_validate(&zero), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_boids_step_validate(NULL), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_boids_step_run(&zero), AK_ERR_NULL_ARG);
    flock f = flock_make(4);
    flock_random(&f, 1, 1.0f, 1.0f, false);
    ak_boids_species sp = {.separation_weight = 1};
    ak_boids_params prm = {.species = &sp, .species_count = 1};
    ak_boids_step_job j = job_for(&f, &prm, 0.1f);
    AK_CHECK_EQ(ak_boids_step_validate(&j), AK_OK);
    ak_boids_step_job b = j;
    b.dt = 0.0f;
    AK_CHECK_EQ(ak_boids_step_validate(&b), AK_ERR_BAD_ARG);
    b = j;
    b.out_positions.ptr = NULL;
    AK_CHECK_EQ(ak_boids_step_validate(&b), AK_ERR_NULL_ARG);
    b = j;
    b.out_positions = (ak_vec3_span){(ak_vec3*)f.p, f.n};
    AK_CHECK_EQ(ak_boids_step_validate(&b), AK_ERR_BAD_ARG);
    b = j;
    b.thread_count = 65;
    AK_CHECK_EQ(ak_boids_step_validate(&b), AK_ERR_BAD_ARG);
    b = j;
    b.velocities.count = 3;
    AK_CHECK_EQ(ak_boids_step_validate(&b), AK_ERR_SPAN_SMALL);
    b = j;
    b.scratch.count = 0;
    AK_CHECK_EQ(ak_boids_step_validate(&b), AK_ERR_SPAN_SMALL);
    b.use_naive = true; /* the naive path needs no scratch */
    AK_CHECK_EQ(ak_boids_step_validate(&b), AK_OK);
    b = j;
    b.positions.count = 0;
    AK_CHECK_EQ(ak_boids_step_validate(&b), AK_ERR_EMPTY);
    f.s[2] = 1;
    AK_CHECK_EQ(ak_boids_step_validate(&j), AK_ERR_BAD_INDEX);
    f.s[2] = 0;
    f.p[3].y = NAN;
    AK_CHECK_EQ(ak_boids_step_validate(&j), AK_ERR_BAD_DATA);
    f.p[3].y = 0.0f;
    ak_boids_species bad = sp;
    bad.k_nearest = AK_BOIDS_MAX_K + 1;
    prm.species = &bad;
    AK_CHECK_EQ(ak_boids_step_validate(&j), AK_ERR_BAD_ARG);
    bad = sp;
    bad.min_speed = 3.0f; /* above the default max_speed 2 */
    bad.max_speed = 1.0f;
    AK_CHECK_EQ(ak_boids_step_validate(&j), AK_ERR_BAD_ARG);
    bad = sp;
    bad.min_speed = 1.5f; /* below the default max_speed 2: fine */
    AK_CHECK_EQ(ak_boids_step_validate(&j), AK_OK);
    bad.min_speed = 2.5f;
    AK_CHECK_EQ(ak_boids_step_validate(&j), AK_ERR_BAD_ARG);
    bad = sp;
    bad.wander_weight = 1.0f;
    j.wander.ptr = NULL;
    AK_CHECK_EQ(ak_boids_step_validate(&j), AK_ERR_NULL_ARG);
    j.wander.ptr = f.w;
    prm.species = &sp;
    ak_boids_obstacle ob = {.kind = AK_BOIDS_SPHERE, .radius = 0.0f};
    prm.obstacles = &ob;
    prm.obstacle_count = 1;
    AK_CHECK_EQ(ak_boids_step_validate(&j), AK_ERR_BAD_ARG);
    ob = (ak_boids_obstacle){.kind = AK_BOIDS_PLANE};
    AK_CHECK_EQ(ak_boids_step_validate(&j), AK_ERR_BAD_ARG);
    ob.normal = ak_vec3_make(0, 1, 0);
    AK_CHECK_EQ(ak_boids_step_validate(&j), AK_OK);
    prm.bounds_max = ak_vec3_make(1, 1, 1); /* min = max on no axis, max > min: fine */
    AK_CHECK_EQ(ak_boids_step_validate(&j), AK_OK);
    prm.bounds_min = ak_vec3_make(2, 0, 0);
    AK_CHECK_EQ(ak_boids_step_validate(&j), AK_ERR_BAD_ARG);
    prm.bounds_min = ak_vec3_zero();
    prm.has_leader = true;
    prm.leader_index = 4;
    AK_CHECK_EQ(ak_boids_step_validate(&j), AK_ERR_BAD_ARG);
    /* Resolved defaults are what the header says. */
    ak_boids_species r;
    ak_boids_species_resolved(NULL, &r);
    AK_CHECK_NEAR(r.max_speed, 2.0f, 0);
    AK_CHECK_NEAR(r.max_force, 8.0f, 0);
    AK_CHECK_NEAR(r.separation_radius, 1.0f, 0);
    AK_CHECK_NEAR(r.alignment_radius, 2.0f, 0);
    AK_CHECK_NEAR(r.cohesion_radius, 2.0f, 0);
    AK_CHECK_NEAR(r.separation_weight, 0.0f, 0);
    flock_free(&f);
}

/* ---- neighbour sets --------------------------------------------------------------------- */

/* The documented definition, written out independently: float distances, strict radius, the
 * view cone, same species, then the k nearest by (d2, index). */
static bool ref_in_view(float cos_half, ak_vec3 v, float dx, float dy, float dz, float d2, float angle) {
    const float v2 = v.x * v.x + v.y * v.y + v.z * v.z;
    if (angle <= 0.0f || angle >= 360.0f || v2 == 0.0f || d2 == 0.0f) return true;
    const float dot = dx * v.x + dy * v.y + dz * v.z;
    const float lim = (cos_half * cos_half) * d2 * v2;
    if (cos_half >= 0.0f) return dot > 0.0f && dot * dot >= lim;
    return dot >= 0.0f || dot * dot <= lim;
}

typedef struct ref_nb {
    float d2;
    uint32_t j;
} ref_nb;

static int ref_cmp(const void* a, const void* b) {
    const ref_nb *x = (const ref_nb*)a, *y = (const ref_nb*)b;
    if (x->d2 != y->d2) return x->d2 < y->d2 ? -1 : 1;
    return x->j < y->j ? -1 : (x->j > y->j ? 1 : 0);
}

/* Compare ak_boids_neighbors_run (grid and naive) with the reference on flock f; returns the
 * number of neighbour pairs seen. */
static size_t check_neighbors(flock* f, const ak_boids_params* prm) {
    const size_t n = f->n;
    ref_nb* tmp = malloc(n * sizeof *tmp);
    uint32_t* off = malloc((n + 1) * sizeof *off);
    size_t total_all = 0;
    for (int naive = 0; naive < 2; ++naive) {
        ak_boids_step_job j = job_for(f, prm, 0.1f);
        j.use_naive = naive != 0;
        j.thread_count = 2;
        size_t total = 0;
        ak_boids_neighbors_job nj = {.step = &j, .out_offsets = {off, n + 1}, .out_total = &total};
        AK_CHECK_EQ(ak_boids_neighbors_run(&nj), total > 0 ? AK_ERR_SPAN_SMALL : AK_OK);
        uint32_t* idx = malloc((total + 1) * sizeof *idx);
        nj.out_indices = (ak_u32_span){idx, total};
        AK_CHECK_EQ(ak_boids_neighbors_run(&nj), AK_OK);
        total_all = total;
        int bad = 0;
        for (size_t i = 0; i < n && bad < 3; ++i) {
            const ak_boids_species* S = &prm->species[f->s[i]];
            const float rs = S->separation_weight > 0 ? (S->separation_radius > 0 ? S->separation_radius : 1.0f) : 0;
            const float ra = S->alignment_weight > 0 ? (S->alignment_radius > 0 ? S->alignment_radius : 2.0f) : 0;
            const float rc = S->cohesion_weight > 0 ? (S->cohesion_radius > 0 ? S->cohesion_radius : 2.0f) : 0;
            const float r2 = fmaxf(rs * rs, fmaxf(ra * ra, rc * rc));
            const float ch = (float)cos(0.5 * (double)S->view_angle * 3.14159265358979323846 / 180.0);
            size_t m = 0;
            for (size_t k = 0; k < n; ++k) {
                if (k == i || f->s[k] != f->s[i]) continue;
                const float dx = f->p[k].x - f->p[i].x, dy = f->p[k].y - f->p[i].y, dz = f->p[k].z - f->p[i].z;
                const float d2 = dx * dx + dy * dy + dz * dz;
                if (d2 < r2 && ref_in_view(ch, f->v[i], dx, dy, dz, d2, S->view_angle))
                    tmp[m++] = (ref_nb){d2, (uint32_t)k};
            }
            qsort(tmp, m, sizeof *tmp, ref_cmp);
            if (S->k_nearest && m > S->k_nearest) m = S->k_nearest;
            const size_t got = off[i + 1] - off[i];
            bool same = got == m;
            for (size_t a = 0; same && a < m; ++a) same = idx[off[i] + a] == tmp[a].j;
            if (!same) {
                AK_FAIL_("%s path, agent %zu: %zu neighbours, reference %zu", naive ? "naive" : "grid", i, got, m);
                ++bad;
            }
        }
        free(idx);
    }
    free(tmp);
    free(off);
    return total_all;
}

AK_TEST(neighbors_random_flocks) {
    flock f = flock_make(900);
    flock_random(&f, 11, 5.0f, 1.0f, false);
    ak_boids_species sp[2] = {
        {.separation_weight = 1, .separation_radius = 0.7f, .alignment_weight = 1, .alignment_radius = 1.3f,
         .cohesion_weight = 1, .cohesion_radius = 1.1f},
        {.alignment_weight = 1, .alignment_radius = 2.0f, .view_angle = 120.0f, .k_nearest = 7},
    };
    ak_boids_params prm = {.species = sp, .species_count = 1};
    AK_CHECK(check_neighbors(&f, &prm) > 900); /* all around */
    sp[0].view_angle = 270.0f;
    AK_CHECK(check_neighbors(&f, &prm) > 900); /* wide cone */
    sp[0].view_angle = 90.0f;
    AK_CHECK(check_neighbors(&f, &prm) > 200); /* narrow cone */
    sp[0].k_nearest = 5;
    check_neighbors(&f, &prm);
    /* Two species, one with a cone and a cap, one predator-like looking farther. */
    for (size_t i = 0; i < f.n; ++i) f.s[i] = (uint8_t)(i % 3 == 0);
    prm.species_count = 2;
    sp[0].flee_mask = 2;
    sp[0].flee_weight = 1;
    sp[0].flee_radius = 5.0f;
    check_neighbors(&f, &prm);
    /* 2D. */
    flock_random(&f, 12, 8.0f, 1.0f, true);
    check_neighbors(&f, &prm);
    flock_free(&f);
}

AK_TEST(neighbors_cell_boundaries_and_far_agents) {
    /* A lattice at exactly the radius spacing: neighbours sit on cell faces, at the radius
     * (excluded: strict <) and diagonals; velocities along axes put agents on the view cone's
     * edge (90 degrees: dot = 0 is outside). */
    const int side = 9;
    flock f = flock_make((size_t)side * side * side + 6);
    size_t n = 0;
    for (int z = 0; z < side; ++z)
        for (int y = 0; y < side; ++y)
            for (int x = 0; x < side; ++x) {
                f.p[n] = ak_vec3_make((float)x * 0.5f, (float)y * 0.5f, (float)z * 0.5f);
                f.v[n] = ak_vec3_make((float)((x + y) % 3 - 1), (float)((y + z) % 3 - 1), 0.0f);
                ++n;
            }
    /* Agents far outside any box, one at a huge coordinate pair, coincident pairs. */
    f.p[n++] = ak_vec3_make(-1e6f, 3e5f, 7.0f);
    f.p[n++] = ak_vec3_make(-1e6f + 0.25f, 3e5f, 7.0f);
    f.p[n++] = ak_vec3_make(1e9f, -1e9f, 1e9f);
    f.p[n++] = ak_vec3_make(1e9f, -1e9f, 1e9f);
    f.p[n++] = ak_vec3_make(-0.5f, -0.5f, -0.5f);
    f.p[n++] = ak_vec3_make(-0.5f, -0.5f, -0.5f);
    f.n = n;
    ak_boids_species sp = {.alignment_weight = 1, .alignment_radius = 1.0f, .separation_weight = 1,
                           .separation_radius = 0.5f};
    ak_boids_params prm = {.species = &sp, .species_count = 1, .bounds_min = {0, 0, 0}, .bounds_max = {4, 4, 4}};
    AK_CHECK(check_neighbors(&f, &prm) > 1000);
    sp.view_angle = 180.0f;
    check_neighbors(&f, &prm);
    sp.k_nearest = 3; /* many ties at equal distance: index order decides */
    check_neighbors(&f, &prm);
    sp.alignment_radius = 0.5f; /* radius = spacing: only the coincident pairs qualify */
    sp.view_angle = 0.0f;
    sp.k_nearest = 0;
    AK_CHECK_EQ(check_neighbors(&f, &prm), 6); /* two coincident pairs, the pair 0.25 apart */
    flock_free(&f);
}

/* ---- each rule alone ------------------------------------------------------------------- */

AK_TEST(rule_separation_two_agents) {
    flock f = flock_make(2);
    f.p[1] = ak_vec3_make(0.5f, 0, 0);
    ak_boids_species sp = {.separation_weight = 1, .separation_radius = 1, .max_force = 100, .max_speed = 100};
    ak_boids_params prm = {.species = &sp, .species_count = 1};
    AK_CHECK_EQ(step(&f, &prm, 0.1f, 1, false, 0), AK_OK);
    /* F_0 = (p0 - p1)/d^2 = (-0.5, 0, 0)/0.25 = (-2, 0, 0): v = -0.2, p = -0.02. */
    AK_CHECK_NEAR(f.v[0].x, -0.2f, 1e-6);
    AK_CHECK_NEAR(f.p[0].x, -0.02f, 1e-7);
    AK_CHECK_NEAR(f.v[1].x, 0.2f, 1e-6);
    AK_CHECK_NEAR(f.p[1].x, 0.52f, 1e-6);
    AK_CHECK_NEAR(f.v[0].y, 0.0f, 0);
    /* Weight 3 and a third agent at (0, 1.5): outside the radius, no effect. Force clamp 5:
     * |F| = 3 * 1/0.54 = 5.55 > 5 -> clamped. */
    flock g = flock_make(3);
    g.p[1] = ak_vec3_make(0.54f, 0, 0);
    g.p[2] = ak_vec3_make(0, 1.5f, 0);
    sp.separation_weight = 3;
    sp.max_force = 5;
    AK_CHECK_EQ(step(&g, &prm, 0.1f, 1, false, 0), AK_OK);
    AK_CHECK_NEAR(g.v[0].x, -0.5f, 1e-6);
    AK_CHECK_NEAR(g.v[2].x, 0.0f, 0);
    AK_CHECK_NEAR(g.v[2].y, 0.0f, 0);
    flock_free(&f);
    flock_free(&g);
}

AK_TEST(rule_alignment_and_cohesion) {
    flock f = flock_make(2);
    f.p[1] = ak_vec3_make(0.5f, 0, 0);
    f.v[0] = ak_vec3_make(1, 0, 0);
    f.v[1] = ak_vec3_make(0, 1, 0);
    ak_boids_species sp = {.alignment_weight = 2, .alignment_radius = 1, .max_force = 100, .max_speed = 100};
    ak_boids_params prm = {.species = &sp, .species_count = 1};
    AK_CHECK_EQ(step(&f, &prm, 0.1f, 1, false, 0), AK_OK);
    /* F_0 = 2 ((0,1,0) - (1,0,0)) = (-2, 2, 0): v0 = (0.8, 0.2, 0). F_1 = 2((1,0,0)-(0,1,0)). */
    AK_CHECK_NEAR(f.v[0].x, 0.8f, 1e-6);
    AK_CHECK_NEAR(f.v[0].y, 0.2f, 1e-6);
    AK_CHECK_NEAR(f.v[1].x, 0.2f, 1e-6);
    AK_CHECK_NEAR(f.v[1].y, 0.8f, 1e-6);
    AK_CHECK_NEAR(f.p[0].x, 0.08f, 1e-6);
    /* Cohesion, three agents at rest: F_0 = mean(p1, p2) - p0 = (0.5, 0.5, 0). */
    flock g = flock_make(3);
    g.p[1] = ak_vec3_make(1, 0, 0);
    g.p[2] = ak_vec3_make(0, 1, 0);
    ak_boids_species sc = {.cohesion_weight = 1, .cohesion_radius = 2, .max_force = 100, .max_speed = 100};
    prm.species = &sc;
    AK_CHECK_EQ(step(&g, &prm, 0.1f, 1, false, 0), AK_OK);
    AK_CHECK_NEAR(g.v[0].x, 0.05f, 1e-7);
    AK_CHECK_NEAR(g.v[0].y, 0.05f, 1e-7);
    /* Agent 1: mean(p0, p2) - p1 = (0, .5) - (1, 0) = (-1, 0.5). */
    AK_CHECK_NEAR(g.v[1].x, -0.1f, 1e-7);
    AK_CHECK_NEAR(g.v[1].y, 0.05f, 1e-7);
    /* View cone: agent 0 heads +x with a 180-degree view, agent 1 is behind it: unseen. */
    flock h = flock_make(2);
    h.p[1] = ak_vec3_make(-0.5f, 0, 0);
    h.v[0] = ak_vec3_make(1, 0, 0);
    h.v[1] = ak_vec3_make(1, 0, 0);
    sc.view_angle = 180.0f;
    AK_CHECK_EQ(step(&h, &prm, 0.1f, 1, false, 0), AK_OK);
    AK_CHECK_NEAR(h.v[0].x, 1.0f, 0); /* sees nobody */
    AK_CHECK_NEAR(h.v[1].x, 1.0f + 0.1f * 0.5f, 1e-6); /* sees agent 0 ahead: pulled +x */
    flock_free(&f);
    flock_free(&g);
    flock_free(&h);
}

AK_TEST(rule_extensions_signs) {
    /* Goal: at rest at the origin, goal at (3,0,4): desired 2 * (0.6, 0, 0.8), F = w * that. */
    flock f = flock_make(3);
    ak_boids_species sp = {.goal_weight = 1, .max_force = 100, .max_speed = 2};
    ak_boids_params prm = {.species = &sp, .species_count = 1, .goal = {3, 0, 4}};
    f.p[1] = ak_vec3_make(100, 0, 0);
    f.p[2] = ak_vec3_make(200, 0, 0);
    AK_CHECK_EQ(step(&f, &prm, 0.1f, 1, false, 0), AK_OK);
    AK_CHECK_NEAR(f.v[0].x, 0.12f, 1e-6);
    AK_CHECK_NEAR(f.v[0].z, 0.16f, 1e-6);
    /* Flee and pursue: species 0 (prey) at origin, species 1 (predator) at (1, 0, 0). */
    flock g = flock_make(2);
    g.p[1] = ak_vec3_make(1, 0, 0);
    g.s[1] = 1;
    ak_boids_species two[2] = {{.flee_mask = 2, .flee_weight = 1, .flee_radius = 2, .max_speed = 2, .max_force = 100},
                               {.pursue_mask = 1, .pursue_weight = 1, .pursue_radius = 2, .max_speed = 3,
                                .max_force = 100}};
    prm = (ak_boids_params){.species = two, .species_count = 2};
    AK_CHECK_EQ(step(&g, &prm, 0.1f, 1, false, 0), AK_OK);
    AK_CHECK_NEAR(g.v[0].x, -0.2f, 1e-6); /* away at max speed 2: F = (-2,0,0) */
    AK_CHECK_NEAR(g.v[1].x, -0.3f, 1e-6); /* toward the prey (at rest) at 3 */
    /* Predator beyond the flee radius: nothing. */
    flock h = flock_make(2);
    h.p[1] = ak_vec3_make(2.5f, 0, 0);
    h.s[1] = 1;
    AK_CHECK_EQ(step(&h, &prm, 0.1f, 1, false, 0), AK_OK);
    AK_CHECK_NEAR(h.v[0].x, 0.0f, 0);
    /* Leader: the leader at (5,0,0) heading +x; a follower at the origin seeks the point 1 m
     * behind it, (4,0,0), at full speed (4 m > 1 m away). */
    flock l = flock_make(2);
    l.p[0] = ak_vec3_make(5, 0, 0);
    l.v[0] = ak_vec3_make(1, 0, 0);
    ak_boids_species ls = {.leader_weight = 1, .max_speed = 2, .max_force = 100};
    prm = (ak_boids_params){.species = &ls, .species_count = 1, .has_leader = true, .leader_index = 0,
                            .leader_distance = 1};
    AK_CHECK_EQ(step(&l, &prm, 0.1f, 1, false, 0), AK_OK);
    AK_CHECK_NEAR(l.v[1].x, 0.2f, 1e-6);
    AK_CHECK_NEAR(l.v[0].x, 1.0f, 0); /* the leader does not follow itself */
    /* Wander: unit state, force = w * direction; |dv| = w dt exactly, and 2D stays planar. */
    flock w = flock_make(50);
    ak_boids_species ws = {.wander_weight = 3, .max_speed = 100, .max_force = 100};
    prm = (ak_boids_params){.species = &ws, .species_count = 1, .planar = true};
    for (int s = 0; s < 5; ++s) AK_CHECK_EQ(step(&w, &prm, 0.1f, 1, false, (uint64_t)s), AK_OK);
    for (size_t i = 0; i < w.n; ++i) {
        AK_CHECK_NEAR(len3(w.w[i]), 1.0, 1e-5);
        AK_CHECK_NEAR(w.v[i].y, 0.0f, 0);
        AK_CHECK(len3(w.v[i]) <= 1.5 + 1e-5);
    }
    AK_CHECK(fabsf(w.v[0].x - w.v[1].x) > 1e-4f); /* agents draw their own streams */
    flock_free(&f);
    flock_free(&g);
    flock_free(&h);
    flock_free(&l);
    flock_free(&w);
}

AK_TEST(limits_every_step) {
    flock f = flock_make(400);
    flock_random(&f, 3, 3.0f, 0.85f, false); /* |v| <= 1.47 < max_speed */
    ak_boids_species sp = {.max_speed = 1.5f, .max_force = 3.0f, .separation_weight = 5, .alignment_weight = 4,
                           .cohesion_weight = 6, .view_angle = 300, .goal_weight = 2, .wander_weight = 2};
    ak_boids_params prm = {.species = &sp, .species_count = 1, .goal = {10, 0, 0}};
    const float dt = 0.05f;
    double worst_speed = 0, worst_force = 0;
    for (int s = 0; s < 60; ++s) {
        memcpy(f.p2, f.v, f.n * sizeof(ak_vec3)); /* old velocities */
        ak_vec3* old = malloc(f.n * sizeof(ak_vec3));
        memcpy(old, f.v, f.n * sizeof(ak_vec3));
        AK_CHECK_EQ(step(&f, &prm, dt, 2, false, (uint64_t)s), AK_OK);
        for (size_t i = 0; i < f.n; ++i) {
            worst_speed = fmax(worst_speed, len3(f.v[i]) / 1.5);
            worst_force = fmax(worst_force, len3(ak_vec3_sub(f.v[i], old[i])) / dt / 3.0);
        }
        free(old);
    }
    AK_CHECK(worst_speed <= 1.0 + 1e-6);
    AK_CHECK(worst_force <= 1.0 + 1e-4);
    AK_CHECK(worst_force > 0.99); /* the clamp was reached: the test can fail */
    flock_free(&f);
}

/* ---- emergent properties --------------------------------------------------------------- */

AK_TEST(alignment_orders_the_flock) {
    flock f = flock_make(300);
    ak_rng r = ak_rng_make(5);
    for (size_t i = 0; i < f.n; ++i) {
        const float a = ak_rng_range(&r, 0, AK_TWO_PI), rad = 4.0f * sqrtf(ak_rng_float(&r)), h = ak_rng_range(&r, 0, AK_TWO_PI);
        f.p[i] = ak_vec3_make(rad * cosf(a), 0, rad * sinf(a));
        f.v[i] = ak_vec3_make(cosf(h), 0, sinf(h));
    }
    const float order0 = ak_boids_order((ak_vec3_cspan){f.v, f.n});
    AK_CHECK(order0 < 0.15f);
    ak_boids_species sp = {.alignment_weight = 8, .alignment_radius = 4.0f, .max_speed = 0.5f,
                           .min_speed = 0.5f, .max_force = 20};
    ak_boids_params prm = {.species = &sp, .species_count = 1, .planar = true};
    for (int s = 0; s < 200; ++s) AK_CHECK_EQ(step(&f, &prm, 0.05f, 2, false, (uint64_t)s), AK_OK);
    const float order1 = ak_boids_order((ak_vec3_cspan){f.v, f.n});
    printf("  order %.3f -> %.5f\n", order0, order1);
    AK_CHECK(order1 > 0.99f);
    flock_free(&f);
}

/* Separation alone derives from the pair potential U(d) = w ln(r/d) for d < r (force w/d
 * along the pair, 0 beyond r), all around (no view cone), max_force and max_speed not
 * binding: the energy E = sum |v|^2/2 + sum_pairs U is conserved (the speed clamp only
 * removes energy), every U >= 0, so every pair keeps w ln(r/d) <= E, i.e.
 * d >= r exp(-E0 / w) (the bound in docs/boids.md), up to the time-stepping error. */
static double energy(const flock* f, float w, float r) {
    double e = 0;
    for (size_t i = 0; i < f->n; ++i) {
        e += 0.5 * (double)ak_vec3_length_sq(f->v[i]);
        for (size_t j = i + 1; j < f->n; ++j) {
            const double d = len3(ak_vec3_sub(f->p[i], f->p[j]));
            if (d < r) e += w * log(r / d);
        }
    }
    return e;
}

AK_TEST(separation_keeps_its_bound) {
    /* Two agents head-on: the bound is tight, d_min = r exp(-v^2 / w) with both at speed v. */
    flock f = flock_make(2);
    f.p[0] = ak_vec3_make(-2, 0, 0);
    f.p[1] = ak_vec3_make(2, 0, 0);
    f.v[0] = ak_vec3_make(1.2f, 0, 0);
    f.v[1] = ak_vec3_make(-1.2f, 0, 0);
    const float w = 1.0f, r = 1.0f;
    ak_boids_species sp = {.separation_weight = w, .separation_radius = r, .max_force = 1e6f, .max_speed = 1e3f};
    ak_boids_params prm = {.species = &sp, .species_count = 1};
    const double bound = r * exp(-energy(&f, w, r) / w);
    double dmin = 1e9;
    for (int s = 0; s < 4000; ++s) {
        step(&f, &prm, 0.001f, 1, false, 0);
        dmin = fmin(dmin, len3(ak_vec3_sub(f.p[0], f.p[1])));
    }
    printf("  head-on: d_min %.4f, bound %.4f\n", dmin, bound);
    AK_CHECK(dmin >= bound * 0.99);
    AK_CHECK(dmin <= bound * 1.05); /* and the dynamics are the documented ones */
    /* A random flock. */
    flock g = flock_make(60);
    flock_random(&g, 9, 2.5f, 0.5f, false);
    /* Spread the initial configuration so E0 is moderate. */
    for (size_t i = 0; i < g.n; ++i) g.p[i] = ak_vec3_scale(g.p[i], 2.0f);
    const double e0 = energy(&g, w, r);
    const double gbound = r * exp(-e0 / w);
    float gmin = 1e9f;
    uint8_t* scr = malloc(ak_boids_min_distance_scratch_size(g.n));
    for (int s = 0; s < 1500; ++s) {
        step(&g, &prm, 0.002f, 2, false, 0);
        float d;
        ak_boids_min_distance((ak_vec3_cspan){g.p, g.n}, (ak_u8_span){scr, ak_boids_min_distance_scratch_size(g.n)}, &d);
        gmin = fminf(gmin, d);
    }
    printf("  flock: E0 %.3f, d_min %.4f, bound %.4f, energy after %.3f\n", e0, gmin, gbound, energy(&g, w, r));
    AK_CHECK(gmin >= gbound * 0.99);
    AK_CHECK(energy(&g, w, r) <= e0 * 1.02 + 1e-3);
    free(scr);
    flock_free(&f);
    flock_free(&g);
}

/* Distance from p to an obstacle in double precision (negative inside), written apart from
 * the library; in 2D the obstacle is cut at p's height. */
static double ref_sdf(const ak_boids_obstacle* o, ak_vec3 p, bool planar) {
    double d[3] = {(double)p.x - o->center.x, planar ? 0.0 : (double)p.y - o->center.y, (double)p.z - o->center.z};
    if (o->kind == AK_BOIDS_SPHERE) return sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) - o->radius;
    if (o->kind == AK_BOIDS_PLANE) {
        double n[3] = {o->normal.x, planar ? 0.0 : o->normal.y, o->normal.z};
        const double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        return (n[0] * d[0] + n[1] * ((double)p.y - o->center.y) * (planar ? 0 : 1) + n[2] * d[2]) / l;
    }
    const double h[3] = {o->half_extents.x, planar ? 1e30 : o->half_extents.y, o->half_extents.z};
    double out = 0, in = -1e300;
    for (int k = 0; k < 3; ++k) {
        const double q = fabs(d[k]) - h[k];
        if (q > 0) out += q * q;
        if (q > in) in = q;
    }
    return out > 0 ? sqrt(out) : in;
}

static void obstacle_run(bool planar, float avoid, uint32_t* contacts_out, double* worst_out) {
    ak_boids_obstacle obs[4] = {
        {.kind = AK_BOIDS_SPHERE, .center = {0, 0, 0}, .radius = 1.5f},
        {.kind = AK_BOIDS_BOX, .center = {4, 0, 1}, .half_extents = {0.5f, 2.0f, 0.05f}}, /* thin wall */
        {.kind = AK_BOIDS_PLANE, .center = {0, 0, -5}, .normal = {0, 0, 1}},
        {.kind = AK_BOIDS_BOX, .center = {-3, 0, 2}, .half_extents = {1, 1, 1}},
    };
    ak_boids_species sp = {.max_speed = 6, .max_force = 10, .separation_weight = 0.5f, .alignment_weight = 1,
                           .cohesion_weight = 1, .goal_weight = 2, .avoid_weight = avoid, .avoid_distance = 1.5f,
                           .wander_weight = 3};
    ak_boids_params prm = {.species = &sp, .species_count = 1, .obstacles = obs, .obstacle_count = 4,
                           .planar = planar, .goal = {0, 0, -8}};
    flock f = flock_make(200);
    ak_rng r = ak_rng_make(21);
    for (size_t i = 0; i < f.n; ++i) {
        f.p[i] = ak_vec3_make(ak_rng_range(&r, -6, 6), planar ? 0 : ak_rng_range(&r, -3, 3), ak_rng_range(&r, 4, 9));
        f.v[i] = ak_vec3_make(0, 0, -3);
    }
    uint32_t contacts = 0;
    double worst = 1e9;
    for (int s = 0; s < 200; ++s) {
        ak_boids_step_job j = job_for(&f, &prm, 0.05f);
        j.thread_count = 2;
        j.step_index = (uint64_t)s;
        uint32_t c = 0;
        j.out_contact_count = &c;
        AK_CHECK_EQ(ak_boids_step_run(&j), AK_OK);
        contacts += c;
        memcpy(f.p, f.p2, f.n * sizeof(ak_vec3));
        memcpy(f.v, f.v2, f.n * sizeof(ak_vec3));
        for (size_t i = 0; i < f.n; ++i)
            for (int k = 0; k < 4; ++k) worst = fmin(worst, ref_sdf(&obs[k], f.p[i], planar));
        if (s == 100) prm.goal = ak_vec3_make(0, 0, 8); /* and back through the obstacles */
    }
    *contacts_out = contacts;
    *worst_out = worst;
    flock_free(&f);
}

AK_TEST(no_agent_enters_an_obstacle) {
    for (int planar = 0; planar < 2; ++planar) {
        uint32_t c_off, c_on;
        double w_off, w_on;
        obstacle_run(planar != 0, 0.0f, &c_off, &w_off);
        obstacle_run(planar != 0, 4.0f, &c_on, &w_on);
        printf("  %s: no avoidance: %u contacts, min distance %.2e; avoidance: %u contacts, min %.2e\n",
               planar ? "2D" : "3D", c_off, w_off, c_on, w_on);
        AK_CHECK(w_off >= 0.0);
        AK_CHECK(w_on >= 0.0);
        AK_CHECK(c_off > 0);          /* without steering the projection had work to do */
        AK_CHECK(c_on * 10 < c_off);  /* steering avoids most contacts before they happen */
    }
}

AK_TEST(bounds_wrap_and_steer) {
    /* STEER alone: each axis is a spring of stiffness w inside the margin, so an agent leaving
     * at speed v goes at most v / sqrt(w) into the band (1 m here, the band is 2 m wide). */
    flock f = flock_make(200);
    flock_random(&f, 31, 2.9f, 1.15f, false); /* |v| up to 2 */
    ak_boids_species sp = {.max_speed = 2, .max_force = 100, .bounds_weight = 4};
    ak_boids_params prm = {.species = &sp, .species_count = 1, .bounds_min = {-5, -5, -5},
                           .bounds_max = {5, 5, 5}, .bounds_margin = 2};
    float deepest = 0;
    for (int s = 0; s < 300; ++s) {
        AK_CHECK_EQ(step(&f, &prm, 0.01f, 1, false, (uint64_t)s), AK_OK);
        for (size_t i = 0; i < f.n; ++i) {
            const float m = fmaxf(fabsf(f.p[i].x), fmaxf(fabsf(f.p[i].y), fabsf(f.p[i].z)));
            deepest = fmaxf(deepest, m - 3.0f);
        }
    }
    printf("  steer: deepest %.3f m into the 2 m band (bound 1)\n", deepest);
    AK_CHECK(deepest > 0.3f);   /* agents did reach the band */
    AK_CHECK(deepest <= 1.02f); /* v / sqrt(w) = 1, up to time stepping */
    /* WRAP: everything stays in [min, max) and agents do cross the seam. */
    prm.bounds = AK_BOIDS_BOUNDS_WRAP;
    flock_random(&f, 32, 4.9f, 1.15f, true);
    prm.planar = true;
    int wrapped = 0;
    for (int s = 0; s < 200; ++s) {
        memcpy(f.w, f.p, f.n * sizeof(ak_vec3));
        AK_CHECK_EQ(step(&f, &prm, 0.05f, 2, false, (uint64_t)s), AK_OK);
        for (size_t i = 0; i < f.n; ++i) {
            AK_CHECK(f.p[i].x >= -5 && f.p[i].x < 5 && f.p[i].z >= -5 && f.p[i].z < 5);
            AK_CHECK_NEAR(f.p[i].y, 0.0f, 0);
            wrapped += fabsf(f.p[i].x - f.w[i].x) > 5 || fabsf(f.p[i].z - f.w[i].z) > 5;
        }
    }
    AK_CHECK(wrapped > 50);
    flock_free(&f);
}

/* ---- determinism ------------------------------------------------------------------------ */

/* A flock of 40,000 agents in a wrapped box (about 28 neighbours each: the dense layout,
 * sorted over the team, and the symmetric pass) stepped 3 times on 1, 2, 3 and 16 threads:
 * the same positions, velocities and interaction counts, bit for bit. */
AK_TEST(large_flock_threads_bit_identical) {
    enum { N = 40000, STEPS = 3 };
    const uint32_t counts[4] = {1, 2, 3, 16};
    const float side = cbrtf((float)N * 4.18879f / 30.0f);
    ak_boids_species sp = {.max_speed = 2, .max_force = 8, .separation_weight = 1, .separation_radius = 0.5f,
                           .alignment_weight = 1, .alignment_radius = 1, .cohesion_weight = 0.5f,
                           .cohesion_radius = 1, .view_angle = 360};
    ak_boids_params prm = {.species = &sp, .species_count = 1, .bounds_min = {0, 0, 0},
                           .bounds_max = {side, side, side}, .bounds = AK_BOIDS_BOUNDS_WRAP};
    ak_vec3 *p0 = malloc(N * sizeof(ak_vec3)), *v0 = malloc(N * sizeof(ak_vec3));
    ak_vec3 *ref = malloc(2 * N * sizeof(ak_vec3)), *buf[4];
    for (int k = 0; k < 4; ++k) buf[k] = malloc(N * sizeof(ak_vec3));
    ak_rng r = ak_rng_make(2026);
    for (size_t i = 0; i < N; ++i) {
        p0[i] = ak_vec3_make(ak_rng_range(&r, 0, side), ak_rng_range(&r, 0, side), ak_rng_range(&r, 0, side));
        v0[i] = ak_vec3_make(ak_rng_range(&r, -1, 1), ak_rng_range(&r, -1, 1), ak_rng_range(&r, -1, 1));
    }
    uint64_t ref_inter = 0;
    for (int c = 0; c < 4; ++c) {
        ak_vec3 *p = buf[0], *v = buf[1], *p2 = buf[2], *v2 = buf[3];
        memcpy(p, p0, N * sizeof(ak_vec3));
        memcpy(v, v0, N * sizeof(ak_vec3));
        uint64_t inter = 0;
        for (int s = 0; s < STEPS; ++s) {
            ak_boids_step_job j = {.params = &prm, .positions = {p, N}, .velocities = {v, N}, .dt = 1.0f / 60.0f,
                                   .thread_count = counts[c], .out_positions = {p2, N}, .out_velocities = {v2, N},
                                   .out_interaction_count = &inter};
            const size_t need = ak_boids_step_scratch_size(&j);
            void* scratch = malloc(need);
            j.scratch = (ak_u8_span){scratch, need};
            AK_CHECK_EQ(ak_boids_step_run(&j), AK_OK);
            free(scratch);
            ak_vec3* t = p;
            p = p2, p2 = t, t = v, v = v2, v2 = t;
        }
        if (c == 0) {
            memcpy(ref, p, N * sizeof(ak_vec3));
            memcpy(ref + N, v, N * sizeof(ak_vec3));
            ref_inter = inter;
            AK_CHECK(inter > (uint64_t)N * 10); /* a dense flock: the neighbour search found them */
        } else {
            AK_CHECK_MSG(memcmp(ref, p, N * sizeof(ak_vec3)) == 0 && memcmp(ref + N, v, N * sizeof(ak_vec3)) == 0,
                         "%u threads differ from 1", counts[c]);
            AK_CHECK_EQ(inter, ref_inter);
        }
    }
    free(p0), free(v0), free(ref);
    for (int k = 0; k < 4; ++k) free(buf[k]);
}

AK_TEST(threads_and_paths_bit_identical) {
    ak_boids_obstacle obs[2] = {{.kind = AK_BOIDS_SPHERE, .center = {1, 0, 0}, .radius = 1},
                                {.kind = AK_BOIDS_BOX, .center = {-3, 0, 0}, .half_extents = {1, 2, 1}}};
    ak_boids_species sp[2] = {
        {.max_speed = 2, .separation_weight = 2, .separation_radius = 0.6f, .alignment_weight = 1,
         .alignment_radius = 1.4f, .cohesion_weight = 1, .cohesion_radius = 1.6f, .view_angle = 260, .k_nearest = 9,
         .wander_weight = 1, .avoid_weight = 3, .flee_mask = 2, .flee_weight = 2, .flee_radius = 2.5f},
        {.max_speed = 2.5f, .separation_weight = 1, .pursue_mask = 1, .pursue_weight = 1, .pursue_radius = 3},
    };
    ak_boids_params prm = {.species = sp, .species_count = 2, .obstacles = obs, .obstacle_count = 2,
                           .bounds_min = {-6, -6, -6}, .bounds_max = {6, 6, 6}, .bounds = AK_BOIDS_BOUNDS_WRAP,
                           .has_leader = true, .leader_index = 3, .goal = {2, 2, 2}};
    sp[0].leader_weight = 0.5f;
    flock base = flock_make(1000);
    flock_random(&base, 77, 5.5f, 1.5f, false);
    for (size_t i = 0; i < base.n; ++i) base.s[i] = (uint8_t)(i % 50 == 0);
    flock runs[4];
    const uint32_t threads[4] = {1, 2, 3, 1};
    const bool naive[4] = {false, false, false, true};
    for (int k = 0; k < 4; ++k) {
        runs[k] = flock_make(base.n);
        memcpy(runs[k].p, base.p, base.n * sizeof(ak_vec3));
        memcpy(runs[k].v, base.v, base.n * sizeof(ak_vec3));
        memcpy(runs[k].s, base.s, base.n);
        for (int s = 0; s < 8; ++s) AK_CHECK_EQ(step(&runs[k], &prm, 0.05f, threads[k], naive[k], (uint64_t)s), AK_OK);
    }
    for (int k = 1; k < 4; ++k) {
        AK_CHECK(memcmp(runs[0].p, runs[k].p, base.n * sizeof(ak_vec3)) == 0);
        AK_CHECK(memcmp(runs[0].v, runs[k].v, base.n * sizeof(ak_vec3)) == 0);
        AK_CHECK(memcmp(runs[0].w, runs[k].w, base.n * sizeof(ak_vec3)) == 0);
    }
    /* The run moved (and differs from the start), and every output is finite. */
    AK_CHECK(memcmp(runs[0].p, base.p, base.n * sizeof(ak_vec3)) != 0);
    for (size_t i = 0; i < base.n; ++i) AK_CHECK(ak_vec3_is_finite(runs[0].p[i]) && ak_vec3_is_finite(runs[0].v[i]));
    for (int k = 0; k < 4; ++k) flock_free(&runs[k]);
    /* The plain flock (no cap, no predators, one species: the grid's register-sum fast path and,
     * on CPUs with AVX-512, its vector kernels), 2D and 3D, cones narrower and wider than a
     * half-space and none, and a clump where every agent sees every other (more hits than the
     * grid path holds at once, so they are visited in batches). */
    ak_boids_species plain = {.max_speed = 2, .separation_weight = 2, .separation_radius = 0.6f,
                              .alignment_weight = 1, .alignment_radius = 1.4f, .cohesion_weight = 1,
                              .cohesion_radius = 1.6f, .view_angle = 250};
    ak_boids_params pp = {.species = &plain, .species_count = 1};
    const struct {
        bool planar;
        float view, extent;
    } cases[] = {{false, 250, 5.5f}, {true, 250, 5.5f}, {false, 120, 5.5f}, {false, 360, 5.5f}, {false, 250, 0.6f}};
    for (size_t cs = 0; cs < sizeof cases / sizeof cases[0]; ++cs) {
        pp.planar = cases[cs].planar;
        plain.view_angle = cases[cs].view;
        flock_random(&base, 78, cases[cs].extent, 1.5f, pp.planar);
        base.p[1] = base.p[0]; /* coincident agents: distance 0 is in view, separation clamped */
        memset(base.s, 0, base.n);
        for (int k = 0; k < 4; ++k) {
            runs[k] = flock_make(base.n);
            memcpy(runs[k].p, base.p, base.n * sizeof(ak_vec3));
            memcpy(runs[k].v, base.v, base.n * sizeof(ak_vec3));
            for (int s = 0; s < 6; ++s) AK_CHECK_EQ(step(&runs[k], &pp, 0.05f, threads[k], naive[k], (uint64_t)s), AK_OK);
        }
        for (int k = 1; k < 4; ++k) {
            AK_CHECK(memcmp(runs[0].p, runs[k].p, base.n * sizeof(ak_vec3)) == 0);
            AK_CHECK(memcmp(runs[0].v, runs[k].v, base.n * sizeof(ak_vec3)) == 0);
        }
        /* The other kernel sets on 2 threads (AVX2 in place of AVX-512, where the CPU has both;
         * no SIMD): in the clump they take the hits in batches too. */
        for (int kv = 1; kv <= 2; ++kv) {
            if (kv == 1 && strcmp(ak_boids_simd_name(), "avx512") != 0) continue; /* same as fastest */
            flock f = flock_make(base.n);
            memcpy(f.p, base.p, base.n * sizeof(ak_vec3));
            memcpy(f.v, base.v, base.n * sizeof(ak_vec3));
            for (int s = 0; s < 6; ++s) {
                ak_boids_step_job j = job_for(&f, &pp, 0.05f);
                j.thread_count = 2;
                j.step_index = (uint64_t)s;
                j.seed = 7;
                j.skip_avx512 = kv == 1;
                j.skip_simd = kv == 2;
                AK_CHECK_EQ(ak_boids_step_run(&j), AK_OK);
                memcpy(f.p, f.p2, f.n * sizeof(ak_vec3));
                memcpy(f.v, f.v2, f.n * sizeof(ak_vec3));
            }
            AK_CHECK_MSG(memcmp(runs[0].p, f.p, base.n * sizeof(ak_vec3)) == 0 &&
                             memcmp(runs[0].v, f.v, base.n * sizeof(ak_vec3)) == 0,
                         "case %zu: %s kernels differ", cs, kv == 1 ? "avx2" : "scalar");
            flock_free(&f);
        }
        for (int k = 0; k < 4; ++k) flock_free(&runs[k]);
    }
    flock_free(&base);
}

/* A copy of base (positions, velocities, species) stepped twice by dt 0.05: by the naive loop
 * (threads 0), or by the grid on that many threads with simd 0 (fastest), 1 (no AVX-512) or 2
 * (scalar); the interactions counted into *inter. */
static flock two_steps(const flock* base, const ak_boids_params* pp, unsigned threads, int simd, uint64_t* inter) {
    const size_t n = base->n;
    flock f = flock_make(n);
    memcpy(f.p, base->p, n * sizeof(ak_vec3));
    memcpy(f.v, base->v, n * sizeof(ak_vec3));
    memcpy(f.s, base->s, n);
    *inter = 0;
    for (int s = 0; s < 2; ++s) {
        ak_boids_step_job j = job_for(&f, pp, 0.05f);
        j.use_naive = threads == 0;
        j.thread_count = threads;
        j.skip_avx512 = simd == 1;
        j.skip_simd = simd == 2;
        j.out_interaction_count = inter;
        AK_CHECK_EQ(ak_boids_step_run(&j), AK_OK);
        memcpy(f.p, f.p2, n * sizeof(ak_vec3));
        memcpy(f.v, f.v2, n * sizeof(ak_vec3));
    }
    return f;
}

/* The plain flock takes the symmetric pair pass: each pair's distance test runs once and both
 * agents are credited, with their own view cones; threads meet at z-slab boundaries, through
 * a spill buffer when the boundary slabs are few, by atomic adds when most slabs are boundary
 * slabs (the flat box below: 6 slabs, 6 threads). Every thread count, with the fastest
 * kernels, with AVX2 in place of AVX-512 (skip_avx512; on CPUs with both) and without SIMD
 * (skip_simd), must give the naive loop's bits, and the same interaction count.
 * (Dense clumps, whose hits are taken in batches, are in the test above.) */
AK_TEST(symmetric_pass_threads_and_kernels) {
    ak_boids_species plain = {.max_speed = 2, .separation_weight = 2, .separation_radius = 0.6f,
                              .alignment_weight = 1, .alignment_radius = 1.4f, .cohesion_weight = 1,
                              .cohesion_radius = 1.6f};
    ak_boids_params pp = {.species = &plain, .species_count = 1};
    /* wrap: a wrapping box through the flock, a min_speed and a force limit that bind (the
     * batched integration hands such agents to the scalar code). */
    const struct {
        bool column;
        float view;
        bool wrap;
    } cases[] = {{false, 250, false}, {false, 120, false}, {true, 360, false}, {true, 200, false}, {false, 360, true}};
    const uint32_t threads[4] = {1, 2, 3, 6};
    for (size_t cs = 0; cs < sizeof cases / sizeof cases[0]; ++cs) {
        /* 6 threads at most: one per 512 agents (the wrap case, 2: it keeps valgrind runs short) */
        const size_t n = cases[cs].wrap ? 1024 : 3072;
        plain.view_angle = cases[cs].view;
        plain.min_speed = cases[cs].wrap ? 1.2f : 0.0f;
        plain.max_force = cases[cs].wrap ? 3.0f : 0.0f;
        pp.bounds = cases[cs].wrap ? AK_BOIDS_BOUNDS_WRAP : AK_BOIDS_BOUNDS_DEFAULT;
        pp.bounds_min = cases[cs].wrap ? ak_vec3_make(-6.9f, -6.9f, -6.9f) : ak_vec3_zero();
        pp.bounds_max = cases[cs].wrap ? ak_vec3_make(6.9f, 6.9f, 6.9f) : ak_vec3_zero();
        flock base = flock_make(n);
        ak_rng r = ak_rng_make(500 + cs);
        for (size_t i = 0; i < n; ++i) {
            if (cases[cs].column) /* cells of 1.6 m: 6 slabs */
                base.p[i] = ak_vec3_make(ak_rng_range(&r, 0.0f, 16.0f), ak_rng_range(&r, 0.0f, 16.0f),
                                         ak_rng_range(&r, 0.0f, 9.5f));
            else
                base.p[i] = ak_vec3_make(ak_rng_range(&r, -7, 7), ak_rng_range(&r, -7, 7), ak_rng_range(&r, -7, 7));
            base.v[i] = ak_vec3_make(ak_rng_range(&r, -1.5f, 1.5f), ak_rng_range(&r, -1.5f, 1.5f),
                                     ak_rng_range(&r, -1.5f, 1.5f));
        }
        base.v[5] = ak_vec3_zero(); /* a viewer without a heading sees all around */
        base.p[7] = base.p[6];      /* coincident agents */
        uint64_t ref_inter = 0;
        flock ref = two_steps(&base, &pp, 0, 0, &ref_inter);
        printf("  case %zu: %.1f neighbours per agent\n", cs, (double)ref_inter / (double)n);
        AK_CHECK(ref_inter > 3u * n);
        for (int t = 0; t < 4; ++t)
            for (int simd = 0; simd < 3; ++simd) { /* fastest, AVX2 instead of AVX-512, scalar */
                if (simd == 1 && strcmp(ak_boids_simd_name(), "avx512") != 0) continue; /* same as fastest */
                uint64_t inter = 0;
                flock f = two_steps(&base, &pp, threads[t], simd, &inter);
                AK_CHECK_MSG(memcmp(f.p, ref.p, n * sizeof(ak_vec3)) == 0 &&
                                 memcmp(f.v, ref.v, n * sizeof(ak_vec3)) == 0 && inter == ref_inter,
                             "case %zu, %u threads, %s: differs from the naive loop", cs, threads[t],
                             simd == 2 ? "scalar" : simd == 1 ? "no avx512" : ak_boids_simd_name());
                flock_free(&f);
            }
        flock_free(&ref);
        flock_free(&base);
    }
}

/* The threads split the symmetric pass (and the gather of the other path) into runs of whole
 * rows of cells (z, y) of about equal estimated work, so a part starts mid slab, and a part's
 * first dim_y + 1 rows wait for the part before. A flock in a long column (5 x 5 cells across,
 * 30 slabs) denser at one end (z = 48 u^2), and the same spread evenly: on 1, 2, 3 and 8
 * threads (8: more parts than fit at 6 rows each in the dense half, and parts of very
 * different lengths), the naive loop's bits and interaction count, for the symmetric pass and
 * for two species (the gather path). */
AK_TEST(work_partition_threads_bit_identical) {
    enum { N = 4096 };
    ak_boids_species sp[2] = {{.max_speed = 2, .separation_weight = 2, .separation_radius = 0.6f,
                               .alignment_weight = 1, .alignment_radius = 1.4f, .cohesion_weight = 1,
                               .cohesion_radius = 1.6f, .view_angle = 270},
                              {.max_speed = 2, .separation_weight = 1, .separation_radius = 0.8f,
                               .cohesion_weight = 1, .cohesion_radius = 1.6f}};
    const uint32_t threads[4] = {1, 2, 3, 8};
    for (int clumped = 0; clumped < 2; ++clumped)
        for (uint32_t species = 1; species <= 2; ++species) {
            ak_boids_params pp = {.species = sp, .species_count = species};
            flock base = flock_make(N);
            ak_rng r = ak_rng_make(900u + (uint64_t)clumped);
            for (size_t i = 0; i < N; ++i) {
                const float u = ak_rng_range(&r, 0.0f, 1.0f);
                base.p[i] = ak_vec3_make(ak_rng_range(&r, 0.0f, 8.0f), ak_rng_range(&r, 0.0f, 8.0f),
                                         48.0f * (clumped ? u * u : u));
                base.v[i] = ak_vec3_make(ak_rng_range(&r, -1.5f, 1.5f), ak_rng_range(&r, -1.5f, 1.5f),
                                         ak_rng_range(&r, -1.5f, 1.5f));
                base.s[i] = (uint8_t)(i % species);
            }
            uint64_t ref_inter = 0;
            flock ref = two_steps(&base, &pp, 0, 0, &ref_inter);
            AK_CHECK(ref_inter > 2u * N);
            for (int t = 0; t < 4; ++t) {
                uint64_t inter = 0;
                flock f = two_steps(&base, &pp, threads[t], 0, &inter);
                AK_CHECK_MSG(memcmp(f.p, ref.p, N * sizeof(ak_vec3)) == 0 &&
                                 memcmp(f.v, ref.v, N * sizeof(ak_vec3)) == 0 && inter == ref_inter,
                             "%s, %u species, %u threads: differs from the naive loop", clumped ? "clumped" : "even",
                             species, threads[t]);
                flock_free(&f);
            }
            flock_free(&ref);
            flock_free(&base);
        }
}

/* ---- measures ---------------------------------------------------------------------------- */

AK_TEST(order_and_min_distance) {
    flock f = flock_make(700);
    flock_random(&f, 4, 10.0f, 1.0f, false);
    double best = 1e300;
    for (size_t i = 0; i < f.n; ++i)
        for (size_t j = i + 1; j < f.n; ++j) best = fmin(best, len3(ak_vec3_sub(f.p[i], f.p[j])));
    uint8_t* scr = malloc(ak_boids_min_distance_scratch_size(f.n));
    float d = 0;
    AK_CHECK_EQ(ak_boids_min_distance((ak_vec3_cspan){f.p, f.n}, (ak_u8_span){scr, ak_boids_min_distance_scratch_size(f.n)}, &d), AK_OK);
    AK_CHECK_NEAR(d, best, 1e-6 * best + 1e-7);
    AK_CHECK_EQ(ak_boids_min_distance((ak_vec3_cspan){f.p, 1}, (ak_u8_span){scr, 8}, &d), AK_ERR_EMPTY);
    AK_CHECK_EQ(ak_boids_min_distance((ak_vec3_cspan){f.p, f.n}, (ak_u8_span){scr, 8}, &d), AK_ERR_SPAN_SMALL);
    ak_vec3 same[3] = {{1, 0, 0}, {2, 0, 0}, {0, 0, 0}};
    AK_CHECK_NEAR(ak_boids_order((ak_vec3_cspan){same, 2}), 1.0f, 1e-7);
    AK_CHECK_NEAR(ak_boids_order((ak_vec3_cspan)AK_SPAN(same)), 2.0 / 3.0, 1e-7);
    ak_vec3 opp[2] = {{1, 0, 0}, {-3, 0, 0}};
    AK_CHECK_NEAR(ak_boids_order((ak_vec3_cspan)AK_SPAN(opp)), 0.0f, 1e-7);
    free(scr);
    flock_free(&f);
}

/* The grid path's work budget (max_cell_load, the sum over cells of agents^2): a clump of
 * 500 agents in one cell has a load of 250,000; one under it the step refuses and writes
 * nothing, at it the step runs. Both layouts: a compact flock (the dense cell table) and the
 * clump with agents spread 1e5 m around it (the hashed grid). The naive path has no budget. */
AK_TEST(cell_load_budget) {
    ak_boids_species sp = {.separation_weight = 1, .alignment_weight = 1, .cohesion_weight = 1};
    ak_boids_params prm = {.species = &sp, .species_count = 1};
    for (int layout = 0; layout < 2; ++layout) {
        enum { clump = 500 }; /* the load is quadratic: 2000 took minutes under valgrind */
        const size_t n = layout == 0 ? clump : clump + 100;
        flock f = flock_make(n);
        flock_random(&f, 3, 0.2f, 1.0f, false);
        for (size_t i = 0; i < clump; ++i) f.p[i] = ak_vec3_add(ak_vec3_make(0.2f, 0.2f, 0.2f), ak_vec3_scale(f.p[i], 0.5f));
        for (size_t i = clump; i < n; ++i) /* far apart: one agent per cell */
            f.p[i] = ak_vec3_make(1e5f * (float)(i % 7) - 3e5f, 1e4f * (float)(i % 11), -1e5f * (float)(i % 13));
        uint64_t load = (uint64_t)clump * clump + (n - clump);
        for (int ok = 0; ok < 2; ++ok) {
            ak_boids_step_job j = job_for(&f, &prm, 0.01f);
            j.max_cell_load = ok ? load : load - 1;
            for (size_t i = 0; i < n; ++i) f.p2[i] = ak_vec3_make(7, 7, 7);
            ak_result r = ak_boids_step_run(&j);
            AK_CHECK_MSG(r == (ok ? AK_OK : AK_ERR_BUDGET), "layout %d budget %d: %s", layout, ok, ak_result_name(r));
            bool untouched = true;
            for (size_t i = 0; i < n; ++i) untouched &= f.p2[i].x == 7.0f;
            AK_CHECK(ok ? !untouched : untouched);
        }
        ak_boids_step_job naive = job_for(&f, &prm, 0.01f);
        naive.use_naive = true;
        naive.max_cell_load = 1;
        AK_CHECK_EQ(ak_boids_step_run(&naive), AK_OK);
        flock_free(&f);
    }
}

int main(void) {
    AK_RUN(cell_load_budget);
    AK_RUN(validate_rules);
    AK_RUN(validate_every_coordinate);
    AK_RUN(validation_scan_split_over_threads);
    AK_RUN(neighbors_random_flocks);
    AK_RUN(neighbors_cell_boundaries_and_far_agents);
    AK_RUN(rule_separation_two_agents);
    AK_RUN(rule_alignment_and_cohesion);
    AK_RUN(rule_extensions_signs);
    AK_RUN(limits_every_step);
    AK_RUN(alignment_orders_the_flock);
    AK_RUN(separation_keeps_its_bound);
    AK_RUN(no_agent_enters_an_obstacle);
    AK_RUN(bounds_wrap_and_steer);
    AK_RUN(threads_and_paths_bit_identical);
    AK_RUN(large_flock_threads_bit_identical);
    AK_RUN(symmetric_pass_threads_and_kernels);
    AK_RUN(work_partition_threads_bit_identical);
    AK_RUN(order_and_min_distance);
    return ak_test_finish();
}
