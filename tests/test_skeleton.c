/* Tests for skeleton.h: validation rules with their exact codes, reorder, forward kinematics
 * against a naive double-precision recursive FK written here, skinning matrices, swing-twist
 * and joint limits (properties checked with independent double-precision geometry). */
#include <animkit/skeleton.h>

#include "ak_test.h"

#define PI_D 3.14159265358979323846

/* ---- naive double-precision reference FK -------------------------------------------- */

typedef struct dmat4 {
    double m[16]; /* column-major */
} dmat4;

static dmat4 dmat_from_trs(ak_transform t) {
    double x = t.rotation.x, y = t.rotation.y, z = t.rotation.z, w = t.rotation.w;
    double n = sqrt(x * x + y * y + z * z + w * w);
    x /= n, y /= n, z /= n, w /= n;
    double r[9] = {1 - 2 * (y * y + z * z), 2 * (x * y + z * w),     2 * (x * z - y * w),
                   2 * (x * y - z * w),     1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
                   2 * (x * z + y * w),     2 * (y * z - x * w),     1 - 2 * (x * x + y * y)};
    double s[3] = {t.scale.x, t.scale.y, t.scale.z};
    dmat4 m;
    memset(&m, 0, sizeof m);
    for (int c = 0; c < 3; ++c)
        for (int rr = 0; rr < 3; ++rr) m.m[c * 4 + rr] = r[c * 3 + rr] * s[c];
    m.m[12] = t.translation.x, m.m[13] = t.translation.y, m.m[14] = t.translation.z, m.m[15] = 1.0;
    return m;
}

static dmat4 dmat_mul(dmat4 a, dmat4 b) {
    dmat4 r;
    for (int c = 0; c < 4; ++c)
        for (int rr = 0; rr < 4; ++rr) {
            double s = 0.0;
            for (int k = 0; k < 4; ++k) s += a.m[k * 4 + rr] * b.m[c * 4 + k];
            r.m[c * 4 + rr] = s;
        }
    return r;
}

/* Recursive: world(i) = world(parent(i)) * local(i). */
static dmat4 ref_world(const int* parents, const ak_transform* local, int i) {
    dmat4 m = dmat_from_trs(local[i]);
    return parents[i] < 0 ? m : dmat_mul(ref_world(parents, local, parents[i]), m);
}

static double max_diff(const ak_mat4* a, const dmat4* b) {
    double d = 0.0;
    for (int k = 0; k < 16; ++k) d = fmax(d, fabs((double)a->m[k] - b->m[k]));
    return d;
}

static ak_quat random_quat(ak_rng* rng) {
    /* Uniform on SO(3) (Shoemake). */
    double u1 = ak_rng_double(rng), u2 = ak_rng_double(rng) * 2 * PI_D,
           u3 = ak_rng_double(rng) * 2 * PI_D;
    double a = sqrt(1 - u1), b = sqrt(u1);
    return ak_quat_make((float)(a * sin(u2)), (float)(a * cos(u2)), (float)(b * sin(u3)),
                        (float)(b * cos(u3)));
}

static ak_transform random_transform(ak_rng* rng) {
    ak_transform t;
    t.translation =
        ak_vec3_make(ak_rng_range(rng, -1, 1), ak_rng_range(rng, -1, 1), ak_rng_range(rng, -1, 1));
    t.rotation = random_quat(rng);
    float s = ak_rng_range(rng, 0.7f, 1.3f);
    t.scale = ak_vec3_make(s, s * ak_rng_range(rng, 0.9f, 1.1f), s);
    return t;
}

/* Angle in radians between two rotations, in double: 2 atan2(|vec(a* b)|, |w(a* b)|), which
 * stays accurate for small angles (acos of the dot product does not). */
static double quat_angle_d(ak_quat a, ak_quat b) {
    double ax = -a.x, ay = -a.y, az = -a.z, aw = a.w;
    double x = aw * b.x + ax * b.w + ay * b.z - az * b.y;
    double y = aw * b.y - ax * b.z + ay * b.w + az * b.x;
    double z = aw * b.z + ax * b.y - ay * b.x + az * b.w;
    double w = aw * b.w - ax * b.x - ay * b.y - az * b.z;
    return 2.0 * atan2(sqrt(x * x + y * y + z * z), fabs(w));
}

/* ---- creation and validation -------------------------------------------------------- */

static ak_joint_desc joint(const char* name, int parent, float y) {
    ak_joint_desc j;
    memset(&j, 0, sizeof j);
    j.name = name;
    j.parent = parent;
    j.rest = ak_transform_identity();
    j.rest.translation.y = y;
    return j;
}

AK_TEST(create_and_query) {
    ak_joint_desc js[4] = {joint("hip", -1, 1.0f), joint("knee", 0, -0.5f),
                           joint("ankle", 1, -0.5f), joint("other", 0, 0.2f)};
    js[1].type = AK_JOINT_HINGE;
    js[1].limits.min = 0.0f, js[1].limits.max = 2.5f;
    js[3].type = AK_JOINT_BALL;
    ak_skeleton_desc d = {.joints = js, .joint_count = 4, .name = "leg"};
    ak_skeleton* sk = NULL;
    AK_CHECK_EQ(ak_skeleton_create(&d, NULL, &sk, NULL), AK_OK);
    if (!sk) return;
    AK_CHECK_EQ(ak_skeleton_joint_count(sk), 4);
    AK_CHECK_STREQ(ak_skeleton_joint_name(sk, 2), "ankle");
    AK_CHECK_STREQ(ak_skeleton_joint_name(sk, 9), "");
    AK_CHECK_EQ(ak_skeleton_find_joint(sk, "knee"), 1);
    AK_CHECK_EQ(ak_skeleton_find_joint(sk, "nope"), -1);
    AK_CHECK_EQ(ak_skeleton_find_joint(sk, NULL), -1);
    AK_CHECK_EQ(ak_skeleton_joint_type(sk, 1), AK_JOINT_HINGE);
    AK_CHECK_EQ(ak_skeleton_joint_type(sk, 0), AK_JOINT_FREE);
    AK_CHECK_EQ(ak_skeleton_child_count(sk, 0), 2);
    AK_CHECK_EQ(ak_skeleton_child_count(sk, 2), 0);
    ak_i32_cspan par = ak_skeleton_parents(sk);
    AK_CHECK_EQ(par.count, 4);
    AK_CHECK(par.ptr[0] == -1 && par.ptr[1] == 0 && par.ptr[2] == 1 && par.ptr[3] == 0);
    /* Resolved default axes: hinge (1,0,0), ball (0,1,0). */
    ak_joint_limits l1 = ak_skeleton_joint_limits(sk, 1), l3 = ak_skeleton_joint_limits(sk, 3);
    AK_CHECK(l1.axis.x == 1.0f && l1.axis.y == 0.0f && l1.axis.z == 0.0f);
    AK_CHECK(l3.axis.x == 0.0f && l3.axis.y == 1.0f && l3.axis.z == 0.0f);
    AK_CHECK_NEAR(l1.max, 2.5, 0.0);
    /* Default inverse binds: inverse of the rest model matrix (translation -(y sums)). */
    ak_mat4_cspan ib = ak_skeleton_inverse_binds(sk);
    AK_CHECK_NEAR(ib.ptr[2].m[13], -(1.0 - 0.5 - 0.5), 1e-6);
    AK_CHECK_NEAR(ib.ptr[3].m[13], -1.2, 1e-6);
    ak_skeleton_destroy(sk);
    ak_skeleton_destroy(NULL);
}

AK_TEST(create_validation_codes) {
    ak_joint_desc js[3] = {joint("a", -1, 0), joint("b", 0, 1), joint("c", 1, 1)};
    ak_skeleton_desc d = {.joints = js, .joint_count = 3};
    ak_skeleton* sk = (ak_skeleton*)1;
    ak_diag diag;
    AK_CHECK_EQ(ak_skeleton_create(NULL, NULL, &sk, NULL), AK_ERR_NULL_ARG);
    AK_CHECK(sk == NULL);
    AK_CHECK_EQ(ak_skeleton_create(&d, NULL, NULL, NULL), AK_ERR_NULL_ARG);
    ak_skeleton_desc zero = {0};
    AK_CHECK_EQ(ak_skeleton_create(&zero, NULL, &sk, NULL), AK_ERR_EMPTY);
    ak_skeleton_desc nojoints = {.joints = NULL, .joint_count = 2};
    AK_CHECK_EQ(ak_skeleton_create(&nojoints, NULL, &sk, NULL), AK_ERR_NULL_ARG);
    ak_skeleton_desc many = {.joints = js, .joint_count = (size_t)AK_SKELETON_MAX_JOINTS + 1}; /* refused before any joint is read */
    AK_CHECK_EQ(ak_skeleton_create(&many, NULL, &sk, NULL), AK_ERR_BAD_ARG);

    js[2].type = AK_JOINT_TYPE_COUNT;
    AK_CHECK_EQ(ak_skeleton_create(&d, NULL, &sk, &diag), AK_ERR_BAD_ARG);
    AK_CHECK(strstr(diag.message, "'c'") != NULL);
    js[2].type = AK_JOINT_FREE;

    js[1].parent = 1; /* itself */
    AK_CHECK_EQ(ak_skeleton_create(&d, NULL, &sk, &diag), AK_ERR_BAD_HIERARCHY);
    AK_CHECK(strstr(diag.message, "'b'") != NULL);
    js[1].parent = 2; /* after it */
    AK_CHECK_EQ(ak_skeleton_create(&d, NULL, &sk, NULL), AK_ERR_BAD_HIERARCHY);
    js[1].parent = -2;
    AK_CHECK_EQ(ak_skeleton_create(&d, NULL, &sk, NULL), AK_ERR_BAD_HIERARCHY);
    js[1].parent = 0;

    js[2].name = "a";
    AK_CHECK_EQ(ak_skeleton_create(&d, NULL, &sk, &diag), AK_ERR_DUPLICATE);
    AK_CHECK(strstr(diag.message, "'a'") != NULL);
    js[2].name = NULL;
    AK_CHECK_EQ(ak_skeleton_create(&d, NULL, &sk, &diag), AK_ERR_NULL_ARG);
    AK_CHECK(strstr(diag.message, "joint 2") != NULL);
    js[2].name = "c";

    js[1].rest.translation.x = NAN;
    AK_CHECK_EQ(ak_skeleton_create(&d, NULL, &sk, &diag), AK_ERR_BAD_DATA);
    AK_CHECK(strstr(diag.message, "'b'") != NULL);
    js[1].rest.translation.x = 0.0f;
    js[1].rest.scale.z = INFINITY;
    AK_CHECK_EQ(ak_skeleton_create(&d, NULL, &sk, NULL), AK_ERR_BAD_DATA);
    js[1].rest.scale.z = 1.0f;
    js[1].rest.rotation = ak_quat_make(0, 0, 0, 0);
    AK_CHECK_EQ(ak_skeleton_create(&d, NULL, &sk, NULL), AK_ERR_BAD_DATA);
    js[1].rest.rotation = ak_quat_identity();
    ak_mat4 bad = ak_mat4_identity();
    bad.m[5] = NAN;
    js[2].inverse_bind = &bad;
    AK_CHECK_EQ(ak_skeleton_create(&d, NULL, &sk, NULL), AK_ERR_BAD_DATA);
    js[2].inverse_bind = NULL;
    js[1].type = AK_JOINT_HINGE;
    js[1].limits.min = 1.0f, js[1].limits.max = -1.0f;
    AK_CHECK_EQ(ak_skeleton_create(&d, NULL, &sk, NULL), AK_ERR_BAD_DATA);
    js[1].limits.min = -1.0f, js[1].limits.max = NAN;
    AK_CHECK_EQ(ak_skeleton_create(&d, NULL, &sk, NULL), AK_ERR_BAD_DATA);
    js[1].limits.max = 1.0f;
    js[1].limits.twist_min = 0.5f, js[1].limits.twist_max = 0.1f;
    AK_CHECK_EQ(ak_skeleton_create(&d, NULL, &sk, NULL), AK_ERR_BAD_DATA);
    js[1].limits.twist_min = 0.0f, js[1].limits.twist_max = 0.0f;
    AK_CHECK(sk == NULL);
    AK_CHECK_EQ(ak_skeleton_create(&d, NULL, &sk, NULL), AK_OK);
    ak_skeleton_destroy(sk);
}


AK_TEST(one_allocation) {
    ak_test_counter c = {0};
    ak_allocator a = ak_test_counting_allocator(&c);
    ak_joint_desc js[2] = {joint("a", -1, 0), joint("b", 0, 1)};
    ak_skeleton_desc d = {.joints = js, .joint_count = 2};
    ak_skeleton* sk = NULL;
    AK_CHECK_EQ(ak_skeleton_create(&d, &a, &sk, NULL), AK_OK);
    AK_CHECK_EQ(c.live, 1);
    ak_skeleton_destroy(sk);
    AK_CHECK_EQ(c.live, 0);
    js[1].name = "a"; /* failure paths free their scratch */
    AK_CHECK_EQ(ak_skeleton_create(&d, &a, &sk, NULL), AK_ERR_DUPLICATE);
    AK_CHECK_EQ(c.live, 0);
}

/* ---- reorder ------------------------------------------------------------------------- */

AK_TEST(reorder_shuffled) {
    enum { N = 200 };
    ak_rng rng = ak_rng_make(11);
    for (int trial = 0; trial < 20; ++trial) {
        int32_t sorted_parent[N];
        for (int i = 0; i < N; ++i)
            sorted_parent[i] = (i == 0 || ak_rng_float(&rng) < 0.03f)
                                   ? -1
                                   : (int32_t)(ak_rng_u32(&rng) % (uint32_t)i);
        /* Shuffle: perm[new] = old. */
        int32_t perm[N], inv[N];
        for (int i = 0; i < N; ++i) perm[i] = i;
        for (int i = N - 1; i > 0; --i) {
            int k = (int)(ak_rng_u32(&rng) % (uint32_t)(i + 1));
            int32_t t = perm[i];
            perm[i] = perm[k];
            perm[k] = t;
        }
        for (int i = 0; i < N; ++i) inv[perm[i]] = i;
        int32_t shuffled[N];
        for (int i = 0; i < N; ++i)
            shuffled[i] = sorted_parent[perm[i]] < 0 ? -1 : inv[sorted_parent[perm[i]]];
        int32_t order[N];
        AK_CHECK_EQ(ak_skeleton_reorder((ak_i32_cspan){shuffled, N}, (ak_i32_span){order, N}),
                    AK_OK);
        /* A permutation, with every parent placed before its child. */
        int pos[N], seen[N] = {0};
        for (int k = 0; k < N; ++k) {
            AK_CHECK(order[k] >= 0 && order[k] < N);
            if (order[k] < 0 || order[k] >= N) return;
            seen[order[k]]++;
            pos[order[k]] = k;
        }
        int bad = 0;
        for (int i = 0; i < N; ++i) {
            if (seen[i] != 1) ++bad;
            if (shuffled[i] >= 0 && pos[shuffled[i]] >= pos[i]) ++bad;
        }
        AK_CHECK_EQ(bad, 0);
    }
    /* Already sorted input: identity (stable). */
    int32_t p[5] = {-1, 0, 1, 0, 3}, o[6];
    AK_CHECK_EQ(ak_skeleton_reorder((ak_i32_cspan){p, 5}, (ak_i32_span){o, 6}), AK_OK);
    for (int i = 0; i < 5; ++i) AK_CHECK_EQ(o[i], i);
    /* A child listed first moves only behind its parent chain. */
    int32_t q[4] = {2, -1, 1, -1}, oq[4];
    AK_CHECK_EQ(ak_skeleton_reorder((ak_i32_cspan){q, 4}, (ak_i32_span){oq, 4}), AK_OK);
    AK_CHECK(oq[0] == 1 && oq[1] == 2 && oq[2] == 0 && oq[3] == 3);
}

AK_TEST(reorder_errors) {
    int32_t cyc[4] = {-1, 2, 3, 1}, o[4];
    AK_CHECK_EQ(ak_skeleton_reorder((ak_i32_cspan){cyc, 4}, (ak_i32_span){o, 4}),
                AK_ERR_BAD_HIERARCHY);
    int32_t self[2] = {-1, 1};
    AK_CHECK_EQ(ak_skeleton_reorder((ak_i32_cspan){self, 2}, (ak_i32_span){o, 2}),
                AK_ERR_BAD_HIERARCHY);
    int32_t range[2] = {-1, 5};
    AK_CHECK_EQ(ak_skeleton_reorder((ak_i32_cspan){range, 2}, (ak_i32_span){o, 2}),
                AK_ERR_BAD_HIERARCHY);
    range[1] = -3;
    AK_CHECK_EQ(ak_skeleton_reorder((ak_i32_cspan){range, 2}, (ak_i32_span){o, 2}),
                AK_ERR_BAD_HIERARCHY);
    int32_t ok[3] = {-1, 0, 0};
    AK_CHECK_EQ(ak_skeleton_reorder((ak_i32_cspan){ok, 3}, (ak_i32_span){o, 2}), AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_skeleton_reorder((ak_i32_cspan){NULL, 3}, (ak_i32_span){o, 4}), AK_ERR_NULL_ARG);
}

/* ---- FK ------------------------------------------------------------------------------ */

enum { FK_N = 64 };

static ak_skeleton* random_skeleton(ak_rng* rng, int* parents, ak_transform* rest) {
    static char names[FK_N][16];
    ak_joint_desc js[FK_N];
    for (int i = 0; i < FK_N; ++i) {
        snprintf(names[i], sizeof names[i], "j%d", i);
        parents[i] = (i == 0 || i == 40) ? -1 : (int)(ak_rng_u32(rng) % (uint32_t)i);
        rest[i] = random_transform(rng);
        memset(&js[i], 0, sizeof js[i]);
        js[i].name = names[i];
        js[i].parent = parents[i];
        js[i].rest = rest[i];
    }
    ak_skeleton_desc d = {.joints = js, .joint_count = FK_N};
    ak_skeleton* sk = NULL;
    ak_skeleton_create(&d, NULL, &sk, NULL);
    return sk;
}

AK_TEST(fk_affine_products_equal_full_products) {
    /* FK multiplies affine matrices without the bottom row's terms (and a projective root
     * through the full product): every model matrix must equal, float for float (within a few
     * roundings where FMA is used), the chain of full 4x4 products in the same order
     * (ak_mat4_mul), with no root, an affine root and a projective root, and keep the bottom
     * row (0, 0, 0, 1) exactly when affine. */
    ak_rng rng = ak_rng_make(41);
    int parents[FK_N];
    ak_transform rest[FK_N], pose[FK_N];
    ak_skeleton* sk = random_skeleton(&rng, parents, rest);
    AK_CHECK(sk != NULL);
    if (!sk) return;
    for (int i = 0; i < FK_N; ++i) {
        pose[i] = random_transform(&rng);
        pose[i].scale = ak_vec3_make(ak_rng_range(&rng, 0.5f, 2.0f), ak_rng_range(&rng, 0.5f, 2.0f),
                                     ak_rng_range(&rng, 0.5f, 2.0f)); /* non-uniform */
    }
    ak_mat4 roots[3];
    roots[0] = ak_mat4_identity();
    roots[1] = ak_transform_to_mat4(random_transform(&rng));
    roots[2] = roots[1];
    roots[2].m[3] = 0.25f, roots[2].m[15] = 2.0f; /* projective */
    /* every kernel this CPU has: scalar and AVX give ak_mat4_mul's floats, the FMA kernels
     * (AVX2 + FMA, AVX-512) stay within a few roundings */
    for (int lim = AK_FK_SIMD_SCALAR; lim < AK_FK_SIMD_COUNT; ++lim) {
    AK_CHECK_EQ(ak_skeleton_set_simd_limit(sk, (ak_fk_simd)lim), AK_OK);
    const char* kernel = ak_skeleton_simd_name(sk);
    const bool fused = !strcmp(kernel, "avx2") || !strcmp(kernel, "avx512");
    if (lim == AK_FK_SIMD_SCALAR) AK_CHECK(!strcmp(kernel, "scalar"));
    if (lim == AK_FK_SIMD_AVX2) AK_CHECK(strcmp(kernel, "avx512") != 0);
    const float tol = fused ? 2e-6f : 0.0f;
    printf("  FK kernel %s: tolerance vs ak_mat4_mul chains %g x the largest element\n", kernel, (double)tol);
    for (int r = 0; r < 4; ++r) {
        ak_mat4 model[FK_N], ref[FK_N];
        const ak_mat4* root = r == 3 ? NULL : &roots[r];
        if (root)
            AK_CHECK_EQ(ak_skeleton_local_to_model_rooted(sk, *root, (ak_transform_cspan){pose, FK_N},
                                                          (ak_mat4_span){model, FK_N}),
                        AK_OK);
        else
            AK_CHECK_EQ(ak_skeleton_local_to_model(sk, (ak_transform_cspan){pose, FK_N}, (ak_mat4_span){model, FK_N}),
                        AK_OK);
        int differ = 0;
        for (int i = 0; i < FK_N; ++i) {
            const ak_mat4 m = ak_transform_to_mat4(pose[i]);
            ref[i] = parents[i] >= 0 ? ak_mat4_mul(ref[parents[i]], m) : root ? ak_mat4_mul(*root, m) : m;
            float big = 0.0f;
            for (int e = 0; e < 16; ++e) big = fmaxf(big, fabsf(ref[i].m[e]));
            /* the same floats without FMA; with fused multiply-adds (AVX2+FMA CPUs) within a
             * few roundings per product down the chain */
            for (int e = 0; e < 16; ++e) differ += fabsf(model[i].m[e] - ref[i].m[e]) > tol * big; /* -0 == +0 */
            if (r != 2) AK_CHECK(model[i].m[3] == 0.0f && model[i].m[7] == 0.0f && model[i].m[11] == 0.0f &&
                                 model[i].m[15] == 1.0f);
        }
        AK_CHECK_MSG(differ == 0, "kernel %s, root %d: %d floats differ from the full products", kernel, r, differ);
    }
    }
    AK_CHECK_EQ(ak_skeleton_set_simd_limit(sk, AK_FK_SIMD_COUNT), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_skeleton_set_simd_limit(NULL, AK_FK_SIMD_DEFAULT), AK_ERR_NULL_ARG);
    AK_CHECK(!strcmp(ak_skeleton_simd_name(NULL), ""));
    ak_skeleton_destroy(sk);
}

AK_TEST(fk_kernels_chains_and_partial_batches) {
    /* Every FK kernel against the double-precision chain of products, on skeletons whose joint
     * counts are not multiples of the kernels' 8-joint batches, with long parent = i - 1 chains
     * (the kernels' register path), branches back to earlier joints (parents read from the
     * output), two roots, and with no root and an affine root matrix. */
    static const int counts[] = {1, 3, 8, 13, 61};
    ak_rng rng = ak_rng_make(77);
    for (size_t ci = 0; ci < sizeof counts / sizeof counts[0]; ++ci) {
        const int n = counts[ci];
        int parents[61];
        ak_transform pose[61];
        char names[61][8];
        ak_joint_desc js[61];
        for (int i = 0; i < n; ++i) {
            parents[i] = i == 0 || i == 40 ? -1 : i % 7 == 0 ? i / 3 : i - 1;
            pose[i] = random_transform(&rng);
            pose[i].scale = ak_vec3_make(ak_rng_range(&rng, 0.5f, 2.0f), ak_rng_range(&rng, 0.5f, 2.0f),
                                         ak_rng_range(&rng, 0.5f, 2.0f));
            snprintf(names[i], sizeof names[i], "j%d", i);
            memset(&js[i], 0, sizeof js[i]);
            js[i].name = names[i], js[i].parent = parents[i], js[i].rest = ak_transform_identity();
        }
        ak_skeleton_desc d = {.joints = js, .joint_count = (size_t)n};
        ak_skeleton* sk = NULL;
        AK_CHECK_EQ(ak_skeleton_create(&d, NULL, &sk, NULL), AK_OK);
        if (!sk) return;
        const ak_transform rt = random_transform(&rng);
        const dmat4 droot = dmat_from_trs(rt);
        for (int lim = AK_FK_SIMD_SCALAR; lim < AK_FK_SIMD_COUNT; ++lim) {
            AK_CHECK_EQ(ak_skeleton_set_simd_limit(sk, (ak_fk_simd)lim), AK_OK);
            for (int rooted = 0; rooted < 2; ++rooted) {
                ak_mat4 model[62];
                model[n].m[0] = 12345.0f; /* past the end: must stay untouched */
                if (rooted)
                    AK_CHECK_EQ(ak_skeleton_local_to_model_rooted(sk, ak_transform_to_mat4(rt), (ak_transform_cspan){pose, (size_t)n},
                                                                  (ak_mat4_span){model, (size_t)n}),
                                AK_OK);
                else
                    AK_CHECK_EQ(ak_skeleton_local_to_model(sk, (ak_transform_cspan){pose, (size_t)n}, (ak_mat4_span){model, (size_t)n}),
                                AK_OK);
                double worst = 0.0;
                for (int i = 0; i < n; ++i) {
                    dmat4 ref = ref_world(parents, pose, i);
                    if (rooted) ref = dmat_mul(droot, ref);
                    double scale = 1.0;
                    for (int k = 0; k < 16; ++k) scale = fmax(scale, fabs(ref.m[k]));
                    worst = fmax(worst, max_diff(&model[i], &ref) / scale);
                    AK_CHECK(model[i].m[3] == 0.0f && model[i].m[7] == 0.0f && model[i].m[11] == 0.0f && model[i].m[15] == 1.0f);
                }
                AK_CHECK(model[n].m[0] == 12345.0f);
                AK_CHECK_MSG(worst < 2e-5, "FK kernel %s, %d joints, root %d: relative error %g",
                             ak_skeleton_simd_name(sk), n, rooted, worst);
            }
        }
        ak_skeleton_destroy(sk);
    }
}

AK_TEST(fk_matches_naive_double) {
    ak_rng rng = ak_rng_make(3);
    int parents[FK_N];
    ak_transform rest[FK_N], pose[FK_N];
    ak_skeleton* sk = random_skeleton(&rng, parents, rest);
    AK_CHECK(sk != NULL);
    if (!sk) return;
    for (int i = 0; i < FK_N; ++i) pose[i] = random_transform(&rng);
    ak_mat4 model[FK_N];
    double worst = 0.0;
    for (int lim = AK_FK_SIMD_SCALAR; lim < AK_FK_SIMD_COUNT; ++lim) { /* every kernel this CPU has */
        AK_CHECK_EQ(ak_skeleton_set_simd_limit(sk, (ak_fk_simd)lim), AK_OK);
        AK_CHECK_EQ(ak_skeleton_local_to_model(sk, (ak_transform_cspan){pose, FK_N},
                                               (ak_mat4_span){model, FK_N}),
                    AK_OK);
        worst = 0.0;
        for (int i = 0; i < FK_N; ++i) {
            dmat4 ref = ref_world(parents, pose, i);
            double scale = 1.0;
            for (int k = 12; k < 15; ++k) scale = fmax(scale, fabs(ref.m[k]));
            worst = fmax(worst, max_diff(&model[i], &ref) / scale);
        }
        AK_CHECK_MSG(worst < 1e-4, "FK kernel %s: relative error %g", ak_skeleton_simd_name(sk), worst);
    }
    AK_CHECK_EQ(ak_skeleton_set_simd_limit(sk, AK_FK_SIMD_DEFAULT), AK_OK);
    AK_CHECK_EQ(ak_skeleton_local_to_model(sk, (ak_transform_cspan){pose, FK_N}, (ak_mat4_span){model, FK_N}),
                AK_OK);

    /* Rooted: every root gets the extra transform. */
    ak_transform rt = random_transform(&rng);
    ak_mat4 rooted[FK_N];
    AK_CHECK_EQ(ak_skeleton_local_to_model_rooted(sk, ak_transform_to_mat4(rt),
                                                  (ak_transform_cspan){pose, FK_N},
                                                  (ak_mat4_span){rooted, FK_N}),
                AK_OK);
    worst = 0.0;
    dmat4 droot = dmat_from_trs(rt);
    for (int i = 0; i < FK_N; ++i) {
        dmat4 ref = dmat_mul(droot, ref_world(parents, pose, i));
        worst = fmax(worst, max_diff(&rooted[i], &ref));
    }
    AK_CHECK_MSG(worst < 1e-4 * 8, "rooted FK error %g", worst);

    /* Skinning matrices at the rest pose are the identity; in a pose they map the rest model
     * matrix onto the posed one. */
    ak_mat4 rest_model[FK_N], skin[FK_N];
    ak_skeleton_local_to_model(sk, ak_skeleton_rest_pose(sk), (ak_mat4_span){rest_model, FK_N});
    AK_CHECK_EQ(ak_skeleton_skinning_matrices(sk, (ak_mat4_cspan){rest_model, FK_N},
                                              (ak_mat4_span){skin, FK_N}),
                AK_OK);
    worst = 0.0;
    dmat4 id;
    memset(&id, 0, sizeof id);
    id.m[0] = id.m[5] = id.m[10] = id.m[15] = 1.0;
    for (int i = 0; i < FK_N; ++i) worst = fmax(worst, max_diff(&skin[i], &id));
    AK_CHECK_MSG(worst < 1e-3, "bind palette differs from identity by %g", worst);
    ak_skeleton_skinning_matrices(sk, (ak_mat4_cspan){model, FK_N}, (ak_mat4_span){skin, FK_N});
    worst = 0.0;
    for (int i = 0; i < FK_N; ++i) {
        ak_mat4 back = ak_mat4_mul(skin[i], rest_model[i]);
        dmat4 ref = ref_world(parents, pose, i);
        worst = fmax(worst, max_diff(&back, &ref));
    }
    AK_CHECK_MSG(worst < 1e-3, "palette * rest != posed: %g", worst);

    /* Error codes. */
    AK_CHECK_EQ(ak_skeleton_local_to_model(sk, (ak_transform_cspan){pose, FK_N - 1},
                                           (ak_mat4_span){model, FK_N}),
                AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(
        ak_skeleton_local_to_model(sk, (ak_transform_cspan){pose, FK_N}, (ak_mat4_span){model, 3}),
        AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_skeleton_local_to_model(NULL, (ak_transform_cspan){pose, FK_N},
                                           (ak_mat4_span){model, FK_N}),
                AK_ERR_NULL_ARG);
    AK_CHECK_EQ(
        ak_skeleton_skinning_matrices(sk, (ak_mat4_cspan){model, 2}, (ak_mat4_span){skin, FK_N}),
        AK_ERR_SPAN_SMALL);
    ak_skeleton_destroy(sk);
}

AK_TEST(fk_batch) {
    ak_rng rng = ak_rng_make(5);
    int parents[FK_N];
    ak_transform rest[FK_N];
    ak_skeleton* sk = random_skeleton(&rng, parents, rest);
    enum { C = 5 };
    static ak_transform poses[C * FK_N];
    static ak_mat4 batch[C * FK_N];
    for (int i = 0; i < C * FK_N; ++i) poses[i] = random_transform(&rng);
    AK_CHECK_EQ(ak_skeleton_local_to_model_batch(sk, C, (ak_transform_cspan){poses, C * FK_N},
                                                 (ak_mat4_span){batch, C * FK_N}),
                AK_OK);
    double worst = 0.0;
    for (int c = 0; c < C; ++c)
        for (int i = 0; i < FK_N; ++i) {
            dmat4 ref = ref_world(parents, poses + c * FK_N, i);
            worst = fmax(worst, max_diff(&batch[c * FK_N + i], &ref));
        }
    AK_CHECK_MSG(worst < 1e-3, "batch FK error %g", worst);
    AK_CHECK_EQ(ak_skeleton_local_to_model_batch(sk, C, (ak_transform_cspan){poses, C * FK_N - 1},
                                                 (ak_mat4_span){batch, C * FK_N}),
                AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_skeleton_local_to_model_batch(sk, 0, (ak_transform_cspan){NULL, 0},
                                                 (ak_mat4_span){NULL, 0}),
                AK_OK);
    ak_skeleton_destroy(sk);
}

/* ---- swing-twist and limits ------------------------------------------------------------ */

AK_TEST(swing_twist) {
    ak_rng rng = ak_rng_make(17);
    for (int t = 0; t < 500; ++t) {
        ak_quat q = random_quat(&rng);
        ak_vec3 axis = ak_vec3_normalize(ak_vec3_make(
            ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1)));
        ak_quat sw, tw;
        ak_quat_swing_twist(q, axis, &sw, &tw);
        /* q = swing * twist, twist's vector part parallel to axis, swing's perpendicular. */
        AK_CHECK(quat_angle_d(ak_quat_mul(sw, tw), q) < 1e-3);
        ak_vec3 tv = ak_vec3_make(tw.x, tw.y, tw.z), sv = ak_vec3_make(sw.x, sw.y, sw.z);
        AK_CHECK(ak_vec3_length(ak_vec3_cross(tv, axis)) < 1e-4f);
        AK_CHECK(fabsf(ak_vec3_dot(sv, axis)) < 1e-4f);
        /* The twist leaves the axis fixed; the swing moves it exactly as q does. */
        ak_vec3 qa = ak_quat_rotate(q, axis), sa = ak_quat_rotate(sw, axis);
        AK_CHECK(ak_vec3_distance(qa, sa) < 1e-4f);
    }
}

static ak_skeleton* limited_skeleton(void) {
    ak_joint_desc js[5];
    memset(js, 0, sizeof js);
    const char* names[5] = {"root", "hinge", "ball", "prism", "free"};
    ak_quat tilt = ak_quat_from_axis_angle(ak_vec3_make(0.3f, 0.2f, 1.0f), 0.7f);
    for (int i = 0; i < 5; ++i) {
        js[i].name = names[i];
        js[i].parent = i - 1;
        js[i].rest = ak_transform_make(ak_vec3_make(0.1f * i, 0.5f, 0.0f),
                                       i ? tilt : ak_quat_identity(), ak_vec3_one());
    }
    js[1].type = AK_JOINT_HINGE;
    js[1].limits = (ak_joint_limits){.axis = {0, 0, 2}, .min = -0.5f, .max = 1.2f};
    js[2].type = AK_JOINT_BALL;
    js[2].limits = (ak_joint_limits){
        .axis = {0, 1, 0}, .cone_angle = 0.6f, .twist_min = -0.3f, .twist_max = 0.4f};
    js[3].type = AK_JOINT_PRISM;
    js[3].limits = (ak_joint_limits){.axis = {1, 1, 0}, .min = -0.1f, .max = 0.25f};
    js[4].type = AK_JOINT_FREE;
    ak_skeleton_desc d = {.joints = js, .joint_count = 5};
    ak_skeleton* sk = NULL;
    ak_skeleton_create(&d, NULL, &sk, NULL);
    return sk;
}

AK_TEST(limits_clamp_properties) {
    ak_skeleton* sk = limited_skeleton();
    AK_CHECK(sk != NULL);
    if (!sk) return;
    ak_transform_cspan rest = ak_skeleton_rest_pose(sk);
    ak_rng rng = ak_rng_make(23);
    int fails_within = 0, fails_hinge = 0, fails_cone = 0, fails_twist = 0, fails_prism = 0;
    for (int t = 0; t < 1000; ++t) {
        ak_transform pose[5];
        for (int i = 0; i < 5; ++i) pose[i] = random_transform(&rng);
        ak_transform orig[5];
        memcpy(orig, pose, sizeof pose);
        AK_CHECK_EQ(ak_skeleton_apply_limits(sk, (ak_transform_span){pose, 5}), AK_OK);
        for (int i = 0; i < 5; ++i)
            if (!ak_skeleton_joint_within_limits(sk, (size_t)i, pose[i], 1e-3f)) ++fails_within;
        /* Hinge: rest^-1 * rot is a rotation about the (normalised) axis (0,0,1), angle in range.
         */
        ak_quat rel = ak_quat_mul(ak_quat_conjugate(rest.ptr[1].rotation), pose[1].rotation);
        if (rel.w < 0) rel = ak_quat_neg(rel);
        double ang = 2.0 * atan2((double)rel.z, (double)rel.w);
        if (fabs(rel.x) > 1e-5 || fabs(rel.y) > 1e-5 || ang < -0.5 - 1e-4 || ang > 1.2 + 1e-4)
            ++fails_hinge;
        if (ak_vec3_distance(pose[1].translation, rest.ptr[1].translation) > 0) ++fails_hinge;
        /* Ball: the twist axis (0,1,0) moves at most the cone angle; twist in range. */
        ak_quat relb = ak_quat_mul(ak_quat_conjugate(rest.ptr[2].rotation), pose[2].rotation);
        ak_vec3 ya = ak_quat_rotate(relb, ak_vec3_make(0, 1, 0));
        double cone = acos(fmin(1.0, fmax(-1.0, (double)ya.y)));
        if (cone > 0.6 + 1e-3) ++fails_cone;
        /* Twist measured independently: undo the swing (shortest arc y -> ya), read angle about y.
         */
        ak_quat undo = ak_quat_from_to(ya, ak_vec3_make(0, 1, 0));
        ak_quat tw = ak_quat_mul(undo, relb);
        if (tw.w < 0) tw = ak_quat_neg(tw);
        double twist = 2.0 * atan2((double)tw.y, (double)tw.w);
        if (twist < -0.3 - 1e-3 || twist > 0.4 + 1e-3) ++fails_twist;
        /* Prism: rest rotation, translation = rest + d * axis_parent, d in range. */
        ak_vec3 axp =
            ak_quat_rotate(rest.ptr[3].rotation, ak_vec3_normalize(ak_vec3_make(1, 1, 0)));
        ak_vec3 dv = ak_vec3_sub(pose[3].translation, rest.ptr[3].translation);
        double dd = ak_vec3_dot(dv, axp);
        if (quat_angle_d(pose[3].rotation, rest.ptr[3].rotation) > 1e-3 || dd < -0.1 - 1e-5 ||
            dd > 0.25 + 1e-5 || ak_vec3_length(ak_vec3_madd(dv, axp, -(float)dd)) > 1e-5f)
            ++fails_prism;
        /* Free joints are untouched. */
        AK_CHECK(memcmp(&pose[4], &orig[4], sizeof(ak_transform)) == 0);
        AK_CHECK(memcmp(&pose[0], &orig[0], sizeof(ak_transform)) == 0);
    }
    AK_CHECK_EQ(fails_within, 0);
    AK_CHECK_EQ(fails_hinge, 0);
    AK_CHECK_EQ(fails_cone, 0);
    AK_CHECK_EQ(fails_twist, 0);
    AK_CHECK_EQ(fails_prism, 0);
    ak_skeleton_destroy(sk);
}

AK_TEST(limits_inside_unchanged_outside_detected) {
    ak_skeleton* sk = limited_skeleton();
    if (!sk) {
        AK_CHECK(sk != NULL);
        return;
    }
    ak_transform_cspan rest = ak_skeleton_rest_pose(sk);
    /* A hinge rotation inside the range is kept (up to rounding). */
    ak_transform h = rest.ptr[1];
    h.rotation =
        ak_quat_mul(rest.ptr[1].rotation, ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), 0.8f));
    AK_CHECK(ak_skeleton_joint_within_limits(sk, 1, h, 1e-4f));
    ak_transform hc = ak_skeleton_limit_joint(sk, 1, h);
    AK_CHECK(quat_angle_d(hc.rotation, h.rotation) < 1e-4);
    /* Past max: not within, and clamps to exactly max. */
    h.rotation =
        ak_quat_mul(rest.ptr[1].rotation, ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), 1.5f));
    AK_CHECK(!ak_skeleton_joint_within_limits(sk, 1, h, 1e-4f));
    hc = ak_skeleton_limit_joint(sk, 1, h);
    ak_quat want =
        ak_quat_mul(rest.ptr[1].rotation, ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), 1.2f));
    AK_CHECK(quat_angle_d(hc.rotation, want) < 1e-4);
    /* Off-axis rotation is not a hinge motion. */
    h.rotation =
        ak_quat_mul(rest.ptr[1].rotation, ak_quat_from_axis_angle(ak_vec3_make(1, 0, 0), 0.3f));
    AK_CHECK(!ak_skeleton_joint_within_limits(sk, 1, h, 1e-3f));
    /* Ball: swing 0.5 inside the 0.6 cone is fine, 0.9 is not and clamps to 0.6. */
    ak_transform b = rest.ptr[2];
    b.rotation =
        ak_quat_mul(rest.ptr[2].rotation, ak_quat_from_axis_angle(ak_vec3_make(1, 0, 0), 0.5f));
    AK_CHECK(ak_skeleton_joint_within_limits(sk, 2, b, 1e-4f));
    b.rotation =
        ak_quat_mul(rest.ptr[2].rotation, ak_quat_from_axis_angle(ak_vec3_make(1, 0, 0), 0.9f));
    AK_CHECK(!ak_skeleton_joint_within_limits(sk, 2, b, 1e-4f));
    ak_transform bc = ak_skeleton_limit_joint(sk, 2, b);
    want = ak_quat_mul(rest.ptr[2].rotation, ak_quat_from_axis_angle(ak_vec3_make(1, 0, 0), 0.6f));
    AK_CHECK(quat_angle_d(bc.rotation, want) < 1e-4);
    /* Twist 0.5 > 0.4 about the ball axis. */
    b.rotation =
        ak_quat_mul(rest.ptr[2].rotation, ak_quat_from_axis_angle(ak_vec3_make(0, 1, 0), 0.5f));
    AK_CHECK(!ak_skeleton_joint_within_limits(sk, 2, b, 1e-4f));
    /* Prism: slide 0.2 inside, 0.3 outside -> 0.25. */
    ak_vec3 axp = ak_quat_rotate(rest.ptr[3].rotation, ak_vec3_normalize(ak_vec3_make(1, 1, 0)));
    ak_transform p = rest.ptr[3];
    p.translation = ak_vec3_madd(rest.ptr[3].translation, axp, 0.2f);
    AK_CHECK(ak_skeleton_joint_within_limits(sk, 3, p, 1e-5f));
    p.translation = ak_vec3_madd(rest.ptr[3].translation, axp, 0.3f);
    AK_CHECK(!ak_skeleton_joint_within_limits(sk, 3, p, 1e-5f));
    ak_transform pc = ak_skeleton_limit_joint(sk, 3, p);
    AK_CHECK_NEAR(ak_vec3_dot(ak_vec3_sub(pc.translation, rest.ptr[3].translation), axp), 0.25,
                  1e-5);
    /* NaN poses are never within limits; out-of-range joints are refused. */
    p.translation.x = NAN;
    AK_CHECK(!ak_skeleton_joint_within_limits(sk, 3, p, 1.0f));
    AK_CHECK(!ak_skeleton_joint_within_limits(sk, 99, rest.ptr[0], 1.0f));
    ak_transform pose[5];
    AK_CHECK_EQ(ak_skeleton_apply_limits(sk, (ak_transform_span){pose, 4}), AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_skeleton_apply_limits(NULL, (ak_transform_span){pose, 5}), AK_ERR_NULL_ARG);
    ak_skeleton_destroy(sk);
}

/* Random, mostly broken descs: never a crash (ASan/UBSan), always a documented code, and a
 * skeleton exactly when every rule holds (checked here independently). */
AK_TEST(hinge_limits_across_pi) {
    /* Hinge ranges may cross +-pi ([2.5, 3.5]) or span more than one turn's representation
     * ([-0.5, 6]); the twist angle comes in (-pi, pi]. An angle whose rotation lies inside the
     * range (modulo a full turn) must be left unchanged, and one outside must go to an end.
     * The clamp used to compare only the (-pi, pi] value, moving allowed rotations (3.4 rad ->
     * the 3.5 end) although the within-limits check accepted them. */
    const float range[3][2] = {{2.5f, 3.5f}, {-3.5f, -2.5f}, {-0.5f, 6.0f}};
    for (int r = 0; r < 3; ++r) {
        ak_joint_desc j = {.name = "hinge", .parent = -1, .rest = ak_transform_identity(), .type = AK_JOINT_HINGE};
        j.limits.axis = ak_vec3_make(0, 0, 1);
        j.limits.min = range[r][0];
        j.limits.max = range[r][1];
        ak_skeleton_desc d = {.joints = &j, .joint_count = 1};
        ak_skeleton* sk = NULL;
        AK_CHECK_EQ(ak_skeleton_create(&d, NULL, &sk, NULL), AK_OK);
        if (!sk) return;
        for (int i = 0; i <= 60; ++i) {
            double a = -3.1 + 6.2 * i / 60.0;
            bool inside = false;
            for (int k = -1; k <= 1; ++k)
                inside = inside || (a + 2 * PI_D * k >= range[r][0] && a + 2 * PI_D * k <= range[r][1]);
            ak_transform t = ak_transform_identity();
            t.rotation = ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), (float)a);
            ak_transform c = ak_skeleton_limit_joint(sk, 0, t);
            /* the clamped rotation's angle about z, as the nearest end or the input */
            double dot = fabs((double)ak_quat_dot(c.rotation, t.rotation));
            if (inside) {
                AK_CHECK_MSG(dot > 1.0 - 1e-6, "range [%g, %g]: allowed angle %g was moved", (double)range[r][0],
                             (double)range[r][1], a);
            } else {
                double ang = 2.0 * atan2((double)c.rotation.z, (double)c.rotation.w);
                double e0 = fabs(remainder(ang - range[r][0], 2 * PI_D)), e1 = fabs(remainder(ang - range[r][1], 2 * PI_D));
                AK_CHECK_MSG(fmin(e0, e1) < 1e-5, "range [%g, %g]: angle %g clamped to %g, not an end", (double)range[r][0],
                             (double)range[r][1], a, ang);
            }
            AK_CHECK(ak_skeleton_joint_within_limits(sk, 0, c, 1e-4f));
            AK_CHECK_EQ(ak_skeleton_joint_within_limits(sk, 0, t, 1e-4f), inside);
        }
        ak_skeleton_destroy(sk);
    }
}

AK_TEST(create_random_descs) {
    ak_rng rng = ak_rng_make(99);
    static const char* const pool[6] = {"a", "b", "c", "d", "e", "f"};
    int mismatches = 0;
    for (int trial = 0; trial < 3000; ++trial) {
        ak_joint_desc js[6];
        memset(js, 0, sizeof js);
        size_t n = 1 + ak_rng_u32(&rng) % 6;
        bool valid = true;
        for (size_t i = 0; i < n; ++i) {
            uint32_t r = ak_rng_u32(&rng);
            js[i].name = (r % 40 == 0) ? NULL : pool[(r >> 8) % 6];
            js[i].parent = (int)(ak_rng_u32(&rng) % 8) - 2; /* -2 .. 5 */
            js[i].rest = ak_transform_identity();
            if (r % 23 == 1) js[i].rest.translation.y = NAN;
            if (r % 29 == 2) js[i].rest.rotation = ak_quat_make(0, 0, 0, 0);
            js[i].type = (ak_joint_type)(ak_rng_u32(&rng) % 5);
            js[i].limits.min = ak_rng_range(&rng, -1, 1),
            js[i].limits.max = ak_rng_range(&rng, -1, 1);
            bool ok = js[i].name && js[i].type < AK_JOINT_TYPE_COUNT && js[i].parent >= -1 &&
                      js[i].parent < (int)i && r % 23 != 1 && r % 29 != 2 &&
                      js[i].limits.min <= js[i].limits.max;
            for (size_t k = 0; ok && k < i; ++k)
                if (js[k].name && js[i].name && strcmp(js[k].name, js[i].name) == 0) ok = false;
            valid = valid && ok;
        }
        ak_skeleton_desc d = {.joints = js, .joint_count = n};
        ak_skeleton* sk = NULL;
        ak_diag diag;
        ak_result r = ak_skeleton_create(&d, NULL, &sk, &diag);
        bool documented = r == AK_OK || r == AK_ERR_NULL_ARG || r == AK_ERR_BAD_ARG ||
                          r == AK_ERR_BAD_HIERARCHY || r == AK_ERR_DUPLICATE ||
                          r == AK_ERR_BAD_DATA;
        if (!documented || (r == AK_OK) != valid || (r == AK_OK) != (sk != NULL)) ++mismatches;
        if (r != AK_OK && diag.message[0] == 0) ++mismatches;
        ak_skeleton_destroy(sk);
    }
    AK_CHECK_EQ(mismatches, 0);
}

AK_TEST(pose_is_finite) {
    ak_transform p[2] = {ak_transform_identity(), ak_transform_identity()};
    AK_CHECK(ak_pose_is_finite((ak_transform_cspan){p, 2}));
    p[1].rotation.w = NAN;
    AK_CHECK(!ak_pose_is_finite((ak_transform_cspan){p, 2}));
    AK_CHECK(ak_pose_is_finite((ak_transform_cspan){p, 1}));
    AK_CHECK(!ak_pose_is_finite((ak_transform_cspan){NULL, 1}));
}

int main(void) {
    AK_RUN(create_and_query);
    AK_RUN(fk_affine_products_equal_full_products);
    AK_RUN(create_validation_codes);
    AK_RUN(one_allocation);
    AK_RUN(reorder_shuffled);
    AK_RUN(reorder_errors);
    AK_RUN(fk_kernels_chains_and_partial_batches);
    AK_RUN(fk_matches_naive_double);
    AK_RUN(fk_batch);
    AK_RUN(swing_twist);
    AK_RUN(limits_clamp_properties);
    AK_RUN(limits_inside_unchanged_outside_detected);
    AK_RUN(hinge_limits_across_pi);
    AK_RUN(create_random_descs);
    AK_RUN(pose_is_finite);
    return ak_test_finish();
}
