/* SLERP against NLERP: angle travelled and angular speed over t for a 160 degree turn,
 * then the Euler ambiguity: XYZ angles [pi,0,0] and [0,pi,pi] give the same matrix
 * diag(1,-1,-1), and a gimbal-locked decomposition (third angle set to 0). */
#include <stdio.h>

#include <animkit/math.h>

/* Rounding noise such as -8.7e-8 printed as 0 rather than -0.0000. */
static float clean(float x) { return fabsf(x) < 5e-5f ? 0.0f : x; }

static void print_mat3(const char* label, ak_mat3 m) {
    printf("%s\n", label);
    for (int r = 0; r < 3; ++r)
        printf("    [%7.4f %7.4f %7.4f]\n", clean(ak_mat3_at(&m, r, 0)), clean(ak_mat3_at(&m, r, 1)),
               clean(ak_mat3_at(&m, r, 2)));
}

int main(void) {
    /* A large turn shows NLERP's uneven speed best: it moves along the chord, so its
     * angular speed peaks in the middle; SLERP moves along the arc at constant speed. */
    const float total_deg = 160.0f;
    ak_quat a = ak_quat_identity();
    ak_quat b = ak_quat_from_axis_angle(ak_vec3_make(0.3f, 1.0f, 0.2f), ak_radians(total_deg));
    const int steps = 10;
    printf("SLERP vs NLERP for a %.0f degree turn (angles in degrees)\n", total_deg);
    printf("%6s %10s %10s %12s %12s\n", "t", "slerp", "nlerp", "slerp speed", "nlerp speed");
    ak_quat ps = a, pn = a;
    float min_n = 1e30f, max_n = 0.0f, min_s = 1e30f, max_s = 0.0f;
    for (int k = 0; k <= steps; ++k) {
        float t = (float)k / (float)steps;
        ak_quat s = ak_quat_slerp(a, b, t), n = ak_quat_nlerp(a, b, t);
        float as = ak_degrees(ak_quat_angle_between(a, s)), an = ak_degrees(ak_quat_angle_between(a, n));
        /* speed: degrees per unit t over the last step */
        float vs = k ? ak_degrees(ak_quat_angle_between(ps, s)) * (float)steps : 0.0f;
        float vn = k ? ak_degrees(ak_quat_angle_between(pn, n)) * (float)steps : 0.0f;
        if (k) {
            min_s = ak_minf(min_s, vs), max_s = ak_maxf(max_s, vs);
            min_n = ak_minf(min_n, vn), max_n = ak_maxf(max_n, vn);
        }
        printf("%6.2f %10.4f %10.4f %12.4f %12.4f\n", t, as, an, vs, vn);
        ps = s, pn = n;
    }
    printf("speed range: slerp %.4f..%.4f deg/t (constant), nlerp %.4f..%.4f deg/t (%.1f%% spread)\n\n",
           min_s, max_s, min_n, max_n, 100.0f * (max_n - min_n) / min_n);

    /* Two different Euler triples, one rotation. */
    ak_vec3 e1 = ak_vec3_make(AK_PI, 0.0f, 0.0f), e2 = ak_vec3_make(0.0f, AK_PI, AK_PI);
    ak_mat3 m1 = ak_mat3_from_euler(e1, AK_EULER_XYZ, AK_EULER_INTRINSIC);
    ak_mat3 m2 = ak_mat3_from_euler(e2, AK_EULER_XYZ, AK_EULER_INTRINSIC);
    print_mat3("XYZ Euler [pi, 0, 0]:", m1);
    print_mat3("XYZ Euler [0, pi, pi]:", m2);
    float diff = 0.0f;
    for (int i = 0; i < 9; ++i) diff = ak_maxf(diff, fabsf(m1.m[i] - m2.m[i]));
    ak_vec3 back = ak_mat3_to_euler(m1, AK_EULER_XYZ, AK_EULER_INTRINSIC);
    printf("max difference %.2g; decomposing gives [%.4f, %.4f, %.4f]\n\n", diff, clean(back.x), clean(back.y),
           clean(back.z));

    /* Gimbal lock: middle angle 90 degrees, only x + z (for XYZ) is determined. */
    ak_vec3 g = ak_vec3_make(0.4f, AK_HALF_PI, 0.3f);
    ak_mat3 mg = ak_mat3_from_euler(g, AK_EULER_XYZ, AK_EULER_INTRINSIC);
    ak_vec3 gb = ak_mat3_to_euler(mg, AK_EULER_XYZ, AK_EULER_INTRINSIC);
    ak_mat3 mg2 = ak_mat3_from_euler(gb, AK_EULER_XYZ, AK_EULER_INTRINSIC);
    float gd = 0.0f;
    for (int i = 0; i < 9; ++i) gd = ak_maxf(gd, fabsf(mg.m[i] - mg2.m[i]));
    printf("gimbal lock: [%.4f, %.4f, %.4f] decomposes to [%.4f, %.4f, %.4f] (same matrix to %.2g)\n",
           g.x, g.y, g.z, gb.x, gb.y, clean(gb.z), gd);
    return 0;
}
