/* The cloth run shared by `animkit cloth` and `animkit view` (cloth_run.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cloth_run.h"

/* ---- the character: pose, attachments, colliders ------------------------------------------- */

void cloth_character_free(cloth_character* c) {
    if (c->scene) cli_poser_free(&c->poser);
    ak_scene_destroy(c->scene);
    free(c->attach_joint), free(c->attach_offset), free(c->mesh_pos), free(c->mesh_idx);
    free(c->bone_parent), free(c->bone_child), free(c->bone_radius), free(c->capsules);
    memset(c, 0, sizeof *c);
}

/* Pose at time t (looping the clip) and gather the posed meshes into one collider. */
static ak_result character_pose(cloth_character* c, float t) {
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
static int character_bones(cloth_character* c, float scale) {
    const ak_scene* s = c->scene;
    const size_t n = ak_scene_joint_count(s);
    if (!n || !s->skeleton) return CLI_OK;
    ak_i32_cspan parents = ak_skeleton_parents(s->skeleton);
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

/* The library's message ("NAME: problem") after "animkit CMD: ". */
static int fail_diag(const char* cmd, const ak_diag* d) { return cli_fail(cmd, "%s", d->message); }

/* Mirror the library run's arrays into the command's names. */
static void mirror(cloth_run* run) {
    run->cloth = run->lib.cloth;
    run->x = run->lib.positions, run->vel = run->lib.velocities, run->nrm = run->lib.normals;
    run->targets = run->lib.targets, run->caps = run->lib.capsules;
    run->n = run->lib.vertex_count;
    run->step = run->lib.step_index, run->time = run->lib.time;
}

int cloth_run_init(cloth_run* run, ak_cloth_scene* sc, const char* cmd, const char* name) {
    memset(run, 0, sizeof *run);
    run->sc = sc;
    cloth_character* ch = &run->ch;
    ak_result r = AK_OK;

    /* the character, posed at t = 0 (the library builds the cloth around its mesh and capsules) */
    if (sc->model[0]) {
        int rc;
        if ((rc = cli_load_scene(cmd, sc->model, &ch->scene))) return rc;
        if (cli_poser_init(&ch->poser, ch->scene)) {
            ak_scene_destroy(ch->scene);
            ch->scene = NULL;
            return cli_fail(cmd, "out of memory");
        }
        ch->clip = ch->scene->clip_count ? ak_scene_find_clip(ch->scene, sc->clip[0] ? sc->clip : NULL) : -1;
        if (sc->clip[0] && ch->clip < 0) return cli_fail(cmd, "%s: character.clip: no clip '%s' in %s", name, sc->clip, sc->model);
        ch->duration = ch->clip >= 0 ? ak_clip_duration(ch->scene->clips[ch->clip]) : 0.0f;
        for (size_t m = 0; m < ch->scene->mesh_count; ++m)
            if (ch->scene->meshes[m].mesh) {
                ch->mesh_vertices += ch->scene->meshes[m].mesh->vertex_count;
                ch->mesh_tris += ch->scene->meshes[m].mesh->triangle_count;
            }
        ch->mesh_pos = calloc(ch->mesh_vertices + 1, sizeof(ak_vec3));
        ch->mesh_idx = calloc(ch->mesh_tris * 3 + 1, sizeof(uint32_t));
        ch->attach_joint = calloc(sc->attach_count + 1, sizeof(int));
        ch->attach_offset = calloc(sc->attach_count + 1, sizeof(ak_vec3));
        if (!ch->mesh_pos || !ch->mesh_idx || !ch->attach_joint || !ch->attach_offset) return cli_fail(cmd, "out of memory");
        for (size_t m = 0, vo = 0, to = 0; m < ch->scene->mesh_count; ++m) {
            const ak_mesh* mesh = ch->scene->meshes[m].mesh;
            if (!mesh) continue;
            for (size_t k = 0; k < mesh->triangle_count * 3; ++k) ch->mesh_idx[to + k] = mesh->indices[k] + (uint32_t)vo;
            vo += mesh->vertex_count;
            to += mesh->triangle_count * 3;
        }
        if (sc->limb_capsules && character_bones(ch, sc->capsule_scale)) return cli_fail(cmd, "out of memory");
        if ((r = character_pose(ch, 0.0f)) != AK_OK)
            return cli_fail(cmd, "%s: cannot pose %s: %s", name, sc->model, ak_result_string(r));
    }

    /* the cloth and its step job */
    ak_cloth_scene_run_desc d = {.name = name, .extra_capsule_count = ch->bone_count};
    if (ch->scene && sc->mesh_collider && ch->mesh_tris)
        d.mesh = (ak_cloth_collider_mesh){{ch->mesh_pos, ch->mesh_vertices}, {ch->mesh_idx, ch->mesh_tris * 3}};
    ak_diag diag;
    r = ak_cloth_scene_run_init(&run->lib, sc, &d, &diag);
    if (run->lib.stable_substep > 0.0)
        fprintf(stderr, "%s: mass-spring is stable below h = %.4g ms (the stiffest springs on the lightest particle, "
                        "docs/cloth.md): %.0f substeps per step instead of %u\n",
                cmd, 1e3 * run->lib.stable_substep, run->lib.substeps_needed, run->lib.substeps_given);
    mirror(run);
    if (r != AK_OK) return fail_diag(cmd, &diag);

    /* attachments keep their offset from the joint or skinned vertex at t = 0, from their given
     * start position (the library put them there) or else their rest position */
    for (size_t k = 0; ch->scene && k < sc->attach_count; ++k) {
        const ak_cloth_attach_spec* at = &sc->attach[k];
        const ak_vec3 p = run->x[at->vertex];
        char path[40];
        snprintf(path, sizeof path, "attachments[%zu]", k);
        if (at->joint[0]) {
            const int j = ch->scene->skeleton ? ak_skeleton_find_joint(ch->scene->skeleton, at->joint) : -1;
            if (j < 0) return cli_fail(cmd, "%s: %s.joint: no joint '%s' in %s", name, path, at->joint, sc->model);
            ch->attach_joint[k] = j;
            ch->attach_offset[k] = ak_mat4_transform_point(ak_mat4_inverse(ch->poser.world[j]), p);
        } else {
            if ((size_t)at->mesh_vertex >= ch->mesh_vertices)
                return cli_fail(cmd, "%s: %s.mesh_vertex: %ld is out of range (%s has %zu vertices)", name, path,
                                at->mesh_vertex, sc->model, ch->mesh_vertices);
            ch->attach_joint[k] = -1;
            ch->attach_offset[k] = ak_vec3_sub(p, ch->mesh_pos[at->mesh_vertex]);
        }
    }
    return CLI_OK;
}

int cloth_run_step(cloth_run* run, const char* cmd, const char* name) {
    const ak_cloth_scene* sc = run->sc;
    cloth_character* ch = &run->ch;
    /* the character and the attachment targets at the end of this step */
    const float t_end = (float)(run->lib.step_index + 1) * sc->dt;
    if (ch->scene) {
        ak_result r;
        if ((r = character_pose(ch, t_end)) != AK_OK) {
            return cli_fail(cmd, "%s: cannot pose %s at t=%g: %s", name, sc->model, (double)t_end, ak_result_string(r));
        }
        for (size_t k = 0; k < sc->attach_count; ++k)
            run->targets[k] = ch->attach_joint[k] >= 0
                             ? ak_mat4_transform_point(ch->poser.world[ch->attach_joint[k]], ch->attach_offset[k])
                             : ak_vec3_add(ch->mesh_pos[sc->attach[k].mesh_vertex], ch->attach_offset[k]);
        for (size_t k = 0; k < ch->bone_count; ++k)
            run->caps[sc->capsule_count + k] = (ak_cloth_capsule){ak_mat4_get_translation(ch->poser.world[ch->bone_parent[k]]),
                                                            ak_mat4_get_translation(ch->poser.world[ch->bone_child[k]]),
                                                            ch->bone_radius[k]};
    }
    ak_diag diag;
    const ak_result r = ak_cloth_scene_run_step(&run->lib, name, &diag);
    mirror(run);
    return r == AK_OK ? CLI_OK : fail_diag(cmd, &diag);
}

void cloth_run_bounds(const cloth_run* run, ak_vec3* out_lo, ak_vec3* out_hi) {
    const ak_cloth_scene* sc = run->sc;
    ak_vec3 lo, hi;
    ak_points_bounds((ak_vec3_cspan){run->x, run->n}, &lo, &hi);
    for (size_t k = 0; k < sc->sphere_count; ++k) {
        const ak_vec3 rr = ak_vec3_splat(sc->spheres[k].radius);
        lo = ak_vec3_min(lo, ak_vec3_sub(sc->spheres[k].center, rr));
        hi = ak_vec3_max(hi, ak_vec3_add(sc->spheres[k].center, rr));
    }
    for (size_t k = 0; k < sc->plane_count; ++k)
        if (fabsf(ak_vec3_normalize(sc->planes[k].normal).y) > 0.99f) lo.y = ak_minf(lo.y, sc->planes[k].offset);
    if (run->ch.scene) cli_bounds_add_pose(&run->ch.poser, &lo, &hi);
    if (sc->wind.x != 0.0f || sc->wind.z != 0.0f) { /* a flag streams downwind: room for it */
        const ak_vec3 w = ak_vec3_normalize(ak_vec3_make(sc->wind.x, 0, sc->wind.z));
        const float span = ak_vec3_length(ak_vec3_sub(hi, lo));
        hi = ak_vec3_max(hi, ak_vec3_madd(hi, w, 0.3f * span));
        lo = ak_vec3_min(lo, ak_vec3_madd(lo, w, 0.3f * span));
    }
    *out_lo = lo;
    *out_hi = hi;
}

void cloth_run_free(cloth_run* run) {
    cloth_character_free(&run->ch);
    ak_cloth_scene_run_free(&run->lib);
    memset(run, 0, sizeof *run);
}

void cloth_prop_build(cloth_prop* p, ak_vec3 a, ak_vec3 b, float r) {
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

