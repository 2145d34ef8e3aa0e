/* Baking per-frame results into an animated scene (scene.h "baking computed motion"):
 * a deforming mesh as morph-target blocks, a point set as one node per point. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "animkit/scene.h"
#include "internal.h"

#define BAKE_POINTS_HARD_MAX 32000u

static ak_result fail(ak_diag* diag, ak_result r, const char* fmt, size_t a, size_t b) {
    akp_diag_set(diag, NULL, fmt, a, b);
    return r;
}

/* a + b * c into *acc (saturating at SIZE_MAX) */
static void est(size_t* acc, size_t b, size_t c) {
    if (b && c > (SIZE_MAX - *acc) / b) *acc = SIZE_MAX;
    else *acc += b * c;
}

/* Key time of frame k; false when it is not finite or not after the previous frame's. */
static bool frame_times(float frame_time, size_t frame_count, float* out) {
    for (size_t k = 0; k < frame_count; ++k) {
        out[k] = (float)((double)k * (double)frame_time);
        if (!isfinite(out[k]) || (k && !(out[k] > out[k - 1]))) return false;
    }
    return true;
}

static bool interp_ok(ak_interp i) { return i == AK_INTERP_DEFAULT || i == AK_INTERP_LINEAR || i == AK_INTERP_STEP; }

/* Root joint (index 0, named name) and child joints "<name>_<label[i]>". */
static ak_result make_skeleton(ak_scene* s, const char* name, size_t children, const uint32_t* labels,
                               const ak_vec3* rest_translation, ak_diag* diag) {
    size_t n = children + 1;
    ak_joint_desc* j = (ak_joint_desc*)calloc(n, sizeof *j);
    char(*names)[AK_NAME_SIZE] = (char(*)[AK_NAME_SIZE])calloc(n, AK_NAME_SIZE);
    ak_result r = AK_ERR_NO_MEMORY;
    if (j && names) {
        snprintf(names[0], AK_NAME_SIZE, "%s", name);
        j[0] = (ak_joint_desc){.name = names[0], .parent = -1, .rest = ak_transform_identity()};
        for (size_t i = 0; i < children; ++i) {
            snprintf(names[i + 1], AK_NAME_SIZE, "%.40s_%lu", name, (unsigned long)(labels ? labels[i] : i));
            ak_transform t = ak_transform_identity();
            if (rest_translation) t.translation = rest_translation[i];
            j[i + 1] = (ak_joint_desc){.name = names[i + 1], .parent = 0, .rest = t};
        }
        r = ak_skeleton_create(&(ak_skeleton_desc){.joints = j, .joint_count = n, .name = name}, &s->alloc,
                               &s->skeleton, diag);
    }
    free(j);
    free(names);
    return r;
}

/* ---- mesh frames ------------------------------------------------------------------------ */

ak_result ak_scene_bake_mesh_frames(const ak_scene_bake_mesh_desc* desc, const ak_allocator* alloc,
                                    ak_scene** out_scene, ak_diag* diag) {
    if (out_scene) *out_scene = NULL;
    if (!desc || !out_scene || !desc->positions || (desc->indices.count && !desc->indices.ptr))
        return fail(diag, AK_ERR_NULL_ARG, "bake: a required pointer is NULL%.0zu%.0zu", 0, 0);
    const size_t nv = desc->vertex_count, nf = desc->frame_count, ni = desc->indices.count;
    if (!nv || !nf) return fail(diag, AK_ERR_EMPTY, "bake: %zu vertices, %zu frames", nv, nf);
    if (!(desc->frame_time > 0.0f) || !isfinite(desc->frame_time) || !interp_ok(desc->interp) || ni % 3)
        return fail(diag, AK_ERR_BAD_ARG, "bake: frame_time must be > 0, interp LINEAR or STEP, %zu indices a multiple of 3%.0zu",
                    ni, 0);
    const size_t max_frames = desc->max_frames ? desc->max_frames : AK_SCENE_BAKE_MAX_FRAMES;
    if (nf > max_frames)
        return fail(diag, AK_ERR_UNSUPPORTED, "bake: %zu frames, more than the limit of %zu", nf, max_frames);
    if (nv > UINT32_MAX) return fail(diag, AK_ERR_UNSUPPORTED, "bake: %zu vertices, more than %zu", nv, UINT32_MAX);
    const size_t per = AK_SCENE_BAKE_TARGETS_PER_MESH;
    const size_t blocks = nf > 1 ? (nf - 2) / per + 1 : 1;
    /* bytes: every block's base and targets (frames + blocks vertex arrays), indices per
     * block, weights (raw and built, about 64 per frame each) and key times */
    size_t need = 0, vstride = sizeof(ak_vec3) * (desc->normals ? 2 : 1);
    est(&need, nf + blocks, nv);
    if (need != SIZE_MAX) {
        size_t vbytes = need;
        need = 0;
        est(&need, vbytes, vstride);
    }
    est(&need, blocks, ni * sizeof(uint32_t) + 4096);
    est(&need, nf, 3 * (per + 2) * sizeof(float) + sizeof(float) + AK_NAME_SIZE);
    const size_t budget = desc->memory_budget ? desc->memory_budget : AK_SCENE_BAKE_DEFAULT_BUDGET;
    if (need > budget)
        return fail(diag, AK_ERR_UNSUPPORTED, "bake: needs about %zu bytes, over the memory budget of %zu", need, budget);
    for (size_t i = 0; i < ni; ++i)
        if (desc->indices.ptr[i] >= nv)
            return fail(diag, AK_ERR_BAD_INDEX, "bake: index %zu is out of range (%zu vertices)", i, nv);
    for (size_t i = 0; i < nf * nv; ++i)
        if (!ak_vec3_is_finite(desc->positions[i]) || (desc->normals && !ak_vec3_is_finite(desc->normals[i])))
            return fail(diag, AK_ERR_BAD_DATA, "bake: frame %zu vertex %zu is not finite", i / nv, i % nv);

    float* times = (float*)malloc(nf * sizeof(float));
    if (!times) return AK_ERR_NO_MEMORY;
    if (!frame_times(desc->frame_time, nf, times)) {
        free(times);
        return fail(diag, AK_ERR_BAD_ARG, "bake: %zu frames of this frame_time do not give distinct finite times%.0zu", nf, 0);
    }
    const char* name = desc->name ? desc->name : "bake";
    ak_scene* s = NULL;
    ak_result r = ak_scene_alloc(blocks, 0, nf > 1 ? 1 : 0, alloc, &s);
    if (r == AK_OK) {
        snprintf(s->name, sizeof s->name, "%s", name);
        r = make_skeleton(s, name, blocks, NULL, NULL, diag);
    }
    const bool has_mat = desc->base_color.x != 0.0f || desc->base_color.y != 0.0f || desc->base_color.z != 0.0f ||
                         desc->base_color.w != 0.0f;
    for (size_t b = 0; r == AK_OK && b < blocks; ++b) {
        const size_t first = b * per, last = nf > 1 ? (first + per < nf - 1 ? first + per : nf - 1) : 0;
        const size_t nt = last - first;
        char mname[AK_NAME_SIZE];
        snprintf(mname, sizeof mname, "%.40s_%zu", name, b);
        ak_mesh_desc md = {.vertex_count = nv, .triangle_count = ni / 3, .morph_target_count = nt,
                           .has_normals = desc->normals != NULL, .has_morph_normals = desc->normals && nt,
                           .name = mname};
        ak_mesh* m = NULL;
        if ((r = ak_mesh_create(&md, &s->alloc, &m)) != AK_OK) break;
        s->meshes[b].mesh = m;
        s->meshes[b].node = (int32_t)(b + 1);
        s->meshes[b].has_material = has_mat;
        s->meshes[b].base_color = desc->base_color;
        const ak_vec3* p0 = desc->positions + first * nv;
        memcpy(m->positions, p0, nv * sizeof(ak_vec3));
        if (desc->normals) memcpy(m->normals, desc->normals + first * nv, nv * sizeof(ak_vec3));
        if (ni) memcpy(m->indices, desc->indices.ptr, ni * sizeof(uint32_t));
        for (size_t t = 0; t < nt; ++t) {
            const ak_vec3* pk = desc->positions + (first + 1 + t) * nv;
            for (size_t v = 0; v < nv; ++v) m->morph_positions[t * nv + v] = ak_vec3_sub(pk[v], p0[v]);
            if (desc->normals) {
                const ak_vec3 *n0 = desc->normals + first * nv, *nk = desc->normals + (first + 1 + t) * nv;
                for (size_t v = 0; v < nv; ++v) m->morph_normals[t * nv + v] = ak_vec3_sub(nk[v], n0[v]);
            }
            snprintf(m->morph_names[t], AK_NAME_SIZE, "frame_%zu", first + 1 + t);
        }
    }
    if (r == AK_OK && nf > 1) {
        /* per block: a weights channel over its frames, and (several blocks) a STEP scale */
        size_t nch = blocks * (blocks > 1 ? 2 : 1);
        ak_raw_channel* ch = (ak_raw_channel*)calloc(nch, sizeof *ch);
        float* vals = (float*)calloc(blocks * (per + 1) * per + blocks * 9, sizeof(float));
        float* stimes = (float*)calloc(blocks * 3, sizeof(float));
        if (!ch || !vals || !stimes) r = AK_ERR_NO_MEMORY;
        size_t c = 0, vo = 0, wbase = 0;
        const ak_interp wi = desc->interp == AK_INTERP_STEP ? AK_INTERP_STEP : AK_INTERP_LINEAR;
        for (size_t b = 0; r == AK_OK && b < blocks; ++b) {
            const size_t first = b * per, nt = s->meshes[b].mesh->morph_target_count;
            float* w = vals + vo;
            for (size_t k = 1; k <= nt; ++k) w[k * nt + (k - 1)] = 1.0f; /* key 0: all zero */
            ch[c++] = (ak_raw_channel){.target = AK_CHANNEL_MORPH_WEIGHTS, .index = (uint32_t)wbase,
                                       .component_count = (uint32_t)nt, .interp = wi, .key_count = nt + 1,
                                       .times = times + first, .values = w};
            vo += (nt + 1) * nt;
            wbase += nt;
            if (blocks > 1) {
                float* st = stimes + 3 * b;
                float* sv = vals + vo;
                size_t keys = 0;
                if (b > 0) st[keys] = 0.0f, sv[3 * keys] = sv[3 * keys + 1] = sv[3 * keys + 2] = 0.0f, ++keys;
                st[keys] = times[first], sv[3 * keys] = sv[3 * keys + 1] = sv[3 * keys + 2] = 1.0f, ++keys;
                if (b + 1 < blocks)
                    st[keys] = times[first + nt], sv[3 * keys] = sv[3 * keys + 1] = sv[3 * keys + 2] = 0.0f, ++keys;
                vo += 9;
                ch[c++] = (ak_raw_channel){.target = AK_CHANNEL_SCALE, .index = (uint32_t)(b + 1), .component_count = 3,
                                           .interp = AK_INTERP_STEP, .key_count = keys, .times = st, .values = sv};
            }
        }
        if (r == AK_OK) {
            ak_raw_clip raw = {.name = name, .duration = times[nf - 1], .channels = ch, .channel_count = c,
                               .joint_count = blocks + 1, .morph_weight_count = wbase};
            r = ak_clip_build(&raw, &s->alloc, &s->clips[0], diag);
        }
        free(ch);
        free(vals);
        free(stimes);
    }
    free(times);
    if (r != AK_OK) {
        ak_scene_destroy(s);
        return r;
    }
    *out_scene = s;
    return AK_OK;
}

/* ---- point frames ----------------------------------------------------------------------- */

static int cmp_u32(const void* a, const void* b) {
    uint32_t x = *(const uint32_t*)a, y = *(const uint32_t*)b;
    return x < y ? -1 : x > y;
}

static size_t find_id(const uint32_t* ids, size_t n, uint32_t id) {
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (ids[mid] < id) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

/* An octahedron of radius r: 6 vertices on the axes, 8 counter-clockwise triangles. */
static void octahedron(ak_mesh* m, float r) {
    static const float ax[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (size_t v = 0; v < 6; ++v) {
        m->normals[v] = ak_vec3_make(ax[v][0], ax[v][1], ax[v][2]);
        m->positions[v] = ak_vec3_scale(m->normals[v], r);
    }
    size_t t = 0;
    for (uint32_t sx = 0; sx < 2; ++sx)
        for (uint32_t sy = 0; sy < 2; ++sy)
            for (uint32_t sz = 0; sz < 2; ++sz, ++t) {
                uint32_t x = sx, y = 2 + sy, z = 4 + sz; /* 0 -> the + vertex, 1 -> the - one */
                bool flip = (sx + sy + sz) % 2 == 1;     /* an odd number of minus signs */
                m->indices[3 * t] = x;
                m->indices[3 * t + 1] = flip ? z : y;
                m->indices[3 * t + 2] = flip ? y : z;
            }
}

ak_result ak_scene_bake_point_frames(const ak_scene_bake_points_desc* desc, const ak_allocator* alloc,
                                     ak_scene** out_scene, ak_diag* diag) {
    if (out_scene) *out_scene = NULL;
    if (!desc || !out_scene || !desc->frames)
        return fail(diag, AK_ERR_NULL_ARG, "bake: a required pointer is NULL%.0zu%.0zu", 0, 0);
    const size_t nf = desc->frame_count;
    if (!nf) return fail(diag, AK_ERR_EMPTY, "bake: %zu frames%.0zu", nf, 0);
    const size_t max_points = desc->max_points ? desc->max_points : AK_SCENE_BAKE_MAX_POINTS;
    if (!(desc->frame_time > 0.0f) || !isfinite(desc->frame_time) || !interp_ok(desc->interp) ||
        !(desc->marker_size >= 0.0f) || !isfinite(desc->marker_size) || max_points > BAKE_POINTS_HARD_MAX)
        return fail(diag, AK_ERR_BAD_ARG,
                    "bake: frame_time must be > 0, interp LINEAR or STEP, marker_size >= 0, max_points <= %zu%.0zu",
                    BAKE_POINTS_HARD_MAX, 0);
    const size_t max_frames = desc->max_frames ? desc->max_frames : AK_SCENE_BAKE_MAX_FRAMES;
    if (nf > max_frames)
        return fail(diag, AK_ERR_UNSUPPORTED, "bake: %zu frames, more than the limit of %zu", nf, max_frames);
    size_t total = 0;
    for (size_t k = 0; k < nf; ++k) {
        const ak_scene_bake_points* f = &desc->frames[k];
        if (f->count && (!f->positions || !f->ids))
            return fail(diag, AK_ERR_NULL_ARG, "bake: frame %zu has %zu points and a NULL array", k, f->count);
        if (f->count > SIZE_MAX / 64 - total)
            return fail(diag, AK_ERR_UNSUPPORTED, "bake: frame %zu: too many points (%zu)", k, f->count);
        total += f->count;
    }
    /* bytes: sorted ids; translation keys (time + value, raw and built); scale keys; per node
     * a joint, channel headers and with markers an octahedron mesh */
    size_t need = 0;
    est(&need, total, sizeof(uint32_t) + 2 * 2 * (sizeof(float) + sizeof(ak_vec3)) + 2 * 2 * 16);
    est(&need, max_points < total ? max_points : total, 1024 + (desc->marker_size > 0.0f ? 1024 : 0));
    const size_t budget = desc->memory_budget ? desc->memory_budget : AK_SCENE_BAKE_DEFAULT_BUDGET;
    if (need > budget)
        return fail(diag, AK_ERR_UNSUPPORTED, "bake: needs about %zu bytes, over the memory budget of %zu", need, budget);
    for (size_t k = 0; k < nf; ++k)
        for (size_t i = 0; i < desc->frames[k].count; ++i)
            if (!ak_vec3_is_finite(desc->frames[k].positions[i]))
                return fail(diag, AK_ERR_BAD_DATA, "bake: frame %zu point %zu is not finite", k, i);

    /* distinct ids, ascending */
    uint32_t* ids = (uint32_t*)malloc((total ? total : 1) * sizeof(uint32_t));
    float* times = (float*)malloc(nf * sizeof(float));
    if (!ids || !times) {
        free(ids);
        free(times);
        return AK_ERR_NO_MEMORY;
    }
    ak_result r = AK_OK;
    if (!frame_times(desc->frame_time, nf, times))
        r = fail(diag, AK_ERR_BAD_ARG, "bake: %zu frames of this frame_time do not give distinct finite times%.0zu", nf, 0);
    size_t o = 0;
    for (size_t k = 0; k < nf; ++k) {
        if (desc->frames[k].count) memcpy(ids + o, desc->frames[k].ids, desc->frames[k].count * sizeof(uint32_t));
        o += desc->frames[k].count;
    }
    qsort(ids, total, sizeof(uint32_t), cmp_u32);
    size_t np = 0;
    for (size_t i = 0; i < total; ++i)
        if (i == 0 || ids[i] != ids[i - 1]) ids[np++] = ids[i];
    if (r == AK_OK && np > max_points)
        r = fail(diag, AK_ERR_UNSUPPORTED, "bake: %zu distinct points, more than the limit of %zu", np, max_points);

    /* per point: key counts, then offsets into one times array and one values array */
    size_t* first = (size_t*)calloc(np + 1, sizeof(size_t));
    size_t* fill = (size_t*)calloc(np + 1, sizeof(size_t));
    size_t* last_frame = (size_t*)calloc(np + 1, sizeof(size_t));
    size_t* scale_keys = (size_t*)calloc(np + 1, sizeof(size_t));
    float* ttimes = (float*)malloc((total ? total : 1) * sizeof(float));
    ak_vec3* tvals = (ak_vec3*)malloc((total ? total : 1) * sizeof(ak_vec3));
    if (r == AK_OK && (!first || !fill || !last_frame || !scale_keys || !ttimes || !tvals)) r = AK_ERR_NO_MEMORY;
    for (size_t k = 0; r == AK_OK && k < nf; ++k)
        for (size_t i = 0; i < desc->frames[k].count; ++i) {
            size_t p = find_id(ids, np, desc->frames[k].ids[i]);
            if (first[p + 1] && last_frame[p] == k + 1) {
                r = fail(diag, AK_ERR_DUPLICATE, "bake: frame %zu: id %zu appears twice", k, desc->frames[k].ids[i]);
                break;
            }
            ++first[p + 1];
            last_frame[p] = k + 1; /* 1-based: 0 means not seen yet */
        }
    for (size_t p = 0; r == AK_OK && p < np; ++p) first[p + 1] += first[p];
    /* fill translation keys in frame order; count alive/missing transitions for the scale */
    bool* alive = (bool*)calloc(np + 1, sizeof(bool));
    bool* was = (bool*)calloc(np + 1, sizeof(bool));
    if (r == AK_OK && (!alive || !was)) r = AK_ERR_NO_MEMORY;
    size_t scale_total = 0;
    for (size_t k = 0; r == AK_OK && k < nf; ++k) {
        memset(alive, 0, np * sizeof(bool));
        for (size_t i = 0; i < desc->frames[k].count; ++i) {
            size_t p = find_id(ids, np, desc->frames[k].ids[i]);
            size_t at = first[p] + fill[p]++;
            ttimes[at] = times[k];
            tvals[at] = desc->frames[k].positions[i];
            alive[p] = true;
        }
        for (size_t p = 0; p < np; ++p)
            if (k == 0 || alive[p] != was[p]) ++scale_keys[p], ++scale_total;
        memcpy(was, alive, np * sizeof(bool));
    }
    float* stimes = (float*)malloc((scale_total ? scale_total : 1) * sizeof(float));
    ak_vec3* svals = (ak_vec3*)malloc((scale_total ? scale_total : 1) * sizeof(ak_vec3));
    size_t* soff = (size_t*)calloc(np + 1, sizeof(size_t));
    ak_raw_channel* ch = (ak_raw_channel*)calloc(2 * np + 1, sizeof(ak_raw_channel));
    ak_vec3* rest = (ak_vec3*)malloc((np ? np : 1) * sizeof(ak_vec3));
    if (r == AK_OK && (!stimes || !svals || !soff || !ch || !rest)) r = AK_ERR_NO_MEMORY;
    for (size_t p = 0; r == AK_OK && p < np; ++p) {
        soff[p + 1] = soff[p] + scale_keys[p];
        rest[p] = tvals[first[p]];
        scale_keys[p] = 0;
    }
    for (size_t k = 0; r == AK_OK && k < nf; ++k) {
        memset(alive, 0, np * sizeof(bool));
        for (size_t i = 0; i < desc->frames[k].count; ++i) alive[find_id(ids, np, desc->frames[k].ids[i])] = true;
        for (size_t p = 0; p < np; ++p)
            if (k == 0 || alive[p] != was[p]) {
                size_t at = soff[p] + scale_keys[p]++;
                stimes[at] = times[k];
                svals[at] = ak_vec3_splat(alive[p] ? 1.0f : 0.0f);
            }
        memcpy(was, alive, np * sizeof(bool));
    }

    const char* name = desc->name ? desc->name : "particles";
    const bool markers = desc->marker_size > 0.0f;
    ak_scene* s = NULL;
    if (r == AK_OK) r = ak_scene_alloc(markers ? np : 0, 0, nf > 1 && np ? 1 : 0, alloc, &s);
    if (r == AK_OK) {
        snprintf(s->name, sizeof s->name, "%s", name);
        r = make_skeleton(s, name, np, ids, rest, diag);
    }
    for (size_t p = 0; r == AK_OK && markers && p < np; ++p) {
        char mname[AK_NAME_SIZE];
        snprintf(mname, sizeof mname, "%.40s_%lu", name, (unsigned long)ids[p]);
        ak_mesh_desc md = {.vertex_count = 6, .triangle_count = 8, .has_normals = true, .name = mname};
        if ((r = ak_mesh_create(&md, &s->alloc, &s->meshes[p].mesh)) != AK_OK) break;
        octahedron(s->meshes[p].mesh, desc->marker_size);
        s->meshes[p].node = (int32_t)(p + 1);
    }
    if (r == AK_OK && s->clip_count) {
        size_t c = 0;
        const ak_interp ti = desc->interp == AK_INTERP_STEP ? AK_INTERP_STEP : AK_INTERP_LINEAR;
        for (size_t p = 0; p < np; ++p) {
            ch[c++] = (ak_raw_channel){.target = AK_CHANNEL_TRANSLATION, .index = (uint32_t)(p + 1), .component_count = 3,
                                       .interp = ti, .key_count = first[p + 1] - first[p], .times = ttimes + first[p],
                                       .values = &tvals[first[p]].x};
            /* a scale channel only for points missing from some frame */
            if (scale_keys[p] > 1 || svals[soff[p]].x == 0.0f)
                ch[c++] = (ak_raw_channel){.target = AK_CHANNEL_SCALE, .index = (uint32_t)(p + 1), .component_count = 3,
                                           .interp = AK_INTERP_STEP, .key_count = scale_keys[p],
                                           .times = stimes + soff[p], .values = &svals[soff[p]].x};
        }
        ak_raw_clip raw = {.name = name, .duration = times[nf - 1], .channels = ch, .channel_count = c,
                           .joint_count = np + 1};
        r = ak_clip_build(&raw, &s->alloc, &s->clips[0], diag);
    }
    free(ids), free(times), free(first), free(fill), free(last_frame), free(scale_keys), free(ttimes), free(tvals);
    free(alive), free(was), free(stimes), free(svals), free(soff), free(ch), free(rest);
    if (r != AK_OK) {
        ak_scene_destroy(s);
        return r;
    }
    *out_scene = s;
    return AK_OK;
}
