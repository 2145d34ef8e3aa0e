/* animkit crowd: scene files (strict JSON through src/json.h) and presets (keys and defaults:
 * docs/crowd.md). */
#include <animkit/crowd.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "json.h"

#define COORD 1e6f /* metres: largest coordinate a scene may give */

void ak_crowd_scene_defaults(ak_crowd_scene* s) {
    memset(s, 0, sizeof *s);
    s->defaults = ak_crowd_agent_resolved(NULL);
    s->defaults.waypoint_radius = 0.0f; /* 0 -> the agent's radius, resolved per agent */
    s->steps = 1000;
    s->dt = 0.1f;
    s->contact_iterations = 8;
    s->method = AK_CROWD_ORCA;
    s->vision_view = AK_CROWD_VIEW_RAYCAST;
}

/* The agents and their arrays (a file's "agents" replaces them). */
static void free_agents(ak_crowd_scene* s) {
    free(s->agents);
    free(s->positions);
    free(s->velocities);
    free(s->group);
    free(s->waypoints);
    s->agents = NULL;
    s->positions = s->velocities = s->waypoints = NULL;
    s->group = NULL;
    s->agent_count = s->waypoint_count = 0;
}

/* The obstacles and their vertices (a file's "obstacles" replaces them). */
static void free_obstacles(ak_crowd_scene* s) {
    free(s->obstacles);
    free(s->vertices);
    s->obstacles = NULL;
    s->vertices = NULL;
    s->obstacle_count = s->vertex_count = 0;
}

void ak_crowd_scene_free(ak_crowd_scene* s) {
    if (!s) return;
    free_agents(s);
    free_obstacles(s);
}

/* ---- presets ------------------------------------------------------------------------------ */

/* Arrays for n agents with per_agent waypoints each and the given obstacle vertices. */
static int alloc_scene(ak_crowd_scene* s, size_t n, size_t per_agent, size_t obstacles, size_t vertices) {
    s->agents = calloc(n, sizeof *s->agents);
    s->positions = calloc(n, sizeof *s->positions);
    s->velocities = calloc(n, sizeof *s->velocities);
    s->group = calloc(n, 1);
    s->waypoints = calloc(n * per_agent, sizeof *s->waypoints);
    s->obstacles = obstacles ? calloc(obstacles, sizeof *s->obstacles) : NULL;
    s->vertices = vertices ? calloc(vertices, sizeof *s->vertices) : NULL;
    if (!s->agents || !s->positions || !s->velocities || !s->group || !s->waypoints || (obstacles && !s->obstacles) ||
        (vertices && !s->vertices))
        return 1;
    s->agent_count = n;
    s->waypoint_count = n * per_agent;
    for (size_t i = 0; i < n; ++i) {
        s->agents[i] = s->defaults;
        s->agents[i].goals = (ak_vec2_cspan){s->waypoints + i * per_agent, per_agent};
    }
    return 0;
}

/* A wall segment (both sides block) into the scene's obstacle k. */
static void wall(ak_crowd_scene* s, size_t k, ak_vec2 a, ak_vec2 b) {
    s->vertices[2 * k] = a;
    s->vertices[2 * k + 1] = b;
    s->obstacles[k].vertices = (ak_vec2_cspan){s->vertices + 2 * k, 2};
    s->obstacle_count = k + 1;
    s->vertex_count = 2 * (k + 1);
}

static long steps_for(float seconds, float dt) { return (long)ceilf(seconds / dt); }

/* The preset's agents, obstacles and duration over the defaults in s: 0, -1 for an unknown
 * name, 1 when out of memory. */
static int preset_fill(const char* name, size_t count, ak_crowd_scene* s) {
    const float pi = 3.14159265358979f;
    const float v = s->defaults.pref_speed > 0.0f ? s->defaults.pref_speed : 1.3f;
    if (strcmp(name, "circle") == 0) {
        /* count agents 1.8 m apart on a circle (at least 8 m across), each to the antipode */
        const size_t n = count ? count : 100;
        const float R = fmaxf(8.0f, (float)n * 1.8f / (2.0f * pi));
        if (alloc_scene(s, n, 1, 0, 0)) return 1;
        for (size_t i = 0; i < n; ++i) {
            const float a = 2.0f * pi * (float)i / (float)n;
            s->positions[i] = (ak_vec2){R * cosf(a), R * sinf(a)};
            s->waypoints[i] = (ak_vec2){-s->positions[i].x, -s->positions[i].y};
            s->group[i] = (uint8_t)(4 * i / n);
        }
        /* the walk across, half again for the jam in the middle, and two minutes */
        s->duration = 1.5f * 2.0f * R / v + 120.0f + 0.02f * (float)n;
        return 0;
    }
    if (strcmp(name, "crossing") == 0) {
        /* four square blocks (1.6 m apart) walk across the centre from the four sides */
        const size_t n = count ? count : 100;
        const size_t per = (n + 3) / 4;
        const size_t cols = (size_t)ceil(sqrt((double)per));
        const size_t rows = (per + cols - 1) / cols;
        const float sp = 1.6f, half = 0.5f * sp * (float)cols + 4.0f;
        const float travel = 2.0f * half + sp * (float)rows;
        if (alloc_scene(s, n, 1, 0, 0)) return 1;
        static const float dir[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
        for (size_t i = 0; i < n; ++i) {
            const size_t g = i % 4, k = i / 4;
            const float a = ((float)(k % cols) - 0.5f * (float)(cols - 1)) * sp;
            const float b = half + sp * (float)(k / cols);
            s->positions[i] = (ak_vec2){-dir[g][0] * b + dir[g][1] * a, -dir[g][1] * b + dir[g][0] * a};
            s->waypoints[i] = (ak_vec2){s->positions[i].x + travel * dir[g][0], s->positions[i].y + travel * dir[g][1]};
            s->group[i] = (uint8_t)g;
        }
        /* the walk across twice, two minutes, and the jam where the four blocks meet: 10,000
         * agents were all home after 8,000 to 8,500 steps of 0.1 s (docs/crowd.md), hence
         * 0.06 s per agent (9,785 steps there) */
        s->duration = 2.0f * travel / v + 120.0f + 0.06f * (float)n;
        return 0;
    }
    if (strcmp(name, "corridor") == 0) {
        /* two groups (5 abreast, 1 m apart: a 4.6 m wide block) walk at each other down an
         * 8 m wide corridor (walls along x); each group's goals are a block beyond where the
         * other group started, so that nobody arrives where the other group still is (agents
         * caught in a parked block cannot walk out of it). The goal block is 5 abreast too
         * but 1.5 m apart both ways (0.9 m gaps between parked 0.6 m bodies): the groups
         * arrive in lanes along the walls and, with the side preference, approach their
         * goals from the side, so late arrivals must be able to walk between parked agents
         * (with the start block's 1 m, 0.4 m gaps, 16 of 10,000 could not: docs/crowd.md);
         * the front rows, first to arrive, park in the far rows. */
        const size_t n = count ? count : 100;
        const float W = 8.0f, sp = 1.0f, gsp = 1.5f;
        const size_t per_row = 5, rows = ((n + 1) / 2 + per_row - 1) / per_row;
        const float L = 30.0f, depth = sp * (float)rows;
        const float near = 0.5f * L + depth + 2.0f;             /* the goal block's near row */
        const float far = near + gsp * (float)(rows - 1);        /* and its far row */
        const float travel = 0.5f * L + far;                     /* the longest walk */
        if (alloc_scene(s, n, 1, 2, 4)) return 1;
        wall(s, 0, (ak_vec2){-far - 10.0f, -0.5f * W}, (ak_vec2){far + 10.0f, -0.5f * W});
        wall(s, 1, (ak_vec2){-far - 10.0f, 0.5f * W}, (ak_vec2){far + 10.0f, 0.5f * W});
        for (size_t i = 0; i < n; ++i) {
            const size_t g = i % 2, k = i / 2, row = k / per_row;
            const float side = g == 0 ? -1.0f : 1.0f, col = (float)(k % per_row) - 0.5f * (float)(per_row - 1);
            s->positions[i] = (ak_vec2){side * (0.5f * L + sp * (float)row), col * sp};
            s->waypoints[i] = (ak_vec2){-side * (far - gsp * (float)row), col * gsp};
            s->group[i] = (uint8_t)g;
        }
        s->duration = 2.5f * travel / v + 120.0f + 0.02f * (float)n;
        return 0;
    }
    if (strcmp(name, "evacuation") == 0) {
        /* a square room (agents 0.9 m apart) with one door in the +x wall; each agent walks to
         * the door, through it, then to its own place in a grid outside, 1.5 m apart both
         * ways (0.9 m gaps between parked 0.6 m bodies, so that the last out can walk between
         * those parked; with 0.9 x 1.8 m, 0.3 m gaps, one of 100 stalled for 1,500 steps): the
         * columns nearest the door, first out, go farthest */
        const size_t n = count ? count : 100;
        const size_t cols = (size_t)ceil(sqrt((double)n));
        const float sp = 0.9f, gsp = 1.5f, S = fmaxf(10.0f, sp * (float)cols + 4.0f), h = 0.5f * S;
        const float door = fmaxf(2.0f, 0.02f * (float)cols + 2.0f);
        if (alloc_scene(s, n, 3, 5, 10)) return 1;
        wall(s, 0, (ak_vec2){-h, -h}, (ak_vec2){h, -h});
        wall(s, 1, (ak_vec2){h, h}, (ak_vec2){-h, h});
        wall(s, 2, (ak_vec2){-h, h}, (ak_vec2){-h, -h});
        wall(s, 3, (ak_vec2){h, -h}, (ak_vec2){h, -0.5f * door});
        wall(s, 4, (ak_vec2){h, 0.5f * door}, (ak_vec2){h, h});
        for (size_t i = 0; i < n; ++i) {
            const float x = ((float)(i % cols) - 0.5f * (float)(cols - 1)) * sp;
            const float z = ((float)(i / cols) - 0.5f * (float)(cols - 1)) * sp;
            s->positions[i] = (ak_vec2){x - 1.0f, z};
            ak_vec2* w = s->waypoints + 3 * i;
            w[0] = (ak_vec2){h - 1.0f, 0.0f};
            w[1] = (ak_vec2){h + 1.5f, 0.0f};
            w[2] = (ak_vec2){h + 6.0f + gsp * (float)(i % cols), gsp * ((float)(i / cols) - 0.5f * (float)(cols - 1))};
            s->agents[i].waypoint_radius = 0.5f * door; /* passing the door's mouth is enough */
            s->group[i] = (uint8_t)((i / cols) * 4 / cols);
        }
        /* ORCA lets about 0.6 agents per second per metre of door through (measured) */
        s->duration = 3.0f * S / v + 2.5f * (float)n / door + 120.0f;
        return 0;
    }
    return -1;
}

ak_result ak_crowd_scene_preset(const char* name, size_t count, ak_crowd_scene* s, ak_diag* out_diag) {
    if (!s || !name) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, "preset", "no name or scene");
    ak_crowd_scene_defaults(s);
    if (count > AK_CROWD_SCENE_MAX_AGENTS)
        return akp_diag_set(out_diag, AK_ERR_BAD_ARG, name, "%zu agents is more than %u", count,
                            AK_CROWD_SCENE_MAX_AGENTS);
    const int bad = preset_fill(name, count, s);
    if (bad) {
        ak_crowd_scene_free(s);
        ak_crowd_scene_defaults(s);
        if (bad > 0) return akp_diag_set(out_diag, AK_ERR_NO_MEMORY, name, "out of memory");
        return akp_diag_set(out_diag, AK_ERR_NOT_FOUND, name, "unknown preset (allowed: " AK_CROWD_SCENE_PRESETS ")");
    }
    s->steps = steps_for(s->duration, s->dt);
    if (out_diag) memset(out_diag, 0, sizeof *out_diag);
    return AK_OK;
}

/* ---- the file ---------------------------------------------------------------------------- */

/* A [x, z] element at path. */
static bool vec2_elem(akp_json* j, const cJSON* e, const char* path, ak_vec2* out) {
    if (j->failed) return false;
    if (!cJSON_IsArray(e) || cJSON_GetArraySize(e) != 2 || !cJSON_IsNumber(e->child) || !cJSON_IsNumber(e->child->next))
        return akp_json_fail(j, path, NULL, "expected [x, z], two numbers");
    const double x = e->child->valuedouble, z = e->child->next->valuedouble;
    if (!(fabs(x) <= COORD) || !(fabs(z) <= COORD))
        return akp_json_fail(j, path, NULL, "expected coordinates within +-1e6 m");
    *out = (ak_vec2){(float)x, (float)z};
    return true;
}

/* An optional [x, z] member. */
static bool vec2_member(akp_json* j, const cJSON* obj, const char* path, const char* key, ak_vec2* out) {
    if (j->failed) return false;
    const cJSON* e = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!e) return true;
    char p[192];
    return vec2_elem(j, e, akp_json_key(p, sizeof p, path, key), out);
}

static const char* const agent_param_keys[] = {"radius", "pref_speed", "max_speed", "neighbor_distance",
                                               "max_neighbors", "time_horizon", "time_horizon_obstacles",
                                               "waypoint_radius", NULL};

/* The parameter keys of an agent or of agent_defaults over *a. */
static void read_params(akp_json* j, const cJSON* o, const char* path, ak_crowd_agent* a) {
    akp_json_float(j, o, path, "radius", 0.01f, 100.0f, &a->radius);
    akp_json_float(j, o, path, "pref_speed", 0.01f, 100.0f, &a->pref_speed);
    akp_json_float(j, o, path, "max_speed", 0.01f, 100.0f, &a->max_speed);
    akp_json_float(j, o, path, "neighbor_distance", 0.01f, 1000.0f, &a->neighbor_distance);
    long k = (long)a->max_neighbors;
    akp_json_int(j, o, path, "max_neighbors", 0, AK_CROWD_MAX_NEIGHBORS, &k);
    a->max_neighbors = (uint32_t)k;
    akp_json_float(j, o, path, "time_horizon", 0.01f, 1000.0f, &a->time_horizon);
    akp_json_float(j, o, path, "time_horizon_obstacles", 0.01f, 1000.0f, &a->time_horizon_obstacles);
    akp_json_float(j, o, path, "waypoint_radius", 0.0f, 1000.0f, &a->waypoint_radius);
    if (!j->failed && a->max_speed < a->pref_speed)
        akp_json_fail(j, path, "max_speed", "must be at least pref_speed (%g m/s)", (double)a->pref_speed);
}

static double signed_area(const ak_vec2* p, size_t n) {
    double a = 0.0;
    for (size_t k = 0; k < n; ++k) {
        const ak_vec2 u = p[k], w = p[(k + 1) % n];
        a += (double)u.x * w.y - (double)w.x * u.y;
    }
    return 0.5 * a;
}

/* The keys of root over s; false (j failed) on the first error. */
static bool parse(akp_json* j, const cJSON* root, ak_crowd_scene* s) {
    static const char* const keys[] = {"dt",     "steps",     "method",      "contact_iterations", "agent_defaults",
                                       "agents", "obstacles", "vision_view", NULL};
    akp_json_object(j, root, "", keys);
    akp_json_float(j, root, "", "dt", 1e-4f, 10.0f, &s->dt);
    long steps = s->steps;
    akp_json_int(j, root, "", "steps", 0, 100000000, &steps);
    s->steps = steps;
    static const char* const methods[] = {"orca", "vision", NULL}; /* ak_crowd_method's order */
    int method = (int)s->method;
    akp_json_enum(j, root, "", "method", methods, &method);
    s->method = (ak_crowd_method)method;
    static const char* const views[] = {"raycast", "raster", NULL}; /* ak_crowd_view's order */
    int view = (int)s->vision_view;
    akp_json_enum(j, root, "", "vision_view", views, &view);
    s->vision_view = (ak_crowd_view)view;
    long ci = (long)s->contact_iterations;
    akp_json_int(j, root, "", "contact_iterations", 0, 64, &ci);
    s->contact_iterations = (uint32_t)ci;
    const cJSON* d = akp_json_member(j, root, "", "agent_defaults");
    if (d) {
        akp_json_object(j, d, "agent_defaults", agent_param_keys);
        read_params(j, d, "agent_defaults", &s->defaults);
    }
    if (j->failed) return false;

    /* Obstacles: count vertices first (the budget), then copy. */
    size_t on = 0;
    const cJSON* ob = akp_json_array(j, root, "", "obstacles", AK_CROWD_SCENE_MAX_OBSTACLES, &on);
    size_t vn = 0;
    for (const cJSON* e = ob; e && !j->failed; e = e->next) {
        const cJSON* vs = cJSON_IsObject(e) ? cJSON_GetObjectItemCaseSensitive(e, "vertices") : NULL;
        if (vs && cJSON_IsArray(vs)) vn += (size_t)cJSON_GetArraySize(vs);
        if (vn > AK_CROWD_SCENE_MAX_VERTICES)
            return akp_json_fail(j, "obstacles", NULL, "more than %u vertices in all", AK_CROWD_SCENE_MAX_VERTICES);
    }
    if (j->failed) return false;
    const bool obstacles_given = cJSON_GetObjectItemCaseSensitive(root, "obstacles") != NULL;
    if (obstacles_given) free_obstacles(s); /* the file's replace the scene's */
    if (on) {
        s->obstacles = calloc(on, sizeof *s->obstacles);
        s->vertices = calloc(vn ? vn : 1, sizeof *s->vertices);
        if (!s->obstacles || !s->vertices) return akp_json_fail(j, "obstacles", NULL, "out of memory");
    }
    size_t k = 0, used = 0;
    for (const cJSON* e = ob; e && !j->failed; e = e->next, ++k) {
        char p[64];
        akp_json_index(p, sizeof p, "obstacles", k);
        if (!cJSON_IsObject(e)) return akp_json_fail(j, p, NULL, "expected an object");
        static const char* const okeys[] = {"vertices", NULL};
        akp_json_object(j, e, p, okeys);
        size_t m = 0;
        const cJSON* v = akp_json_array(j, e, p, "vertices", AK_CROWD_SCENE_MAX_VERTICES, &m);
        if (j->failed) return false;
        char vp[96];
        akp_json_key(vp, sizeof vp, p, "vertices");
        if (m < 2) return akp_json_fail(j, vp, NULL, "expected at least 2 vertices");
        for (size_t q = 0; v && q < m; ++q, v = v->next) {
            char ep[128];
            vec2_elem(j, v, akp_json_index(ep, sizeof ep, vp, q), &s->vertices[used + q]);
        }
        if (j->failed) return false;
        for (size_t q = 0; q < m; ++q) {
            const ak_vec2 a = s->vertices[used + q], b = s->vertices[used + (q + 1) % m];
            const float ex = b.x - a.x, ez = b.y - a.y;
            if (!(ex * ex + ez * ez > 0.0f)) {
                char ep[128];
                return akp_json_fail(j, akp_json_index(ep, sizeof ep, vp, (q + 1) % m), NULL,
                                     "equals the vertex before it (an edge of zero length)");
            }
        }
        if (m >= 3 && !(signed_area(s->vertices + used, m) > 0.0))
            return akp_json_fail(j, vp, NULL, "a polygon must be counter-clockwise in (x, z) with a positive area");
        s->obstacles[k].vertices = (ak_vec2_cspan){s->vertices + used, m};
        used += m;
    }
    if (obstacles_given) {
        s->obstacle_count = on;
        s->vertex_count = used;
    }

    /* Agents: count waypoints first (the budget), then copy. */
    size_t n = 0;
    const cJSON* ag = akp_json_array(j, root, "", "agents", AK_CROWD_SCENE_MAX_AGENTS, &n);
    if (j->failed) return false;
    size_t wn = 0;
    for (const cJSON* e = ag; e; e = e->next) {
        const cJSON* path = cJSON_IsObject(e) ? cJSON_GetObjectItemCaseSensitive(e, "path") : NULL;
        wn += path && cJSON_IsArray(path) ? (size_t)cJSON_GetArraySize(path) : 1;
        if (wn > AK_CROWD_MAX_WAYPOINTS)
            return akp_json_fail(j, "agents", NULL, "more than %u waypoints in all", AK_CROWD_MAX_WAYPOINTS);
    }
    if (cJSON_GetObjectItemCaseSensitive(root, "agents")) free_agents(s); /* the file's replace the scene's */
    if (n == 0) return true;
    s->agents = calloc(n, sizeof *s->agents);
    s->positions = calloc(n, sizeof *s->positions);
    s->velocities = calloc(n, sizeof *s->velocities);
    s->group = calloc(n, 1);
    s->waypoints = calloc(wn ? wn : 1, sizeof *s->waypoints);
    if (!s->agents || !s->positions || !s->velocities || !s->group || !s->waypoints)
        return akp_json_fail(j, "agents", NULL, "out of memory");
    static const char* const akeys[] = {"position", "velocity", "goal", "path", "group", "radius", "pref_speed",
                                        "max_speed", "neighbor_distance", "max_neighbors", "time_horizon",
                                        "time_horizon_obstacles", "waypoint_radius", NULL};
    size_t i = 0;
    used = 0;
    for (const cJSON* e = ag; e && !j->failed; e = e->next, ++i) {
        char p[64];
        akp_json_index(p, sizeof p, "agents", i);
        if (!cJSON_IsObject(e)) return akp_json_fail(j, p, NULL, "expected an object");
        akp_json_object(j, e, p, akeys);
        if (j->failed) return false;
        if (!cJSON_GetObjectItemCaseSensitive(e, "position")) return akp_json_fail(j, p, "position", "is required");
        vec2_member(j, e, p, "position", &s->positions[i]);
        vec2_member(j, e, p, "velocity", &s->velocities[i]);
        long g = 0;
        akp_json_int(j, e, p, "group", 0, 255, &g);
        s->group[i] = (uint8_t)g;
        ak_crowd_agent a = s->defaults;
        read_params(j, e, p, &a);
        const cJSON* goal = cJSON_GetObjectItemCaseSensitive(e, "goal");
        const cJSON* path = cJSON_GetObjectItemCaseSensitive(e, "path");
        if (j->failed) return false;
        if (!!goal == !!path) return akp_json_fail(j, p, NULL, "expected exactly one of \"goal\" and \"path\"");
        size_t m = 1;
        if (goal) {
            vec2_member(j, e, p, "goal", &s->waypoints[used]);
        } else {
            const cJSON* w = akp_json_array(j, e, p, "path", AK_CROWD_SCENE_MAX_PATH, &m);
            char pp[96];
            akp_json_key(pp, sizeof pp, p, "path");
            if (!j->failed && m == 0) return akp_json_fail(j, pp, NULL, "expected at least one waypoint");
            for (size_t q = 0; w && q < m && !j->failed; ++q, w = w->next) {
                char ep[128];
                vec2_elem(j, w, akp_json_index(ep, sizeof ep, pp, q), &s->waypoints[used + q]);
            }
        }
        if (j->failed) return false;
        a.goals = (ak_vec2_cspan){s->waypoints + used, m};
        used += m;
        s->agents[i] = a;
    }
    s->agent_count = n;
    s->waypoint_count = used;
    return !j->failed;
}

ak_result ak_crowd_scene_load_bytes(const void* bytes, size_t size, const char* name, ak_crowd_scene* scene,
                                    ak_diag* out_diag) {
    if (!scene) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, name ? name : "(scene)", "no scene to fill");
    akp_json j = {.file = name ? name : "(scene)"};
    if (!bytes && size) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, j.file, "no bytes");
    cJSON* root = akp_json_parse(&j, bytes ? (const char*)bytes : "", size);
    if (root && parse(&j, root, scene)) {
        if (cJSON_GetObjectItemCaseSensitive(root, "steps"))
            scene->duration = 0.0f; /* the file's count wins */
        else if (scene->duration > 0.0f)
            scene->steps = steps_for(scene->duration, scene->dt); /* a preset's run at the file's dt */
        if (scene->agent_count == 0) akp_json_fail(&j, "", "agents", "the scene has no agents");
    }
    cJSON_Delete(root);
    if (j.failed) return akp_json_diag(&j, AK_ERR_PARSE, out_diag);
    if (out_diag) memset(out_diag, 0, sizeof *out_diag);
    return AK_OK;
}

ak_result ak_crowd_scene_load_file(const char* path, ak_crowd_scene* scene, ak_diag* out_diag) {
    if (!scene || !path) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, path ? path : "(scene)", "no path or scene");
    akp_json j = {.file = path};
    size_t size = 0;
    char* text = akp_json_read_file(&j, path, AK_CROWD_SCENE_MAX_FILE_SIZE, &size);
    if (!text) return akp_json_diag(&j, AK_ERR_IO, out_diag);
    const ak_result r = ak_crowd_scene_load_bytes(text, size, path, scene, out_diag);
    free(text);
    return r;
}
