/* Tests for particle systems: closed forms, convergence orders, energy, collisions, emission. */
#include <animkit/particles.h>

#include "ak_test.h"

static const ak_particles_integrator kIntegrators[4] = {
    AK_INTEGRATOR_EULER, AK_INTEGRATOR_SYMPLECTIC, AK_INTEGRATOR_VERLET, AK_INTEGRATOR_RK4};

static ak_particles* make(uint32_t cap, ak_particles_integrator integ, uint32_t threads,
                          uint64_t seed) {
    ak_particles* ps = NULL;
    ak_particles_desc d = {
        .capacity = cap, .integrator = integ, .thread_count = threads, .seed = seed};
    AK_CHECK_EQ(ak_particles_create(&d, NULL, &ps), AK_OK);
    return ps;
}

static size_t add(ak_particles* ps, ak_vec3 p, ak_vec3 v, float mass) {
    size_t idx = 0;
    ak_particle_init in = {.position = p, .velocity = v, .mass = mass};
    AK_CHECK_EQ(ak_particles_add(ps, &in, &idx), AK_OK);
    return idx;
}

/* ---- integrators against closed forms -------------------------------------------------- */

AK_TEST(projectile_closed_forms) {
    const double g = -9.81, dt = 0.01, vx = 3.0, vy = 10.0;
    const int n = 150;
    for (int k = 0; k < 4; ++k) {
        ak_particles* ps = make(4, kIntegrators[k], 1, 1);
        add(ps, ak_vec3_make(0, 1, 0), ak_vec3_make((float)vx, (float)vy, 0), 2.0f);
        ak_particles_world w = {.gravity = {0, (float)g, 0}};
        for (int s = 0; s < n; ++s) AK_CHECK_EQ(ak_particles_step(ps, &w, (float)dt), AK_OK);
        ak_particles_state st = ak_particles_get_state(ps);
        const double t = n * dt;
        /* Exact: y = 1 + vy t + g t^2 / 2. Explicit Euler lags by g dt t / 2, semi-implicit
         * Euler leads by it (sum of n(n-1)/2 vs n(n+1)/2 dt^2 g). */
        double y = 1.0 + vy * t + 0.5 * g * t * t;
        if (kIntegrators[k] == AK_INTEGRATOR_EULER)
            y = 1.0 + vy * t + g * dt * dt * n * (n - 1) / 2.0;
        if (kIntegrators[k] == AK_INTEGRATOR_SYMPLECTIC)
            y = 1.0 + vy * t + g * dt * dt * n * (n + 1) / 2.0;
        printf("  integrator %d: position error %.2g, velocity error %.2g\n", k,
               fabs(st.position[0].y - y), fabs(st.velocity[0].y - (vy + g * t)));
        /* Float rounding only: a few ulps of the magnitudes (about 10) per step. */
        AK_CHECK_NEAR(st.position[0].y, y, 2e-6 * n);
        AK_CHECK_NEAR(st.position[0].x, vx * t, 2e-6 * n);
        AK_CHECK_NEAR(st.velocity[0].y, vy + g * t, 2e-6 * n);
        AK_CHECK_NEAR(st.velocity[0].x, vx, 1e-6);
        AK_CHECK_NEAR(ak_particles_time(ps), n * (double)(float)dt, 1e-9);
        if (kIntegrators[k] == AK_INTEGRATOR_EULER ||
            kIntegrators[k] == AK_INTEGRATOR_SYMPLECTIC) /* first order */
            AK_CHECK(fabs(st.position[0].y - (1.0 + vy * t + 0.5 * g * t * t)) > 0.05);
        ak_particles_destroy(ps);
    }
}

/* Damped oscillator x'' = -(k x + c x') / m, anchor pinned at the origin, rest length 0. */
static double oscillator_error(ak_particles_integrator integ, double dt, double T) {
    const double k = 4.0, c = 0.4, m = 1.0;
    ak_particles* ps = make(4, integ, 1, 1);
    add(ps, ak_vec3_zero(), ak_vec3_zero(), 0.0f); /* pinned anchor */
    add(ps, ak_vec3_make(1, 0, 0), ak_vec3_zero(), (float)m);
    ak_particle_spring sp = {.i = 0, .j = 1, .rest = 0.0f, .k = (float)k, .damping = (float)c};
    ak_particles_world w = {.springs = {&sp, 1}};
    const int n = (int)lround(T / dt);
    const double g = c / (2 * m), wd = sqrt(k / m - g * g);
    double err = 0.0; /* largest error over the run (an end-point error can pass near zero) */
    for (int s = 1; s <= n; ++s) {
        ak_particles_step(ps, &w, (float)dt);
        const double t = s * (double)(float)dt;
        const double x = exp(-g * t) * (cos(wd * t) + g / wd * sin(wd * t));
        err = fmax(err, fabs(ak_particles_get_state(ps).position[1].x - x));
    }
    ak_particles_destroy(ps);
    return err;
}

AK_TEST(convergence_orders) {
    /* Halving dt divides the error by 2, 2, 4, 16 (each time step chosen so the error is in
     * the asymptotic range and well above float rounding). */
    const double dts[4] = {0.004, 0.004, 0.02, 0.1};
    const double want[4] = {2, 2, 4, 16};
    for (int k = 0; k < 4; ++k) {
        double e1 = oscillator_error(kIntegrators[k], dts[k], 4.0);
        double e2 = oscillator_error(kIntegrators[k], dts[k] / 2, 4.0);
        double ratio = e1 / e2;
        printf("  integrator %d: error %.3g -> %.3g, ratio %.3f (want %.0f)\n", k, e1, e2, ratio,
               want[k]);
        AK_CHECK_NEAR(ratio, want[k], 0.15 * want[k]);
    }
}

static double spring_energy_drift(ak_particles_integrator integ) {
    ak_particles* ps = make(4, integ, 1, 1);
    add(ps, ak_vec3_zero(), ak_vec3_zero(), 0.0f);
    add(ps, ak_vec3_make(1, 0, 0), ak_vec3_make(0, 0, 0), 1.0f);
    ak_particle_spring sp = {.i = 0, .j = 1, .rest = 0.0f, .k = 100.0f};
    ak_particles_world w = {.springs = {&sp, 1}};
    const double e0 = 0.5 * 100.0;
    double worst = 0.0;
    for (int s = 0; s < 10000; ++s) {
        ak_particles_step(ps, &w, 0.0005f);
        ak_particles_state st = ak_particles_get_state(ps);
        double x = st.position[1].x, v = st.velocity[1].x;
        double e = 0.5 * v * v + 0.5 * 100.0 * x * x;
        if (fabs(e - e0) / e0 > fabs(worst)) worst = (e - e0) / e0;
    }
    ak_particles_destroy(ps);
    return worst;
}

AK_TEST(energy_symplectic_vs_euler) {
    double euler = spring_energy_drift(AK_INTEGRATOR_EULER);
    double sympl = spring_energy_drift(AK_INTEGRATOR_SYMPLECTIC);
    double verlet = spring_energy_drift(AK_INTEGRATOR_VERLET);
    printf("  worst relative energy change over 10000 steps: euler %+.4f symplectic %+.5f verlet "
           "%+.7f\n",
           euler, sympl, verlet);
    AK_CHECK(fabs(sympl) < 0.01);
    AK_CHECK(fabs(verlet) < 0.01);
    AK_CHECK(euler > 0.05); /* explicit Euler gains energy: (1 + w^2 dt^2)^(n/2) - 1 = 13% */
}

/* ---- forces ---------------------------------------------------------------------------- */

AK_TEST(drag_wind_attractor_vortex) {
    /* Linear drag towards the wind: v(t) = w + (v0 - w) exp(-k t / m), with RK4. */
    ak_particles* ps = make(4, AK_INTEGRATOR_RK4, 1, 1);
    add(ps, ak_vec3_zero(), ak_vec3_make(5, 0, 0), 2.0f);
    ak_particles_world w = {.drag_linear = 0.8f, .wind = {1, 2, 0}};
    for (int s = 0; s < 100; ++s) ak_particles_step(ps, &w, 0.01f);
    double f = exp(-0.8 * 1.0 / 2.0);
    ak_vec3 v = ak_particles_get_state(ps).velocity[0];
    AK_CHECK_NEAR(v.x, 1.0 + 4.0 * f, 1e-5);
    AK_CHECK_NEAR(v.y, 2.0 - 2.0 * f, 1e-5);
    ak_particles_destroy(ps);

    /* Quadratic drag on a 1D fall from rest: terminal speed sqrt(m g / k2). */
    ps = make(4, AK_INTEGRATOR_RK4, 1, 1);
    add(ps, ak_vec3_zero(), ak_vec3_zero(), 1.0f);
    ak_particles_world q = {.gravity = {0, -9.81f, 0}, .drag_quadratic = 0.5f};
    for (int s = 0; s < 1000; ++s) ak_particles_step(ps, &q, 0.01f);
    AK_CHECK_NEAR(ak_particles_get_state(ps).velocity[0].y, -sqrt(9.81 / 0.5), 1e-4);
    ak_particles_destroy(ps);

    /* One explicit Euler step: dv = dt F / m with the documented formulas. */
    ps = make(4, AK_INTEGRATOR_EULER, 1, 1);
    add(ps, ak_vec3_make(3, 4, 0), ak_vec3_zero(), 2.0f);
    ak_particle_attractor at = {.position = {0, 0, 0}, .strength = 10.0f, .softening = 1.0f};
    ak_particle_vortex vo = {
        .center = {0, 7, 0}, .axis = {0, 2, 0}, .strength = 3.0f, .softening = 0.5f};
    ak_particles_world fw = {.attractors = {&at, 1}, .vortices = {&vo, 1}};
    ak_particles_step(ps, &fw, 0.1f);
    /* attractor: 10 * (-3,-4,0) / 26^1.5; vortex: axis y, r = (3,0,0): (y x r) = (0,0,-3),
     * 3/(9+0.25) */
    double s = 10.0 / pow(26.0, 1.5), sv = 3.0 / 9.25;
    ak_vec3 v1 = ak_particles_get_state(ps).velocity[0];
    AK_CHECK_NEAR(v1.x, 0.1 * (-3 * s) / 2.0, 1e-7);
    AK_CHECK_NEAR(v1.y, 0.1 * (-4 * s) / 2.0, 1e-7);
    AK_CHECK_NEAR(v1.z, 0.1 * (-3 * sv) / 2.0, 1e-7);
    ak_particles_destroy(ps);
}

static void push_up(const ak_vec3* p, const ak_vec3* v, const float* im, size_t n, double t,
                    ak_vec3* f, void* user) {
    (void)p, (void)v, (void)im, (void)t;
    int* calls = (int*)user;
    ++*calls;
    for (size_t i = 0; i < n; ++i) f[i].y += 9.81f; /* 1 kg: cancels gravity */
}

AK_TEST(spring_damping_and_callback) {
    /* Spring force: k (len - rest) + damping (relative velocity along the spring). */
    ak_particles* ps = make(4, AK_INTEGRATOR_EULER, 1, 1);
    add(ps, ak_vec3_zero(), ak_vec3_zero(), 0.0f);
    add(ps, ak_vec3_make(0, 3, 0), ak_vec3_make(0, 2, 1), 1.0f);
    ak_particle_spring sp = {.i = 0, .j = 1, .rest = 1.0f, .k = 10.0f, .damping = 0.5f};
    ak_particles_world w = {.springs = {&sp, 1}};
    ak_particles_step(ps, &w, 0.01f);
    ak_particles_state st = ak_particles_get_state(ps);
    AK_CHECK_NEAR(st.force[1].y, -(10.0 * 2.0 + 0.5 * 2.0), 1e-5);
    AK_CHECK_NEAR(st.force[0].y, 10.0 * 2.0 + 0.5 * 2.0, 1e-5);
    AK_CHECK_NEAR(st.velocity[1].y, 2.0 - 0.01 * 21.0, 1e-6);
    AK_CHECK_NEAR(st.position[0].y, 0.0, 0.0); /* pinned */
    ak_particles_destroy(ps);

    int calls = 0;
    ps = make(4, AK_INTEGRATOR_RK4, 1, 1);
    add(ps, ak_vec3_make(0, 1, 0), ak_vec3_zero(), 1.0f);
    ak_particles_world cw = {
        .gravity = {0, -9.81f, 0}, .callback = push_up, .callback_user = &calls};
    for (int s = 0; s < 10; ++s) ak_particles_step(ps, &cw, 0.01f);
    AK_CHECK_EQ(calls, 40); /* four evaluations per RK4 step */
    AK_CHECK_NEAR(ak_particles_get_state(ps).position[0].y, 1.0, 1e-6);
    ak_particles_destroy(ps);
}

AK_TEST(lennard_jones_matches_brute_force) {
    ak_particles* ps = make(600, AK_INTEGRATOR_SYMPLECTIC, 1, 1);
    ak_rng rng = ak_rng_make(4);
    for (int i = 0; i < 500; ++i)
        add(ps,
            ak_vec3_make(ak_rng_range(&rng, 0, 4), ak_rng_range(&rng, 0, 4),
                         ak_rng_range(&rng, 0, 4)),
            ak_vec3_zero(), 1.0f);
    ak_particles_state st = ak_particles_get_state(ps);
    ak_vec3 p[500];
    memcpy(p, st.position, sizeof p);
    ak_particles_world w = {.lennard_jones = {.epsilon = 0.01f, .sigma = 0.3f, .cutoff = 0.6f}};
    ak_particles_step(ps, &w, 1e-4f);
    st = ak_particles_get_state(ps);
    double worst = 0.0;
    int interacting = 0;
    for (int i = 0; i < 500; ++i) {
        double f[3] = {0, 0, 0};
        for (int j = 0; j < 500; ++j) {
            double d[3] = {p[i].x - p[j].x, p[i].y - p[j].y, p[i].z - p[j].z};
            double r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            if (j == i || r2 >= 0.36) continue;
            double q6 = pow(0.09 / r2, 3), s = 24 * 0.01 * (2 * q6 * q6 - q6) / r2;
            for (int a = 0; a < 3; ++a) f[a] += s * d[a];
        }
        interacting += f[0] != 0.0;
        double scale = 1.0 + fabs(f[0]) + fabs(f[1]) + fabs(f[2]);
        worst = fmax(worst, fabs(st.force[i].x - f[0]) / scale);
        worst = fmax(worst, fabs(st.force[i].y - f[1]) / scale);
        worst = fmax(worst, fabs(st.force[i].z - f[2]) / scale);
    }
    AK_CHECK(interacting > 200);
    AK_CHECK(worst < 1e-4);
    ak_particles_destroy(ps);
}

/* ---- collisions ------------------------------------------------------------------------ */

AK_TEST(floor_touch_time_and_no_tunnelling) {
    const double h = 2.0, g = 9.81, dt = 0.002;
    for (int k = 0; k < 4; ++k) {
        ak_particles* ps = make(4, kIntegrators[k], 1, 1);
        add(ps, ak_vec3_make(0, (float)h, 0), ak_vec3_zero(), 1.0f);
        ak_particle_plane floor = {.normal = {0, 1, 0}};
        ak_particles_world w = {.gravity = {0, (float)-g, 0}, .planes = {&floor, 1}};
        double touch = -1.0;
        for (int s = 1; s <= 1000 && touch < 0; ++s) {
            ak_particles_step(ps, &w, (float)dt);
            if (ak_particles_get_state(ps).position[0].y <= 1e-6f) touch = s * dt;
        }
        /* Within one step of the closed form (Euler lags, semi-implicit Euler leads). */
        AK_CHECK_NEAR(touch, sqrt(2 * h / g), dt + 1e-9);
        ak_particles_destroy(ps);
    }
    /* 100 m/s at a plane 0.5 m away with dt = 0.1 (10 m per step), and at a sphere. */
    ak_particles* ps = make(4, AK_INTEGRATOR_SYMPLECTIC, 1, 1);
    add(ps, ak_vec3_make(0, 0.5f, 0), ak_vec3_make(0, -100, 0), 1.0f);
    add(ps, ak_vec3_make(10, 3, 0), ak_vec3_make(0, -100, 0), 1.0f);
    ak_particle_plane floor = {.normal = {0, 2, 0}, .restitution = 1.0f};
    ak_particle_sphere ball = {.center = {10, 1, 0}, .radius = 0.5f, .restitution = 1.0f};
    ak_particles_world w = {.planes = {&floor, 1}, .spheres = {&ball, 1}};
    ak_particles_step(ps, &w, 0.1f);
    ak_particles_state st = ak_particles_get_state(ps);
    AK_CHECK_NEAR(st.position[0].y, 9.5, 1e-4); /* reflected: 0.5 down, 9.5 up */
    AK_CHECK_NEAR(st.velocity[0].y, 100.0, 1e-4);
    AK_CHECK_NEAR(st.position[1].y, 1.5 + 8.5, 1e-4); /* hits the top at 1.5 after 1.5 m */
    AK_CHECK_NEAR(st.velocity[1].y, 100.0, 1e-4);
    ak_particles_destroy(ps);
}

/* Highest point after the first bounce of a drop from h onto a collider. */
static double rebound_height(ak_particles_integrator integ, float e, int use_sphere, int use_mesh) {
    ak_particles* ps = make(4, integ, 1, 1);
    add(ps, ak_vec3_make(0.0f, 1.0f, 0.0f), ak_vec3_zero(), 1.0f);
    ak_particle_plane floor = {.normal = {0, 1, 0}, .restitution = e};
    ak_particle_sphere ball = {.center = {0, -10, 0}, .radius = 10.0f, .restitution = e};
    ak_vec3 quad[4] = {{-5, 0, -5}, {5, 0, -5}, {5, 0, 5}, {-5, 0, 5}};
    uint32_t tri[6] = {0, 2, 1, 0, 3, 2};
    ak_particle_mesh* mesh = NULL;
    ak_particle_mesh_desc md = {
        .positions = AK_SPAN(quad), .indices = AK_SPAN(tri), .restitution = e};
    AK_CHECK_EQ(ak_particle_mesh_create(&md, NULL, &mesh), AK_OK);
    const ak_particle_mesh* meshes[1] = {mesh};
    ak_particles_world w = {.gravity = {0, -9.81f, 0}};
    if (use_sphere)
        w.spheres = (ak_particle_sphere_cspan){&ball, 1};
    else if (use_mesh)
        w.meshes = (ak_particle_mesh_cspan){meshes, 1};
    else
        w.planes = (ak_particle_plane_cspan){&floor, 1};
    double best = 0.0;
    bool bounced = false;
    for (int s = 0; s < 3000; ++s) {
        ak_particles_step(ps, &w, 0.0005f);
        ak_particles_state st = ak_particles_get_state(ps);
        if (st.velocity[0].y > 0.0f) bounced = true;
        if (bounced && st.velocity[0].y < 0.0f) break;
        if (bounced) best = fmax(best, st.position[0].y);
    }
    ak_particle_mesh_destroy(mesh);
    ak_particles_destroy(ps);
    return best;
}

AK_TEST(restitution_rebound_ratio) {
    const float es[3] = {0.3f, 0.6f, 0.9f};
    for (int k = 0; k < 3; ++k) {
        double e2 = (double)es[k] * es[k];
        AK_CHECK_NEAR(rebound_height(AK_INTEGRATOR_VERLET, es[k], 0, 0), e2, 0.01 * e2);
        AK_CHECK_NEAR(rebound_height(AK_INTEGRATOR_SYMPLECTIC, es[k], 0, 0), e2, 0.01 * e2);
        AK_CHECK_NEAR(rebound_height(AK_INTEGRATOR_RK4, es[k], 1, 0), e2,
                      0.01 * e2); /* top of a sphere */
        AK_CHECK_NEAR(rebound_height(AK_INTEGRATOR_VERLET, es[k], 0, 1), e2,
                      0.01 * e2); /* triangle mesh */
    }
}

AK_TEST(friction_stopping_distance) {
    const float mus[2] = {0.3f, 0.8f};
    for (int k = 0; k < 2; ++k)
        for (int integ = 1; integ < 4; ++integ) {
            ak_particles* ps = make(4, kIntegrators[integ], 1, 1);
            add(ps, ak_vec3_zero(), ak_vec3_make(4, 0, 0), 1.0f);
            ak_particle_plane floor = {
                .normal = {0, 1, 0}, .friction = mus[k], .restitution = 0.5f};
            ak_particles_world w = {.gravity = {0, -9.81f, 0}, .planes = {&floor, 1}};
            for (int s = 0; s < 5000; ++s) ak_particles_step(ps, &w, 0.001f);
            ak_particles_state st = ak_particles_get_state(ps);
            double want = 16.0 / (2.0 * mus[k] * 9.81);
            AK_CHECK_NEAR(st.position[0].x, want, 0.01 * want);
            AK_CHECK_NEAR(st.velocity[0].x, 0.0, 1e-6);
            AK_CHECK_NEAR(st.position[0].y, 0.0, 1e-6);
            ak_particles_destroy(ps);
        }
}

AK_TEST(box_and_moving_mesh) {
    /* Straight at a box face: reflected with restitution 1. */
    ak_particles* ps = make(8, AK_INTEGRATOR_SYMPLECTIC, 1, 1);
    add(ps, ak_vec3_make(-2, 0.5f, 0.5f), ak_vec3_make(10, 0, 0), 1.0f);
    ak_particle_box box = {.min = {0, 0, 0}, .max = {1, 1, 1}, .restitution = 1.0f};
    ak_particles_world w = {.boxes = {&box, 1}};
    for (int s = 0; s < 30; ++s) ak_particles_step(ps, &w, 0.01f);
    ak_particles_state st = ak_particles_get_state(ps);
    AK_CHECK_NEAR(st.velocity[0].x, -10.0, 1e-4);
    AK_CHECK_NEAR(st.position[0].x, -1.0, 1e-4); /* 2 m to the face at x = 0, then 1 m back */
    ak_particles_destroy(ps);

    /* A mesh moved between steps: particles resting on it stay above it (never fall through). */
    ps = make(64, AK_INTEGRATOR_SYMPLECTIC, 1, 1);
    for (int i = 0; i < 50; ++i)
        add(ps, ak_vec3_make(-2 + 0.08f * i, 0.5f, 0.03f * i - 1), ak_vec3_zero(), 1.0f);
    ak_vec3 quad[4] = {{-5, 0, -5}, {5, 0, -5}, {5, 0, 5}, {-5, 0, 5}};
    uint32_t tri[6] = {0, 2, 1, 0, 3, 2};
    ak_particle_mesh* mesh = NULL;
    ak_particle_mesh_desc md = {.positions = AK_SPAN(quad), .indices = AK_SPAN(tri)};
    AK_CHECK_EQ(ak_particle_mesh_create(&md, NULL, &mesh), AK_OK);
    const ak_particle_mesh* meshes[1] = {mesh};
    ak_particles_world mw = {.gravity = {0, -9.81f, 0}, .meshes = {meshes, 1}};
    for (int s = 0; s < 400; ++s) {
        float h = s < 200 ? 0.0f : 0.001f * (s - 200); /* rises 1 mm per step after 200 steps */
        for (int k = 0; k < 4; ++k) quad[k].y = h;
        AK_CHECK_EQ(ak_particle_mesh_update(mesh, (ak_vec3_cspan)AK_SPAN(quad), 0.005f), AK_OK);
        ak_particles_step(ps, &mw, 0.005f);
        st = ak_particles_get_state(ps);
        int below = 0;
        for (size_t i = 0; i < st.count; ++i) below += st.position[i].y < h - 1e-4f;
        AK_CHECK_EQ(below, 0);
        if (below) break;
    }
    ak_particle_mesh_destroy(mesh);
    ak_particles_destroy(ps);
}

/* ---- emission, lifetime, determinism --------------------------------------------------- */

AK_TEST(emission_counts) {
    const float dts[3] = {0.01f, 0.1f, 1.0f / 60.0f};
    const int steps[3] = {200, 20, 120};
    for (int k = 0; k < 3; ++k) {
        ak_particles* ps = make(100, AK_INTEGRATOR_DEFAULT, 1, 1);
        ak_particle_emitter e = {.rate = 2.5f, .speed_min = 1, .speed_max = 2};
        uint32_t total = 0, got = 0;
        for (int s = 0; s < steps[k]; ++s) {
            AK_CHECK_EQ(ak_particles_emit(ps, &e, dts[k], &got), AK_OK);
            total += got;
        }
        AK_CHECK_EQ(total, 5);
        AK_CHECK_EQ(ak_particles_count(ps), 5);
        ak_particles_destroy(ps);
    }
    /* 1000/s for one second at 60 Hz; bursts; capacity drops the rest. */
    ak_particles* ps = make(1500, AK_INTEGRATOR_DEFAULT, 1, 1);
    ak_particle_emitter e = {.rate = 1000.0f};
    for (int s = 0; s < 60; ++s) ak_particles_emit(ps, &e, 1.0f / 60.0f, NULL);
    AK_CHECK_EQ(ak_particles_count(ps), 1000);
    uint32_t got = 0;
    AK_CHECK_EQ(ak_particles_burst(ps, &e, 300, &got), AK_OK);
    AK_CHECK_EQ(got, 300);
    AK_CHECK_EQ(ak_particles_burst(ps, &e, 300, &got), AK_OK);
    AK_CHECK_EQ(got, 200);
    AK_CHECK_EQ(ak_particles_count(ps), 1500);
    ak_particles_destroy(ps);
}

AK_TEST(emitter_shapes_and_ranges) {
    ak_particles* ps = make(20000, AK_INTEGRATOR_DEFAULT, 1, 3);
    const ak_vec3 c = {1, 2, 3};
    ak_particle_emitter base = {.center = c,
                                .radius = 0.5f,
                                .half_extents = {0.2f, 0.4f, 0.6f},
                                .direction = {0, 0, 3},
                                .cone_angle = 0.4f,
                                .speed_min = 2,
                                .speed_max = 3,
                                .lifetime_min = 1,
                                .lifetime_max = 2,
                                .size_min = 0.1f,
                                .size_max = 0.2f};
    for (int shape = 0; shape < 5; ++shape) {
        ak_particles_clear(ps);
        ak_particle_emitter e = base;
        e.shape = (ak_emitter_shape)shape;
        AK_CHECK_EQ(ak_particles_burst(ps, &e, 2000, NULL), AK_OK);
        ak_particles_state st = ak_particles_get_state(ps);
        int bad = 0;
        double mean_r = 0.0;
        for (size_t i = 0; i < st.count; ++i) {
            ak_vec3 d = ak_vec3_sub(st.position[i], c);
            float r = ak_vec3_length(d), speed = ak_vec3_length(st.velocity[i]);
            mean_r += r / (double)st.count;
            float cosang = st.velocity[i].z / speed;
            bad += speed < 2.0f - 1e-5f || speed > 3.0f + 1e-5f || cosang < cosf(0.4f) - 1e-5f;
            bad += st.lifetime[i] < 1.0f || st.lifetime[i] > 2.0f || st.size[i] < 0.1f ||
                   st.size[i] > 0.2f;
            if (shape == AK_EMITTER_POINT) bad += r != 0.0f;
            if (shape == AK_EMITTER_SPHERE) bad += r > 0.5f + 1e-5f;
            if (shape == AK_EMITTER_SPHERE_SURFACE) bad += fabsf(r - 0.5f) > 1e-5f;
            if (shape == AK_EMITTER_DISC)
                bad += r > 0.5f + 1e-5f || fabsf(d.z) > 1e-5f; /* disc faces +Z */
            if (shape == AK_EMITTER_BOX)
                bad += fabsf(d.x) > 0.2f || fabsf(d.y) > 0.4f || fabsf(d.z) > 0.6f;
        }
        AK_CHECK_EQ(bad, 0);
        /* Uniform densities: mean radius 3/4 R in a ball, 2/3 R on a disc. */
        if (shape == AK_EMITTER_SPHERE) AK_CHECK_NEAR(mean_r, 0.375, 0.01);
        if (shape == AK_EMITTER_DISC) AK_CHECK_NEAR(mean_r, 1.0 / 3.0, 0.01);
    }
    /* Mesh: two triangles of areas 0.5 and 1.5 in the z = 0 plane: a quarter of the samples
     * in the first; velocities along the normal (+Z for counter-clockwise corners). */
    ak_vec3 v[5] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}, {2, 3, 0}};
    uint32_t idx[6] = {0, 1, 2, 1, 3, 4};
    float cdf[2];
    ak_particle_emitter me = {.shape = AK_EMITTER_MESH,
                              .mesh_positions = AK_SPAN(v),
                              .mesh_indices = AK_SPAN(idx),
                              .mesh_area_cdf = AK_SPAN(cdf),
                              .speed_min = 1,
                              .speed_max = 1};
    ak_particles_clear(ps);
    AK_CHECK_EQ(ak_particles_burst(ps, &me, 20000, NULL), AK_OK);
    ak_particles_state st = ak_particles_get_state(ps);
    int first = 0, bad = 0;
    for (size_t i = 0; i < st.count; ++i) {
        ak_vec3 p = st.position[i];
        bool in1 = p.x >= 0 && p.y >= 0 && p.x + p.y <= 1.0f + 1e-5f;
        first += in1;
        bad += fabsf(p.z - 1e-4f) > 1e-6f || fabsf(st.velocity[i].z - 1.0f) > 1e-5f;
    }
    AK_CHECK_EQ(bad, 0);
    AK_CHECK_NEAR(first / 20000.0, 0.25, 0.015);
    ak_particles_destroy(ps);
}

AK_TEST(lifetime_expiry_keeps_order) {
    ak_particles* ps = make(100, AK_INTEGRATOR_DEFAULT, 1, 1);
    add(ps, ak_vec3_zero(), ak_vec3_zero(), 0.0f); /* pinned, immortal: index 0 forever */
    ak_particle_emitter shortlived = {.lifetime_min = 0.5f, .lifetime_max = 0.5f};
    ak_particle_emitter longlived = {.lifetime_min = 5.0f, .lifetime_max = 5.0f};
    ak_particles_burst(ps, &longlived, 3, NULL);
    ak_particles_burst(ps, &shortlived, 10, NULL);
    ak_particles_burst(ps, &longlived, 3, NULL);
    ak_particles_world w = {.gravity = {0, -1, 0}};
    for (int s = 0; s < 4; ++s) ak_particles_step(ps, &w, 0.1f);
    AK_CHECK_EQ(ak_particles_count(ps), 17);
    ak_particles_step(ps, &w, 0.1f); /* age 0.5 >= lifetime 0.5 */
    AK_CHECK_EQ(ak_particles_count(ps), 7);
    ak_particles_state st = ak_particles_get_state(ps);
    const uint32_t ids[7] = {0, 1, 2, 3, 14, 15, 16};
    for (int i = 0; i < 7; ++i) AK_CHECK_EQ(st.id[i], ids[i]);
    AK_CHECK_NEAR(st.position[0].y, 0.0, 0.0);
    ak_particles_destroy(ps);
}

/* A busy scene: everything on, 20000 particles (enough for several threads). */
static ak_particles* busy_run(ak_particles_integrator integ, uint32_t threads, uint64_t seed) {
    ak_particles* ps = make(20000, integ, threads, seed);
    ak_particle_emitter e = {.shape = AK_EMITTER_SPHERE,
                             .center = {0, 2, 0},
                             .radius = 1.5f,
                             .cone_angle = 1.0f,
                             .speed_min = 0,
                             .speed_max = 3,
                             .lifetime_min = 0.1f,
                             .lifetime_max = 2.0f};
    ak_particles_burst(ps, &e, 18000, NULL);
    ak_particle_spring springs[100];
    for (uint32_t k = 0; k < 100; ++k)
        springs[k] = (ak_particle_spring){k, k + 1, 0.1f, 50.0f, 0.2f};
    for (uint32_t k = 0; k < 101; ++k) ak_particles_get_state(ps).lifetime[k] = INFINITY;
    ak_particle_attractor at = {.position = {1, 1, 1}, .strength = 2.0f, .softening = 0.1f};
    ak_particle_vortex vo = {
        .center = {0, 0, 0}, .axis = {0, 1, 0}, .strength = 1.0f, .softening = 0.2f};
    ak_particle_plane pl = {.normal = {0, 1, 0}, .restitution = 0.4f, .friction = 0.3f};
    ak_particle_sphere sp = {
        .center = {0.5f, 0.5f, 0}, .radius = 0.4f, .restitution = 0.7f, .friction = 0.1f};
    ak_particle_box bx = {
        .min = {-1, 0, -1}, .max = {-0.5f, 0.6f, -0.4f}, .restitution = 0.2f, .friction = 0.5f};
    ak_vec3 quad[4] = {{-3, 0.3f, -3}, {3, 0.2f, -3}, {3, 0.3f, 3}, {-3, 0.25f, 3}};
    uint32_t tri[6] = {0, 2, 1, 0, 3, 2};
    ak_particle_mesh* mesh = NULL;
    ak_particle_mesh_desc md = {
        .positions = AK_SPAN(quad), .indices = AK_SPAN(tri), .restitution = 0.3f};
    ak_particle_mesh_create(&md, NULL, &mesh);
    const ak_particle_mesh* meshes[1] = {mesh};
    ak_particles_world w = {.gravity = {0, -9.81f, 0},
                            .drag_linear = 0.1f,
                            .drag_quadratic = 0.05f,
                            .wind = {1, 0, 0},
                            .attractors = {&at, 1},
                            .vortices = {&vo, 1},
                            .springs = {springs, 100},
                            .lennard_jones = {.epsilon = 1e-4f, .sigma = 0.02f},
                            .planes = {&pl, 1},
                            .spheres = {&sp, 1},
                            .boxes = {&bx, 1},
                            .meshes = {meshes, 1}};
    ak_particle_emitter rate = e;
    rate.rate = 5000.0f;
    for (int s = 0; s < 6; ++s) {
        ak_particles_emit(ps, &rate, 0.02f, NULL);
        AK_CHECK_EQ(ak_particles_step(ps, &w, 0.02f), AK_OK);
    }
    ak_particle_mesh_destroy(mesh);
    return ps;
}

static bool same_state(ak_particles* a, ak_particles* b) {
    ak_particles_state x = ak_particles_get_state(a), y = ak_particles_get_state(b);
    if (x.count != y.count) return false;
    return memcmp(x.position, y.position, x.count * sizeof(ak_vec3)) == 0 &&
           memcmp(x.velocity, y.velocity, x.count * sizeof(ak_vec3)) == 0 &&
           memcmp(x.id, y.id, x.count * sizeof(uint32_t)) == 0 &&
           memcmp(x.lifetime, y.lifetime, x.count * sizeof(float)) == 0;
}

AK_TEST(determinism_and_threads) {
    for (int k = 0; k < 4; ++k) {
        ak_particles* a = busy_run(kIntegrators[k], 1, 42);
        ak_particles* b = busy_run(kIntegrators[k], 2, 42);
        ak_particles* c = busy_run(kIntegrators[k], 1, 42);
        ak_particles* d = busy_run(kIntegrators[k], 1, 43);
        ak_particles_state st = ak_particles_get_state(a);
        AK_CHECK(st.count > 16384); /* more than one thread's share */
        int finite = 1;
        for (size_t i = 0; i < st.count; ++i)
            finite &= ak_finitef(st.position[i].x) && ak_finitef(st.position[i].y) &&
                      ak_finitef(st.velocity[i].z);
        AK_CHECK(finite);
        AK_CHECK(same_state(a, c));  /* same seed: bit for bit */
        AK_CHECK(same_state(a, b));  /* 1 and 2 threads */
        AK_CHECK(!same_state(a, d)); /* another seed differs */
        ak_particles_destroy(a), ak_particles_destroy(b), ak_particles_destroy(c),
            ak_particles_destroy(d);
    }
}

/* The fused semi-implicit path (SIMD blocks of four where available, a scalar tail at each
 * thread's range end): different thread splits put different particles in the tails, so
 * equal results mean the block and scalar code agree bit for bit. */
static ak_particles* simple_run(uint32_t threads) {
    const size_t n = 30001;
    ak_particles* ps = make((uint32_t)n, AK_INTEGRATOR_SYMPLECTIC, threads, 9);
    ak_rng rng = ak_rng_make(21);
    for (size_t i = 0; i < n; ++i) {
        ak_particle_init in = {
            .position = {ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, 0, 0.3f), 0},
            .velocity = {ak_rng_range(&rng, -3, 3), ak_rng_range(&rng, -3, 1), 0},
            .mass = i % 17 ? ak_rng_range(&rng, 0.5f, 2) : 0.0f,
            .lifetime = i % 5 ? 0.0f : ak_rng_range(&rng, 0.01f, 0.2f)};
        ak_particles_add(ps, &in, NULL);
    }
    ak_particle_plane planes[2] = {{.normal = {0, 1, 0}, .restitution = 0.6f, .friction = 0.3f},
                                   {.normal = {-1, 0, 0}, .d = -0.9f, .restitution = 0.9f}};
    ak_particles_world w = {.gravity = {0, -9.81f, 0},
                            .drag_linear = 0.3f,
                            .drag_quadratic = 0.05f,
                            .wind = {0.5f, 0, 0},
                            .planes = {planes, 2}};
    for (int s = 0; s < 20; ++s) ak_particles_step(ps, &w, 0.01f);
    return ps;
}

AK_TEST(fused_path_any_split) {
    ak_particles* a = simple_run(1);
    ak_particles* b = simple_run(2);
    ak_particles* c = simple_run(3);
    size_t n = ak_particles_count(a);
    AK_CHECK(n < 30001 && n > 20000); /* some died */
    AK_CHECK(same_state(a, b));
    AK_CHECK(same_state(a, c));
    ak_particles_state st = ak_particles_get_state(a);
    int below = 0;
    for (size_t i = 0; i < st.count; ++i) {
        below += st.inv_mass[i] != 0.0f && (st.position[i].y < 0.0f || st.position[i].x > 0.9f);
    }
    AK_CHECK_EQ(below, 0);
    ak_particles_destroy(a), ak_particles_destroy(b), ak_particles_destroy(c);
}

AK_TEST(validation_codes) {
    ak_particles* ps = NULL;
    ak_particles_desc zero = {0};
    AK_CHECK_EQ(ak_particles_create(&zero, NULL, &ps), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_particles_create(NULL, NULL, &ps), AK_ERR_NULL_ARG);
    ak_particles_desc bad_int = {.capacity = 4, .integrator = AK_INTEGRATOR_COUNT};
    AK_CHECK_EQ(ak_particles_create(&bad_int, NULL, &ps), AK_ERR_BAD_ARG);
    ak_particles_desc bad_threads = {.capacity = 4, .thread_count = 65};
    AK_CHECK_EQ(ak_particles_create(&bad_threads, NULL, &ps), AK_ERR_BAD_ARG);
    ak_particles_desc res = ak_particles_desc_resolved(&zero);
    AK_CHECK_EQ(res.integrator, AK_INTEGRATOR_SYMPLECTIC);
    AK_CHECK_EQ(res.thread_count, 1);
    ps = make(2, AK_INTEGRATOR_DEFAULT, 0, 0);
    ak_particle_init nan_init = {.position = {NAN, 0, 0}};
    AK_CHECK_EQ(ak_particles_add(ps, &nan_init, NULL), AK_ERR_BAD_DATA);
    add(ps, ak_vec3_zero(), ak_vec3_zero(), 1.0f);
    add(ps, ak_vec3_zero(), ak_vec3_zero(), 1.0f);
    ak_particle_init ok = {.mass = 1};
    AK_CHECK_EQ(ak_particles_add(ps, &ok, NULL), AK_ERR_SPAN_SMALL);
    ak_particles_world w = {0};
    AK_CHECK_EQ(ak_particles_step(ps, NULL, 0.1f), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_particles_step(ps, &w, 0.0f), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_particles_step(ps, &w, NAN), AK_ERR_BAD_ARG);
    ak_particle_spring sp = {.i = 0, .j = 2};
    ak_particles_world ws = {.springs = {&sp, 1}};
    AK_CHECK_EQ(ak_particles_step(ps, &ws, 0.1f), AK_ERR_BAD_INDEX);
    ws.springs.ptr = NULL;
    AK_CHECK_EQ(ak_particles_step(ps, &ws, 0.1f), AK_ERR_NULL_ARG);
    ak_particle_plane pl = {.restitution = 1.5f};
    ak_particles_world wp = {.planes = {&pl, 1}};
    AK_CHECK_EQ(ak_particles_step(ps, &wp, 0.1f), AK_ERR_BAD_ARG);
    ak_particle_sphere sph = {.radius = -1.0f};
    ak_particles_world wsph = {.spheres = {&sph, 1}};
    AK_CHECK_EQ(ak_particles_step(ps, &wsph, 0.1f), AK_ERR_BAD_ARG);
    ak_particles_world wg = {.gravity = {0, INFINITY, 0}};
    AK_CHECK_EQ(ak_particles_step(ps, &wg, 0.1f), AK_ERR_BAD_DATA);
    ak_particles_world wlj = {.lennard_jones = {.epsilon = 1.0f}};
    AK_CHECK_EQ(ak_particles_step(ps, &wlj, 0.1f), AK_ERR_BAD_ARG);
    ak_particle_emitter e = {.rate = -1.0f};
    AK_CHECK_EQ(ak_particles_emit(ps, &e, 0.1f, NULL), AK_ERR_BAD_ARG);
    ak_particle_emitter cone = {.cone_angle = 4.0f};
    AK_CHECK_EQ(ak_particles_burst(ps, &cone, 1, NULL), AK_ERR_BAD_ARG);
    ak_particle_emitter mesh = {.shape = AK_EMITTER_MESH};
    AK_CHECK_EQ(ak_particles_burst(ps, &mesh, 1, NULL), AK_ERR_NULL_ARG);
    ak_vec3 v[3] = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
    uint32_t idx[3] = {0, 1, 3};
    float cdf[1];
    mesh.mesh_positions = (ak_vec3_cspan)AK_SPAN(v);
    mesh.mesh_indices = (ak_u32_cspan)AK_SPAN(idx);
    mesh.mesh_area_cdf = (ak_f32_span)AK_SPAN(cdf);
    AK_CHECK_EQ(ak_particles_burst(ps, &mesh, 1, NULL), AK_ERR_BAD_INDEX);
    idx[2] = 2; /* degenerate: zero area */
    ak_particles_clear(ps);
    AK_CHECK_EQ(ak_particles_burst(ps, &mesh, 1, NULL), AK_ERR_EMPTY);
    ak_particle_mesh* m = NULL;
    ak_particle_mesh_desc md = {.positions = AK_SPAN(v), .indices = {idx, 2}};
    AK_CHECK_EQ(ak_particle_mesh_create(&md, NULL, &m), AK_ERR_EMPTY);
    md.indices.count = 3;
    idx[2] = 7;
    AK_CHECK_EQ(ak_particle_mesh_create(&md, NULL, &m), AK_ERR_BAD_INDEX);
    ak_particles_destroy(ps);
    ak_particles_destroy(NULL);
    ak_particle_mesh_destroy(NULL);
}

/* The Lennard-Jones work budget: 600 particles in one cell are 179,700 distance tests per
 * evaluation; under a budget of 100,000 the step refuses and changes nothing (positions,
 * velocities, time), at 179,700 it runs; spread out (cells of the cut-off) they pass a budget
 * that the clump does not. */
AK_TEST(lennard_jones_work_budget) {
    ak_particles* ps = make(600, AK_INTEGRATOR_SYMPLECTIC, 1, 1);
    ak_rng rng = ak_rng_make(8);
    for (int i = 0; i < 600; ++i)
        add(ps, ak_vec3_make(ak_rng_range(&rng, 0, 1), ak_rng_range(&rng, 0, 1), ak_rng_range(&rng, 0, 1)),
            ak_vec3_zero(), 1.0f);
    ak_particles_state st = ak_particles_get_state(ps);
    static ak_vec3 before[600];
    memcpy(before, st.position, sizeof before);
    ak_particles_world w = {.gravity = {0, -9.81f, 0},
                            .lennard_jones = {.epsilon = 1e-6f, .sigma = 0.01f, .cutoff = 10.0f, .max_pair_tests = 100000}};
    AK_CHECK_EQ(ak_particles_step(ps, &w, 1e-3f), AK_ERR_BUDGET);
    st = ak_particles_get_state(ps);
    AK_CHECK(memcmp(before, st.position, sizeof before) == 0);
    AK_CHECK_EQ(ak_particles_time(ps), 0.0);
    w.lennard_jones.max_pair_tests = 600u * 599u / 2u; /* exactly the tests: allowed */
    AK_CHECK_EQ(ak_particles_step(ps, &w, 1e-3f), AK_OK);
    /* the same particles with a 0.05 m cut-off: cells of 0.05 m, far fewer tests */
    w.lennard_jones.cutoff = 0.05f;
    w.lennard_jones.max_pair_tests = 100000;
    AK_CHECK_EQ(ak_particles_step(ps, &w, 1e-3f), AK_OK);
    ak_particles_destroy(ps);
}

/* Colour and size over life at known ages, worked out by hand from the keys; frames. */
AK_TEST(look_over_life) {
    ak_particle_look look = {
        .colour_keys = {{0.0f, {1, 1, 0, 1}}, {0.25f, {1, 0.5f, 0, 0.8f}}, {1.0f, {0.2f, 0.2f, 0.2f, 0}}},
        .colour_key_count = 3,
        .size_keys = {{0.1f, 0.5f}, {0.5f, 2.0f}},
        .size_key_count = 2,
        .frame_count = 16,
    };
    AK_CHECK_EQ(ak_particle_look_validate(&look), AK_OK);
    const float life = 2.0f;
    /* age 0.25 s: t = 0.125, half way between keys 0 and 1 */
    ak_vec4 c = ak_particle_look_colour(&look, 0.25f, life);
    AK_CHECK_NEAR(c.x, 1.0f, 1e-6);
    AK_CHECK_NEAR(c.y, 0.75f, 1e-6);
    AK_CHECK_NEAR(c.w, 0.9f, 1e-6);
    /* age 1.25 s: t = 0.625 = 0.25 + 0.5 * 0.75 */
    c = ak_particle_look_colour(&look, 1.25f, life);
    AK_CHECK_NEAR(c.x, 0.6f, 1e-6);
    AK_CHECK_NEAR(c.y, 0.35f, 1e-6);
    AK_CHECK_NEAR(c.z, 0.1f, 1e-6);
    AK_CHECK_NEAR(c.w, 0.4f, 1e-6);
    /* past the end of life: held at the last key */
    c = ak_particle_look_colour(&look, 5.0f, life);
    AK_CHECK_NEAR(c.w, 0.0f, 1e-7);
    /* size: held before the first key (t = 0.05), linear after (t = 0.3 -> 0.5 + 1.5 * 0.5) */
    AK_CHECK_NEAR(ak_particle_look_size(&look, 0.1f, life), 0.5f, 1e-6);
    AK_CHECK_NEAR(ak_particle_look_size(&look, 0.6f, life), 1.25f, 1e-6);
    AK_CHECK_NEAR(ak_particle_look_size(&look, 1.9f, life), 2.0f, 1e-6);
    /* no keys, NULL, infinite lifetime (t = 0) */
    AK_CHECK_NEAR(ak_particle_look_size(NULL, 1.0f, life), 1.0f, 0);
    ak_particle_look plain = {0};
    AK_CHECK_NEAR(ak_particle_look_colour(&plain, 1.0f, life).y, 1.0f, 0);
    AK_CHECK_NEAR(ak_particle_look_colour(&look, 7.0f, INFINITY).y, 1.0f, 0);
    /* frames spread over the lifetime: t = 0.5 -> 8; the last instant stays on 15 */
    AK_CHECK_EQ(ak_particle_look_frame(&look, 1.0f, life), 8u);
    AK_CHECK_EQ(ak_particle_look_frame(&look, 0.0f, life), 0u);
    AK_CHECK_EQ(ak_particle_look_frame(&look, 1.99f, life), 15u);
    AK_CHECK_EQ(ak_particle_look_frame(&look, 2.0f, life), 15u);
    /* at a frame rate, looping: 24 fps, 1.0 s -> frame 24 mod 16 = 8; 0.49 s -> 11 */
    look.frame_rate = 24.0f;
    AK_CHECK_EQ(ak_particle_look_frame(&look, 1.0f, life), 8u);
    AK_CHECK_EQ(ak_particle_look_frame(&look, 0.49f, life), 11u);
    /* validation */
    ak_particle_look bad = look;
    bad.size_keys[1].t = 0.05f; /* not increasing */
    AK_CHECK_EQ(ak_particle_look_validate(&bad), AK_ERR_BAD_ARG);
    bad = look;
    bad.colour_key_count = AK_PARTICLE_LOOK_MAX_KEYS + 1;
    AK_CHECK_EQ(ak_particle_look_validate(&bad), AK_ERR_BAD_ARG);
    bad = look;
    bad.colour_keys[0].colour.x = NAN;
    AK_CHECK_EQ(ak_particle_look_validate(&bad), AK_ERR_BAD_ARG);
    bad = look;
    bad.frame_rate = -1.0f;
    AK_CHECK_EQ(ak_particle_look_validate(&bad), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_particle_look_validate(NULL), AK_ERR_NULL_ARG);
}

int main(void) {
    AK_RUN(projectile_closed_forms);
    AK_RUN(convergence_orders);
    AK_RUN(energy_symplectic_vs_euler);
    AK_RUN(drag_wind_attractor_vortex);
    AK_RUN(spring_damping_and_callback);
    AK_RUN(lennard_jones_matches_brute_force);
    AK_RUN(lennard_jones_work_budget);
    AK_RUN(floor_touch_time_and_no_tunnelling);
    AK_RUN(restitution_rebound_ratio);
    AK_RUN(friction_stopping_distance);
    AK_RUN(box_and_moving_mesh);
    AK_RUN(emission_counts);
    AK_RUN(emitter_shapes_and_ranges);
    AK_RUN(lifetime_expiry_keeps_order);
    AK_RUN_SLOW(determinism_and_threads);
    AK_RUN(fused_path_any_split);
    AK_RUN(validation_codes);
    AK_RUN(look_over_life);
    return ak_test_finish();
}
