/* animkit rigid: a run baked as glTF node animation (ak_rigid_bake_scene): one node per body
 * carrying its shape's mesh, with translation and rotation channels. */
#include <animkit/rigid.h>
#include <animkit/scene.h>
#include <animkit/skeleton.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "json.h" /* akp_diag_set */

enum { RINGS = 8, SEGS = 16 }; /* sphere and capsule tessellation: latitude rows, longitudes */

/* Vertices and triangles of a body's mesh (0 vertices: nothing drawn). */
static void shape_counts(ak_rigid_shape_type t, size_t* nv, size_t* nt) {
    switch (t) {
    case AK_RIGID_BOX:
        *nv = 24, *nt = 12;
        break;
    case AK_RIGID_PLANE:
        *nv = 4, *nt = 2;
        break;
    case AK_RIGID_SPHERE:
        *nv = (RINGS + 1) * (SEGS + 1), *nt = 2 * SEGS * (RINGS - 1);
        break;
    case AK_RIGID_CAPSULE:
        *nv = (RINGS + 2) * (SEGS + 1), *nt = 2 * SEGS * RINGS;
        break;
    default:
        *nv = 0, *nt = 0;
        break;
    }
}

/* A latitude-longitude grid, counter-clockwise seen from outside: rows from the south pole to
 * the north; a capsule's rows below the equator are moved down by half_height and those above
 * up (the equator row is doubled so the cylinder joins the caps). Degenerate triangles at the
 * poles are left out. */
static void round_mesh(ak_vec3* pos, ak_vec3* nrm, uint32_t* t, float radius, float half_height,
                       bool capsule) {
    const int rows = capsule ? RINGS + 2 : RINGS + 1;
    size_t v = 0;
    for (int k = 0; k < rows; ++k) {
        int lat = capsule && k > RINGS / 2 ? k - 1 : k;
        float th = -0.5f * AK_PI + AK_PI * (float)lat / (float)RINGS;
        float shift = !capsule ? 0.0f : (k <= RINGS / 2 ? -half_height : half_height);
        for (int s = 0; s <= SEGS; ++s) {
            float ph = 2.0f * AK_PI * (float)s / (float)SEGS;
            ak_vec3 n = ak_vec3_make(cosf(th) * sinf(ph), sinf(th), cosf(th) * cosf(ph));
            if (k == 0) n = ak_vec3_make(0.0f, -1.0f, 0.0f);
            if (k == rows - 1) n = ak_vec3_make(0.0f, 1.0f, 0.0f);
            nrm[v] = n;
            pos[v++] = ak_vec3_make(radius * n.x, radius * n.y + shift, radius * n.z);
        }
    }
    for (int k = 0; k + 1 < rows; ++k)
        for (int s = 0; s < SEGS; ++s) {
            uint32_t a = (uint32_t)(k * (SEGS + 1) + s), b = a + 1, c = a + SEGS + 1, d = c + 1;
            if (k > 0) t[0] = a, t[1] = b, t[2] = d, t += 3; /* a == b at the south pole */
            if (k + 1 < rows - 1) t[0] = a, t[1] = d, t[2] = c, t += 3; /* c == d at the north */
        }
}

static void box_mesh(ak_vec3* pos, ak_vec3* nrm, uint32_t* t, ak_vec3 h) {
    size_t v = 0;
    for (int axis = 0; axis < 3; ++axis)
        for (int sign = -1; sign <= 1; sign += 2) {
            float n[3] = {0, 0, 0};
            n[axis] = (float)sign;
            int u = (axis + 1) % 3, w = (axis + 2) % 3;
            uint32_t base = (uint32_t)v;
            const float cu[4] = {-1, 1, 1, -1}, cw[4] = {-1, -1, 1, 1};
            for (int c = 0; c < 4; ++c) {
                float p[3];
                p[axis] = (float)sign;
                p[u] = cu[c];
                p[w] = cw[c];
                pos[v] = ak_vec3_make(p[0] * h.x, p[1] * h.y, p[2] * h.z);
                nrm[v++] = ak_vec3_make(n[0], n[1], n[2]);
            }
            /* (u, w, axis) is right-handed: corners 0..3 run counter-clockwise about +axis */
            if (sign > 0)
                t[0] = base, t[1] = base + 1, t[2] = base + 2, t[3] = base, t[4] = base + 2,
                t[5] = base + 3;
            else
                t[0] = base, t[1] = base + 2, t[2] = base + 1, t[3] = base, t[4] = base + 3,
                t[5] = base + 2;
            t += 6;
        }
}

static void plane_mesh(ak_vec3* pos, ak_vec3* nrm, uint32_t* t, float size) {
    const float c[4][2] = {{-1, -1}, {-1, 1}, {1, 1}, {1, -1}}; /* ccw seen from +Y */
    for (int k = 0; k < 4; ++k) {
        pos[k] = ak_vec3_make(c[k][0] * size, 0.0f, c[k][1] * size);
        nrm[k] = ak_vec3_make(0.0f, 1.0f, 0.0f);
    }
    const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    memcpy(t, idx, sizeof idx);
}

/* The shape's mesh into arrays sized by shape_counts. */
static void shape_mesh(const ak_rigid_shape* sh, float plane_size, ak_vec3* pos, ak_vec3* nrm,
                       uint32_t* idx) {
    switch (sh->type) {
    case AK_RIGID_BOX:
        box_mesh(pos, nrm, idx, sh->half_extents);
        break;
    case AK_RIGID_PLANE:
        plane_mesh(pos, nrm, idx, plane_size > 0.0f ? plane_size : 10.0f);
        break;
    case AK_RIGID_CAPSULE:
        round_mesh(pos, nrm, idx, sh->radius, sh->half_height, true);
        break;
    case AK_RIGID_SPHERE:
        round_mesh(pos, nrm, idx, sh->radius, 0.0f, false);
        break;
    default:
        break;
    }
}

void ak_rigid_shape_mesh_size(const ak_rigid_shape* shape, size_t* out_vertex_count,
                              size_t* out_index_count) {
    size_t nv = 0, nt = 0;
    if (shape) shape_counts(shape->type, &nv, &nt);
    if (out_vertex_count) *out_vertex_count = nv;
    if (out_index_count) *out_index_count = 3 * nt;
}

ak_result ak_rigid_shape_mesh(const ak_rigid_shape* shape, float plane_size,
                              ak_vec3_span out_positions, ak_vec3_span out_normals,
                              ak_u32_span out_indices) {
    if (!shape || !out_positions.ptr || !out_normals.ptr || !out_indices.ptr)
        return AK_ERR_NULL_ARG;
    if ((unsigned)shape->type >= AK_RIGID_SHAPE_COUNT) return AK_ERR_BAD_ARG;
    size_t nv, ni;
    ak_rigid_shape_mesh_size(shape, &nv, &ni);
    if (out_positions.count < nv || out_normals.count < nv || out_indices.count < ni)
        return AK_ERR_SPAN_SMALL;
    shape_mesh(shape, plane_size, out_positions.ptr, out_normals.ptr, out_indices.ptr);
    return AK_OK;
}

void ak_rigid_world_mesh_size(const ak_rigid_model* model, size_t* out_vertex_count,
                              size_t* out_index_count) {
    size_t nv = 0, ni = 0, n = ak_rigid_body_count(model);
    for (size_t i = 0; i < n; ++i) {
        ak_rigid_body_desc d = ak_rigid_body_get_desc(model, i);
        if (d.shape.type == AK_RIGID_PLANE) continue;
        size_t a, b;
        ak_rigid_shape_mesh_size(&d.shape, &a, &b);
        nv += a, ni += b;
    }
    if (out_vertex_count) *out_vertex_count = nv;
    if (out_index_count) *out_index_count = ni;
}

ak_result ak_rigid_world_mesh(const ak_rigid_model* model, ak_vec3_cspan positions,
                              ak_quat_cspan orientations, ak_vec3_span out_positions,
                              ak_vec3_span out_normals, ak_u32_span out_indices) {
    if (!model || !positions.ptr || !orientations.ptr || !out_positions.ptr || !out_normals.ptr ||
        !out_indices.ptr)
        return AK_ERR_NULL_ARG;
    const size_t n = ak_rigid_body_count(model);
    size_t nv, ni;
    ak_rigid_world_mesh_size(model, &nv, &ni);
    if (positions.count < n || orientations.count < n || out_positions.count < nv ||
        out_normals.count < nv || out_indices.count < ni)
        return AK_ERR_SPAN_SMALL;
    for (size_t i = 0; i < n; ++i)
        if (!ak_vec3_is_finite(positions.ptr[i]) || !ak_quat_is_finite(orientations.ptr[i]))
            return AK_ERR_BAD_DATA;
    size_t v = 0, k = 0;
    for (size_t i = 0; i < n; ++i) {
        ak_rigid_body_desc d = ak_rigid_body_get_desc(model, i);
        if (d.shape.type == AK_RIGID_PLANE) continue;
        size_t a, b;
        ak_rigid_shape_mesh_size(&d.shape, &a, &b);
        shape_mesh(&d.shape, 0.0f, out_positions.ptr + v, out_normals.ptr + v, out_indices.ptr + k);
        const ak_quat q = ak_quat_normalize(orientations.ptr[i]);
        for (size_t j = v; j < v + a; ++j) {
            out_positions.ptr[j] =
                ak_vec3_add(positions.ptr[i], ak_quat_rotate(q, out_positions.ptr[j]));
            out_normals.ptr[j] = ak_quat_rotate(q, out_normals.ptr[j]);
        }
        for (size_t j = k; j < k + b; ++j) out_indices.ptr[j] += (uint32_t)v;
        v += a, k += b;
    }
    return AK_OK;
}

/* A node's pose for body i in a frame: planes are drawn around their point, Y along the normal. */
static ak_quat node_rotation(const ak_rigid_body_desc* d, ak_quat q) {
    if (d->shape.type == AK_RIGID_PLANE)
        return ak_quat_from_to(ak_vec3_make(0.0f, 1.0f, 0.0f), d->shape.normal);
    return ak_quat_normalize(q);
}

ak_result ak_rigid_bake_scene(const ak_rigid_bake_desc* desc, const ak_allocator* alloc,
                              struct ak_scene** out_scene, ak_diag* diag) {
    if (out_scene) *out_scene = NULL;
    if (!desc || !out_scene || !desc->model || !desc->positions || !desc->orientations)
        return akp_diag_set(diag, AK_ERR_NULL_ARG, "rigid bake", "a required pointer is NULL");
    const ak_rigid_model* model = desc->model;
    const size_t nb = ak_rigid_body_count(model), nf = desc->frame_count;
    const char* name = desc->name && *desc->name ? desc->name : "rigid";
    if (!nf) return akp_diag_set(diag, AK_ERR_EMPTY, "rigid bake", "no frames");
    const size_t max_frames = desc->max_frames ? desc->max_frames : AK_SCENE_BAKE_MAX_FRAMES;
    if (nf > max_frames)
        return akp_diag_set(diag, AK_ERR_UNSUPPORTED, "rigid bake",
                            "%zu frames, more than the limit of %zu", nf, max_frames);
    if (!(desc->frame_time > 0.0f) || !ak_finitef(desc->frame_time) ||
        !(desc->plane_size >= 0.0f) || !ak_finitef(desc->plane_size))
        return akp_diag_set(diag, AK_ERR_BAD_ARG, "rigid bake",
                            "frame_time must be > 0 and plane_size >= 0, both finite");
    if (nb > 32000)
        return akp_diag_set(diag, AK_ERR_UNSUPPORTED, "rigid bake",
                            "%zu bodies, more than the 32000 nodes a skeleton holds", nb);
    /* bytes: keys (time + translation + rotation, raw and built), meshes, nodes */
    size_t need = 0;
    const size_t per_key = 2 * (2 * sizeof(float) + sizeof(ak_vec3) + sizeof(ak_quat));
    if (nb && nf > SIZE_MAX / nb / per_key)
        need = SIZE_MAX;
    else
        need = nf * nb * per_key;
    const size_t mesh_bytes = (RINGS + 2) * (SEGS + 1) * 2 * sizeof(ak_vec3) +
                              2 * SEGS * RINGS * 3 * sizeof(uint32_t) + 2048;
    if (need < SIZE_MAX - nb * mesh_bytes)
        need += nb * mesh_bytes;
    else
        need = SIZE_MAX;
    const size_t budget = desc->memory_budget ? desc->memory_budget : AK_SCENE_BAKE_DEFAULT_BUDGET;
    if (need > budget)
        return akp_diag_set(diag, AK_ERR_UNSUPPORTED, "rigid bake",
                            "needs about %zu bytes, over the memory budget of %zu", need, budget);
    for (size_t k = 0; k < nf; ++k)
        for (size_t i = 0; i < nb; ++i)
            if (!ak_vec3_is_finite(desc->positions[k * nb + i]) ||
                !ak_quat_is_finite(desc->orientations[k * nb + i]) ||
                !(ak_quat_dot(desc->orientations[k * nb + i], desc->orientations[k * nb + i]) >
                  0.0f))
                return akp_diag_set(diag, AK_ERR_BAD_DATA, "rigid bake",
                                    "frame %zu body %zu: not a finite pose", k, i);

    /* which bodies move (a channel each): dynamic ones */
    size_t moving = 0;
    for (size_t i = 0; i < nb; ++i) moving += !ak_rigid_body_get_desc(model, i).is_static;
    ak_scene* s = NULL;
    ak_result r = ak_scene_alloc(nb, 0, nf > 1 && moving ? 1 : 0, alloc, &s);
    if (r != AK_OK) return akp_diag_set(diag, r, "rigid bake", "%s", ak_result_string(r));
    snprintf(s->name, sizeof s->name, "%s", name);
    ak_joint_desc* joints = calloc(nb + 1, sizeof *joints);
    char(*names)[AK_NAME_SIZE] = calloc(nb + 1, AK_NAME_SIZE);
    float* times = malloc(nf * sizeof *times);
    ak_vec3* tv = malloc((moving ? moving : 1) * nf * sizeof *tv);
    ak_quat* rv = malloc((moving ? moving : 1) * nf * sizeof *rv);
    ak_raw_channel* ch = calloc(2 * moving + 1, sizeof *ch);
    if (!joints || !names || !times || !tv || !rv || !ch) r = AK_ERR_NO_MEMORY;
    for (size_t k = 0; r == AK_OK && k < nf; ++k) {
        times[k] = (float)((double)k * (double)desc->frame_time);
        if (!ak_finitef(times[k]) || (k && !(times[k] > times[k - 1])))
            r = akp_diag_set(diag, AK_ERR_BAD_ARG, "rigid bake",
                             "%zu frames of this frame_time do not give distinct finite times", nf);
    }
    if (r == AK_OK) {
        snprintf(names[0], AK_NAME_SIZE, "%s", name);
        joints[0] =
            (ak_joint_desc){.name = names[0], .parent = -1, .rest = ak_transform_identity()};
        for (size_t i = 0; i < nb; ++i) {
            ak_rigid_body_desc d = ak_rigid_body_get_desc(model, i);
            snprintf(names[i + 1], AK_NAME_SIZE, "%.40s_%zu", name, i);
            ak_transform t = ak_transform_identity();
            t.translation = desc->positions[i];
            t.rotation = node_rotation(&d, desc->orientations[i]);
            joints[i + 1] = (ak_joint_desc){.name = names[i + 1], .parent = 0, .rest = t};
        }
        r = ak_skeleton_create(
            &(ak_skeleton_desc){.joints = joints, .joint_count = nb + 1, .name = name}, &s->alloc,
            &s->skeleton, diag);
    }
    for (size_t i = 0; r == AK_OK && i < nb; ++i) {
        ak_rigid_body_desc d = ak_rigid_body_get_desc(model, i);
        size_t nv, nt;
        shape_counts(d.shape.type, &nv, &nt);
        char mname[AK_NAME_SIZE];
        snprintf(mname, sizeof mname, "%.40s_%zu", name, i);
        ak_mesh_desc md = {
            .vertex_count = nv, .triangle_count = nt, .has_normals = true, .name = mname};
        if ((r = ak_mesh_create(&md, &s->alloc, &s->meshes[i].mesh)) != AK_OK) break;
        ak_mesh* m = s->meshes[i].mesh;
        shape_mesh(&d.shape, desc->plane_size, m->positions, m->normals, m->indices);
        s->meshes[i].node = (int32_t)(i + 1);
        s->meshes[i].has_material = true;
        s->meshes[i].base_color = d.is_static ? ak_vec4_make(0.55f, 0.55f, 0.5f, 1.0f)
                                              : ak_vec4_make(0.85f, 0.45f, 0.2f, 1.0f);
    }
    if (r == AK_OK && s->clip_count) {
        size_t c = 0, o = 0;
        for (size_t i = 0; i < nb; ++i) {
            ak_rigid_body_desc d = ak_rigid_body_get_desc(model, i);
            if (d.is_static) continue;
            for (size_t k = 0; k < nf; ++k) {
                tv[o + k] = desc->positions[k * nb + i];
                ak_quat q = node_rotation(&d, desc->orientations[k * nb + i]);
                /* the shorter way from the previous key, so LINEAR (slerp) turns the short way */
                if (k && ak_quat_dot(q, rv[o + k - 1]) < 0.0f) q = ak_quat_neg(q);
                rv[o + k] = q;
            }
            ch[c++] = (ak_raw_channel){.target = AK_CHANNEL_TRANSLATION,
                                       .index = (uint32_t)(i + 1),
                                       .component_count = 3,
                                       .interp = AK_INTERP_LINEAR,
                                       .key_count = nf,
                                       .times = times,
                                       .values = &tv[o].x};
            ch[c++] = (ak_raw_channel){.target = AK_CHANNEL_ROTATION,
                                       .index = (uint32_t)(i + 1),
                                       .component_count = 4,
                                       .interp = AK_INTERP_LINEAR,
                                       .key_count = nf,
                                       .times = times,
                                       .values = &rv[o].x};
            o += nf;
        }
        ak_raw_clip raw = {.name = name,
                           .duration = times[nf - 1],
                           .channels = ch,
                           .channel_count = c,
                           .joint_count = nb + 1};
        r = ak_clip_build(&raw, &s->alloc, &s->clips[0], diag);
    }
    free(joints), free(names), free(times), free(tv), free(rv), free(ch);
    if (r != AK_OK) {
        ak_scene_destroy(s);
        if (r == AK_ERR_NO_MEMORY) akp_diag_set(diag, r, "rigid bake", "out of memory");
        return r;
    }
    *out_scene = s;
    return AK_OK;
}

ak_result ak_rigid_bake_ragdoll_clip(const ak_rigid_bake_ragdoll_desc* desc,
                                     const ak_allocator* alloc, struct ak_clip** out_clip,
                                     ak_diag* diag) {
    if (out_clip) *out_clip = NULL;
    if (!desc || !out_clip || !desc->skeleton || !desc->bones.ptr || !desc->fallback_pose.ptr ||
        !desc->positions || !desc->orientations)
        return akp_diag_set(diag, AK_ERR_NULL_ARG, "ragdoll bake", "a required pointer is NULL");
    const ak_skeleton* sk = desc->skeleton;
    const size_t n = ak_skeleton_joint_count(sk), nb = desc->body_count, nf = desc->frame_count;
    if (!nf || !n) return akp_diag_set(diag, AK_ERR_EMPTY, "ragdoll bake", "no frames or joints");
    if (!(desc->frame_time > 0.0f) || !ak_finitef(desc->frame_time))
        return akp_diag_set(diag, AK_ERR_BAD_ARG, "ragdoll bake", "frame_time must be > 0");
    if (desc->bones.count < n || desc->fallback_pose.count < n)
        return akp_diag_set(diag, AK_ERR_SPAN_SMALL, "ragdoll bake",
                            "bones and fallback_pose need %zu entries", n);
    for (size_t i = 0; i < n; ++i)
        if (desc->bones.ptr[i].body >= 0 && (size_t)desc->bones.ptr[i].body >= nb)
            return akp_diag_set(diag, AK_ERR_BAD_INDEX, "ragdoll bake",
                                "joint %zu's body is past the %zu bodies", i, nb);
    const size_t max_frames = desc->max_frames ? desc->max_frames : AK_SCENE_BAKE_MAX_FRAMES;
    if (nf > max_frames)
        return akp_diag_set(diag, AK_ERR_UNSUPPORTED, "ragdoll bake",
                            "%zu frames, more than the limit of %zu", nf, max_frames);
    const size_t per_key = 2 * (sizeof(float) + sizeof(ak_vec3) + sizeof(ak_quat));
    size_t need = nf > SIZE_MAX / n / (per_key + 64) ? SIZE_MAX : nf * n * (per_key + 64);
    const size_t budget = desc->memory_budget ? desc->memory_budget : AK_SCENE_BAKE_DEFAULT_BUDGET;
    if (need > budget)
        return akp_diag_set(diag, AK_ERR_UNSUPPORTED, "ragdoll bake",
                            "needs about %zu bytes, over the memory budget of %zu", need, budget);
    float* times = malloc(nf * sizeof *times);
    ak_vec3* tv = malloc(nf * n * sizeof *tv); /* joint-major: joint i's keys at [i * nf] */
    ak_quat* rv = malloc(nf * n * sizeof *rv);
    ak_transform* local = malloc(n * sizeof *local);
    ak_raw_channel* ch = calloc(2 * n, sizeof *ch);
    ak_result r = times && tv && rv && local && ch ? AK_OK : AK_ERR_NO_MEMORY;
    for (size_t k = 0; r == AK_OK && k < nf; ++k) {
        times[k] = (float)((double)k * (double)desc->frame_time);
        if (!ak_finitef(times[k]) || (k && !(times[k] > times[k - 1]))) {
            r = akp_diag_set(diag, AK_ERR_BAD_ARG, "ragdoll bake",
                             "%zu frames of this frame_time do not give distinct finite times", nf);
            break;
        }
        r = ak_rigid_ragdoll_pose(sk, desc->bones, desc->root,
                                  (ak_vec3_cspan){desc->positions + k * nb, nb},
                                  (ak_quat_cspan){desc->orientations + k * nb, nb},
                                  desc->fallback_pose, (ak_transform_span){local, n});
        if (r == AK_OK && !ak_pose_is_finite((ak_transform_cspan){local, n})) r = AK_ERR_BAD_DATA;
        if (r != AK_OK) {
            akp_diag_set(diag, r, "ragdoll bake", "frame %zu: %s", k, ak_result_string(r));
            break;
        }
        for (size_t i = 0; i < n; ++i) {
            tv[i * nf + k] = local[i].translation;
            ak_quat q = local[i].rotation;
            if (k && ak_quat_dot(q, rv[i * nf + k - 1]) < 0.0f) q = ak_quat_neg(q);
            rv[i * nf + k] = q;
        }
    }
    if (r == AK_OK) {
        for (size_t i = 0; i < n; ++i) {
            ch[2 * i] = (ak_raw_channel){.target = AK_CHANNEL_TRANSLATION,
                                         .index = (uint32_t)i,
                                         .component_count = 3,
                                         .interp = AK_INTERP_LINEAR,
                                         .key_count = nf,
                                         .times = times,
                                         .values = &tv[i * nf].x};
            ch[2 * i + 1] = (ak_raw_channel){.target = AK_CHANNEL_ROTATION,
                                             .index = (uint32_t)i,
                                             .component_count = 4,
                                             .interp = AK_INTERP_LINEAR,
                                             .key_count = nf,
                                             .times = times,
                                             .values = &rv[i * nf].x};
        }
        ak_raw_clip raw = {.name = desc->name ? desc->name : "ragdoll",
                           .duration = times[nf - 1],
                           .channels = ch,
                           .channel_count = 2 * n,
                           .joint_count = n};
        r = ak_clip_build(&raw, alloc, out_clip, diag);
    }
    if (r == AK_ERR_NO_MEMORY) akp_diag_set(diag, r, "ragdoll bake", "out of memory");
    free(times), free(tv), free(rv), free(local), free(ch);
    return r;
}
