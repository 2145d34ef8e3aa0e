/* clip_reduce_keys: bakes a 2 s, 60 fps motion of a 5-joint arm (one key per frame, as a
 * motion-capture or IK bake gives), removes keys with ak_clip_reduce at a 1 mm model-space
 * tolerance, prints the keys per channel before and after, then measures the model-space
 * error itself: its own double-precision forward kinematics of both clips, at every frame
 * time and at the midpoints between frames, at each joint's origin and at points 10 cm along
 * its axes (the points ak_clip_reduce promises to keep within the tolerance). Exits 1 when
 * that error exceeds the tolerance. */
#include <animkit/clip.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

enum { JOINTS = 5, FRAMES = 121 };
static const int32_t parents[JOINTS] = {-1, 0, 1, 2, 3};

/* Column-major 4x4 in double: m[col * 4 + row]. */
static void trs_matrix(const ak_transform* t, double m[16]) {
    double x = t->rotation.x, y = t->rotation.y, z = t->rotation.z, w = t->rotation.w;
    double n = sqrt(x * x + y * y + z * z + w * w);
    x /= n, y /= n, z /= n, w /= n;
    const double r[9] = {1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y),
                         2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x),
                         2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)};
    const double s[3] = {t->scale.x, t->scale.y, t->scale.z};
    for (int c = 0; c < 3; ++c) {
        for (int k = 0; k < 3; ++k) m[c * 4 + k] = r[c * 3 + k] * s[c];
        m[c * 4 + 3] = 0.0;
    }
    m[12] = t->translation.x, m[13] = t->translation.y, m[14] = t->translation.z, m[15] = 1.0;
}

static void mat_mul(const double a[16], const double b[16], double out[16]) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) {
            double v = 0.0;
            for (int k = 0; k < 4; ++k) v += a[k * 4 + r] * b[c * 4 + k];
            out[c * 4 + r] = v;
        }
}

/* Model-space positions of each joint's origin and of its three axis points at distance d. */
static void model_points(const ak_transform* local, double d, double out[JOINTS][4][3]) {
    double model[JOINTS][16], m[16];
    for (int j = 0; j < JOINTS; ++j) {
        trs_matrix(&local[j], m);
        if (parents[j] < 0) {
            for (int k = 0; k < 16; ++k) model[j][k] = m[k];
        } else {
            mat_mul(model[parents[j]], m, model[j]);
        }
        for (int p = 0; p < 4; ++p) {
            const double v[3] = {p == 1 ? d : 0.0, p == 2 ? d : 0.0, p == 3 ? d : 0.0};
            for (int r = 0; r < 3; ++r)
                out[j][p][r] = model[j][r] * v[0] + model[j][4 + r] * v[1] + model[j][8 + r] * v[2] + model[j][12 + r];
        }
    }
}

static void sample(const ak_clip* clip, const ak_transform* rest, float t, ak_transform* out) {
    for (int j = 0; j < JOINTS; ++j) out[j] = rest[j];
    ak_clip_sample(clip, t, NULL, (ak_transform_span){out, JOINTS}, (ak_f32_span){0}, (ak_f32_span){0});
}

static size_t total_keys(const ak_clip* clip) {
    size_t n = 0;
    for (size_t c = 0; c < ak_clip_channel_count(clip); ++c) n += ak_clip_channel_key_count(clip, c);
    return n;
}

int main(void) {
    static const char* const property[] = {"translation", "rotation", "scale", "weights", "scalars"};
    ak_transform rest[JOINTS];
    for (int j = 0; j < JOINTS; ++j) {
        rest[j] = ak_transform_identity();
        rest[j].translation = ak_vec3_make(0.0f, j == 0 ? 1.0f : 0.3f, 0.0f);
    }
    /* The motion: the root walks forward at a constant speed (a straight line: most keys go)
     * and bobs; the shoulder swings with a sine, the elbow bends in two linear ramps, the
     * wrist holds still for the first second, the finger wiggles fast and small. */
    static ak_transform poses[FRAMES * JOINTS];
    for (int f = 0; f < FRAMES; ++f) {
        float t = (float)f / 60.0f;
        ak_transform* p = &poses[f * JOINTS];
        for (int j = 0; j < JOINTS; ++j) p[j] = rest[j];
        p[0].translation = ak_vec3_make(0.8f * t, 1.0f + 0.02f * sinf(2.0f * AK_PI * 2.0f * t), 0.0f);
        p[1].rotation = ak_quat_from_axis_angle(ak_vec3_make(1, 0, 0), 0.6f * sinf(AK_PI * t));
        p[2].rotation = ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), t < 1.0f ? 1.2f * t : 1.2f * (2.0f - t));
        p[3].rotation = ak_quat_from_axis_angle(ak_vec3_make(0, 1, 0), t < 1.0f ? 0.0f : 0.8f * (t - 1.0f));
        p[4].rotation = ak_quat_from_axis_angle(ak_vec3_make(1, 0, 0), 0.05f * sinf(2.0f * AK_PI * 5.0f * t));
    }
    ak_clip_bake_desc bake = {.poses = poses, .frame_count = FRAMES, .joint_count = JOINTS, .frame_rate = 60.0f,
                              .rest_pose = {rest, JOINTS}, .name = "arm"};
    ak_clip *clip = NULL, *reduced = NULL;
    ak_diag diag;
    if (ak_clip_bake(&bake, NULL, &clip, &diag) != AK_OK) {
        fprintf(stderr, "bake: %s\n", diag.message);
        return 1;
    }
    const float tolerance = 0.001f, distance = 0.1f;
    ak_clip_reduce_desc desc = {.parents = parents, .rest_pose = {rest, JOINTS}, .tolerance = tolerance,
                                .distance = distance};
    double reported = 0.0;
    ak_result r = ak_clip_reduce(clip, &desc, NULL, &reduced, &reported, &diag);
    if (r != AK_OK) {
        fprintf(stderr, "reduce: %s: %s\n", ak_result_name(r), diag.message);
        ak_clip_destroy(clip);
        return 1;
    }

    printf("%-6s %-12s %7s %7s\n", "joint", "channel", "before", "after");
    for (size_t c = 0; c < ak_clip_channel_count(clip); ++c)
        printf("%-6u %-12s %7zu %7zu\n", (unsigned)ak_clip_channel_index(clip, c),
               property[ak_clip_channel_target(clip, c)], ak_clip_channel_key_count(clip, c),
               ak_clip_channel_key_count(reduced, c));
    size_t before = total_keys(clip), after = total_keys(reduced);
    printf("keys: %zu -> %zu (%.1f%% kept)\n", before, after, 100.0 * (double)after / (double)before);

    /* The independent check, at every frame time and every midpoint between frames. */
    double worst = 0.0, worst_t = 0.0;
    for (int i = 0; i <= 2 * (FRAMES - 1); ++i) {
        float t = (float)i / 120.0f;
        ak_transform a[JOINTS], b[JOINTS];
        double pa[JOINTS][4][3], pb[JOINTS][4][3];
        sample(clip, rest, t, a);
        sample(reduced, rest, t, b);
        model_points(a, distance, pa);
        model_points(b, distance, pb);
        for (int j = 0; j < JOINTS; ++j)
            for (int p = 0; p < 4; ++p) {
                double dx = pa[j][p][0] - pb[j][p][0], dy = pa[j][p][1] - pb[j][p][1], dz = pa[j][p][2] - pb[j][p][2];
                double e = sqrt(dx * dx + dy * dy + dz * dz);
                if (e > worst) worst = e, worst_t = t;
            }
    }
    printf("max model-space error: %.6f m at t = %.4f s (ak_clip_reduce reported %.6f), tolerance %.6f m\n", worst,
           worst_t, reported, (double)tolerance);
    /* Both clips are sampled in float: allow float rounding on top of the tolerance. */
    int ok = worst <= (double)tolerance + 1e-5;
    printf("%s\n", ok ? "within tolerance" : "ERROR: above tolerance");
    ak_clip_destroy(reduced);
    ak_clip_destroy(clip);
    return ok ? 0 : 1;
}
