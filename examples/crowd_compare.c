/* crowd: ORCA and vision-based steering on the same preset, side by side; prints per method
 * how many agents are at their goals at the end and how many got there at some time, the step
 * when all were home at once, the mean time to goal and path length over the straight line
 * (of those that got there), the mean speed on the way, the smallest clearance over every step
 * (centre distance minus radii), pairs that ever overlapped by more than 1 mm, the lanes of
 * the corridor (each group's mean z where |x| < 10 m over the first 200 steps, and a lane
 * index over the whole run: 1 - (share of the other group among the agents within 3 m along x
 * and 0.3 m across, of an agent where |x| < 10 m) / (that share within 3 m along x at any z):
 * 0 when the groups are mixed across the width, 1 when they walk in separate lanes, whatever
 * their number and place), the lane order Phi of the two flows (each walking agent that meets
 * the other flow within 3 m ahead: (own - other) / (own + other) among the walking agents
 * within 3 m ahead and 0.5 m across; Phi is its mean over agents and steps, 1 in lanes; Phi_mix
 * the same over the whole width ahead, which mixed flows match: docs/crowd.md, "Lanes"; with
 * ANIMKIT_PHI_EVERY=K in the environment also per K steps) and the step time. docs/crowd.md's
 * ORCA/vision table comes from it:
 *     example_crowd_compare [PRESET|SCENE.json [AGENTS [raycast|raster]]]   (default: crossing 24)
 * A scene file (AGENTS ignored; its "vision_view" unless the third argument says) gets the
 * corridor's lane measures (its groups 0 and 1). The third argument is the vision run's view.
 * Shows: ak_crowd_scene_preset, ak_crowd_scene_load_file, ak_crowd_desc.method and
 * vision_view, ak_crowd_clearance. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <animkit/crowd.h>

static double seconds(void) {
    return (double)clock() / CLOCKS_PER_SEC;
}

/* Lane order (see the top): adds each meeting agent's order to sum[0] (band across) and to
 * sum[1] (any z), and counts them in *count. Group 0 walks +x, group 1 -x. */
static void lane_order(size_t n, const ak_vec2* p, const uint8_t* group, const bool* walking, double sum[2],
                       size_t* count) {
    for (size_t i = 0; i < n; ++i) {
        if (!walking[i] || group[i] > 1) continue;
        const double dir = group[i] == 0 ? 1.0 : -1.0;
        int s[2] = {0, 0}, o[2] = {0, 0};
        for (size_t j = 0; j < n; ++j) {
            if (j == i || !walking[j] || group[j] > 1) continue;
            const double ahead = ((double)p[j].x - p[i].x) * dir;
            if (!(ahead > 0.0 && ahead <= 3.0)) continue;
            const bool same = group[j] == group[i];
            s[1] += same, o[1] += !same;
            if (fabs((double)p[j].y - p[i].y) <= 0.5) s[0] += same, o[0] += !same;
        }
        if (o[1] == 0 || s[0] + o[0] == 0) continue; /* o[1] > 0 implies s[1] + o[1] > 0 */
        sum[0] += (double)(s[0] - o[0]) / (double)(s[0] + o[0]);
        sum[1] += (double)(s[1] - o[1]) / (double)(s[1] + o[1]);
        ++*count;
    }
}

static int run(const char* preset, size_t agents, ak_crowd_method method, const char* view) {
    ak_crowd_scene sc;
    ak_diag diag;
    const size_t plen = strlen(preset);
    const bool file = plen > 5 && strcmp(preset + plen - 5, ".json") == 0;
    if (file) ak_crowd_scene_defaults(&sc); /* a file is read over the defaults */
    if ((file ? ak_crowd_scene_load_file(preset, &sc, &diag) : ak_crowd_scene_preset(preset, agents, &sc, &diag)) !=
        AK_OK) {
        fprintf(stderr, "%s\n", diag.message);
        return 1;
    }
    if (view) sc.vision_view = strcmp(view, "raster") == 0 ? AK_CROWD_VIEW_RASTER : AK_CROWD_VIEW_RAYCAST;
    const bool lanes = file || strcmp(preset, "corridor") == 0;
    const size_t n = sc.agent_count;
    ak_crowd_desc d = {.agents = {sc.agents, n}, .obstacles = sc.obstacles,
                       .obstacle_count = (uint32_t)sc.obstacle_count, .method = method,
                       .vision_view = sc.vision_view};
    ak_crowd* c = NULL;
    if (ak_crowd_create(&d, NULL, &c) != AK_OK) return 1;
    ak_vec2 *p = malloc(n * sizeof *p), *v = calloc(n, sizeof *v), *p2 = malloc(n * sizeof *p2),
            *v2 = malloc(n * sizeof *v2);
    uint32_t* wp = calloc(n, sizeof *wp);
    double *walked = calloc(n, sizeof *walked), *straight = calloc(n, sizeof *straight);
    long* t_home = malloc(n * sizeof *t_home);
    const size_t pair_cap = 1u << 16;
    uint32_t* pairs = malloc(2 * pair_cap * sizeof *pairs);
    if (!p || !v || !p2 || !v2 || !wp || !walked || !straight || !t_home || !pairs) return 1;
    memcpy(p, sc.positions, n * sizeof *p);
    for (size_t i = 0; i < n; ++i) {
        const ak_vec2 g = sc.agents[i].goals.ptr[sc.agents[i].goals.count - 1];
        straight[i] = hypot(g.x - p[i].x, g.y - p[i].y);
        t_home[i] = -1;
    }
    ak_crowd_step_job job = {.crowd = c, .dt = sc.dt, .contact_iterations = sc.contact_iterations,
                             .waypoints = {wp, n}};
    job.positions = (ak_vec2_cspan){p, n};
    job.velocities = (ak_vec2_cspan){v, n};
    job.out_positions = (ak_vec2_span){p2, n};
    job.out_velocities = (ak_vec2_span){v2, n};
    const size_t bytes = ak_crowd_step_scratch_size(&job), cbytes = ak_crowd_clearance_scratch_size(c, n);
    void *scratch = malloc(bytes), *cscratch = malloc(cbytes);
    if (!scratch || !cscratch) return 1;
    job.scratch = (ak_u8_span){scratch, bytes};
    /* pairs that ever overlapped: a sorted list of (i << 32 | j) */
    size_t ov_count = 0, ov_cap = 1024;
    uint64_t* ov = malloc(ov_cap * sizeof *ov);
    double min_clear = INFINITY, step_time = 0.0, speed_sum = 0.0, z[2] = {0, 0};
    double win[2] = {0, 0}, strip[2] = {0, 0}; /* neighbours within 3 m along x / and 0.3 m in z: all, of the other group */
    size_t speed_n = 0, zn[2] = {0, 0};
    double phi[2] = {0, 0}, wphi[2] = {0, 0}; /* lane order: over the run, over the window */
    size_t phi_n = 0, wphi_n = 0;
    const long every = getenv("ANIMKIT_PHI_EVERY") ? strtol(getenv("ANIMKIT_PHI_EVERY"), NULL, 10) : 0;
    bool* walking = malloc(n * sizeof *walking);
    if (!walking) return 1;
    long s = 0, all_home = -1;
    for (; s < sc.steps; ++s) {
        job.positions = (ak_vec2_cspan){p, n};
        job.velocities = (ak_vec2_cspan){v, n};
        job.out_positions = (ak_vec2_span){p2, n};
        job.out_velocities = (ak_vec2_span){v2, n};
        job.step_index = (uint64_t)s;
        const double t0 = seconds();
        if (ak_crowd_step_run(&job) != AK_OK) return 1;
        step_time += seconds() - t0;
        for (size_t i = 0; i < n; ++i)
            if (t_home[i] < 0) {
                walked[i] += hypot(p2[i].x - p[i].x, p2[i].y - p[i].y);
                speed_sum += hypot(v2[i].x, v2[i].y);
                ++speed_n;
            }
        ak_vec2* t = p;
        p = p2, p2 = t;
        t = v, v = v2, v2 = t;
        float md = 0.0f;
        size_t over = 0;
        if (ak_crowd_clearance(c, (ak_vec2_cspan){p, n}, 1e-3f, (ak_u8_span){cscratch, cbytes}, &md,
                               (ak_u32_span){pairs, 2 * pair_cap}, &over) != AK_OK)
            return 1;
        min_clear = fmin(min_clear, md);
        for (size_t k = 0; k < over && k < pair_cap; ++k) {
            const uint64_t key = (uint64_t)pairs[2 * k] << 32 | pairs[2 * k + 1];
            size_t a = 0;
            while (a < ov_count && ov[a] != key) ++a;
            if (a < ov_count) continue;
            if (ov_count == ov_cap) {
                uint64_t* o2 = realloc(ov, (ov_cap *= 2) * sizeof *ov);
                if (!o2) return 1;
                ov = o2;
            }
            ov[ov_count++] = key;
        }
        size_t home = 0;
        for (size_t i = 0; i < n; ++i) {
            const bool h = ak_crowd_goal_reached(c, i, p[i], wp[i]);
            if (h && t_home[i] < 0) t_home[i] = s + 1;
            home += h;
        }
        if (lanes && s < 200)
            for (size_t i = 0; i < n; ++i)
                if (fabsf(p[i].x) < 10.0f && sc.group[i] < 2) z[sc.group[i]] += p[i].y, zn[sc.group[i]]++;
        if (lanes)
            for (size_t i = 0; i < n; ++i) {
                if (!(fabsf(p[i].x) < 10.0f)) continue;
                for (size_t j = 0; j < n; ++j) {
                    if (j == i || !(fabsf(p[j].x - p[i].x) < 3.0f)) continue;
                    const bool opp = sc.group[j] != sc.group[i];
                    win[0] += 1.0, win[1] += opp;
                    if (fabsf(p[j].y - p[i].y) < 0.3f) strip[0] += 1.0, strip[1] += opp;
                }
            }
        if (lanes) {
            for (size_t i = 0; i < n; ++i) walking[i] = !ak_crowd_goal_reached(c, i, p[i], wp[i]);
            const size_t before = wphi_n;
            const double b0 = wphi[0], b1 = wphi[1];
            lane_order(n, p, sc.group, walking, wphi, &wphi_n);
            phi[0] += wphi[0] - b0, phi[1] += wphi[1] - b1, phi_n += wphi_n - before;
            if (every > 0 && (s + 1) % every == 0) {
                if (wphi_n) printf("  steps %ld-%ld: Phi %.2f, Phi_mix %.2f over %zu agent-steps, %zu home\n", s + 2 - every,
                                   s + 1, wphi[0] / (double)wphi_n, wphi[1] / (double)wphi_n, wphi_n, home);
                wphi[0] = wphi[1] = 0.0, wphi_n = 0;
            }
        }
        if (home == n) {
            all_home = s + 1;
            ++s;
            break;
        }
    }
    size_t at_goal = 0, reached = 0;
    double tt = 0.0, ratio = 0.0;
    for (size_t i = 0; i < n; ++i) {
        at_goal += ak_crowd_goal_reached(c, i, p[i], wp[i]);
        if (t_home[i] < 0) continue;
        ++reached;
        tt += (double)t_home[i] * sc.dt;
        ratio += straight[i] > 0.0 ? walked[i] / straight[i] : 1.0;
    }
    printf("%-10s %-6s%s %zu agents: at goal at the end %zu, got there %zu; all home at step %ld of %ld; "
           "time to goal %.1f s, path / straight %.3f, speed on the way %.2f m/s; min clearance %.5f m, "
           "%zu pairs overlapped > 1 mm; %.2f ms per step (%.0f agent-steps/s)",
           preset, method == AK_CROWD_VISION ? "vision" : "orca",
           method == AK_CROWD_VISION && sc.vision_view == AK_CROWD_VIEW_RASTER ? " (raster view)" : "", n, at_goal, reached, all_home, sc.steps,
           reached ? tt / (double)reached : 0.0, reached ? ratio / (double)reached : 0.0,
           speed_n ? speed_sum / (double)speed_n : 0.0, min_clear, ov_count, 1e3 * step_time / (double)s,
           step_time > 0.0 ? (double)n * (double)s / step_time : 0.0);
    if (zn[0] && zn[1]) printf("; lanes: mean z %.2f m / %.2f m", z[0] / (double)zn[0], z[1] / (double)zn[1]);
    if (win[1] > 0.0 && strip[0] > 0.0)
        printf(", lane index %.2f", 1.0 - (strip[1] / strip[0]) / (win[1] / win[0]));
    if (phi_n) printf(", lane order Phi %.2f (Phi_mix %.2f, %zu agent-steps)", phi[0] / (double)phi_n, phi[1] / (double)phi_n, phi_n);
    printf("\n");
    free(walking);
    free(ov);
    free(pairs);
    free(scratch);
    free(cscratch);
    free(p), free(v), free(p2), free(v2), free(wp), free(walked), free(straight), free(t_home);
    ak_crowd_destroy(c);
    ak_crowd_scene_free(&sc);
    return 0;
}

int main(int argc, char** argv) {
    const char* preset = argc > 1 ? argv[1] : "crossing";
    const size_t agents = argc > 2 ? (size_t)strtoul(argv[2], NULL, 10) : 24;
    const char* view = argc > 3 ? argv[3] : NULL;
    if (view && strcmp(view, "raycast") != 0 && strcmp(view, "raster") != 0) {
        fprintf(stderr, "view '%s': raycast or raster\n", view);
        return 1;
    }
    if (run(preset, agents, AK_CROWD_ORCA, NULL) != 0) return 1;
    return run(preset, agents, AK_CROWD_VISION, view);
}
