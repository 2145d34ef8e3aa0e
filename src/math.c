/* Non-inline math: matrix inverses, projections. */
#include <animkit/math.h>

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
