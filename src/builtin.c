/* Built-in models: a skinned cylinder and a capsule humanoid, with keyframed clips. */
#include <animkit/builtin.h>

#include "internal.h"
#include "simd.h"

/* ---- private types ------------------------------------------------------------------- */

#define KEYS_MAX 33
#define CHANNELS_MAX 24

/* One clip being keyed in code: shared key times, one value block per channel. */
typedef struct keyed_clip {
    const char* name;
    size_t key_count;
    float times[KEYS_MAX];
    size_t channel_count;
    ak_raw_channel channels[CHANNELS_MAX];
    float values[CHANNELS_MAX][KEYS_MAX * 4];
} keyed_clip;

/* A tapered capsule of the humanoid's implicit surface (model space, rest pose). */
typedef struct capsule {
    ak_vec3 a, b;
    float ra, rb;
    float zscale; /* < 1 flattens the capsule front to back */
} capsule;

/* Humanoid joint table entry. */
typedef struct hjoint {
    const char* name;
    int parent;
    ak_vec3 pos; /* model space, rest */
    ak_joint_type type;
    ak_joint_limits limits;
    int side;             /* +1 left (+X), -1 right, 0 centre */
    ak_vec3 seg_a, seg_b; /* bone segment whose vertices this joint drives */
    float radius;         /* flesh radius around that segment (weights measure from it) */
} hjoint;

enum {
    H_PELVIS,
    H_SPINE1,
    H_SPINE2,
    H_NECK,
    H_HEAD,
    H_LSHOULDER,
    H_LELBOW,
    H_LWRIST,
    H_RSHOULDER,
    H_RELBOW,
    H_RWRIST,
    H_LHIP,
    H_LKNEE,
    H_LANKLE,
    H_RHIP,
    H_RKNEE,
    H_RANKLE,
    H_COUNT
};

#define H_CAPSULES 18 /* even: body_field runs the capsules in pairs */

typedef struct humanoid_def {
    hjoint joints[H_COUNT];
    capsule caps[H_CAPSULES];
    ak_vec3 arm_dir[2]; /* [0] left, [1] right: rest direction shoulder -> wrist */
} humanoid_def;

static const char* const builtin_names[] = {"cylinder", "humanoid"};

/* ---- static helpers ------------------------------------------------------------------ */

static float smoothstep01(float x) {
    x = ak_clampf(x, 0.0f, 1.0f);
    return x * x * (3.0f - 2.0f * x);
}

static bool finite_pos(float x) { return ak_finitef(x) && x > 0.0f; }

static float* clip_channel(keyed_clip* k, ak_channel_target target, uint32_t joint) {
    AK_ASSERT(k->channel_count < CHANNELS_MAX);
    ak_raw_channel* c = &k->channels[k->channel_count];
    memset(c, 0, sizeof *c);
    c->target = target;
    c->index = joint;
    c->component_count = target == AK_CHANNEL_ROTATION ? 4u : 3u;
    c->interp = AK_INTERP_LINEAR;
    c->key_count = k->key_count;
    c->times = k->times;
    c->values = k->values[k->channel_count];
    return k->values[k->channel_count++];
}

static void put_quat(float* v, size_t key, ak_quat q) {
    v[4 * key + 0] = q.x, v[4 * key + 1] = q.y, v[4 * key + 2] = q.z, v[4 * key + 3] = q.w;
}

static void put_vec3(float* v, size_t key, ak_vec3 p) {
    v[3 * key + 0] = p.x, v[3 * key + 1] = p.y, v[3 * key + 2] = p.z;
}

static ak_result build_clip(const keyed_clip* k, float duration, size_t joint_count,
                            ak_scene* scene, size_t slot) {
    ak_raw_clip raw = {.name = k->name,
                       .duration = duration,
                       .channels = k->channels,
                       .channel_count = k->channel_count,
                       .joint_count = joint_count};
    ak_result r = ak_clip_build(&raw, &scene->alloc, &scene->clips[slot], NULL);
    /* The keys are written in this file: anything but NO_MEMORY is a bug here. */
    AK_ASSERT(r == AK_OK || r == AK_ERR_NO_MEMORY);
    return r == AK_OK ? AK_OK : AK_ERR_NO_MEMORY;
}

/* Skeleton, one skinned mesh and a 1:1 skin: the shape every builtin shares. */
static ak_result scene_assemble(ak_scene* scene, const ak_joint_desc* joints, size_t joint_count,
                                ak_mesh* mesh) {
    ak_skeleton_desc sd = {.joints = joints, .joint_count = joint_count, .name = scene->name};
    ak_result r = ak_skeleton_create(&sd, &scene->alloc, &scene->skeleton, NULL);
    if (r != AK_OK) {
        ak_mesh_destroy(mesh);
        return r == AK_ERR_NO_MEMORY ? r : AK_ERR_BAD_DATA;
    }
    scene->meshes[0].mesh = mesh;
    scene->meshes[0].node = -1;
    scene->meshes[0].skin = 0;
    r = ak_scene_skin_alloc(scene, 0, joint_count);
    if (r != AK_OK) return r;
    snprintf(scene->skins[0].name, AK_NAME_SIZE, "%s", scene->name);
    ak_mat4_cspan ib = ak_skeleton_inverse_binds(scene->skeleton);
    for (size_t j = 0; j < joint_count; ++j) {
        scene->skins[0].joints[j] = (int32_t)j;
        scene->skins[0].inverse_binds[j] = ib.ptr[j];
    }
    return AK_OK;
}

/* ---- cylinder -------------------------------------------------------------------------- */

static ak_result cylinder_create(const ak_builtin_desc* d, ak_scene* scene) {
    const uint32_t B = d->bone_count, R = d->rings, S = d->segments;
    const float L = d->length, rad = d->radius, bone_len = L / (float)B, band = d->blend * bone_len;
    const size_t side_v = (size_t)(R + 1) * S;
    ak_mesh_desc md = {.vertex_count = side_v + 2,
                       .triangle_count = 2 * (size_t)R * S + 2 * (size_t)S,
                       .influence_count = 4,
                       .has_normals = true,
                       .has_uvs = true,
                       .name = "cylinder"};
    ak_mesh* m = NULL;
    ak_result r = ak_mesh_create(&md, &scene->alloc, &m);
    if (r != AK_OK) return r;
    const uint32_t bottom = (uint32_t)side_v, top = bottom + 1;
    for (uint32_t i = 0; i <= R; ++i)
        for (uint32_t j = 0; j < S; ++j) {
            /* theta = 0 faces +Z and grows towards +X, so (ring i, j) -> (j+1) -> (ring i+1)
             * runs counter-clockwise seen from outside. */
            double th = 2.0 * 3.14159265358979323846 * j / S;
            size_t v = (size_t)i * S + j;
            float y = L * (float)i / (float)R;
            m->positions[v] = ak_vec3_make(rad * (float)sin(th), y, rad * (float)cos(th));
            m->normals[v] = ak_vec3_make((float)sin(th), 0.0f, (float)cos(th));
            m->uvs[v] = ak_vec2_make((float)j / (float)S, (float)i / (float)R);
        }
    m->positions[bottom] = ak_vec3_make(0, 0, 0);
    m->positions[top] = ak_vec3_make(0, L, 0);
    m->normals[bottom] = ak_vec3_make(0, -1, 0);
    m->normals[top] = ak_vec3_make(0, 1, 0);
    m->uvs[bottom] = ak_vec2_make(0.5f, 0.0f);
    m->uvs[top] = ak_vec2_make(0.5f, 1.0f);
    uint32_t* t = m->indices;
    for (uint32_t i = 0; i < R; ++i)
        for (uint32_t j = 0; j < S; ++j) {
            uint32_t a = i * S + j, b = i * S + (j + 1) % S, c = b + S, e = a + S;
            *t++ = a, *t++ = b, *t++ = c;
            *t++ = a, *t++ = c, *t++ = e;
        }
    for (uint32_t j = 0; j < S; ++j) {
        uint32_t a = j, b = (j + 1) % S;
        *t++ = bottom, *t++ = b, *t++ = a;
        *t++ = top, *t++ = R * S + a, *t++ = R * S + b;
    }
    /* Weights: bone b (driven by joint b) gets s_b(y) - s_b+1(y), where s_k rises from 0 to 1
     * across the band centred on interior joint k (s_0 = 1, s_B = 0): a partition of unity. */
    for (size_t v = 0; v < md.vertex_count; ++v) {
        float y = m->positions[v].y;
        float s_prev = 1.0f;
        uint32_t slot = 0;
        for (uint32_t b = 0; b < B; ++b) {
            float s_next =
                b + 1 < B ? smoothstep01((y - ((float)(b + 1) * bone_len - 0.5f * band)) / band)
                          : 0.0f;
            float w = s_prev - s_next;
            if (w > 0.0f && slot < 4) {
                m->joints[4 * v + slot] = (uint16_t)b;
                m->weights[4 * v + slot] = w;
                ++slot;
            }
            s_prev = s_next;
        }
    }
    ak_weights_normalize(m->joints, m->weights, md.vertex_count, 4, 4, 0.0f);

    /* Skeleton: root at the base, interior balls, a leaf tip at the top. */
    static const char* const names[2][4] = {{"root", "joint1", "tip", ""},
                                            {"root", "joint1", "joint2", "tip"}};
    ak_joint_desc js[4];
    memset(js, 0, sizeof js);
    for (uint32_t i = 0; i <= B; ++i) {
        js[i].name = names[B - 2][i];
        js[i].parent = (int)i - 1;
        js[i].rest = ak_transform_identity();
        if (i > 0) js[i].rest.translation.y = bone_len;
        if (i > 0 && i < B) {
            js[i].type = AK_JOINT_BALL;
            js[i].limits.axis = ak_vec3_make(0, 1, 0);
            js[i].limits.cone_angle = ak_radians(150.0f);
        }
    }
    r = scene_assemble(scene, js, B + 1, m);
    if (r != AK_OK) return r;

    /* Clips: 5 keys over 1 s, angles linear in time, split over the B-1 interior joints. */
    const float bend_total = ak_radians(120.0f), twist_total = AK_PI;
    const char* clip_names[3] = {"bend", "twist", "bend_twist"};
    for (int c = 0; c < 3; ++c) {
        keyed_clip* k = (keyed_clip*)akp_alloc(&scene->alloc, sizeof(keyed_clip));
        if (!k) return AK_ERR_NO_MEMORY;
        memset(k, 0, offsetof(keyed_clip, values));
        k->name = clip_names[c];
        k->key_count = 5;
        for (size_t i = 0; i < 5; ++i) k->times[i] = 0.25f * (float)i;
        for (uint32_t j = 1; j < B; ++j) {
            float* v = clip_channel(k, AK_CHANNEL_ROTATION, j);
            for (size_t i = 0; i < 5; ++i) {
                float u = k->times[i];
                ak_quat bend =
                    ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), u * bend_total / (float)(B - 1));
                ak_quat twist = ak_quat_from_axis_angle(ak_vec3_make(0, 1, 0),
                                                        u * twist_total / (float)(B - 1));
                ak_quat q = c == 0 ? bend : c == 1 ? twist : ak_quat_mul(bend, twist);
                put_quat(v, i, q);
            }
        }
        r = build_clip(k, 1.0f, B + 1, scene, (size_t)c);
        akp_free(&scene->alloc, k);
        if (r != AK_OK) return r;
    }
    return AK_OK;
}

/* ---- humanoid: definition ---------------------------------------------------------------- */

static ak_joint_limits ball_limits(ak_vec3 axis, float cone, float twist) {
    ak_joint_limits l = {.axis = axis, .cone_angle = cone, .twist_min = -twist, .twist_max = twist};
    return l;
}

static ak_joint_limits hinge_limits(ak_vec3 axis, float lo, float hi) {
    ak_joint_limits l = {.axis = axis, .min = lo, .max = hi};
    return l;
}

static void humanoid_define(humanoid_def* h) {
    memset(h, 0, sizeof *h);
    const float c45 = 0.70710678f;
    const ak_vec3 up = ak_vec3_make(0, 1, 0), down = ak_vec3_make(0, -1, 0),
                  xaxis = ak_vec3_make(1, 0, 0);
    hjoint* J = h->joints;
    J[H_PELVIS] = (hjoint){"pelvis",
                           -1,
                           {0, 0.95f, 0},
                           AK_JOINT_FREE,
                           {{0, 0, 0}, 0, 0, 0, 0, 0},
                           0,
                           {-0.1f, 0.93f, 0},
                           {0.1f, 0.93f, 0},
                           0.115f};
    J[H_SPINE1] = (hjoint){
        "spine_01", H_PELVIS,      {0, 1.05f, 0}, AK_JOINT_BALL, ball_limits(up, 0.45f, 0.5f),
        0,          {0, 1.05f, 0}, {0, 1.22f, 0}, 0.125f};
    J[H_SPINE2] = (hjoint){
        "spine_02", H_SPINE1,      {0, 1.22f, 0}, AK_JOINT_BALL, ball_limits(up, 0.45f, 0.5f),
        0,          {0, 1.22f, 0}, {0, 1.42f, 0}, 0.15f};
    J[H_NECK] =
        (hjoint){"neck", H_SPINE2,      {0, 1.47f, 0}, AK_JOINT_BALL, ball_limits(up, 0.7f, 1.0f),
                 0,      {0, 1.47f, 0}, {0, 1.57f, 0}, 0.05f};
    J[H_HEAD] =
        (hjoint){"head", H_NECK,        {0, 1.57f, 0}, AK_JOINT_BALL, ball_limits(up, 0.6f, 0.8f),
                 0,      {0, 1.60f, 0}, {0, 1.80f, 0}, 0.1f};
    for (int s = 0; s < 2; ++s) {
        const float sx = s == 0 ? 1.0f : -1.0f; /* left is +X */
        const int side = s == 0 ? 1 : -1;
        const int base = s == 0 ? H_LSHOULDER : H_RSHOULDER;
        const ak_vec3 d = ak_vec3_make(sx * c45, -c45, 0.0f); /* A-pose arm direction */
        h->arm_dir[s] = d;
        const ak_vec3 sh = ak_vec3_make(sx * 0.19f, 1.42f, 0.0f);
        const ak_vec3 el = ak_vec3_madd(sh, d, 0.28f), wr = ak_vec3_madd(el, d, 0.26f);
        const ak_vec3 hand_end = ak_vec3_madd(wr, d, 0.15f);
        /* Elbow flexion turns the forearm towards +Z: axis d x Z. */
        const ak_vec3 elbow_axis = ak_vec3_cross(d, ak_vec3_make(0, 0, 1));
        J[base] = (hjoint){s == 0 ? "left_shoulder" : "right_shoulder",
                           H_SPINE2,
                           sh,
                           AK_JOINT_BALL,
                           ball_limits(d, 2.4f, 2.0f),
                           side,
                           sh,
                           el,
                           0.05f};
        J[base + 1] = (hjoint){s == 0 ? "left_elbow" : "right_elbow",
                               base,
                               el,
                               AK_JOINT_HINGE,
                               hinge_limits(elbow_axis, 0.0f, ak_radians(145.0f)),
                               side,
                               el,
                               wr,
                               0.04f};
        J[base + 2] = (hjoint){s == 0 ? "left_wrist" : "right_wrist",
                               base + 1,
                               wr,
                               AK_JOINT_BALL,
                               ball_limits(d, 1.2f, 0.8f),
                               side,
                               wr,
                               hand_end,
                               0.035f};
        const int lb = s == 0 ? H_LHIP : H_RHIP;
        const ak_vec3 hip = ak_vec3_make(sx * 0.1f, 0.90f, 0.0f),
                      knee = ak_vec3_make(sx * 0.1f, 0.48f, 0.0f);
        const ak_vec3 ankle = ak_vec3_make(sx * 0.1f, 0.085f, 0.0f),
                      toe = ak_vec3_make(sx * 0.1f, 0.04f, 0.14f);
        /* Knee flexion swings the shank backwards (-Z): +X; positive ankle angle = toes down. */
        J[lb] = (hjoint){s == 0 ? "left_hip" : "right_hip",
                         H_PELVIS,
                         hip,
                         AK_JOINT_BALL,
                         ball_limits(down, ak_radians(90.0f), 0.7f),
                         side,
                         hip,
                         knee,
                         0.07f};
        J[lb + 1] = (hjoint){s == 0 ? "left_knee" : "right_knee",
                             lb,
                             knee,
                             AK_JOINT_HINGE,
                             hinge_limits(xaxis, 0.0f, ak_radians(140.0f)),
                             side,
                             knee,
                             ankle,
                             0.05f};
        J[lb + 2] = (hjoint){s == 0 ? "left_ankle" : "right_ankle",
                             lb + 1,
                             ankle,
                             AK_JOINT_HINGE,
                             hinge_limits(xaxis, ak_radians(-25.0f), ak_radians(35.0f)),
                             side,
                             ankle,
                             toe,
                             0.04f};
        /* Limb capsules. */
        capsule* c = h->caps + 8 + 5 * s;
        c[0] = (capsule){sh, el, 0.056f, 0.046f, 1.0f};
        c[1] = (capsule){el, wr, 0.045f, 0.034f, 1.0f};
        c[2] =
            (capsule){ak_vec3_madd(wr, d, 0.03f), ak_vec3_madd(wr, d, 0.12f), 0.04f, 0.036f, 0.8f};
        c[3] = (capsule){hip, knee, 0.082f, 0.06f, 1.0f};
        c[4] = (capsule){knee, ankle, 0.06f, 0.042f, 1.0f};
        h->caps[6 + s] = (capsule){ak_vec3_make(sx * 0.1f, 0.045f, -0.05f),
                                   ak_vec3_make(sx * 0.1f, 0.04f, 0.16f), 0.042f, 0.04f, 1.0f};
    }
    /* Trunk and head. */
    h->caps[0] = (capsule){{-0.085f, 0.93f, 0}, {0.085f, 0.93f, 0}, 0.115f, 0.115f, 0.78f};
    h->caps[1] = (capsule){{0, 0.95f, 0}, {0, 1.15f, 0}, 0.125f, 0.125f, 0.75f};
    h->caps[2] = (capsule){{0, 1.18f, 0}, {0, 1.34f, 0}, 0.15f, 0.15f, 0.72f};
    h->caps[3] = (capsule){{-0.16f, 1.40f, 0}, {0.16f, 1.40f, 0}, 0.065f, 0.065f, 1.0f};
    h->caps[4] = (capsule){{0, 1.38f, 0}, {0, 1.58f, 0}, 0.052f, 0.052f, 1.0f};
    h->caps[5] = (capsule){{0, 1.66f, 0.01f}, {0, 1.72f, 0}, 0.1f, 0.1f, 1.0f};
}

/* ---- humanoid: implicit surface ------------------------------------------------------------ */

#define BLEND_K 0.012 /* smooth-union radius, metres */

/* The capsules as flat double arrays (the field's hot loop runs over them in lanes), with the
 * same double values the per-capsule formula computed from the floats. */
typedef struct body_soa {
    double ax[H_CAPSULES], ay[H_CAPSULES], az[H_CAPSULES];
    double abx[H_CAPSULES], aby[H_CAPSULES], abz[H_CAPSULES], len2[H_CAPSULES];
    double ra[H_CAPSULES], dr[H_CAPSULES], zscale[H_CAPSULES];
} body_soa;

_Static_assert(H_CAPSULES % 2 == 0, "body_field runs the capsules in pairs");

static void body_soa_make(const humanoid_def* h, body_soa* b) {
    for (int i = 0; i < H_CAPSULES; ++i) {
        const capsule* c = &h->caps[i];
        b->ax[i] = c->a.x, b->ay[i] = c->a.y, b->az[i] = c->a.z;
        b->abx[i] = (double)c->b.x - c->a.x, b->aby[i] = (double)c->b.y - c->a.y, b->abz[i] = (double)c->b.z - c->a.z;
        b->len2[i] = b->abx[i] * b->abx[i] + b->aby[i] * b->aby[i] + b->abz[i] * b->abz[i];
        if (!(b->len2[i] > 0.0)) b->len2[i] = 1.0; /* a point capsule: its dot product is 0, t = 0 */
        b->ra[i] = c->ra, b->dr[i] = (double)c->rb - c->ra, b->zscale[i] = c->zscale;
    }
}

/* Signed field: negative inside. Smooth minimum (log-sum-exp) of the capsule distances (a
 * tapered capsule flattened front to back: the distance to the segment, z divided by zscale,
 * minus the radius interpolated along it). A capsule more than 38 blend radii farther than
 * the nearest adds under exp(-38) = 3e-17 to a sum of at least 1: below half an ulp of it, so
 * leaving out its exp() changes nothing (the meshes were compared byte for byte). */
static double body_field(const body_soa* b, double x, double y, double z) {
    double d[H_CAPSULES], m = 1e30;
#if AK_SIMD_SSE2
    /* two capsules a step, the scalar loop's operations in its order (bit-identical: the clamps
     * differ only for t = -0, which gives the same distance) */
    const __m128d px = _mm_set1_pd(x), py = _mm_set1_pd(y), pz = _mm_set1_pd(z);
    for (int i = 0; i < H_CAPSULES; i += 2) {
        const __m128d apx = _mm_sub_pd(px, _mm_loadu_pd(b->ax + i)), apy = _mm_sub_pd(py, _mm_loadu_pd(b->ay + i)),
                      apz = _mm_sub_pd(pz, _mm_loadu_pd(b->az + i));
        const __m128d abx = _mm_loadu_pd(b->abx + i), aby = _mm_loadu_pd(b->aby + i), abz = _mm_loadu_pd(b->abz + i);
        __m128d t = _mm_add_pd(_mm_add_pd(_mm_mul_pd(apx, abx), _mm_mul_pd(apy, aby)), _mm_mul_pd(apz, abz));
        t = _mm_div_pd(t, _mm_loadu_pd(b->len2 + i));
        t = _mm_min_pd(_mm_max_pd(t, _mm_setzero_pd()), _mm_set1_pd(1.0));
        const __m128d vx = _mm_sub_pd(apx, _mm_mul_pd(t, abx)), vy = _mm_sub_pd(apy, _mm_mul_pd(t, aby));
        const __m128d vz = _mm_div_pd(_mm_sub_pd(apz, _mm_mul_pd(t, abz)), _mm_loadu_pd(b->zscale + i));
        const __m128d len = _mm_sqrt_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(vx, vx), _mm_mul_pd(vy, vy)), _mm_mul_pd(vz, vz)));
        const __m128d r = _mm_add_pd(_mm_loadu_pd(b->ra + i), _mm_mul_pd(t, _mm_loadu_pd(b->dr + i)));
        _mm_storeu_pd(d + i, _mm_sub_pd(len, r));
    }
#else
    for (int i = 0; i < H_CAPSULES; ++i) {
        const double apx = x - b->ax[i], apy = y - b->ay[i], apz = z - b->az[i];
        double t = (apx * b->abx[i] + apy * b->aby[i] + apz * b->abz[i]) / b->len2[i];
        t = t < 0.0 ? 0.0 : t;
        t = t > 1.0 ? 1.0 : t;
        const double vx = apx - t * b->abx[i], vy = apy - t * b->aby[i], vz = (apz - t * b->abz[i]) / b->zscale[i];
        d[i] = sqrt(vx * vx + vy * vy + vz * vz) - (b->ra[i] + t * b->dr[i]);
    }
#endif
    for (int i = 0; i < H_CAPSULES; ++i) m = d[i] < m ? d[i] : m;
    double s = 0.0;
    for (int i = 0; i < H_CAPSULES; ++i)
        if (d[i] - m < 38.0 * BLEND_K) s += exp(-(d[i] - m) / BLEND_K);
    return m - BLEND_K * log(s);
}

static ak_vec3 body_gradient(const body_soa* h, ak_vec3 p, double eps) {
    double gx = body_field(h, p.x + eps, p.y, p.z) - body_field(h, p.x - eps, p.y, p.z);
    double gy = body_field(h, p.x, p.y + eps, p.z) - body_field(h, p.x, p.y - eps, p.z);
    double gz = body_field(h, p.x, p.y, p.z + eps) - body_field(h, p.x, p.y, p.z - eps);
    return ak_vec3_make((float)(gx / (2 * eps)), (float)(gy / (2 * eps)), (float)(gz / (2 * eps)));
}

/* Marching tetrahedra: each grid cube is split into the 6 Kuhn tetrahedra around its main
 * diagonal; every tetrahedron edge joins corners c0 < c1 with c1 a superset of c0's bits, so
 * an edge is (lower grid point, direction c1 ^ c0 in 1..7) and crossing vertices are shared
 * between neighbouring tetrahedra. The decomposition matches across cube faces, so each
 * iso-segment on a tetrahedron face is produced by exactly the two tetrahedra sharing it:
 * the result is closed and manifold. Orientation is decided on exact integer geometry (edge
 * midpoints against the inside -> outside direction), never on the float crossings. */
static const int kuhn_tets[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7},
                                    {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};

typedef struct mt_grid {
    int nx, ny, nz;
    double x0, y0, z0, h;
    const double* f;    /* [nx*ny*nz] */
    int32_t* edge_vert; /* [7 * nx*ny*nz], vertex index + 1, 0 = none */
    ak_vec3* verts;
    size_t vert_count, vert_cap;
    uint32_t* tris;
    size_t tri_count, tri_cap;
    bool overflow;
} mt_grid;

static size_t grid_index(const mt_grid* g, int i, int j, int k) {
    return ((size_t)k * (size_t)g->ny + (size_t)j) * (size_t)g->nx + (size_t)i;
}

static int32_t edge_vertex(mt_grid* g, int ci, int cj, int ck, int c0, int c1) {
    int i0 = ci + (c0 & 1), j0 = cj + ((c0 >> 1) & 1), k0 = ck + ((c0 >> 2) & 1);
    int i1 = ci + (c1 & 1), j1 = cj + ((c1 >> 1) & 1), k1 = ck + ((c1 >> 2) & 1);
    size_t p0 = grid_index(g, i0, j0, k0), p1 = grid_index(g, i1, j1, k1);
    size_t key = p0 * 7 + (size_t)((c0 ^ c1) - 1);
    if (g->edge_vert[key]) return g->edge_vert[key] - 1;
    if (g->vert_count >= g->vert_cap) {
        g->overflow = true;
        return 0;
    }
    double f0 = g->f[p0], f1 = g->f[p1];
    double t = f0 / (f0 - f1);
    t = t < 0.02 ? 0.02 : (t > 0.98 ? 0.98 : t);
    double x0 = g->x0 + g->h * i0, y0 = g->y0 + g->h * j0, z0 = g->z0 + g->h * k0;
    double x1 = g->x0 + g->h * i1, y1 = g->y0 + g->h * j1, z1 = g->z0 + g->h * k1;
    g->verts[g->vert_count] = ak_vec3_make((float)(x0 + t * (x1 - x0)), (float)(y0 + t * (y1 - y0)),
                                           (float)(z0 + t * (z1 - z0)));
    g->edge_vert[key] = (int32_t)(++g->vert_count);
    return (int32_t)(g->vert_count - 1);
}

/* Corner offset of a cube corner, doubled (so edge midpoints are integers). */
static void corner2(int c, long out[3]) {
    out[0] = 2 * (c & 1), out[1] = 2 * ((c >> 1) & 1), out[2] = 2 * ((c >> 2) & 1);
}

static void emit_tri(mt_grid* g, int32_t a, int32_t b, int32_t c) {
    if (g->tri_count >= g->tri_cap) {
        g->overflow = true;
        return;
    }
    g->tris[3 * g->tri_count] = (uint32_t)a, g->tris[3 * g->tri_count + 1] = (uint32_t)b;
    g->tris[3 * g->tri_count + 2] = (uint32_t)c;
    g->tri_count++;
}

/* True when the triangle over edges (e[0], e[1], e[2]) (corner pairs, midpoints) turns
 * counter-clockwise seen from the outside corners. */
static bool midpoint_ccw(const int e[3][2], const int* inside, int in_count, const int* outside,
                         int out_count) {
    long m[3][3];
    for (int i = 0; i < 3; ++i) {
        long a[3], b[3];
        corner2(e[i][0], a);
        corner2(e[i][1], b);
        for (int k = 0; k < 3; ++k) m[i][k] = (a[k] + b[k]); /* 2 * 2 * midpoint */
    }
    long u[3] = {m[1][0] - m[0][0], m[1][1] - m[0][1], m[1][2] - m[0][2]};
    long v[3] = {m[2][0] - m[0][0], m[2][1] - m[0][1], m[2][2] - m[0][2]};
    long n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    /* in_count * out_count * (centroid_out - centroid_in), in integers. */
    long dir[3] = {0, 0, 0};
    for (int i = 0; i < out_count; ++i) {
        long c[3];
        corner2(outside[i], c);
        for (int k = 0; k < 3; ++k) dir[k] += in_count * c[k];
    }
    for (int i = 0; i < in_count; ++i) {
        long c[3];
        corner2(inside[i], c);
        for (int k = 0; k < 3; ++k) dir[k] -= out_count * c[k];
    }
    return n[0] * dir[0] + n[1] * dir[1] + n[2] * dir[2] > 0;
}

static void march_tet(mt_grid* g, int ci, int cj, int ck, const int corners[4]) {
    int inside[4], outside[4], ni = 0, no = 0;
    for (int v = 0; v < 4; ++v) {
        int c = corners[v];
        double f = g->f[grid_index(g, ci + (c & 1), cj + ((c >> 1) & 1), ck + ((c >> 2) & 1))];
        if (f < 0.0)
            inside[ni++] = c;
        else
            outside[no++] = c;
    }
    if (ni == 0 || no == 0) return;
#define EDGE_(a, b) ((a) < (b) ? (a) : (b)), ((a) < (b) ? (b) : (a))
    if (ni == 1 || no == 1) {
        const int lone = ni == 1 ? inside[0] : outside[0];
        const int* others = ni == 1 ? outside : inside;
        int e[3][2] = {
            {EDGE_(lone, others[0])}, {EDGE_(lone, others[1])}, {EDGE_(lone, others[2])}};
        bool ccw = midpoint_ccw((const int(*)[2])e, inside, ni, outside, no);
        int32_t v[3];
        for (int i = 0; i < 3; ++i) v[i] = edge_vertex(g, ci, cj, ck, e[i][0], e[i][1]);
        if (ccw)
            emit_tri(g, v[0], v[1], v[2]);
        else
            emit_tri(g, v[0], v[2], v[1]);
    } else {
        const int a = inside[0], b = inside[1], c = outside[0], d = outside[1];
        int e[4][2] = {{EDGE_(a, c)}, {EDGE_(a, d)}, {EDGE_(b, d)}, {EDGE_(b, c)}};
        bool ccw = midpoint_ccw((const int(*)[2])e, inside, ni, outside, no);
        int32_t v[4];
        for (int i = 0; i < 4; ++i) v[i] = edge_vertex(g, ci, cj, ck, e[i][0], e[i][1]);
        if (ccw) {
            emit_tri(g, v[0], v[1], v[2]);
            emit_tri(g, v[0], v[2], v[3]);
        } else {
            emit_tri(g, v[0], v[2], v[1]);
            emit_tri(g, v[0], v[3], v[2]);
        }
    }
#undef EDGE_
}

/* Polygonise the body into a new mesh (positions, indices, normals). */
static ak_result humanoid_surface(const humanoid_def* h, float cell, const ak_allocator* alloc,
                                  ak_mesh** out) {
    ak_vec3 lo = ak_vec3_splat(1e30f), hi = ak_vec3_splat(-1e30f);
    for (int i = 0; i < H_CAPSULES; ++i) {
        float r = ak_maxf(h->caps[i].ra, h->caps[i].rb);
        lo =
            ak_vec3_min(lo, ak_vec3_sub(ak_vec3_min(h->caps[i].a, h->caps[i].b), ak_vec3_splat(r)));
        hi =
            ak_vec3_max(hi, ak_vec3_add(ak_vec3_max(h->caps[i].a, h->caps[i].b), ak_vec3_splat(r)));
    }
    const double hstep = cell, margin = 3.0 * cell;
    body_soa soa;
    body_soa_make(h, &soa);
    mt_grid g;
    memset(&g, 0, sizeof g);
    g.h = hstep;
    g.x0 = lo.x - margin, g.y0 = lo.y - margin, g.z0 = lo.z - margin;
    g.nx = (int)ceil((hi.x - lo.x + 2 * margin) / hstep) + 1;
    g.ny = (int)ceil((hi.y - lo.y + 2 * margin) / hstep) + 1;
    g.nz = (int)ceil((hi.z - lo.z + 2 * margin) / hstep) + 1;
    const size_t np = (size_t)g.nx * (size_t)g.ny * (size_t)g.nz;
    double* f = (double*)akp_alloc(alloc, np * sizeof(double));
    g.edge_vert = (int32_t*)akp_calloc(alloc, 7 * np * sizeof(int32_t));
    ak_result r = AK_OK;
    if (!f || !g.edge_vert) {
        r = AK_ERR_NO_MEMORY;
        goto done;
    }
    g.f = f;
    for (int k = 0; k < g.nz; ++k)
        for (int j = 0; j < g.ny; ++j)
            for (int i = 0; i < g.nx; ++i)
                f[grid_index(&g, i, j, k)] =
                    body_field(&soa, g.x0 + hstep * i, g.y0 + hstep * j, g.z0 + hstep * k);
    /* Exact output bounds: one vertex per sign-changing edge (lower end, direction 1..7),
     * at most two triangles per tetrahedron with mixed signs. */
    for (int k = 0; k < g.nz; ++k)
        for (int j = 0; j < g.ny; ++j)
            for (int i = 0; i < g.nx; ++i) {
                const bool in0 = f[grid_index(&g, i, j, k)] < 0.0;
                for (int c = 1; c < 8; ++c) {
                    int i1 = i + (c & 1), j1 = j + ((c >> 1) & 1), k1 = k + ((c >> 2) & 1);
                    if (i1 < g.nx && j1 < g.ny && k1 < g.nz)
                        g.vert_cap += in0 != (f[grid_index(&g, i1, j1, k1)] < 0.0);
                }
                if (i + 1 == g.nx || j + 1 == g.ny || k + 1 == g.nz) continue;
                for (int t = 0; t < 6; ++t) {
                    int n_in = 0;
                    for (int v = 0; v < 4; ++v) {
                        int c = kuhn_tets[t][v];
                        n_in +=
                            f[grid_index(&g, i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1))] <
                            0.0;
                    }
                    if (n_in > 0 && n_in < 4) g.tri_cap += 2;
                }
            }
    g.verts = (ak_vec3*)akp_alloc(alloc, (g.vert_cap ? g.vert_cap : 1) * sizeof(ak_vec3));
    g.tris = (uint32_t*)akp_alloc(alloc, 3 * (g.tri_cap ? g.tri_cap : 1) * sizeof(uint32_t));
    if (!g.verts || !g.tris) {
        r = AK_ERR_NO_MEMORY;
        goto done;
    }
    for (int k = 0; k + 1 < g.nz; ++k)
        for (int j = 0; j + 1 < g.ny; ++j)
            for (int i = 0; i + 1 < g.nx; ++i)
                for (int t = 0; t < 6; ++t) march_tet(&g, i, j, k, kuhn_tets[t]);
    if (g.overflow || g.tri_count == 0 || g.vert_count > UINT32_MAX) {
        r = AK_ERR_BAD_ARG;
        goto done;
    }
    /* Relax: umbrella steps (each directed edge a->b adds b to a's average; in a closed
     * oriented mesh every neighbour appears once), each followed by Newton projection back
     * onto the zero set. The connectivity, hence closedness, never changes. */
    {
        ak_vec3* acc = (ak_vec3*)akp_alloc(alloc, g.vert_count * sizeof(ak_vec3));
        uint32_t* cnt = (uint32_t*)akp_alloc(alloc, g.vert_count * sizeof(uint32_t));
        if (!acc || !cnt) {
            akp_free(alloc, acc);
            akp_free(alloc, cnt);
            r = AK_ERR_NO_MEMORY;
            goto done;
        }
        const double eps = 0.05 * hstep;
        for (int it = 0; it < 4; ++it) {
            memset(acc, 0, g.vert_count * sizeof(ak_vec3));
            memset(cnt, 0, g.vert_count * sizeof(uint32_t));
            for (size_t t = 0; t < g.tri_count; ++t)
                for (int e = 0; e < 3; ++e) {
                    uint32_t a = g.tris[3 * t + (size_t)e],
                             b = g.tris[3 * t + (size_t)((e + 1) % 3)];
                    acc[a] = ak_vec3_add(acc[a], g.verts[b]);
                    cnt[a]++;
                }
            for (size_t v = 0; v < g.vert_count; ++v) {
                ak_vec3 p = g.verts[v];
                if (cnt[v]) p = ak_vec3_lerp(p, ak_vec3_scale(acc[v], 1.0f / (float)cnt[v]), 0.5f);
                for (int n = 0; n < 3; ++n) {
                    double fv = body_field(&soa, p.x, p.y, p.z);
                    ak_vec3 gr = body_gradient(&soa, p, eps);
                    float g2 = ak_vec3_length_sq(gr);
                    if (!(g2 > 1e-8f)) break;
                    float step = (float)(fv / g2);
                    ak_vec3 delta = ak_vec3_scale(gr, step);
                    float dl = ak_vec3_length(delta);
                    if (dl > (float)hstep) delta = ak_vec3_scale(delta, (float)hstep / dl);
                    p = ak_vec3_sub(p, delta);
                }
                g.verts[v] = p;
            }
        }
        akp_free(alloc, acc);
        akp_free(alloc, cnt);
    }
    {
        ak_mesh_desc md = {.vertex_count = g.vert_count,
                           .triangle_count = g.tri_count,
                           .influence_count = 4,
                           .has_normals = true,
                           .name = "humanoid"};
        ak_mesh* m = NULL;
        r = ak_mesh_create(&md, alloc, &m);
        if (r != AK_OK) goto done;
        memcpy(m->positions, g.verts, g.vert_count * sizeof(ak_vec3));
        memcpy(m->indices, g.tris, 3 * g.tri_count * sizeof(uint32_t));
        ak_mesh_compute_normals(m); /* fallback where the field gradient degenerates */
        for (size_t v = 0; v < g.vert_count; ++v) {
            ak_vec3 n = ak_vec3_normalize(body_gradient(&soa, m->positions[v], 0.05 * hstep));
            if (ak_vec3_length_sq(n) > 0.5f) m->normals[v] = n;
        }
        *out = m;
    }
done:
    akp_free(alloc, f);
    akp_free(alloc, g.edge_vert);
    akp_free(alloc, g.verts);
    akp_free(alloc, g.tris);
    return r;
}

static double segment_distance2(ak_vec3 p, ak_vec3 a, ak_vec3 b) {
    double abx = (double)b.x - a.x, aby = (double)b.y - a.y, abz = (double)b.z - a.z;
    double apx = (double)p.x - a.x, apy = (double)p.y - a.y, apz = (double)p.z - a.z;
    double len2 = abx * abx + aby * aby + abz * abz;
    double t = len2 > 0.0 ? (apx * abx + apy * aby + apz * abz) / len2 : 0.0;
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    double dx = apx - t * abx, dy = apy - t * aby, dz = apz - t * abz;
    return dx * dx + dy * dy + dz * dz;
}

/* Weights: 1 / (d^2 + eps^2)^2 with d the distance to each joint's bone segment less 3/4 of
 * the flesh radius there (so a chest vertex belongs to the chest, not to the nearer but
 * thinner upper arm), one side's limbs faded out on the other side, then the 4 largest kept
 * and renormalised. */
static void humanoid_weights(const humanoid_def* h, ak_mesh* m) {
    for (size_t v = 0; v < m->vertex_count; ++v) {
        ak_vec3 p = m->positions[v];
        float left = smoothstep01((p.x + 0.02f) / 0.04f);
        double w[H_COUNT];
        for (int j = 0; j < H_COUNT; ++j) {
            const hjoint* J = &h->joints[j];
            double dist = sqrt(segment_distance2(p, J->seg_a, J->seg_b)) - 0.75 * J->radius;
            double d2 = (dist > 0.0 ? dist * dist : 0.0) + 4e-4;
            double side = J->side > 0 ? left : (J->side < 0 ? 1.0 - left : 1.0);
            w[j] = side / (d2 * d2);
        }
        for (int k = 0; k < 4; ++k) {
            int best = 0;
            for (int j = 1; j < H_COUNT; ++j)
                if (w[j] > w[best]) best = j;
            m->joints[4 * v + (size_t)k] = (uint16_t)best;
            m->weights[4 * v + (size_t)k] = (float)w[best];
            w[best] = -1.0;
        }
        /* Scale so the largest is 1 before the float renormalisation. */
        float top = m->weights[4 * v];
        for (int k = 0; k < 4; ++k)
            m->weights[4 * v + (size_t)k] =
                top > 0.0f ? ak_maxf(m->weights[4 * v + (size_t)k], 0.0f) / top : 0.0f;
    }
    ak_weights_normalize(m->joints, m->weights, m->vertex_count, 4, 4, 0.01f);
}

/* ---- humanoid: clips ----------------------------------------------------------------------- */

static ak_quat qaxis(float x, float y, float z, float angle) {
    return ak_quat_from_axis_angle(ak_vec3_make(x, y, z), angle);
}

static ak_result humanoid_clips(const humanoid_def* h, ak_scene* scene) {
    keyed_clip* k = (keyed_clip*)akp_alloc(&scene->alloc, sizeof(keyed_clip));
    if (!k) return AK_ERR_NO_MEMORY;
    const float tau = AK_TWO_PI;

    /* walk: 1 s cycle, 17 keys (the last equals the first, so it loops). Phase p = 2 pi t.
     * The left thigh is forward at p = pi/2; each knee flexes during its swing; the arms
     * swing against the legs; the pelvis is lowest with the feet apart. */
    memset(k, 0, offsetof(keyed_clip, values));
    k->name = "walk";
    k->key_count = 17;
    for (size_t i = 0; i < 17; ++i) k->times[i] = (float)i / 16.0f;
    float* pel_t = clip_channel(k, AK_CHANNEL_TRANSLATION, H_PELVIS);
    float* pel_r = clip_channel(k, AK_CHANNEL_ROTATION, H_PELVIS);
    float* sp1 = clip_channel(k, AK_CHANNEL_ROTATION, H_SPINE1);
    float* sp2 = clip_channel(k, AK_CHANNEL_ROTATION, H_SPINE2);
    float* head = clip_channel(k, AK_CHANNEL_ROTATION, H_HEAD);
    float *hip[2], *knee[2], *ankle[2], *shoulder[2], *elbow[2];
    for (int s = 0; s < 2; ++s) {
        hip[s] = clip_channel(k, AK_CHANNEL_ROTATION, (uint32_t)(s ? H_RHIP : H_LHIP));
        knee[s] = clip_channel(k, AK_CHANNEL_ROTATION, (uint32_t)(s ? H_RKNEE : H_LKNEE));
        ankle[s] = clip_channel(k, AK_CHANNEL_ROTATION, (uint32_t)(s ? H_RANKLE : H_LANKLE));
        shoulder[s] =
            clip_channel(k, AK_CHANNEL_ROTATION, (uint32_t)(s ? H_RSHOULDER : H_LSHOULDER));
        elbow[s] = clip_channel(k, AK_CHANNEL_ROTATION, (uint32_t)(s ? H_RELBOW : H_LELBOW));
    }
    for (size_t i = 0; i < 17; ++i) {
        const float p = tau * (float)(i % 16) / 16.0f;
        put_vec3(pel_t, i, ak_vec3_make(0.0f, 0.95f + 0.02f * cosf(2.0f * p), 0.0f));
        put_quat(pel_r, i, qaxis(0, 1, 0, -0.08f * sinf(p)));
        put_quat(sp1, i, qaxis(1, 0, 0, 0.04f));
        put_quat(sp2, i, qaxis(0, 1, 0, 0.14f * sinf(p)));
        put_quat(head, i, qaxis(0, 1, 0, -0.06f * sinf(p)));
        for (int s = 0; s < 2; ++s) {
            const float ps = s == 0 ? p : p + AK_PI; /* right side half a cycle later */
            const float sx = s == 0 ? 1.0f : -1.0f;
            put_quat(hip[s], i, qaxis(1, 0, 0, -0.42f * sinf(ps)));
            float swing = ak_maxf(0.0f, cosf(ps));
            put_quat(knee[s], i,
                     ak_quat_from_axis_angle(h->joints[H_LKNEE].limits.axis,
                                             0.1f + 0.8f * swing * swing));
            put_quat(ankle[s], i, qaxis(1, 0, 0, 0.18f * sinf(ps)));
            /* Arm: lowered 30 degrees towards the body, then swung against the same-side leg. */
            ak_quat lower = qaxis(0, 0, 1, -sx * ak_radians(30.0f));
            put_quat(shoulder[s], i, ak_quat_mul(qaxis(1, 0, 0, 0.35f * sinf(ps)), lower));
            const int ej = s == 0 ? H_LELBOW : H_RELBOW;
            put_quat(elbow[s], i,
                     ak_quat_from_axis_angle(h->joints[ej].limits.axis, 0.4f + 0.2f * sinf(ps)));
        }
    }
    ak_result r = build_clip(k, 1.0f, H_COUNT, scene, 0);
    if (r != AK_OK) {
        akp_free(&scene->alloc, k);
        return r;
    }

    /* wave: 2 s, 21 keys. The right upper arm rises 65 degrees (to 20 degrees above
     * horizontal) and turns 90 degrees about its own axis so the elbow flexes upwards; the
     * wave is that turn oscillating +-20 degrees, three times. Envelope in and out 0.4 s. */
    memset(k, 0, offsetof(keyed_clip, values));
    k->name = "wave";
    k->key_count = 21;
    for (size_t i = 0; i < 21; ++i) k->times[i] = 0.1f * (float)i;
    float* rs = clip_channel(k, AK_CHANNEL_ROTATION, H_RSHOULDER);
    float* re = clip_channel(k, AK_CHANNEL_ROTATION, H_RELBOW);
    float* rw = clip_channel(k, AK_CHANNEL_ROTATION, H_RWRIST);
    float* hd = clip_channel(k, AK_CHANNEL_ROTATION, H_HEAD);
    const ak_vec3 d = h->arm_dir[1];
    for (size_t i = 0; i < 21; ++i) {
        const float t = k->times[i];
        const float env =
            t < 0.4f ? smoothstep01(t / 0.4f) : (t > 1.6f ? smoothstep01((2.0f - t) / 0.4f) : 1.0f);
        const float osc = (t > 0.4f && t < 1.6f) ? sinf(tau * (t - 0.4f) / 0.4f) : 0.0f;
        ak_quat raise = qaxis(0, 0, 1, -ak_radians(65.0f) * env);
        ak_quat turn = ak_quat_from_axis_angle(d, env * (AK_HALF_PI + ak_radians(20.0f) * osc));
        put_quat(rs, i, ak_quat_mul(raise, turn));
        put_quat(
            re, i,
            ak_quat_from_axis_angle(h->joints[H_RELBOW].limits.axis, env * (1.5f + 0.1f * osc)));
        put_quat(rw, i, ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), 0.2f * env * osc));
        put_quat(hd, i, qaxis(0, 1, 0, -0.25f * env));
    }
    r = build_clip(k, 2.0f, H_COUNT, scene, 1);
    akp_free(&scene->alloc, k);
    return r;
}

static ak_result humanoid_create(const ak_builtin_desc* d, ak_scene* scene) {
    humanoid_def* h = (humanoid_def*)akp_alloc(&scene->alloc, sizeof(humanoid_def));
    if (!h) return AK_ERR_NO_MEMORY;
    humanoid_define(h);
    ak_mesh* m = NULL;
    ak_result r = humanoid_surface(h, d->cell_size, &scene->alloc, &m);
    if (r == AK_OK) {
        humanoid_weights(h, m);
        ak_joint_desc js[H_COUNT];
        memset(js, 0, sizeof js);
        for (int j = 0; j < H_COUNT; ++j) {
            const hjoint* J = &h->joints[j];
            js[j].name = J->name;
            js[j].parent = J->parent;
            js[j].rest = ak_transform_identity();
            js[j].rest.translation =
                J->parent < 0 ? J->pos : ak_vec3_sub(J->pos, h->joints[J->parent].pos);
            js[j].type = J->type;
            js[j].limits = J->limits;
        }
        r = scene_assemble(scene, js, H_COUNT, m);
    }
    if (r == AK_OK) r = humanoid_clips(h, scene);
    akp_free(&scene->alloc, h);
    return r;
}

/* ---- public ------------------------------------------------------------------------------ */

ak_builtin_desc ak_builtin_desc_resolved(const ak_builtin_desc* desc) {
    ak_builtin_desc d;
    memset(&d, 0, sizeof d);
    if (desc) d = *desc;
    if (d.length == 0.0f) d.length = 2.0f;
    if (d.radius == 0.0f) d.radius = 0.25f;
    if (d.rings == 0) d.rings = 48;
    if (d.segments == 0) d.segments = 32;
    if (d.bone_count == 0) d.bone_count = 2;
    if (d.blend == 0.0f) d.blend = 0.5f;
    if (d.cell_size == 0.0f) d.cell_size = 0.03f;
    return d;
}

ak_result ak_builtin_create(const char* name, const ak_builtin_desc* desc,
                            const ak_allocator* alloc, ak_scene** out_scene) {
    if (out_scene) *out_scene = NULL;
    if (!name || !out_scene) return AK_ERR_NULL_ARG;
    if (strncmp(name, "builtin:", 8) == 0) name += 8;
    int which = -1;
    for (int i = 0; i < 2; ++i)
        if (strcmp(name, builtin_names[i]) == 0) which = i;
    if (which < 0) return AK_ERR_NOT_FOUND;
    if (alloc && (!alloc->alloc != !alloc->free)) return AK_ERR_BAD_ARG;
    const ak_builtin_desc d = ak_builtin_desc_resolved(desc);
    if (which == 0) {
        if (!finite_pos(d.length) || !finite_pos(d.radius) || d.rings > 4096 || d.segments < 3 ||
            d.segments > 4096 || d.bone_count < 2 || d.bone_count > 3 || !finite_pos(d.blend) ||
            d.blend > 1.0f)
            return AK_ERR_BAD_ARG;
    } else if (!(d.cell_size >= 0.008f && d.cell_size <= 0.1f)) {
        return AK_ERR_BAD_ARG;
    }
    ak_scene* scene = NULL;
    ak_result r = ak_scene_alloc(1, 1, which == 0 ? 3 : 2, alloc, &scene);
    if (r != AK_OK) return r;
    snprintf(scene->name, AK_NAME_SIZE, "builtin:%s", builtin_names[which]);
    r = which == 0 ? cylinder_create(&d, scene) : humanoid_create(&d, scene);
    if (r != AK_OK) {
        ak_scene_destroy(scene);
        return r;
    }
    *out_scene = scene;
    return AK_OK;
}

const char* const* ak_builtin_names(size_t* out_count) {
    if (out_count) *out_count = sizeof builtin_names / sizeof builtin_names[0];
    return builtin_names;
}
