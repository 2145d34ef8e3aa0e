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
#include "rigid_impl.h"

enum { RINGS = 8, SEGS = 16 }; /* sphere and capsule tessellation: latitude rows, longitudes */

/* Vertices and triangles of a primitive shape's mesh (0 vertices: nothing drawn). */
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

/* Vertices and triangles of any shape's mesh: a hull's faces fanned (each face its own
 * vertices, for flat normals), a compound's children, a heightfield's grid (a vertex per
 * sample), a trimesh's triangles (three vertices each). hull and compound come from the model
 * (NULL: the shape alone, which draws nothing for those two types). */
static void mesh_counts(const ak_rigid_shape* s, const akp_hull* hull, const akp_compound* comp,
                        size_t* nv, size_t* nt) {
    *nv = 0, *nt = 0;
    switch (s->type) {
    case AK_RIGID_HULL:
        if (hull)
            for (uint32_t f = 0; f < hull->nf; ++f)
                *nv += hull->faces[f].count, *nt += hull->faces[f].count - 2;
        break;
    case AK_RIGID_COMPOUND:
        if (comp)
            for (uint32_t k = 0; k < comp->count; ++k) {
                size_t a, b;
                mesh_counts(&comp->kids[k].shape, comp->kids[k].hull, NULL, &a, &b);
                *nv += a, *nt += b;
            }
        break;
    case AK_RIGID_HEIGHTFIELD:
        if (s->rows >= 2 && s->cols >= 2 && s->heights.ptr &&
            s->heights.count == (size_t)s->rows * s->cols)
            *nv = (size_t)s->rows * s->cols, *nt = 2 * (size_t)(s->rows - 1) * (s->cols - 1);
        break;
    case AK_RIGID_TRIMESH:
        if (s->vertices.ptr && s->indices.ptr) *nt = s->indices.count / 3, *nv = 3 * *nt;
        break;
    default:
        shape_counts(s->type, nv, nt);
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

static void hull_mesh(ak_vec3* pos, ak_vec3* nrm, uint32_t* t, const akp_hull* h) {
    uint32_t v = 0;
    for (uint32_t f = 0; f < h->nf; ++f) {
        const akp_hull_face* fc = &h->faces[f];
        for (uint32_t k = 0; k < fc->count; ++k) {
            pos[v + k] = h->verts[h->idx[fc->first + k]];
            nrm[v + k] = fc->n;
        }
        for (uint32_t k = 1; k + 1 < fc->count; ++k)
            t[0] = v, t[1] = v + k, t[2] = v + k + 1, t += 3;
        v += fc->count;
    }
}

static ak_vec3 hf_point(const ak_rigid_shape* s, uint32_t i, uint32_t j) {
    return ak_vec3_make((float)i * s->spacing, s->heights.ptr[(size_t)j * s->cols + i],
                        (float)j * s->spacing);
}

/* The grid as the collision code splits it: cell (i, j) is (00, 01, 11) and (00, 11, 10), both
 * counter-clockwise seen from +Y; normals by central differences. */
static void heightfield_mesh(ak_vec3* pos, ak_vec3* nrm, uint32_t* t, const ak_rigid_shape* s) {
    const uint32_t rows = s->rows, cols = s->cols;
    for (uint32_t j = 0; j < rows; ++j)
        for (uint32_t i = 0; i < cols; ++i) {
            uint32_t i0 = i ? i - 1 : i, i1 = i + 1 < cols ? i + 1 : i;
            uint32_t j0 = j ? j - 1 : j, j1 = j + 1 < rows ? j + 1 : j;
            float dx =
                (hf_point(s, i1, j).y - hf_point(s, i0, j).y) / ((float)(i1 - i0) * s->spacing);
            float dz =
                (hf_point(s, i, j1).y - hf_point(s, i, j0).y) / ((float)(j1 - j0) * s->spacing);
            pos[(size_t)j * cols + i] = hf_point(s, i, j);
            nrm[(size_t)j * cols + i] = ak_vec3_normalize(ak_vec3_make(-dx, 1.0f, -dz));
        }
    for (uint32_t j = 0; j + 1 < rows; ++j)
        for (uint32_t i = 0; i + 1 < cols; ++i) {
            uint32_t a = j * cols + i, b = a + 1, c = a + cols, d = c + 1; /* 00 10 01 11 */
            t[0] = a, t[1] = c, t[2] = d, t[3] = a, t[4] = d, t[5] = b;
            t += 6;
        }
}

static void trimesh_mesh(ak_vec3* pos, ak_vec3* nrm, uint32_t* t, const ak_rigid_shape* s) {
    const size_t nt = s->indices.count / 3;
    for (size_t k = 0; k < nt; ++k) {
        ak_vec3 p[3];
        for (int c = 0; c < 3; ++c) p[c] = s->vertices.ptr[s->indices.ptr[3 * k + (size_t)c]];
        ak_vec3 n = ak_vec3_cross(ak_vec3_sub(p[1], p[0]), ak_vec3_sub(p[2], p[0]));
        float l = ak_vec3_length(n);
        n = l > 0.0f ? ak_vec3_scale(n, 1.0f / l) : ak_vec3_make(0.0f, 1.0f, 0.0f);
        for (int c = 0; c < 3; ++c) {
            pos[3 * k + (size_t)c] = p[c];
            nrm[3 * k + (size_t)c] = n;
            t[3 * k + (size_t)c] = (uint32_t)(3 * k + (size_t)c);
        }
    }
}

/* The shape's mesh into arrays sized by mesh_counts. */
static void shape_mesh(const ak_rigid_shape* sh, const akp_hull* hull, const akp_compound* comp,
                       float plane_size, ak_vec3* pos, ak_vec3* nrm, uint32_t* idx) {
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
    case AK_RIGID_HULL:
        if (hull) hull_mesh(pos, nrm, idx, hull);
        break;
    case AK_RIGID_HEIGHTFIELD: {
        size_t nv, nt;
        mesh_counts(sh, NULL, NULL, &nv, &nt);
        if (nv) heightfield_mesh(pos, nrm, idx, sh);
        break;
    }
    case AK_RIGID_TRIMESH:
        if (sh->vertices.ptr && sh->indices.ptr) trimesh_mesh(pos, nrm, idx, sh);
        break;
    case AK_RIGID_COMPOUND:
        if (comp) {
            size_t v = 0, k3 = 0;
            for (uint32_t k = 0; k < comp->count; ++k) {
                const rigid_body* kid = &comp->kids[k];
                size_t a, b;
                mesh_counts(&kid->shape, kid->hull, NULL, &a, &b);
                shape_mesh(&kid->shape, kid->hull, NULL, 0.0f, pos + v, nrm + v, idx + k3);
                const rigid_pose p = comp->poses[k];
                for (size_t j = v; j < v + a; ++j) {
                    pos[j] = ak_vec3_add(p.x, ak_quat_rotate(p.q, pos[j]));
                    nrm[j] = ak_quat_rotate(p.q, nrm[j]);
                }
                for (size_t j = k3; j < k3 + 3 * b; ++j) idx[j] += (uint32_t)v;
                v += a, k3 += 3 * b;
            }
        }
        break;
    default:
        break;
    }
}

void ak_rigid_shape_mesh_size(const ak_rigid_shape* shape, size_t* out_vertex_count,
                              size_t* out_index_count) {
    size_t nv = 0, nt = 0;
    if (shape && (unsigned)shape->type < AK_RIGID_SHAPE_COUNT)
        mesh_counts(shape, NULL, NULL, &nv, &nt);
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
    shape_mesh(shape, NULL, NULL, plane_size, out_positions.ptr, out_normals.ptr, out_indices.ptr);
    return AK_OK;
}

void ak_rigid_body_mesh_size(const ak_rigid_model* model, size_t body_index,
                             size_t* out_vertex_count, size_t* out_index_count) {
    size_t nv = 0, nt = 0;
    if (model && body_index < model->body_count) {
        const rigid_body* b = &model->bodies[body_index];
        mesh_counts(&b->shape, b->hull, b->compound, &nv, &nt);
    }
    if (out_vertex_count) *out_vertex_count = nv;
    if (out_index_count) *out_index_count = 3 * nt;
}

ak_result ak_rigid_body_mesh(const ak_rigid_model* model, size_t body_index, float plane_size,
                             ak_vec3_span out_positions, ak_vec3_span out_normals,
                             ak_u32_span out_indices) {
    if (!model || !out_positions.ptr || !out_normals.ptr || !out_indices.ptr)
        return AK_ERR_NULL_ARG;
    if (body_index >= model->body_count) return AK_ERR_BAD_INDEX;
    if (!(plane_size >= 0.0f) || !ak_finitef(plane_size)) return AK_ERR_BAD_ARG;
    size_t nv, ni;
    ak_rigid_body_mesh_size(model, body_index, &nv, &ni);
    if (out_positions.count < nv || out_normals.count < nv || out_indices.count < ni)
        return AK_ERR_SPAN_SMALL;
    const rigid_body* b = &model->bodies[body_index];
    shape_mesh(&b->shape, b->hull, b->compound, plane_size, out_positions.ptr, out_normals.ptr,
               out_indices.ptr);
    return AK_OK;
}

void ak_rigid_world_mesh_size(const ak_rigid_model* model, size_t* out_vertex_count,
                              size_t* out_index_count) {
    size_t nv = 0, ni = 0, n = ak_rigid_body_count(model);
    for (size_t i = 0; i < n; ++i) {
        if (model->bodies[i].shape.type == AK_RIGID_PLANE) continue;
        size_t a, b;
        ak_rigid_body_mesh_size(model, i, &a, &b);
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
    if (nv > UINT32_MAX) return AK_ERR_UNSUPPORTED; /* the 32-bit indices could not reach them */
    for (size_t i = 0; i < n; ++i)
        if (!ak_vec3_is_finite(positions.ptr[i]) || !ak_quat_is_finite(orientations.ptr[i]))
            return AK_ERR_BAD_DATA;
    size_t v = 0, k = 0;
    for (size_t i = 0; i < n; ++i) {
        const rigid_body* bd = &model->bodies[i];
        if (bd->shape.type == AK_RIGID_PLANE) continue;
        size_t a, b;
        ak_rigid_body_mesh_size(model, i, &a, &b);
        shape_mesh(&bd->shape, bd->hull, bd->compound, 0.0f, out_positions.ptr + v,
                   out_normals.ptr + v, out_indices.ptr + k);
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
    for (size_t i = 0; i < nb && need < SIZE_MAX; ++i) {
        size_t mv, mi; /* each body's mesh as drawn (a trimesh or heightfield may be large) */
        ak_rigid_body_mesh_size(model, i, &mv, &mi);
        const size_t mesh_bytes = mv * 2 * sizeof(ak_vec3) + mi * sizeof(uint32_t) + 2048;
        need = need < SIZE_MAX - mesh_bytes ? need + mesh_bytes : SIZE_MAX;
    }
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
        ak_rigid_body_mesh_size(model, i, &nv, &nt);
        nt /= 3;
        char mname[AK_NAME_SIZE];
        snprintf(mname, sizeof mname, "%.40s_%zu", name, i);
        ak_mesh_desc md = {
            .vertex_count = nv, .triangle_count = nt, .has_normals = true, .name = mname};
        if ((r = ak_mesh_create(&md, &s->alloc, &s->meshes[i].mesh)) != AK_OK) break;
        ak_mesh* m = s->meshes[i].mesh;
        ak_rigid_body_mesh(model, i, desc->plane_size, (ak_vec3_span){m->positions, nv},
                           (ak_vec3_span){m->normals, nv}, (ak_u32_span){m->indices, 3 * nt});
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
