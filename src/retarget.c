/* Retargeting: joint mapping by name, rest-pose-relative rotation transfer in model space,
 * scaled root motion, foot-contact clean-up with the two-bone IK, baking (retarget.h). */
#include <animkit/ik.h>
#include <animkit/retarget.h>
#include <ctype.h>
#include <stdio.h>

#include "internal.h"

/* ---- private types ---------------------------------------------------------------------- */

typedef struct bone_name {
    const char* core; /* lower case, separators removed, side removed */
    int bone;         /* side-less bone: the LEFT_ value for sided bones */
    bool sided;
} bone_name;

/* Core names after lower-casing, dropping everything up to ':', separators and the side. */
static const bone_name k_names[] = {
    {"hips", AK_BONE_HIPS, false},        {"pelvis", AK_BONE_HIPS, false},     {"hip", AK_BONE_HIPS, false},
    {"spine", AK_BONE_SPINE, false},      {"spine0", AK_BONE_SPINE, false},    {"spine01", AK_BONE_SPINE, false},
    {"spine1", AK_BONE_SPINE, false},     {"spine02", AK_BONE_SPINE, false},   {"spine2", AK_BONE_SPINE, false},
    {"spine03", AK_BONE_SPINE, false},    {"spine3", AK_BONE_SPINE, false},    {"lowerback", AK_BONE_SPINE, false},
    {"chest", AK_BONE_SPINE, false},      {"upperchest", AK_BONE_SPINE, false}, {"abdomen", AK_BONE_SPINE, false},
    {"torso", AK_BONE_SPINE, false},
    {"neck", AK_BONE_NECK, false},        {"neck01", AK_BONE_NECK, false},     {"neck1", AK_BONE_NECK, false},
    {"head", AK_BONE_HEAD, false},
    {"shoulder", AK_BONE_LEFT_SHOULDER, true}, {"clavicle", AK_BONE_LEFT_SHOULDER, true},
    {"collar", AK_BONE_LEFT_SHOULDER, true},
    {"arm", AK_BONE_LEFT_UPPER_ARM, true},     {"upperarm", AK_BONE_LEFT_UPPER_ARM, true},
    {"uparm", AK_BONE_LEFT_UPPER_ARM, true},   {"humerus", AK_BONE_LEFT_UPPER_ARM, true},
    {"forearm", AK_BONE_LEFT_LOWER_ARM, true}, {"lowerarm", AK_BONE_LEFT_LOWER_ARM, true},
    {"elbow", AK_BONE_LEFT_LOWER_ARM, true},
    {"hand", AK_BONE_LEFT_HAND, true},         {"wrist", AK_BONE_LEFT_HAND, true},
    {"upleg", AK_BONE_LEFT_UPPER_LEG, true},   {"upperleg", AK_BONE_LEFT_UPPER_LEG, true},
    {"thigh", AK_BONE_LEFT_UPPER_LEG, true},   {"hip", AK_BONE_LEFT_UPPER_LEG, true},
    {"femur", AK_BONE_LEFT_UPPER_LEG, true},
    {"leg", AK_BONE_LEFT_LOWER_LEG, true},     {"lowerleg", AK_BONE_LEFT_LOWER_LEG, true},
    {"calf", AK_BONE_LEFT_LOWER_LEG, true},    {"knee", AK_BONE_LEFT_LOWER_LEG, true},
    {"shin", AK_BONE_LEFT_LOWER_LEG, true},
    {"foot", AK_BONE_LEFT_FOOT, true},         {"ankle", AK_BONE_LEFT_FOOT, true},
    {"toe", AK_BONE_LEFT_TOES, true},          {"toes", AK_BONE_LEFT_TOES, true},
    {"toebase", AK_BONE_LEFT_TOES, true},      {"ball", AK_BONE_LEFT_TOES, true},
};

static const char* const k_bone_names[AK_BONE_COUNT] = {
    "none",          "hips",          "spine",         "chest",          "upperChest",   "neck",
    "head",          "leftShoulder",  "leftUpperArm",  "leftLowerArm",   "leftHand",     "rightShoulder",
    "rightUpperArm", "rightLowerArm", "rightHand",     "leftUpperLeg",   "leftLowerLeg", "leftFoot",
    "leftToes",      "rightUpperLeg", "rightLowerLeg", "rightFoot",      "rightToes",
};

/* ---- static helpers --------------------------------------------------------------------- */

/* Lower-case copy without separators, after the last ':'. */
static void normalise(const char* name, char out[AK_NAME_SIZE]) {
    const char* colon = strrchr(name, ':');
    const char* s = colon ? colon + 1 : name;
    size_t o = 0;
    for (; *s && o + 1 < AK_NAME_SIZE; ++s) {
        unsigned char ch = (unsigned char)*s;
        if (isalnum(ch)) out[o++] = (char)tolower(ch);
    }
    out[o] = '\0';
}

static int right_of(int left_bone) {
    return left_bone >= AK_BONE_LEFT_SHOULDER && left_bone <= AK_BONE_LEFT_HAND
               ? left_bone + (AK_BONE_RIGHT_SHOULDER - AK_BONE_LEFT_SHOULDER)
               : left_bone + (AK_BONE_RIGHT_UPPER_LEG - AK_BONE_LEFT_UPPER_LEG);
}

/* Mixamo/CMU digits after a bone ("Spine1", "Neck1") are kept in the core; builtin/Unreal
 * style trailing "_01" indices are part of spine/neck names only. */
static int lookup(const char* core, bool sided) {
    for (size_t i = 0; i < sizeof k_names / sizeof k_names[0]; ++i)
        if (k_names[i].sided == sided && strcmp(core, k_names[i].core) == 0) return k_names[i].bone;
    return AK_BONE_NONE;
}

/* Quaternion chain FK: model-space rotations (uniform scales assumed). */
static void model_rotations(const ak_skeleton* sk, const ak_transform* local, ak_quat* out) {
    ak_i16_cspan parents = ak_skeleton_parents(sk);
    for (size_t j = 0; j < parents.count; ++j)
        out[j] = parents.ptr[j] < 0 ? local[j].rotation
                                    : ak_quat_normalize(ak_quat_mul(out[parents.ptr[j]], local[j].rotation));
}

static ak_vec3 model_position(const ak_mat4* m) { return ak_mat4_get_translation(*m); }

static bool is_ancestor(const ak_skeleton* sk, int a, int j) {
    ak_i16_cspan p = ak_skeleton_parents(sk);
    while (j >= 0) {
        if (j == a) return true;
        j = p.ptr[j];
    }
    return false;
}

/* ---- public ----------------------------------------------------------------------------- */

const char* ak_humanoid_bone_name(ak_humanoid_bone bone) {
    return (unsigned)bone < (unsigned)AK_BONE_COUNT ? k_bone_names[bone] : "none";
}

ak_humanoid_bone ak_humanoid_bone_of_name(const char* name) {
    if (!name) return AK_BONE_NONE;
    char n[AK_NAME_SIZE];
    normalise(name, n);
    const char* colon = strrchr(name, ':');
    const char* raw = colon ? colon + 1 : name;
    size_t len = strlen(n), rlen = strlen(raw);
    int b = lookup(n, false);
    if (b) return (ak_humanoid_bone)b;
    /* side: Left/Right prefix or suffix, L/R prefix before an upper-case letter or a separator,
     * _l/_r/.l/.r suffix */
    int side = 0; /* 1 left, 2 right */
    char core[AK_NAME_SIZE] = "";
    if (!strncmp(n, "left", 4)) side = 1, snprintf(core, sizeof core, "%s", n + 4);
    else if (!strncmp(n, "right", 5)) side = 2, snprintf(core, sizeof core, "%s", n + 5);
    else if (len > 4 && !strcmp(n + len - 4, "left")) side = 1, snprintf(core, sizeof core, "%.*s", (int)(len - 4), n);
    else if (len > 5 && !strcmp(n + len - 5, "right")) side = 2, snprintf(core, sizeof core, "%.*s", (int)(len - 5), n);
    else if (rlen > 2 && (raw[0] == 'L' || raw[0] == 'R') && (isupper((unsigned char)raw[1]) || raw[1] == '_' || raw[1] == '.'))
        side = raw[0] == 'L' ? 1 : 2, snprintf(core, sizeof core, "%s", n + 1);
    else if (rlen > 2 && (raw[rlen - 2] == '_' || raw[rlen - 2] == '.' || raw[rlen - 2] == ' ') &&
             (tolower((unsigned char)raw[rlen - 1]) == 'l' || tolower((unsigned char)raw[rlen - 1]) == 'r'))
        side = tolower((unsigned char)raw[rlen - 1]) == 'l' ? 1 : 2, snprintf(core, sizeof core, "%.*s", (int)(len - 1), n);
    if (!side) return AK_BONE_NONE;
    /* Unreal numbers its bones ("upperarm_twist_01_l" is not the arm; "thigh_l" is) */
    b = lookup(core, true);
    if (!b) return AK_BONE_NONE;
    return (ak_humanoid_bone)(side == 1 ? b : right_of(b));
}

ak_result ak_humanoid_bones_of_skeleton(const ak_skeleton* skeleton, ak_i32_span out_bones) {
    if (!skeleton || !out_bones.ptr) return AK_ERR_NULL_ARG;
    size_t n = ak_skeleton_joint_count(skeleton);
    if (out_bones.count < n) return AK_ERR_SPAN_SMALL;
    ak_i16_cspan parents = ak_skeleton_parents(skeleton);
    int32_t* b = out_bones.ptr;
    bool taken[AK_BONE_COUNT] = {false};
    for (size_t j = 0; j < n; ++j) b[j] = (int32_t)ak_humanoid_bone_of_name(ak_skeleton_joint_name(skeleton, j));
    /* a SHOULDER whose child is the LOWER_ARM is the UPPER_ARM */
    for (size_t j = 0; j < n; ++j) {
        if (parents.ptr[j] < 0) continue;
        int32_t p = parents.ptr[j];
        if (b[j] == AK_BONE_LEFT_LOWER_ARM && b[p] == AK_BONE_LEFT_SHOULDER) b[p] = AK_BONE_LEFT_UPPER_ARM;
        if (b[j] == AK_BONE_RIGHT_LOWER_ARM && b[p] == AK_BONE_RIGHT_SHOULDER) b[p] = AK_BONE_RIGHT_UPPER_ARM;
    }
    /* first claim wins */
    for (size_t j = 0; j < n; ++j) {
        if (b[j] == AK_BONE_SPINE) continue;
        if (b[j] != AK_BONE_NONE && taken[b[j]]) b[j] = AK_BONE_NONE;
        if (b[j] != AK_BONE_NONE) taken[b[j]] = true;
    }
    /* spine joints between the hips and the neck, in hierarchy order */
    int hips = -1, neck = -1;
    for (size_t j = 0; j < n; ++j) {
        if (b[j] == AK_BONE_HIPS) hips = (int)j;
        if (b[j] == AK_BONE_NECK) neck = (int)j;
    }
    int next = AK_BONE_SPINE;
    for (size_t j = 0; j < n; ++j) {
        if (b[j] != AK_BONE_SPINE) continue;
        bool on_path = neck >= 0 && is_ancestor(skeleton, (int)j, neck) && (hips < 0 || is_ancestor(skeleton, hips, (int)j));
        b[j] = on_path && next <= AK_BONE_UPPER_CHEST ? next++ : AK_BONE_NONE;
    }
    return AK_OK;
}

ak_result ak_retarget_map_by_name(const ak_skeleton* source, const ak_skeleton* target, ak_i32_span out,
                                  size_t* out_mapped_count) {
    if (out_mapped_count) *out_mapped_count = 0;
    if (!source || !target || !out.ptr) return AK_ERR_NULL_ARG;
    size_t ns = ak_skeleton_joint_count(source), nt = ak_skeleton_joint_count(target);
    if (out.count < nt) return AK_ERR_SPAN_SMALL;
    int32_t* sb = (int32_t*)malloc((ns + 1) * sizeof(int32_t));
    int32_t* tb = (int32_t*)malloc((nt + 1) * sizeof(int32_t));
    bool* used = (bool*)calloc(ns + 1, sizeof(bool));
    if (!sb || !tb || !used) {
        free(sb), free(tb), free(used);
        return AK_ERR_NO_MEMORY;
    }
    ak_humanoid_bones_of_skeleton(source, (ak_i32_span){sb, ns});
    ak_humanoid_bones_of_skeleton(target, (ak_i32_span){tb, nt});
    size_t mapped = 0;
    for (size_t k = 0; k < nt; ++k) {
        out.ptr[k] = -1;
        char a[AK_NAME_SIZE], b[AK_NAME_SIZE];
        normalise(ak_skeleton_joint_name(target, k), a);
        for (size_t j = 0; j < ns && a[0]; ++j) {
            /* the same name for two different bones is no match: builtin:humanoid's
             * left_shoulder is its upper arm, a CMU LeftShoulder is the collarbone */
            if (tb[k] != AK_BONE_NONE && sb[j] != AK_BONE_NONE && tb[k] != sb[j]) continue;
            normalise(ak_skeleton_joint_name(source, j), b);
            if (!used[j] && strcmp(a, b) == 0) {
                out.ptr[k] = (int32_t)j;
                used[j] = true;
                break;
            }
        }
    }
    for (size_t k = 0; k < nt; ++k) {
        for (size_t j = 0; j < ns && out.ptr[k] < 0 && tb[k] != AK_BONE_NONE; ++j)
            if (!used[j] && sb[j] == tb[k]) {
                out.ptr[k] = (int32_t)j;
                used[j] = true;
            }
        if (out.ptr[k] >= 0) ++mapped;
    }
    free(sb), free(tb), free(used);
    if (out_mapped_count) *out_mapped_count = mapped;
    return AK_OK;
}

/* A name of a map line, trimmed, copied NUL-terminated into out; false when empty or too long. */
static bool map_name(const char* s, size_t n, char out[AK_NAME_SIZE]) {
    while (n && (*s == ' ' || *s == '\t')) ++s, --n;
    while (n && (s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\r')) --n;
    if (n == 0 || n >= AK_NAME_SIZE) return false;
    memcpy(out, s, n);
    out[n] = '\0';
    return true;
}

/* Fail with "line N: ..." in the diag. */
#if defined(__GNUC__)
__attribute__((format(printf, 4, 5)))
#endif
static ak_result map_fail(ak_diag* diag, ak_result r, long line, const char* fmt, ...) {
    if (diag) {
        char msg[sizeof diag->message];
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(msg, sizeof msg, fmt, ap);
        va_end(ap);
        akp_diag_set(diag, NULL, "%s", msg);
        diag->line = line;
    }
    return r;
}

ak_result ak_retarget_map_parse(const char* text, size_t text_size, const ak_skeleton* source,
                                const ak_skeleton* target, ak_i32_span out, size_t* out_mapped_count, ak_diag* diag) {
    if (out_mapped_count) *out_mapped_count = 0;
    if (!source || !target || !out.ptr || (!text && text_size > 0))
        return map_fail(diag, AK_ERR_NULL_ARG, 0, "a skeleton, the map span or the text is NULL");
    const size_t nt = ak_skeleton_joint_count(target);
    if (out.count < nt) return map_fail(diag, AK_ERR_SPAN_SMALL, 0, "the map span holds %zu entries, fewer than the "
                                        "target's %zu joints", out.count, nt);
    for (size_t k = 0; k < nt; ++k) out.ptr[k] = -1;
    size_t mapped = 0;
    long line = 1;
    for (size_t at = 0; at < text_size; ++line) {
        const char* s = text + at;
        const char* nl = (const char*)memchr(s, '\n', text_size - at);
        size_t n = nl ? (size_t)(nl - s) : text_size - at;
        at += n + (nl ? 1 : 0);
        if (memchr(s, '\0', n)) {
            for (size_t k = 0; k < nt; ++k) out.ptr[k] = -1;
            return map_fail(diag, AK_ERR_PARSE, line, "line %ld holds a NUL byte", line);
        }
        const char* hash = (const char*)memchr(s, '#', n);
        if (hash) n = (size_t)(hash - s);
        size_t blank = 0;
        while (blank < n && (s[blank] == ' ' || s[blank] == '\t' || s[blank] == '\r')) ++blank;
        if (blank == n) continue;
        const char* eq = (const char*)memchr(s, '=', n);
        char tn[AK_NAME_SIZE], sn[AK_NAME_SIZE];
        ak_result r = AK_OK;
        if (!eq || !map_name(s, (size_t)(eq - s), tn) || !map_name(eq + 1, n - (size_t)(eq - s) - 1, sn)) {
            r = map_fail(diag, AK_ERR_PARSE, line,
                         "line %ld: expected 'TARGET_JOINT = SOURCE_JOINT' (names of 1 to %d bytes)", line,
                         AK_NAME_SIZE - 1);
        } else {
            const int tj = ak_skeleton_find_joint(target, tn), sj = ak_skeleton_find_joint(source, sn);
            if (tj < 0) r = map_fail(diag, AK_ERR_NOT_FOUND, line, "line %ld: the target has no joint '%s'", line, tn);
            else if (sj < 0) r = map_fail(diag, AK_ERR_NOT_FOUND, line, "line %ld: the source has no joint '%s'", line, sn);
            else if (out.ptr[tj] >= 0)
                r = map_fail(diag, AK_ERR_DUPLICATE, line, "line %ld: target joint '%s' is mapped twice", line, tn);
            else out.ptr[tj] = sj, ++mapped;
        }
        if (r != AK_OK) {
            for (size_t k = 0; k < nt; ++k) out.ptr[k] = -1;
            return r;
        }
    }
    if (mapped == 0) return map_fail(diag, AK_ERR_EMPTY, 0, "the map maps no joint");
    if (out_mapped_count) *out_mapped_count = mapped;
    return AK_OK;
}

ak_retarget_desc ak_retarget_desc_resolved(const ak_retarget_desc* desc) {
    ak_retarget_desc d;
    memset(&d, 0, sizeof d);
    if (desc) d = *desc;
    if (d.frame_rate == 0.0f) d.frame_rate = 30.0f;
    if (d.contact_height == 0.0f) d.contact_height = 0.08f;
    if (d.contact_speed == 0.0f) d.contact_speed = 0.6f;
    if (!d.name && d.clip) d.name = ak_clip_name(d.clip);
    return d;
}

/* Length hip -> knee -> ankle of one leg in the rest pose (0 when not found). */
static float leg_length(const ak_skeleton* sk, const int32_t* bones, const ak_mat4* rest_model, int upper) {
    int u = -1, l = -1, f = -1;
    size_t n = ak_skeleton_joint_count(sk);
    for (size_t j = 0; j < n; ++j) {
        if (bones[j] == upper) u = (int)j;
        if (bones[j] == upper + 1) l = (int)j;
        if (bones[j] == upper + 2) f = (int)j;
    }
    if (u < 0 || l < 0 || f < 0) return 0.0f;
    return ak_vec3_length(ak_vec3_sub(model_position(&rest_model[l]), model_position(&rest_model[u]))) +
           ak_vec3_length(ak_vec3_sub(model_position(&rest_model[f]), model_position(&rest_model[l])));
}

static int find_bone(const int32_t* bones, size_t n, int bone) {
    for (size_t j = 0; j < n; ++j)
        if (bones[j] == bone) return (int)j;
    return -1;
}

ak_result ak_retarget_clip(const ak_retarget_desc* desc_in, const ak_allocator* alloc, ak_clip** out_clip,
                           ak_retarget_stats* out_stats, ak_diag* diag) {
    if (out_clip) *out_clip = NULL;
    if (out_stats) memset(out_stats, 0, sizeof *out_stats);
    if (!desc_in || !out_clip || !desc_in->source || !desc_in->clip || !desc_in->target) {
        akp_diag_set(diag, NULL, "desc, source, clip, target and out_clip are required");
        return AK_ERR_NULL_ARG;
    }
    ak_retarget_desc d = ak_retarget_desc_resolved(desc_in);
    if (!(d.frame_rate > 0.0f) || !ak_finitef(d.frame_rate) || !(d.contact_height > 0.0f) ||
        !ak_finitef(d.contact_height) || !(d.contact_speed > 0.0f) || !ak_finitef(d.contact_speed)) {
        akp_diag_set(diag, NULL, "frame_rate, contact_height and contact_speed must be positive and finite");
        return AK_ERR_BAD_ARG;
    }
    const ak_skeleton *src = d.source, *dst = d.target;
    size_t ns = ak_skeleton_joint_count(src), nt = ak_skeleton_joint_count(dst);
    if (ak_clip_joint_count(d.clip) > ns) {
        akp_diag_set(diag, NULL, "the clip animates %zu joints, the source skeleton has %zu", ak_clip_joint_count(d.clip), ns);
        return AK_ERR_BAD_INDEX;
    }
    if (d.source_of_target.ptr && d.source_of_target.count < nt) {
        akp_diag_set(diag, NULL, "the map has %zu entries, the target has %zu joints", d.source_of_target.count, nt);
        return AK_ERR_SPAN_SMALL;
    }
    float duration = ak_clip_duration(d.clip);
    double frames_d = ceil((double)duration * (double)d.frame_rate - 1e-6) + 1.0;
    if (!(frames_d >= 1.0) || frames_d > 1e7) {
        akp_diag_set(diag, NULL, "clip of %g s at %g fps: too many frames", (double)duration, (double)d.frame_rate);
        return AK_ERR_BAD_ARG;
    }
    size_t nf = (size_t)frames_d;

    /* one block of temporary arrays */
    size_t bytes = nt * sizeof(int32_t) * 2 + ns * sizeof(int32_t) + (ns + nt) * (sizeof(ak_quat) * 2 + sizeof(ak_mat4) * 2) +
                   ns * sizeof(ak_transform) + nt * sizeof(ak_quat) + nf * nt * sizeof(ak_transform) +
                   2 * nf * sizeof(ak_vec3) + 2 * nf * sizeof(bool) + 64 * 16;
    uint8_t* mem = (uint8_t*)akp_calloc(alloc, bytes);
    if (!mem) {
        akp_diag_set(diag, NULL, "out of memory (%zu frames x %zu joints)", nf, nt);
        return AK_ERR_NO_MEMORY;
    }
    uint8_t* cur = mem;
#define TAKE(type, count) ((type*)(void*)(cur += akp_align16((count) * sizeof(type)), cur - akp_align16((count) * sizeof(type))))
    int32_t* map = TAKE(int32_t, nt);
    int32_t* sbones = TAKE(int32_t, ns);
    int32_t* tbones = TAKE(int32_t, nt);
    ak_quat* s_rest_q = TAKE(ak_quat, ns);
    ak_quat* s_q = TAKE(ak_quat, ns);
    ak_mat4* s_rest_m = TAKE(ak_mat4, ns);
    ak_mat4* s_m = TAKE(ak_mat4, ns);
    ak_quat* t_rest_q = TAKE(ak_quat, nt);
    ak_quat* t_q = TAKE(ak_quat, nt);
    ak_mat4* t_rest_m = TAKE(ak_mat4, nt);
    ak_mat4* t_m = TAKE(ak_mat4, nt);
    ak_transform* s_local = TAKE(ak_transform, ns);
    ak_quat* align = TAKE(ak_quat, nt);
    ak_transform* poses = TAKE(ak_transform, nf * nt);
    ak_vec3* foot_pos = TAKE(ak_vec3, 2 * nf);
    bool* contact = TAKE(bool, 2 * nf);
#undef TAKE
    ak_result r = AK_OK;
    size_t mapped = 0;
    if (d.source_of_target.ptr) {
        for (size_t k = 0; k < nt; ++k) {
            int32_t j = d.source_of_target.ptr[k];
            if (j < -1 || j >= (int32_t)ns) {
                akp_diag_set(diag, NULL, "map entry %zu (%s) = %d is not a source joint (%zu joints)", k,
                             ak_skeleton_joint_name(dst, k), (int)j, ns);
                r = AK_ERR_BAD_INDEX;
                goto done;
            }
            map[k] = j;
            mapped += j >= 0;
        }
    } else {
        ak_retarget_map_by_name(src, dst, (ak_i32_span){map, nt}, &mapped);
    }
    if (!mapped) {
        akp_diag_set(diag, NULL, "no target joint is mapped to a source joint");
        r = AK_ERR_NOT_FOUND;
        goto done;
    }
    ak_humanoid_bones_of_skeleton(src, (ak_i32_span){sbones, ns});
    ak_humanoid_bones_of_skeleton(dst, (ak_i32_span){tbones, nt});
    /* a target joint whose name says nothing takes the bone of its source joint (user maps) */
    for (size_t k = 0; k < nt; ++k)
        if (tbones[k] == AK_BONE_NONE && map[k] >= 0 && find_bone(tbones, nt, sbones[map[k]]) < 0) tbones[k] = sbones[map[k]];

    /* rest poses in model space */
    ak_transform_cspan s_rest = ak_skeleton_rest_pose(src), t_rest = ak_skeleton_rest_pose(dst);
    model_rotations(src, s_rest.ptr, s_rest_q);
    model_rotations(dst, t_rest.ptr, t_rest_q);
    ak_skeleton_local_to_model(src, s_rest, (ak_mat4_span){s_rest_m, ns});
    ak_skeleton_local_to_model(dst, t_rest, (ak_mat4_span){t_rest_m, nt});

    /* root-motion joint: the hips, else the first mapped joint */
    int root = find_bone(tbones, nt, AK_BONE_HIPS);
    if (root < 0 || map[root] < 0)
        for (size_t k = 0; k < nt && (root < 0 || map[root] < 0); ++k)
            if (map[k] >= 0) root = (int)k;
    float s_leg = leg_length(src, sbones, s_rest_m, AK_BONE_LEFT_UPPER_LEG);
    float t_leg = leg_length(dst, tbones, t_rest_m, AK_BONE_LEFT_UPPER_LEG);
    if (!(s_leg > 0.0f) || !(t_leg > 0.0f)) {
        s_leg = fabsf(model_position(&s_rest_m[map[root]]).y);
        t_leg = fabsf(model_position(&t_rest_m[root]).y);
    }
    float scale = d.unscaled_root_motion || !(s_leg > 1e-12f) || !(t_leg > 0.0f) ? 1.0f : t_leg / s_leg;

    /* rest alignment: target rest bone direction onto the source's */
    ak_i16_cspan tpar = ak_skeleton_parents(dst);
    for (size_t k = 0; k < nt; ++k) {
        align[k] = ak_quat_identity();
        bool set = false;
        if (map[k] >= 0 && (int)k != root) {
            for (size_t c = k + 1; c < nt; ++c) {
                if (tpar.ptr[c] != (int16_t)k || map[c] < 0) continue;
                ak_vec3 dt = ak_vec3_sub(model_position(&t_rest_m[c]), model_position(&t_rest_m[k]));
                ak_vec3 ds = ak_vec3_sub(model_position(&s_rest_m[map[c]]), model_position(&s_rest_m[map[k]]));
                if (ak_vec3_length(dt) > 1e-12f && ak_vec3_length(ds) > 1e-12f) {
                    align[k] = ak_quat_from_to(dt, ds);
                    set = true;
                }
                break;
            }
        }
        if (!set && (int)k != root && tpar.ptr[k] >= 0) align[k] = align[tpar.ptr[k]];
    }

    /* per frame: sample the source, transfer, root motion */
    ak_vec3 s_root_rest = model_position(&s_rest_m[map[root]]);
    ak_vec3 t_root_rest = model_position(&t_rest_m[root]);
    int feet[2] = {find_bone(tbones, nt, AK_BONE_LEFT_FOOT), find_bone(tbones, nt, AK_BONE_RIGHT_FOOT)};
    for (size_t f = 0; f < nf && r == AK_OK; ++f) {
        float t = (float)((double)f / (double)d.frame_rate);
        if (t > duration || f + 1 == nf) t = duration;
        memcpy(s_local, s_rest.ptr, ns * sizeof(ak_transform));
        ak_clip_sample(d.clip, t, NULL, (ak_transform_span){s_local, ns}, (ak_f32_span){0}, (ak_f32_span){0});
        if (!ak_pose_is_finite((ak_transform_cspan){s_local, ns})) {
            akp_diag_set(diag, NULL, "the source pose at %g s is not finite", (double)t);
            r = AK_ERR_BAD_DATA;
            break;
        }
        model_rotations(src, s_local, s_q);
        ak_skeleton_local_to_model(src, (ak_transform_cspan){s_local, ns}, (ak_mat4_span){s_m, ns});
        ak_transform* out = poses + f * nt;
        for (size_t k = 0; k < nt; ++k) {
            out[k] = t_rest.ptr[k];
            ak_quat parent_q = tpar.ptr[k] >= 0 ? t_q[tpar.ptr[k]] : ak_quat_identity();
            int32_t j = map[k];
            if (j >= 0) {
                ak_quat delta = ak_quat_mul(s_q[j], ak_quat_conjugate(s_rest_q[j]));
                ak_quat world = ak_quat_normalize(ak_quat_mul(delta, ak_quat_mul(align[k], t_rest_q[k])));
                out[k].rotation = ak_quat_normalize(ak_quat_mul(ak_quat_conjugate(parent_q), world));
            }
            t_q[k] = ak_quat_normalize(ak_quat_mul(parent_q, out[k].rotation));
            if ((int)k == root) {
                ak_vec3 disp = ak_vec3_sub(model_position(&s_m[j]), s_root_rest);
                ak_vec3 want = ak_vec3_add(t_root_rest, ak_vec3_scale(disp, scale));
                if (tpar.ptr[k] >= 0) { /* into the parent's space (ancestors are done) */
                    ak_skeleton_local_to_model(dst, (ak_transform_cspan){out, nt}, (ak_mat4_span){t_m, nt});
                    want = ak_mat4_transform_point(ak_mat4_inverse_affine(t_m[tpar.ptr[k]]), want);
                }
                out[k].translation = want;
            }
        }
        for (int s = 0; s < 2; ++s)
            foot_pos[2 * f + (size_t)s] = feet[s] >= 0 && map[feet[s]] >= 0 ? model_position(&s_m[map[feet[s]]]) : ak_vec3_make(0, 0, 0);
    }
    if (r != AK_OK) goto done;

    /* Ground the clip: the root's height is not measured from the source's rest pose (a BVH's
     * rest pose has the hips at the origin while its motion carries them at hip height, so the
     * rest displacement counted that height twice and the target floated above the floor).
     * With both feet mapped, the whole clip moves up or down by the one offset that brings the
     * target's lowest ankle over the clip to its lowest ankle at rest: the feet reach the floor
     * when the source's get lowest, and no lower. */
    if (feet[0] >= 0 && feet[1] >= 0 && map[feet[0]] >= 0 && map[feet[1]] >= 0) {
        float low = HUGE_VALF;
        for (size_t f = 0; f < nf; ++f) {
            ak_skeleton_local_to_model(dst, (ak_transform_cspan){poses + f * nt, nt}, (ak_mat4_span){t_m, nt});
            low = fminf(low, fminf(model_position(&t_m[feet[0]]).y, model_position(&t_m[feet[1]]).y));
        }
        const float rest_low = fminf(model_position(&t_rest_m[feet[0]]).y, model_position(&t_rest_m[feet[1]]).y);
        const float dy = rest_low - low;
        for (size_t f = 0; f < nf && ak_finitef(dy); ++f) {
            ak_transform* out = poses + f * nt;
            if (tpar.ptr[root] < 0) {
                out[root].translation.y += dy;
                continue;
            }
            /* a root under other joints (CesiumMan's): the model-space offset into the parent's space */
            ak_skeleton_local_to_model(dst, (ak_transform_cspan){out, nt}, (ak_mat4_span){t_m, nt});
            ak_vec3 want = model_position(&t_m[root]);
            want.y += dy;
            out[root].translation = ak_mat4_transform_point(ak_mat4_inverse_affine(t_m[tpar.ptr[root]]), want);
        }
    }

    /* foot contacts on the source, pinned on the target */
    size_t contact_frames = 0, pinned = 0, unreached = 0;
    for (int s = 0; s < 2 && !d.skip_foot_contacts; ++s) {
        int foot = feet[s];
        if (foot < 0 || map[foot] < 0) continue;
        int lower = tpar.ptr[foot], upper = lower >= 0 ? tpar.ptr[lower] : -1;
        if (upper < 0) continue;
        float floor_y = foot_pos[(size_t)s].y;
        for (size_t f = 1; f < nf; ++f) floor_y = fminf(floor_y, foot_pos[2 * f + (size_t)s].y);
        float h = d.contact_height * s_leg, v = d.contact_speed * s_leg;
        for (size_t f = 0; f < nf; ++f) {
            size_t a = f > 0 ? f - 1 : f, b = f + 1 < nf ? f + 1 : f;
            ak_vec3 dp = ak_vec3_sub(foot_pos[2 * b + (size_t)s], foot_pos[2 * a + (size_t)s]);
            float dt = (float)(b - a) / d.frame_rate;
            float speed = b > a ? sqrtf(dp.x * dp.x + dp.z * dp.z) / dt : 0.0f;
            contact[2 * f + (size_t)s] = foot_pos[2 * f + (size_t)s].y - floor_y < h && speed < v;
            contact_frames += contact[2 * f + (size_t)s];
        }
        /* each contact run: the foot is pinned at its mean position over the run (half the
         * reach the first frame's position would ask of the leg at the run's far end) */
        for (size_t a = 0; a < nf;) {
            if (!contact[2 * a + (size_t)s]) {
                ++a;
                continue;
            }
            size_t b = a;
            double sum[3] = {0, 0, 0};
            for (; b < nf && contact[2 * b + (size_t)s]; ++b) {
                ak_skeleton_local_to_model(dst, (ak_transform_cspan){poses + b * nt, nt}, (ak_mat4_span){t_m, nt});
                ak_vec3 p = model_position(&t_m[foot]);
                sum[0] += p.x, sum[1] += p.y, sum[2] += p.z;
            }
            double cnt = (double)(b - a);
            ak_vec3 pin = ak_vec3_make((float)(sum[0] / cnt), (float)(sum[1] / cnt), (float)(sum[2] / cnt));
            for (size_t f = a; f < b; ++f) {
                ak_transform* out = poses + f * nt;
                ak_skeleton_local_to_model(dst, (ak_transform_cspan){out, nt}, (ak_mat4_span){t_m, nt});
                model_rotations(dst, out, t_q);
                ak_quat foot_world = t_q[foot];
                ak_quat cs, cm;
                bool reached = false;
                ak_ik_two_bone_job job = {.start = t_m[upper], .mid = t_m[lower], .end = t_m[foot], .target = pin,
                                          .out_start_rot = &cs, .out_mid_rot = &cm, .out_reached = &reached};
                if (ak_ik_two_bone_run(&job) != AK_OK) continue;
                out[upper].rotation = ak_quat_normalize(ak_quat_mul(out[upper].rotation, cs));
                out[lower].rotation = ak_quat_normalize(ak_quat_mul(out[lower].rotation, cm));
                model_rotations(dst, out, t_q);
                out[foot].rotation = ak_quat_normalize(ak_quat_mul(ak_quat_conjugate(t_q[lower]), foot_world));
                ++pinned;
                unreached += !reached;
            }
            a = b;
        }
    }

    ak_clip_bake_desc bd = {.poses = poses, .frame_count = nf, .joint_count = nt, .frame_rate = d.frame_rate,
                            .rest_pose = t_rest, .name = d.name};
    r = ak_clip_bake(&bd, alloc, out_clip, diag);
    if (r == AK_OK && out_stats) {
        out_stats->frame_count = nf;
        out_stats->mapped_count = mapped;
        out_stats->root_joint = root;
        out_stats->root_scale = scale;
        out_stats->contact_frames = contact_frames;
        out_stats->pinned_frames = pinned;
        out_stats->unreached_frames = unreached;
    }
done:
    akp_free(alloc, mem);
    return r;
}
