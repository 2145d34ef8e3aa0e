/* animkit math: vectors, matrices, quaternions, transforms.
 *
 * CONVENTIONS (also in docs/conventions.md; every module follows them):
 *   - right-handed coordinates, +Y up, -Z forward for cameras;
 *   - angles in radians, time in seconds, lengths in the asset's units (metres for builtins);
 *   - column vectors: p' = M p; a chain M = A B applies B first, then A;
 *   - ak_mat4 / ak_mat3 are column-major: element (row r, column c) is m[c*4 + r] (m[c*3 + r]);
 *   - quaternions are stored (x, y, z, w), w the scalar part; ak_quat_mul(a, b) applies b
 *     first, then a (the same order as matrices); unit quaternions represent rotations and
 *     q and -q are the same rotation;
 *   - ak_transform is T * R * S: scale first, then rotate, then translate;
 *   - Euler angles: ak_euler_order names the axes in storage order, ak_euler_frame says
 *     intrinsic (default) or extrinsic; see those enums;
 *   - ak_dualquat is (real = rotation r, dual = 0.5 (t, 0) r): rotate first, then translate.
 *
 * What it does: small value types and pure static inline functions on them (vectors,
 * quaternions with exp/log/slerp, Rodrigues matrices, 3x3/4x4 matrices, projections, TRS
 * transforms, dual quaternions). Compiled in src/math: matrix inverses, Euler angles in all
 * 12 orders (intrinsic and extrinsic), 3x3 SVD and polar decomposition, affine matrix
 * interpolation, dual quaternion blending, and array functions with SSE2 paths.
 *
 * What it does NOT do: fail, allocate or keep state. On degenerate input every function
 * returns a documented, finite fallback (normalising a zero vector gives zero; inverting a
 * singular matrix gives the identity; slerp between antipodal quaternions takes the shorter
 * path). No double-precision API: hot paths are float; decompositions use double inside.
 *
 * Usage:
 *     ak_quat q = ak_quat_from_axis_angle(ak_vec3_make(0, 1, 0), 0.5f * AK_PI);
 *     ak_vec3 p = ak_quat_rotate(q, ak_vec3_make(1, 0, 0));          // (0, 0, -1)
 *     ak_transform t = { .translation = {1, 2, 3}, .rotation = q, .scale = {1, 1, 1} };
 *     ak_mat4 m = ak_transform_to_mat4(t);
 *     ak_vec3 w = ak_mat4_transform_point(m, ak_vec3_make(1, 0, 0));  // (1, 2, 2)
 *     ak_quat h = ak_quat_slerp(ak_quat_identity(), q, 0.5f);         // 45 degrees about Y
 *     ak_vec3 e = ak_quat_to_euler(q, AK_EULER_XYZ, AK_EULER_INTRINSIC); // (0, pi/2, 0)
 *     ak_dualquat dq = ak_dualquat_from_rigid(q, t.translation);
 *     ak_vec3 w2 = ak_dualquat_transform_point(dq, ak_vec3_make(1, 0, 0)); // (1, 2, 2)
 *     ak_polar pd = ak_mat3_polar(ak_mat4_to_mat3(m));                // rotation + stretch
 *     ak_quat qs[64], out[64];  // ... filled by the caller
 *     ak_quat_cspan in = {qs, 64};
 *     ak_quat_span dst = {out, 64};
 *     if (ak_quat_normalize_array(in, dst) != AK_OK) { ... }
 *
 * Ownership and threading: the library keeps no pointer after a call returns; every function
 * is pure and reentrant.
 */
#ifndef ANIMKIT_MATH_H
#define ANIMKIT_MATH_H

#include <math.h>

#include "core.h"

#ifdef __cplusplus
extern "C" {
#endif

#define AK_PI 3.14159265358979323846f
#define AK_TWO_PI 6.28318530717958647692f
#define AK_HALF_PI 1.57079632679489661923f

/* ---- types -------------------------------------------------------------------------- */

typedef struct ak_vec2 { float x, y; } ak_vec2;
typedef struct ak_vec3 { float x, y, z; } ak_vec3;
typedef struct ak_vec4 { float x, y, z, w; } ak_vec4;
typedef struct ak_quat { float x, y, z, w; } ak_quat;          /* w is the scalar part */
typedef struct ak_mat3 { float m[9]; } ak_mat3;                 /* column-major */
typedef struct ak_mat4 { float m[16]; } ak_mat4;                /* column-major */

/* Translation, rotation, scale: M = T * R * S. */
typedef struct ak_transform {
    ak_vec3 translation; /* parent space */
    ak_quat rotation;    /* unit quaternion; zero-init is NOT identity: use ak_transform_identity() */
    ak_vec3 scale;       /* per-axis scale; zero-init is NOT identity */
} ak_transform;

/* Unit dual quaternion q = real + eps * dual for rigid transforms. */
typedef struct ak_dualquat {
    ak_quat real; /* rotation */
    ak_quat dual; /* 0.5 * t * real, t the translation as a pure quaternion */
} ak_dualquat;

AK_DEFINE_SPAN(vec2, ak_vec2)
AK_DEFINE_SPAN(vec3, ak_vec3)
AK_DEFINE_SPAN(vec4, ak_vec4)
AK_DEFINE_SPAN(quat, ak_quat)
AK_DEFINE_SPAN(mat4, ak_mat4)
AK_DEFINE_SPAN(transform, ak_transform)
AK_DEFINE_SPAN(dualquat, ak_dualquat)

/* ---- scalars ------------------------------------------------------------------------ */

/* Clamp, lerp, min and max of floats. */
static inline float ak_clampf(float x, float lo, float hi) { return x < lo ? lo : (x > hi ? hi : x); }
static inline float ak_lerpf(float a, float b, float t) { return a + (b - a) * t; }
static inline float ak_minf(float a, float b) { return a < b ? a : b; }
static inline float ak_maxf(float a, float b) { return a > b ? a : b; }
/* True when x is neither NaN nor infinite. */
static inline bool ak_finitef(float x) { return x - x == 0.0f; }
/* Degrees <-> radians. */
static inline float ak_radians(float degrees) { return degrees * (AK_PI / 180.0f); }
static inline float ak_degrees(float radians) { return radians * (180.0f / AK_PI); }

/* ---- vec2 / vec3 / vec4 -------------------------------------------------------------- */

/* Constructors and constants. */
static inline ak_vec2 ak_vec2_make(float x, float y) { ak_vec2 r = {x, y}; return r; }
static inline ak_vec3 ak_vec3_make(float x, float y, float z) { ak_vec3 r = {x, y, z}; return r; }
static inline ak_vec4 ak_vec4_make(float x, float y, float z, float w) { ak_vec4 r = {x, y, z, w}; return r; }
static inline ak_vec3 ak_vec3_zero(void) { ak_vec3 r = {0.0f, 0.0f, 0.0f}; return r; }
static inline ak_vec3 ak_vec3_one(void) { ak_vec3 r = {1.0f, 1.0f, 1.0f}; return r; }
static inline ak_vec3 ak_vec3_splat(float s) { ak_vec3 r = {s, s, s}; return r; }

/* Component-wise arithmetic (ak_vec3_mul is the component-wise product). */
static inline ak_vec3 ak_vec3_add(ak_vec3 a, ak_vec3 b) { return ak_vec3_make(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline ak_vec3 ak_vec3_sub(ak_vec3 a, ak_vec3 b) { return ak_vec3_make(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline ak_vec3 ak_vec3_mul(ak_vec3 a, ak_vec3 b) { return ak_vec3_make(a.x * b.x, a.y * b.y, a.z * b.z); }
static inline ak_vec3 ak_vec3_scale(ak_vec3 a, float s) { return ak_vec3_make(a.x * s, a.y * s, a.z * s); }
static inline ak_vec3 ak_vec3_neg(ak_vec3 a) { return ak_vec3_make(-a.x, -a.y, -a.z); }
/* a + b * s */
static inline ak_vec3 ak_vec3_madd(ak_vec3 a, ak_vec3 b, float s) {
    return ak_vec3_make(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s);
}
/* Dot and cross product (right-handed: x cross y = z), lengths and distance. */
static inline float ak_vec3_dot(ak_vec3 a, ak_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline ak_vec3 ak_vec3_cross(ak_vec3 a, ak_vec3 b) {
    return ak_vec3_make(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline float ak_vec3_length_sq(ak_vec3 a) { return ak_vec3_dot(a, a); }
static inline float ak_vec3_length(ak_vec3 a) { return sqrtf(ak_vec3_dot(a, a)); }
static inline float ak_vec3_distance(ak_vec3 a, ak_vec3 b) { return ak_vec3_length(ak_vec3_sub(a, b)); }
/* Unit vector along a; the zero vector (length below 1e-30) or a non-finite one gives zero.
 * A finite vector whose squared length overflows (components above ~1e19) is rescaled first,
 * so it still gives its direction. */
static inline ak_vec3 ak_vec3_normalize(ak_vec3 a) {
    float l2 = ak_vec3_dot(a, a);
    if (!(l2 > 1e-30f) || !ak_finitef(l2)) {
        if (!(l2 > 1e-30f) || !ak_finitef(a.x) || !ak_finitef(a.y) || !ak_finitef(a.z)) return ak_vec3_zero();
        float m = fmaxf(fabsf(a.x), fmaxf(fabsf(a.y), fabsf(a.z)));
        a = ak_vec3_make(a.x / m, a.y / m, a.z / m);
        l2 = ak_vec3_dot(a, a);
    }
    return ak_vec3_scale(a, 1.0f / sqrtf(l2));
}
/* a + (b - a) t; t outside [0, 1] extrapolates. */
static inline ak_vec3 ak_vec3_lerp(ak_vec3 a, ak_vec3 b, float t) {
    return ak_vec3_make(a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t, a.z + (b.z - a.z) * t);
}
/* Component-wise min and max; true when all three components are finite. */
static inline ak_vec3 ak_vec3_min(ak_vec3 a, ak_vec3 b) { return ak_vec3_make(ak_minf(a.x, b.x), ak_minf(a.y, b.y), ak_minf(a.z, b.z)); }
static inline ak_vec3 ak_vec3_max(ak_vec3 a, ak_vec3 b) { return ak_vec3_make(ak_maxf(a.x, b.x), ak_maxf(a.y, b.y), ak_maxf(a.z, b.z)); }
static inline bool ak_vec3_is_finite(ak_vec3 a) { return ak_finitef(a.x) && ak_finitef(a.y) && ak_finitef(a.z); }
/* A unit vector perpendicular to a (any one); a = 0 gives (1, 0, 0). */
static inline ak_vec3 ak_vec3_any_perpendicular(ak_vec3 a) {
    ak_vec3 other = fabsf(a.x) < 0.57735f ? ak_vec3_make(1, 0, 0) : ak_vec3_make(0, 1, 0);
    ak_vec3 p = ak_vec3_normalize(ak_vec3_cross(a, other));
    return ak_vec3_length_sq(p) > 0.0f ? p : ak_vec3_make(1, 0, 0);
}

/* vec2 and vec4 arithmetic; ak_vec2_cross is the z of the 3D cross product. */
static inline ak_vec2 ak_vec2_add(ak_vec2 a, ak_vec2 b) { return ak_vec2_make(a.x + b.x, a.y + b.y); }
static inline ak_vec2 ak_vec2_sub(ak_vec2 a, ak_vec2 b) { return ak_vec2_make(a.x - b.x, a.y - b.y); }
static inline ak_vec2 ak_vec2_scale(ak_vec2 a, float s) { return ak_vec2_make(a.x * s, a.y * s); }
static inline float ak_vec2_dot(ak_vec2 a, ak_vec2 b) { return a.x * b.x + a.y * b.y; }
static inline float ak_vec2_cross(ak_vec2 a, ak_vec2 b) { return a.x * b.y - a.y * b.x; }
static inline float ak_vec2_length(ak_vec2 a) { return sqrtf(a.x * a.x + a.y * a.y); }
static inline ak_vec4 ak_vec4_add(ak_vec4 a, ak_vec4 b) { return ak_vec4_make(a.x + b.x, a.y + b.y, a.z + b.z, a.w + b.w); }
static inline ak_vec4 ak_vec4_scale(ak_vec4 a, float s) { return ak_vec4_make(a.x * s, a.y * s, a.z * s, a.w * s); }
static inline float ak_vec4_dot(ak_vec4 a, ak_vec4 b) { return a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w; }

/* ---- quaternions -------------------------------------------------------------------- */

/* Basic quaternion algebra; ak_quat_conjugate (-x,-y,-z,w) inverts a unit quaternion. */
static inline ak_quat ak_quat_make(float x, float y, float z, float w) { ak_quat q = {x, y, z, w}; return q; }
static inline ak_quat ak_quat_identity(void) { return ak_quat_make(0.0f, 0.0f, 0.0f, 1.0f); }
static inline float ak_quat_dot(ak_quat a, ak_quat b) { return a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w; }
static inline float ak_quat_norm(ak_quat q) { return sqrtf(ak_quat_dot(q, q)); }
static inline ak_quat ak_quat_neg(ak_quat q) { return ak_quat_make(-q.x, -q.y, -q.z, -q.w); }
static inline ak_quat ak_quat_scale(ak_quat q, float s) { return ak_quat_make(q.x * s, q.y * s, q.z * s, q.w * s); }
static inline ak_quat ak_quat_add(ak_quat a, ak_quat b) { return ak_quat_make(a.x + b.x, a.y + b.y, a.z + b.z, a.w + b.w); }
static inline ak_quat ak_quat_conjugate(ak_quat q) { return ak_quat_make(-q.x, -q.y, -q.z, q.w); }
static inline bool ak_quat_is_finite(ak_quat q) { return ak_finitef(q.x) && ak_finitef(q.y) && ak_finitef(q.z) && ak_finitef(q.w); }

/* Unit quaternion; a zero, tiny or non-finite quaternion gives the identity. A finite one
 * whose squared norm overflows (components above ~1e19) is rescaled first. */
static inline ak_quat ak_quat_normalize(ak_quat q) {
    float n2 = ak_quat_dot(q, q);
    if (!(n2 > 1e-30f) || !ak_finitef(n2)) {
        if (!(n2 > 1e-30f) || !ak_quat_is_finite(q)) return ak_quat_identity();
        float m = fmaxf(fmaxf(fabsf(q.x), fabsf(q.y)), fmaxf(fabsf(q.z), fabsf(q.w)));
        q = ak_quat_make(q.x / m, q.y / m, q.z / m, q.w / m);
        n2 = ak_quat_dot(q, q);
    }
    return ak_quat_scale(q, 1.0f / sqrtf(n2));
}

/* Multiplicative inverse conj(q)/|q|^2; the zero quaternion gives the identity. */
static inline ak_quat ak_quat_inverse(ak_quat q) {
    float n2 = ak_quat_dot(q, q);
    if (!(n2 > 1e-30f) || !ak_finitef(n2)) return ak_quat_identity();
    return ak_quat_scale(ak_quat_conjugate(q), 1.0f / n2);
}

/* Hamilton product a * b: the rotation b followed by a. */
static inline ak_quat ak_quat_mul(ak_quat a, ak_quat b) {
    return ak_quat_make(a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
                        a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
                        a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w,
                        a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z);
}

/* Rotate v by unit quaternion q (q v q*), in the optimised form v + 2w(u x v) + 2u x (u x v). */
static inline ak_vec3 ak_quat_rotate(ak_quat q, ak_vec3 v) {
    ak_vec3 u = ak_vec3_make(q.x, q.y, q.z);
    ak_vec3 t = ak_vec3_scale(ak_vec3_cross(u, v), 2.0f);
    return ak_vec3_add(ak_vec3_add(v, ak_vec3_scale(t, q.w)), ak_vec3_cross(u, t));
}

/* Rotation of angle radians about axis (normalised here); a zero or non-finite axis or a
 * non-finite angle gives the identity. */
static inline ak_quat ak_quat_from_axis_angle(ak_vec3 axis, float angle) {
    ak_vec3 n = ak_vec3_normalize(axis);
    if (ak_vec3_length_sq(n) == 0.0f || !ak_finitef(angle)) return ak_quat_identity();
    float s = sinf(0.5f * angle);
    return ak_quat_make(n.x * s, n.y * s, n.z * s, cosf(0.5f * angle));
}

/* Axis and angle in [0, pi] of unit quaternion q; the identity gives axis (1,0,0), angle 0. */
static inline void ak_quat_to_axis_angle(ak_quat q, ak_vec3* out_axis, float* out_angle) {
    if (q.w < 0.0f) q = ak_quat_neg(q);
    ak_vec3 v = ak_vec3_make(q.x, q.y, q.z);
    float s = ak_vec3_length(v);
    if (s < 1e-12f) {
        *out_axis = ak_vec3_make(1.0f, 0.0f, 0.0f);
        *out_angle = 0.0f;
        return;
    }
    *out_axis = ak_vec3_scale(v, 1.0f / s);
    *out_angle = 2.0f * atan2f(s, q.w);
}

/* Angle in [0, pi] of the rotation taking a to b (both unit). */
static inline float ak_quat_angle_between(ak_quat a, ak_quat b) {
    float d = fabsf(ak_quat_dot(a, b));
    ak_quat diff = ak_quat_mul(ak_quat_conjugate(a), b);
    float s = sqrtf(diff.x * diff.x + diff.y * diff.y + diff.z * diff.z);
    return 2.0f * atan2f(s, d);
}

/* Normalised linear interpolation along the shorter arc (b is negated when a.b < 0). */
static inline ak_quat ak_quat_nlerp(ak_quat a, ak_quat b, float t) {
    if (ak_quat_dot(a, b) < 0.0f) b = ak_quat_neg(b);
    return ak_quat_normalize(ak_quat_make(a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t,
                                          a.z + (b.z - a.z) * t, a.w + (b.w - a.w) * t));
}

/* Spherical linear interpolation along the shorter arc, constant angular speed in t.
 * Nearly parallel inputs (angle below ~1e-3 rad) use normalised lerp, which agrees with the
 * exact formula to float precision there and avoids dividing by sin(theta) ~ 0. */
static inline ak_quat ak_quat_slerp(ak_quat a, ak_quat b, float t) {
    float d = ak_quat_dot(a, b);
    if (d < 0.0f) {
        b = ak_quat_neg(b);
        d = -d;
    }
    if (d > 0.9999995f) return ak_quat_nlerp(a, b, t);
    /* atan2 of the chord lengths is accurate for all angles, unlike acos near 1. The usual
     * 1/sin(theta) factor is left out: the normalisation below removes any common scale. */
    ak_quat diff = ak_quat_make(b.x - a.x * d, b.y - a.y * d, b.z - a.z * d, b.w - a.w * d);
    float s = ak_quat_norm(diff);
    float theta = atan2f(s, d);
    float wa = sinf((1.0f - t) * theta);
    float wb = sinf(t * theta);
    return ak_quat_normalize(ak_quat_make(wa * a.x + wb * b.x, wa * a.y + wb * b.y,
                                          wa * a.z + wb * b.z, wa * a.w + wb * b.w));
}

/* The shortest rotation taking direction from onto direction to (need not be unit).
 * Exactly opposite vectors give a 180 degree turn about ak_vec3_any_perpendicular(to); a
 * zero input gives the identity. Accurate to float precision for every pair, including
 * nearly opposite ones. */
static inline ak_quat ak_quat_from_to(ak_vec3 from, ak_vec3 to) {
    ak_vec3 a = ak_vec3_normalize(from), b = ak_vec3_normalize(to);
    if (ak_vec3_length_sq(a) == 0.0f || ak_vec3_length_sq(b) == 0.0f) return ak_quat_identity();
    float d = ak_vec3_dot(a, b);
    if (d >= 0.0f) {
        ak_vec3 c = ak_vec3_cross(a, b);
        return ak_quat_normalize(ak_quat_make(c.x, c.y, c.z, 1.0f + d));
    }
    /* Nearly opposite inputs make a x b and 1 + a.b cancel. Turn a onto -b first (well
     * conditioned), then half a turn about an axis n perpendicular to b. With n along a x b
     * both turns share one axis, so the product is exactly the shortest arc. */
    ak_vec3 c = ak_vec3_cross(a, ak_vec3_neg(b));
    ak_quat q1 = ak_quat_normalize(ak_quat_make(c.x, c.y, c.z, 1.0f - d));
    ak_vec3 n = ak_vec3_normalize(ak_vec3_madd(c, b, -ak_vec3_dot(b, c)));
    if (ak_vec3_length_sq(n) == 0.0f) n = ak_vec3_any_perpendicular(b);
    return ak_quat_mul(ak_quat_make(n.x, n.y, n.z, 0.0f), q1);
}

/* Quaternion exponential: exp(v, w) = e^w (v/|v| sin|v|, cos|v|). For a pure quaternion
 * (axis * angle/2, 0) it gives the unit rotation quaternion of that axis-angle. w is clamped
 * to 88 so the result stays finite; a non-finite input gives the identity. */
static inline ak_quat ak_quat_exp(ak_quat q) {
    if (!ak_quat_is_finite(q)) return ak_quat_identity();
    float th = sqrtf(q.x * q.x + q.y * q.y + q.z * q.z);
    if (!ak_finitef(th)) {
        /* |v| overflows float: angle and direction in double (sin and cos stay bounded). */
        double dth = sqrt((double)q.x * q.x + (double)q.y * q.y + (double)q.z * q.z);
        double e2 = exp((double)ak_minf(q.w, 88.0f)), k2 = e2 * sin(dth) / dth;
        return ak_quat_make((float)(k2 * q.x), (float)(k2 * q.y), (float)(k2 * q.z), (float)(e2 * cos(dth)));
    }
    float e = expf(ak_minf(q.w, 88.0f));
    /* sin(th)/th by its series below 1e-4, where the division loses digits. */
    float k = th < 1e-4f ? 1.0f - th * th * (1.0f / 6.0f) : sinf(th) / th;
    return ak_quat_make(e * k * q.x, e * k * q.y, e * k * q.z, e * cosf(th));
}

/* Quaternion logarithm: log(q) = (v/|v| atan2(|v|, w), ln|q|), the inverse of ak_quat_exp.
 * For a unit q of angle theta about n it is (n theta/2, 0), so 2 log(q).xyz is the rotation
 * vector. q = -1 gives (pi, 0, 0, 0); the zero or a non-finite quaternion gives (0,0,0,0). */
static inline ak_quat ak_quat_log(ak_quat q) {
    float n2 = ak_quat_dot(q, q);
    if (!(n2 > 1e-30f) || !ak_finitef(n2)) return ak_quat_make(0.0f, 0.0f, 0.0f, 0.0f);
    float s = sqrtf(q.x * q.x + q.y * q.y + q.z * q.z);
    float lw = 0.5f * logf(n2);
    if (!(s > 1e-30f)) {
        if (q.w > 0.0f) return ak_quat_make(0.0f, 0.0f, 0.0f, lw);
        return ak_quat_make(AK_PI, 0.0f, 0.0f, lw);
    }
    float k = atan2f(s, q.w) / s;
    return ak_quat_make(q.x * k, q.y * k, q.z * k, lw);
}

/* ---- mat3 --------------------------------------------------------------------------- */

/* The identity. */
static inline ak_mat3 ak_mat3_identity(void) {
    ak_mat3 r = {{1, 0, 0, 0, 1, 0, 0, 0, 1}};
    return r;
}
/* Element at row r, column c. */
static inline float ak_mat3_at(const ak_mat3* m, int r, int c) { return m->m[c * 3 + r]; }
/* Matrix with the given columns; ak_mat3_col reads column c (0..2). */
static inline ak_mat3 ak_mat3_from_cols(ak_vec3 c0, ak_vec3 c1, ak_vec3 c2) {
    ak_mat3 r = {{c0.x, c0.y, c0.z, c1.x, c1.y, c1.z, c2.x, c2.y, c2.z}};
    return r;
}
static inline ak_vec3 ak_mat3_col(ak_mat3 m, int c) { return ak_vec3_make(m.m[c * 3], m.m[c * 3 + 1], m.m[c * 3 + 2]); }
/* Product a * b (b applies first). */
static inline ak_mat3 ak_mat3_mul(ak_mat3 a, ak_mat3 b) {
    ak_mat3 r;
    for (int c = 0; c < 3; ++c)
        for (int row = 0; row < 3; ++row)
            r.m[c * 3 + row] = a.m[row] * b.m[c * 3] + a.m[3 + row] * b.m[c * 3 + 1] + a.m[6 + row] * b.m[c * 3 + 2];
    return r;
}
/* m * v (column vector). */
static inline ak_vec3 ak_mat3_mul_vec3(ak_mat3 m, ak_vec3 v) {
    return ak_vec3_make(m.m[0] * v.x + m.m[3] * v.y + m.m[6] * v.z,
                        m.m[1] * v.x + m.m[4] * v.y + m.m[7] * v.z,
                        m.m[2] * v.x + m.m[5] * v.y + m.m[8] * v.z);
}
/* Transpose; the inverse of a rotation. */
static inline ak_mat3 ak_mat3_transpose(ak_mat3 m) {
    ak_mat3 r = {{m.m[0], m.m[3], m.m[6], m.m[1], m.m[4], m.m[7], m.m[2], m.m[5], m.m[8]}};
    return r;
}
/* Determinant: negative for reflections, ~0 for singular matrices. */
static inline float ak_mat3_determinant(ak_mat3 m) {
    return m.m[0] * (m.m[4] * m.m[8] - m.m[7] * m.m[5]) - m.m[3] * (m.m[1] * m.m[8] - m.m[7] * m.m[2]) +
           m.m[6] * (m.m[1] * m.m[5] - m.m[4] * m.m[2]);
}
/* Inverse; a singular matrix (|det| below 1e-30) or a non-finite det gives the identity. */
static inline ak_mat3 ak_mat3_inverse(ak_mat3 m) {
    ak_vec3 c0 = ak_mat3_col(m, 0), c1 = ak_mat3_col(m, 1), c2 = ak_mat3_col(m, 2);
    ak_vec3 r0 = ak_vec3_cross(c1, c2), r1 = ak_vec3_cross(c2, c0), r2 = ak_vec3_cross(c0, c1);
    float det = ak_vec3_dot(c0, r0);
    if (!(fabsf(det) > 1e-30f) || !ak_finitef(det)) return ak_mat3_identity();
    float inv = 1.0f / det;
    ak_mat3 r = {{r0.x * inv, r1.x * inv, r2.x * inv, r0.y * inv, r1.y * inv, r2.y * inv,
                  r0.z * inv, r1.z * inv, r2.z * inv}};
    return r;
}

/* Rotation matrix of angle radians about axis (normalised here), by Rodrigues' formula
 * R = cos(a) I + sin(a) [n]x + (1 - cos(a)) n n^T. A zero or non-finite axis or a
 * non-finite angle gives the identity. */
static inline ak_mat3 ak_mat3_from_axis_angle(ak_vec3 axis, float angle) {
    ak_vec3 n = ak_vec3_normalize(axis);
    if (ak_vec3_length_sq(n) == 0.0f || !ak_finitef(angle)) return ak_mat3_identity();
    float c = cosf(angle), s = sinf(angle);
    float h = sinf(0.5f * angle), t = 2.0f * h * h; /* 1 - cos(a) without cancellation */
    ak_mat3 r = {{c + n.x * n.x * t, n.x * n.y * t + n.z * s, n.x * n.z * t - n.y * s,
                  n.x * n.y * t - n.z * s, c + n.y * n.y * t, n.y * n.z * t + n.x * s,
                  n.x * n.z * t + n.y * s, n.y * n.z * t - n.x * s, c + n.z * n.z * t}};
    return r;
}
/* diag(d.x, d.y, d.z). */
static inline ak_mat3 ak_mat3_diagonal(ak_vec3 d) {
    ak_mat3 r = {{d.x, 0, 0, 0, d.y, 0, 0, 0, d.z}};
    return r;
}
/* Element-wise a + b. */
static inline ak_mat3 ak_mat3_add(ak_mat3 a, ak_mat3 b) {
    for (int i = 0; i < 9; ++i) a.m[i] += b.m[i];
    return a;
}
/* Every element times s. */
static inline ak_mat3 ak_mat3_scale(ak_mat3 a, float s) {
    for (int i = 0; i < 9; ++i) a.m[i] *= s;
    return a;
}
/* Element-wise a + (b - a) t. */
static inline ak_mat3 ak_mat3_lerp(ak_mat3 a, ak_mat3 b, float t) {
    for (int i = 0; i < 9; ++i) a.m[i] += (b.m[i] - a.m[i]) * t;
    return a;
}
/* True when every element is finite. */
static inline bool ak_mat3_is_finite(ak_mat3 m) {
    for (int i = 0; i < 9; ++i)
        if (!ak_finitef(m.m[i])) return false;
    return true;
}

/* Rotation matrix of unit quaternion q. */
static inline ak_mat3 ak_mat3_from_quat(ak_quat q) {
    float xx = q.x * q.x, yy = q.y * q.y, zz = q.z * q.z;
    float xy = q.x * q.y, xz = q.x * q.z, yz = q.y * q.z;
    float wx = q.w * q.x, wy = q.w * q.y, wz = q.w * q.z;
    ak_mat3 r = {{1 - 2 * (yy + zz), 2 * (xy + wz), 2 * (xz - wy),
                  2 * (xy - wz), 1 - 2 * (xx + zz), 2 * (yz + wx),
                  2 * (xz + wy), 2 * (yz - wx), 1 - 2 * (xx + yy)}};
    return r;
}

/* Unit quaternion of a rotation matrix, by Shepperd's method: the largest of w, x, y, z is
 * recovered first, so the result is accurate for every rotation including 180 degrees.
 * The result has w >= 0. A matrix that is not a rotation gives the quaternion of its
 * nearest rotation only approximately: orthonormalise first (ak_mat3_polar). */
static inline ak_quat ak_quat_from_mat3(ak_mat3 m) {
    float m00 = m.m[0], m11 = m.m[4], m22 = m.m[8];
    float tr = m00 + m11 + m22;
    ak_quat q;
    if (tr >= m00 && tr >= m11 && tr >= m22) {
        float s = 2.0f * sqrtf(ak_maxf(1.0f + tr, 1e-30f));
        q = ak_quat_make((m.m[5] - m.m[7]) / s, (m.m[6] - m.m[2]) / s, (m.m[1] - m.m[3]) / s, 0.25f * s);
    } else if (m00 >= m11 && m00 >= m22) {
        float s = 2.0f * sqrtf(ak_maxf(1.0f + m00 - m11 - m22, 1e-30f));
        q = ak_quat_make(0.25f * s, (m.m[3] + m.m[1]) / s, (m.m[6] + m.m[2]) / s, (m.m[5] - m.m[7]) / s);
    } else if (m11 >= m22) {
        float s = 2.0f * sqrtf(ak_maxf(1.0f + m11 - m00 - m22, 1e-30f));
        q = ak_quat_make((m.m[3] + m.m[1]) / s, 0.25f * s, (m.m[7] + m.m[5]) / s, (m.m[6] - m.m[2]) / s);
    } else {
        float s = 2.0f * sqrtf(ak_maxf(1.0f + m22 - m00 - m11, 1e-30f));
        q = ak_quat_make((m.m[6] + m.m[2]) / s, (m.m[7] + m.m[5]) / s, 0.25f * s, (m.m[1] - m.m[3]) / s);
    }
    if (q.w < 0.0f) q = ak_quat_neg(q);
    return ak_quat_normalize(q);
}

/* ---- mat4 --------------------------------------------------------------------------- */

/* The identity. */
static inline ak_mat4 ak_mat4_identity(void) {
    ak_mat4 r = {{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}};
    return r;
}
/* Element at row r, column c. */
static inline float ak_mat4_at(const ak_mat4* m, int r, int c) { return m->m[c * 4 + r]; }
/* Product a * b (b applies first). */
static inline ak_mat4 ak_mat4_mul(ak_mat4 a, ak_mat4 b) {
    ak_mat4 r;
    for (int c = 0; c < 4; ++c)
        for (int row = 0; row < 4; ++row)
            r.m[c * 4 + row] = a.m[row] * b.m[c * 4] + a.m[4 + row] * b.m[c * 4 + 1] +
                               a.m[8 + row] * b.m[c * 4 + 2] + a.m[12 + row] * b.m[c * 4 + 3];
    return r;
}
/* m * v (column vector). */
static inline ak_vec4 ak_mat4_mul_vec4(ak_mat4 m, ak_vec4 v) {
    return ak_vec4_make(m.m[0] * v.x + m.m[4] * v.y + m.m[8] * v.z + m.m[12] * v.w,
                        m.m[1] * v.x + m.m[5] * v.y + m.m[9] * v.z + m.m[13] * v.w,
                        m.m[2] * v.x + m.m[6] * v.y + m.m[10] * v.z + m.m[14] * v.w,
                        m.m[3] * v.x + m.m[7] * v.y + m.m[11] * v.z + m.m[15] * v.w);
}
/* M * (p, 1), ignoring the projective row (affine M). */
static inline ak_vec3 ak_mat4_transform_point(ak_mat4 m, ak_vec3 p) {
    return ak_vec3_make(m.m[0] * p.x + m.m[4] * p.y + m.m[8] * p.z + m.m[12],
                        m.m[1] * p.x + m.m[5] * p.y + m.m[9] * p.z + m.m[13],
                        m.m[2] * p.x + m.m[6] * p.y + m.m[10] * p.z + m.m[14]);
}
/* M * (v, 0). */
static inline ak_vec3 ak_mat4_transform_vector(ak_mat4 m, ak_vec3 v) {
    return ak_vec3_make(m.m[0] * v.x + m.m[4] * v.y + m.m[8] * v.z,
                        m.m[1] * v.x + m.m[5] * v.y + m.m[9] * v.z,
                        m.m[2] * v.x + m.m[6] * v.y + m.m[10] * v.z);
}
/* M * (p, 1) followed by the divide by w; w = 0 gives (0,0,0). */
static inline ak_vec3 ak_mat4_project_point(ak_mat4 m, ak_vec3 p) {
    ak_vec4 r = ak_mat4_mul_vec4(m, ak_vec4_make(p.x, p.y, p.z, 1.0f));
    if (r.w == 0.0f) return ak_vec3_zero();
    return ak_vec3_make(r.x / r.w, r.y / r.w, r.z / r.w);
}
/* Transpose. */
static inline ak_mat4 ak_mat4_transpose(ak_mat4 m) {
    ak_mat4 r;
    for (int c = 0; c < 4; ++c)
        for (int row = 0; row < 4; ++row) r.m[c * 4 + row] = m.m[row * 4 + c];
    return r;
}
/* Translation by t. */
static inline ak_mat4 ak_mat4_translation(ak_vec3 t) {
    ak_mat4 r = ak_mat4_identity();
    r.m[12] = t.x; r.m[13] = t.y; r.m[14] = t.z;
    return r;
}
/* Axis-aligned scale by s. */
static inline ak_mat4 ak_mat4_scaling(ak_vec3 s) {
    ak_mat4 r = ak_mat4_identity();
    r.m[0] = s.x; r.m[5] = s.y; r.m[10] = s.z;
    return r;
}
/* Upper-left 3x3 block. */
static inline ak_mat3 ak_mat4_to_mat3(ak_mat4 m) {
    ak_mat3 r = {{m.m[0], m.m[1], m.m[2], m.m[4], m.m[5], m.m[6], m.m[8], m.m[9], m.m[10]}};
    return r;
}
/* Affine matrix with linear part l and translation t. */
static inline ak_mat4 ak_mat4_from_mat3(ak_mat3 l, ak_vec3 t) {
    ak_mat4 r = {{l.m[0], l.m[1], l.m[2], 0, l.m[3], l.m[4], l.m[5], 0, l.m[6], l.m[7], l.m[8], 0, t.x, t.y, t.z, 1}};
    return r;
}
/* Translation column (m[12], m[13], m[14]); ak_mat4_from_quat is the rotation matrix of unit q. */
static inline ak_vec3 ak_mat4_get_translation(ak_mat4 m) { return ak_vec3_make(m.m[12], m.m[13], m.m[14]); }
static inline ak_mat4 ak_mat4_from_quat(ak_quat q) { return ak_mat4_from_mat3(ak_mat3_from_quat(q), ak_vec3_zero()); }

/* General 4x4 inverse (cofactors). A singular matrix (|det| below 1e-30) or a non-finite
 * determinant gives the identity. */
AK_API ak_mat4 ak_mat4_inverse(ak_mat4 m);
/* Inverse of an affine matrix (bottom row 0,0,0,1): cheaper and more accurate than the
 * general inverse. A singular linear part gives the identity. */
AK_API ak_mat4 ak_mat4_inverse_affine(ak_mat4 m);
/* Transpose of the inverse of the upper 3x3 block: transforms normals. Singular -> identity. */
AK_API ak_mat3 ak_mat4_normal_matrix(ak_mat4 m);
/* Determinant of the full 4x4 matrix (0 for a singular matrix). */
AK_API float ak_mat4_determinant(ak_mat4 m);
/* True when every element is finite. */
AK_API bool ak_mat4_is_finite(const ak_mat4* m);

/* OpenGL perspective projection: f = 1/tan(fovy/2), C = (far+near)/(near-far),
 * D = 2 far near/(near-far); maps view-space -Z into clip space with NDC z in [-1, 1].
 * fovy in radians, aspect = width/height. Non-positive or non-finite inputs are replaced
 * by fovy = 60 degrees, aspect = 1, near = 0.1, far = near * 1000. */
AK_API ak_mat4 ak_mat4_perspective(float fovy, float aspect, float near_z, float far_z);
/* OpenGL orthographic projection of the box [l,r]x[b,t]x[-near,-far] to NDC [-1,1]^3.
 * A zero-width range is widened to 1 so the result stays finite; a non-finite argument
 * gives the identity. */
AK_API ak_mat4 ak_mat4_orthographic(float left, float right, float bottom, float top, float near_z, float far_z);
/* View matrix of a camera at eye looking at target, up roughly +Y: camera looks down -Z.
 * eye == target gives a translation by -eye; up parallel to the view picks another up;
 * a non-finite eye, target or up gives the identity. */
AK_API ak_mat4 ak_mat4_look_at(ak_vec3 eye, ak_vec3 target, ak_vec3 up);

/* ---- Euler angles ------------------------------------------------------------------ */

/* Axis sequence of Euler angles. The letters name the axes in the order the angles are
 * stored: angles.x is about the first letter's axis, angles.y the second, angles.z the
 * third (so for AK_EULER_ZYX, angles.x is the angle about Z). The first six are
 * Tait-Bryan (three distinct axes), the last six proper Euler (first axis repeated). */
typedef enum ak_euler_order {
    AK_EULER_XYZ = 0, /* the default */
    AK_EULER_XZY,
    AK_EULER_YXZ,
    AK_EULER_YZX,
    AK_EULER_ZXY,
    AK_EULER_ZYX,
    AK_EULER_XYX,
    AK_EULER_XZX,
    AK_EULER_YXY,
    AK_EULER_YZY,
    AK_EULER_ZXZ,
    AK_EULER_ZYZ,
    AK_EULER_ORDER_COUNT
} ak_euler_order;

/* Which axes the sequence turns about.
 * INTRINSIC: each turn is about the axis as moved by the turns before it (body axes, as in
 *   BVH channel lists): order ABC gives R = R_A(angles.x) * R_B(angles.y) * R_C(angles.z).
 * EXTRINSIC: each turn is about the fixed parent axis: order ABC gives
 *   R = R_C(angles.z) * R_B(angles.y) * R_A(angles.x) (A is applied to the vector first).
 * Intrinsic ABC with angles (a, b, c) is the same rotation as extrinsic CBA with (c, b, a). */
typedef enum ak_euler_frame {
    AK_EULER_INTRINSIC = 0, /* the default */
    AK_EULER_EXTRINSIC
} ak_euler_frame;

/* Rotation quaternion of Euler angles (radians). An out-of-range order or frame is read as
 * the default (XYZ, intrinsic); a non-finite angle gives the identity. */
AK_API ak_quat ak_quat_from_euler(ak_vec3 angles, ak_euler_order order, ak_euler_frame frame);
/* Rotation matrix of Euler angles (radians); same conventions and fallbacks as
 * ak_quat_from_euler. */
AK_API ak_mat3 ak_mat3_from_euler(ak_vec3 angles, ak_euler_order order, ak_euler_frame frame);
/* Euler angles of rotation matrix m (a rotation; orthonormalise first otherwise), computed
 * in double precision. Ranges: first and third angle in [-pi, pi]; middle angle in
 * [-pi/2, pi/2] for Tait-Bryan orders and [0, pi] for proper Euler orders.
 * Gimbal lock (middle angle at +-pi/2 for Tait-Bryan, 0 or pi for proper Euler, detected
 * when its cosine resp. sine is below 1e-6): only a combination of the outer angles is
 * determined, so angles.z is set to 0 and angles.x carries the whole turn, in both frames.
 * The result always rebuilds m through ak_mat3_from_euler. Non-finite m gives (0, 0, 0). */
AK_API ak_vec3 ak_mat3_to_euler(ak_mat3 m, ak_euler_order order, ak_euler_frame frame);
/* Euler angles of quaternion q (normalised here); see ak_mat3_to_euler. The zero or a
 * non-finite quaternion gives (0, 0, 0). */
AK_API ak_vec3 ak_quat_to_euler(ak_quat q, ak_euler_order order, ak_euler_frame frame);

/* ---- 3x3 decompositions ------------------------------------------------------------ */

/* Signed singular value decomposition m = U * diag(sigma) * V^T. */
typedef struct ak_svd3 {
    ak_mat3 u;     /* proper rotation (det +1) */
    ak_vec3 sigma; /* sigma.x >= sigma.y >= |sigma.z|; sigma.z < 0 exactly when det(m) < 0 */
    ak_mat3 v;     /* proper rotation (det +1) */
} ak_svd3;

/* SVD of a 3x3 matrix by one-sided Jacobi rotations in double precision. U and V are
 * rotations, so the sign of det(m) moves onto the smallest singular value. For rank-deficient
 * m the missing columns of U are completed to a right-handed frame. The zero or a non-finite
 * matrix gives U = V = identity, sigma = 0. */
AK_API ak_svd3 ak_mat3_svd(ak_mat3 m);

/* Polar decomposition m = R * D. */
typedef struct ak_polar {
    ak_mat3 rotation; /* R: proper rotation, det +1 */
    ak_mat3 stretch;  /* D = R^T m: symmetric; positive semi-definite when det(m) >= 0 */
    int iterations;   /* iterations of the averaging scheme; 0 when the SVD path ran */
    bool used_svd;    /* true when m was reflected, near-singular or did not converge */
} ak_polar;

/* Polar decomposition m = R D with R the rotation nearest to m and D symmetric.
 * Well-conditioned m with det > 0 runs the averaging scheme R_{i+1} = (g R_i + R_i^-T / g)/2
 * in double precision (g is Higham's Frobenius-norm scaling while far from convergence,
 * then 1: the plain scheme), until the change is below 1e-12 relative or 40 iterations.
 * Otherwise (det <= 0, condition |m|_F |m^-1|_F above 1e5, or no convergence) it uses the
 * SVD (ak_mat3_svd):
 * R = U V^T and D = V diag(sigma) V^T. Results for the special cases:
 *   - reflection (det < 0): R stays a proper rotation and D gets one negative eigenvalue,
 *     -sigma_min, along the direction of the smallest singular value;
 *   - rank-deficient m: D has a zero eigenvalue along the null direction and R maps it to
 *     the right-handed completion of the image (R D = m still holds);
 *   - the zero matrix: R = identity, D = 0; non-finite m: R = D = identity. */
AK_API ak_polar ak_mat3_polar(ak_mat3 m);

/* ---- transforms --------------------------------------------------------------------- */

/* Translation 0, rotation identity, scale 1. */
static inline ak_transform ak_transform_identity(void) {
    ak_transform t = {{0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f, 1.0f}, {1.0f, 1.0f, 1.0f}};
    return t;
}
/* Transform from its three parts (no normalisation). */
static inline ak_transform ak_transform_make(ak_vec3 translation, ak_quat rotation, ak_vec3 scale) {
    ak_transform t = {translation, rotation, scale};
    return t;
}
/* T * R * S as a matrix. */
static inline ak_mat4 ak_transform_to_mat4(ak_transform t) {
    ak_mat3 r = ak_mat3_from_quat(t.rotation);
    for (int i = 0; i < 3; ++i) {
        r.m[i] *= t.scale.x;
        r.m[3 + i] *= t.scale.y;
        r.m[6 + i] *= t.scale.z;
    }
    return ak_mat4_from_mat3(r, t.translation);
}
/* T R S p: scale, rotate, then translate point p. */
static inline ak_vec3 ak_transform_point(ak_transform t, ak_vec3 p) {
    return ak_vec3_add(ak_quat_rotate(t.rotation, ak_vec3_mul(t.scale, p)), t.translation);
}
/* parent * child, exact when scales are uniform; with non-uniform parent scale and a rotated
 * child the true product has shear, which a TRS cannot hold: use matrices then. */
static inline ak_transform ak_transform_mul(ak_transform parent, ak_transform child) {
    ak_transform r;
    r.rotation = ak_quat_normalize(ak_quat_mul(parent.rotation, child.rotation));
    r.scale = ak_vec3_mul(parent.scale, child.scale);
    r.translation = ak_transform_point(parent, child.translation);
    return r;
}
/* Inverse, exact for uniform scale (see ak_transform_mul); zero scale components give 0. */
static inline ak_transform ak_transform_inverse(ak_transform t) {
    ak_transform r;
    r.rotation = ak_quat_conjugate(ak_quat_normalize(t.rotation));
    r.scale = ak_vec3_make(t.scale.x != 0.0f ? 1.0f / t.scale.x : 0.0f, t.scale.y != 0.0f ? 1.0f / t.scale.y : 0.0f,
                           t.scale.z != 0.0f ? 1.0f / t.scale.z : 0.0f);
    r.translation = ak_vec3_mul(r.scale, ak_quat_rotate(r.rotation, ak_vec3_neg(t.translation)));
    return r;
}
/* True when every component is finite. */
static inline bool ak_transform_is_finite(ak_transform t) {
    return ak_vec3_is_finite(t.translation) && ak_quat_is_finite(t.rotation) && ak_vec3_is_finite(t.scale);
}

/* ---- dual quaternions --------------------------------------------------------------
 * Layout: real is the rotation quaternion r, dual is d = 0.5 * (t, 0) * r, t the
 * translation. A unit dual quaternion has |r| = 1 and r.d = 0; it applies the rotation
 * first, then the translation (like ak_transform without scale). ak_dualquat_mul(a, b)
 * applies b first, then a. Functions below expect unit input unless they say otherwise. */

/* No rotation, no translation: real (0,0,0,1), dual 0. */
static inline ak_dualquat ak_dualquat_identity(void) {
    ak_dualquat r = {{0.0f, 0.0f, 0.0f, 1.0f}, {0.0f, 0.0f, 0.0f, 0.0f}};
    return r;
}
/* Rigid transform "rotate by rotation (normalised here), then translate". */
static inline ak_dualquat ak_dualquat_from_rigid(ak_quat rotation, ak_vec3 translation) {
    ak_dualquat r;
    r.real = ak_quat_normalize(rotation);
    r.dual = ak_quat_scale(ak_quat_mul(ak_quat_make(translation.x, translation.y, translation.z, 0.0f), r.real), 0.5f);
    return r;
}
/* Translation part t = 2 d r* / |r|^2 (exact also for non-unit dq); zero real part gives 0. */
static inline ak_vec3 ak_dualquat_get_translation(ak_dualquat dq) {
    float n2 = ak_quat_dot(dq.real, dq.real);
    if (!(n2 > 1e-30f) || !ak_finitef(n2)) return ak_vec3_zero();
    ak_quat t = ak_quat_mul(dq.dual, ak_quat_conjugate(dq.real));
    float k = 2.0f / n2;
    return ak_vec3_make(t.x * k, t.y * k, t.z * k);
}
/* Rotation part, normalised (zero real part gives the identity). */
static inline ak_quat ak_dualquat_get_rotation(ak_dualquat dq) { return ak_quat_normalize(dq.real); }
/* Rotation and translation of t; its scale is ignored. */
static inline ak_dualquat ak_dualquat_from_transform(ak_transform t) {
    return ak_dualquat_from_rigid(t.rotation, t.translation);
}
/* The rigid transform of dq, with scale (1, 1, 1). */
static inline ak_transform ak_dualquat_to_transform(ak_dualquat dq) {
    return ak_transform_make(ak_dualquat_get_translation(dq), ak_dualquat_get_rotation(dq), ak_vec3_one());
}
/* Product a * b = (a.r b.r, a.r b.d + a.d b.r): b first, then a. */
static inline ak_dualquat ak_dualquat_mul(ak_dualquat a, ak_dualquat b) {
    ak_dualquat r;
    r.real = ak_quat_mul(a.real, b.real);
    r.dual = ak_quat_add(ak_quat_mul(a.real, b.dual), ak_quat_mul(a.dual, b.real));
    return r;
}
/* Quaternion conjugate of both parts (r*, d*): the inverse of a unit dual quaternion. */
static inline ak_dualquat ak_dualquat_conjugate(ak_dualquat dq) {
    ak_dualquat r = {ak_quat_conjugate(dq.real), ak_quat_conjugate(dq.dual)};
    return r;
}
/* Dual-number conjugate (r, -d). */
static inline ak_dualquat ak_dualquat_dual_conjugate(ak_dualquat dq) {
    ak_dualquat r = {dq.real, ak_quat_neg(dq.dual)};
    return r;
}
/* Both conjugates at once (r*, -d*): a point p maps to dq (1 + eps p) this. */
static inline ak_dualquat ak_dualquat_full_conjugate(ak_dualquat dq) {
    ak_dualquat r = {ak_quat_conjugate(dq.real), ak_quat_neg(ak_quat_conjugate(dq.dual))};
    return r;
}
/* Unit dual quaternion: both parts divided by |r|, then the part of d along r removed so
 * that r.d = 0. A zero or non-finite real part gives the identity. */
static inline ak_dualquat ak_dualquat_normalize(ak_dualquat dq) {
    float n2 = ak_quat_dot(dq.real, dq.real);
    if (!(n2 > 1e-30f) || !ak_finitef(n2) || !ak_quat_is_finite(dq.dual)) return ak_dualquat_identity();
    float inv = 1.0f / sqrtf(n2);
    ak_dualquat r;
    r.real = ak_quat_scale(dq.real, inv);
    r.dual = ak_quat_scale(dq.dual, inv);
    r.dual = ak_quat_add(r.dual, ak_quat_scale(r.real, -ak_quat_dot(r.real, r.dual)));
    return r;
}
/* Rotate then translate point p. */
static inline ak_vec3 ak_dualquat_transform_point(ak_dualquat dq, ak_vec3 p) {
    ak_quat t = ak_quat_mul(dq.dual, ak_quat_conjugate(dq.real));
    return ak_vec3_add(ak_quat_rotate(dq.real, p), ak_vec3_make(2.0f * t.x, 2.0f * t.y, 2.0f * t.z));
}
/* Rotate direction v (no translation). */
static inline ak_vec3 ak_dualquat_transform_vector(ak_dualquat dq, ak_vec3 v) { return ak_quat_rotate(dq.real, v); }
/* Affine matrix of a unit dual quaternion (rotation part from the normalised real part). */
static inline ak_mat4 ak_dualquat_to_mat4(ak_dualquat dq) {
    return ak_mat4_from_mat3(ak_mat3_from_quat(ak_quat_normalize(dq.real)), ak_dualquat_get_translation(dq));
}

/* Dual quaternion linear blend sum(w_i dq_i) / |sum(w_i r_i)|, for skinning. Every dq_i is
 * first moved into the hemisphere of the one with the largest weight (dq and -dq are the
 * same transform), then the sum is normalised with ak_dualquat_normalize. Uses the first
 * min(dqs.count, weights.count) pairs; weights need not sum to 1. An empty input, zero total
 * weight or a sum whose real part vanishes gives the identity. */
AK_API ak_dualquat ak_dualquat_blend(ak_dualquat_cspan dqs, ak_f32_cspan weights);

/* ---- affine interpolation ------------------------------------------------------------ */

/* Interpolates two affine matrices (the bottom rows are ignored and the result's is
 * 0,0,0,1): each linear part is split by ak_mat3_polar into R D, R is SLERPed (shorter arc),
 * D and the translation are lerped, and the result is R(t) D(t) plus the translation.
 * t = 0 and t = 1 give a and b (to float precision); reflections interpolate their D as
 * documented in ak_mat3_polar. Non-finite input gives the identity. */
AK_API ak_mat4 ak_mat4_interpolate_affine(ak_mat4 a, ak_mat4 b, float t);

/* ---- arrays ---------------------------------------------------------------------------
 * Compiled in src/math, with SSE2 code when the compiler targets it (scalar with AK_NO_SIMD)
 * and the same results to float rounding. Pointers need no alignment. Each returns
 * AK_ERR_NULL_ARG when a span with a non-zero count has a NULL pointer, and
 * AK_ERR_SPAN_SMALL when an input or output is shorter than the count the function works
 * on (named per function); nothing is written then. An output may be the same array as an
 * input (exactly the same, not partly overlapping). Counts larger than needed are fine. */

/* out[i] = ak_quat_normalize(q[i]) for i < q.count (needs out.count >= q.count); zero,
 * infinite or NaN quaternions give the identity. */
AK_API ak_result ak_quat_normalize_array(ak_quat_cspan q, ak_quat_span out);
/* out[i] = a[i] * b[i] for i < a.count (needs b.count, out.count >= a.count). */
AK_API ak_result ak_quat_mul_array(ak_quat_cspan a, ak_quat_cspan b, ak_quat_span out);
/* out[i] = ak_quat_rotate(q[i], v[i]) for i < v.count (needs out.count >= v.count; q unit).
 * q.count is at least v.count, or exactly 1 to rotate every vector by q[0]. */
AK_API ak_result ak_quat_rotate_array(ak_quat_cspan q, ak_vec3_cspan v, ak_vec3_span out);
/* out[i] = a[i] * b[i] for i < b.count (needs out.count >= b.count). a.count is at least
 * b.count, or exactly 1 to multiply every b[i] by a[0] (out may then also hold a[0]). */
AK_API ak_result ak_mat4_mul_array(ak_mat4_cspan a, ak_mat4_cspan b, ak_mat4_span out);

#ifdef __cplusplus
}
#endif
#endif /* ANIMKIT_MATH_H */
