/* animkit view crowd: a crowd (include/animkit/crowd.h) walking live, as `animkit crowd` draws
 * it: a walking character per agent, each posed on its own up to CROWD_CHARACTERS_MAX agents,
 * sharing skinned poses above (no foot planting, no shadows). `crowd` runs the circle
 * preset, `crowd:preset:NAME` another preset, `crowd:SCENE.json` a scene file (the command
 * line's `view crowd --preset NAME` and `view crowd SCENE.json` say the same). A left click on
 * the ground sends the group of the agent nearest to the click there, each agent keeping its
 * offset from the group's centre (G: the whole crowd instead); dragging moves that goal. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "crowd_draw.h"
#include "view_app.h"

#define MAX_STEPS_PER_FRAME 16
#define MARKER_VERTS 24 /* the goal marker: a flat ring of 8 quads */

typedef struct xsim {
    ak_crowd_scene sc;
    char name[300];
    ak_crowd_agent* agents; /* sc.agents with the goals the clicks set */
    ak_vec2* goal;          /* [n] a clicked goal per agent (agents[i].goals points here) */
    ak_crowd* crowd;
    size_t n;
    ak_vec2 *p, *v, *p2, *v2;
    uint32_t* wp;
    uint8_t* scratch;
    size_t scratch_size;
    uint32_t threads;
    crowd_chars chars;
    bool shared; /* more than CROWD_CHARACTERS_MAX agents: shared poses, drawn by xsim_draw */
    crowd_people people;
    ak_vec3* wall;
    size_t wall_count;
    ak_vec3 marker[MARKER_VERTS];
    bool has_marker, whole_crowd;
    int group; /* the group the last click sent, -1 -> all */
    ak_vec2 click;
    long step_index;
    double carry;
    bool failed;
    ak_vec3 lo, hi;
} xsim;

static void xsim_destroy(void* state) {
    xsim* x = state;
    if (!x) return;
    ak_crowd_destroy(x->crowd);
    free(x->agents);
    free(x->goal);
    free(x->p);
    free(x->v);
    free(x->p2);
    free(x->v2);
    free(x->wp);
    free(x->scratch);
    crowd_chars_free(&x->chars);
    crowd_people_free(&x->people);
    free(x->wall);
    ak_crowd_scene_free(&x->sc);
    free(x);
}

/* (Re)build the crowd from x->agents; scratch grows when it must. */
static ak_result rebuild(xsim* x) {
    ak_crowd_destroy(x->crowd);
    x->crowd = NULL;
    ak_crowd_desc d = {.agents = {x->agents, x->n}, .obstacles = x->sc.obstacles,
                       .obstacle_count = (uint32_t)x->sc.obstacle_count, .method = x->sc.method};
    ak_result r = ak_crowd_create(&d, NULL, &x->crowd);
    if (r != AK_OK) return r;
    ak_crowd_step_job job = {.crowd = x->crowd, .dt = x->sc.dt, .thread_count = x->threads,
                             .contact_iterations = x->sc.contact_iterations};
    const size_t bytes = ak_crowd_step_scratch_size(&job);
    if (bytes > x->scratch_size) {
        free(x->scratch);
        x->scratch = malloc(bytes);
        x->scratch_size = x->scratch ? bytes : 0;
        if (!x->scratch) return AK_ERR_NO_MEMORY;
    }
    return AK_OK;
}

static int xsim_restart(xsim* x) {
    memcpy(x->agents, x->sc.agents, x->n * sizeof *x->agents);
    memcpy(x->p, x->sc.positions, x->n * sizeof *x->p);
    memcpy(x->v, x->sc.velocities, x->n * sizeof *x->v);
    memset(x->wp, 0, x->n * sizeof *x->wp);
    x->step_index = 0;
    x->carry = 0.0;
    x->failed = false;
    x->has_marker = false;
    crowd_chars_reset(&x->chars, &x->sc);
    return rebuild(x) == AK_OK ? CLI_OK : CLI_BAD_INPUT;
}

static int xsim_init(void** state, const char* spec, const view_sim_opts* o, char* err, size_t err_size) {
    xsim* x = calloc(1, sizeof *x);
    if (!x) {
        snprintf(err, err_size, "out of memory");
        return CLI_BAD_INPUT;
    }
    x->threads = o->threads > 0 ? (uint32_t)o->threads : 1;
    x->group = -1;
    ak_diag diag;
    if (!spec[0] || strncmp(spec, "preset:", 7) == 0) {
        const char* name = spec[0] ? spec + 7 : "circle";
        const ak_result r = ak_crowd_scene_preset(name, 0, &x->sc, &diag);
        if (r == AK_ERR_NOT_FOUND) {
            snprintf(err, err_size, "crowd:%s: the presets are " AK_CROWD_SCENE_PRESETS, spec);
            xsim_destroy(x);
            return CLI_BAD_USAGE;
        }
        if (r != AK_OK) {
            snprintf(err, err_size, "%s", diag.message);
            xsim_destroy(x);
            return CLI_BAD_INPUT;
        }
        snprintf(x->name, sizeof x->name, "crowd preset %s", name);
    } else {
        ak_crowd_scene_defaults(&x->sc);
        if (ak_crowd_scene_load_file(spec, &x->sc, &diag) != AK_OK) {
            snprintf(err, err_size, "%s", diag.message);
            xsim_destroy(x);
            return CLI_BAD_INPUT;
        }
        snprintf(x->name, sizeof x->name, "%s", spec);
    }
    const size_t n = x->n = x->sc.agent_count;
    x->agents = malloc(n * sizeof *x->agents);
    x->goal = malloc(n * sizeof *x->goal);
    x->p = malloc(n * sizeof *x->p);
    x->v = malloc(n * sizeof *x->v);
    x->p2 = malloc(n * sizeof *x->p2);
    x->v2 = malloc(n * sizeof *x->v2);
    x->wp = malloc(n * sizeof *x->wp);
    x->shared = n > CROWD_CHARACTERS_MAX;
    bool ok = x->agents && x->goal && x->p && x->v && x->p2 && x->v2 && x->wp;
    if (ok) ok = crowd_chars_init(&x->chars, &x->sc, 0, &diag) == AK_OK;
    x->chars.unplanted = x->shared; /* shared poses have no foot planting */
    if (ok)
        ok = (x->shared ? crowd_people_init_shared(&x->people, n, &x->chars)
                        : crowd_people_init(&x->people, n, &x->chars)) &&
             crowd_walls(&x->sc, &x->wall, &x->wall_count);
    if (!ok || xsim_restart(x) != CLI_OK) {
        snprintf(err, err_size, "%s: cannot start the crowd (out of memory or a bad scene)", x->name);
        xsim_destroy(x);
        return CLI_BAD_INPUT;
    }
    /* the box the camera frames: starts and goals, 1.8 m high */
    x->lo = ak_vec3_make(INFINITY, 0.0f, INFINITY);
    x->hi = ak_vec3_make(-INFINITY, 1.8f, -INFINITY);
    for (size_t i = 0; i < n; ++i) {
        const ak_vec2 a = x->sc.positions[i], g = x->sc.agents[i].goals.ptr[x->sc.agents[i].goals.count - 1];
        x->lo.x = fminf(x->lo.x, fminf(a.x, g.x));
        x->lo.z = fminf(x->lo.z, fminf(a.y, g.y));
        x->hi.x = fmaxf(x->hi.x, fmaxf(a.x, g.x));
        x->hi.z = fmaxf(x->hi.z, fmaxf(a.y, g.y));
    }
    *state = x;
    return CLI_OK;
}

static bool xsim_step_once(void* state) {
    xsim* x = state;
    ak_crowd_step_job job = {.crowd = x->crowd, .dt = x->sc.dt, .thread_count = x->threads,
                             .positions = {x->p, x->n}, .velocities = {x->v, x->n}, .waypoints = {x->wp, x->n},
                             .scratch = {x->scratch, x->scratch_size}, .out_positions = {x->p2, x->n},
                             .out_velocities = {x->v2, x->n}, .step_index = (uint64_t)x->step_index,
                             .contact_iterations = x->sc.contact_iterations};
    ak_result r = ak_crowd_step_run(&job);
    if (r == AK_OK) r = crowd_chars_update(&x->chars, x->v2, x->p2, x->sc.dt);
    if (r != AK_OK) {
        cli_fail("view", "%s: step %ld: %s", x->name, x->step_index + 1, ak_result_string(r));
        return false;
    }
    ak_vec2* t = x->p;
    x->p = x->p2;
    x->p2 = t;
    t = x->v;
    x->v = x->v2;
    x->v2 = t;
    ++x->step_index;
    return true;
}

static void xsim_step(void* state, float dt) {
    xsim* x = state;
    if (x->failed) return;
    x->carry += (double)dt;
    for (int k = 0; x->carry >= 0.999999 * (double)x->sc.dt && k < MAX_STEPS_PER_FRAME; ++k) {
        if (!xsim_step_once(x)) {
            x->failed = true;
            return;
        }
        x->carry -= (double)x->sc.dt;
    }
    if (x->carry > (double)x->sc.dt) x->carry = 0.0; /* fell behind: drop the debt */
}

static void xsim_reset(void* state) {
    xsim* x = state;
    if (xsim_restart(x) != CLI_OK) x->failed = true;
}

static bool xsim_failed(void* state) { return ((const xsim*)state)->failed; }

static size_t xsim_meshes(void* state, ak_raster_mesh* out, size_t cap) {
    xsim* x = state;
    size_t k = 0;
    ak_raster_mesh people;
    if (!x->shared && k < cap && crowd_people_update(&x->people, &x->sc, x->p, &x->chars, &people) == AK_OK)
        out[k++] = people;
    if (k < cap && x->wall_count)
        out[k++] = (ak_raster_mesh){.positions = {x->wall, x->wall_count}, .material = {.color = {0.6f, 0.6f, 0.62f, 1}}};
    if (k < cap && x->has_marker)
        out[k++] = (ak_raster_mesh){.positions = {x->marker, MARKER_VERTS}, .material = {.color = {0.9f, 0.15f, 0.1f, 1}}};
    return k;
}

/* Above CROWD_CHARACTERS_MAX agents the characters share skinned poses and are drawn here,
 * CROWD_SHARED_CHUNK at a time, after the ground (the scene's meshes carry the walls only). */
static ak_result xsim_draw(void* state, ak_raster* raster, const ak_raster_camera* cam, int w, int h) {
    (void)w, (void)h;
    xsim* x = state;
    if (!x->shared) return AK_OK;
    ak_raster_mesh people;
    const ak_result r = crowd_people_update(&x->people, &x->sc, x->p, &x->chars, &people);
    return r == AK_OK ? crowd_people_draw(&x->people, raster, cam, &people) : r;
}

static void xsim_bounds(void* state, ak_vec3* lo, ak_vec3* hi) {
    const xsim* x = state;
    *lo = ak_vec3_min(*lo, x->lo);
    *hi = ak_vec3_max(*hi, x->hi);
}

/* The ground point (y = 0) under pixel (px, py); false when the ray misses it. */
static bool ground_under(const ak_raster_camera* cam, int w, int h, float px, float py, ak_vec2* out) {
    const ak_mat4 inv = ak_mat4_inverse(ak_mat4_mul(cam->projection, cam->view));
    const float nx = 2.0f * px / (float)w - 1.0f, ny = 1.0f - 2.0f * py / (float)h;
    ak_vec4 a = ak_mat4_mul_vec4(inv, ak_vec4_make(nx, ny, 0.0f, 1.0f));
    ak_vec4 b = ak_mat4_mul_vec4(inv, ak_vec4_make(nx, ny, 0.5f, 1.0f));
    if (a.w == 0.0f || b.w == 0.0f) return false;
    const ak_vec3 p = ak_vec3_make(a.x / a.w, a.y / a.w, a.z / a.w), q = ak_vec3_make(b.x / b.w, b.y / b.w, b.z / b.w);
    const float dy = q.y - p.y;
    if (!(fabsf(dy) > 1e-12f)) return false;
    const float t = -p.y / dy;
    if (!(t > 0.0f) || !ak_finitef(t)) return false;
    *out = ak_vec2_make(p.x + t * (q.x - p.x), p.z + t * (q.z - p.z));
    return ak_finitef(out->x) && ak_finitef(out->y) && fabsf(out->x) < 1e6f && fabsf(out->y) < 1e6f;
}

/* Send the selected agents (x->group, or all) to goal: each keeps its offset from their centre. */
static void send(xsim* x, ak_vec2 goal) {
    ak_vec2 c = {0, 0};
    size_t m = 0;
    for (size_t i = 0; i < x->n; ++i)
        if (x->group < 0 || x->sc.group[i] == (uint8_t)x->group) c = ak_vec2_add(c, x->p[i]), ++m;
    if (!m) return;
    c = ak_vec2_scale(c, 1.0f / (float)m);
    for (size_t i = 0; i < x->n; ++i) {
        if (x->group >= 0 && x->sc.group[i] != (uint8_t)x->group) continue;
        x->goal[i] = ak_vec2_add(goal, ak_vec2_sub(x->p[i], c));
        x->agents[i].goals = (ak_vec2_cspan){&x->goal[i], 1};
        x->wp[i] = 0;
    }
    x->click = goal;
    x->has_marker = true;
    const float pi = 3.14159265358979f, r0 = 0.35f, r1 = 0.55f;
    for (int s = 0; s < 4; ++s) { /* a ring of 4 flat quads, 2 cm above the ground */
        const float a0 = 0.5f * pi * (float)s, a1 = a0 + 0.5f * pi;
        const ak_vec3 i0 = {goal.x + r0 * cosf(a0), 0.02f, goal.y + r0 * sinf(a0)},
                      i1 = {goal.x + r0 * cosf(a1), 0.02f, goal.y + r0 * sinf(a1)},
                      o0 = {goal.x + r1 * cosf(a0), 0.02f, goal.y + r1 * sinf(a0)},
                      o1 = {goal.x + r1 * cosf(a1), 0.02f, goal.y + r1 * sinf(a1)};
        ak_vec3* q = x->marker + 6 * s;
        q[0] = i0, q[1] = o0, q[2] = o1, q[3] = i0, q[4] = o1, q[5] = i1;
    }
    if (rebuild(x) != AK_OK) x->failed = true;
}

static bool xsim_grab(void* state, const ak_raster_camera* cam, int w, int h, float px, float py, ak_vec3* anchor) {
    xsim* x = state;
    ak_vec2 g;
    if (!ground_under(cam, w, h, px, py, &g)) return false;
    x->group = -1;
    if (!x->whole_crowd) {
        float best = INFINITY;
        for (size_t i = 0; i < x->n; ++i) {
            const float d = ak_vec2_length(ak_vec2_sub(x->p[i], g));
            if (d < best) best = d, x->group = x->sc.group[i];
        }
    }
    send(x, g);
    *anchor = ak_vec3_make(g.x, 0.0f, g.y);
    return true;
}

static void xsim_drag(void* state, ak_vec3 delta) {
    xsim* x = state;
    if (!x->has_marker || !ak_vec3_is_finite(delta)) return;
    const ak_vec2 g = ak_vec2_make(x->click.x + delta.x, x->click.y + delta.z);
    if (fabsf(g.x) > 1e6f || fabsf(g.y) > 1e6f) return;
    /* move the goals, not the formation: the offsets stay those of the click */
    const ak_vec2 d = ak_vec2_sub(g, x->click);
    for (size_t i = 0; i < x->n; ++i)
        if (x->agents[i].goals.ptr == &x->goal[i]) x->goal[i] = ak_vec2_add(x->goal[i], d);
    x->click = g;
    for (int k = 0; k < MARKER_VERTS; ++k) x->marker[k].x += d.x, x->marker[k].z += d.y;
    if (rebuild(x) != AK_OK) x->failed = true;
}

static bool xsim_key(void* state, int key, char* msg, size_t msg_size) {
    xsim* x = state;
    if (key != 'g') return false;
    x->whole_crowd = !x->whole_crowd;
    snprintf(msg, msg_size, "a click sends %s", x->whole_crowd ? "the whole crowd" : "the nearest group");
    return true;
}

static void xsim_status(void* state, char* out, size_t n) {
    xsim* x = state;
    size_t home = 0;
    for (size_t i = 0; i < x->n; ++i) home += ak_crowd_goal_reached(x->crowd, i, x->p[i], x->wp[i]);
    char sent[64] = "";
    if (x->has_marker) snprintf(sent, sizeof sent, ", goal %.1f %.1f", (double)x->click.x, (double)x->click.y);
    snprintf(out, n, "t %.2fs, %zu agents, %zu at their goal%s%s", (double)x->step_index * (double)x->sc.dt, x->n,
             home, sent, x->failed ? ", stopped (step failed)" : "");
}

static const view_help_entry xsim_keys[] = {
    {"r", "restart the crowd (also tab)"},
    {"g", "a click sends the nearest group / the whole crowd"},
    {"right", "one frame of simulation, paused"},
};

const view_sim view_crowd_sim = {
    .name = "crowd",
    .init = xsim_init,
    .step = xsim_step,
    .reset = xsim_reset,
    .meshes = xsim_meshes,
    .draw = xsim_draw,
    .bounds = xsim_bounds,
    .key = xsim_key,
    .grab = xsim_grab,
    .drag = xsim_drag,
    .status = xsim_status,
    .destroy = xsim_destroy,
    .failed = xsim_failed,
    .grab_help = "left on the ground: send the nearest group there (g: the crowd)",
    .keys = xsim_keys,
    .key_count = sizeof xsim_keys / sizeof xsim_keys[0],
};
