/* animkit skin --compare: LBS vs DQS vs CoR vs implicit on the classic poses: volume, bulge,
 * collapse and self-intersections. */
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

static const char* const usage =
    "usage: animkit skin --compare [FILE|builtin:NAME] [--json]\n"
    "Compare linear blend (LBS), dual quaternion (DQS), optimized-center (CoR), implicit\n"
    "(Vaillant et al. 2013/2014) and volumetric (soft: a simulated tetrahedral flesh,\n"
    "softskin.h) skinning. Soft reaches each cylinder pose by turning the joint over 1/6 s and\n"
    "holding it 1/2 s (60 Hz steps), and runs through a clip's 24 samples in order.\n"
    "On builtin:cylinder (the default) the middle joint is bent 90, 120 and 150 degrees and\n"
    "twisted 90 and 180 degrees (179.8, so the turn has a defined direction); for each pose and\n"
    "method it prints the volume of the deformed closed mesh relative to rest, the maximum\n"
    "bulge: the largest distance of a vertex from the posed bone axis beyond the rest radius, as\n"
    "a fraction of that radius, the minimum radius (the narrowest cross-section: the\n"
    "candy-wrapper collapse) and the number of intersecting pairs of non-adjacent triangles\n"
    "(exact test, ak_mesh_self_intersections).\n"
    "On another model it samples every clip at 24 times and prints, per method, the range of\n"
    "the volume ratio (closed meshes only), the largest distance from the LBS result and the\n"
    "most self-intersecting triangle pairs (every 4th frame).\n"
    "  --json  one JSON object instead: {\"model\", \"rest_volume\", \"rest_radius\", \"poses\":\n"
    "          [{\"pose\", \"LBS\"|\"DQS\"|\"CoR\"|\"implicit\"|\"soft\": {\"volume_ratio\", \"volume_change\",\n"
    "          \"max_bulge\", \"min_radius\", \"self_intersections\"}}]} for the cylinder;\n"
    "          {\"model\", \"methods\": [{\"method\", \"max_distance_from_lbs\", \"volume_min\",\n"
    "          \"volume_max\", \"volume_change_max\", \"self_intersections_max\"}]} for another model (volumes for closed\n"
    "          meshes)\n";

#define METHOD_COUNT 5
static const cli_method methods[METHOD_COUNT] = {CLI_LBS, CLI_DQS, CLI_COR, CLI_IMPLICIT, CLI_SOFT};

/* Pairs of non-adjacent triangles of mesh that intersect at pos (exact count, mesh.h). */
static size_t crossings(const ak_mesh* m, const ak_vec3* pos) {
    size_t n = 0;
    if (ak_mesh_self_intersections((ak_vec3_cspan){pos, m->vertex_count}, (ak_u32_cspan){m->indices, m->triangle_count * 3},
                                   (ak_u32_span){NULL, 0}, &n) != AK_OK)
        return 0;
    return n;
}

/* Distance from p to segment ab. */
static float seg_dist(ak_vec3 p, ak_vec3 a, ak_vec3 b) {
    ak_vec3 ab = ak_vec3_sub(b, a);
    float l2 = ak_vec3_length_sq(ab);
    float t = l2 > 0.0f ? ak_clampf(ak_vec3_dot(ak_vec3_sub(p, a), ab) / l2, 0.0f, 1.0f) : 0.0f;
    return ak_vec3_distance(p, ak_vec3_madd(a, ab, t));
}

/* Distance from p to the chain polyline of joint positions. */
static float chain_dist(ak_vec3 p, const ak_vec3* j, size_t n) {
    float d = INFINITY;
    for (size_t i = 0; i + 1 < n; ++i) d = ak_minf(d, seg_dist(p, j[i], j[i + 1]));
    return d;
}

static double mesh_volume(const ak_mesh* m, const ak_vec3* pos) {
    return ak_volume_compute((ak_vec3_cspan){pos, m->vertex_count}, (ak_u32_cspan){m->indices, m->triangle_count * 3});
}

/* Soft at one cylinder pose, in its own poser (its own soft body: the lattice is built the same
 * way, so the result is the one a shared poser gives): turn the joint over 10 frames, then
 * hold 30 (60 Hz). The poses run on their own threads: each is a few hundred milliseconds of
 * solve and none depends on another. */
typedef struct soft_pose_job {
    const ak_scene* scene;
    int mid;
    ak_quat rot;
    ak_vec3* out; /* [vertex count of mesh 0] */
    ak_result r;
} soft_pose_job;

static void* soft_pose_run(void* arg) {
    soft_pose_job* job = (soft_pose_job*)arg;
    cli_poser q;
    if (cli_poser_init(&q, job->scene)) {
        job->r = AK_ERR_NO_MEMORY;
        return NULL;
    }
    job->r = AK_OK;
    for (int fr = 0; fr < 40 && job->r == AK_OK; ++fr) {
        cli_poser_sample(&q, -1, 0.0f, true);
        const float u = ak_minf(1.0f, (float)fr / 10.0f);
        q.local[job->mid].rotation = ak_quat_mul(q.local[job->mid].rotation, ak_quat_slerp(ak_quat_identity(), job->rot, u));
        q.sample_time = (float)fr / 60.0f;
        job->r = cli_poser_deform(&q, false, CLI_SOFT);
    }
    if (job->r == AK_OK) memcpy(job->out, q.positions[0], job->scene->meshes[0].mesh->vertex_count * sizeof(ak_vec3));
    cli_poser_free(&q);
    return NULL;
}

static int compare_cylinder(ak_scene* s, bool json) {
    cli_poser p;
    if (cli_poser_init(&p, s)) return cli_fail("skin", "out of memory");
    const ak_mesh* mesh = s->meshes[0].mesh;
    size_t n = p.joint_count;
    int mid = ak_skeleton_find_joint(s->skeleton, "joint1");
    double rest_volume = mesh_volume(mesh, mesh->positions);
    /* rest radius: the largest distance of a vertex from the rest axis */
    ak_vec3* jp = calloc(n, sizeof(ak_vec3));
    int rc = CLI_OK;
    if (!jp || mid < 0) {
        free(jp);
        cli_poser_free(&p);
        return cli_fail("skin", "%s: not a cylinder chain (no joint 'joint1')", s->name);
    }
    cli_poser_sample(&p, -1, 0.0f, true);
    ak_scene_world_matrices(s, (ak_transform_cspan){p.local, n}, (ak_mat4_span){p.world, n});
    for (size_t j = 0; j < n; ++j) jp[j] = ak_mat4_get_translation(p.world[j]);
    float radius = 0.0f;
    for (size_t v = 0; v < mesh->vertex_count; ++v) radius = ak_maxf(radius, chain_dist(mesh->positions[v], jp, n));
    /* side vertices (not the caps): their rest distance to the axis is the radius */
    bool* side = calloc(mesh->vertex_count, sizeof(bool));
    if (!side) {
        free(jp);
        cli_poser_free(&p);
        return cli_fail("skin", "out of memory");
    }
    for (size_t v = 0; v < mesh->vertex_count; ++v) side[v] = chain_dist(mesh->positions[v], jp, n) > 0.99f * radius;
    struct {
        const char* name;
        ak_quat rot;
    } poses[5] = {
        {"bend 90", ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), AK_HALF_PI)},
        {"bend 120", ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), AK_PI * 2.0f / 3.0f)},
        {"bend 150", ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), AK_PI * 5.0f / 6.0f)},
        {"twist 90", ak_quat_from_axis_angle(ak_vec3_make(0, 1, 0), AK_HALF_PI)},
        {"twist 180", ak_quat_from_axis_angle(ak_vec3_make(0, 1, 0), AK_PI * 0.999f)},
    };
    /* soft at the five poses, one thread each (a pose the thread could not start for runs here) */
    soft_pose_job jobs[5];
    pthread_t threads[5];
    bool started[5] = {false, false, false, false, false};
    ak_vec3* soft_out = malloc(5 * mesh->vertex_count * sizeof(ak_vec3));
    if (!soft_out) {
        free(side);
        free(jp);
        cli_poser_free(&p);
        return cli_fail("skin", "out of memory");
    }
    for (int k = 0; k < 5; ++k) {
        jobs[k] = (soft_pose_job){.scene = s, .mid = mid, .rot = poses[k].rot, .out = soft_out + (size_t)k * mesh->vertex_count};
        started[k] = pthread_create(&threads[k], NULL, soft_pose_run, &jobs[k]) == 0;
    }
    for (int k = 0; k < 5; ++k) {
        if (started[k]) pthread_join(threads[k], NULL);
        else soft_pose_run(&jobs[k]);
    }
    if (json) printf("{\"model\": \"%s\", \"rest_volume\": %.9g, \"rest_radius\": %.9g, \"poses\": [", s->name,
                     rest_volume, (double)radius);
    else printf("%s: rest volume %.6g, rest radius %.4g\n%-10s %-8s %12s %12s %12s %10s\n", s->name, rest_volume, (double)radius,
                "pose", "", "volume/rest", "max bulge", "min radius", "crossings");
    for (int k = 0; k < 5 && rc == CLI_OK; ++k) {
        if (json) printf("%s{\"pose\": \"%s\"", k ? ", " : "", poses[k].name);
        for (int mi = 0; mi < METHOD_COUNT; ++mi) {
            /* soft: the pose's thread's result (the skeleton posed here by LBS's pass) */
            const bool soft = methods[mi] == CLI_SOFT;
            cli_poser_sample(&p, -1, 0.0f, true);
            p.local[mid].rotation = ak_quat_mul(p.local[mid].rotation, ak_quat_slerp(ak_quat_identity(), poses[k].rot, 1.0f));
            ak_result r = soft ? jobs[k].r : AK_OK;
            if (r == AK_OK) r = cli_poser_deform(&p, false, soft ? CLI_LBS : methods[mi]);
            if (r == AK_OK && soft) memcpy(p.positions[0], jobs[k].out, mesh->vertex_count * sizeof(ak_vec3));
            if (r != AK_OK) {
                rc = cli_fail("skin", "%s: %s", s->name, ak_result_string(r));
                break;
            }
            for (size_t j = 0; j < n; ++j) jp[j] = ak_mat4_get_translation(p.world[j]);
            double vol = mesh_volume(mesh, p.positions[0]) / rest_volume;
            float bulge = 0.0f, narrowest = INFINITY;
            for (size_t v = 0; v < mesh->vertex_count; ++v) {
                float dv = chain_dist(p.positions[0][v], jp, n);
                bulge = ak_maxf(bulge, dv - radius);
                if (side[v]) narrowest = ak_minf(narrowest, dv);
            }
            size_t cross = crossings(mesh, p.positions[0]);
            if (json)
                printf(", \"%s\": {\"volume_ratio\": %.9g, \"volume_change\": %.9g, \"max_bulge\": %.9g, \"min_radius\": %.9g, "
                       "\"self_intersections\": %zu}",
                       cli_method_name(methods[mi]), vol, vol - 1.0, (double)(bulge / radius), (double)(narrowest / radius), cross);
            else
                printf("%-10s %-8s %12.4f %11.2f%% %11.2f%% %10zu\n", mi == 0 ? poses[k].name : "", cli_method_name(methods[mi]),
                       vol, 100.0 * (double)(bulge / radius), 100.0 * (double)(narrowest / radius), cross);
        }
        if (json) printf("}");
    }
    if (json && rc == CLI_OK) printf("]}\n");
    free(soft_out);
    free(side);
    free(jp);
    cli_poser_free(&p);
    return rc;
}

static int compare_generic(ak_scene* s, bool json) {
    cli_poser p;
    if (cli_poser_init(&p, s)) return cli_fail("skin", "out of memory");
    int rc = CLI_OK;
    double vmin[METHOD_COUNT] = {INFINITY, INFINITY, INFINITY, INFINITY, INFINITY};
    double vmax[METHOD_COUNT] = {-INFINITY, -INFINITY, -INFINITY, -INFINITY, -INFINITY};
    float dmax[METHOD_COUNT] = {0, 0, 0, 0, 0};
    size_t xmax[METHOD_COUNT] = {0, 0, 0, 0, 0};
    size_t max_v = 0;
    for (size_t m = 0; m < s->mesh_count; ++m) max_v = s->meshes[m].mesh->vertex_count > max_v ? s->meshes[m].mesh->vertex_count : max_v;
    ak_vec3* lbs = calloc(max_v ? max_v : 1, sizeof(ak_vec3));
    bool any_closed = false;
    size_t clips = s->clip_count ? s->clip_count : 1;
    for (size_t c = 0; c < clips && rc == CLI_OK && lbs; ++c) {
        float dur = s->clip_count ? ak_clip_duration(s->clips[c]) : 0.0f;
        cli_poser_soft_reset(&p); /* soft runs through the clip's samples in order */
        for (int f = 0; f < 24 && rc == CLI_OK; ++f) {
            float t = dur * (float)f / 23.0f;
            for (int mi = 0; mi < METHOD_COUNT; ++mi) {
                ak_result r = cli_poser_pose(&p, s->clip_count ? (int)c : -1, t, false, methods[mi]);
                if (r != AK_OK) {
                    rc = cli_fail("skin", "%s: %s", s->name, ak_result_string(r));
                    break;
                }
                for (size_t m = 0; m < s->mesh_count; ++m) {
                    const ak_mesh* mesh = s->meshes[m].mesh;
                    if (s->meshes[m].skin < 0) continue;
                    if (ak_mesh_is_closed_oriented(mesh)) {
                        any_closed = true;
                        double v = mesh_volume(mesh, p.positions[m]) / mesh_volume(mesh, mesh->positions);
                        vmin[mi] = v < vmin[mi] ? v : vmin[mi];
                        vmax[mi] = v > vmax[mi] ? v : vmax[mi];
                    }
                    if (f % 4 == 0 && mesh->triangle_count) { /* every 4th frame: the count costs more */
                        size_t x = crossings(mesh, p.positions[m]);
                        xmax[mi] = x > xmax[mi] ? x : xmax[mi];
                    }
                    if (m == 0 && mi == 0) memcpy(lbs, p.positions[0], mesh->vertex_count * sizeof(ak_vec3));
                    if (m == 0)
                        for (size_t v = 0; v < mesh->vertex_count; ++v)
                            dmax[mi] = ak_maxf(dmax[mi], ak_vec3_distance(lbs[v], p.positions[0][v]));
                }
            }
        }
    }
    if (rc == CLI_OK) {
        if (json) printf("{\"model\": ");
        if (json) cli_json_string(stdout, s->name);
        if (json) printf(", \"methods\": [");
        else printf("%s: %zu clip%s x 24 frames\n%-8s %22s %18s %10s\n", s->name, s->clip_count, cli_plural(s->clip_count), "",
                    "volume/rest (min..max)", "max dist from LBS", "crossings");
        for (int mi = 0; mi < METHOD_COUNT; ++mi) {
            if (json) {
                printf("%s{\"method\": \"%s\", \"max_distance_from_lbs\": %.9g", mi ? ", " : "", cli_method_name(methods[mi]),
                       (double)dmax[mi]);
                if (any_closed)
                    printf(", \"volume_min\": %.9g, \"volume_max\": %.9g, \"volume_change_max\": %.9g", vmin[mi], vmax[mi],
                           fmax(fabs(vmin[mi] - 1.0), fabs(vmax[mi] - 1.0)));
                printf(", \"self_intersections_max\": %zu}", xmax[mi]);
            } else if (any_closed) {
                printf("%-8s %10.4f .. %-9.4f %18.6g %10zu\n", cli_method_name(methods[mi]), vmin[mi], vmax[mi], (double)dmax[mi],
                       xmax[mi]);
            } else {
                printf("%-8s %22s %18.6g %10zu\n", cli_method_name(methods[mi]), "(open mesh)", (double)dmax[mi], xmax[mi]);
            }
        }
        if (json) printf("]}\n");
    }
    free(lbs);
    cli_poser_free(&p);
    return rc;
}

int cmd_skin(int argc, char** argv) {
    static const cli_opt opts[] = {{"--compare", NULL, false}, {"--json", NULL, false}};
    cli_args a;
    int rc = cli_parse("skin", argc, argv, opts, sizeof opts / sizeof opts[0], &a);
    if (rc) return rc;
    if (a.help) {
        fputs(usage, stdout);
        return CLI_OK;
    }
    if (!CLI_GET(&a, "--compare")) return cli_usage("skin", "nothing to do: use --compare");
    if (a.pos_count > 1) return cli_usage("skin", "expected at most one FILE or builtin:NAME");
    const char* spec = a.pos_count ? a.pos[0] : "builtin:cylinder";
    ak_scene* s = NULL;
    if ((rc = cli_load_scene("skin", spec, &s))) return rc;
    bool skinned = false;
    for (size_t m = 0; m < s->mesh_count; ++m) skinned = skinned || (s->meshes[m].skin >= 0 && s->meshes[m].mesh->influence_count);
    if (!skinned) rc = cli_fail("skin", "%s: no skinned mesh to compare", spec);
    else if (strcmp(s->name, "builtin:cylinder") == 0) rc = compare_cylinder(s, CLI_GET(&a, "--json") != NULL);
    else rc = compare_generic(s, CLI_GET(&a, "--json") != NULL);
    ak_scene_destroy(s);
    return rc;
}
