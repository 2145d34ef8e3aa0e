/* Non-inline math: matrix inverses, projections, Euler angles, dual quaternion blending and
 * affine interpolation. Decompositions (SVD, polar) are in src/math/decompose.c, array
 * kernels in src/math/array.c. */
#include <animkit/math.h>

/* ---- private types and helpers (Euler angles in double precision) ------------------ */

/* Axis index (0 = X, 1 = Y, 2 = Z) of each letter of each order, in enum order. */
static const unsigned char euler_axes[AK_EULER_ORDER_COUNT][3] = {
    {0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0},
    {0, 1, 0}, {0, 2, 0}, {1, 0, 1}, {1, 2, 1}, {2, 0, 2}, {2, 1, 2},
};

typedef struct dmat3 {
    double m[3][3]; /* [row][column] */
} dmat3;

static const unsigned char* euler_resolve(ak_euler_order order, ak_euler_frame* frame) {
    if ((unsigned)*frame > (unsigned)AK_EULER_EXTRINSIC) *frame = AK_EULER_INTRINSIC;
    if ((unsigned)order >= (unsigned)AK_EULER_ORDER_COUNT) order = AK_EULER_XYZ;
    return euler_axes[order];
}

static dmat3 dmat3_axis_rotation(int axis, double angle) {
    dmat3 r = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
    int i = (axis + 1) % 3, j = (axis + 2) % 3;
    double c = cos(angle), s = sin(angle);
    r.m[i][i] = c, r.m[i][j] = -s;
    r.m[j][i] = s, r.m[j][j] = c;
    return r;
}

static dmat3 dmat3_mul(dmat3 a, dmat3 b) {
    dmat3 r;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) r.m[i][j] = a.m[i][0] * b.m[0][j] + a.m[i][1] * b.m[1][j] + a.m[i][2] * b.m[2][j];
    return r;
}


/* Intrinsic angles (a, b, c) of R = R_i(a) R_j(b) R_k(c) (k = i for proper Euler orders).
 * s is +1 when (i, j, third axis) is a cyclic permutation of (X, Y, Z), else -1; then
 * e_i x e_j = s e_third, which fixes every sign below. At gimbal lock either c = 0
 * (zero_first false) or a = 0, and the other outer angle is read from the column resp. row
 * of the middle axis, which the zeroed turn leaves untouched. */
static void euler_decompose(const dmat3* R, int i, int j, int k, int zero_first, double out[3]) {
    const double (*m)[3] = R->m;
    double s = j == (i + 1) % 3 ? 1.0 : -1.0;
    const double eps = 1e-6;
    double a, b, c;
    if (k != i) {
        double cb = sqrt(m[i][i] * m[i][i] + m[i][j] * m[i][j]);
        b = atan2(s * m[i][k], cb);
        if (cb > eps) {
            a = atan2(-s * m[j][k], m[k][k]);
            c = atan2(-s * m[i][j], m[i][i]);
        } else if (!zero_first) {
            c = 0.0, a = atan2(s * m[k][j], m[j][j]);
        } else {
            a = 0.0, c = atan2(s * m[j][i], m[j][j]);
        }
    } else {
        int t = 3 - i - j; /* the third axis */
        double sb = sqrt(m[i][j] * m[i][j] + m[i][t] * m[i][t]);
        b = atan2(sb, m[i][i]);
        if (sb > eps) {
            c = atan2(m[i][j], s * m[i][t]);
            a = atan2(m[j][i], -s * m[t][i]);
        } else if (!zero_first) {
            c = 0.0, a = atan2(s * m[t][j], m[j][j]);
        } else {
            a = 0.0, c = atan2(-s * m[j][t], m[j][j]);
        }
    }
    out[0] = a, out[1] = b, out[2] = c;
}

static ak_vec3 euler_from_dmat3(const dmat3* r, ak_euler_order order, ak_euler_frame frame) {
    const unsigned char* ax = euler_resolve(order, &frame);
    double e[3];
    if (frame == AK_EULER_INTRINSIC) {
        euler_decompose(r, ax[0], ax[1], ax[2], 0, e);
        return ak_vec3_make((float)e[0], (float)e[1], (float)e[2]);
    }
    /* Extrinsic ABC (x, y, z) is intrinsic CBA (z, y, x); zeroing the intrinsic first angle
     * puts the gimbal-lock zero into angles.z as documented. */
    euler_decompose(r, ax[2], ax[1], ax[0], 1, e);
    return ak_vec3_make((float)e[2], (float)e[1], (float)e[0]);
}

/* ---- matrices and projections -------------------------------------------------------- */

ak_mat4 ak_mat4_inverse(ak_mat4 m) {
    const float* a = m.m;
    float inv[16];
    inv[0] = a[5] * a[10] * a[15] - a[5] * a[11] * a[14] - a[9] * a[6] * a[15] + a[9] * a[7] * a[14] +
             a[13] * a[6] * a[11] - a[13] * a[7] * a[10];
    inv[4] = -a[4] * a[10] * a[15] + a[4] * a[11] * a[14] + a[8] * a[6] * a[15] - a[8] * a[7] * a[14] -
             a[12] * a[6] * a[11] + a[12] * a[7] * a[10];
    inv[8] = a[4] * a[9] * a[15] - a[4] * a[11] * a[13] - a[8] * a[5] * a[15] + a[8] * a[7] * a[13] +
             a[12] * a[5] * a[11] - a[12] * a[7] * a[9];
    inv[12] = -a[4] * a[9] * a[14] + a[4] * a[10] * a[13] + a[8] * a[5] * a[14] - a[8] * a[6] * a[13] -
              a[12] * a[5] * a[10] + a[12] * a[6] * a[9];
    inv[1] = -a[1] * a[10] * a[15] + a[1] * a[11] * a[14] + a[9] * a[2] * a[15] - a[9] * a[3] * a[14] -
             a[13] * a[2] * a[11] + a[13] * a[3] * a[10];
    inv[5] = a[0] * a[10] * a[15] - a[0] * a[11] * a[14] - a[8] * a[2] * a[15] + a[8] * a[3] * a[14] +
             a[12] * a[2] * a[11] - a[12] * a[3] * a[10];
    inv[9] = -a[0] * a[9] * a[15] + a[0] * a[11] * a[13] + a[8] * a[1] * a[15] - a[8] * a[3] * a[13] -
             a[12] * a[1] * a[11] + a[12] * a[3] * a[9];
    inv[13] = a[0] * a[9] * a[14] - a[0] * a[10] * a[13] - a[8] * a[1] * a[14] + a[8] * a[2] * a[13] +
              a[12] * a[1] * a[10] - a[12] * a[2] * a[9];
    inv[2] = a[1] * a[6] * a[15] - a[1] * a[7] * a[14] - a[5] * a[2] * a[15] + a[5] * a[3] * a[14] +
             a[13] * a[2] * a[7] - a[13] * a[3] * a[6];
    inv[6] = -a[0] * a[6] * a[15] + a[0] * a[7] * a[14] + a[4] * a[2] * a[15] - a[4] * a[3] * a[14] -
             a[12] * a[2] * a[7] + a[12] * a[3] * a[6];
    inv[10] = a[0] * a[5] * a[15] - a[0] * a[7] * a[13] - a[4] * a[1] * a[15] + a[4] * a[3] * a[13] +
              a[12] * a[1] * a[7] - a[12] * a[3] * a[5];
    inv[14] = -a[0] * a[5] * a[14] + a[0] * a[6] * a[13] + a[4] * a[1] * a[14] - a[4] * a[2] * a[13] -
              a[12] * a[1] * a[6] + a[12] * a[2] * a[5];
    inv[3] = -a[1] * a[6] * a[11] + a[1] * a[7] * a[10] + a[5] * a[2] * a[11] - a[5] * a[3] * a[10] -
             a[9] * a[2] * a[7] + a[9] * a[3] * a[6];
    inv[7] = a[0] * a[6] * a[11] - a[0] * a[7] * a[10] - a[4] * a[2] * a[11] + a[4] * a[3] * a[10] +
             a[8] * a[2] * a[7] - a[8] * a[3] * a[6];
    inv[11] = -a[0] * a[5] * a[11] + a[0] * a[7] * a[9] + a[4] * a[1] * a[11] - a[4] * a[3] * a[9] -
              a[8] * a[1] * a[7] + a[8] * a[3] * a[5];
    inv[15] = a[0] * a[5] * a[10] - a[0] * a[6] * a[9] - a[4] * a[1] * a[10] + a[4] * a[2] * a[9] +
              a[8] * a[1] * a[6] - a[8] * a[2] * a[5];
    float det = a[0] * inv[0] + a[1] * inv[4] + a[2] * inv[8] + a[3] * inv[12];
    if (!(fabsf(det) > 1e-30f) || !ak_finitef(det)) return ak_mat4_identity();
    float s = 1.0f / det;
    ak_mat4 r;
    for (int i = 0; i < 16; ++i) r.m[i] = inv[i] * s;
    return r;
}

float ak_mat4_determinant(ak_mat4 m) {
    const float* a = m.m;
    float c0 = a[5] * a[10] * a[15] - a[5] * a[11] * a[14] - a[9] * a[6] * a[15] + a[9] * a[7] * a[14] +
               a[13] * a[6] * a[11] - a[13] * a[7] * a[10];
    float c1 = -a[4] * a[10] * a[15] + a[4] * a[11] * a[14] + a[8] * a[6] * a[15] - a[8] * a[7] * a[14] -
               a[12] * a[6] * a[11] + a[12] * a[7] * a[10];
    float c2 = a[4] * a[9] * a[15] - a[4] * a[11] * a[13] - a[8] * a[5] * a[15] + a[8] * a[7] * a[13] +
               a[12] * a[5] * a[11] - a[12] * a[7] * a[9];
    float c3 = -a[4] * a[9] * a[14] + a[4] * a[10] * a[13] + a[8] * a[5] * a[14] - a[8] * a[6] * a[13] -
               a[12] * a[5] * a[10] + a[12] * a[6] * a[9];
    return a[0] * c0 + a[1] * c1 + a[2] * c2 + a[3] * c3;
}

ak_mat4 ak_mat4_inverse_affine(ak_mat4 m) {
    ak_mat3 l = ak_mat4_to_mat3(m);
    float det = ak_mat3_determinant(l);
    if (!(fabsf(det) > 1e-30f) || !ak_finitef(det)) return ak_mat4_identity();
    ak_mat3 li = ak_mat3_inverse(l);
    ak_vec3 t = ak_mat3_mul_vec3(li, ak_mat4_get_translation(m));
    return ak_mat4_from_mat3(li, ak_vec3_neg(t));
}

ak_mat3 ak_mat4_normal_matrix(ak_mat4 m) { return ak_mat3_transpose(ak_mat3_inverse(ak_mat4_to_mat3(m))); }

bool ak_mat4_is_finite(const ak_mat4* m) {
    for (int i = 0; i < 16; ++i)
        if (!ak_finitef(m->m[i])) return false;
    return true;
}

ak_mat4 ak_mat4_perspective(float fovy, float aspect, float near_z, float far_z) {
    if (!(fovy > 0.0f && fovy < AK_PI)) fovy = ak_radians(60.0f);
    if (!(aspect > 0.0f) || !ak_finitef(aspect)) aspect = 1.0f;
    if (!(near_z > 0.0f) || !ak_finitef(near_z)) near_z = 0.1f;
    if (!(far_z > near_z) || !ak_finitef(far_z)) far_z = near_z * 1000.0f;
    float f = 1.0f / tanf(0.5f * fovy);
    ak_mat4 r = {{0}};
    r.m[0] = f / aspect;
    r.m[5] = f;
    r.m[10] = (far_z + near_z) / (near_z - far_z);
    r.m[11] = -1.0f;
    r.m[14] = 2.0f * far_z * near_z / (near_z - far_z);
    return r;
}

ak_mat4 ak_mat4_orthographic(float l, float r, float b, float t, float n, float f) {
    if (!ak_finitef(l) || !ak_finitef(r) || !ak_finitef(b) || !ak_finitef(t) || !ak_finitef(n) ||
        !ak_finitef(f))
        return ak_mat4_identity();
    if (r == l) r = l + 1.0f;
    if (t == b) t = b + 1.0f;
    if (f == n) f = n + 1.0f;
    ak_mat4 m = ak_mat4_identity();
    m.m[0] = 2.0f / (r - l);
    m.m[5] = 2.0f / (t - b);
    m.m[10] = -2.0f / (f - n);
    m.m[12] = -(r + l) / (r - l);
    m.m[13] = -(t + b) / (t - b);
    m.m[14] = -(f + n) / (f - n);
    return m;
}

ak_mat4 ak_mat4_look_at(ak_vec3 eye, ak_vec3 target, ak_vec3 up) {
    if (!ak_vec3_is_finite(eye) || !ak_vec3_is_finite(target) || !ak_vec3_is_finite(up)) return ak_mat4_identity();
    ak_vec3 fwd = ak_vec3_normalize(ak_vec3_sub(target, eye));
    if (ak_vec3_length_sq(fwd) == 0.0f) return ak_mat4_translation(ak_vec3_neg(eye));
    ak_vec3 side = ak_vec3_normalize(ak_vec3_cross(fwd, up));
    if (ak_vec3_length_sq(side) == 0.0f) side = ak_vec3_any_perpendicular(fwd);
    ak_vec3 u = ak_vec3_cross(side, fwd);
    ak_mat4 m = ak_mat4_identity();
    m.m[0] = side.x; m.m[4] = side.y; m.m[8] = side.z;
    m.m[1] = u.x;    m.m[5] = u.y;    m.m[9] = u.z;
    m.m[2] = -fwd.x; m.m[6] = -fwd.y; m.m[10] = -fwd.z;
    m.m[12] = -ak_vec3_dot(side, eye);
    m.m[13] = -ak_vec3_dot(u, eye);
    m.m[14] = ak_vec3_dot(fwd, eye);
    return m;
}

/* ---- Euler angles ------------------------------------------------------------------ */

ak_quat ak_quat_from_euler(ak_vec3 angles, ak_euler_order order, ak_euler_frame frame) {
    if (!ak_vec3_is_finite(angles)) return ak_quat_identity();
    const unsigned char* ax = euler_resolve(order, &frame);
    const float a[3] = {angles.x, angles.y, angles.z};
    double q[4] = {0, 0, 0, 1}; /* x y z w, accumulated in double */
    for (int n = 0; n < 3; ++n) {
        /* Intrinsic: q = q0 q1 q2 (multiply on the right); extrinsic: q = q2 q1 q0 (left). */
        double e[4] = {0, 0, 0, cos(0.5 * a[n])};
        e[ax[n]] = sin(0.5 * a[n]);
        const double* l = frame == AK_EULER_INTRINSIC ? q : e;
        const double* r = frame == AK_EULER_INTRINSIC ? e : q;
        double p[4] = {l[3] * r[0] + l[0] * r[3] + l[1] * r[2] - l[2] * r[1],
                       l[3] * r[1] - l[0] * r[2] + l[1] * r[3] + l[2] * r[0],
                       l[3] * r[2] + l[0] * r[1] - l[1] * r[0] + l[2] * r[3],
                       l[3] * r[3] - l[0] * r[0] - l[1] * r[1] - l[2] * r[2]};
        for (int k = 0; k < 4; ++k) q[k] = p[k];
    }
    return ak_quat_make((float)q[0], (float)q[1], (float)q[2], (float)q[3]);
}

ak_mat3 ak_mat3_from_euler(ak_vec3 angles, ak_euler_order order, ak_euler_frame frame) {
    if (!ak_vec3_is_finite(angles)) return ak_mat3_identity();
    const unsigned char* ax = euler_resolve(order, &frame);
    dmat3 r0 = dmat3_axis_rotation(ax[0], angles.x);
    dmat3 r1 = dmat3_axis_rotation(ax[1], angles.y);
    dmat3 r2 = dmat3_axis_rotation(ax[2], angles.z);
    dmat3 r = frame == AK_EULER_INTRINSIC ? dmat3_mul(dmat3_mul(r0, r1), r2) : dmat3_mul(dmat3_mul(r2, r1), r0);
    ak_mat3 out;
    for (int c = 0; c < 3; ++c)
        for (int row = 0; row < 3; ++row) out.m[c * 3 + row] = (float)r.m[row][c];
    return out;
}

ak_vec3 ak_mat3_to_euler(ak_mat3 m, ak_euler_order order, ak_euler_frame frame) {
    if (!ak_mat3_is_finite(m)) return ak_vec3_zero();
    dmat3 r;
    for (int c = 0; c < 3; ++c)
        for (int row = 0; row < 3; ++row) r.m[row][c] = m.m[c * 3 + row];
    return euler_from_dmat3(&r, order, frame);
}

ak_vec3 ak_quat_to_euler(ak_quat q, ak_euler_order order, ak_euler_frame frame) {
    double x = q.x, y = q.y, z = q.z, w = q.w;
    double n2 = x * x + y * y + z * z + w * w;
    if (!(n2 > 1e-30) || !ak_quat_is_finite(q)) return ak_vec3_zero();
    /* The rotation matrix of q / |q|, formed in double so that small angles keep their digits. */
    double k = 2.0 / n2;
    dmat3 r = {{{1 - k * (y * y + z * z), k * (x * y - w * z), k * (x * z + w * y)},
                {k * (x * y + w * z), 1 - k * (x * x + z * z), k * (y * z - w * x)},
                {k * (x * z - w * y), k * (y * z + w * x), 1 - k * (x * x + y * y)}}};
    return euler_from_dmat3(&r, order, frame);
}

/* ---- dual quaternions --------------------------------------------------------------- */

ak_dualquat ak_dualquat_blend(ak_dualquat_cspan dqs, ak_f32_cspan weights) {
    size_t n = dqs.count < weights.count ? dqs.count : weights.count;
    if (n == 0 || !dqs.ptr || !weights.ptr) return ak_dualquat_identity();
    size_t pivot = 0;
    for (size_t i = 1; i < n; ++i)
        if (weights.ptr[i] > weights.ptr[pivot]) pivot = i;
    ak_quat ref = dqs.ptr[pivot].real;
    ak_dualquat sum = {{0, 0, 0, 0}, {0, 0, 0, 0}};
    for (size_t i = 0; i < n; ++i) {
        float w = weights.ptr[i];
        if (w == 0.0f) continue; /* skips 0 * inf or 0 * NaN in unused slots */
        if (ak_quat_dot(dqs.ptr[i].real, ref) < 0.0f) w = -w;
        sum.real = ak_quat_add(sum.real, ak_quat_scale(dqs.ptr[i].real, w));
        sum.dual = ak_quat_add(sum.dual, ak_quat_scale(dqs.ptr[i].dual, w));
    }
    return ak_dualquat_normalize(sum);
}

/* ---- affine interpolation ------------------------------------------------------------ */

ak_mat4 ak_mat4_interpolate_affine(ak_mat4 a, ak_mat4 b, float t) {
    if (!ak_mat4_is_finite(&a) || !ak_mat4_is_finite(&b) || !ak_finitef(t)) return ak_mat4_identity();
    ak_polar pa = ak_mat3_polar(ak_mat4_to_mat3(a));
    ak_polar pb = ak_mat3_polar(ak_mat4_to_mat3(b));
    ak_quat q = ak_quat_slerp(ak_quat_from_mat3(pa.rotation), ak_quat_from_mat3(pb.rotation), t);
    ak_mat3 d = ak_mat3_lerp(pa.stretch, pb.stretch, t);
    ak_vec3 tr = ak_vec3_lerp(ak_mat4_get_translation(a), ak_mat4_get_translation(b), t);
    return ak_mat4_from_mat3(ak_mat3_mul(ak_mat3_from_quat(q), d), tr);
}
