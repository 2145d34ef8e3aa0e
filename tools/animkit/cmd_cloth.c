/* animkit cloth: simulate a cloth scene or preset; write JSON, OBJ, PNG or GIF. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "cli_json.h"
#include "render.h"
#include "scene_cloth.h"

static const char* const usage =
    "usage: animkit cloth [SCENE.json | --preset flag|curtain|drape|cape] [--solver springs|xpbd]\n"
    "                     [--steps N] [--dt DT] [--substeps S] [--threads T] [--json OUT.json]\n"
    "                     [-o OUT.gif|OUT.png|OUT.obj]\n"
    "Simulate a cloth: a flag in gusty wind, a curtain on rings, a square draped on a sphere, or a\n"
    "cape on builtin:humanoid walking; or the scene a JSON file describes (docs/cloth.md lists\n"
    "every key). The solver is XPBD (compliant constraints, substeps) or the classic mass-spring\n"
    "model (semi-implicit Euler, which needs small steps: raise --substeps if it blows up).\n"
    "--json writes {\"time\", \"positions\", \"max_stretch\", \"energy\"} of the final state;\n"
    "-o renders the run (GIF), its last frame (PNG) or writes the last state as OBJ.\n"
    "Exit status: 0 success, 1 bad scene or a blow-up (named by its step), 2 bad usage.\n";

/* ---- the character: pose, attachments, colliders ------------------------------------------- */

typedef struct character {
    ak_scene* scene;
    cli_poser poser;
    int clip;
    float duration;
    int* attach_joint;      /* [attach_count] joint index or -1 */
    ak_vec3* attach_offset; /* joint-local offset, or offset from the mesh vertex */
    ak_vec3* mesh_pos;      /* all meshes' posed positions, concatenated */
    uint32_t* mesh_idx;
    size_t mesh_vertices, mesh_tris;
    int* bone_parent;       /* limb capsules: joint pairs and radii */
    int* bone_child;
    float* bone_radius;
    size_t bone_count;
    ak_cloth_capsule* capsules; /* scene capsules then limb capsules */
} character;

static void character_free(character* c) {
    if (c->scene) cli_poser_free(&c->poser);
    ak_scene_destroy(c->scene);
    free(c->attach_joint), free(c->attach_offset), free(c->mesh_pos), free(c->mesh_idx);
    free(c->bone_parent), free(c->bone_child), free(c->bone_radius), free(c->capsules);
    memset(c, 0, sizeof *c);
}

/* Pose at time t (looping the clip) and gather the posed meshes into one collider. */
static ak_result character_pose(character* c, float t) {
    const float tt = c->duration > 0.0f ? fmodf(t, c->duration) : 0.0f;
    ak_result r = cli_poser_pose(&c->poser, c->clip, tt, c->clip < 0, CLI_LBS);
    if (r != AK_OK) return r;
    size_t off = 0;
    for (size_t m = 0; m < c->scene->mesh_count; ++m) {
        const ak_mesh* mesh = c->scene->meshes[m].mesh;
        if (!mesh) continue;
        memcpy(c->mesh_pos + off, c->poser.positions[m], mesh->vertex_count * sizeof(ak_vec3));
        off += mesh->vertex_count;
    }
    return AK_OK;
}

/* Limb capsules: each bone between two skin joints, with radius scale x the mean distance from
 * the bone of the bind-pose vertices its parent joint dominates that lie along the bone. */
static int character_bones(character* c, float scale) {
    const ak_scene* s = c->scene;
    const size_t n = ak_scene_joint_count(s);
    if (!n || !s->skeleton) return CLI_OK;
    ak_i16_cspan parents = ak_skeleton_parents(s->skeleton);
    c->bone_parent = calloc(n, sizeof(int));
    c->bone_child = calloc(n, sizeof(int));
    c->bone_radius = calloc(n, sizeof(float));
    if (!c->bone_parent || !c->bone_child || !c->bone_radius) return CLI_BAD_INPUT;
    character_pose(c, 0.0f);
    cli_poser_pose(&c->poser, -1, 0.0f, true, CLI_LBS); /* bind pose: world matrices at rest */
    for (size_t j = 0; j < n; ++j) {
        const int p = parents.ptr[j];
        if (p < 0 || (s->is_joint && (!s->is_joint[j] || !s->is_joint[p]))) continue;
        const ak_vec3 a = ak_mat4_get_translation(c->poser.world[p]), b = ak_mat4_get_translation(c->poser.world[j]);
        const ak_vec3 ab = ak_vec3_sub(b, a);
        const float l2 = ak_vec3_length_sq(ab);
        if (l2 < 1e-8f) continue;
        double sum = 0;
        size_t cnt = 0;
        for (size_t m = 0; m < s->mesh_count; ++m) {
            const ak_mesh* mesh = s->meshes[m].mesh;
            const int sk = s->meshes[m].skin;
            if (!mesh || sk < 0 || !mesh->influence_count) continue;
            const ak_scene_skin* skin = &s->skins[sk];
            for (size_t v = 0; v < mesh->vertex_count; ++v) {
                const uint16_t* jj = mesh->joints + v * mesh->influence_count;
                const float* ww = mesh->weights + v * mesh->influence_count;
                uint32_t best = 0;
                for (uint32_t k = 1; k < mesh->influence_count; ++k)
                    if (ww[k] > ww[best]) best = k;
                if (jj[best] >= skin->joint_count || skin->joints[jj[best]] != p) continue;
                const ak_vec3 x = mesh->positions[v];
                const float t = ak_vec3_dot(ak_vec3_sub(x, a), ab) / l2;
                if (t <= 0.1f || t >= 0.9f) continue;
                sum += ak_vec3_distance(x, ak_vec3_madd(a, ab, t));
                ++cnt;
            }
        }
        if (cnt < 8) continue;
        c->bone_parent[c->bone_count] = p;
        c->bone_child[c->bone_count] = (int)j;
        c->bone_radius[c->bone_count] = scale * (float)(sum / (double)cnt);
        c->bone_count++;
    }
    return CLI_OK;
}

/* ---- output ------------------------------------------------------------------------------ */

static int write_json(const char* path, float time, const ak_vec3* x, size_t n, float stretch, double energy) {
    FILE* f = fopen(path, "w");
    if (!f) return cli_fail("cloth", "%s: cannot open for writing", path);
    fprintf(f, "{\"time\": %.9g, \"positions\": [", (double)time);
    for (size_t v = 0; v < n; ++v)
        fprintf(f, "%s[%.9g, %.9g, %.9g]", v ? ", " : "", (double)x[v].x, (double)x[v].y, (double)x[v].z);
    fprintf(f, "], \"max_stretch\": %.9g, \"energy\": %.9g}\n", (double)stretch, energy);
    if (fclose(f) != 0) return cli_fail("cloth", "%s: cannot write", path);
    return CLI_OK;
}

static int write_obj(const char* path, const ak_cloth* cloth, const ak_vec3* x, const ak_vec3* nrm) {
    FILE* f = fopen(path, "w");
    if (!f) return cli_fail("cloth", "%s: cannot open for writing", path);
    const size_t n = ak_cloth_vertex_count(cloth);
    ak_u32_cspan idx = ak_cloth_indices(cloth);
    fprintf(f, "# animkit cloth: %zu vertices, %zu triangles\no cloth\n", n, idx.count / 3);
    for (size_t v = 0; v < n; ++v) fprintf(f, "v %.7g %.7g %.7g\n", (double)x[v].x, (double)x[v].y, (double)x[v].z);
    for (size_t v = 0; v < n; ++v) fprintf(f, "vn %.6g %.6g %.6g\n", (double)nrm[v].x, (double)nrm[v].y, (double)nrm[v].z);
    for (size_t t = 0; t + 2 < idx.count; t += 3)
        fprintf(f, "f %u//%u %u//%u %u//%u\n", idx.ptr[t] + 1, idx.ptr[t] + 1, idx.ptr[t + 1] + 1, idx.ptr[t + 1] + 1,
                idx.ptr[t + 2] + 1, idx.ptr[t + 2] + 1);
    if (fclose(f) != 0) return cli_fail("cloth", "%s: cannot write", path);
    return CLI_OK;
}

/* A sphere (a == b) or capsule mesh for drawing: rings x segments of a unit sphere whose halves
 * are centred on a and b. */
enum { PROP_RINGS = 12, PROP_SEGS = 20, PROP_VERTS = (PROP_RINGS + 1) * PROP_SEGS, PROP_TRIS = PROP_RINGS * PROP_SEGS * 2 };
typedef struct prop {
    ak_vec3 pos[PROP_VERTS], nrm[PROP_VERTS];
    uint32_t idx[PROP_TRIS * 3];
} prop;

static void prop_build(prop* p, ak_vec3 a, ak_vec3 b, float r) {
    ak_vec3 axis = ak_vec3_sub(b, a);
    ak_vec3 z = ak_vec3_length(axis) > 1e-6f ? ak_vec3_normalize(axis) : ak_vec3_make(0, 1, 0);
    ak_vec3 x = ak_vec3_normalize(ak_vec3_cross(fabsf(z.y) < 0.9f ? ak_vec3_make(0, 1, 0) : ak_vec3_make(1, 0, 0), z));
    ak_vec3 y = ak_vec3_cross(z, x);
    for (int i = 0; i <= PROP_RINGS; ++i) {
        const float th = AK_PI * (float)i / PROP_RINGS;
        for (int k = 0; k < PROP_SEGS; ++k) {
            const float ph = 2.0f * AK_PI * (float)k / PROP_SEGS;
            ak_vec3 u = ak_vec3_add(ak_vec3_scale(z, cosf(th)),
                                    ak_vec3_add(ak_vec3_scale(x, sinf(th) * cosf(ph)), ak_vec3_scale(y, sinf(th) * sinf(ph))));
            p->nrm[i * PROP_SEGS + k] = u;
            p->pos[i * PROP_SEGS + k] = ak_vec3_madd(cosf(th) >= 0.0f ? b : a, u, r);
        }
    }
    int t = 0;
    for (int i = 0; i < PROP_RINGS; ++i)
        for (int k = 0; k < PROP_SEGS; ++k) {
            const uint32_t q0 = (uint32_t)(i * PROP_SEGS + k), q1 = (uint32_t)(i * PROP_SEGS + (k + 1) % PROP_SEGS);
            const uint32_t q2 = q0 + PROP_SEGS, q3 = q1 + PROP_SEGS;
            uint32_t* o = p->idx + 6 * t++;
            o[0] = q0, o[1] = q2, o[2] = q1, o[3] = q1, o[4] = q2, o[5] = q3;
        }
}

/* ---- the command -------------------------------------------------------------------------- */

static char* read_file(const char* path, size_t* out_size) {
    FILE* f = fopen(path, "rb");
    if (!f) return NULL;
    char* buf = malloc(CLI_JSON_MAX_SIZE + 1);
    size_t n = buf ? fread(buf, 1, CLI_JSON_MAX_SIZE + 1, f) : 0;
    fclose(f);
    if (!buf || n > CLI_JSON_MAX_SIZE) {
        free(buf);
        return NULL;
    }
    *out_size = n;
    return buf;
}

int cmd_cloth(int argc, char** argv) {
    static const cli_opt opts[] = {{"--preset", NULL, true}, {"--solver", NULL, true},   {"--steps", NULL, true},
                                   {"--dt", NULL, true},     {"--substeps", NULL, true}, {"--threads", NULL, true},
                                   {"--json", NULL, true},   {"--output", "-o", true}};
    cli_args a;
    int rc = cli_parse("cloth", argc, argv, opts, sizeof opts / sizeof opts[0], &a);
    if (rc) return rc;
    if (a.help) {
        fputs(usage, stdout);
        return CLI_OK;
    }
    const char* preset = CLI_GET(&a, "--preset");
    if (a.pos_count > 1) return cli_usage("cloth", "expected at most one SCENE.json");
    if ((a.pos_count == 1) == (preset != NULL)) return cli_usage("cloth", "give either SCENE.json or --preset NAME");
    const char* out = CLI_GET(&a, "--output");
    const char* json = CLI_GET(&a, "--json");
    if (out && !cli_has_ext(out, ".gif") && !cli_has_ext(out, ".png") && !cli_has_ext(out, ".obj"))
        return cli_usage("cloth", "output '%s' must end in .gif, .png or .obj", out);
    cloth_scene sc;
    const char* name = preset ? preset : a.pos[0];
    if (preset) {
        if (!cloth_scene_preset(preset, &sc)) {
            cloth_scene_free(&sc);
            return cli_usage("cloth", "unknown preset '%s' (flag, curtain, drape, cape)", preset);
        }
    } else {
        size_t size = 0;
        char* text = read_file(a.pos[0], &size);
        if (!text) return cli_fail("cloth", "%s: cannot read the file (missing, unreadable or over %zu bytes)", a.pos[0],
                                   CLI_JSON_MAX_SIZE);
        char msg[600];
        bool ok = cloth_scene_parse(a.pos[0], text, size, &sc, msg, sizeof msg);
        free(text);
        if (!ok) return cli_fail("cloth", "%s", msg);
    }
    /* command-line overrides */
    const char* v;
    long lv;
    if ((v = CLI_GET(&a, "--solver"))) {
        if (strcmp(v, "xpbd") == 0) sc.desc.solver = AK_CLOTH_XPBD;
        else if (strcmp(v, "springs") == 0) sc.desc.solver = AK_CLOTH_SPRINGS;
        else rc = cli_usage("cloth", "--solver must be springs or xpbd, not '%s'", v);
        if (sc.desc.solver == AK_CLOTH_SPRINGS &&
            (sc.desc.bending == AK_CLOTH_BEND_DIHEDRAL || sc.desc.bending == AK_CLOTH_BEND_ISOMETRIC))
            sc.desc.bending = AK_CLOTH_BEND_SPRINGS;
    }
    if (!rc && (v = CLI_GET(&a, "--steps"))) {
        if (!cli_parse_int(v, 0, CLOTH_SCENE_MAX_STEPS, &lv)) rc = cli_usage("cloth", "--steps must be 0..%ld", CLOTH_SCENE_MAX_STEPS);
        else sc.steps = lv;
    }
    if (!rc && (v = CLI_GET(&a, "--dt"))) {
        float dt;
        if (!cli_parse_float(v, &dt) || !(dt > 0.0f) || dt > 1.0f) rc = cli_usage("cloth", "--dt must be in (0, 1] seconds");
        else sc.dt = dt;
    }
    if (!rc && (v = CLI_GET(&a, "--substeps"))) {
        if (!cli_parse_int(v, 1, 10000, &lv)) rc = cli_usage("cloth", "--substeps must be 1..10000");
        else sc.substeps = (uint32_t)lv;
    }
    if (!rc && (v = CLI_GET(&a, "--threads"))) {
        if (!cli_parse_int(v, 1, 64, &lv)) rc = cli_usage("cloth", "--threads must be 1..64");
        else sc.thread_count = (int)lv;
    }
    if (rc) {
        cloth_scene_free(&sc);
        return rc;
    }

    character ch;
    memset(&ch, 0, sizeof ch);
    ak_cloth* cloth = NULL;
    ak_vec3 *x = NULL, *vel = NULL, *nrm = NULL, *targets = NULL;
    uint8_t* scratch = NULL;
    uint32_t* attach_idx = NULL;
    ak_cloth_capsule* caps = NULL;
    cli_frame frame;
    memset(&frame, 0, sizeof frame);
    ak_image img = {0};
    ak_gif_writer* gw = NULL;

    /* the cloth */
    if (sc.attach_count) {
        attach_idx = calloc(sc.attach_count, sizeof(uint32_t));
        if (!attach_idx) {
            rc = cli_fail("cloth", "out of memory");
            goto done;
        }
        for (size_t k = 0; k < sc.attach_count; ++k) attach_idx[k] = sc.attach[k].vertex;
        sc.desc.attachments = (ak_u32_cspan){attach_idx, sc.attach_count};
    }
    ak_result r = ak_cloth_create(&sc.desc, NULL, &cloth);
    if (r != AK_OK) {
        rc = cli_fail("cloth", "%s: the cloth cannot be built: %s", name, ak_result_string(r));
        goto done;
    }
    const size_t n = ak_cloth_vertex_count(cloth);
    x = malloc(n * sizeof(ak_vec3));
    vel = calloc(n, sizeof(ak_vec3));
    nrm = malloc(n * sizeof(ak_vec3));
    targets = calloc(sc.attach_count + 1, sizeof(ak_vec3));
    if (!x || !vel || !nrm || !targets) {
        rc = cli_fail("cloth", "out of memory");
        goto done;
    }
    ak_cloth_rest_positions(cloth, (ak_vec3_span){x, n});

    /* the character */
    if (sc.model[0]) {
        if ((rc = cli_load_scene("cloth", sc.model, &ch.scene))) goto done;
        if (cli_poser_init(&ch.poser, ch.scene)) {
            ak_scene_destroy(ch.scene);
            ch.scene = NULL;
            rc = cli_fail("cloth", "out of memory");
            goto done;
        }
        ch.clip = ch.scene->clip_count ? ak_scene_find_clip(ch.scene, sc.clip[0] ? sc.clip : NULL) : -1;
        if (sc.clip[0] && ch.clip < 0) {
            rc = cli_fail("cloth", "%s: character.clip: no clip '%s' in %s", name, sc.clip, sc.model);
            goto done;
        }
        ch.duration = ch.clip >= 0 ? ak_clip_duration(ch.scene->clips[ch.clip]) : 0.0f;
        for (size_t m = 0; m < ch.scene->mesh_count; ++m)
            if (ch.scene->meshes[m].mesh) {
                ch.mesh_vertices += ch.scene->meshes[m].mesh->vertex_count;
                ch.mesh_tris += ch.scene->meshes[m].mesh->triangle_count;
            }
        ch.mesh_pos = calloc(ch.mesh_vertices + 1, sizeof(ak_vec3));
        ch.mesh_idx = calloc(ch.mesh_tris * 3 + 1, sizeof(uint32_t));
        ch.attach_joint = calloc(sc.attach_count + 1, sizeof(int));
        ch.attach_offset = calloc(sc.attach_count + 1, sizeof(ak_vec3));
        if (!ch.mesh_pos || !ch.mesh_idx || !ch.attach_joint || !ch.attach_offset) {
            rc = cli_fail("cloth", "out of memory");
            goto done;
        }
        for (size_t m = 0, vo = 0, to = 0; m < ch.scene->mesh_count; ++m) {
            const ak_mesh* mesh = ch.scene->meshes[m].mesh;
            if (!mesh) continue;
            for (size_t k = 0; k < mesh->triangle_count * 3; ++k) ch.mesh_idx[to + k] = mesh->indices[k] + (uint32_t)vo;
            vo += mesh->vertex_count;
            to += mesh->triangle_count * 3;
        }
        if (sc.limb_capsules && character_bones(&ch, sc.capsule_scale)) {
            rc = cli_fail("cloth", "out of memory");
            goto done;
        }
        if ((r = character_pose(&ch, 0.0f)) != AK_OK) {
            rc = cli_fail("cloth", "%s: cannot pose %s: %s", name, sc.model, ak_result_string(r));
            goto done;
        }
        /* attachments keep their offset from the joint or skinned vertex at t = 0 */
        for (size_t k = 0; k < sc.attach_count; ++k) {
            const cloth_attach_spec* at = &sc.attach[k];
            const ak_vec3 p = x[at->vertex];
            char path[40];
            snprintf(path, sizeof path, "attachments[%zu]", k);
            if (at->joint[0]) {
                const int j = ch.scene->skeleton ? ak_skeleton_find_joint(ch.scene->skeleton, at->joint) : -1;
                if (j < 0) {
                    rc = cli_fail("cloth", "%s: %s.joint: no joint '%s' in %s", name, path, at->joint, sc.model);
                    goto done;
                }
                ch.attach_joint[k] = j;
                ch.attach_offset[k] = ak_mat4_transform_point(ak_mat4_inverse(ch.poser.world[j]), p);
            } else {
                if ((size_t)at->mesh_vertex >= ch.mesh_vertices) {
                    rc = cli_fail("cloth", "%s: %s.mesh_vertex: %ld is out of range (%s has %zu vertices)", name, path,
                                  at->mesh_vertex, sc.model, ch.mesh_vertices);
                    goto done;
                }
                ch.attach_joint[k] = -1;
                ch.attach_offset[k] = ak_vec3_sub(p, ch.mesh_pos[at->mesh_vertex]);
            }
        }
    }
    caps = calloc(sc.capsule_count + ch.bone_count + 1, sizeof(ak_cloth_capsule));
    if (!caps) {
        rc = cli_fail("cloth", "out of memory");
        goto done;
    }
    if (sc.capsule_count) memcpy(caps, sc.capsules, sc.capsule_count * sizeof(ak_cloth_capsule));

    ak_cloth_step_job job = {
        .cloth = cloth, .dt = sc.dt, .substeps = sc.substeps, .iterations = sc.iterations, .gravity = sc.gravity,
        .drag = sc.drag, .lift = sc.lift, .air_density = sc.air_density, .damping = sc.damping,
        .planes = sc.planes, .plane_count = sc.plane_count, .spheres = sc.spheres, .sphere_count = sc.sphere_count,
        .capsules = caps, .capsule_count = sc.capsule_count + ch.bone_count,
        .thickness = sc.thickness, .friction = sc.friction, .self_collision = sc.self_collision,
        .self_distance = sc.self_distance,
        .attachment_targets = {targets, sc.attach_count}, .thread_count = (uint32_t)sc.thread_count,
        .positions = {x, n}, .velocities = {vel, n}, .out_normals = {nrm, n},
    };
    if (ch.scene && sc.mesh_collider && ch.mesh_tris)
        job.mesh = (ak_cloth_collider_mesh){{ch.mesh_pos, ch.mesh_vertices}, {ch.mesh_idx, ch.mesh_tris * 3}};
    const size_t scratch_size = ak_cloth_step_scratch_size(&job);
    scratch = malloc(scratch_size);
    if (!scratch) {
        rc = cli_fail("cloth", "out of memory");
        goto done;
    }
    job.scratch = (ak_u8_span){scratch, scratch_size};
    ak_cloth_normals(cloth, (ak_vec3_cspan){x, n}, (ak_vec3_span){nrm, n});

    /* rendering: a camera framed on the cloth, the colliders and the character at rest */
    const bool gif = out && cli_has_ext(out, ".gif"), png = out && cli_has_ext(out, ".png");
    prop* props = NULL;
    size_t prop_count = 0;
    if (gif || png) {
        ak_vec3 lo, hi;
        ak_points_bounds((ak_vec3_cspan){x, n}, &lo, &hi);
        for (size_t k = 0; k < sc.sphere_count; ++k) {
            const ak_vec3 rr = ak_vec3_splat(sc.spheres[k].radius);
            lo = ak_vec3_min(lo, ak_vec3_sub(sc.spheres[k].center, rr));
            hi = ak_vec3_max(hi, ak_vec3_add(sc.spheres[k].center, rr));
        }
        for (size_t k = 0; k < sc.plane_count; ++k)
            if (fabsf(ak_vec3_normalize(sc.planes[k].normal).y) > 0.99f) lo.y = ak_minf(lo.y, sc.planes[k].offset);
        if (ch.scene) cli_bounds_add_pose(&ch.poser, &lo, &hi);
        if (sc.wind.x != 0.0f || sc.wind.z != 0.0f) { /* a flag streams downwind: room for it */
            const ak_vec3 w = ak_vec3_normalize(ak_vec3_make(sc.wind.x, 0, sc.wind.z));
            const float span = ak_vec3_length(ak_vec3_sub(hi, lo));
            hi = ak_vec3_max(hi, ak_vec3_madd(hi, w, 0.3f * span));
            lo = ak_vec3_min(lo, ak_vec3_madd(lo, w, 0.3f * span));
        }
        /* a character faces +Z: look from behind, where a cape hangs */
        if (cli_frame_init(&frame, ch.scene, 480, 360, lo, hi, ch.scene ? 3.6f : 0.6f) || cli_image_alloc(&img, 480, 360)) {
            rc = cli_fail("cloth", "out of memory");
            goto done;
        }
        prop_count = sc.sphere_count + sc.capsule_count;
        if (prop_count > CLI_MAX_EXTRA - 1) prop_count = CLI_MAX_EXTRA - 1;
        props = calloc(prop_count + 1, sizeof(prop));
        if (!props) {
            rc = cli_fail("cloth", "out of memory");
            goto done;
        }
        for (size_t k = 0; k < prop_count; ++k) {
            if (k < sc.sphere_count) prop_build(&props[k], sc.spheres[k].center, sc.spheres[k].center, sc.spheres[k].radius);
            else {
                const ak_cloth_capsule* cp = &sc.capsules[k - sc.sphere_count];
                prop_build(&props[k], cp->a, cp->b, cp->radius);
            }
        }
        if (gif && ak_gif_writer_create(out, &(ak_gif_desc){.width = 480, .height = 360, .delay_cs = 4}, NULL, &gw) != AK_OK) {
            free(props);
            rc = cli_fail("cloth", "%s: cannot create the file", out);
            goto done;
        }
    }

    const double t0 = cli_now();
    int frames = 0;
    float time = 0.0f;
    for (long step = 0; step <= sc.steps; ++step) {
        /* draw the state at `time` (25 frames per second of simulated time) */
        if ((gif && (step == 0 || floorf(time * 25.0f) != floorf((time - sc.dt) * 25.0f))) || (png && step == sc.steps)) {
            ak_raster_mesh extra[CLI_MAX_EXTRA];
            size_t ne = 0;
            ak_u32_cspan idx = ak_cloth_indices(cloth);
            extra[ne++] = (ak_raster_mesh){.positions = {x, n}, .normals = {nrm, n}, .indices = idx,
                                           .material = {.color = {0.72f, 0.16f, 0.18f, 1}, .specular = 0.1f}};
            for (size_t k = 0; k < prop_count; ++k)
                extra[ne++] = (ak_raster_mesh){.positions = {props[k].pos, PROP_VERTS}, .normals = {props[k].nrm, PROP_VERTS},
                                               .indices = {props[k].idx, PROP_TRIS * 3},
                                               .material = {.color = {0.55f, 0.62f, 0.72f, 1}}};
            char title[160];
            snprintf(title, sizeof title, "cloth %s  %s  t=%.2fs", preset ? preset : "", sc.desc.solver == AK_CLOTH_SPRINGS ? "springs" : sc.desc.solver == AK_CLOTH_PBD ? "pbd" : "xpbd", (double)time);
            cli_draw_opts o = {.title = title, .extra = extra, .extra_count = ne};
            r = cli_frame_draw(&frame, ch.scene ? &ch.poser : NULL, &o, &img);
            if (r == AK_OK) r = gif ? ak_gif_writer_add_frame(gw, &img) : ak_png_write(out, &img);
            if (r != AK_OK) {
                free(props);
                rc = cli_fail("cloth", "%s: cannot render or write: %s", out, ak_result_string(r));
                goto done;
            }
            ++frames;
        }
        if (step == sc.steps) break;
        /* the character and the attachment targets at the end of this step */
        const float t_end = (float)(step + 1) * sc.dt;
        if (ch.scene) {
            if ((r = character_pose(&ch, t_end)) != AK_OK) {
                free(props);
                rc = cli_fail("cloth", "%s: cannot pose %s at t=%g: %s", name, sc.model, (double)t_end, ak_result_string(r));
                goto done;
            }
            for (size_t k = 0; k < sc.attach_count; ++k)
                targets[k] = ch.attach_joint[k] >= 0
                                 ? ak_mat4_transform_point(ch.poser.world[ch.attach_joint[k]], ch.attach_offset[k])
                                 : ak_vec3_add(ch.mesh_pos[sc.attach[k].mesh_vertex], ch.attach_offset[k]);
            for (size_t k = 0; k < ch.bone_count; ++k)
                caps[sc.capsule_count + k] = (ak_cloth_capsule){ak_mat4_get_translation(ch.poser.world[ch.bone_parent[k]]),
                                                                ak_mat4_get_translation(ch.poser.world[ch.bone_child[k]]),
                                                                ch.bone_radius[k]};
        }
        const float gust = 1.0f + sc.gust * sinf(2.0f * AK_PI * sc.gust_frequency * time);
        job.wind = ak_vec3_scale(sc.wind, gust);
        r = ak_cloth_step_run(&job);
        if (r == AK_ERR_NO_CONVERGENCE) {
            free(props);
            rc = cli_fail("cloth", "%s: blow-up: the state became non-finite at step %ld (t = %.4g s); try a smaller --dt "
                                   "or more --substeps", name, step + 1, (double)t_end);
            goto done;
        }
        if (r != AK_OK) {
            free(props);
            rc = cli_fail("cloth", "%s: step %ld: %s", name, step + 1, ak_result_string(r));
            goto done;
        }
        time = t_end;
        cli_progress("cloth", (size_t)step + 1, (size_t)sc.steps);
    }
    const double elapsed = cli_now() - t0;
    free(props);
    if (gw) {
        r = ak_gif_writer_finish(gw);
        gw = NULL;
        if (r != AK_OK) {
            rc = cli_fail("cloth", "%s: cannot write: %s", out, ak_result_string(r));
            goto done;
        }
    }
    const float stretch = ak_cloth_max_stretch(cloth, (ak_vec3_cspan){x, n});
    ak_cloth_energy e;
    ak_cloth_energy_compute(cloth, (ak_vec3_cspan){x, n}, (ak_vec3_cspan){vel, n}, sc.gravity, &e);
    if (json && (rc = write_json(json, time, x, n, stretch, e.total))) goto done;
    if (out && cli_has_ext(out, ".obj") && (rc = write_obj(out, cloth, x, nrm))) goto done;
    printf("cloth %s: %s, %zu particles, %ld steps of %.4g s (%u substeps): t = %.3g s, max stretch %.4f, energy %.6g J"
           " (kinetic %.3g)\n",
           name, sc.desc.solver == AK_CLOTH_SPRINGS ? "mass-spring" : sc.desc.solver == AK_CLOTH_PBD ? "PBD" : "XPBD", n,
           sc.steps, (double)sc.dt, sc.substeps, (double)time, (double)stretch, e.total, e.kinetic);
    if (gif) fprintf(stderr, "wrote %s: %d frames\n", out, frames);
    else if (out) fprintf(stderr, "wrote %s\n", out);
    if (sc.steps > 0) fprintf(stderr, "%.3f ms per step (including rendering)\n", 1e3 * elapsed / (double)sc.steps);

done:
    if (gw) ak_gif_writer_finish(gw);
    free(img.pixels);
    cli_frame_free(&frame);
    character_free(&ch);
    free(x), free(vel), free(nrm), free(targets), free(scratch), free(attach_idx), free(caps);
    ak_cloth_destroy(cloth);
    cloth_scene_free(&sc);
    return rc;
}
