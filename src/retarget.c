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
    ak_i32_cspan parents = ak_skeleton_parents(sk);
    for (size_t j = 0; j < parents.count; ++j)
        out[j] = parents.ptr[j] < 0 ? local[j].rotation
                                    : ak_quat_normalize(ak_quat_mul(out[parents.ptr[j]], local[j].rotation));
}

static ak_vec3 model_position(const ak_mat4* m) { return ak_mat4_get_translation(*m); }

static bool is_ancestor(const ak_skeleton* sk, int a, int j) {
    ak_i32_cspan p = ak_skeleton_parents(sk);
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
    ak_i32_cspan parents = ak_skeleton_parents(skeleton);
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
    ak_i32_cspan tpar = ak_skeleton_parents(dst);
    for (size_t k = 0; k < nt; ++k) {
        align[k] = ak_quat_identity();
        bool set = false;
        if (map[k] >= 0 && (int)k != root) {
            for (size_t c = k + 1; c < nt; ++c) {
                if (tpar.ptr[c] != (int32_t)k || map[c] < 0) continue;
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

/* ---- humanoid template (ak_humanoid_roles_find) ------------------------------------------- */

enum { WORD_NONE = 0, WORD_TORSO, WORD_HEAD, WORD_ARM, WORD_LEG };

typedef struct role_ctx {
    const ak_skeleton* sk;
    size_t n;
    const int32_t* parent;
    ak_vec3* pos;          /* rest model positions */
    int32_t* first_child;  /* child lists in index order */
    int32_t* next_sibling;
    int32_t* size;         /* joints in the subtree */
    float* reach;          /* longest path length below the joint */
    int32_t* name_bone;    /* ak_humanoid_bones_of_skeleton */
    uint8_t* name_side;    /* from the name's words: 1 left, 2 right */
    uint8_t* name_word;    /* WORD_* from the name's words */
    int32_t* chain;        /* scratch: a chain, then its merged keys */
    int32_t* stack;        /* scratch: DFS / BFS */
    float eps;             /* positions closer than this are one */
} role_ctx;

/* A limb: the joints found along one chain. */
typedef struct limb {
    int32_t before, upper, lower, end, after; /* -1 when absent */
    float quality;                            /* 1, or 0.6 when no bone pair passed the rules */
} limb;

static bool word_is(const char* w, size_t n, const char* s) { return strlen(s) == n && strncmp(w, s, n) == 0; }

/* Side (1 left, 2 right) and limb word of a name, from its words: split at separators, at a
 * lower-to-upper case change, before the last capital of a run of capitals followed by a
 * lower-case letter ("LHip" -> L, Hip) and between letters and digits. */
static void name_words(const char* name, uint8_t* out_side, uint8_t* out_word) {
    const char* colon = strrchr(name, ':');
    const char* s = colon ? colon + 1 : name;
    char w[AK_NAME_SIZE];
    size_t n = 0;
    *out_side = 0, *out_word = WORD_NONE;
    for (size_t i = 0;; ++i) {
        unsigned char ch = (unsigned char)s[i];
        bool cut = !ch || !isalnum(ch);
        if (!cut && n > 0 && i > 0) {
            unsigned char pv = (unsigned char)s[i - 1], nx = (unsigned char)s[i + 1];
            cut = (islower(pv) && isupper(ch)) || (isupper(pv) && isupper(ch) && islower(nx)) ||
                  (isdigit(pv) != 0) != (isdigit(ch) != 0);
        }
        if (cut && n > 0) {
            static const char* const side_l[] = {"l", "left", "lft"};
            static const char* const side_r[] = {"r", "right", "rt", "rgt"};
            static const char* const words[][2] = {
                {"hips", "1"},     {"pelvis", "1"},   {"spine", "1"},    {"chest", "1"},   {"torso", "1"},
                {"abdomen", "1"},  {"lowerback", "1"}, {"back", "1"},    {"neck", "2"},    {"head", "2"},
                {"skull", "2"},    {"arm", "3"},      {"shoulder", "3"}, {"clavicle", "3"}, {"collar", "3"},
                {"elbow", "3"},    {"forearm", "3"},  {"hand", "3"},     {"wrist", "3"},   {"finger", "3"},
                {"thumb", "3"},    {"leg", "4"},      {"thigh", "4"},    {"upleg", "4"},   {"knee", "4"},
                {"shin", "4"},     {"calf", "4"},     {"foot", "4"},     {"ankle", "4"},   {"toe", "4"},
                {"toes", "4"},     {"femur", "4"},
            };
            for (size_t k = 0; k < sizeof side_l / sizeof side_l[0]; ++k)
                if (word_is(w, n, side_l[k])) *out_side = 1;
            for (size_t k = 0; k < sizeof side_r / sizeof side_r[0]; ++k)
                if (word_is(w, n, side_r[k])) *out_side = 2;
            /* "LeftUpLeg" -> left, up, leg; "leftUpperArm" -> left, upper, arm */
            if (n > 4 && strncmp(w, "left", 4) == 0) *out_side = 1;
            if (n > 5 && strncmp(w, "right", 5) == 0) *out_side = 2;
            for (size_t k = 0; k < sizeof words / sizeof words[0]; ++k)
                if (word_is(w, n, words[k][0]) && *out_word == WORD_NONE) *out_word = (uint8_t)(words[k][1][0] - '0');
            n = 0;
        }
        if (!ch) break;
        if (!cut || (isalnum(ch) && n == 0)) {
            if (n + 1 < sizeof w) w[n++] = (char)tolower(ch);
        }
    }
}

static int role_word(int bone) {
    if (bone == AK_BONE_HIPS || (bone >= AK_BONE_SPINE && bone <= AK_BONE_UPPER_CHEST)) return WORD_TORSO;
    if (bone == AK_BONE_NECK || bone == AK_BONE_HEAD) return WORD_HEAD;
    if (bone >= AK_BONE_LEFT_SHOULDER && bone <= AK_BONE_RIGHT_HAND) return WORD_ARM;
    if (bone >= AK_BONE_LEFT_UPPER_LEG && bone <= AK_BONE_RIGHT_TOES) return WORD_LEG;
    return WORD_NONE;
}

static int role_side(int bone) {
    if ((bone >= AK_BONE_LEFT_SHOULDER && bone <= AK_BONE_LEFT_HAND) ||
        (bone >= AK_BONE_LEFT_UPPER_LEG && bone <= AK_BONE_LEFT_TOES))
        return 1;
    if ((bone >= AK_BONE_RIGHT_SHOULDER && bone <= AK_BONE_RIGHT_HAND) ||
        (bone >= AK_BONE_RIGHT_UPPER_LEG && bone <= AK_BONE_RIGHT_TOES))
        return 2;
    return 0;
}

static bool name_has_word(const char* name, const char* word) {
    char n[AK_NAME_SIZE];
    normalise(name, n);
    return strstr(n, word) != NULL;
}

/* Walk down from start, each time to the child with the longest path below it; returns the
 * joint count written to c->chain. */
static size_t chain_follow(const role_ctx* c, int32_t start) {
    size_t m = 0;
    for (int32_t j = start; j >= 0 && m < c->n;) {
        c->chain[m++] = j;
        int32_t best = -1;
        float best_len = -1.0f;
        for (int32_t k = c->first_child[j]; k >= 0; k = c->next_sibling[k]) {
            float len = ak_vec3_length(ak_vec3_sub(c->pos[k], c->pos[j])) + c->reach[k];
            if (len > best_len || (len == best_len && c->size[k] > c->size[best])) best = k, best_len = len;
        }
        j = best;
    }
    return m;
}

static float dist(const role_ctx* c, int32_t a, int32_t b) { return ak_vec3_length(ak_vec3_sub(c->pos[a], c->pos[b])); }

/* Upper, lower, end (hand or foot), the joint before and after, along the chain from start. */
static limb limb_find(const role_ctx* c, int32_t start) {
    limb L = {-1, -1, -1, -1, -1, 0.0f};
    size_t m = chain_follow(c, start), keys = 0;
    for (size_t i = 0; i < m; ++i) /* joints at one position: the first of them stands for all */
        if (keys == 0 || dist(c, c->chain[i], c->chain[keys - 1]) > c->eps) c->chain[keys++] = c->chain[i];
    if (keys < 3) return L;
    const int32_t* k = c->chain;
    int best = -1, fallback = -1;
    float best_sum = 0.0f, fallback_sum = 0.0f;
    for (size_t i = 0; i + 2 < keys; ++i) {
        float up = dist(c, k[i], k[i + 1]), lo = dist(c, k[i + 1], k[i + 2]);
        float next = i + 3 < keys ? dist(c, k[i + 2], k[i + 3]) : 0.0f;
        if (up + lo > fallback_sum) fallback = (int)i, fallback_sum = up + lo;
        if (lo < 0.4f * up || lo > 2.5f * up || next >= 0.6f * lo) continue;
        if (up + lo > best_sum) best = (int)i, best_sum = up + lo;
    }
    L.quality = 1.0f;
    if (best < 0) best = fallback, L.quality = 0.6f;
    if (best < 0) return L;
    L.upper = k[best], L.lower = k[best + 1], L.end = k[best + 2];
    L.before = best > 0 ? k[best - 1] : -1;
    L.after = (size_t)best + 3 < keys ? k[best + 3] : -1;
    return L;
}

/* The most similar pair among the children of j with subtrees of >= 3 joints, skipping
 * `skip`; false when fewer than two. Similarity: path length and distance from j. */
static bool pair_find(const role_ctx* c, int32_t j, int32_t skip, int32_t* a, int32_t* b) {
    float best = INFINITY;
    *a = *b = -1;
    for (int32_t x = c->first_child[j]; x >= 0; x = c->next_sibling[x]) {
        if (x == skip || c->size[x] < 3) continue;
        for (int32_t y = c->next_sibling[x]; y >= 0; y = c->next_sibling[y]) {
            if (y == skip || c->size[y] < 3) continue;
            float lx = c->reach[x] + dist(c, x, j), ly = c->reach[y] + dist(c, y, j);
            float scale = fmaxf(fmaxf(lx, ly), 1e-20f);
            float d = fabsf(lx - ly) / scale + fabsf(dist(c, x, j) - dist(c, y, j)) / scale;
            if (d < best) best = d, *a = x, *b = y;
        }
    }
    return *a >= 0;
}

/* A chest below s: the shallowest joint of s's subtree with an arm pair and one more child. */
static int32_t chest_find(const role_ctx* c, int32_t s, int32_t* arm_a, int32_t* arm_b) {
    size_t top = 0;
    int32_t found = -1;
    c->stack[top++] = s;
    /* breadth first: the first joint found is the shallowest */
    for (size_t head = 0; head < top && found < 0; ++head) {
        int32_t j = c->stack[head];
        int kids = 0;
        for (int32_t k = c->first_child[j]; k >= 0; k = c->next_sibling[k]) ++kids;
        if (kids >= 3 && pair_find(c, j, -1, arm_a, arm_b)) {
            found = j;
            break;
        }
        for (int32_t k = c->first_child[j]; k >= 0 && top < c->n; k = c->next_sibling[k]) c->stack[top++] = k;
    }
    return found;
}

static float angle_deg(ak_vec3 a, ak_vec3 b) {
    float la = ak_vec3_length(a), lb = ak_vec3_length(b);
    if (!(la > 0.0f) || !(lb > 0.0f)) return 180.0f;
    float cs = ak_vec3_dot(a, b) / (la * lb);
    return acosf(fmaxf(-1.0f, fminf(1.0f, cs))) * (180.0f / 3.14159265f);
}

static ak_vec3 unit_or(ak_vec3 v, ak_vec3 fallback) {
    float l = ak_vec3_length(v);
    return l > 1e-20f ? ak_vec3_scale(v, 1.0f / l) : fallback;
}

static void role_set(ak_humanoid_roles* r, const role_ctx* c, int bone, int32_t j, float quality) {
    if (j < 0) return;
    r->joint[bone] = j;
    int nb = c->name_bone[j];
    r->name_bone[bone] = nb;
    float f = 0.8f;
    if (nb == bone) f = 1.0f;
    else if (nb != AK_BONE_NONE) f = 0.5f;
    else if ((c->name_word[j] != WORD_NONE && c->name_word[j] != role_word(bone)) ||
             (c->name_side[j] && role_side(bone) && c->name_side[j] != role_side(bone)))
        f = 0.5f;
    r->confidence[bone] = f * quality;
}

static int side_votes(const role_ctx* c, const limb* L) {
    int32_t js[5] = {L->before, L->upper, L->lower, L->end, L->after};
    int v = 0;
    for (int i = 0; i < 5; ++i)
        if (js[i] >= 0) v += c->name_side[js[i]] == 1 ? 1 : c->name_side[js[i]] == 2 ? -1 : 0;
    return v;
}

/* Fit the template with h as the hips; false when it does not fit. */
static bool template_fit(const role_ctx* c, int32_t h, ak_humanoid_roles* r) {
    int32_t spine = -1, chest = -1, arm[2] = {-1, -1};
    int32_t best_size = -1;
    for (int32_t s = c->first_child[h]; s >= 0; s = c->next_sibling[s]) {
        if (c->size[s] < 3) continue;
        int32_t a, b;
        int32_t ch = chest_find(c, s, &a, &b);
        if (ch >= 0 && c->size[s] > best_size) spine = s, chest = ch, arm[0] = a, arm[1] = b, best_size = c->size[s];
    }
    if (spine < 0) return false;
    int32_t leg[2];
    if (!pair_find(c, h, spine, &leg[0], &leg[1])) return false;
    /* head chain: the chest's other child pointing most along hips -> chest */
    ak_vec3 body = ak_vec3_sub(c->pos[chest], c->pos[h]);
    int32_t neck = -1;
    float best_cos = -2.0f;
    for (int32_t k = c->first_child[chest]; k >= 0; k = c->next_sibling[k]) {
        if (k == arm[0] || k == arm[1]) continue;
        size_t m = chain_follow(c, k);
        ak_vec3 d = ak_vec3_sub(c->pos[c->chain[m - 1]], c->pos[chest]);
        float cs = ak_vec3_dot(unit_or(d, ak_vec3_zero()), unit_or(body, ak_vec3_zero()));
        if (cs > best_cos) best_cos = cs, neck = k;
    }
    if (neck < 0) return false;
    limb legs[2] = {limb_find(c, leg[0]), limb_find(c, leg[1])};
    limb arms[2] = {limb_find(c, arm[0]), limb_find(c, arm[1])};
    if (legs[0].end < 0 || legs[1].end < 0 || arms[0].end < 0 || arms[1].end < 0) return false;

    /* head: the joint named head on the chain, else its last joint (its parent when that is an
     * "end"/"top" leaf); the neck is the chain's first joint when the head is not */
    size_t m = chain_follow(c, neck);
    int32_t head = -1;
    for (size_t i = 0; i < m; ++i)
        if (c->name_bone[c->chain[i]] == AK_BONE_HEAD) head = c->chain[i];
    if (head < 0) {
        head = c->chain[m - 1];
        const char* hn = ak_skeleton_joint_name(c->sk, (size_t)head);
        if (m >= 2 && (name_has_word(hn, "end") || name_has_word(hn, "top"))) head = c->chain[m - 2];
    }
    /* torso: hips .. chest */
    int32_t torso[3] = {-1, -1, -1};
    size_t k = 0;
    for (int32_t j = chest; j >= 0 && j != h; j = c->parent[j]) ++k;
    {
        size_t i = k;
        for (int32_t j = chest; j >= 0 && j != h && i > 0; j = c->parent[j]) c->stack[--i] = j;
    }
    if (k == 1) torso[0] = c->stack[0];
    else if (k == 2) torso[0] = c->stack[0], torso[1] = c->stack[1];
    else torso[0] = c->stack[0], torso[1] = c->stack[k - 2], torso[2] = c->stack[k - 1];

    /* axes */
    ak_vec3 feet = ak_vec3_scale(ak_vec3_add(c->pos[legs[0].end], c->pos[legs[1].end]), 0.5f);
    ak_vec3 up = unit_or(ak_vec3_sub(c->pos[head], feet), ak_vec3_make(0, 1, 0));
    ak_vec3 lat = ak_vec3_sub(c->pos[legs[0].upper], c->pos[legs[1].upper]);
    lat = ak_vec3_sub(lat, ak_vec3_scale(up, ak_vec3_dot(lat, up)));
    if (ak_vec3_length(lat) < c->eps) {
        lat = ak_vec3_sub(c->pos[arms[0].upper], c->pos[arms[1].upper]);
        lat = ak_vec3_sub(lat, ak_vec3_scale(up, ak_vec3_dot(lat, up)));
    }
    ak_vec3 fwd0 = unit_or(ak_vec3_cross(lat, up), ak_vec3_make(0, 0, 1)); /* forward if leg 0 is left */
    int leg0_left = 0; /* 1 yes, -1 no, 0 undecided */
    if (legs[0].after >= 0 && legs[1].after >= 0) {
        ak_vec3 t = ak_vec3_add(ak_vec3_sub(c->pos[legs[0].after], c->pos[legs[0].end]),
                                ak_vec3_sub(c->pos[legs[1].after], c->pos[legs[1].end]));
        t = ak_vec3_sub(t, ak_vec3_scale(up, ak_vec3_dot(t, up)));
        float d = ak_vec3_dot(t, fwd0), tl = ak_vec3_length(t);
        if (tl > c->eps && fabsf(d) > 0.3f * tl) leg0_left = d > 0 ? 1 : -1, r->sides = AK_SIDES_TOES;
    }
    if (!leg0_left) {
        int v = side_votes(c, &legs[0]) - side_votes(c, &legs[1]);
        if (v) leg0_left = v > 0 ? 1 : -1, r->sides = AK_SIDES_NAMES;
    }
    if (!leg0_left) {
        ak_vec3 z = ak_vec3_make(0, 0, 1);
        z = ak_vec3_sub(z, ak_vec3_scale(up, ak_vec3_dot(z, up)));
        float d = ak_vec3_length(z) > 1e-3f ? ak_vec3_dot(fwd0, z) : lat.x;
        leg0_left = d >= 0 ? 1 : -1, r->sides = AK_SIDES_CONVENTION;
    }
    r->up = up;
    r->forward = leg0_left > 0 ? fwd0 : ak_vec3_scale(fwd0, -1.0f);
    ak_vec3 left = ak_vec3_cross(up, r->forward);
    if (leg0_left < 0) {
        limb t = legs[0];
        legs[0] = legs[1], legs[1] = t;
    }
    if (ak_vec3_dot(ak_vec3_sub(c->pos[arms[0].upper], c->pos[chest]), left) <
        ak_vec3_dot(ak_vec3_sub(c->pos[arms[1].upper], c->pos[chest]), left)) {
        limb t = arms[0];
        arms[0] = arms[1], arms[1] = t;
    }

    role_set(r, c, AK_BONE_HIPS, h, 1.0f);
    role_set(r, c, AK_BONE_SPINE, torso[0], 1.0f);
    role_set(r, c, AK_BONE_CHEST, torso[1], 1.0f);
    role_set(r, c, AK_BONE_UPPER_CHEST, torso[2], 1.0f);
    if (neck != head) role_set(r, c, AK_BONE_NECK, neck, 1.0f);
    role_set(r, c, AK_BONE_HEAD, head, 1.0f);
    for (int s = 0; s < 2; ++s) {
        const int ab = s == 0 ? AK_BONE_LEFT_SHOULDER : AK_BONE_RIGHT_SHOULDER;
        const int lb = s == 0 ? AK_BONE_LEFT_UPPER_LEG : AK_BONE_RIGHT_UPPER_LEG;
        role_set(r, c, ab, arms[s].before, arms[s].quality);
        role_set(r, c, ab + 1, arms[s].upper, arms[s].quality);
        role_set(r, c, ab + 2, arms[s].lower, arms[s].quality);
        role_set(r, c, ab + 3, arms[s].end, arms[s].quality);
        role_set(r, c, lb, legs[s].upper, legs[s].quality);
        role_set(r, c, lb + 1, legs[s].lower, legs[s].quality);
        role_set(r, c, lb + 2, legs[s].end, legs[s].quality);
        role_set(r, c, lb + 3, legs[s].after, legs[s].quality);
    }
    /* does it stand? */
    ak_vec3 leg_up = ak_vec3_sub(c->pos[h], feet);
    r->spine_angle = angle_deg(ak_vec3_sub(c->pos[head], c->pos[h]), leg_up);
    float leg_len = 0.5f * (dist(c, legs[0].upper, legs[0].lower) + dist(c, legs[0].lower, legs[0].end) +
                            dist(c, legs[1].upper, legs[1].lower) + dist(c, legs[1].lower, legs[1].end));
    ak_vec3 lu = unit_or(leg_up, up);
    float lowest = fminf(ak_vec3_dot(ak_vec3_sub(c->pos[arms[0].end], c->pos[h]), lu),
                         ak_vec3_dot(ak_vec3_sub(c->pos[arms[1].end], c->pos[h]), lu));
    r->hand_height = leg_len > 0.0f ? lowest / leg_len : 0.0f;
    return true;
}

static const int k_required[15] = {
    AK_BONE_HIPS,           AK_BONE_SPINE,          AK_BONE_HEAD,           AK_BONE_LEFT_UPPER_ARM,
    AK_BONE_LEFT_LOWER_ARM, AK_BONE_LEFT_HAND,      AK_BONE_RIGHT_UPPER_ARM, AK_BONE_RIGHT_LOWER_ARM,
    AK_BONE_RIGHT_HAND,     AK_BONE_LEFT_UPPER_LEG, AK_BONE_LEFT_LOWER_LEG, AK_BONE_LEFT_FOOT,
    AK_BONE_RIGHT_UPPER_LEG, AK_BONE_RIGHT_LOWER_LEG, AK_BONE_RIGHT_FOOT,
};

ak_result ak_humanoid_roles_find(const ak_skeleton* skeleton, const ak_allocator* alloc, ak_humanoid_roles* out,
                                 ak_diag* diag) {
    if (!skeleton || !out) {
        akp_diag_set(diag, NULL, "skeleton and out are required");
        return AK_ERR_NULL_ARG;
    }
    memset(out, 0, sizeof *out);
    for (int b = 0; b < AK_BONE_COUNT; ++b) out->joint[b] = -1;
    out->up = ak_vec3_make(0, 1, 0), out->forward = ak_vec3_make(0, 0, 1);
    const size_t n = ak_skeleton_joint_count(skeleton);
    if (n == 0) {
        akp_diag_set(diag, NULL, "not a humanoid: the skeleton has no joint");
        return AK_ERR_NOT_FOUND;
    }
    size_t bytes = n * (sizeof(ak_vec3) + sizeof(ak_mat4) + 6 * sizeof(int32_t) + sizeof(float) + 2) + 16 * 16;
    uint8_t* mem = (uint8_t*)akp_calloc(alloc, bytes);
    if (!mem) {
        akp_diag_set(diag, NULL, "out of memory (%zu joints)", n);
        return AK_ERR_NO_MEMORY;
    }
    uint8_t* cur = mem;
#define TAKE(type, count) ((type*)(void*)(cur += akp_align16((count) * sizeof(type)), cur - akp_align16((count) * sizeof(type))))
    role_ctx c = {.sk = skeleton, .n = n, .parent = ak_skeleton_parents(skeleton).ptr};
    ak_mat4* model = TAKE(ak_mat4, n);
    c.pos = TAKE(ak_vec3, n);
    c.first_child = TAKE(int32_t, n);
    c.next_sibling = TAKE(int32_t, n);
    c.size = TAKE(int32_t, n);
    c.name_bone = TAKE(int32_t, n);
    c.chain = TAKE(int32_t, n);
    c.stack = TAKE(int32_t, n);
    c.reach = TAKE(float, n);
    c.name_side = TAKE(uint8_t, n);
    c.name_word = TAKE(uint8_t, n);
#undef TAKE
    ak_result r = ak_skeleton_local_to_model(skeleton, ak_skeleton_rest_pose(skeleton), (ak_mat4_span){model, n});
    float extent = 0.0f;
    for (size_t j = 0; j < n && r == AK_OK; ++j) {
        c.pos[j] = model_position(&model[j]);
        if (!ak_vec3_is_finite(c.pos[j])) r = AK_ERR_BAD_DATA;
        c.first_child[j] = c.next_sibling[j] = -1;
        c.size[j] = 1;
        name_words(ak_skeleton_joint_name(skeleton, j), &c.name_side[j], &c.name_word[j]);
    }
    if (r != AK_OK) {
        akp_diag_set(diag, NULL, "the rest pose is not finite");
        akp_free(alloc, mem);
        return AK_ERR_BAD_DATA;
    }
    ak_humanoid_bones_of_skeleton(skeleton, (ak_i32_span){c.name_bone, n});
    for (size_t jj = n; jj-- > 0;) { /* parents come before their children */
        int32_t p = c.parent[jj];
        if (p < 0) continue;
        c.next_sibling[jj] = c.first_child[p], c.first_child[p] = (int32_t)jj;
        c.size[p] += c.size[jj];
        c.reach[p] = fmaxf(c.reach[p], dist(&c, p, (int32_t)jj) + c.reach[jj]);
        extent = fmaxf(extent, c.reach[p]);
    }
    c.eps = fmaxf(extent * 1e-5f, 1e-12f);
    /* hips candidates breadth first from the roots; the first that fits */
    int32_t* queue = (int32_t*)akp_calloc(alloc, n * sizeof(int32_t));
    if (!queue) {
        akp_free(alloc, mem);
        akp_diag_set(diag, NULL, "out of memory (%zu joints)", n);
        return AK_ERR_NO_MEMORY;
    }
    size_t qn = 0;
    for (size_t j = 0; j < n; ++j)
        if (c.parent[j] < 0) queue[qn++] = (int32_t)j;
    bool fit = false;
    int32_t two_legs = -1;
    for (size_t qi = 0; qi < qn && !fit; ++qi) {
        int32_t h = queue[qi];
        int big = 0;
        for (int32_t k = c.first_child[h]; k >= 0; k = c.next_sibling[k]) {
            big += c.size[k] >= 3;
            if (qn < n) queue[qn++] = k;
        }
        if (big >= 2 && two_legs < 0) two_legs = h;
        if (big >= 3) fit = template_fit(&c, h, out);
    }
    akp_free(alloc, queue);
    float sum = 0.0f;
    for (int i = 0; i < 15; ++i) sum += out->confidence[k_required[i]];
    out->score = sum / 15.0f;
    r = AK_OK;
    if (!fit) {
        r = AK_ERR_NOT_FOUND;
        if (two_legs < 0)
            akp_diag_set(diag, NULL, "not a humanoid: no joint has two leg chains (subtrees of 3 joints or more)");
        else
            akp_diag_set(diag, NULL, "not a humanoid: no joint has two leg chains beside a spine whose chest has two "
                                     "arm chains and a head chain (first branching joint: %s)",
                         ak_skeleton_joint_name(skeleton, (size_t)two_legs));
    } else if (out->spine_angle > 45.0f || out->hand_height < -0.8f) {
        r = AK_ERR_NOT_FOUND;
        char why[300];
        if (out->spine_angle > 45.0f && out->hand_height < -0.8f)
            snprintf(why, sizeof why, "hips -> head runs %.0f degrees from the legs' upward direction (at most 45) and "
                                      "the front limbs reach %.2f leg lengths below the hips, as low as the feet",
                     (double)out->spine_angle, (double)-out->hand_height);
        else if (out->spine_angle > 45.0f)
            snprintf(why, sizeof why, "hips -> head runs %.0f degrees from the legs' upward direction (at most 45)",
                     (double)out->spine_angle);
        else
            snprintf(why, sizeof why, "the hands reach %.2f leg lengths below the hips (at most 0.8)",
                     (double)-out->hand_height);
        akp_diag_set(diag, NULL, "not a humanoid: %s (a quadruped?)", why);
    } else {
        for (int i = 0; i < 15; ++i)
            if (out->joint[k_required[i]] < 0) {
                r = AK_ERR_NOT_FOUND;
                akp_diag_set(diag, NULL, "not a humanoid: no %s", k_bone_names[k_required[i]]);
                break;
            }
    }
    out->is_humanoid = r == AK_OK;
    if (r == AK_OK) akp_diag_set(diag, NULL, "humanoid, score %.2f", (double)out->score);
    akp_free(alloc, mem);
    return r;
}

static bool is_torso(int b) { return b >= AK_BONE_SPINE && b <= AK_BONE_UPPER_CHEST; }

ak_result ak_retarget_map_by_roles(const ak_skeleton* source, const ak_humanoid_roles* sr, const ak_skeleton* target,
                                   const ak_humanoid_roles* tr, ak_i32_span out, size_t* out_mapped_count) {
    if (out_mapped_count) *out_mapped_count = 0;
    if (!source || !sr || !target || !tr || !out.ptr) return AK_ERR_NULL_ARG;
    const size_t ns = ak_skeleton_joint_count(source), nt = ak_skeleton_joint_count(target);
    if (out.count < nt) return AK_ERR_SPAN_SMALL;
    for (int b = 1; b < AK_BONE_COUNT; ++b)
        if (sr->joint[b] < -1 || sr->joint[b] >= (int32_t)ns || tr->joint[b] < -1 || tr->joint[b] >= (int32_t)nt)
            return AK_ERR_BAD_INDEX;
    for (size_t k = 0; k < nt; ++k) out.ptr[k] = -1;
    for (int b = 1; b < AK_BONE_COUNT; ++b)
        if (!is_torso(b) && sr->joint[b] >= 0 && tr->joint[b] >= 0) out.ptr[tr->joint[b]] = sr->joint[b];
    /* torso: bottom to bottom, top to top, the middle in proportion */
    int32_t st[3], tt[3];
    size_t sn = 0, tn = 0;
    for (int b = AK_BONE_SPINE; b <= AK_BONE_UPPER_CHEST; ++b) {
        if (sr->joint[b] >= 0) st[sn++] = sr->joint[b];
        if (tr->joint[b] >= 0) tt[tn++] = tr->joint[b];
    }
    for (size_t i = 0; i < tn && sn > 0; ++i) {
        size_t si = tn == 1 ? sn - 1 : (i * (sn - 1) * 2 + (tn - 1)) / (2 * (tn - 1));
        out.ptr[tt[i]] = st[si];
    }
    size_t mapped = 0;
    for (size_t k = 0; k < nt; ++k) mapped += out.ptr[k] >= 0;
    if (out_mapped_count) *out_mapped_count = mapped;
    return AK_OK;
}

ak_result ak_retarget_map_auto(const ak_skeleton* source, const ak_skeleton* target, const ak_allocator* alloc,
                               ak_i32_span out, size_t* out_mapped_count, bool* out_by_name, ak_diag* diag) {
    if (out_mapped_count) *out_mapped_count = 0;
    if (out_by_name) *out_by_name = false;
    if (!source || !target || !out.ptr) return AK_ERR_NULL_ARG;
    if (out.count < ak_skeleton_joint_count(target)) return AK_ERR_SPAN_SMALL;
    ak_humanoid_roles sr, tr;
    ak_diag sd, td;
    memset(&sd, 0, sizeof sd);
    memset(&td, 0, sizeof td);
    ak_result a = ak_humanoid_roles_find(source, alloc, &sr, &sd);
    if (a != AK_OK && a != AK_ERR_NOT_FOUND) {
        akp_diag_set(diag, NULL, "source: %s", sd.message);
        return a;
    }
    ak_result b = ak_humanoid_roles_find(target, alloc, &tr, &td);
    if (b != AK_OK && b != AK_ERR_NOT_FOUND) {
        akp_diag_set(diag, NULL, "target: %s", td.message);
        return b;
    }
    if (a == AK_ERR_NOT_FOUND && b == AK_ERR_NOT_FOUND) {
        size_t mapped = 0;
        ak_retarget_map_by_name(source, target, out, &mapped);
        if (out_mapped_count) *out_mapped_count = mapped;
        if (out_by_name) *out_by_name = true;
        if (!mapped) {
            akp_diag_set(diag, NULL, "neither skeleton is a humanoid and no joint name matches; give a map");
            return AK_ERR_NOT_FOUND;
        }
        return AK_OK;
    }
    if (a != AK_OK || b != AK_OK) {
        akp_diag_set(diag, NULL, "%s: %s; give a map", a != AK_OK ? "source" : "target",
                     a != AK_OK ? sd.message : td.message);
        return AK_ERR_NOT_FOUND;
    }
    return ak_retarget_map_by_roles(source, &sr, target, &tr, out, out_mapped_count);
}

/* snprintf-style appender. */
typedef struct text_out {
    char* buf;
    size_t cap, len;
} text_out;

#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
static void text_add(text_out* t, const char* fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    char* at = t->len < t->cap ? t->buf + t->len : NULL;
    int n = vsnprintf(at, at ? t->cap - t->len : 0, fmt, ap);
    va_end(ap);
    if (n > 0) t->len += (size_t)n;
}

static const char* sides_text(ak_humanoid_sides s) {
    switch (s) {
    case AK_SIDES_TOES: return "left/right from the toes' direction";
    case AK_SIDES_NAMES: return "left/right from the names (no toes)";
    case AK_SIDES_CONVENTION: return "left/right from glTF's +Z facing (no toes, no side in the names)";
    default: return "left/right not decided";
    }
}

static void roles_header(text_out* t, const char* what, const ak_skeleton* sk, const ak_humanoid_roles* r) {
    (void)sk;
    text_add(t, "# %s: %s, score %.2f, up (%.2f, %.2f, %.2f), forward (%.2f, %.2f, %.2f), %s\n", what,
             r->is_humanoid ? "humanoid" : "NOT a humanoid", (double)r->score, (double)r->up.x, (double)r->up.y,
             (double)r->up.z, (double)r->forward.x, (double)r->forward.y, (double)r->forward.z, sides_text(r->sides));
}

ak_result ak_retarget_map_write(const ak_skeleton* source, const ak_humanoid_roles* sr, const ak_skeleton* target,
                                const ak_humanoid_roles* tr, ak_i32_cspan map, char* buffer, size_t buffer_size,
                                size_t* out_size) {
    if (out_size) *out_size = 0;
    if (!source || !target || !map.ptr || (!buffer && buffer_size > 0)) return AK_ERR_NULL_ARG;
    const size_t ns = ak_skeleton_joint_count(source), nt = ak_skeleton_joint_count(target);
    if (map.count < nt) return AK_ERR_SPAN_SMALL;
    for (size_t k = 0; k < nt; ++k)
        if (map.ptr[k] < -1 || map.ptr[k] >= (int32_t)ns) return AK_ERR_BAD_INDEX;
    for (int b = 1; b < AK_BONE_COUNT; ++b)
        if ((sr && (sr->joint[b] < -1 || sr->joint[b] >= (int32_t)ns)) ||
            (tr && (tr->joint[b] < -1 || tr->joint[b] >= (int32_t)nt)))
            return AK_ERR_BAD_INDEX;
    text_out t = {buffer, buffer_size, 0};
    if (buffer_size) buffer[0] = '\0';
    text_add(&t, "# animkit retarget map: TARGET_JOINT = SOURCE_JOINT, one a line ('#' starts a comment).\n"
                 "# Edit it and pass it back with --map FILE: only the joints listed are driven.\n");
    if (tr) roles_header(&t, "target", target, tr);
    if (sr) roles_header(&t, "source", source, sr);
    /* column widths */
    int tw = 12, sw = 12;
    for (size_t k = 0; k < nt; ++k)
        if (map.ptr[k] >= 0) {
            tw = (int)fmax(tw, (double)strlen(ak_skeleton_joint_name(target, k)));
            sw = (int)fmax(sw, (double)strlen(ak_skeleton_joint_name(source, (size_t)map.ptr[k])));
        }
    text_add(&t, "# %-*s   %-*s  # bone           confidence target / source\n", tw - 2, "TARGET", sw, "SOURCE");
    for (int b = 1; b < AK_BONE_COUNT; ++b) {
        int32_t tj = tr ? tr->joint[b] : -1, sj = sr ? sr->joint[b] : -1;
        if (tj >= 0 && map.ptr[tj] >= 0) {
            text_add(&t, "%-*s = %-*s  # %-14s %.2f / ", tw, ak_skeleton_joint_name(target, (size_t)tj), sw,
                     ak_skeleton_joint_name(source, (size_t)map.ptr[tj]), k_bone_names[b], (double)tr->confidence[b]);
            int sb = 0;
            for (int x = 1; sr && x < AK_BONE_COUNT && !sb; ++x)
                if (sr->joint[x] == map.ptr[tj]) sb = x;
            if (sb == b) text_add(&t, "%.2f\n", (double)sr->confidence[b]);
            else if (sb) text_add(&t, "%.2f (%s)\n", (double)sr->confidence[sb], k_bone_names[sb]);
            else text_add(&t, "-\n");
        } else if (tr && sr && (tj >= 0 || sj >= 0) && !(tj >= 0 && map.ptr[tj] >= 0)) {
            bool used = false;
            for (size_t k = 0; k < nt && sj >= 0; ++k) used |= map.ptr[k] == sj;
            if (used) continue;
            if (tj < 0)
                text_add(&t, "# %-14s no target joint (source %s)\n", k_bone_names[b],
                         ak_skeleton_joint_name(source, (size_t)sj));
            else
                text_add(&t, "# %-14s no source joint (target %s keeps its rest pose)\n", k_bone_names[b],
                         ak_skeleton_joint_name(target, (size_t)tj));
        } else if (tr && sr && tj < 0 && sj < 0 && b != AK_BONE_UPPER_CHEST && b != AK_BONE_CHEST) {
            bool required = false;
            for (int i = 0; i < 15; ++i) required |= k_required[i] == b;
            if (required) text_add(&t, "# %-14s not found in either skeleton\n", k_bone_names[b]);
        }
    }
    for (size_t k = 0; k < nt; ++k) {
        bool role = false;
        for (int b = 1; tr && b < AK_BONE_COUNT; ++b) role |= tr->joint[b] == (int32_t)k;
        if (map.ptr[k] >= 0 && !role)
            text_add(&t, "%-*s = %s\n", tw, ak_skeleton_joint_name(target, k),
                     ak_skeleton_joint_name(source, (size_t)map.ptr[k]));
    }
    if (out_size) *out_size = t.len;
    return AK_OK;
}
