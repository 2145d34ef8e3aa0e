/* Shared interface between the C animkit part and the C++ driver (ozz part): a copy of
 * ../shared/peers/vs_ozz/harness.h with the FK and sampling kernel names. */
#ifndef HARNESS_H
#define HARNESS_H
#include <stddef.h>
#include <stdint.h>
#ifdef __cplusplus
extern "C" {
#endif
typedef struct skin_data {
    size_t n;
    int K;
    const float* pos;       /* 3n */
    const float* nrm;       /* 3n */
    const float* ctr;       /* 3n, CoR centers */
    const uint16_t* joints; /* K n */
    const float* weights;   /* K n (ozz reads the first K-1 through stride K) */
    const float* palette;   /* 64 column-major 4x4, 64-byte aligned */
    float* out_pos;
    float* out_nrm;
} skin_data;
/* method 0 LBS, 1 DQS, 2 CoR; returns 0 on success */
int akh_skin(const skin_data* d, int method, int normals, int threads);
int akh_skin_validate(const skin_data* d, int method, int normals);
const char* akh_skin_kernel(void);
const char* akh_fk_kernel(void);     /* FK kernel animkit uses (after akh_anim_setup) */
const char* akh_sample_kernel(void); /* clip sampling kernel animkit uses (after akh_anim_setup) */

/* 60-joint animation: parents[60], rest translations, keys: times[KEYS], T[60][KEYS][3], R[60][KEYS][4] (x,y,z,w), S[60][KEYS][3] */
int akh_anim_setup(int joints, const int* parents, const float* rest_t, int keys, const float* times, const float* T,
                   const float* R, const float* S, int nlerp);
/* sample (and FK when fk) at time; clip 0 = slerp (LINEAR), 1 = NLERP; cursor 1/0 */
void akh_anim_eval(int clip, float time, int use_cursor, int fk);
const float* akh_anim_model(void); /* 60 x 16 floats */
const float* akh_anim_local(void); /* 60 x 10 floats (t3 q4 s3) */

/* two-bone: model-space matrices start, mid, end (16 floats each) */
void akh_ik_setup(const float* start, const float* mid, const float* end, const float* pole, const float* mid_axis);
void akh_ik_solve(const float* target, float* out_qs, float* out_qm);
void akh_ik_solve_many(const float* targets /* 3 x count */, size_t count, float* out /* 8 x count */);
#ifdef __cplusplus
}
#endif
#endif
