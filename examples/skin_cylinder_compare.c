/* skin_cylinder_compare: bone-heat weights on a capped cylinder with a two-joint chain, then
 * LBS, dual quaternions and optimized centers of rotation on a 90 degree bend and 90/180 degree
 * twists; prints the volume relative to rest and the bulge beyond the rest radius. */
#include <stdio.h>
#include <stdlib.h>

#include <animkit/skin.h>

enum { RINGS = 49, SEGMENTS = 32, K = 4 };
#define RADIUS 0.2f
#define LENGTH 2.0f

static float seg_dist(ak_vec3 p, ak_vec3 a, ak_vec3 b) {
    ak_vec3 ab = ak_vec3_sub(b, a);
    float t = ak_clampf(ak_vec3_dot(ak_vec3_sub(p, a), ab) / ak_vec3_dot(ab, ab), 0.0f, 1.0f);
    return ak_vec3_distance(p, ak_vec3_madd(a, ab, t));
}

int main(void) {
    const size_t n = (size_t)RINGS * SEGMENTS + 2, tris = (size_t)(RINGS - 1) * SEGMENTS * 2 + 2 * SEGMENTS;
    ak_vec3* pos = malloc(n * sizeof *pos);
    ak_vec3* out = malloc(n * sizeof *out);
    ak_vec3* centers = malloc(n * sizeof *centers);
    uint32_t* idx = malloc(3 * tris * sizeof *idx);
    uint16_t* joints = malloc(n * K * sizeof *joints);
    float* weights = malloc(n * K * sizeof *weights);
    if (!pos || !out || !centers || !idx || !joints || !weights) return 1;

    /* the tube: rings along +Y, counter-clockwise seen from outside, fan caps */
    size_t t = 0;
    for (int r = 0; r < RINGS; ++r)
        for (int s = 0; s < SEGMENTS; ++s) {
            float a = AK_TWO_PI * (float)s / SEGMENTS;
            pos[r * SEGMENTS + s] = ak_vec3_make(RADIUS * cosf(a), LENGTH * (float)r / (RINGS - 1), -RADIUS * sinf(a));
            if (r + 1 == RINGS) continue;
            uint32_t i0 = (uint32_t)(r * SEGMENTS + s), i1 = (uint32_t)(r * SEGMENTS + (s + 1) % SEGMENTS);
            uint32_t quad[6] = {i0, i1, i1 + SEGMENTS, i0, i1 + SEGMENTS, i0 + SEGMENTS};
            for (int k = 0; k < 6; ++k) idx[3 * t + (size_t)k] = quad[k];
            t += 2;
        }
    const uint32_t bottom = RINGS * SEGMENTS, top = bottom + 1, last = (RINGS - 1) * SEGMENTS;
    pos[bottom] = ak_vec3_make(0, 0, 0);
    pos[top] = ak_vec3_make(0, LENGTH, 0);
    for (uint32_t s = 0; s < SEGMENTS; ++s, t += 2) {
        uint32_t s1 = (s + 1) % SEGMENTS;
        uint32_t caps[6] = {bottom, s1, s, top, last + s, last + s1};
        for (int k = 0; k < 6; ++k) idx[3 * t + (size_t)k] = caps[k];
    }

    /* automatic weights (bone heat) for the chain hip (0, 0, 0) -> knee (0, 1, 0) -> end */
    ak_vec3 joint_pos[3] = {{0, 0, 0}, {0, 1, 0}, {0, 2, 0}};
    int32_t parents[3] = {-1, 0, 1};
    ak_skin_bone bones[6];
    size_t bone_count = 0;
    ak_skin_bones_from_joints((ak_vec3_cspan){joint_pos, 3}, (ak_i32_cspan){parents, 3}, true,
                              (ak_skin_bone_span){bones, 6}, &bone_count);
    ak_weights_desc wd = {
        .positions = {pos, n},
        .indices = {idx, 3 * tris},
        .bones = {bones, bone_count},
        .max_influences = K,
    };
    ak_result r = ak_skin_weights_compute(&wd, NULL, (ak_u16_span){joints, n * K}, (ak_f32_span){weights, n * K});
    if (r != AK_OK) return fprintf(stderr, "weights: %s\n", ak_result_string(r)), 1;

    ak_skin_cor_desc cd = {
        .positions = {pos, n},
        .indices = {idx, 3 * tris},
        .joints = {joints, n * K},
        .weights = {weights, n * K},
        .influence_count = K,
    };
    r = ak_skin_cor_centers_compute(&cd, NULL, (ak_vec3_span){centers, n});
    if (r != AK_OK) return fprintf(stderr, "centers: %s\n", ak_result_string(r)), 1;

    const double rest = ak_volume_compute((ak_vec3_cspan){pos, n}, (ak_u32_cspan){idx, 3 * tris});
    const struct {
        const char* name;
        ak_vec3 axis;
        float degrees;
    } poses[3] = {{"bend 90", {0, 0, 1}, 90}, {"twist 90", {0, 1, 0}, 90}, {"twist 180", {0, 1, 0}, 180}};
    const char* methods[3] = {"LBS", "DQS", "CoR"};
    unsigned char scratch[64 + 192 * 2]; /* >= ak_skin_job_scratch_size for every method */
    printf("pose       method  volume/rest  bulge/radius\n");
    for (int p = 0; p < 3; ++p) {
        /* joint 1 turns about its own position; joint 0 stays */
        ak_mat4 turn = ak_mat4_from_quat(ak_quat_from_axis_angle(poses[p].axis, ak_radians(poses[p].degrees)));
        ak_mat4 palette[2] = {ak_mat4_identity(),
                              ak_mat4_mul(ak_mat4_translation(joint_pos[1]),
                                          ak_mat4_mul(turn, ak_mat4_translation(ak_vec3_neg(joint_pos[1]))))};
        ak_vec3 end = ak_mat4_transform_point(palette[1], joint_pos[2]);
        for (int m = 0; m < 3; ++m) {
            ak_skin_job job = {
                .method = (ak_skin_method)m,
                .influence_count = K,
                .palette = {palette, 2},
                .positions = {pos, n, 0},
                .joints = {joints, n, 0},
                .weights = {weights, n, 0},
                .cor_centers = {centers, n, 0},
                .scratch = {scratch, sizeof scratch},
                .out_positions = {out, n, 0},
            };
            r = ak_skin_job_run(&job);
            if (r != AK_OK) return fprintf(stderr, "skin: %s\n", ak_result_string(r)), 1;
            double vol = ak_volume_compute((ak_vec3_cspan){out, n}, (ak_u32_cspan){idx, 3 * tris});
            float bulge = 0.0f; /* outward distance beyond the rest radius from the posed bones */
            for (size_t v = 0; v < bottom; ++v) {
                float d = ak_minf(seg_dist(out[v], joint_pos[0], joint_pos[1]), seg_dist(out[v], joint_pos[1], end));
                bulge = ak_maxf(bulge, d - RADIUS);
            }
            printf("%-10s %-6s  %10.4f  %12.4f\n", poses[p].name, methods[m], vol / rest, bulge / RADIUS);
        }
    }
    free(pos);
    free(out);
    free(centers);
    free(idx);
    free(joints);
    free(weights);
    return 0;
}
