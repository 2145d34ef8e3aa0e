/* Skeleton: creation and validation, reordering, forward kinematics, joint limits. */
#include <animkit/skeleton.h>

#include "internal.h"
#include "simd.h" /* SSE2 columns in the FK products */

struct ak_skeleton {
    ak_allocator alloc;
    size_t joint_count;
    char name[AK_NAME_SIZE];
    int32_t* parents;            /* [n] */
    ak_transform* rest;          /* [n], rotations normalised */
    ak_mat4* inverse_binds;      /* [n] */
    char (*names)[AK_NAME_SIZE]; /* [n] */
    ak_joint_limits* limits;     /* [n], defaults resolved */
    uint32_t* child_counts;      /* [n] */
    uint8_t* types;              /* [n] ak_joint_type */
    bool palette_from_skins;     /* desc.palette_from_skins */
    uint8_t fk_kernel;           /* AKP_FK_K_*: the FK kernel (fk_pick at create, or the limit set) */
};

/* FK kernels (src/skeleton.c, "forward kinematics"). */
enum { AKP_FK_K_SCALAR = 0, AKP_FK_K_AVX, AKP_FK_K_AVX2, AKP_FK_K_AVX512 };
static uint8_t fk_pick(ak_fk_simd limit);

#define MAX_JOINTS AK_SKELETON_MAX_JOINTS

static bool limits_finite(const ak_joint_limits* l) {
    return ak_vec3_is_finite(l->axis) && ak_finitef(l->min) && ak_finitef(l->max) &&
           ak_finitef(l->cone_angle) && ak_finitef(l->twist_min) && ak_finitef(l->twist_max);
}

static bool mat4_finite(const ak_mat4* m) {
    for (int i = 0; i < 16; ++i)
        if (!ak_finitef(m->m[i])) return false;
    return true;
}

static ak_joint_limits resolve_limits(ak_joint_type type, ak_joint_limits l) {
    ak_vec3 axis = ak_vec3_normalize(l.axis);
    if (ak_vec3_length_sq(axis) < 0.5f)
        axis =
            type == AK_JOINT_BALL ? ak_vec3_make(0.0f, 1.0f, 0.0f) : ak_vec3_make(1.0f, 0.0f, 0.0f);
    l.axis = axis;
    return l;
}

/* Index sort of names for duplicate detection. */
typedef struct name_ref {
    const char* name;
    size_t index;
} name_ref;

static int cmp_name_ref(const void* a, const void* b) {
    const name_ref *x = (const name_ref*)a, *y = (const name_ref*)b;
    int c = strcmp(x->name, y->name);
    if (c) return c;
    return (x->index > y->index) - (x->index < y->index);
}

/* Signed angle of a twist quaternion about unit axis, in [-pi, pi]. */
static float twist_angle(ak_quat twist, ak_vec3 axis) {
    if (twist.w < 0.0f) twist = ak_quat_neg(twist);
    float s = twist.x * axis.x + twist.y * axis.y + twist.z * axis.z;
    return 2.0f * atan2f(s, twist.w);
}

/* Angle in [0, pi] of a rotation. */
static float rotation_angle(ak_quat q) {
    float s = sqrtf(q.x * q.x + q.y * q.y + q.z * q.z);
    return 2.0f * atan2f(s, fabsf(q.w));
}

static float wrap_pi(float a) {
    while (a > AK_PI) a -= AK_TWO_PI;
    while (a < -AK_PI) a += AK_TWO_PI;
    return a;
}

/* The angle equal to a modulo a full turn in [lo, lo + 2 pi): the same rotation. Limits may
 * cross +-pi (e.g. [2.5, 3.5]) while twist angles come in (-pi, pi]. */
static float angle_from(float a, float lo) {
    float d = fmodf(a - lo, AK_TWO_PI);
    if (d < 0.0f) d += AK_TWO_PI;
    return lo + d;
}

/* Clamp an angle to [lo, hi] on the circle: outside the range, go to the nearer end. */
static float clamp_angle(float a, float lo, float hi) {
    if ((a >= lo && a <= hi) || angle_from(a, lo) <= hi) return a;
    float dlo = fabsf(wrap_pi(a - lo)), dhi = fabsf(wrap_pi(a - hi));
    return dlo <= dhi ? lo : hi;
}

static bool angle_in_range(float a, float lo, float hi, float tol) {
    if (a >= lo - tol && a <= hi + tol) return true;
    /* The same rotation written with the angle a whole number of turns away. */
    return angle_from(a, lo - tol) <= hi + tol;
}

/* ---- creation ------------------------------------------------------------------------ */

ak_result ak_skeleton_create(const ak_skeleton_desc* desc, const ak_allocator* alloc,
                             ak_skeleton** out_skeleton, ak_diag* diag) {
    if (out_skeleton) *out_skeleton = NULL;
    if (!desc || !out_skeleton) return AK_ERR_NULL_ARG;
    if (desc->joint_count == 0) {
        akp_diag_set(diag, NULL, "skeleton has no joints");
        return AK_ERR_EMPTY;
    }
    if (!desc->joints) return AK_ERR_NULL_ARG;
    if (desc->joint_count > MAX_JOINTS) {
        akp_diag_set(diag, NULL, "skeleton has %zu joints, more than %u", desc->joint_count,
                     MAX_JOINTS);
        return AK_ERR_BAD_ARG;
    }
    if (alloc && (!alloc->alloc != !alloc->free)) return AK_ERR_BAD_ARG;
    const size_t n = desc->joint_count;
    for (size_t i = 0; i < n; ++i) {
        const ak_joint_desc* j = &desc->joints[i];
        if (!j->name) {
            akp_diag_set(diag, NULL, "joint %zu has no name", i);
            return AK_ERR_NULL_ARG;
        }
        if ((int)j->type < 0 || j->type >= AK_JOINT_TYPE_COUNT) {
            akp_diag_set(diag, NULL, "joint %zu '%s' has unknown type %d", i, j->name,
                         (int)j->type);
            return AK_ERR_BAD_ARG;
        }
        if (j->parent < -1 || (j->parent >= 0 && (size_t)j->parent >= i)) {
            akp_diag_set(
                diag, NULL,
                "joint %zu '%s' has parent %d, which is not before it (use ak_skeleton_reorder)", i,
                j->name, j->parent);
            return AK_ERR_BAD_HIERARCHY;
        }
        if (!ak_transform_is_finite(j->rest)) {
            akp_diag_set(diag, NULL, "joint %zu '%s' has a non-finite rest transform", i, j->name);
            return AK_ERR_BAD_DATA;
        }
        if (!(ak_quat_dot(j->rest.rotation, j->rest.rotation) > 1e-12f)) {
            akp_diag_set(diag, NULL,
                         "joint %zu '%s' has a zero rest rotation (use ak_transform_identity())", i,
                         j->name);
            return AK_ERR_BAD_DATA;
        }
        if (j->inverse_bind && !mat4_finite(j->inverse_bind)) {
            akp_diag_set(diag, NULL, "joint %zu '%s' has a non-finite inverse bind matrix", i,
                         j->name);
            return AK_ERR_BAD_DATA;
        }
        const ak_joint_limits* l = &j->limits;
        if (!limits_finite(l) || l->min > l->max || l->twist_min > l->twist_max ||
            l->cone_angle < 0.0f) {
            akp_diag_set(
                diag, NULL,
                "joint %zu '%s' has invalid limits (non-finite, min > max or negative cone)", i,
                j->name);
            return AK_ERR_BAD_DATA;
        }
    }

    size_t total = akp_align16(sizeof(ak_skeleton));
    const size_t off_parents = total;
    total = akp_align16(total + n * sizeof(int32_t));
    const size_t off_rest = total;
    total = akp_align16(total + n * sizeof(ak_transform));
    const size_t off_ib = total;
    total = akp_align16(total + n * sizeof(ak_mat4));
    const size_t off_names = total;
    total = akp_align16(total + n * AK_NAME_SIZE);
    const size_t off_limits = total;
    total = akp_align16(total + n * sizeof(ak_joint_limits));
    const size_t off_children = total;
    total = akp_align16(total + n * sizeof(uint32_t));
    const size_t off_types = total;
    total = akp_align16(total + n);
    /* Scratch for the duplicate-name check, freed before returning. */
    name_ref* refs = (name_ref*)akp_alloc(alloc, n * sizeof(name_ref));
    unsigned char* base = (unsigned char*)akp_calloc(alloc, total);
    if (!base || !refs) {
        akp_free(alloc, refs);
        akp_free(alloc, base);
        return AK_ERR_NO_MEMORY;
    }
    ak_skeleton* sk = (ak_skeleton*)base;
    if (alloc) sk->alloc = *alloc;
    sk->joint_count = n;
    if (desc->name) snprintf(sk->name, sizeof sk->name, "%s", desc->name);
    sk->palette_from_skins = desc->palette_from_skins;
    sk->fk_kernel = fk_pick(AK_FK_SIMD_DEFAULT);
    sk->parents = (int32_t*)(base + off_parents);
    sk->rest = (ak_transform*)(base + off_rest);
    sk->inverse_binds = (ak_mat4*)(base + off_ib);
    sk->names = (char(*)[AK_NAME_SIZE])(base + off_names);
    sk->limits = (ak_joint_limits*)(base + off_limits);
    sk->child_counts = (uint32_t*)(base + off_children);
    sk->types = (uint8_t*)(base + off_types);

    for (size_t i = 0; i < n; ++i) {
        const ak_joint_desc* j = &desc->joints[i];
        sk->parents[i] = (int32_t)j->parent;
        sk->rest[i] = j->rest;
        sk->rest[i].rotation = ak_quat_normalize(j->rest.rotation);
        snprintf(sk->names[i], AK_NAME_SIZE, "%s", j->name);
        sk->types[i] = (uint8_t)j->type;
        sk->limits[i] = resolve_limits(j->type, j->limits);
        if (j->parent >= 0) sk->child_counts[j->parent]++;
        refs[i].name = sk->names[i];
        refs[i].index = i;
    }
    /* Inverse binds: given, or the inverse of the rest pose's model matrix. The rest model
     * matrices are accumulated in inverse_binds first (parents come first), then inverted. */
    for (size_t i = 0; i < n; ++i) {
        ak_mat4 model_i = ak_transform_to_mat4(sk->rest[i]);
        if (sk->parents[i] >= 0) model_i = ak_mat4_mul(sk->inverse_binds[sk->parents[i]], model_i);
        sk->inverse_binds[i] = model_i;
    }
    for (size_t i = 0; i < n; ++i) {
        const ak_joint_desc* j = &desc->joints[i];
        sk->inverse_binds[i] =
            j->inverse_bind ? *j->inverse_bind : ak_mat4_inverse_affine(sk->inverse_binds[i]);
    }

    qsort(refs, n, sizeof(name_ref), cmp_name_ref);
    for (size_t i = 1; i < n; ++i) {
        if (strcmp(refs[i - 1].name, refs[i].name) == 0) {
            akp_diag_set(diag, NULL, "joints %zu and %zu share the name '%s'", refs[i - 1].index,
                         refs[i].index, refs[i].name);
            akp_free(alloc, refs);
            akp_free(alloc, base);
            return AK_ERR_DUPLICATE;
        }
    }
    akp_free(alloc, refs);
    *out_skeleton = sk;
    return AK_OK;
}

void ak_skeleton_destroy(ak_skeleton* skeleton) {
    if (!skeleton) return;
    ak_allocator a = skeleton->alloc;
    akp_free(&a, skeleton);
}

ak_result ak_skeleton_reorder(ak_i32_cspan parents, ak_i32_span out_order) {
    if ((parents.count && !parents.ptr) || (parents.count && !out_order.ptr))
        return AK_ERR_NULL_ARG;
    if (out_order.count < parents.count) return AK_ERR_SPAN_SMALL;
    const size_t n = parents.count;
    if (n == 0) return AK_OK;
    for (size_t i = 0; i < n; ++i)
        if (parents.ptr[i] < -1 || (parents.ptr[i] >= 0 && (size_t)parents.ptr[i] >= n))
            return AK_ERR_BAD_HIERARCHY;
    /* Temporary state per joint: 0 not placed, 1 placed, 2 on the chain being walked. This is
     * an offline helper, so it uses the C heap for its scratch. */
    uint8_t* state = (uint8_t*)calloc(n, 1);
    if (!state) return AK_ERR_NO_MEMORY;
    size_t placed = 0;
    ak_result r = AK_OK;
    /* For each joint in input order, place its unplaced ancestors (root-most first), then it.
     * A joint moves earlier only when a descendant that comes before it in the input needs it. */
    for (size_t i = 0; i < n && r == AK_OK; ++i) {
        if (state[i] == 1) continue;
        size_t len = 0;
        int32_t j = (int32_t)i;
        while (j >= 0 && state[j] != 1) {
            if (state[j] == 2) {
                r = AK_ERR_BAD_HIERARCHY;
                break;
            }
            state[j] = 2;
            out_order.ptr[placed + len++] = j; /* the chain: distinct unplaced joints, fits */
            j = parents.ptr[j];
        }
        if (r != AK_OK) break;
        for (size_t a = 0, b = len - 1; a < b; ++a, --b) {
            int32_t t = out_order.ptr[placed + a];
            out_order.ptr[placed + a] = out_order.ptr[placed + b];
            out_order.ptr[placed + b] = t;
        }
        for (size_t k = 0; k < len; ++k) state[out_order.ptr[placed + k]] = 1;
        placed += len;
    }
    free(state);
    return r;
}

/* ---- queries ------------------------------------------------------------------------- */

size_t ak_skeleton_joint_count(const ak_skeleton* skeleton) {
    return skeleton ? skeleton->joint_count : 0;
}

ak_i32_cspan ak_skeleton_parents(const ak_skeleton* skeleton) {
    ak_i32_cspan s = {skeleton ? skeleton->parents : NULL, skeleton ? skeleton->joint_count : 0};
    return s;
}

ak_transform_cspan ak_skeleton_rest_pose(const ak_skeleton* skeleton) {
    ak_transform_cspan s = {skeleton ? skeleton->rest : NULL, skeleton ? skeleton->joint_count : 0};
    return s;
}

ak_mat4_cspan ak_skeleton_inverse_binds(const ak_skeleton* skeleton) {
    ak_mat4_cspan s = {skeleton ? skeleton->inverse_binds : NULL,
                       skeleton ? skeleton->joint_count : 0};
    return s;
}

const char* ak_skeleton_joint_name(const ak_skeleton* skeleton, size_t joint_index) {
    if (!skeleton || joint_index >= skeleton->joint_count) return "";
    return skeleton->names[joint_index];
}

int ak_skeleton_find_joint(const ak_skeleton* skeleton, const char* name) {
    if (!skeleton || !name) return -1;
    for (size_t i = 0; i < skeleton->joint_count; ++i)
        if (strcmp(skeleton->names[i], name) == 0) return (int)i;
    return -1;
}

ak_joint_type ak_skeleton_joint_type(const ak_skeleton* skeleton, size_t joint_index) {
    if (!skeleton || joint_index >= skeleton->joint_count) return AK_JOINT_FREE;
    return (ak_joint_type)skeleton->types[joint_index];
}

ak_joint_limits ak_skeleton_joint_limits(const ak_skeleton* skeleton, size_t joint_index) {
    ak_joint_limits zero;
    memset(&zero, 0, sizeof zero);
    if (!skeleton || joint_index >= skeleton->joint_count)
        return resolve_limits(AK_JOINT_FREE, zero);
    return skeleton->limits[joint_index];
}

bool ak_skeleton_palette_from_skins(const ak_skeleton* skeleton) { return skeleton && skeleton->palette_from_skins; }

size_t ak_skeleton_child_count(const ak_skeleton* skeleton, size_t joint_index) {
    if (!skeleton || joint_index >= skeleton->joint_count) return 0;
    return skeleton->child_counts[joint_index];
}

/* ---- forward kinematics -------------------------------------------------------------- */

/* parent * child for affine matrices (bottom rows (0, 0, 0, 1)): the 4x4 product without the
 * terms that multiply the child's bottom row (0 or 1), summed in the same order as
 * ak_mat4_mul, so the result is the same floats (up to the sign of a zero). */
static inline void affine_mul(const ak_mat4* a, const ak_mat4* b, ak_mat4* out) {
#if AK_SIMD_SSE2
    const __m128 a0 = _mm_loadu_ps(a->m), a1 = _mm_loadu_ps(a->m + 4), a2 = _mm_loadu_ps(a->m + 8),
                 a3 = _mm_loadu_ps(a->m + 12);
    for (int c = 0; c < 4; ++c) {
        const float* bc = b->m + 4 * c;
        __m128 r = _mm_add_ps(_mm_add_ps(_mm_mul_ps(a0, _mm_set1_ps(bc[0])), _mm_mul_ps(a1, _mm_set1_ps(bc[1]))),
                              _mm_mul_ps(a2, _mm_set1_ps(bc[2])));
        if (c == 3) r = _mm_add_ps(r, a3);
        _mm_storeu_ps(out->m + 4 * c, r);
    }
#else
    for (int c = 0; c < 4; ++c)
        for (int row = 0; row < 4; ++row) {
            float r = a->m[row] * b->m[c * 4] + a->m[4 + row] * b->m[c * 4 + 1] + a->m[8 + row] * b->m[c * 4 + 2];
            out->m[c * 4 + row] = c == 3 ? r + a->m[12 + row] : r;
        }
#endif
}

static bool mat4_affine(const ak_mat4* m) {
    return m->m[3] == 0.0f && m->m[7] == 0.0f && m->m[11] == 0.0f && m->m[15] == 1.0f;
}

#if AK_SIMD_SSE2 && defined(__GNUC__) && defined(__x86_64__)
#define AKP_FK_AVX 1
#include <immintrin.h>
/* The local 3x3 parts of joints b .. b + cnt - 1 (cnt <= 8) in structure-of-arrays form:
 * L[0..8] column by column (ak_mat3_from_quat's formulas times the scale, lane by lane, no
 * FMA, so the same floats as ak_transform_to_mat4). The rotations (and scales) of joints v and
 * v + 4 load into the two halves of one AVX register (the second half an insert from memory, no
 * shuffle), and one 4x4 transpose within the halves gives all eight joints' components; joints
 * past cnt repeat joint b. The translations are not gathered (the products broadcast them from
 * the pose itself). */
__attribute__((target("avx"), always_inline)) static inline void local_soa8(const ak_transform* local, size_t b,
                                                                            size_t cnt, float L[9][8]) {
    __m256 r[4], c[4];
    for (int v = 0; v < 4; ++v) {
        const size_t jl = (size_t)v < cnt ? (size_t)v : 0, jh = (size_t)v + 4 < cnt ? (size_t)v + 4 : 0;
        const float* lo = &local[b + jl].rotation.x;
        const float* hi = &local[b + jh].rotation.x;
        r[v] = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(lo)), _mm_loadu_ps(hi), 1); /* q */
        c[v] = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(lo + 3)), _mm_loadu_ps(hi + 3), 1); /* qw s */
    }
    const __m256 t0 = _mm256_unpacklo_ps(r[0], r[1]), t1 = _mm256_unpacklo_ps(r[2], r[3]);
    const __m256 t2 = _mm256_unpackhi_ps(r[0], r[1]), t3 = _mm256_unpackhi_ps(r[2], r[3]);
    const __m256 x = _mm256_shuffle_ps(t0, t1, 0x44), y = _mm256_shuffle_ps(t0, t1, 0xEE);
    const __m256 z = _mm256_shuffle_ps(t2, t3, 0x44), w = _mm256_shuffle_ps(t2, t3, 0xEE);
    const __m256 u0 = _mm256_unpacklo_ps(c[0], c[1]), u1 = _mm256_unpacklo_ps(c[2], c[3]); /* qw qw sx sx */
    const __m256 u2 = _mm256_unpackhi_ps(c[0], c[1]), u3 = _mm256_unpackhi_ps(c[2], c[3]); /* sy sy sz sz */
    const __m256 sx = _mm256_shuffle_ps(u0, u1, 0xEE), sy = _mm256_shuffle_ps(u2, u3, 0x44),
                 sz = _mm256_shuffle_ps(u2, u3, 0xEE);
    const __m256 xx = _mm256_mul_ps(x, x), yy = _mm256_mul_ps(y, y), zz = _mm256_mul_ps(z, z);
    const __m256 xy = _mm256_mul_ps(x, y), xz = _mm256_mul_ps(x, z), yz = _mm256_mul_ps(y, z);
    const __m256 wx = _mm256_mul_ps(w, x), wy = _mm256_mul_ps(w, y), wz = _mm256_mul_ps(w, z);
    const __m256 one = _mm256_set1_ps(1.0f), two = _mm256_set1_ps(2.0f);
#define AKP_TWO(e) _mm256_mul_ps(two, (e))
    _mm256_store_ps(L[0], _mm256_mul_ps(_mm256_sub_ps(one, AKP_TWO(_mm256_add_ps(yy, zz))), sx));
    _mm256_store_ps(L[1], _mm256_mul_ps(AKP_TWO(_mm256_add_ps(xy, wz)), sx));
    _mm256_store_ps(L[2], _mm256_mul_ps(AKP_TWO(_mm256_sub_ps(xz, wy)), sx));
    _mm256_store_ps(L[3], _mm256_mul_ps(AKP_TWO(_mm256_sub_ps(xy, wz)), sy));
    _mm256_store_ps(L[4], _mm256_mul_ps(_mm256_sub_ps(one, AKP_TWO(_mm256_add_ps(xx, zz))), sy));
    _mm256_store_ps(L[5], _mm256_mul_ps(AKP_TWO(_mm256_add_ps(yz, wx)), sy));
    _mm256_store_ps(L[6], _mm256_mul_ps(AKP_TWO(_mm256_add_ps(xz, wy)), sz));
    _mm256_store_ps(L[7], _mm256_mul_ps(AKP_TWO(_mm256_sub_ps(yz, wx)), sz));
    _mm256_store_ps(L[8], _mm256_mul_ps(_mm256_sub_ps(one, AKP_TWO(_mm256_add_ps(xx, yy))), sz));
#undef AKP_TWO
}

/* The translations of joints b .. b + cnt - 1 (cnt <= 8) as x, y, z rows of 8 lanes (lanes past
 * cnt repeat joint b): the transpose local_soa8 does for the rotations. */
__attribute__((target("avx"), always_inline)) static inline void translation_soa8(const ak_transform* local, size_t b,
                                                                                size_t cnt, __m256 T[3]) {
    __m256 r[4];
    for (int v = 0; v < 4; ++v) {
        const size_t jl = (size_t)v < cnt ? (size_t)v : 0, jh = (size_t)v + 4 < cnt ? (size_t)v + 4 : 0;
        r[v] = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(&local[b + jl].translation.x)),
                                    _mm_loadu_ps(&local[b + jh].translation.x), 1);
    }
    const __m256 t0 = _mm256_unpacklo_ps(r[0], r[1]), t1 = _mm256_unpacklo_ps(r[2], r[3]);
    const __m256 t2 = _mm256_unpackhi_ps(r[0], r[1]), t3 = _mm256_unpackhi_ps(r[2], r[3]);
    T[0] = _mm256_shuffle_ps(t0, t1, 0x44), T[1] = _mm256_shuffle_ps(t0, t1, 0xEE), T[2] = _mm256_shuffle_ps(t2, t3, 0x44);
}

/* The AVX kernel (no FMA) for no root or an affine root: the local 3x3 parts of 8 joints at a
 * time in structure-of-arrays form (local_soa8), then the parent products joint by joint, one
 * column at a time, each local entry broadcast from memory (the translation straight from the
 * pose). A joint whose parent is the joint before it takes the parent's columns from registers.
 * AKP_FK_PRODUCT_0: (a0 b0 + a1 b1) + a2 b2 [+ a3], ak_mat4_mul's order and roundings. The
 * AVX2 + FMA and AVX-512 kernels below hold two or four columns per register instead. */
#define AKP_FK_KERNEL(NAME, TARGET, FMA)                                                                          \
    __attribute__((target(TARGET))) static void NAME(const ak_skeleton* sk, const ak_mat4* root,                \
                                                     const ak_transform* local, ak_mat4* out) {                \
        const size_t n = sk->joint_count;                                                                      \
        const int32_t* const parents = sk->parents;                                                            \
        _Alignas(32) float L[9][8]; /* columns 0..2 (x y z each), 8 joints */                                  \
        __m128 prev[4] = {_mm_setzero_ps(), _mm_setzero_ps(), _mm_setzero_ps(), _mm_setzero_ps()};             \
        for (size_t b = 0; b < n; b += 8) {                                                                    \
            const size_t cnt = n - b < 8 ? n - b : 8;                                                          \
            local_soa8(local, b, cnt, L);                                                                      \
            for (size_t v = 0; v < cnt; ++v) {                                                                 \
                const size_t i = b + v;                                                                        \
                const int p = parents[i];                                                                      \
                const float* t = &local[i].translation.x;                                                      \
                float* o = out[i].m;                                                                           \
                __m128 a0, a1, a2, a3;                                                                         \
                if (p >= 0 && (size_t)p + 1 == i) {                                                            \
                    a0 = prev[0], a1 = prev[1], a2 = prev[2], a3 = prev[3];                                    \
                } else if (p >= 0 || root) {                                                                   \
                    const float* a = p >= 0 ? out[p].m : root->m;                                              \
                    a0 = _mm_loadu_ps(a), a1 = _mm_loadu_ps(a + 4), a2 = _mm_loadu_ps(a + 8),                  \
                    a3 = _mm_loadu_ps(a + 12);                                                                 \
                } else { /* a root joint without root matrix: the local matrix itself */                      \
                    for (int c = 0; c < 3; ++c) prev[c] = _mm_setr_ps(L[3 * c][v], L[3 * c + 1][v], L[3 * c + 2][v], 0.0f); \
                    prev[3] = _mm_setr_ps(t[0], t[1], t[2], 1.0f);                                             \
                    for (int c = 0; c < 4; ++c) _mm_storeu_ps(o + 4 * c, prev[c]);                             \
                    continue;                                                                                  \
                }                                                                                              \
                AKP_FK_PRODUCT_##FMA                                                                           \
                for (int c = 0; c < 4; ++c) _mm_storeu_ps(o + 4 * c, prev[c]);                                 \
            }                                                                                                  \
        }                                                                                                      \
    }
#define AKP_FK_PRODUCT_0                                                                                       \
    for (int c = 0; c < 4; ++c) {                                                                              \
        const float* e0 = c < 3 ? &L[3 * c][v] : t;                                                            \
        const float* e1 = c < 3 ? &L[3 * c + 1][v] : t + 1;                                                    \
        const float* e2 = c < 3 ? &L[3 * c + 2][v] : t + 2;                                                    \
        __m128 r = _mm_add_ps(_mm_add_ps(_mm_mul_ps(a0, _mm_broadcast_ss(e0)), _mm_mul_ps(a1, _mm_broadcast_ss(e1))),  \
                              _mm_mul_ps(a2, _mm_broadcast_ss(e2)));                                               \
        prev[c] = c == 3 ? _mm_add_ps(r, a3) : r;                                                              \
    }
AKP_FK_KERNEL(fk_affine_avx, "avx", 0)
/* The AVX2 + FMA kernel: a joint's model matrix in two 256-bit registers, columns 0 1 and 2 3
 * (one per 128-bit half), the AVX-512 kernel's scheme at half width: per half, the local
 * coefficients (B[k][c] x4, B[k][c + 1] x4) of 4 joints sit in one register per k (the SoA rows
 * of two columns, one 128-bit half each), and one lane permute per k and half picks the joint's;
 * the parent's columns come from the previous joint's registers (128-bit lane permutes) or
 * 128-bit broadcast loads. Per half a0 b0 + a1 b1 + a2 b2 (+ a3) in fused steps, the order of
 * the per-column FMA kernel this replaces (same floats). 16 vector operations and at most 4
 * loads per joint where the per-column kernel spent 12 operations on 12 broadcast loads: 6%
 * less time on Zen 5 (docs/fk.md). */
__attribute__((target("avx2,fma"))) static void fk_affine_fma(const ak_skeleton* sk, const ak_mat4* root,
                                                             const ak_transform* local, ak_mat4* out) {
    const size_t n = sk->joint_count;
    const int32_t* const parents = sk->parents;
    _Alignas(32) float L[9][8];
    const __m256i base_idx = _mm256_setr_epi32(0, 0, 0, 0, 4, 4, 4, 4);
    const __m256 id01_0 = _mm256_setr_ps(1, 0, 0, 0, 1, 0, 0, 0), id01_1 = _mm256_setr_ps(0, 1, 0, 0, 0, 1, 0, 0);
    const __m256 id01_2 = _mm256_setr_ps(0, 0, 1, 0, 0, 0, 1, 0), id3 = _mm256_setr_ps(0, 0, 0, 0, 0, 0, 0, 1);
    __m256 o01 = _mm256_setzero_ps(), o23 = _mm256_setzero_ps();
    for (size_t b = 0; b < n; b += 8) {
        const size_t cnt = n - b < 8 ? n - b : 8;
        local_soa8(local, b, cnt, L);
        __m256 T[3];
        translation_soa8(local, b, cnt, T);
        for (size_t h = 0; h < 2 && 4 * h < cnt; ++h) {
            __m256 r01[3], r23[3];
            for (int k = 0; k < 3; ++k) {
                r01[k] = h ? _mm256_permute2f128_ps(_mm256_load_ps(L[k]), _mm256_load_ps(L[3 + k]), 0x31)
                           : _mm256_permute2f128_ps(_mm256_load_ps(L[k]), _mm256_load_ps(L[3 + k]), 0x20);
                r23[k] = h ? _mm256_permute2f128_ps(_mm256_load_ps(L[6 + k]), T[k], 0x31)
                           : _mm256_permute2f128_ps(_mm256_load_ps(L[6 + k]), T[k], 0x20);
            }
            const size_t e = cnt - 4 * h < 4 ? cnt - 4 * h : 4;
            for (size_t v = 0; v < e; ++v) {
                const size_t i = b + 4 * h + v;
                const int p = parents[i];
                const __m256i idx = _mm256_add_epi32(base_idx, _mm256_set1_epi32((int)v));
                __m256 p0, p1, p2, p3;
                if (p >= 0 && (size_t)p + 1 == i) {
                    p0 = _mm256_permute2f128_ps(o01, o01, 0x00), p1 = _mm256_permute2f128_ps(o01, o01, 0x11);
                    p2 = _mm256_permute2f128_ps(o23, o23, 0x00), p3 = _mm256_permute2f128_ps(o23, o23, 0x18);
                } else if (p >= 0 || root) {
                    const float* a = p >= 0 ? out[p].m : root->m;
                    p0 = _mm256_broadcast_ps((const __m128*)a), p1 = _mm256_broadcast_ps((const __m128*)(a + 4));
                    p2 = _mm256_broadcast_ps((const __m128*)(a + 8));
                    p3 = _mm256_insertf128_ps(_mm256_setzero_ps(), _mm_loadu_ps(a + 12), 1);
                } else {
                    p0 = id01_0, p1 = id01_1, p2 = id01_2, p3 = id3;
                }
                const __m256 a0 = _mm256_permutevar8x32_ps(r01[0], idx), a1 = _mm256_permutevar8x32_ps(r01[1], idx),
                             a2 = _mm256_permutevar8x32_ps(r01[2], idx);
                const __m256 b0 = _mm256_permutevar8x32_ps(r23[0], idx), b1 = _mm256_permutevar8x32_ps(r23[1], idx),
                             b2 = _mm256_permutevar8x32_ps(r23[2], idx);
                o01 = _mm256_fmadd_ps(p2, a2, _mm256_fmadd_ps(p1, a1, _mm256_mul_ps(p0, a0)));
                o23 = _mm256_fmadd_ps(p2, b2, _mm256_fmadd_ps(p1, b1, _mm256_fmadd_ps(p0, b0, p3)));
                _mm256_storeu_ps(out[i].m, o01);
                _mm256_storeu_ps(out[i].m + 8, o23);
            }
        }
    }
}
/* The AVX-512 kernel: one joint's whole model matrix per 512-bit register (four columns, one
 * per 128-bit block). model = parent * local is, per block c, a0 B[0][c] + a1 B[1][c] +
 * a2 B[2][c] (+ a3 in block 3), with P_k = parent column k in every block and C_k = (B[k][0] x4,
 * B[k][1] x4, B[k][2] x4, t_k x4), summed as (a0 B[0][c] + a3) + (a2 B[2][c] + a1 B[1][c]): two
 * fused multiply-adds, one multiply and one add, a parent-to-child dependency chain of about 9
 * cycles (Zen 5) where a0 b0 + a1 b1 + a2 b2 in fused steps takes 12; within a few roundings of
 * ak_mat4_mul, like the FMA kernel. C_k comes from the 8-joint structure-of-arrays rows
 * (local_soa8 and the transposed translations) by one two-source permute per k, P_k from the
 * previous joint's register (block shuffles) or 128-bit broadcast loads: about 10 vector
 * operations and at most 4 loads per joint where the per-column kernel spends 12 operations on
 * 12 broadcast loads (docs/fk.md). */
__attribute__((target("avx512f,avx512vl,avx2,fma"))) static void fk_affine_avx512(const ak_skeleton* sk,
                                                                                const ak_mat4* root,
                                                                                const ak_transform* local,
                                                                                ak_mat4* out) {
    const size_t n = sk->joint_count;
    const int32_t* const parents = sk->parents;
    _Alignas(32) float L[9][8];
    const __m512i base_idx = _mm512_setr_epi32(0, 0, 0, 0, 8, 8, 8, 8, 16, 16, 16, 16, 24, 24, 24, 24);
    /* a root joint without root matrix: the identity as parent (exact: products by 1 and 0) */
    const __m512 id0 = _mm512_broadcast_f32x4(_mm_setr_ps(1.0f, 0.0f, 0.0f, 0.0f));
    const __m512 id1 = _mm512_broadcast_f32x4(_mm_setr_ps(0.0f, 1.0f, 0.0f, 0.0f));
    const __m512 id2 = _mm512_broadcast_f32x4(_mm_setr_ps(0.0f, 0.0f, 1.0f, 0.0f));
    const __m512 id3 = _mm512_maskz_broadcast_f32x4(0xF000, _mm_setr_ps(0.0f, 0.0f, 0.0f, 1.0f));
    __m512 prev = _mm512_setzero_ps();
    for (size_t b = 0; b < n; b += 8) {
        const size_t cnt = n - b < 8 ? n - b : 8;
        local_soa8(local, b, cnt, L);
        __m256 T[3];
        translation_soa8(local, b, cnt, T);
        const __m256 tx = T[0], ty = T[1], tz = T[2];
#define AKP_Z(A, B) _mm512_castpd_ps(_mm512_insertf64x4(_mm512_castpd256_pd512(_mm256_castps_pd(A)), _mm256_castps_pd(B), 1))
        const __m512 z0l = AKP_Z(_mm256_load_ps(L[0]), _mm256_load_ps(L[3])), z0h = AKP_Z(_mm256_load_ps(L[6]), tx);
        const __m512 z1l = AKP_Z(_mm256_load_ps(L[1]), _mm256_load_ps(L[4])), z1h = AKP_Z(_mm256_load_ps(L[7]), ty);
        const __m512 z2l = AKP_Z(_mm256_load_ps(L[2]), _mm256_load_ps(L[5])), z2h = AKP_Z(_mm256_load_ps(L[8]), tz);
#undef AKP_Z
        for (size_t v = 0; v < cnt; ++v) {
            const size_t i = b + v;
            const int p = parents[i];
            const __m512i idx = _mm512_add_epi32(base_idx, _mm512_set1_epi32((int)v));
            const __m512 c0 = _mm512_permutex2var_ps(z0l, idx, z0h), c1 = _mm512_permutex2var_ps(z1l, idx, z1h),
                         c2 = _mm512_permutex2var_ps(z2l, idx, z2h);
            __m512 p0, p1, p2, p3;
            if (p >= 0 && (size_t)p + 1 == i) {
                p0 = _mm512_shuffle_f32x4(prev, prev, 0x00), p1 = _mm512_shuffle_f32x4(prev, prev, 0x55);
                p2 = _mm512_shuffle_f32x4(prev, prev, 0xAA), p3 = _mm512_maskz_shuffle_f32x4(0xF000, prev, prev, 0xFF);
            } else if (p >= 0 || root) {
                const float* a = p >= 0 ? out[p].m : root->m;
                p0 = _mm512_broadcast_f32x4(_mm_loadu_ps(a)), p1 = _mm512_broadcast_f32x4(_mm_loadu_ps(a + 4));
                p2 = _mm512_broadcast_f32x4(_mm_loadu_ps(a + 8));
                p3 = _mm512_maskz_broadcast_f32x4(0xF000, _mm_loadu_ps(a + 12));
            } else {
                p0 = id0, p1 = id1, p2 = id2, p3 = id3;
            }
            prev = _mm512_add_ps(_mm512_fmadd_ps(p0, c0, p3), _mm512_fmadd_ps(p2, c2, _mm512_mul_ps(p1, c1)));
            _mm512_storeu_ps(out[i].m, prev);
        }
    }
}
#undef AKP_FK_KERNEL
#undef AKP_FK_PRODUCT_0
#else
#define AKP_FK_AVX 0
#endif

/* The kernel for a limit on this CPU. */
static uint8_t fk_pick(ak_fk_simd limit) {
#if AKP_FK_AVX
    const ak_fk_simd lim = limit == AK_FK_SIMD_DEFAULT ? AK_FK_SIMD_AVX512 : limit;
    if (lim >= AK_FK_SIMD_AVX512 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
        __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
        return AKP_FK_K_AVX512;
    if (lim >= AK_FK_SIMD_AVX2 && __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
        return AKP_FK_K_AVX2;
    if (lim >= AK_FK_SIMD_AVX2 && __builtin_cpu_supports("avx")) return AKP_FK_K_AVX;
#else
    (void)limit;
#endif
    return AKP_FK_K_SCALAR;
}

ak_result ak_skeleton_set_simd_limit(ak_skeleton* skeleton, ak_fk_simd limit) {
    if (!skeleton) return AK_ERR_NULL_ARG;
    if ((unsigned)limit >= (unsigned)AK_FK_SIMD_COUNT) return AK_ERR_BAD_ARG;
    skeleton->fk_kernel = fk_pick(limit);
    return AK_OK;
}

const char* ak_skeleton_simd_name(const ak_skeleton* skeleton) {
    static const char* const names[] = {"scalar", "avx", "avx2", "avx512"};
    return skeleton ? names[skeleton->fk_kernel] : "";
}

/* Local TRS to model matrices, parents first. Local matrices are affine, so with no root or an
 * affine root every model matrix is affine and the products skip the bottom row's terms
 * (affine_mul: a quarter fewer multiplies, SSE2 columns; the SIMD kernels above where the
 * skeleton's kernel is one); a projective root keeps the full 4x4 products. */
static void fk(const ak_skeleton* sk, const ak_mat4* root, const ak_transform* local,
               ak_mat4* out) {
    const size_t n = sk->joint_count;
    if (!root || mat4_affine(root)) {
#if AKP_FK_AVX
        switch (sk->fk_kernel) {
        case AKP_FK_K_AVX512: fk_affine_avx512(sk, root, local, out); return;
        case AKP_FK_K_AVX2: fk_affine_fma(sk, root, local, out); return;
        case AKP_FK_K_AVX: fk_affine_avx(sk, root, local, out); return;
        default: break;
        }
#endif
        for (size_t i = 0; i < n; ++i) {
            const ak_mat4 m = ak_transform_to_mat4(local[i]);
            const int p = sk->parents[i];
            if (p >= 0) affine_mul(&out[p], &m, &out[i]);
            else if (root) affine_mul(root, &m, &out[i]);
            else out[i] = m;
        }
        return;
    }
    for (size_t i = 0; i < n; ++i) {
        ak_mat4 m = ak_transform_to_mat4(local[i]);
        int p = sk->parents[i];
        if (p >= 0)
            out[i] = ak_mat4_mul(out[p], m);
        else
            out[i] = root ? ak_mat4_mul(*root, m) : m;
    }
}

ak_result ak_skeleton_local_to_model(const ak_skeleton* skeleton, ak_transform_cspan local,
                                     ak_mat4_span out_model) {
    if (!skeleton || !local.ptr || !out_model.ptr) return AK_ERR_NULL_ARG;
    if (local.count < skeleton->joint_count || out_model.count < skeleton->joint_count)
        return AK_ERR_SPAN_SMALL;
    fk(skeleton, NULL, local.ptr, out_model.ptr);
    return AK_OK;
}

ak_result ak_skeleton_local_to_model_rooted(const ak_skeleton* skeleton, ak_mat4 root,
                                            ak_transform_cspan local, ak_mat4_span out_model) {
    if (!skeleton || !local.ptr || !out_model.ptr) return AK_ERR_NULL_ARG;
    if (local.count < skeleton->joint_count || out_model.count < skeleton->joint_count)
        return AK_ERR_SPAN_SMALL;
    fk(skeleton, &root, local.ptr, out_model.ptr);
    return AK_OK;
}

ak_result ak_skeleton_skinning_matrices(const ak_skeleton* skeleton, ak_mat4_cspan model,
                                        ak_mat4_span out_skin) {
    if (!skeleton || !model.ptr || !out_skin.ptr) return AK_ERR_NULL_ARG;
    if (skeleton->palette_from_skins) return AK_ERR_UNSUPPORTED; /* see ak_scene_skin_palette */
    if (model.count < skeleton->joint_count || out_skin.count < skeleton->joint_count)
        return AK_ERR_SPAN_SMALL;
    for (size_t i = 0; i < skeleton->joint_count; ++i)
        out_skin.ptr[i] = ak_mat4_mul(model.ptr[i], skeleton->inverse_binds[i]);
    return AK_OK;
}

ak_result ak_skeleton_local_to_model_batch(const ak_skeleton* skeleton, size_t character_count,
                                           ak_transform_cspan local, ak_mat4_span out_model) {
    if (!skeleton) return AK_ERR_NULL_ARG;
    if (character_count == 0) return AK_OK;
    if (!local.ptr || !out_model.ptr) return AK_ERR_NULL_ARG;
    const size_t n = skeleton->joint_count;
    if (character_count > SIZE_MAX / n) return AK_ERR_SPAN_SMALL;
    if (local.count < character_count * n || out_model.count < character_count * n)
        return AK_ERR_SPAN_SMALL;
    for (size_t c = 0; c < character_count; ++c)
        fk(skeleton, NULL, local.ptr + c * n, out_model.ptr + c * n);
    return AK_OK;
}

/* ---- limits -------------------------------------------------------------------------- */

void ak_quat_swing_twist(ak_quat q, ak_vec3 axis, ak_quat* out_swing, ak_quat* out_twist) {
    ak_vec3 a = ak_vec3_normalize(axis);
    q = ak_quat_normalize(q);
    float d = q.x * a.x + q.y * a.y + q.z * a.z;
    ak_quat twist = ak_quat_make(a.x * d, a.y * d, a.z * d, q.w);
    /* A 180-degree swing leaves no twist component: any twist works, take the identity. */
    if (ak_quat_dot(twist, twist) < 1e-12f)
        twist = ak_quat_identity();
    else
        twist = ak_quat_normalize(twist);
    ak_quat swing = ak_quat_normalize(ak_quat_mul(q, ak_quat_conjugate(twist)));
    if (out_swing) *out_swing = swing;
    if (out_twist) *out_twist = twist;
}

ak_transform ak_skeleton_limit_joint(const ak_skeleton* skeleton, size_t joint_index,
                                     ak_transform local) {
    if (!skeleton || joint_index >= skeleton->joint_count) return local;
    const ak_joint_type type = (ak_joint_type)skeleton->types[joint_index];
    if (type == AK_JOINT_FREE) return local;
    const ak_transform rest = skeleton->rest[joint_index];
    const ak_joint_limits* l = &skeleton->limits[joint_index];
    ak_transform out = local;
    out.translation = rest.translation;
    /* Rotation relative to rest, in the joint's rest frame: local = rest * rel. */
    ak_quat rel = ak_quat_mul(ak_quat_conjugate(rest.rotation), ak_quat_normalize(local.rotation));
    ak_quat swing, twist;
    ak_quat_swing_twist(rel, l->axis, &swing, &twist);
    switch (type) {
    case AK_JOINT_HINGE: {
        float a = twist_angle(twist, l->axis);
        if (l->min != 0.0f || l->max != 0.0f) a = clamp_angle(a, l->min, l->max);
        out.rotation =
            ak_quat_normalize(ak_quat_mul(rest.rotation, ak_quat_from_axis_angle(l->axis, a)));
        break;
    }
    case AK_JOINT_BALL: {
        if (l->cone_angle > 0.0f) {
            float s = rotation_angle(swing);
            if (s > l->cone_angle) {
                ak_vec3 ax;
                float ang;
                ak_quat_to_axis_angle(swing, &ax, &ang);
                swing = ak_quat_from_axis_angle(ax, l->cone_angle);
            }
        }
        if (l->twist_min != 0.0f || l->twist_max != 0.0f) {
            float a = clamp_angle(twist_angle(twist, l->axis), l->twist_min, l->twist_max);
            twist = ak_quat_from_axis_angle(l->axis, a);
        }
        out.rotation = ak_quat_normalize(ak_quat_mul(rest.rotation, ak_quat_mul(swing, twist)));
        break;
    }
    case AK_JOINT_PRISM: {
        ak_vec3 axis_p = ak_quat_rotate(rest.rotation, l->axis); /* slide axis in parent space */
        float d = ak_vec3_dot(ak_vec3_sub(local.translation, rest.translation), axis_p);
        if (!ak_finitef(d)) d = 0.0f;
        if (l->min != 0.0f || l->max != 0.0f) d = ak_clampf(d, l->min, l->max);
        out.rotation = rest.rotation;
        out.translation = ak_vec3_madd(rest.translation, axis_p, d);
        break;
    }
    default:
        break;
    }
    return out;
}

ak_result ak_skeleton_apply_limits(const ak_skeleton* skeleton, ak_transform_span pose) {
    if (!skeleton || !pose.ptr) return AK_ERR_NULL_ARG;
    if (pose.count < skeleton->joint_count) return AK_ERR_SPAN_SMALL;
    for (size_t i = 0; i < skeleton->joint_count; ++i)
        pose.ptr[i] = ak_skeleton_limit_joint(skeleton, i, pose.ptr[i]);
    return AK_OK;
}

bool ak_skeleton_joint_within_limits(const ak_skeleton* skeleton, size_t joint_index,
                                     ak_transform local, float tol) {
    if (!skeleton || joint_index >= skeleton->joint_count) return false;
    if (!ak_transform_is_finite(local)) return false;
    const ak_joint_type type = (ak_joint_type)skeleton->types[joint_index];
    if (type == AK_JOINT_FREE) return true;
    if (!(tol >= 0.0f)) tol = 0.0f;
    const ak_transform rest = skeleton->rest[joint_index];
    const ak_joint_limits* l = &skeleton->limits[joint_index];
    ak_quat rel = ak_quat_mul(ak_quat_conjugate(rest.rotation), ak_quat_normalize(local.rotation));
    ak_quat swing, twist;
    ak_quat_swing_twist(rel, l->axis, &swing, &twist);
    switch (type) {
    case AK_JOINT_HINGE:
        if (ak_vec3_distance(local.translation, rest.translation) > tol) return false;
        if (rotation_angle(swing) > tol) return false;
        if (l->min == 0.0f && l->max == 0.0f) return true;
        return angle_in_range(twist_angle(twist, l->axis), l->min, l->max, tol);
    case AK_JOINT_BALL:
        if (ak_vec3_distance(local.translation, rest.translation) > tol) return false;
        if (l->cone_angle > 0.0f && rotation_angle(swing) > l->cone_angle + tol) return false;
        if (l->twist_min == 0.0f && l->twist_max == 0.0f) return true;
        return angle_in_range(twist_angle(twist, l->axis), l->twist_min, l->twist_max, tol);
    case AK_JOINT_PRISM: {
        if (rotation_angle(rel) > tol) return false;
        ak_vec3 axis_p = ak_quat_rotate(rest.rotation, l->axis);
        ak_vec3 dv = ak_vec3_sub(local.translation, rest.translation);
        float d = ak_vec3_dot(dv, axis_p);
        if (ak_vec3_length(ak_vec3_madd(dv, axis_p, -d)) > tol) return false;
        if (l->min == 0.0f && l->max == 0.0f) return true;
        return d >= l->min - tol && d <= l->max + tol;
    }
    default:
        return true;
    }
}

bool ak_pose_is_finite(ak_transform_cspan pose) {
    if (pose.count && !pose.ptr) return false;
    for (size_t i = 0; i < pose.count; ++i)
        if (!ak_transform_is_finite(pose.ptr[i])) return false;
    return true;
}
