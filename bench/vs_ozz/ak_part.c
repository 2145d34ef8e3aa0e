/* animkit side of the vs_ozz harness (a copy of ../shared/peers/vs_ozz/ak_part.c, public API
 * only) whose skinning jobs, FK (ak_skeleton_set_simd_limit) and clip sampling take their
 * SIMD limit from AK_VS_OZZ_SIMD (scalar, avx2, avx512; unset: the default, the fastest
 * kernel), so ozz can be compared with each animkit kernel.
 * Run with bench/vs_ozz/run.sh. */
#include <stdlib.h>
#include <string.h>
#include <animkit/clip.h>
#include <animkit/ik.h>
#include <animkit/skeleton.h>
#include <animkit/skin.h>
#include "harness.h"

static unsigned char g_scratch[64 + 192 * 64];

static ak_skin_simd simd_limit(void) {
    const char* e = getenv("AK_VS_OZZ_SIMD");
    if (!e || !*e) return AK_SKIN_SIMD_DEFAULT;
    if (!strcmp(e, "scalar")) return AK_SKIN_SIMD_SCALAR;
    if (!strcmp(e, "avx2")) return AK_SKIN_SIMD_AVX2;
    return AK_SKIN_SIMD_AVX512;
}

static ak_skin_job make_job(const skin_data* d, int method, int normals, int threads) {
    ak_skin_job job = {
        .simd_limit = simd_limit(),
        .method = method == 0 ? AK_SKIN_LBS : method == 1 ? AK_SKIN_DQS : AK_SKIN_COR,
        .influence_count = (uint32_t)d->K,
        .palette = {(const ak_mat4*)d->palette, 64},
        .positions = {d->pos, d->n, 0},
        .joints = {d->joints, d->n, 0},
        .weights = {d->weights, d->n, 0},
        .normals = {normals ? d->nrm : NULL, normals ? d->n : 0, 0},
        .cor_centers = {d->ctr, d->n, 0},
        .out_positions = {d->out_pos, d->n, 0},
        .out_normals = {d->out_nrm, d->n, 0},
        .scratch = {g_scratch, sizeof g_scratch},
        .thread_count = (uint32_t)threads,
        .skip_data_check = true,
    };
    return job;
}
int akh_skin_validate(const skin_data* d, int method, int normals) {
    ak_skin_job job = make_job(d, method, normals, 1);
    job.skip_data_check = false;
    return (int)ak_skin_job_validate(&job);
}
int akh_skin(const skin_data* d, int method, int normals, int threads) {
    ak_skin_job job = make_job(d, method, normals, threads);
    return (int)ak_skin_job_run(&job);
}
static ak_fk_simd fk_limit(void) {
    const char* e = getenv("AK_VS_OZZ_SIMD");
    if (!e || !*e) return AK_FK_SIMD_DEFAULT;
    if (!strcmp(e, "scalar")) return AK_FK_SIMD_SCALAR;
    if (!strcmp(e, "avx2")) return AK_FK_SIMD_AVX2;
    return AK_FK_SIMD_AVX512;
}
const char* akh_skin_kernel(void) {
    const char* e = getenv("AK_VS_OZZ_SIMD");
    return e && *e ? e : ak_skin_simd_name();
}

/* ---- animation ---- */
static ak_skeleton* g_sk;
static ak_clip* g_clip[2];
static ak_clip_cursor g_cur[2];
static uint32_t* g_seg[2];
static ak_transform* g_local;
static ak_mat4* g_model;
static size_t g_nj;

int akh_anim_setup(int joints, const int* parents, const float* rest_t, int keys, const float* times, const float* T,
                   const float* R, const float* S, int unused) {
    (void)unused;
    g_nj = (size_t)joints;
    ak_joint_desc* js = calloc((size_t)joints, sizeof *js);
    char(*names)[16] = calloc((size_t)joints, 16);
    for (int i = 0; i < joints; ++i) {

        names[i][0] = 'j';
        names[i][1] = (char)('0' + i / 10);
        names[i][2] = (char)('0' + i % 10);
        js[i].name = names[i];
        js[i].parent = parents[i];
        js[i].rest = ak_transform_identity();
        js[i].rest.translation = ak_vec3_make(rest_t[3 * i], rest_t[3 * i + 1], rest_t[3 * i + 2]);
    }
    ak_skeleton_desc sd = {.joints = js, .joint_count = (size_t)joints};
    if (ak_skeleton_create(&sd, NULL, &g_sk, NULL) != AK_OK) return 1;
    if (ak_skeleton_set_simd_limit(g_sk, fk_limit()) != AK_OK) return 1;
    free(js);
    free(names);
    for (int c = 0; c < 2; ++c) {
        ak_raw_channel* ch = calloc(3 * (size_t)joints, sizeof *ch);
        for (int j = 0; j < joints; ++j) {
            size_t o3 = (size_t)j * keys * 3, o4 = (size_t)j * keys * 4;
            ch[3 * j] = (ak_raw_channel){.target = AK_CHANNEL_TRANSLATION, .index = (uint32_t)j, .interp = AK_INTERP_LINEAR,
                                         .key_count = (size_t)keys, .times = times, .values = T + o3};
            ch[3 * j + 1] = (ak_raw_channel){.target = AK_CHANNEL_ROTATION, .index = (uint32_t)j,
                                             .interp = c == 0 ? AK_INTERP_LINEAR : AK_INTERP_NLERP,
                                             .key_count = (size_t)keys, .times = times, .values = R + o4};
            ch[3 * j + 2] = (ak_raw_channel){.target = AK_CHANNEL_SCALE, .index = (uint32_t)j, .interp = AK_INTERP_LINEAR,
                                             .key_count = (size_t)keys, .times = times, .values = S + o3};
        }
        ak_raw_clip raw = {.name = "h", .channels = ch, .channel_count = 3 * (size_t)joints, .joint_count = (size_t)joints};
        ak_result r = ak_clip_build(&raw, NULL, &g_clip[c], NULL);
        free(ch);
        if (r != AK_OK) return 2;
        const ak_fk_simd lim = fk_limit();
        if (ak_clip_set_simd_limit(g_clip[c], lim == AK_FK_SIMD_SCALAR ? AK_CLIP_SIMD_SCALAR
                                              : lim == AK_FK_SIMD_AVX2 ? AK_CLIP_SIMD_AVX2
                                              : lim == AK_FK_SIMD_AVX512 ? AK_CLIP_SIMD_AVX512
                                                                         : AK_CLIP_SIMD_DEFAULT) != AK_OK)
            return 2;
        size_t sc = ak_clip_cursor_storage_count(g_clip[c]);
        g_seg[c] = calloc(sc, sizeof(uint32_t));
        ak_clip_cursor_init(&g_cur[c], g_clip[c], (ak_u32_span){g_seg[c], sc});
    }
    g_local = malloc(g_nj * sizeof *g_local);
    g_model = aligned_alloc(64, g_nj * sizeof *g_model);
    memcpy(g_local, ak_skeleton_rest_pose(g_sk).ptr, g_nj * sizeof *g_local);
    return 0;
}
void akh_anim_eval(int clip, float time, int use_cursor, int fk) {
    if (fk != 2)
        ak_clip_sample(g_clip[clip], time, use_cursor ? &g_cur[clip] : NULL, (ak_transform_span){g_local, g_nj},
                       (ak_f32_span){0}, (ak_f32_span){0});
    if (fk) ak_skeleton_local_to_model(g_sk, (ak_transform_cspan){g_local, g_nj}, (ak_mat4_span){g_model, g_nj});
}
const char* akh_fk_kernel(void) { return ak_skeleton_simd_name(g_sk); }
const char* akh_sample_kernel(void) { return ak_clip_simd_name(g_clip[0]); }
const float* akh_anim_model(void) { return g_model[0].m; }
const float* akh_anim_local(void) { return &g_local[0].translation.x; }

/* ---- two-bone IK ---- */
static ak_ik_two_bone_job g_ik;
static ak_quat g_qs, g_qm;
void akh_ik_setup(const float* start, const float* mid, const float* end, const float* pole, const float* mid_axis) {
    memset(&g_ik, 0, sizeof g_ik);
    memcpy(g_ik.start.m, start, 64);
    memcpy(g_ik.mid.m, mid, 64);
    memcpy(g_ik.end.m, end, 64);
    g_ik.pole = ak_vec3_make(pole[0], pole[1], pole[2]);
    /* ozz's mid_axis is signed (a positive turn about it opens the joint, which sets the bend
     * side); animkit keeps the input's bend side unless mid_axis_signed asks for ozz's rule.
     * The driver's limb is bent +0.6 rad about z, against ozz's side for mid_axis z, so
     * without it the two solve different problems (same positions, joints turned half a
     * turn about their bones). */
    if (mid_axis) g_ik.mid_axis = ak_vec3_make(mid_axis[0], mid_axis[1], mid_axis[2]), g_ik.mid_axis_signed = true;
    g_ik.out_start_rot = &g_qs;
    g_ik.out_mid_rot = &g_qm;
}
void akh_ik_solve(const float* target, float* out_qs, float* out_qm) {
    g_ik.target = ak_vec3_make(target[0], target[1], target[2]);
    ak_ik_two_bone_run(&g_ik);
    memcpy(out_qs, &g_qs, 16);
    memcpy(out_qm, &g_qm, 16);
}
void akh_ik_solve_many(const float* targets, size_t count, float* out) {
    enum { B = 64 };
    static ak_ik_two_bone_job jobs[B];
    for (size_t i0 = 0; i0 < count; i0 += B) {
        size_t m = count - i0 < B ? count - i0 : B;
        for (size_t i = 0; i < m; ++i) {
            jobs[i] = g_ik;
            jobs[i].target = ak_vec3_make(targets[3 * (i0 + i)], targets[3 * (i0 + i) + 1], targets[3 * (i0 + i) + 2]);
            jobs[i].out_start_rot = (ak_quat*)(out + 8 * (i0 + i));
            jobs[i].out_mid_rot = (ak_quat*)(out + 8 * (i0 + i) + 4);
        }
        ak_ik_two_bone_run_many(jobs, m, NULL);
    }
}
