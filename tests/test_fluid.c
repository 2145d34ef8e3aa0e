/* Fluids: MCG kernels, lattice density, hydrostatic SPH column, PBF dam break, free fall,
 * colliders, emitters and sinks, thread-count independence. */
#include <animkit/fluid.h>

#include "ak_test.h"
#include "fluid_fit.h"

#define PI_D 3.14159265358979323846

typedef float (*radial_fn)(float r, float h);
static float poly6_r(float r, float h) { return ak_fluid_poly6(r * r, h); }

/* int_0^h f(r) 4 pi r^2 dr by the midpoint rule in double. */
static double integrate(radial_fn f, float h) {
    const int steps = 20000;
    double sum = 0.0, dr = (double)h / steps;
    for (int k = 0; k < steps; ++k) {
        double r = (k + 0.5) * dr;
        sum += (double)f((float)r, h) * 4.0 * PI_D * r * r * dr;
    }
    return sum;
}

AK_TEST(kernels_integrate_to_one) {
    const float hs[] = {0.05f, 0.1f, 1.0f};
    for (int k = 0; k < 3; ++k) {
        float h = hs[k];
        AK_CHECK_NEAR(integrate(poly6_r, h), 1.0, 1e-3);
        AK_CHECK_NEAR(integrate(ak_fluid_spiky, h), 1.0, 1e-3);
        AK_CHECK_NEAR(integrate(ak_fluid_visc, h), 1.0, 2e-3);
        AK_CHECK_NEAR(integrate(ak_fluid_cubic, h), 1.0, 1e-3);
        /* the Laplacian's regular part integrates to 15 / h^2 (see fluid.h) */
        AK_CHECK_NEAR(integrate(ak_fluid_visc_laplacian, h) * h * h, 15.0, 1e-2);
    }
}

AK_TEST(kernels_support) {
    const float h = 0.1f;
    const float rs[] = {0.1f, 0.10001f, 0.2f, 5.0f};
    for (int k = 0; k < 4; ++k) {
        float r = rs[k];
        AK_CHECK(ak_fluid_poly6(r * r, h) == 0.0f);
        AK_CHECK(ak_fluid_spiky(r, h) == 0.0f);
        AK_CHECK(ak_fluid_visc(r, h) == 0.0f);
        AK_CHECK(ak_fluid_visc_laplacian(r, h) == 0.0f);
        AK_CHECK(ak_fluid_cubic(r, h) == 0.0f);
        AK_CHECK(ak_vec3_length(ak_fluid_cubic_grad(ak_vec3_make(0, r, 0), h)) == 0.0f);
        ak_vec3 g = ak_fluid_spiky_grad(ak_vec3_make(r, 0, 0), h);
        AK_CHECK(g.x == 0.0f && g.y == 0.0f && g.z == 0.0f);
        g = ak_fluid_poly6_grad(ak_vec3_make(0, 0, r), h);
        AK_CHECK(g.x == 0.0f && g.y == 0.0f && g.z == 0.0f);
    }
    AK_CHECK(ak_fluid_poly6(0.0099f * 0.0099f, 0.1f) > 0.0f);
    AK_CHECK(ak_fluid_spiky(0.099f, 0.1f) > 0.0f);
    AK_CHECK(ak_fluid_cubic(0.099f, 0.1f) > 0.0f);
}

AK_TEST(kernel_gradients_match_finite_differences) {
    const float h = 1.0f, e = 1e-3f;
    const ak_vec3 pts[] = {{0.3f, 0.2f, -0.1f}, {0.05f, -0.6f, 0.4f}, {-0.5f, 0.5f, 0.5f}};
    for (int k = 0; k < 3; ++k) {
        ak_vec3 r = pts[k];
        ak_vec3 gs = ak_fluid_spiky_grad(r, h), gp = ak_fluid_poly6_grad(r, h);
        float fs[3], fp[3];
        for (int a = 0; a < 3; ++a) {
            ak_vec3 rp = r, rm = r;
            (&rp.x)[a] += e;
            (&rm.x)[a] -= e;
            fs[a] = (ak_fluid_spiky(ak_vec3_length(rp), h) - ak_fluid_spiky(ak_vec3_length(rm), h)) / (2 * e);
            fp[a] = (ak_fluid_poly6(ak_vec3_length_sq(rp), h) - ak_fluid_poly6(ak_vec3_length_sq(rm), h)) / (2 * e);
        }
        AK_CHECK_NEAR(gs.x, fs[0], 2e-3 * fabs(fs[0]) + 2e-3);
        AK_CHECK_NEAR(gs.y, fs[1], 2e-3 * fabs(fs[1]) + 2e-3);
        AK_CHECK_NEAR(gs.z, fs[2], 2e-3 * fabs(fs[2]) + 2e-3);
        AK_CHECK_NEAR(gp.x, fp[0], 2e-3 * fabs(fp[0]) + 2e-3);
        AK_CHECK_NEAR(gp.y, fp[1], 2e-3 * fabs(fp[1]) + 2e-3);
        AK_CHECK_NEAR(gp.z, fp[2], 2e-3 * fabs(fp[2]) + 2e-3);
        /* the cubic spline (both branches: |r| = 0.37, 0.79, 0.87) */
        ak_vec3 gc = ak_fluid_cubic_grad(r, h);
        for (int a = 0; a < 3; ++a) {
            ak_vec3 rp = r, rm = r;
            (&rp.x)[a] += e;
            (&rm.x)[a] -= e;
            const float fc = (ak_fluid_cubic(ak_vec3_length(rp), h) - ak_fluid_cubic(ak_vec3_length(rm), h)) / (2 * e);
            AK_CHECK_NEAR((&gc.x)[a], fc, 2e-3 * fabs(fc) + 2e-3);
        }
    }
    /* viscosity: lap W = W'' + 2 W' / r by central differences in double */
    for (double r = 0.2; r < 0.95; r += 0.15) {
        const double d = 1e-2;
        double w0 = ak_fluid_visc((float)r, 1.0f), wp = ak_fluid_visc((float)(r + d), 1.0f),
               wm = ak_fluid_visc((float)(r - d), 1.0f);
        double lap = (wp - 2 * w0 + wm) / (d * d) + 2.0 / r * (wp - wm) / (2 * d);
        AK_CHECK_NEAR(ak_fluid_visc_laplacian((float)r, 1.0f), lap, 0.02 * fabs(lap) + 0.05);
    }
}

/* Density of the centre of a lattice block at rest spacing, through the solver (SPH, zero
 * dt effect measured by out_densities before motion matters). The discretisation error of
 * poly6 on a cubic lattice (closed-form sums, double): +0.98% at h = 2s, -0.46% at h = 2.5s,
 * -0.0002% at h = 4s. */
AK_TEST(lattice_density_is_rest_density) {
    const float ratios[] = {2.0f, 2.5f, 4.0f};
    const double bounds[] = {0.012, 0.006, 1e-4};
    for (int k = 0; k < 3; ++k) {
        ak_fluid_desc d = {.solver = AK_FLUID_SPH, .particle_mass = 0.001f, .rest_density = 1000.0f};
        const float s = ak_fluid_rest_spacing(&d);
        d.h = ratios[k] * s;
        d.max_neighbours = 400;
        const int side = 11;
        ak_vec3 pos[11 * 11 * 11], vel[11 * 11 * 11];
        float rho[11 * 11 * 11];
        size_t n = ak_fluid_fill_box(&d, ak_vec3_make(0, 0, 0), ak_vec3_make(side * s, side * s, side * s),
                                     (ak_vec3_span)AK_SPAN(pos));
        AK_CHECK_EQ(n, side * side * side);
        memset(vel, 0, sizeof vel);
        size_t bytes = ak_fluid_scratch_size(n, &d);
        void* mem = malloc(bytes);
        ak_fluid_stats st;
        ak_fluid_step_job job = {.desc = &d, .dt = 1e-6f, .positions = {pos, n}, .velocities = {vel, n},
                                 .particle_count = &n, .scratch = {mem, bytes}, .out_densities = {rho, n},
                                 .out_stats = &st};
        AK_CHECK_EQ(ak_fluid_step_run(&job), AK_OK);
        size_t centre = (size_t)(5 * side * side + 5 * side + 5);
        double err = rho[centre] / 1000.0 - 1.0;
        AK_CHECK_MSG(fabs(err) < bounds[k], "h = %.1fs: density error %.5f", ratios[k], err);
        /* the rest lattice density PBF's constraint holds is that same sum (another order) */
        AK_CHECK_NEAR(st.rest_lattice_density, rho[centre], 1e-5 * rho[centre]);
        free(mem);
    }
}

static bool inside_box(const ak_vec3* p, size_t n, ak_vec3 lo, ak_vec3 hi) {
    for (size_t i = 0; i < n; ++i)
        if (p[i].x < lo.x || p[i].y < lo.y || p[i].z < lo.z || p[i].x > hi.x || p[i].y > hi.y || p[i].z > hi.z)
            return false;
    return true;
}

/* Fitted slope of pressure against height, -dp/dy, over particles at least h above the floor
 * and h below the highest particle (kernel truncation there; no boundary particles), averaged
 * over the last `window` of `steps` steps of a WCSPH column at rest in a box (w x w particles
 * across, ht high, at rest spacing, each moved by up to jitter * s along each axis). */
static double column_slope(int w, int ht, float jitter, uint32_t seed, int steps, int window) {
    ak_fluid_desc d = {.solver = AK_FLUID_WCSPH, .particle_mass = 0.001f, .gravity = {0, -9.81f, 0},
                       .viscosity = 0.2f, .sound_speed = 15.0f};
    const float s = ak_fluid_rest_spacing(&d);
    d.h = 2.0f * s;
    d.box_min = ak_vec3_make(0, 0, 0);
    d.box_max = ak_vec3_make((float)w * s, 3.0f * (float)ht * s, (float)w * s);
    const size_t cap = (size_t)w * (size_t)w * (size_t)ht;
    ak_vec3* pos = malloc(cap * sizeof *pos);
    ak_vec3* vel = calloc(cap, sizeof *vel);
    float* pres = malloc(cap * sizeof *pres);
    size_t n = ak_fluid_fill_box(&d, d.box_min, ak_vec3_make((float)w * s, (float)ht * s, (float)w * s),
                                 (ak_vec3_span){pos, cap});
    for (size_t i = 0; i < n; ++i)
        for (int a = 0; a < 3; ++a) {
            seed = seed * 1664525u + 1013904223u;
            (&pos[i].x)[a] += jitter * s * ((float)(seed >> 8) / 16777216.0f - 0.5f);
        }
    size_t bytes = ak_fluid_scratch_size(cap, &d);
    void* mem = malloc(bytes);
    ak_fluid_step_job job = {.desc = &d, .dt = 3e-4f, .positions = {pos, cap}, .velocities = {vel, cap},
                             .particle_count = &n, .scratch = {mem, bytes}, .out_pressures = {pres, cap}};
    double sum = 0.0;
    int fits = 0;
    for (int step = 0; step < steps; ++step) {
        if (ak_fluid_step_run(&job) != AK_OK) break;
        if (step < steps - window) continue;
        double slope;
        if (fluid_pressure_slope(pos, pres, n, d.h, d.h, &slope)) sum += slope, ++fits;
    }
    free(mem);
    free(pres);
    free(vel);
    free(pos);
    return fits == window ? sum / fits : NAN;
}

/* Hydrostatic column: the fitted slope of p against depth, averaged over the last 500 of 1300
 * steps (0.39 s; the column settles in about 0.15 s), within 5% of rho0 g, and within 10% for a
 * column one particle wider with its lattice jittered by 10% of the spacing. Measured 1.002 and 1.046
 * rho0 g (jitter seeds 2-5: 1.016-1.055); MCG's poly6/spiky pair in place of the cubic spline
 * gives 1.13 and 1.24 (fails). */
AK_TEST(hydrostatic_column_pressure_is_linear) {
    const double want = 1000.0 * 9.81;
    const double a = column_slope(6, 16, 0.0f, 1u, 1300, 500), b = column_slope(7, 16, 0.1f, 7u, 1300, 500);
    printf("  hydrostatic: mean fitted slope %.1f and %.1f (jittered) Pa/m vs rho g %.1f\n", a, b, want);
    AK_CHECK_MSG(fabs(a / want - 1.0) < 0.05, "slope %.1f vs rho g %.1f", a, want);
    AK_CHECK_MSG(fabs(b / want - 1.0) < 0.1, "jittered: slope %.1f vs rho g %.1f", b, want);
}

static void dam_desc(ak_fluid_desc* d, float* s) {
    *d = (ak_fluid_desc){.solver = AK_FLUID_PBF, .particle_mass = 0.001f, .gravity = {0, -9.81f, 0},
                         .xsph_c = 0.01f, .vorticity_epsilon = 0.0f, .iterations = 4};
    *s = ak_fluid_rest_spacing(d);
    d->h = 2.0f * *s;
}

/* A PBF dam break: a column a wide and 2a high (Martin & Moyce's n^2 = 2), `depth` deep, at rest
 * spacing 1 cm (h = 2 s) against the wall x = 0 of a box 4a long, as fill_box lays it out. Every
 * step records the mean density of the full-neighbourhood particles (signed, ak_fluid_stats) and
 * the front: the largest x + s/2 (a particle stands for a cube of side s). */
typedef struct dam_run {
    double lo, hi;       /* min and max over steps of mean_density / rho_0 (steps with >= 20 full) */
    bool inside;         /* every particle inside the box after every step */
    ak_result r;         /* the last step's result */
    size_t coincident;   /* the largest coincident_count of any step */
    double front[64];    /* front / a after step k * every (k < 64) */
} dam_run;

static void dam_break(float a, float depth, float dt, uint32_t iterations, bool scorr, int steps, int every,
                      dam_run* out) {
    ak_fluid_desc d = {.solver = AK_FLUID_PBF, .particle_mass = 0.001f, .gravity = {0, -9.81f, 0},
                       .xsph_c = 0.01f, .iterations = iterations, .scorr = scorr};
    const float s = ak_fluid_rest_spacing(&d);
    d.h = 2.0f * s;
    d.box_max = ak_vec3_make(4.0f * a, 3.0f * a, depth);
    const ak_vec3 hi = ak_vec3_make(a, 2.0f * a, depth);
    const size_t cap = ak_fluid_fill_box(&d, d.box_min, hi, (ak_vec3_span){NULL, 0});
    ak_vec3* pos = malloc(cap * sizeof *pos);
    ak_vec3* vel = calloc(cap, sizeof *vel);
    size_t n = ak_fluid_fill_box(&d, d.box_min, hi, (ak_vec3_span){pos, cap});
    size_t bytes = ak_fluid_scratch_size(cap, &d);
    void* mem = malloc(bytes);
    ak_fluid_stats st;
    ak_fluid_step_job job = {.desc = &d, .dt = dt, .positions = {pos, cap}, .velocities = {vel, cap},
                             .particle_count = &n, .scratch = {mem, bytes}, .out_stats = &st};
    memset(out, 0, sizeof *out);
    out->lo = out->hi = 1.0;
    out->inside = true;
    for (int step = 0; step < steps; ++step) {
        out->r = ak_fluid_step_run(&job);
        if (out->r != AK_OK) break;
        out->inside = out->inside && inside_box(pos, n, d.box_min, d.box_max);
        if (st.coincident_count > out->coincident) out->coincident = st.coincident_count;
        if (st.full_count >= 20) {
            const double q = st.mean_density / 1000.0;
            out->lo = q < out->lo ? q : out->lo;
            out->hi = q > out->hi ? q : out->hi;
        }
        if ((step + 1) % every == 0 && (step + 1) / every < 64) {
            float front = 0.0f;
            for (size_t i = 0; i < n; ++i) front = fmaxf(front, pos[i].x);
            out->front[(step + 1) / every] = (front + 0.5f * s) / a;
        }
    }
    free(mem);
    free(vel);
    free(pos);
}

/* Interior density through a dam break, with the defaults (unilateral constraint, no s_corr):
 * the mean density of the full-neighbourhood particles stays within 3% of rho_0 at every step,
 * at the step (1 ms, 6 iterations) and the command's (1/400 s, 4 iterations); no
 * particle leaves the box or sits on another. Measured (a = 0.1 m, 1000 particles, 0.2 s):
 * 0.972-1.010 and 0.975-1.012 (see docs/fluid.md for the larger dam). The control: the same
 * dam with s_corr on (k = 0.1) swells, its interior falls below 0.97 rho_0 (measured 0.71),
 * which shows this check can fail. */
AK_TEST(pbf_dam_break_keeps_interior_density) {
    dam_run r;
    dam_break(0.1f, 0.05f, 1e-3f, 6, false, 200, 10, &r);
    printf("  dam (1 ms, 6 it): interior mean density %.4f..%.4f rho0, front Z %.2f at T %.2f, %zu coincident\n", r.lo,
           r.hi, r.front[20], 0.2 * sqrt(2 * 9.81 / 0.1), r.coincident);
    AK_CHECK_EQ(r.r, AK_OK);
    AK_CHECK(r.inside);
    /* a few particles pinned to the same box edge (measured 14): far from a collapse */
    AK_CHECK_MSG(r.coincident < 20, "%zu coincident particles", r.coincident);
    AK_CHECK_MSG(r.lo > 0.97 && r.hi < 1.03, "interior density %.4f..%.4f rho0", r.lo, r.hi);
    AK_CHECK_MSG(r.front[20] > 2.0, "the front only reached %.2f a", r.front[20]);
    dam_break(0.1f, 0.05f, 1.0f / 400.0f, 4, false, 80, 10, &r);
    printf("  dam (1/400 s, 4 it): interior mean density %.4f..%.4f rho0\n", r.lo, r.hi);
    AK_CHECK_EQ(r.r, AK_OK);
    AK_CHECK_MSG(r.lo > 0.97 && r.hi < 1.03, "interior density %.4f..%.4f rho0", r.lo, r.hi);
    ak_fluid_desc k = {.particle_mass = 0.001f, .h = 0.02f};
    AK_CHECK_NEAR(ak_fluid_desc_resolved(&k).scorr_k, 0.01f, 0.0f);
    dam_break(0.1f, 0.05f, 1e-3f, 6, true, 200, 10, &r);
    printf("  control, s_corr on: interior mean density %.4f..%.4f rho0\n", r.lo, r.hi);
    AK_CHECK_MSG(r.lo < 0.97, "s_corr on kept the interior at %.4f..%.4f rho0", r.lo, r.hi);
}

/* Martin & Moyce (1952), the collapse of a column of n^2 = 2 (height 2a): surge front Z = x/a
 * against T = t sqrt(2 g / a), read from their table for a = 2.25 in (fronts every 0.25-0.5 in).
 * The PBF front (a = 0.2 m, 20 x 40 x 5 particles, 1 ms, 6 iterations, free-slip walls) must
 * stay within 12% of theirs for 1 <= T <= 2.5. Measured: 4.6-9% behind (docs/fluid.md); an
 * inviscid, frictionless model would be ahead, a liquid that swells or sticks would be far off. */
static const double martin_moyce[][2] = {{0.41, 1.11}, {0.84, 1.22}, {1.19, 1.44}, {1.43, 1.67},
                                          {1.63, 1.89}, {1.83, 2.11}, {1.98, 2.33}, {2.20, 2.56},
                                          {2.32, 2.78}, {2.51, 3.00}};

static double martin_moyce_z(double T) {
    const size_t count = sizeof martin_moyce / sizeof martin_moyce[0];
    if (T <= martin_moyce[0][0]) return 1.0 + (martin_moyce[0][1] - 1.0) * T / martin_moyce[0][0];
    for (size_t k = 1; k < count; ++k)
        if (T <= martin_moyce[k][0]) {
            const double u = (T - martin_moyce[k - 1][0]) / (martin_moyce[k][0] - martin_moyce[k - 1][0]);
            return martin_moyce[k - 1][1] + u * (martin_moyce[k][1] - martin_moyce[k - 1][1]);
        }
    return martin_moyce[count - 1][1];
}

AK_TEST(pbf_dam_break_front_against_martin_moyce) {
    const float a = 0.2f, dt = 1e-3f;
    const double scale = sqrt(2.0 * 9.81 / a); /* T per second */
    dam_run r;
    const int every = 10;
    dam_break(a, 0.05f, dt, 6, false, (int)(2.55 / scale / dt) + 1, every, &r);
    AK_CHECK_EQ(r.r, AK_OK);
    AK_CHECK_MSG(r.lo > 0.97 && r.hi < 1.03, "interior density %.4f..%.4f rho0", r.lo, r.hi);
    int checked = 0;
    for (int k = 1; k < 64; ++k) {
        const double T = k * every * dt * scale;
        if (T < 1.0 || T > 2.5) continue;
        const double want = martin_moyce_z(T), got = r.front[k];
        printf("  T %.2f: front Z %.3f, Martin & Moyce %.3f (%+.1f%%)\n", T, got, want, 100.0 * (got / want - 1.0));
        AK_CHECK_MSG(fabs(got / want - 1.0) < 0.12, "T %.2f: Z %.3f vs %.3f", T, got, want);
        ++checked;
    }
    AK_CHECK(checked >= 10);
}

static void free_fall(ak_fluid_solver solver) {
    ak_fluid_desc d;
    float s;
    dam_desc(&d, &s);
    d.solver = solver;
    d.viscosity = solver == AK_FLUID_PBF ? 0.0f : 0.01f;
    enum { CAP = 6 * 6 * 6 };
    ak_vec3 pos[CAP], vel[CAP];
    /* slightly compressed so internal forces are busy */
    size_t n = ak_fluid_fill_box(&d, ak_vec3_make(0, 0, 0), ak_vec3_make(6 * s, 6 * s, 6 * s), (ak_vec3_span)AK_SPAN(pos));
    for (size_t i = 0; i < n; ++i) pos[i] = ak_vec3_scale(pos[i], 0.9f);
    memset(vel, 0, sizeof vel);
    size_t bytes = ak_fluid_scratch_size(n, &d);
    void* mem = malloc(bytes);
    const float dt = solver == AK_FLUID_PBF ? 1.0f / 240.0f : 1e-4f;
    ak_fluid_step_job job = {.desc = &d, .dt = dt, .positions = {pos, n}, .velocities = {vel, n},
                             .particle_count = &n, .scratch = {mem, bytes}};
    const int steps = 40;
    for (int k = 0; k < steps; ++k) AK_CHECK_EQ(ak_fluid_step_run(&job), AK_OK);
    double px = 0, py = 0, pz = 0;
    for (size_t i = 0; i < n; ++i) px += vel[i].x, py += vel[i].y, pz += vel[i].z;
    const double M = (double)n * d.particle_mass, t = steps * (double)dt;
    const double want = M * -9.81 * t;
    AK_CHECK_NEAR(py * d.particle_mass, want, 1e-3 * fabs(want));
    AK_CHECK_NEAR(px * d.particle_mass, 0.0, 1e-3 * fabs(want));
    AK_CHECK_NEAR(pz * d.particle_mass, 0.0, 1e-3 * fabs(want));
    free(mem);
}

AK_TEST(free_fall_momentum_is_mgt) {
    free_fall(AK_FLUID_PBF);
    free_fall(AK_FLUID_SPH);
    free_fall(AK_FLUID_WCSPH);
}

/* A particle on a 30-degree plane slides with a = g sin(30): free slip, no sticking. */
AK_TEST(plane_free_slip_no_sticking) {
    ak_fluid_desc d = {.solver = AK_FLUID_SPH, .particle_mass = 0.001f, .h = 0.02f, .gravity = {0, -9.81f, 0}};
    const float c = cosf(0.5235988f), sn = sinf(0.5235988f);
    ak_fluid_collider plane = {.shape = AK_FLUID_PLANE, .normal = {sn, c, 0}};
    ak_vec3 pos[1] = {{0, 0, 0}}, vel[1] = {{0, 0, 0}};
    size_t n = 1;
    size_t bytes = ak_fluid_scratch_size(1, &d);
    void* mem = malloc(bytes);
    ak_fluid_step_job job = {.desc = &d, .dt = 1e-3f, .positions = {pos, 1}, .velocities = {vel, 1},
                             .particle_count = &n, .colliders = {&plane, 1}, .scratch = {mem, bytes}};
    for (int k = 0; k < 500; ++k) AK_CHECK_EQ(ak_fluid_step_run(&job), AK_OK);
    float speed = ak_vec3_length(vel[0]);
    AK_CHECK_NEAR(speed, 9.81f * sn * 0.5f, 0.01f * 9.81f * sn * 0.5f);
    AK_CHECK(ak_vec3_dot(pos[0], plane.normal) >= -1e-5f);
    free(mem);
}

/* Liquid poured on a sphere and a capsule, with a moving sphere sweeping past: no particle
 * ever ends a step inside a collider or outside the box. The moving sphere stays clear of the
 * fixed one (centres at least 7.2 s apart, radii 4 s and 3 s): where two colliders overlap, the
 * projection cannot always free a particle caught in the crease (see fluid.h). */
AK_TEST(colliders_never_leak) {
    ak_fluid_desc d;
    float s;
    dam_desc(&d, &s);
    d.box_min = ak_vec3_make(0, 0, 0);
    d.box_max = ak_vec3_make(20 * s, 30 * s, 20 * s);
    ak_fluid_collider cols[3] = {
        {.shape = AK_FLUID_SPHERE, .a = {10 * s, 8 * s, 10 * s}, .radius = 4 * s},
        {.shape = AK_FLUID_CAPSULE, .a = {2 * s, 3 * s, 5 * s}, .b = {18 * s, 3 * s, 5 * s}, .radius = 2 * s},
        {.shape = AK_FLUID_SPHERE, .a = {4 * s, 4 * s, 16.5f * s}, .radius = 3 * s, .velocity = {0.2f, 0, 0}},
    };
    enum { CAP = 600 };
    ak_vec3 pos[CAP], vel[CAP];
    size_t n = ak_fluid_fill_box(&d, ak_vec3_make(6 * s, 14 * s, 6 * s), ak_vec3_make(14 * s, 20 * s, 14 * s),
                                 (ak_vec3_span)AK_SPAN(pos));
    memset(vel, 0, sizeof vel);
    size_t bytes = ak_fluid_scratch_size(CAP, &d);
    void* mem = malloc(bytes);
    const float dt = 1.0f / 400.0f;
    ak_fluid_step_job job = {.desc = &d, .dt = dt, .positions = {pos, CAP}, .velocities = {vel, CAP},
                             .particle_count = &n, .colliders = {cols, 3}, .scratch = {mem, bytes}};
    bool ok = true;
    for (int k = 0; k < 200; ++k) {
        AK_CHECK_EQ(ak_fluid_step_run(&job), AK_OK);
        ok = ok && inside_box(pos, n, d.box_min, d.box_max);
        for (size_t i = 0; i < n; ++i) {
            float d0 = ak_vec3_distance(pos[i], cols[0].a) - cols[0].radius;
            float d2 = ak_vec3_distance(pos[i], cols[2].a) - cols[2].radius;
            float t = (pos[i].x - cols[1].a.x) / (cols[1].b.x - cols[1].a.x);
            t = t < 0 ? 0 : t > 1 ? 1 : t;
            ak_vec3 q = ak_vec3_add(cols[1].a, ak_vec3_scale(ak_vec3_sub(cols[1].b, cols[1].a), t));
            float d1 = ak_vec3_distance(pos[i], q) - cols[1].radius;
            if (d0 < -1e-4f * s || d1 < -1e-4f * s || d2 < -1e-4f * s) {
                if (ok) printf("  step %d particle %zu inside: %g %g %g\n", k, i, d0, d1, d2);
                ok = false;
            }
        }
        cols[2].a.x += cols[2].velocity.x * dt;
    }
    AK_CHECK(ok);
    free(mem);
}

AK_TEST(emitter_and_sink) {
    ak_fluid_desc d;
    float s;
    dam_desc(&d, &s);
    d.gravity = ak_vec3_make(0, 0, 0);
    /* a disc of radius 1.2 s holds the 9 lattice points with a^2 + b^2 <= 1.44: (0,0), 4 axis, 4 diagonal */
    ak_fluid_emitter em = {.position = {0, 0, 0}, .direction = {0, 0, 1}, .radius = 1.5f * s, .speed = 1.0f};
    ak_fluid_sink sink = {.min = {-1, -1, 20 * s}, .max = {1, 1, 10}};
    enum { CAP = 2000 };
    static ak_vec3 pos[CAP], vel[CAP];
    size_t n = 0;
    size_t bytes = ak_fluid_scratch_size(CAP, &d);
    void* mem = malloc(bytes);
    ak_fluid_stats st;
    const float dt = 1.0f / 240.0f;
    ak_fluid_step_job job = {.desc = &d, .dt = dt, .positions = {pos, CAP}, .velocities = {vel, CAP},
                             .particle_count = &n, .emitters = {&em, 1}, .scratch = {mem, bytes}, .out_stats = &st};
    size_t emitted = 0;
    const int steps = 24;
    for (int k = 0; k < steps; ++k) {
        job.time = k * dt;
        AK_CHECK_EQ(ak_fluid_step_run(&job), AK_OK);
        emitted += st.emitted_count;
    }
    /* layers at t = k s / speed for t < steps dt */
    size_t layers = (size_t)ceil(steps * dt / s);
    AK_CHECK_EQ(emitted, layers * 9);
    AK_CHECK_EQ(n, emitted);
    /* a sink across the stream removes what flows into it */
    job.sinks = (ak_fluid_sink_cspan){&sink, 1};
    job.emitters = (ak_fluid_emitter_cspan){NULL, 0};
    size_t removed = 0;
    for (int k = 0; k < 800; ++k) {
        AK_CHECK_EQ(ak_fluid_step_run(&job), AK_OK);
        removed += st.removed_count;
    }
    AK_CHECK_EQ(n, 0);
    AK_CHECK_EQ(removed, emitted);
    free(mem);
}

static void run_threads(uint32_t threads, ak_fluid_solver solver, ak_vec3* pos, ak_vec3* vel, size_t cap) {
    ak_fluid_desc d;
    float s;
    dam_desc(&d, &s);
    d.solver = solver;
    d.vorticity_epsilon = 0.5f;
    d.scorr = true;
    d.viscosity = 0.01f;
    d.box_min = ak_vec3_make(0, 0, 0);
    d.box_max = ak_vec3_make(24 * s, 20 * s, 12 * s);
    size_t n = ak_fluid_fill_box(&d, d.box_min, ak_vec3_make(12 * s, 12 * s, 10 * s), (ak_vec3_span){pos, cap});
    memset(vel, 0, cap * sizeof *vel);
    size_t bytes = ak_fluid_scratch_size(n, &d);
    void* mem = malloc(bytes);
    ak_fluid_step_job job = {.desc = &d, .dt = solver == AK_FLUID_PBF ? 1.0f / 400.0f : 2e-4f,
                             .positions = {pos, n}, .velocities = {vel, n}, .particle_count = &n,
                             .thread_count = threads, .scratch = {mem, bytes}};
    for (int k = 0; k < 6; ++k) AK_CHECK_EQ(ak_fluid_step_run(&job), AK_OK);
    free(mem);
}

AK_TEST(thread_count_gives_identical_results) {
    enum { CAP = 12 * 12 * 10 };
    static ak_vec3 p1[CAP], v1[CAP], p2[CAP], v2[CAP];
    const ak_fluid_solver solvers[] = {AK_FLUID_PBF, AK_FLUID_SPH};
    for (int k = 0; k < 2; ++k) {
        run_threads(1, solvers[k], p1, v1, CAP);
        run_threads(2, solvers[k], p2, v2, CAP);
        AK_CHECK(memcmp(p1, p2, sizeof p1) == 0 && memcmp(v1, v2, sizeof v1) == 0);
        run_threads(3, solvers[k], p2, v2, CAP);
        AK_CHECK(memcmp(p1, p2, sizeof p1) == 0 && memcmp(v1, v2, sizeof v1) == 0);
    }
}

/* A dam of 32 x 24 x 16 = 12,288 particles (dense cell sort over the team, several
 * thousand particles per thread) on 1, 2, 3 and 16 threads: the same positions, velocities,
 * densities and statistics, bit for bit, after 5 steps of either solver. */
AK_TEST(large_dam_thread_count_gives_identical_results) {
    enum { CAP = 32 * 24 * 16, STEPS = 5 };
    const uint32_t counts[4] = {1, 2, 3, 16};
    const ak_fluid_solver solvers[] = {AK_FLUID_PBF, AK_FLUID_SPH};
    ak_vec3* pos = malloc(CAP * sizeof(ak_vec3));
    ak_vec3* vel = malloc(CAP * sizeof(ak_vec3));
    float* rho = malloc(CAP * sizeof(float));
    ak_vec3* ref = malloc(2 * CAP * sizeof(ak_vec3));
    float* ref_rho = malloc(CAP * sizeof(float));
    for (int k = 0; k < 2; ++k) {
        ak_fluid_stats ref_st;
        memset(&ref_st, 0, sizeof ref_st);
        for (int c = 0; c < 4; ++c) {
            ak_fluid_desc d;
            float s;
            dam_desc(&d, &s);
            d.solver = solvers[k];
            d.vorticity_epsilon = 0.5f;
            d.box_max = ak_vec3_make(64 * s, 40 * s, 16 * s);
            size_t n = ak_fluid_fill_box(&d, d.box_min, ak_vec3_make(32 * s, 24 * s, 16 * s), (ak_vec3_span){pos, CAP});
            AK_CHECK(n > CAP / 2);
            memset(vel, 0, CAP * sizeof(ak_vec3));
            memset(rho, 0, CAP * sizeof(float));
            const size_t bytes = ak_fluid_scratch_size(n, &d);
            void* mem = malloc(bytes);
            ak_fluid_stats st;
            ak_fluid_step_job job = {.desc = &d, .dt = solvers[k] == AK_FLUID_PBF ? 1.0f / 400.0f : 2e-4f,
                                     .positions = {pos, n}, .velocities = {vel, n}, .particle_count = &n,
                                     .thread_count = counts[c], .scratch = {mem, bytes},
                                     .out_densities = {rho, n}, .out_stats = &st};
            for (int f = 0; f < STEPS; ++f) AK_CHECK_EQ(ak_fluid_step_run(&job), AK_OK);
            free(mem);
            st.neighbour_seconds = 0.0f; /* a time, not a result */
            if (c == 0) {
                memcpy(ref, pos, n * sizeof(ak_vec3));
                memcpy(ref + n, vel, n * sizeof(ak_vec3));
                memcpy(ref_rho, rho, n * sizeof(float));
                ref_st = st;
                AK_CHECK(st.full_count > 0);
            } else {
                const bool same = memcmp(ref, pos, n * sizeof(ak_vec3)) == 0 &&
                                  memcmp(ref + n, vel, n * sizeof(ak_vec3)) == 0 &&
                                  memcmp(ref_rho, rho, n * sizeof(float)) == 0;
                AK_CHECK_MSG(same, "solver %d: %u threads differ from 1", k, counts[c]);
                AK_CHECK(st.mean_density_error == ref_st.mean_density_error && st.full_count == ref_st.full_count);
            }
        }
    }
    free(pos), free(vel), free(rho), free(ref), free(ref_rho);
}

/* A jittered lattice block of 13 x 11 x 9 = 1287 particles (not a multiple of 16, above the
 * 1024 that the solver needs before it uses threads); far adds one particle 1000 h away, so
 * the bounding box is too sparse for the dense cell sort and the hashed grid path runs. */
enum { NAIVE_CAP = 13 * 11 * 9 + 1 };
static size_t jittered_block(const ak_fluid_desc* d, float s, ak_vec3* pos, bool far) {
    size_t n = 0;
    uint32_t state = 12345u;
    for (int z = 0; z < 9; ++z)
        for (int y = 0; y < 11; ++y)
            for (int x = 0; x < 13; ++x) {
                float j[3];
                for (int a = 0; a < 3; ++a) {
                    state = state * 1664525u + 1013904223u;
                    j[a] = ((float)(state >> 8) / 16777216.0f - 0.5f) * 0.4f * s;
                }
                pos[n++] = ak_vec3_make((x + 0.5f) * s + j[0], (y + 0.5f) * s + j[1], (z + 0.5f) * s + j[2]);
            }
    if (far) pos[n++] = ak_vec3_make(1000.0f * d->h, 3.0f * s, 3.0f * s);
    return n;
}

/* rho_i = m sum_j W_poly6(|x_i - x_j|) over every j, in double (no grid). */
static double naive_density(const ak_fluid_desc* d, const ak_vec3* pos, size_t n, size_t i) {
    const double h = d->h, h2 = h * h, k = 315.0 / (64.0 * PI_D * pow(h, 9.0));
    double rho = 0.0;
    for (size_t j = 0; j < n; ++j) {
        const double dx = (double)pos[i].x - pos[j].x, dy = (double)pos[i].y - pos[j].y, dz = (double)pos[i].z - pos[j].z;
        const double r2 = dx * dx + dy * dy + dz * dz;
        if (r2 < h2) rho += k * (h2 - r2) * (h2 - r2) * (h2 - r2);
    }
    return rho * d->particle_mass;
}

/* One SPH step reports the densities at the input positions: on both neighbour paths (dense
 * cells, hashed grid), every kernel set (scalar, AVX2, AVX-512, each where the CPU has it) and 1
 * or 3 threads they match the naive double sum within float rounding (relative 2e-5), and all
 * runs give the same bits. */
AK_TEST(densities_match_naive_sum_on_every_path) {
    ak_fluid_desc d;
    float s;
    dam_desc(&d, &s);
    d.solver = AK_FLUID_SPH;
    static ak_vec3 pos0[NAIVE_CAP], pos[NAIVE_CAP], vel[NAIVE_CAP];
    static float rho[NAIVE_CAP], first[NAIVE_CAP];
    for (int far = 0; far < 2; ++far) {
        const size_t n0 = jittered_block(&d, s, pos0, far == 1);
        double worst = 0.0;
        for (int run = 0; run < 6; ++run) {
            size_t n = n0;
            memcpy(pos, pos0, n * sizeof *pos);
            memset(vel, 0, sizeof vel);
            size_t bytes = ak_fluid_scratch_size(n, &d);
            void* mem = malloc(bytes);
            ak_fluid_step_job job = {.desc = &d, .dt = 1e-5f, .positions = {pos, n}, .velocities = {vel, n},
                                     .particle_count = &n, .thread_count = run & 1 ? 3u : 1u,
                                     .kernels = (ak_fluid_kernels)(AK_FLUID_KERNELS_SCALAR + run / 2), .scratch = {mem, bytes}, .out_densities = {rho, n}};
            AK_CHECK_EQ(ak_fluid_step_run(&job), AK_OK);
            free(mem);
            for (size_t i = 0; i < n0; ++i) {
                const double want = naive_density(&d, pos0, n0, i);
                const double err = fabs(rho[i] - want) / want;
                worst = err > worst ? err : worst;
            }
            if (run == 0) memcpy(first, rho, n0 * sizeof *rho);
            else AK_CHECK_MSG(memcmp(first, rho, n0 * sizeof *rho) == 0, "run %d differs (far %d)", run, far);
        }
        printf("  %s path: densities within %.2g of the naive double sum\n", far ? "hashed" : "dense", worst);
        AK_CHECK_MSG(worst < 2e-5, "relative density error %.3g (far %d)", worst, far);
        /* the far particle is alone: m W(0) */
        if (far) AK_CHECK_NEAR(rho[n0 - 1], d.particle_mass * ak_fluid_poly6(0.0f, d.h), 1e-6 * rho[n0 - 1]);
    }
}

typedef struct simd_case {
    const char* name;
    ak_fluid_solver solver;
    float scorr_n;
    uint32_t max_neighbours;
    bool far; /* no box and a particle 1000 h away: the hashed grid path */
} simd_case;

static void run_case(const simd_case* k, ak_fluid_kernels kernels, ak_vec3* pos, ak_vec3* vel, float* rho, float* pres,
                     uint8_t* flags, ak_fluid_stats* st) {
    ak_fluid_desc d;
    float s;
    dam_desc(&d, &s);
    d.solver = k->solver;
    d.scorr = true; /* the tensile term's paths (off by default) */
    d.scorr_n = k->scorr_n;
    d.max_neighbours = k->max_neighbours;
    d.vorticity_epsilon = 0.3f;
    d.viscosity = 0.01f;
    d.box_max = k->far ? d.box_min : ak_vec3_make(20 * s, 16 * s, 12 * s);
    size_t n = jittered_block(&d, s, pos, k->far);
    memset(vel, 0, NAIVE_CAP * sizeof *vel);
    const ak_fluid_collider cols[2] = {
        {.shape = AK_FLUID_SPHERE, .a = {16 * s, 2 * s, 6 * s}, .radius = 2.5f * s, .velocity = {-0.2f, 0, 0}},
        {.shape = AK_FLUID_CAPSULE, .a = {4 * s, 14 * s, 0}, .b = {4 * s, 14 * s, 12 * s}, .radius = 2 * s}};
    size_t bytes = ak_fluid_scratch_size(n, &d);
    void* mem = malloc(bytes);
    ak_fluid_step_job job = {.desc = &d, .dt = k->solver == AK_FLUID_PBF ? 1.0f / 400.0f : 2e-4f,
                             .positions = {pos, n}, .velocities = {vel, n}, .particle_count = &n,
                             .colliders = {cols, 2}, .thread_count = 2, .kernels = kernels,
                             .scratch = {mem, bytes}, .out_densities = {rho, n}, .out_pressures = {pres, n},
                             .out_flags = {flags, n}, .out_stats = st};
    const int steps = AK_TEST_REPS(8, 2); /* 2 under valgrind (AK_TEST_SELECT=light) */
    for (int step = 0; step < steps; ++step) AK_CHECK_EQ(ak_fluid_step_run(&job), AK_OK);
    free(mem);
}

/* The AVX2 and AVX-512 kernels (where this CPU has them) against the scalar ones: the same bits
 * for positions, velocities, densities, pressures, flags and statistics after 8 steps, for PBF (with the
 * tensile term's n = 4 fast path, a general n, lists truncated at 12 neighbours, and the hashed
 * grid path), SPH and WCSPH (their density and force kernels with viscosity, on the hashed grid
 * path and with truncated lists too), with moving colliders and 2 threads. */
AK_TEST(simd_and_scalar_kernels_are_bit_identical) {
    static ak_vec3 p1[NAIVE_CAP], v1[NAIVE_CAP], p2[NAIVE_CAP], v2[NAIVE_CAP];
    static float r1[NAIVE_CAP], r2[NAIVE_CAP], q1[NAIVE_CAP], q2[NAIVE_CAP];
    static uint8_t f1[NAIVE_CAP], f2[NAIVE_CAP];
    const simd_case cases[] = {{"pbf", AK_FLUID_PBF, 0.0f, 0, false},
                               {"pbf scorr n=3", AK_FLUID_PBF, 3.0f, 0, false},
                               {"pbf 12 neighbours", AK_FLUID_PBF, 0.0f, 12, false},
                               {"pbf hashed grid", AK_FLUID_PBF, 0.0f, 0, true},
                               {"sph", AK_FLUID_SPH, 0.0f, 0, false},
                               {"wcsph", AK_FLUID_WCSPH, 0.0f, 0, false},
                               {"sph hashed grid", AK_FLUID_SPH, 0.0f, 0, true},
                               {"wcsph 20 neighbours", AK_FLUID_WCSPH, 0.0f, 20, false}};
    const ak_fluid_kernels sets[] = {AK_FLUID_KERNELS_AVX2, AK_FLUID_KERNELS_AVX512};
    for (int s = 0; s < 2; ++s) {
        const ak_fluid_kernels got = ak_fluid_kernels_resolved(sets[s]);
        if (got != sets[s]) {
            printf("  %s: not on this CPU or build (runs %s; nothing to compare)\n", ak_fluid_kernels_name(sets[s]),
                   ak_fluid_kernels_name(got));
            continue;
        }
        printf("  %s against scalar\n", ak_fluid_kernels_name(sets[s]));
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        ak_fluid_stats s1, s2;
        run_case(&cases[k], sets[s], p1, v1, r1, q1, f1, &s1);
        run_case(&cases[k], AK_FLUID_KERNELS_SCALAR, p2, v2, r2, q2, f2, &s2);
        const size_t n = 13 * 11 * 9 + (cases[k].far ? 1 : 0);
        const bool same = memcmp(p1, p2, n * sizeof *p1) == 0 && memcmp(v1, v2, n * sizeof *v1) == 0 &&
                          memcmp(r1, r2, n * sizeof *r1) == 0 && memcmp(q1, q2, n * sizeof *q1) == 0 &&
                          memcmp(f1, f2, n) == 0 && s1.coincident_count == s2.coincident_count &&
                          s1.max_density_error == s2.max_density_error && s1.full_count == s2.full_count &&
                          s1.surface_count == s2.surface_count && s1.truncated_count == s2.truncated_count;
        AK_CHECK_MSG(same, "%s: %s and scalar kernels differ", cases[k].name, ak_fluid_kernels_name(sets[s]));
        if (cases[k].max_neighbours) AK_CHECK_MSG(s1.truncated_count > 0, "%s: nothing truncated", cases[k].name);
    }
    }
}

/* ak_fluid_step_run checks the particles' data on its threads when there are many (70,000
 * here): a non-finite position or velocity at the start, middle or end, on 1, 2 and 3 threads,
 * is AK_ERR_BAD_DATA with nothing written, as ak_fluid_step_validate (one thread) says; all
 * finite, the step runs. */
AK_TEST(validation_scan_split_over_threads) {
    enum { N = 70000 };
    ak_fluid_desc d = {.particle_mass = 0.001f, .h = 0.02f, .box_max = {1, 1, 1}};
    const float sp = ak_fluid_rest_spacing(&d);
    d.h = 2.0f * sp;
    ak_vec3* pos = malloc(N * sizeof(ak_vec3));
    ak_vec3* vel = calloc(N, sizeof(ak_vec3));
    ak_vec3* copy = malloc(2 * N * sizeof(ak_vec3));
    const size_t bytes = ak_fluid_scratch_size(N, &d);
    void* mem = malloc(bytes);
    AK_CHECK(pos && vel && copy && mem);
    if (!pos || !vel || !copy || !mem) return;
    for (size_t i = 0; i < N; ++i) /* a 50 x 50 x 28 lattice, the last layer part full */
        pos[i] = ak_vec3_make(sp * (float)(i % 50), sp * (float)(i / 2500), sp * (float)(i / 50 % 50));
    size_t n = N;
    ak_fluid_step_job job = {.desc = &d, .dt = 0.001f, .positions = {pos, N}, .velocities = {vel, N},
                             .particle_count = &n, .scratch = {mem, bytes}};
    const size_t at[3] = {0, N / 2, N - 1};
    for (uint32_t threads = 1; threads <= 3; ++threads) {
        job.thread_count = threads;
        for (int k = 0; k < 3; ++k)
            for (int field = 0; field < 2; ++field) {
                ak_vec3* a = field ? vel : pos;
                const float keep = a[at[k]].y;
                a[at[k]].y = field ? INFINITY : NAN;
                memcpy(copy, pos, N * sizeof(ak_vec3));
                memcpy(copy + N, vel, N * sizeof(ak_vec3));
                AK_CHECK_EQ(ak_fluid_step_validate(&job), AK_ERR_BAD_DATA);
                AK_CHECK_MSG(ak_fluid_step_run(&job) == AK_ERR_BAD_DATA, "%u threads, particle %zu", threads, at[k]);
                AK_CHECK(memcmp(copy, pos, N * sizeof(ak_vec3)) == 0 && memcmp(copy + N, vel, N * sizeof(ak_vec3)) == 0);
                a[at[k]].y = keep;
            }
    }
    job.thread_count = 2;
    AK_CHECK_EQ(ak_fluid_step_run(&job), AK_OK);
    AK_CHECK_EQ(n, (size_t)N);
    free(pos), free(vel), free(copy), free(mem);
}

AK_TEST(validation_and_blow_up) {
    ak_fluid_desc d = {.particle_mass = 0.001f, .h = 0.02f};
    ak_vec3 pos[4] = {{0, 0, 0}, {0.01f, 0, 0}}, vel[4] = {{0}};
    size_t n = 2;
    unsigned char mem[1];
    ak_fluid_step_job job = {.desc = &d, .dt = 0.01f, .positions = {pos, 4}, .velocities = {vel, 4},
                             .particle_count = &n, .scratch = {mem, 1}};
    AK_CHECK_EQ(ak_fluid_step_run(&job), AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_fluid_step_validate(NULL), AK_ERR_NULL_ARG);
    size_t bytes = ak_fluid_scratch_size(4, &d);
    void* big = malloc(bytes);
    job.scratch = (ak_u8_span){big, bytes};
    job.dt = 0.0f;
    AK_CHECK_EQ(ak_fluid_step_run(&job), AK_ERR_BAD_ARG);
    job.dt = 0.01f;
    job.kernels = AK_FLUID_KERNELS_COUNT;
    AK_CHECK_EQ(ak_fluid_step_run(&job), AK_ERR_BAD_ARG);
    job.kernels = AK_FLUID_KERNELS_BEST;
    AK_CHECK_EQ(ak_fluid_kernels_resolved(AK_FLUID_KERNELS_SCALAR), AK_FLUID_KERNELS_SCALAR);
    AK_CHECK(ak_fluid_kernels_resolved(AK_FLUID_KERNELS_BEST) != AK_FLUID_KERNELS_BEST);
    pos[1].x = NAN;
    AK_CHECK_EQ(ak_fluid_step_run(&job), AK_ERR_BAD_DATA);
    AK_CHECK(isnan(pos[1].x)); /* nothing written */
    pos[1].x = 0.01f;
    d.solver = AK_FLUID_SPH;
    d.stiffness = 1e9f; /* absurdly stiff at a huge step: blows up */
    pos[1].x = 0.001f;
    ak_result r = AK_OK;
    for (int k = 0; k < 50 && r == AK_OK; ++k) r = ak_fluid_step_run(&job);
    AK_CHECK_EQ(r, AK_ERR_NO_CONVERGENCE);
    free(big);
}

int main(void) {
    AK_RUN(kernels_integrate_to_one);
    AK_RUN(kernels_support);
    AK_RUN(kernel_gradients_match_finite_differences);
    AK_RUN(lattice_density_is_rest_density);
    AK_RUN_SLOW(hydrostatic_column_pressure_is_linear);
    AK_RUN_HEAVY(pbf_dam_break_keeps_interior_density); /* valgrind: the other cases step the same code */
    AK_RUN(free_fall_momentum_is_mgt);
    AK_RUN(plane_free_slip_no_sticking);
    AK_RUN(colliders_never_leak);
    AK_RUN(emitter_and_sink);
    AK_RUN(thread_count_gives_identical_results);
    AK_RUN(large_dam_thread_count_gives_identical_results);
    AK_RUN(densities_match_naive_sum_on_every_path);
    AK_RUN(simd_and_scalar_kernels_are_bit_identical);
    AK_RUN(validation_scan_split_over_threads);
    AK_RUN(validation_and_blow_up);
    AK_RUN_SLOW(pbf_dam_break_front_against_martin_moyce);
    return ak_test_finish();
}
