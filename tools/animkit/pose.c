/* The posing pipeline shared by the commands: sample a clip into the local pose, forward
 * kinematics, morph targets, then skinning, exactly as glTF 2.0 defines it (see scene.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

bool cli_method_parse(const char* s, cli_method* out) {
    if (!s) return false;
    if (strcmp(s, "lbs") == 0) *out = CLI_LBS;
    else if (strcmp(s, "dqs") == 0) *out = CLI_DQS;
    else if (strcmp(s, "cor") == 0) *out = CLI_COR;
    else if (strcmp(s, "implicit") == 0) *out = CLI_IMPLICIT;
    else if (strcmp(s, "soft") == 0) *out = CLI_SOFT;
    else return false;
    return true;
}

const char* cli_method_name(cli_method m) {
    switch (m) {
    case CLI_DQS: return "DQS";
    case CLI_COR: return "CoR";
    case CLI_IMPLICIT: return "implicit";
    case CLI_SOFT: return "soft";
    default: return "LBS";
    }
}

static size_t total_morph_targets(const ak_scene* s) {
    size_t n = 0;
    for (size_t m = 0; m < s->mesh_count; ++m)
        if (s->meshes[m].mesh) n += s->meshes[m].mesh->morph_target_count;
    return n;
}

int cli_poser_init(cli_poser* p, const ak_scene* scene) {
    memset(p, 0, sizeof(*p));
    p->scene = scene;
    p->joint_count = ak_scene_joint_count(scene);
    size_t jc = p->joint_count ? p->joint_count : 1;
    size_t max_skin = 1, max_vertices = 1;
    for (size_t k = 0; k < scene->skin_count; ++k)
        if (scene->skins[k].joint_count > max_skin) max_skin = scene->skins[k].joint_count;
    for (size_t m = 0; m < scene->mesh_count; ++m)
        if (scene->meshes[m].mesh && scene->meshes[m].mesh->vertex_count > max_vertices)
            max_vertices = scene->meshes[m].mesh->vertex_count;
    size_t morphs = total_morph_targets(scene);
    p->local = calloc(jc, sizeof(ak_transform));
    p->world = calloc(jc, sizeof(ak_mat4));
    p->palette = calloc(max_skin, sizeof(ak_mat4));
    p->morph_weights = calloc(morphs ? morphs : 1, sizeof(float));
    p->morphed = calloc(max_vertices, sizeof(ak_vec3));
    p->morphed_normals = calloc(max_vertices, sizeof(ak_vec3));
    size_t mc = scene->mesh_count ? scene->mesh_count : 1;
    p->positions = calloc(mc, sizeof(ak_vec3*));
    p->normals = calloc(mc, sizeof(ak_vec3*));
    p->cor_centers = calloc(mc, sizeof(ak_vec3*));
    p->implicit = calloc(mc, sizeof(ak_skin_implicit*));
    /* DQS/CoR scratch depends only on the method and palette size: size it once for the
     * largest skin and the method that needs most (CoR) */
    ak_skin_job probe = {.method = AK_SKIN_COR, .palette = {p->palette, max_skin}};
    p->skin_scratch_size = ak_skin_job_scratch_size(&probe);
    p->skin_scratch = malloc(p->skin_scratch_size);
    bool ok = p->local && p->world && p->palette && p->morph_weights && p->morphed && p->morphed_normals &&
              p->positions && p->normals && p->cor_centers && p->implicit && p->skin_scratch;
    for (size_t m = 0; ok && m < scene->mesh_count; ++m) {
        size_t n = scene->meshes[m].mesh ? scene->meshes[m].mesh->vertex_count : 1;
        p->positions[m] = calloc(n, sizeof(ak_vec3));
        p->normals[m] = calloc(n, sizeof(ak_vec3));
        ok = p->positions[m] && p->normals[m];
    }
    if (!ok) {
        cli_poser_free(p);
        return CLI_BAD_INPUT;
    }
    return CLI_OK;
}

void cli_poser_free(cli_poser* p) {
    if (p->scene) {
        for (size_t m = 0; m < p->scene->mesh_count; ++m) {
            if (p->positions) free(p->positions[m]);
            if (p->normals) free(p->normals[m]);
            if (p->cor_centers) free(p->cor_centers[m]);
            if (p->implicit) ak_skin_implicit_destroy(p->implicit[m]);
        }
    }
    free(p->positions);
    free(p->normals);
    free(p->cor_centers);
    free(p->implicit);
    free(p->implicit_scratch);
    free(p->local);
    free(p->world);
    free(p->palette);
    free(p->morph_weights);
    free(p->morphed);
    free(p->morphed_normals);
    free(p->skin_scratch);
    free(p->weld_scratch);
    if (p->soft && p->scene)
        for (size_t m = 0; m < p->scene->mesh_count; ++m) {
            ak_skin_soft_destroy(p->soft[m].soft);
            free(p->soft[m].x);
            free(p->soft[m].v);
            free(p->soft[m].scratch);
            free(p->soft[m].previous);
        }
    free(p->soft);
    memset(p, 0, sizeof(*p));
}

size_t cli_skin_bones(const ak_scene* s, const ak_scene_skin* skin, ak_skin_bone* out) {
    size_t n = skin->joint_count, count = 0;
    ak_i32_cspan parents = ak_skeleton_parents(s->skeleton);
    ak_vec3* pos = calloc(n, sizeof(ak_vec3));
    int* parent_slot = calloc(n, sizeof(int));
    bool* has_child = calloc(n, sizeof(bool));
    if (!pos || !parent_slot || !has_child) goto done;
    for (size_t k = 0; k < n; ++k) pos[k] = ak_mat4_get_translation(ak_mat4_inverse_affine(skin->inverse_binds[k]));
    for (size_t k = 0; k < n; ++k) {
        parent_slot[k] = -1;
        for (int j = parents.ptr[skin->joints[k]]; j >= 0 && parent_slot[k] < 0; j = parents.ptr[j])
            for (size_t q = 0; q < n; ++q)
                if (skin->joints[q] == j) parent_slot[k] = (int)q;
    }
    for (size_t k = 0; k < n; ++k) {
        if (parent_slot[k] < 0) continue;
        size_t ps = (size_t)parent_slot[k];
        has_child[ps] = true;
        out[count++] = (ak_skin_bone){pos[ps], pos[k], (uint16_t)ps};
    }
    for (size_t k = 0; k < n; ++k)
        if (!has_child[k]) out[count++] = (ak_skin_bone){pos[k], pos[k], (uint16_t)k};
done:
    free(pos);
    free(parent_slot);
    free(has_child);
    return count;
}

void cli_poser_soft_reset(cli_poser* p) {
    if (p->soft && p->scene)
        for (size_t m = 0; m < p->scene->mesh_count; ++m) p->soft[m].started = false;
}

/* Build mesh m's soft body on first use; false when it cannot be built (then DQS). */
static ak_result soft_build(cli_poser* p, size_t m, size_t palette_count) {
    if (!p->soft && !(p->soft = calloc(p->scene->mesh_count, sizeof(cli_soft_mesh)))) return AK_ERR_NO_MEMORY;
    cli_soft_mesh* sm = &p->soft[m];
    if (sm->soft || sm->failed) return AK_OK;
    const ak_scene_mesh* scm = &p->scene->meshes[m];
    const ak_mesh* mesh = scm->mesh;
    const ak_scene_skin* skin = &p->scene->skins[scm->skin];
    ak_skin_bone* bones = calloc(2 * skin->joint_count + 1, sizeof(ak_skin_bone));
    if (!bones) return AK_ERR_NO_MEMORY;
    size_t bone_count = cli_skin_bones(p->scene, skin, bones);
    size_t wn = mesh->vertex_count * mesh->influence_count;
    ak_skin_soft_desc d = {.positions = {mesh->positions, mesh->vertex_count},
                           .indices = {mesh->indices, 3 * mesh->triangle_count},
                           .joints = {mesh->joints, wn},
                           .weights = {mesh->weights, wn},
                           .influence_count = mesh->influence_count,
                           .bones = {bones, bone_count},
                           .resolution = p->soft_resolution};
    ak_result r = ak_skin_soft_create(&d, NULL, &sm->soft);
    free(bones);
    if (r == AK_ERR_NO_MEMORY) return r;
    if (r != AK_OK) {
        sm->failed = true;
        return AK_OK;
    }
    size_t nn = ak_skin_soft_node_count(sm->soft);
    sm->x = malloc(nn * sizeof(ak_vec3));
    sm->v = malloc(nn * sizeof(ak_vec3));
    sm->scratch = malloc(ak_skin_soft_step_scratch_size(sm->soft));
    sm->previous = malloc(palette_count * sizeof(ak_mat4));
    if (!sm->x || !sm->v || !sm->scratch || !sm->previous) return AK_ERR_NO_MEMORY;
    return AK_OK;
}

/* Advance mesh m's soft body to the palette in p->palette and write its surface. */
static ak_result soft_deform(cli_poser* p, size_t m, size_t palette_count) {
    cli_soft_mesh* sm = &p->soft[m];
    const ak_mesh* mesh = p->scene->meshes[m].mesh;
    size_t nn = ak_skin_soft_node_count(sm->soft);
    ak_mat4_cspan pal = {p->palette, palette_count};
    ak_result r = AK_OK;
    float dt = p->sample_time - p->soft_time;
    if (!sm->started || dt < 0.0f || dt > 0.5f) {
        if ((r = ak_skin_soft_state_init(sm->soft, pal, (ak_vec3_span){sm->x, nn}, (ak_vec3_span){sm->v, nn})) != AK_OK) return r;
        memcpy(sm->previous, p->palette, palette_count * sizeof(ak_mat4));
        sm->started = true;
        dt = 0.0f;
    }
    int steps = dt > 0.0f ? (int)ceilf(dt * 60.0f - 1e-3f) : 0;
    for (int k = 0; k < steps; ++k) {
        ak_skin_soft_step_job job = {.soft = sm->soft,
                                     .palette = pal,
                                     .previous_palette = {sm->previous, palette_count},
                                     .dt = dt / (float)steps,
                                     .node_positions = {sm->x, nn},
                                     .node_velocities = {sm->v, nn},
                                     .scratch = {sm->scratch, ak_skin_soft_step_scratch_size(sm->soft)}};
        if ((r = ak_skin_soft_step_run(&job)) != AK_OK) return r;
        memcpy(sm->previous, p->palette, palette_count * sizeof(ak_mat4));
    }
    if ((r = ak_skin_soft_surface(sm->soft, (ak_vec3_cspan){sm->x, nn}, (ak_vec3_span){p->positions[m], mesh->vertex_count})) != AK_OK)
        return r;
    return ak_normals_compute((ak_vec3_cspan){p->positions[m], mesh->vertex_count},
                              (ak_u32_cspan){mesh->indices, 3 * mesh->triangle_count},
                              (ak_vec3_span){p->normals[m], mesh->vertex_count});
}

/* Centers of rotation for mesh m, computed on first use. */
static ak_result cor_centers(cli_poser* p, size_t m) {
    if (p->cor_centers[m]) return AK_OK;
    const ak_mesh* mesh = p->scene->meshes[m].mesh;
    ak_vec3* c = calloc(mesh->vertex_count, sizeof(ak_vec3));
    if (!c) return AK_ERR_NO_MEMORY;
    size_t wn = mesh->vertex_count * mesh->influence_count;
    ak_skin_cor_desc d = {
        .positions = {mesh->positions, mesh->vertex_count},
        .indices = {mesh->indices, mesh->triangle_count * 3},
        .joints = {mesh->joints, wn},
        .weights = {mesh->weights, wn},
        .influence_count = mesh->influence_count,
    };
    ak_result r = ak_skin_cor_centers_compute(&d, NULL, (ak_vec3_span){c, mesh->vertex_count});
    if (r != AK_OK) {
        free(c);
        return r;
    }
    p->cor_centers[m] = c;
    return AK_OK;
}

/* Implicit skinning of mesh m with the palette in p->palette: the precompute on first use,
 * then one run into p->positions[m] / p->normals[m]. */
static ak_result implicit_deform(cli_poser* p, size_t m, size_t joint_count) {
    const ak_mesh* mesh = p->scene->meshes[m].mesh;
    if (!p->implicit[m]) {
        size_t wn = mesh->vertex_count * mesh->influence_count;
        ak_skin_implicit_desc d = {
            .positions = {mesh->positions, mesh->vertex_count},
            .indices = {mesh->indices, mesh->triangle_count * 3},
            .joints = {mesh->joints, wn},
            .weights = {mesh->weights, wn},
            .influence_count = mesh->influence_count,
            .joint_count = joint_count,
        };
        ak_result r = ak_skin_implicit_create(&d, NULL, &p->implicit[m]);
        if (r != AK_OK) return r;
    }
    size_t need = ak_skin_implicit_scratch_size(p->implicit[m], joint_count);
    if (need > p->implicit_scratch_size) {
        uint8_t* grown = realloc(p->implicit_scratch, need);
        if (!grown) return AK_ERR_NO_MEMORY;
        p->implicit_scratch = grown;
        p->implicit_scratch_size = need;
    }
    ak_skin_implicit_job job = {
        .implicit = p->implicit[m],
        .palette = {p->palette, joint_count},
        .thread_count = 2,
        .scratch = {p->implicit_scratch, p->implicit_scratch_size},
        .normals = {mesh->normals, mesh->normals ? mesh->vertex_count : 0},
        .out_positions = {p->positions[m], mesh->vertex_count},
        .out_normals = {p->normals[m], mesh->vertex_count},
    };
    return ak_skin_implicit_run(&job);
}

static void transform_rigid(const ak_mesh* mesh, ak_mat4 m, const ak_vec3* pos, const ak_vec3* nrm, ak_vec3* out_p,
                            ak_vec3* out_n) {
    ak_mat3 nm = ak_mat4_normal_matrix(m);
    for (size_t v = 0; v < mesh->vertex_count; ++v) {
        out_p[v] = ak_mat4_transform_point(m, pos[v]);
        if (nrm) out_n[v] = ak_vec3_normalize(ak_mat3_mul_vec3(nm, nrm[v]));
    }
}

/* Normals of mesh m from its posed positions: per vertex, or shared by the vertices at one
 * position when p->weld_normals is set. */
static ak_result computed_normals(cli_poser* p, size_t m) {
    const ak_mesh* mesh = p->scene->meshes[m].mesh;
    size_t n = mesh->vertex_count;
    ak_vec3_cspan pos = {p->positions[m], n};
    ak_u32_cspan idx = {mesh->indices, mesh->triangle_count * 3};
    ak_vec3_span out = {p->normals[m], n};
    if (!p->weld_normals) return ak_normals_compute(pos, idx, out);
    size_t need = ak_normals_welded_scratch_count(n);
    if (need == SIZE_MAX) return AK_ERR_NO_MEMORY;
    if (need > p->weld_scratch_count) {
        uint32_t* grown = realloc(p->weld_scratch, need * sizeof(uint32_t));
        if (!grown) return AK_ERR_NO_MEMORY;
        p->weld_scratch = grown;
        p->weld_scratch_count = need;
    }
    return ak_normals_compute_welded(pos, idx, (ak_u32_span){p->weld_scratch, p->weld_scratch_count}, out);
}

ak_result cli_poser_sample(cli_poser* p, int clip, float t, bool bind) {
    const ak_scene* s = p->scene;
    ak_result r = AK_OK;
    size_t morphs = total_morph_targets(s);
    /* default morph weights (glTF mesh.weights), in the scene's flat morph index space */
    for (size_t m = 0, off = 0; m < s->mesh_count; ++m) {
        const ak_mesh* mesh = s->meshes[m].mesh;
        if (!mesh) continue;
        for (size_t k = 0; k < mesh->morph_target_count; ++k)
            p->morph_weights[off + k] = mesh->morph_weights ? mesh->morph_weights[k] : 0.0f;
        off += mesh->morph_target_count;
    }
    p->sample_time = bind ? 0.0f : t;
    if (!p->joint_count) return AK_OK;
    ak_transform_span local = {p->local, p->joint_count};
    if ((r = ak_scene_rest_pose(s, local)) != AK_OK) return r;
    if (!bind && clip >= 0 && (size_t)clip < s->clip_count) {
        const ak_clip* c = s->clips[clip];
        ak_f32_span mw = {NULL, 0};
        if (ak_clip_morph_weight_count(c) > 0 && morphs >= ak_clip_morph_weight_count(c))
            mw = (ak_f32_span){p->morph_weights, morphs};
        ak_transform_span lp = ak_clip_joint_count(c) ? local : (ak_transform_span){NULL, 0};
        if ((r = ak_clip_sample(c, t, NULL, lp, mw, (ak_f32_span){NULL, 0})) != AK_OK) return r;
    }
    return AK_OK;
}

ak_result cli_poser_pose(cli_poser* p, int clip, float t, bool bind, cli_method method) {
    ak_result r = cli_poser_sample(p, clip, t, bind);
    return r != AK_OK ? r : cli_poser_deform(p, bind, method);
}

ak_result cli_poser_deform(cli_poser* p, bool bind, cli_method method) {
    const ak_scene* s = p->scene;
    ak_result r = AK_OK;
    if (p->joint_count &&
        (r = ak_scene_world_matrices(s, (ak_transform_cspan){p->local, p->joint_count},
                                     (ak_mat4_span){p->world, p->joint_count})) != AK_OK)
        return r;
    for (size_t m = 0, off = 0; m < s->mesh_count; ++m) {
        const ak_scene_mesh* sm = &s->meshes[m];
        const ak_mesh* mesh = sm->mesh;
        if (!mesh) continue;
        size_t n = mesh->vertex_count;
        const ak_vec3* pos = mesh->positions;
        const ak_vec3* nrm = mesh->normals;
        size_t morph_off = off;
        off += mesh->morph_target_count;
        if (bind) {
            memcpy(p->positions[m], pos, n * sizeof(ak_vec3));
            if (nrm) memcpy(p->normals[m], nrm, n * sizeof(ak_vec3));
            else if ((r = computed_normals(p, m)) != AK_OK) return r;
            continue;
        }
        if (mesh->morph_target_count > 0) {
            ak_blendshape_mesh_job mj = {
                .mesh = mesh,
                .weights = {p->morph_weights + morph_off, mesh->morph_target_count},
                .out_positions = {p->morphed, n},
                .out_normals = {nrm ? p->morphed_normals : NULL, nrm ? n : 0},
            };
            if ((r = ak_blendshape_mesh_run(&mj)) != AK_OK) return r;
            pos = p->morphed;
            if (nrm) nrm = p->morphed_normals;
        }
        bool skinned = sm->skin >= 0 && (size_t)sm->skin < s->skin_count && mesh->influence_count > 0 && p->joint_count;
        if (skinned) {
            const ak_scene_skin* skin = &s->skins[sm->skin];
            if ((r = ak_scene_skin_palette(s, (size_t)sm->skin, (ak_mat4_cspan){p->world, p->joint_count},
                                           (ak_mat4_span){p->palette, skin->joint_count})) != AK_OK)
                return r;
            if (method == CLI_IMPLICIT && mesh->triangle_count > 0 && mesh->morph_target_count == 0) {
                if ((r = implicit_deform(p, m, skin->joint_count)) != AK_OK) return r;
                continue;
            }
            if (method == CLI_SOFT && mesh->triangle_count > 0) {
                if ((r = soft_build(p, m, skin->joint_count)) != AK_OK) return r;
                if (!p->soft[m].failed) {
                    if ((r = soft_deform(p, m, skin->joint_count)) != AK_OK) return r;
                    continue;
                }
            }
            /* implicit on points or morphs, soft that could not build: DQS */
            ak_skin_method sm_method = method == CLI_DQS || method == CLI_IMPLICIT || method == CLI_SOFT ? AK_SKIN_DQS
                                       : method == CLI_COR                                             ? AK_SKIN_COR
                                                                                                       : AK_SKIN_LBS;
            if (sm_method == AK_SKIN_COR && mesh->triangle_count == 0) sm_method = AK_SKIN_DQS;
            if (sm_method == AK_SKIN_COR && (r = cor_centers(p, m)) != AK_OK) return r;
            bool faces = nrm == NULL && mesh->triangle_count > 0;
            ak_skin_job job = {
                .method = sm_method,
                .influence_count = mesh->influence_count,
                .palette = {p->palette, skin->joint_count},
                .positions = {pos, n, 0},
                .joints = {mesh->joints, n, mesh->influence_count * sizeof(uint16_t)},
                .weights = {mesh->weights, n, mesh->influence_count * sizeof(float)},
                .normals = {nrm, nrm ? n : 0, 0},
                .cor_centers = {p->cor_centers[m], p->cor_centers[m] ? n : 0, 0},
                .indices = {mesh->indices, mesh->triangle_count * 3},
                .normals_from_faces = faces,
                .out_positions = {p->positions[m], n, 0},
                .out_normals = {(nrm || faces) ? p->normals[m] : NULL, n, 0},
            };
            job.scratch = (ak_u8_span){p->skin_scratch, p->skin_scratch_size};
            if ((r = ak_skin_job_run(&job)) != AK_OK) return r;
            if (!nrm && !faces)
                for (size_t v = 0; v < n; ++v) p->normals[m][v] = ak_vec3_make(0, 1, 0);
        } else {
            ak_mat4 place = ak_mat4_identity();
            if (sm->node >= 0 && (size_t)sm->node < p->joint_count) place = p->world[sm->node];
            transform_rigid(mesh, place, pos, nrm, p->positions[m], p->normals[m]);
            if (!nrm && (r = computed_normals(p, m)) != AK_OK) return r;
        }
    }
    if (method == CLI_SOFT) p->soft_time = p->sample_time;
    return AK_OK;
}
