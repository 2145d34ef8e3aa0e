// animkit crowd (ORCA) beside RVO2, the paper's reference library, in one process.
//
//   vs_rvo2 agree [S]    RVO2's Circle example (250 agents, 200 m circle, radius 1.5, dt 0.25,
//                        neighbour distance 15, 10 neighbours, horizons 10, max speed 2,
//                        preferred velocity: unit vector to the goal, the goal offset within
//                        1 m): both run S steps (default 500); prints the largest position difference and
//                        each library's smallest clearance (centre distance minus radii).
//   vs_rvo2 time [N...]  time per step (median of rounds, the two libraries alternating) on a
//                        jittered square block of N agents 4 m apart, each walking to the
//                        point mirrored through the block's centre, 1 and 2 threads (RVO2
//                        through OpenMP when built with it).
//   vs_rvo2 time1 [N...] the same on 1 thread only (for profiling).
//   vs_rvo2 work [N...]  CPU work on 2 threads: the CPU time of all the process's threads
//                        (CLOCK_PROCESS_CPUTIME_ID) per step of each library, rounds
//                        alternating, and their ratio; OpenMP's idle threads sleep
//                        (OMP_WAIT_POLICY=passive, set by re-running itself) so that no
//                        spinning of one library's threads is charged to the other's rounds.
//   vs_rvo2 vision [N...] animkit's vision-based steering (default view: 48 pixels over 150
//                        degrees) beside its ORCA on the same block, 1 thread, rounds
//                        alternating: agents per second of each (default N: 1000, 10000);
//                        then vision's two views alternating, the ray cast and the raster
//                        view (raster.h, 48 x 8 pixels, ak_crowd_desc.vision_view).
//
// RVO2 is linked from ../shared/peers/rvo2 (Apache-2.0), never copied into animkit.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <time.h>
#include <unistd.h>
#include <vector>

#if defined(_OPENMP)
#include <omp.h>
#endif

#include "RVO.h"

#include <animkit/crowd.h>

namespace {

struct Scenario {
    std::vector<ak_vec2> start, goal;
    float radius, max_speed, neighbor_dist, horizon, dt;
    unsigned max_neighbors;
};

Scenario circle250() {
    Scenario s;
    s.radius = 1.5f;
    s.max_speed = 2.0f;
    s.neighbor_dist = 15.0f;
    s.horizon = 10.0f;
    s.dt = 0.25f;
    s.max_neighbors = 10;
    for (int i = 0; i < 250; ++i) {
        const float a = static_cast<float>(i) * 6.28318530717958647692F * 0.004F;
        const RVO::Vector2 p = 200.0f * RVO::Vector2(std::cos(a), std::sin(a));
        s.start.push_back({p.x(), p.y()});
        s.goal.push_back({-p.x(), -p.y()});
    }
    return s;
}

Scenario block(size_t n) {
    Scenario s = circle250();
    s.start.clear();
    s.goal.clear();
    const size_t side = static_cast<size_t>(std::ceil(std::sqrt(static_cast<double>(n))));
    uint64_t seed = 42;
    auto rnd = [&seed]() {
        seed = seed * 6364136223846793005ull + 1442695040888963407ull;
        return static_cast<float>((seed >> 40) & 0xffffff) / 16777216.0f;
    };
    const float spacing = 4.0f, c = 0.5f * spacing * static_cast<float>(side - 1);
    for (size_t i = 0; i < n; ++i) {
        const float x = spacing * static_cast<float>(i % side) + (rnd() - 0.5f) - c;
        const float z = spacing * static_cast<float>(i / side) + (rnd() - 0.5f) - c;
        s.start.push_back({x, z});
        s.goal.push_back({-x, -z});
    }
    return s;
}

struct Rvo {
    RVO::RVOSimulator sim;
    std::vector<RVO::Vector2> goals;
    explicit Rvo(const Scenario& s) {
        sim.setTimeStep(s.dt);
        sim.setAgentDefaults(s.neighbor_dist, s.max_neighbors, s.horizon, s.horizon, s.radius, s.max_speed);
        for (size_t i = 0; i < s.start.size(); ++i) {
            sim.addAgent(RVO::Vector2(s.start[i].x, s.start[i].y));
            goals.emplace_back(s.goal[i].x, s.goal[i].y);
        }
    }
    // As RVO2's Circle example does it.
    void step() {
        for (size_t i = 0; i < sim.getNumAgents(); ++i) {
            RVO::Vector2 g = goals[i] - sim.getAgentPosition(i);
            if (RVO::absSq(g) > 1.0f) g = RVO::normalize(g);
            sim.setAgentPrefVelocity(i, g);
        }
        sim.doStep();
    }
};

struct Ak {
    ak_crowd* crowd = nullptr;
    size_t n;
    std::vector<ak_vec2> p, v, p2, v2;
    std::vector<uint32_t> wp;
    std::vector<uint8_t> scratch;
    ak_crowd_step_job job;
    Ak(const Scenario& s, uint32_t threads, ak_crowd_method method = AK_CROWD_ORCA,
       ak_crowd_view view = AK_CROWD_VIEW_RAYCAST)
        : n(s.start.size()) {
        std::vector<ak_crowd_agent> ag(n);
        for (size_t i = 0; i < n; ++i) {
            ag[i] = ak_crowd_agent{};
            ag[i].radius = s.radius;
            ag[i].pref_speed = 1.0f;
            ag[i].max_speed = s.max_speed;
            ag[i].neighbor_distance = s.neighbor_dist;
            ag[i].max_neighbors = s.max_neighbors;
            ag[i].time_horizon = s.horizon;
            ag[i].time_horizon_obstacles = s.horizon;
            ag[i].goals = ak_vec2_cspan{&s.goal[i], 1};
        }
        ak_crowd_desc d{};
        d.agents.ptr = ag.data();
        d.agents.count = n;
        d.method = method;
        d.vision_view = view;
        if (ak_crowd_create(&d, nullptr, &crowd) != AK_OK) std::abort();
        p = s.start;
        v.assign(n, ak_vec2{0, 0});
        p2 = v;
        v2 = v;
        wp.assign(n, 0);
        job = ak_crowd_step_job{};
        job.crowd = crowd;
        job.dt = s.dt;
        job.thread_count = threads;
        job.skip_perturbation = true;  // RVO2's preferred velocities, bit for bit
        job.allow_overlap = true;      // pure ORCA: RVO2 has no contact projection
        bind();
        scratch.resize(ak_crowd_step_scratch_size(&job));
        job.scratch = ak_u8_span{scratch.data(), scratch.size()};
    }
    ~Ak() { ak_crowd_destroy(crowd); }
    void bind() {
        job.positions = ak_vec2_cspan{p.data(), n};
        job.velocities = ak_vec2_cspan{v.data(), n};
        job.waypoints = ak_u32_span{wp.data(), n};
        job.out_positions = ak_vec2_span{p2.data(), n};
        job.out_velocities = ak_vec2_span{v2.data(), n};
    }
    void step() {
        if (ak_crowd_step_run(&job) != AK_OK) std::abort();
        p.swap(p2);
        v.swap(v2);
        bind();
    }
};

double min_clearance(const std::vector<ak_vec2>& p, float r) {
    double best = INFINITY;
    for (size_t i = 0; i < p.size(); ++i)
        for (size_t j = i + 1; j < p.size(); ++j)
            best = std::min(best, std::hypot(static_cast<double>(p[i].x) - p[j].x, static_cast<double>(p[i].y) - p[j].y) - 2.0 * r);
    return best;
}

int agree(int steps) {
    const Scenario s = circle250();
    Rvo rvo(s);
    Ak ak(s, 1);
    double worst = 0.0, clear_rvo = INFINITY, clear_ak = INFINITY;
    int worst_step = -1;
    std::vector<ak_vec2> pr(s.start.size());
    for (int step = 0; step < steps; ++step) {
        rvo.step();
        ak.step();
        for (size_t i = 0; i < pr.size(); ++i) {
            pr[i] = {rvo.sim.getAgentPosition(i).x(), rvo.sim.getAgentPosition(i).y()};
            const double d = std::hypot(static_cast<double>(pr[i].x) - ak.p[i].x, static_cast<double>(pr[i].y) - ak.p[i].y);
            if (d > worst) {
                worst = d;
                worst_step = step;
            }
        }
        clear_rvo = std::min(clear_rvo, min_clearance(pr, s.radius));
        clear_ak = std::min(clear_ak, min_clearance(ak.p, s.radius));
    }
    std::printf("circle 250 agents, %d steps: max |p_animkit - p_rvo2| = %.3g m (step %d)\n", steps, worst, worst_step);
    std::printf("smallest clearance: animkit %.4f m, RVO2 %.4f m\n", clear_ak, clear_rvo);
    const bool ok = worst <= 1e-3;
    std::printf("%s: trajectories agree within 1e-3 m\n", ok ? "PASS" : "FAIL");
    return ok ? 0 : 1;
}

double now() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// This thread's CPU time (s): on a loaded machine it leaves out the time the thread waited
// for a core, which wall time counts (one-thread rows only).
double cpu_now() {
#if defined(CLOCK_THREAD_CPUTIME_ID)
    timespec ts;
    if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts) == 0) return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
#endif
    return now();
}

// Per-step times of a and b over rounds of `per` steps each, the two alternating (one warm-up
// step each first): wall time and the given CPU clock, each list sorted (medians, ranges).
struct Alternated {
    std::vector<double> wall_a, wall_b, cpu_a, cpu_b;
};
template <class A, class B>
Alternated alternate(A& a, B& b, int rounds, int per, double (*cpu)()) {
    Alternated r;
    a.step();
    b.step();
    for (int k = 0; k < rounds; ++k) {
        const double c0 = cpu(), t0 = now();
        for (int i = 0; i < per; ++i) a.step();
        const double c1 = cpu(), t1 = now();
        for (int i = 0; i < per; ++i) b.step();
        const double c2 = cpu(), t2 = now();
        r.wall_a.push_back((t1 - t0) / per);
        r.wall_b.push_back((t2 - t1) / per);
        r.cpu_a.push_back((c1 - c0) / per);
        r.cpu_b.push_back((c2 - c1) / per);
    }
    for (auto* v : {&r.wall_a, &r.wall_b, &r.cpu_a, &r.cpu_b}) std::sort(v->begin(), v->end());
    return r;
}

void time_one(size_t n, int threads) {
    const Scenario s = block(n);
#if defined(_OPENMP)
    omp_set_num_threads(threads);
#else
    if (threads > 1) {
        std::printf("%8zu agents %d threads: RVO2 built without OpenMP, skipped\n", n, threads);
        return;
    }
#endif
    Rvo rvo(s);
    Ak ak(s, static_cast<uint32_t>(threads));
    const int rounds = n >= 100000 ? 5 : n >= 10000 ? 9 : 15;
    const int per = n >= 100000 ? 2 : n >= 10000 ? 4 : 20;
    const Alternated t = alternate(rvo, ak, rounds, per, cpu_now);
    const std::vector<double>&tr = t.wall_a, &ta = t.wall_b, &cr = t.cpu_a, &ca = t.cpu_b;
    const double mr = tr[tr.size() / 2], ma = ta[ta.size() / 2];
    std::printf("%8zu agents %d thread%s: RVO2 %9.3f ms/step  animkit %9.3f ms/step  (%.2f M agent-steps/s)  "
                "animkit/RVO2 speed %.2fx  [ranges %.3f-%.3f, %.3f-%.3f]",
                n, threads, threads > 1 ? "s" : " ", 1e3 * mr, 1e3 * ma, 1e-6 * static_cast<double>(n) / ma, mr / ma,
                1e3 * tr.front(), 1e3 * tr.back(), 1e3 * ta.front(), 1e3 * ta.back());
    if (threads == 1)
        std::printf("  thread CPU time: RVO2 %.3f, animkit %.3f ms/step, speed %.2fx", 1e3 * cr[cr.size() / 2],
                    1e3 * ca[ca.size() / 2], cr[cr.size() / 2] / ca[ca.size() / 2]);
    std::printf("\n");
    std::fflush(stdout);
}

// CPU time of every thread of the process (s).
double process_cpu_now() {
#if defined(CLOCK_PROCESS_CPUTIME_ID)
    timespec ts;
    if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts) == 0) return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
#endif
    return now();
}

// 2 threads, CPU time of all threads per step (the work a step costs, whatever the cores'
// load): medians over rounds, the libraries alternating.
void time_work(size_t n) {
    const int threads = 2;
    const Scenario s = block(n);
#if defined(_OPENMP)
    omp_set_num_threads(threads);
#else
    std::printf("%8zu agents %d threads: RVO2 built without OpenMP, skipped\n", n, threads);
    return;
#endif
    Rvo rvo(s);
    Ak ak(s, static_cast<uint32_t>(threads));
    const int rounds = n >= 100000 ? 5 : n >= 10000 ? 9 : 15;
    const int per = n >= 100000 ? 2 : n >= 10000 ? 4 : 20;
    const Alternated t = alternate(rvo, ak, rounds, per, process_cpu_now);
    const std::vector<double>&tr = t.wall_a, &ta = t.wall_b, &cr = t.cpu_a, &ca = t.cpu_b;
    const double mr = cr[cr.size() / 2], ma = ca[ca.size() / 2];
    std::printf("%8zu agents %d threads: CPU time of all threads: RVO2 %9.3f ms/step  animkit %9.3f ms/step  "
                "animkit/RVO2 work speed %.2fx  [ranges %.3f-%.3f, %.3f-%.3f]  (wall: RVO2 %.3f, animkit %.3f ms/step)\n",
                n, threads, 1e3 * mr, 1e3 * ma, mr / ma, 1e3 * cr.front(), 1e3 * cr.back(), 1e3 * ca.front(),
                1e3 * ca.back(), 1e3 * tr[tr.size() / 2], 1e3 * ta[ta.size() / 2]);
    std::fflush(stdout);
}

void time_vision(size_t n) {
    const Scenario s = block(n);
    Ak orca(s, 1), vision(s, 1, AK_CROWD_VISION);
    const int rounds = n >= 10000 ? 7 : 11, per = n >= 10000 ? 3 : 10;
    const Alternated t = alternate(orca, vision, rounds, per, cpu_now);
    const std::vector<double>&to = t.wall_a, &tv = t.wall_b;
    const double mo = to[to.size() / 2], mv = tv[tv.size() / 2];
    std::printf("%8zu agents 1 thread : ORCA %8.3f ms/step (%.2f M agents/s)  vision (48 px, 150 deg) %8.3f ms/step "
                "(%.3f M agents/s)  vision/ORCA time %.2fx  [ranges %.3f-%.3f, %.3f-%.3f]\n",
                n, 1e3 * mo, 1e-6 * static_cast<double>(n) / mo, 1e3 * mv, 1e-6 * static_cast<double>(n) / mv, mv / mo,
                1e3 * to.front(), 1e3 * to.back(), 1e3 * tv.front(), 1e3 * tv.back());
    std::fflush(stdout);
    // the two views of vision, alternating: the ray cast and the rasterizer's 48 x 8 image
    Ak ray(s, 1, AK_CROWD_VISION), ras(s, 1, AK_CROWD_VISION, AK_CROWD_VIEW_RASTER);
    const Alternated u = alternate(ray, ras, rounds, per, cpu_now);
    const std::vector<double>&ur = u.cpu_a, &us = u.cpu_b;  // this thread's CPU time
    const double mr = ur[ur.size() / 2], ms = us[us.size() / 2];
    std::printf("%8zu agents 1 thread : CPU time: vision raycast view (48 px) %8.3f ms/step (%.3f M agents/s)  raster view "
                "(48 x 8 px) %8.3f ms/step (%.4f M agents/s)  raster/raycast time %.2fx  [ranges %.3f-%.3f, "
                "%.3f-%.3f]\n",
                n, 1e3 * mr, 1e-6 * static_cast<double>(n) / mr, 1e3 * ms, 1e-6 * static_cast<double>(n) / ms, ms / mr,
                1e3 * ur.front(), 1e3 * ur.back(), 1e3 * us.front(), 1e3 * us.back());
    std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
    if (argc >= 2 && std::strcmp(argv[1], "agree") == 0) return agree(argc >= 3 ? std::atoi(argv[2]) : 500);
    if (argc >= 2 && (std::strcmp(argv[1], "time") == 0 || std::strcmp(argv[1], "time1") == 0)) {
        const int max_threads = std::strcmp(argv[1], "time1") == 0 ? 1 : 2;
        std::vector<size_t> sizes;
        for (int i = 2; i < argc; ++i) sizes.push_back(static_cast<size_t>(std::atol(argv[i])));
        if (sizes.empty()) sizes = {1000, 10000, 100000};
        for (size_t n : sizes)
            for (int t = 1; t <= max_threads; ++t) time_one(n, t);
        return 0;
    }
    if (argc >= 2 && std::strcmp(argv[1], "work") == 0) {
#if defined(_OPENMP)
        // libgomp reads the policy when it loads: run again with it set
        if (!std::getenv("OMP_WAIT_POLICY")) {
            setenv("OMP_WAIT_POLICY", "passive", 1);
            execv("/proc/self/exe", argv);
            std::fprintf(stderr, "vs_rvo2: could not re-run with OMP_WAIT_POLICY=passive; set it and run again\n");
            return 1;
        }
#endif
        std::vector<size_t> sizes;
        for (int i = 2; i < argc; ++i) sizes.push_back(static_cast<size_t>(std::atol(argv[i])));
        if (sizes.empty()) sizes = {1000, 10000, 100000};
        for (size_t n : sizes) time_work(n);
        return 0;
    }
    if (argc >= 2 && std::strcmp(argv[1], "vision") == 0) {
        std::vector<size_t> sizes;
        for (int i = 2; i < argc; ++i) sizes.push_back(static_cast<size_t>(std::atol(argv[i])));
        if (sizes.empty()) sizes = {1000, 10000};
        for (size_t n : sizes) time_vision(n);
        return 0;
    }
    std::fprintf(stderr, "usage: vs_rvo2 agree [STEPS] | time [N...] | time1 [N...] | work [N...] | vision [N...]\n");
    return 2;
}
