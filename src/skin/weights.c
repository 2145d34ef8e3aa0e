/* Skin weights shared pieces: bones from joints, the desc defaults, post-processing
 * (k largest, drop tiny, renormalise), validation, the weights file format, and the
 * dispatch to the distance and heat methods. */
#include "skin_internal.h"
#include "weights_internal.h"

/* ---- bones --------------------------------------------------------------------------- */

size_t ak_skin_bones_from_joints_bound(size_t joint_count) { return 2u * joint_count; }

ak_result ak_skin_bones_from_joints(ak_vec3_cspan joint_positions, ak_i32_cspan parents, bool skip_leaf_joints,
                                    ak_skin_bone_span out_bones, size_t* out_bone_count) {
    if (!joint_positions.ptr || !parents.ptr || !out_bones.ptr || !out_bone_count) return AK_ERR_NULL_ARG;
    const size_t n = joint_positions.count;
    *out_bone_count = 0;
    if (n == 0) return AK_ERR_EMPTY;
    if (n > 65535) return AK_ERR_BAD_ARG;
    if (parents.count < n) return AK_ERR_SPAN_SMALL;
    for (size_t i = 0; i < n; ++i)
        if (parents.ptr[i] < -1 || (parents.ptr[i] >= 0 && (size_t)parents.ptr[i] >= i)) return AK_ERR_BAD_HIERARCHY;
    size_t count = 0;
    for (size_t i = 0; i < n; ++i) {
        bool has_child = false;
        for (size_t c = i + 1; c < n; ++c) {
            if (parents.ptr[c] != (int32_t)i) continue;
            has_child = true;
            if (count >= out_bones.count) return AK_ERR_SPAN_SMALL;
            ak_skin_bone b = {joint_positions.ptr[i], joint_positions.ptr[c], (uint16_t)i};
            out_bones.ptr[count++] = b;
        }
        if (!has_child && !skip_leaf_joints) {
            if (count >= out_bones.count) return AK_ERR_SPAN_SMALL;
            ak_skin_bone b = {joint_positions.ptr[i], joint_positions.ptr[i], (uint16_t)i};
            out_bones.ptr[count++] = b;
        }
    }
    *out_bone_count = count;
    return AK_OK;
}

/* ---- desc ------------------------------------------------------------------------------ */

ak_weights_desc ak_weights_desc_resolved(const ak_weights_desc* desc) {
    ak_weights_desc d;
    memset(&d, 0, sizeof d);
    if (desc) d = *desc;
    if (d.max_influences == 0) d.max_influences = 4;
    if (d.min_weight == 0.0f) d.min_weight = 0.001f;
    if (d.distance_power == 0.0f) d.distance_power = 4.0f;
    if (d.heat_strength == 0.0f) d.heat_strength = 1.0f;
    return d;
}

/* ---- post-processing -------------------------------------------------------------------- */

void akp_weights_finish(const double* dense, size_t joint_count, uint32_t k, float min_weight, uint16_t fallback_joint,
                        uint16_t* out_joints, float* out_weights) {
    double total = 0.0;
    for (size_t j = 0; j < joint_count; ++j)
        if (dense[j] > 0.0 && dense[j] < 1e300) total += dense[j];
    uint16_t bj[AK_MAX_INFLUENCES];
    double bw[AK_MAX_INFLUENCES];
    uint32_t n = 0;
    if (total > 0.0) {
        const double cut = min_weight > 0.0f ? (double)min_weight : 0.0;
        for (size_t j = 0; j < joint_count; ++j) {
            double w = dense[j] / total;
            if (!(w > 0.0) || !(w < 1e300)) continue;
            /* insertion into the sorted top-k (ties keep the lower joint index first) */
            if (n == k && w <= bw[k - 1]) continue;
            uint32_t pos = n < k ? n : k - 1;
            while (pos > 0 && bw[pos - 1] < w) {
                if (pos < k) {
                    bw[pos] = bw[pos - 1];
                    bj[pos] = bj[pos - 1];
                }
                --pos;
            }
            bw[pos] = w;
            bj[pos] = (uint16_t)j;
            if (n < k) ++n;
        }
        /* drop tiny weights, but always keep the largest */
        while (n > 1 && bw[n - 1] < cut) --n;
    }
    if (n == 0) {
        bj[0] = fallback_joint;
        bw[0] = 1.0;
        n = 1;
    }
    double sum = 0.0;
    for (uint32_t i = 0; i < n; ++i) sum += bw[i];
    double rest = 0.0;
    for (uint32_t i = 1; i < n; ++i) {
        out_weights[i] = (float)(bw[i] / sum);
        rest += out_weights[i];
        out_joints[i] = bj[i];
    }
    out_joints[0] = bj[0];
    out_weights[0] = (float)(1.0 - rest); /* the largest absorbs the rounding: sum is 1 to float precision */
    for (uint32_t i = n; i < k; ++i) {
        out_joints[i] = 0;
        out_weights[i] = 0.0f;
    }
}

/* ---- compute ---------------------------------------------------------------------------- */

ak_result ak_skin_weights_compute(const ak_weights_desc* desc, const ak_allocator* alloc, ak_u16_span out_joints,
                                  ak_f32_span out_weights) {
    if (!desc || !desc->positions.ptr || !desc->bones.ptr || !out_joints.ptr || !out_weights.ptr)
        return AK_ERR_NULL_ARG;
    ak_weights_desc d = ak_weights_desc_resolved(desc);
    const size_t n = d.positions.count;
    if (n == 0 || d.bones.count == 0) return AK_ERR_EMPTY;
    if ((unsigned)d.method >= AK_WEIGHTS_METHOD_COUNT || d.max_influences > AK_MAX_INFLUENCES ||
        d.indices.count % 3 != 0 || !(d.distance_power > 0.0f) || !ak_finitef(d.distance_power) ||
        !(d.heat_strength > 0.0f) || !ak_finitef(d.heat_strength))
        return AK_ERR_BAD_ARG;
    if (d.method == AK_WEIGHTS_HEAT && (!d.indices.ptr || d.indices.count == 0)) return AK_ERR_EMPTY;
    for (size_t i = 0; i < d.indices.count; ++i)
        if (d.indices.ptr[i] >= n) return AK_ERR_BAD_INDEX;
    for (size_t i = 0; i < n; ++i)
        if (!ak_vec3_is_finite(d.positions.ptr[i])) return AK_ERR_BAD_DATA;
    for (size_t b = 0; b < d.bones.count; ++b)
        if (!ak_vec3_is_finite(d.bones.ptr[b].head) || !ak_vec3_is_finite(d.bones.ptr[b].tail)) return AK_ERR_BAD_DATA;
    if (n > SIZE_MAX / d.max_influences || out_joints.count < n * d.max_influences ||
        out_weights.count < n * d.max_influences)
        return AK_ERR_SPAN_SMALL;
    if (d.method == AK_WEIGHTS_DISTANCE) return akp_weights_distance(&d, alloc, out_joints.ptr, out_weights.ptr);
    return akp_weights_heat(&d, alloc, out_joints.ptr, out_weights.ptr);
}

ak_result ak_skin_weights_validate(ak_u16_cspan joints, ak_f32_cspan weights, size_t vertex_count,
                                   uint32_t influence_count, size_t joint_count, float tolerance,
                                   size_t* out_bad_vertex) {
    if (!joints.ptr || !weights.ptr) return AK_ERR_NULL_ARG;
    if (influence_count == 0 || influence_count > AK_MAX_INFLUENCES) return AK_ERR_BAD_ARG;
    const size_t k = influence_count;
    if (vertex_count > SIZE_MAX / k || joints.count < vertex_count * k || weights.count < vertex_count * k)
        return AK_ERR_SPAN_SMALL;
    const double tol = tolerance > 0.0f ? tolerance : 1e-3;
    for (size_t v = 0; v < vertex_count; ++v) {
        double sum = 0.0;
        ak_result r = AK_OK;
        for (size_t e = 0; e < k; ++e) {
            float w = weights.ptr[v * k + e];
            if (!(w >= 0.0f) || !ak_finitef(w)) r = AK_ERR_BAD_WEIGHTS;
            sum += w;
        }
        if (r == AK_OK && !(fabs(sum - 1.0) <= tol)) r = AK_ERR_BAD_WEIGHTS;
        for (size_t e = 0; r == AK_OK && e < k; ++e)
            if (joints.ptr[v * k + e] >= joint_count) r = AK_ERR_BAD_INDEX;
        if (r != AK_OK) {
            if (out_bad_vertex) *out_bad_vertex = v;
            return r;
        }
    }
    return AK_OK;
}

/* ---- file format ------------------------------------------------------------------------ */

static size_t joints_bytes_padded(size_t count) { return (count * 2u + 3u) & ~(size_t)3u; }

size_t ak_skin_weights_encoded_size(size_t vertex_count, uint32_t influence_count) {
    if (influence_count == 0 || influence_count > AK_MAX_INFLUENCES || vertex_count > 0xFFFFFFFFu) return 0;
    size_t c = vertex_count * influence_count;
    return 16u + joints_bytes_padded(c) + c * 4u;
}

ak_result ak_skin_weights_encode(ak_u16_cspan joints, ak_f32_cspan weights, size_t vertex_count,
                                 uint32_t influence_count, ak_u8_span out_buffer, size_t* out_size) {
    if (!joints.ptr || !weights.ptr || !out_buffer.ptr) return AK_ERR_NULL_ARG;
    size_t size = ak_skin_weights_encoded_size(vertex_count, influence_count);
    if (size == 0) return AK_ERR_BAD_ARG;
    const size_t c = vertex_count * influence_count;
    if (joints.count < c || weights.count < c || out_buffer.count < size) return AK_ERR_SPAN_SMALL;
    unsigned char* p = out_buffer.ptr;
    memcpy(p, "AKWT", 4);
    akp_put_u32(p + 4, 1u);
    akp_put_u32(p + 8, (uint32_t)vertex_count);
    akp_put_u32(p + 12, influence_count);
    p += 16;
    for (size_t i = 0; i < c; ++i) {
        p[2 * i] = (unsigned char)(joints.ptr[i] & 0xFF);
        p[2 * i + 1] = (unsigned char)(joints.ptr[i] >> 8);
    }
    memset(p + 2 * c, 0, joints_bytes_padded(c) - 2 * c);
    p += joints_bytes_padded(c);
    for (size_t i = 0; i < c; ++i) akp_put_f32(p + 4 * i, weights.ptr[i]);
    if (out_size) *out_size = size;
    return AK_OK;
}

ak_result ak_skin_weights_decode_info(ak_u8_cspan buffer, size_t* out_vertex_count, uint32_t* out_influence_count,
                                      ak_diag* diag) {
    if (!buffer.ptr || !out_vertex_count || !out_influence_count) return AK_ERR_NULL_ARG;
    if (buffer.count < 16 || memcmp(buffer.ptr, "AKWT", 4) != 0) {
        akp_diag_set(diag, NULL, "not an animkit weights buffer (magic AKWT missing)");
        return AK_ERR_PARSE;
    }
    uint32_t version = akp_get_u32(buffer.ptr + 4), vc = akp_get_u32(buffer.ptr + 8), k = akp_get_u32(buffer.ptr + 12);
    if (version != 1 || k == 0 || k > AK_MAX_INFLUENCES) {
        akp_diag_set(diag, NULL, "weights buffer: unsupported version %u or influence count %u", version, k);
        return AK_ERR_PARSE;
    }
    size_t need = ak_skin_weights_encoded_size(vc, k);
    if (buffer.count < need) {
        akp_diag_set(diag, NULL, "weights buffer truncated: %zu bytes, header needs %zu", buffer.count, need);
        if (diag) diag->byte_offset = (long)buffer.count;
        return AK_ERR_PARSE;
    }
    *out_vertex_count = vc;
    *out_influence_count = k;
    return AK_OK;
}

ak_result ak_skin_weights_decode(ak_u8_cspan buffer, ak_u16_span out_joints, ak_f32_span out_weights, ak_diag* diag) {
    if (!out_joints.ptr || !out_weights.ptr) return AK_ERR_NULL_ARG;
    size_t vc = 0;
    uint32_t k = 0;
    ak_result r = ak_skin_weights_decode_info(buffer, &vc, &k, diag);
    if (r != AK_OK) return r;
    const size_t c = vc * k;
    if (out_joints.count < c || out_weights.count < c) return AK_ERR_SPAN_SMALL;
    const unsigned char* p = buffer.ptr + 16;
    for (size_t i = 0; i < c; ++i) out_joints.ptr[i] = (uint16_t)(p[2 * i] | (p[2 * i + 1] << 8));
    p += joints_bytes_padded(c);
    for (size_t i = 0; i < c; ++i) out_weights.ptr[i] = akp_get_f32(p + 4 * i);
    return AK_OK;
}

ak_result ak_skin_weights_write_file(const char* path, ak_u16_cspan joints, ak_f32_cspan weights, size_t vertex_count,
                                     uint32_t influence_count) {
    if (!path) return AK_ERR_NULL_ARG;
    size_t size = ak_skin_weights_encoded_size(vertex_count, influence_count);
    if (size == 0) return AK_ERR_BAD_ARG;
    unsigned char* buf = (unsigned char*)malloc(size);
    if (!buf) return AK_ERR_NO_MEMORY;
    ak_u8_span span = {buf, size};
    ak_result r = ak_skin_weights_encode(joints, weights, vertex_count, influence_count, span, NULL);
    if (r == AK_OK) r = akp_write_file(path, buf, size);
    free(buf);
    return r;
}

/* Read a whole file into a malloc'd buffer. */
static ak_result read_all(const char* path, unsigned char** out, size_t* out_size) {
    FILE* f = fopen(path, "rb");
    if (!f) return AK_ERR_IO;
    size_t cap = 1 << 16, len = 0;
    unsigned char* buf = (unsigned char*)malloc(cap);
    if (!buf) {
        fclose(f);
        return AK_ERR_NO_MEMORY;
    }
    for (;;) {
        if (len == cap) {
            unsigned char* nb = (unsigned char*)realloc(buf, cap * 2);
            if (!nb) {
                free(buf);
                fclose(f);
                return AK_ERR_NO_MEMORY;
            }
            buf = nb;
            cap *= 2;
        }
        size_t got = fread(buf + len, 1, cap - len, f);
        len += got;
        if (got == 0) break;
    }
    bool err = ferror(f) != 0;
    fclose(f);
    if (err) {
        free(buf);
        return AK_ERR_IO;
    }
    *out = buf;
    *out_size = len;
    return AK_OK;
}

ak_result akp_read_file(const char* path, unsigned char** out, size_t* out_size) { return read_all(path, out, out_size); }

ak_result akp_write_file(const char* path, const unsigned char* buf, size_t size) {
    ak_atomic_file out; /* a temporary renamed over path once complete (internal.h) */
    if (ak_atomic_file_open(&out, path) != AK_OK) return AK_ERR_IO;
    if (fwrite(buf, 1, size, out.f) != size) {
        ak_atomic_file_abort(&out);
        return AK_ERR_IO;
    }
    return ak_atomic_file_commit(&out);
}

/* Read a weights file and decode it: the header only (out_joints NULL) or everything. The
 * diag names the file whichever step fails. */
static ak_result read_weights_file(const char* path, size_t* out_vertex_count, uint32_t* out_influence_count,
                                   ak_u16_span out_joints, ak_f32_span out_weights, ak_diag* diag) {
    unsigned char* buf = NULL;
    size_t size = 0;
    ak_result r = read_all(path, &buf, &size);
    if (r != AK_OK) {
        akp_diag_set(diag, path, "cannot read the weights file");
        return r;
    }
    ak_u8_cspan span = {buf, size};
    r = out_joints.ptr ? ak_skin_weights_decode(span, out_joints, out_weights, diag)
                       : ak_skin_weights_decode_info(span, out_vertex_count, out_influence_count, diag);
    if (r != AK_OK && diag) snprintf(diag->path, sizeof diag->path, "%s", path);
    free(buf);
    return r;
}

ak_result ak_skin_weights_read_file_info(const char* path, size_t* out_vertex_count, uint32_t* out_influence_count,
                                         ak_diag* diag) {
    if (!path || !out_vertex_count || !out_influence_count) return AK_ERR_NULL_ARG;
    return read_weights_file(path, out_vertex_count, out_influence_count, (ak_u16_span){NULL, 0},
                             (ak_f32_span){NULL, 0}, diag);
}

ak_result ak_skin_weights_read_file(const char* path, ak_u16_span out_joints, ak_f32_span out_weights, ak_diag* diag) {
    if (!path || !out_joints.ptr || !out_weights.ptr) return AK_ERR_NULL_ARG;
    return read_weights_file(path, NULL, NULL, out_joints, out_weights, diag);
}
