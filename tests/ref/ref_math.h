/* Double-precision reference math for the tests. Written independently of src/math and
 * include/animkit/math.h (different formulations on purpose: quaternion products in
 * scalar/vector form, rotation matrices by conjugating basis vectors or by Rodrigues' matrix
 * series, inverses by Gauss-Jordan elimination, eigenvalues of symmetric 3x3 matrices by the
 * trigonometric closed form), so that agreement is evidence and not a tautology.
 * Matrices here are [row][column]. */
#ifndef ANIMKIT_REF_MATH_H
#define ANIMKIT_REF_MATH_H

#include <math.h>
#include <string.h>

#define REF_PI 3.14159265358979323846

typedef struct ref_v3 { double x, y, z; } ref_v3;
typedef struct ref_q { double x, y, z, w; } ref_q;
typedef struct ref_m3 { double m[3][3]; } ref_m3;
typedef struct ref_m4 { double m[4][4]; } ref_m4;

static inline ref_v3 ref_v3_make(double x, double y, double z) { ref_v3 r = {x, y, z}; return r; }
static inline double ref_v3_dot(ref_v3 a, ref_v3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline ref_v3 ref_v3_cross(ref_v3 a, ref_v3 b) {
    return ref_v3_make(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline ref_v3 ref_v3_scale(ref_v3 a, double s) { return ref_v3_make(a.x * s, a.y * s, a.z * s); }
static inline ref_v3 ref_v3_add(ref_v3 a, ref_v3 b) { return ref_v3_make(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline double ref_v3_len(ref_v3 a) { return sqrt(ref_v3_dot(a, a)); }

/* Hamilton product in scalar/vector form: (a.w b.v + b.w a.v + a.v x b.v, a.w b.w - a.v.b.v). */
static inline ref_q ref_q_mul(ref_q a, ref_q b) {
    ref_v3 av = {a.x, a.y, a.z}, bv = {b.x, b.y, b.z};
    ref_v3 v = ref_v3_add(ref_v3_add(ref_v3_scale(bv, a.w), ref_v3_scale(av, b.w)), ref_v3_cross(av, bv));
    ref_q r = {v.x, v.y, v.z, a.w * b.w - ref_v3_dot(av, bv)};
    return r;
}
static inline ref_q ref_q_conj(ref_q a) { ref_q r = {-a.x, -a.y, -a.z, a.w}; return r; }
static inline double ref_q_dot(ref_q a, ref_q b) { return a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w; }
static inline ref_q ref_q_normalize(ref_q a) {
    double n = sqrt(ref_q_dot(a, a));
    ref_q r = {a.x / n, a.y / n, a.z / n, a.w / n};
    return r;
}
/* Rotate v by unit q as the sandwich q (v, 0) q*. */
static inline ref_v3 ref_q_rotate(ref_q q, ref_v3 v) {
    ref_q p = {v.x, v.y, v.z, 0.0};
    ref_q r = ref_q_mul(ref_q_mul(q, p), ref_q_conj(q));
    return ref_v3_make(r.x, r.y, r.z);
}
/* Rotation matrix of unit q: its columns are the rotated basis vectors. */
static inline ref_m3 ref_m3_from_q(ref_q q) {
    ref_m3 r;
    for (int c = 0; c < 3; ++c) {
        ref_v3 e = {c == 0, c == 1, c == 2};
        ref_v3 v = ref_q_rotate(q, e);
        r.m[0][c] = v.x, r.m[1][c] = v.y, r.m[2][c] = v.z;
    }
    return r;
}
/* Unit quaternion of an axis-angle (axis normalised here). */
static inline ref_q ref_q_axis_angle(ref_v3 axis, double angle) {
    ref_v3 n = ref_v3_scale(axis, 1.0 / ref_v3_len(axis));
    double s = sin(angle / 2);
    ref_q r = {n.x * s, n.y * s, n.z * s, cos(angle / 2)};
    return r;
}
/* Rotation angle in [0, pi] between the rotations of unit quaternions a and b. */
static inline double ref_q_angle(ref_q a, ref_q b) {
    ref_q d = ref_q_mul(ref_q_conj(a), b);
    return 2.0 * atan2(sqrt(d.x * d.x + d.y * d.y + d.z * d.z), fabs(d.w));
}

static inline ref_m3 ref_m3_identity(void) {
    ref_m3 r = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
    return r;
}
static inline ref_m3 ref_m3_mul(ref_m3 a, ref_m3 b) {
    ref_m3 r;
    memset(&r, 0, sizeof r);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k) r.m[i][j] += a.m[i][k] * b.m[k][j];
    return r;
}
static inline ref_m3 ref_m3_transpose(ref_m3 a) {
    ref_m3 r;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) r.m[i][j] = a.m[j][i];
    return r;
}
static inline ref_v3 ref_m3_apply(ref_m3 a, ref_v3 v) {
    return ref_v3_make(a.m[0][0] * v.x + a.m[0][1] * v.y + a.m[0][2] * v.z,
                       a.m[1][0] * v.x + a.m[1][1] * v.y + a.m[1][2] * v.z,
                       a.m[2][0] * v.x + a.m[2][1] * v.y + a.m[2][2] * v.z);
}
/* Determinant by the rule of Sarrus. */
static inline double ref_m3_det(ref_m3 a) {
    double(*m)[3] = a.m;
    return m[0][0] * m[1][1] * m[2][2] + m[0][1] * m[1][2] * m[2][0] + m[0][2] * m[1][0] * m[2][1] -
           m[0][2] * m[1][1] * m[2][0] - m[0][0] * m[1][2] * m[2][1] - m[0][1] * m[1][0] * m[2][2];
}
/* Rodrigues as R = I + sin(a) K + (1 - cos(a)) K^2, K the cross-product matrix of the unit axis. */
static inline ref_m3 ref_m3_axis_angle(ref_v3 axis, double angle) {
    ref_v3 n = ref_v3_scale(axis, 1.0 / ref_v3_len(axis));
    ref_m3 k = {{{0, -n.z, n.y}, {n.z, 0, -n.x}, {-n.y, n.x, 0}}};
    ref_m3 k2 = ref_m3_mul(k, k), r = ref_m3_identity();
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) r.m[i][j] += sin(angle) * k.m[i][j] + (1.0 - cos(angle)) * k2.m[i][j];
    return r;
}
/* Elementary rotation about axis 0 (X), 1 (Y) or 2 (Z), written out. */
static inline ref_m3 ref_m3_elementary(int axis, double a) {
    double c = cos(a), s = sin(a);
    ref_m3 rx = {{{1, 0, 0}, {0, c, -s}, {0, s, c}}};
    ref_m3 ry = {{{c, 0, s}, {0, 1, 0}, {-s, 0, c}}};
    ref_m3 rz = {{{c, -s, 0}, {s, c, 0}, {0, 0, 1}}};
    return axis == 0 ? rx : axis == 1 ? ry : rz;
}
/* Euler matrix for axes ax[3] (0..2) and angles e[3]: intrinsic R0 R1 R2, extrinsic R2 R1 R0. */
static inline ref_m3 ref_m3_euler(const int ax[3], const double e[3], int intrinsic) {
    ref_m3 r0 = ref_m3_elementary(ax[0], e[0]), r1 = ref_m3_elementary(ax[1], e[1]);
    ref_m3 r2 = ref_m3_elementary(ax[2], e[2]);
    return intrinsic ? ref_m3_mul(ref_m3_mul(r0, r1), r2) : ref_m3_mul(ref_m3_mul(r2, r1), r0);
}
/* Eigenvalues (ascending) of a symmetric 3x3 matrix by the trigonometric closed form. */
static inline void ref_sym3_eigenvalues(ref_m3 a, double out[3]) {
    double(*m)[3] = a.m;
    double p1 = m[0][1] * m[0][1] + m[0][2] * m[0][2] + m[1][2] * m[1][2];
    double q = (m[0][0] + m[1][1] + m[2][2]) / 3.0;
    if (p1 == 0.0) {
        double d[3] = {m[0][0], m[1][1], m[2][2]};
        for (int i = 0; i < 3; ++i)
            for (int j = i + 1; j < 3; ++j)
                if (d[j] < d[i]) { double t = d[i]; d[i] = d[j]; d[j] = t; }
        out[0] = d[0], out[1] = d[1], out[2] = d[2];
        return;
    }
    double p2 = (m[0][0] - q) * (m[0][0] - q) + (m[1][1] - q) * (m[1][1] - q) + (m[2][2] - q) * (m[2][2] - q) + 2.0 * p1;
    double p = sqrt(p2 / 6.0);
    ref_m3 b = a;
    for (int i = 0; i < 3; ++i) {
        b.m[i][i] -= q;
        for (int j = 0; j < 3; ++j) b.m[i][j] /= p;
    }
    double r = ref_m3_det(b) / 2.0;
    double phi = r <= -1.0 ? REF_PI / 3.0 : r >= 1.0 ? 0.0 : acos(r) / 3.0;
    double e1 = q + 2.0 * p * cos(phi), e3 = q + 2.0 * p * cos(phi + 2.0 * REF_PI / 3.0);
    out[2] = e1, out[0] = e3, out[1] = 3.0 * q - e1 - e3;
}
/* Inverse by Gauss-Jordan elimination with partial pivoting; returns 0 when singular. */
static inline int ref_m4_inverse(ref_m4 a, ref_m4* out) {
    double w[4][8];
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 8; ++j) w[i][j] = j < 4 ? a.m[i][j] : (j - 4 == i);
    for (int c = 0; c < 4; ++c) {
        int piv = c;
        for (int r = c + 1; r < 4; ++r)
            if (fabs(w[r][c]) > fabs(w[piv][c])) piv = r;
        if (w[piv][c] == 0.0) return 0;
        for (int j = 0; j < 8; ++j) { double t = w[c][j]; w[c][j] = w[piv][j]; w[piv][j] = t; }
        double d = w[c][c];
        for (int j = 0; j < 8; ++j) w[c][j] /= d;
        for (int r = 0; r < 4; ++r)
            if (r != c) {
                double f = w[r][c];
                for (int j = 0; j < 8; ++j) w[r][j] -= f * w[c][j];
            }
    }
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) out->m[i][j] = w[i][j + 4];
    return 1;
}
static inline ref_m4 ref_m4_mul(ref_m4 a, ref_m4 b) {
    ref_m4 r;
    memset(&r, 0, sizeof r);
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            for (int k = 0; k < 4; ++k) r.m[i][j] += a.m[i][k] * b.m[k][j];
    return r;
}
/* Determinant by Laplace expansion along the first row. */
static inline double ref_m4_det(ref_m4 a) {
    double det = 0.0;
    for (int c = 0; c < 4; ++c) {
        ref_m3 minor;
        for (int i = 1; i < 4; ++i)
            for (int j = 0, jj = 0; j < 4; ++j)
                if (j != c) minor.m[i - 1][jj++] = a.m[i][j];
        det += (c % 2 ? -1.0 : 1.0) * a.m[0][c] * ref_m3_det(minor);
    }
    return det;
}

#endif
