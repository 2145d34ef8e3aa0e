/* Curl noise, noise wind, and the procedural sway layer on a pose. */
#include <math.h>

#include "noise_internal.h"

static bool finite3(ak_vec3 p) { return isfinite(p.x) && isfinite(p.y) && isfinite(p.z); }

ak_vec3 ak_noise_curl3(const ak_noise* noise, const ak_fractal_desc* desc, ak_vec3 p) {
    if (!noise || !finite3(p) || ak_fractal_desc_validate(desc) != AK_OK) return ak_vec3_zero();
    const float q0[3] = {p.x, p.y, p.z}, q1[3] = {p.x + 31.4f, p.y, p.z}, q2[3] = {p.x, p.y + 47.2f, p.z};
    float a[3], b[3], c[3]; /* gradients of psi_x, psi_y, psi_z */
    ak_fractal_eval(noise, desc, 3, q0, a);
    ak_fractal_eval(noise, desc, 3, q1, b);
    ak_fractal_eval(noise, desc, 3, q2, c);
    /* curl psi = (dpsi_z/dy - dpsi_y/dz, dpsi_x/dz - dpsi_z/dx, dpsi_y/dx - dpsi_x/dy) */
    return ak_vec3_make(c[1] - b[2], a[2] - c[0], b[0] - a[1]);
}

ak_vec2 ak_noise_curl2(const ak_noise* noise, const ak_fractal_desc* desc, ak_vec2 p) {
    if (!noise || !isfinite(p.x) || !isfinite(p.y) || ak_fractal_desc_validate(desc) != AK_OK)
        return ak_vec2_make(0.0f, 0.0f);
    const float q[2] = {p.x, p.y};
    float g[2];
    ak_fractal_eval(noise, desc, 2, q, g);
    return ak_vec2_make(g[1], -g[0]);
}

ak_vec3 ak_noise_wind(const ak_noise* noise, const ak_noise_wind_desc* desc, ak_vec3 p, float t) {
    if (!noise || !desc || !finite3(p) || !isfinite(t) || !finite3(desc->direction)) return ak_vec3_zero();
    ak_vec3 dir = desc->direction;
    if (ak_vec3_length(dir) < 1e-20f) dir = ak_vec3_make(1.0f, 0.0f, 0.0f);
    dir = ak_vec3_normalize(dir);
    const float gf = desc->gust_frequency != 0.0f ? desc->gust_frequency : 0.25f;
    /* offset 0.5: the 1D noise is 0 at integers, so t = 0 would always start calm */
    const float gust = 1.0f + desc->gust * ak_noise_perlin1(noise, t * gf + 0.5f, NULL);
    ak_vec3 v = ak_vec3_scale(dir, desc->speed * gust);
    if (desc->turbulence != 0.0f) {
        const float scale = desc->turbulence_scale != 0.0f ? desc->turbulence_scale : 2.0f;
        const float evo = desc->evolution != 0.0f ? desc->evolution : 0.3f;
        /* the swirl drifts with the mean wind; its potential is 4D noise whose fourth
         * coordinate is time, so the pattern also changes shape. The curl takes only the
         * spatial derivatives, so the field stays divergence-free at every instant. */
        const float drift = desc->speed * t / scale;
        const float q[3] = {p.x / scale - dir.x * drift, p.y / scale - dir.y * drift, p.z / scale - dir.z * drift};
        const ak_fractal_desc fd = {.octaves = 2};
        static const float off[3][3] = {{0, 0, 0}, {31.4f, 0, 0}, {0, 47.2f, 0}};
        float g[3][4];
        for (int k = 0; k < 3; ++k) {
            const float p4[4] = {q[0] + off[k][0], q[1] + off[k][1], q[2] + off[k][2], (float)fmod((double)t * evo, 256.0)};
            ak_fractal_eval(noise, &fd, 4, p4, g[k]);
        }
        /* curl of psi(p / scale): derivatives carry 1 / scale */
        const ak_vec3 curl = ak_vec3_make(g[2][1] - g[1][2], g[0][2] - g[2][0], g[1][0] - g[0][1]);
        v = ak_vec3_add(v, ak_vec3_scale(curl, desc->turbulence / scale));
    }
    return finite3(v) ? v : ak_vec3_zero();
}

ak_result ak_noise_sway_validate(const ak_noise_sway_job* job) {
    if (!job || !job->noise || !job->pose.ptr || !job->amplitudes.ptr || !job->out_pose.ptr) return AK_ERR_NULL_ARG;
    const size_t n = job->pose.count;
    if (job->amplitudes.count < n || job->out_pose.count < n || (job->frequencies.ptr && job->frequencies.count < n) ||
        (job->translation_amplitudes.ptr && job->translation_amplitudes.count < n))
        return AK_ERR_SPAN_SMALL;
    if (!isfinite(job->time)) return AK_ERR_BAD_DATA;
    for (size_t j = 0; j < n; ++j) {
        if (!isfinite(job->amplitudes.ptr[j])) return AK_ERR_BAD_DATA;
        if (job->frequencies.ptr && !(job->frequencies.ptr[j] >= 0.0f && isfinite(job->frequencies.ptr[j])))
            return AK_ERR_BAD_DATA;
        if (job->translation_amplitudes.ptr && !isfinite(job->translation_amplitudes.ptr[j])) return AK_ERR_BAD_DATA;
    }
    return AK_OK;
}

/* Noise vector for joint j at phase s: three decorrelated 2D Perlin samples (the second
 * coordinate, a per-joint per-axis constant off the lattice, selects the "track"). */
static ak_vec3 sway_vec(const ak_noise* noise, float s, size_t j, int set) {
    const float row = (float)(j % 4096u) * 3.0f + (float)set * 12289.0f;
    return ak_vec3_make(ak_noise_perlin2(noise, s, row * 0.618034f + 0.31f, NULL),
                        ak_noise_perlin2(noise, s + 57.7f, row * 0.618034f + 1.47f, NULL),
                        ak_noise_perlin2(noise, s + 113.3f, row * 0.618034f + 2.29f, NULL));
}

ak_result ak_noise_sway_run(const ak_noise_sway_job* job) {
    const ak_result r = ak_noise_sway_validate(job);
    if (r != AK_OK) return r;
    for (size_t j = 0; j < job->pose.count; ++j) {
        ak_transform t = job->pose.ptr[j];
        const float freq = job->frequencies.ptr ? job->frequencies.ptr[j] : 0.5f;
        /* the phase wraps every 256 noise units (the noise's own period), so it stays exact
         * for long clocks */
        const float s = (float)fmod((double)job->time * freq, 256.0);
        const float amp = job->amplitudes.ptr[j];
        if (amp != 0.0f) {
            const ak_vec3 aa = ak_vec3_scale(sway_vec(job->noise, s, j, 0), amp);
            const float angle = ak_vec3_length(aa);
            if (angle > 0.0f) {
                const ak_quat delta = ak_quat_from_axis_angle(ak_vec3_scale(aa, 1.0f / angle), angle);
                t.rotation = ak_quat_normalize(ak_quat_mul(t.rotation, delta));
            }
        }
        if (job->translation_amplitudes.ptr && job->translation_amplitudes.ptr[j] != 0.0f)
            t.translation = ak_vec3_add(t.translation,
                                        ak_vec3_scale(sway_vec(job->noise, s, j, 1), job->translation_amplitudes.ptr[j]));
        job->out_pose.ptr[j] = t;
    }
    return AK_OK;
}
