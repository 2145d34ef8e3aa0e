/* Batch and grid evaluation: validation, thread fan-out, and the choice between the AVX-512
 * and AVX2 kernels and the scalar reference (and, within a path, between its two builds:
 * AVX-512 with VBMI byte permutes where the CPU has them; AVX2 with gathers where
 * akp_noise_avx2_gather_preferred says so). Points go through in chunks of CHUNK: the grid
 * job makes the chunk's coordinates on the stack, the kernel gets whole blocks of 16 (AVX-512)
 * or 8 (AVX2); a short tail is padded into one block, so it also runs the kernel and gives the
 * same bits. */
#include <math.h>
#include <string.h>

#include "tasks.h"
#include "noise_internal.h"

#define CHUNK 256u

enum { PATH_SCALAR = 0, PATH_AVX2 = 1, PATH_AVX512 = 2 };

bool akp_noise_simd_handles(const ak_fractal_desc* d, uint32_t dims) {
    return (dims == 2 || dims == 3) && d->warp == 0.0f &&
           (d->basis == AK_NOISE_BASIS_PERLIN || d->basis == AK_NOISE_BASIS_SIMPLEX ||
            d->basis == AK_NOISE_BASIS_VALUE || d->basis == AK_NOISE_BASIS_WORLEY) &&
           (d->type == AK_FRACTAL_FBM || d->type == AK_FRACTAL_TURBULENCE || d->type == AK_FRACTAL_RIDGED);
}

bool ak_noise_simd_available(void) {
#if defined(AK_NO_SIMD)
    return false;
#else
    return akp_noise_have_avx2() || akp_noise_have_avx512();
#endif
}

const char* ak_noise_simd_name(void) {
#if defined(AK_NO_SIMD)
    return "scalar";
#else
    return akp_noise_have_avx512() ? "avx512" : akp_noise_have_avx2() ? "avx2" : "scalar";
#endif
}

typedef struct eval_ctx {
    const ak_noise* noise;
    ak_fractal_desc desc; /* resolved */
    uint32_t dims;
    int path; /* PATH_* */
    bool alt; /* the other build of the path: PATH_AVX512 with VBMI, PATH_AVX2 with gathers */
} eval_ctx;

/* Evaluate count (<= CHUNK) points: xs[k][i] coordinates, out[i], grad[k][i] (grad NULL -> none). */
static void eval_chunk(const eval_ctx* c, const float* const* xs, size_t count, float* out, float* const* grad) {
    const uint32_t dims = c->dims;
    if (c->path != PATH_SCALAR) {
        const size_t w = c->path == PATH_AVX512 ? 16u : 8u;
        void (*kernel)(const ak_noise*, const ak_fractal_desc*, uint32_t, const float* const*, size_t, float*,
                       float* const*) = c->path == PATH_AVX2 ? (c->alt ? akp_noise_fractal_avx2gather : akp_noise_fractal_avx2)
                                        : c->alt ? akp_noise_fractal_avx512vbmi
                                                 : akp_noise_fractal_avx512;
        const size_t whole = count / w * w;
        if (whole) kernel(c->noise, &c->desc, dims, xs, whole, out, grad);
        const size_t done = whole;
        if (done < count) {
            float px[4][16], po[16], pg[4][16];
            const float* pxs[4];
            float* pgs[4];
            for (uint32_t k = 0; k < 4; ++k) {
                for (size_t i = 0; i < 16; ++i) px[k][i] = (k < dims && done + i < count) ? xs[k][done + i] : 0.0f;
                pxs[k] = px[k];
                pgs[k] = pg[k];
            }
            kernel(c->noise, &c->desc, dims, pxs, w, po, grad ? pgs : NULL);
            for (size_t i = done; i < count; ++i) {
                out[i] = po[i - done];
                if (grad)
                    for (uint32_t k = 0; k < dims; ++k) grad[k][i] = pg[k][i - done];
            }
        }
        return;
    }
    for (size_t i = 0; i < count; ++i) {
        float p[4], g[4];
        for (uint32_t k = 0; k < dims; ++k) p[k] = xs[k][i];
        out[i] = akp_fractal_point(c->noise, &c->desc, dims, p, grad ? g : NULL);
        if (grad)
            for (uint32_t k = 0; k < dims; ++k) grad[k][i] = g[k];
    }
}

static int pick_path(const ak_fractal_desc* d, uint32_t dims, bool skip, ak_noise_simd limit) {
#if defined(AK_NO_SIMD)
    (void)d, (void)dims, (void)skip, (void)limit;
    return PATH_SCALAR;
#else
    if (skip || limit == AK_NOISE_SIMD_SCALAR || !akp_noise_simd_handles(d, dims)) return PATH_SCALAR;
    if (limit != AK_NOISE_SIMD_AVX2 && akp_noise_have_avx512()) return PATH_AVX512;
    return akp_noise_have_avx2() ? PATH_AVX2 : PATH_SCALAR;
#endif
}

typedef struct range_task {
    const void* job;
    const eval_ctx* ctx;
    size_t begin, end; /* points (batch) or rows (grid) */
} range_task;

static void run_tasks(void* (*fn)(void*), range_task* tasks, uint32_t count) {
    akp_run_tasks(fn, tasks, sizeof(range_task), count);
}

/* ---- batch ------------------------------------------------------------------------------ */

static uint32_t job_dims(const ak_noise_job* job) { return job->dimensions ? job->dimensions : 3u; }

static bool has_gradient(const ak_noise_job* job) {
    return job->out_gradient_x.ptr || job->out_gradient_y.ptr || job->out_gradient_z.ptr || job->out_gradient_w.ptr;
}

ak_result ak_noise_job_validate(const ak_noise_job* job) {
    if (!job || !job->noise || !job->out_values.ptr) return AK_ERR_NULL_ARG;
    const uint32_t dims = job_dims(job);
    if (dims > 4 || job->thread_count > 64 || (unsigned)job->simd_limit >= AK_NOISE_SIMD_COUNT) return AK_ERR_BAD_ARG;
    if (ak_fractal_desc_validate(&job->fractal) != AK_OK) return AK_ERR_BAD_ARG;
    if (!ak_noise_basis_supports(ak_fractal_desc_resolved(&job->fractal).basis, dims)) return AK_ERR_BAD_ARG;
    const ak_f32_cspan in[4] = {job->x, job->y, job->z, job->w};
    const ak_f32_span gr[4] = {job->out_gradient_x, job->out_gradient_y, job->out_gradient_z, job->out_gradient_w};
    const size_t n = job->out_values.count;
    const bool want_grad = has_gradient(job);
    for (uint32_t k = 0; k < dims; ++k) {
        if (!in[k].ptr || (want_grad && !gr[k].ptr)) return AK_ERR_NULL_ARG;
    }
    for (uint32_t k = 0; k < dims; ++k) {
        if (in[k].count < n || (want_grad && gr[k].count < n)) return AK_ERR_SPAN_SMALL;
    }
    return AK_OK;
}

static void* batch_thread(void* arg) {
    const range_task* t = (const range_task*)arg;
    const ak_noise_job* job = (const ak_noise_job*)t->job;
    const uint32_t dims = t->ctx->dims;
    const ak_f32_cspan in[4] = {job->x, job->y, job->z, job->w};
    const ak_f32_span gr[4] = {job->out_gradient_x, job->out_gradient_y, job->out_gradient_z, job->out_gradient_w};
    const bool want_grad = has_gradient(job);
    for (size_t b = t->begin; b < t->end; b += CHUNK) {
        const size_t count = t->end - b < CHUNK ? t->end - b : CHUNK;
        const float* xs[4];
        float* gs[4];
        for (uint32_t k = 0; k < 4; ++k) {
            xs[k] = k < dims ? in[k].ptr + b : NULL;
            gs[k] = (k < dims && want_grad) ? gr[k].ptr + b : NULL;
        }
        eval_chunk(t->ctx, xs, count, job->out_values.ptr + b, want_grad ? gs : NULL);
    }
    return NULL;
}

ak_noise_simd ak_noise_job_kernel(const ak_noise_job* job) {
    if (ak_noise_job_validate(job) != AK_OK) return AK_NOISE_SIMD_SCALAR;
    const ak_fractal_desc d = ak_fractal_desc_resolved(&job->fractal);
    const int path = pick_path(&d, job_dims(job), job->skip_simd, job->simd_limit);
    return path == PATH_AVX512 ? AK_NOISE_SIMD_AVX512 : path == PATH_AVX2 ? AK_NOISE_SIMD_AVX2 : AK_NOISE_SIMD_SCALAR;
}

ak_result ak_noise_job_run(const ak_noise_job* job) {
    const ak_result r = ak_noise_job_validate(job);
    if (r != AK_OK) return r;
    eval_ctx ctx = {job->noise, ak_fractal_desc_resolved(&job->fractal), job_dims(job), PATH_SCALAR, false};
    ctx.path = pick_path(&ctx.desc, ctx.dims, job->skip_simd, job->simd_limit);
    ctx.alt = ctx.path == PATH_AVX512 ? akp_noise_have_avx512vbmi() : ctx.path == PATH_AVX2 && akp_noise_avx2_gather_preferred();
    const size_t n = job->out_values.count;
    uint32_t threads = job->thread_count > 1 ? job->thread_count : 1;
    if (threads > n / CHUNK + 1) threads = (uint32_t)(n / CHUNK + 1);
    range_task tasks[64];
    size_t chunk = (n + threads - 1) / threads;
    chunk = (chunk + 15u) & ~(size_t)15u;
    for (uint32_t t = 0; t < threads; ++t) {
        size_t b = (size_t)t * chunk, e = b + chunk;
        tasks[t] = (range_task){job, &ctx, b < n ? b : n, e < n ? e : n};
    }
    run_tasks(batch_thread, tasks, threads);
    return AK_OK;
}

/* ---- grid -------------------------------------------------------------------------------- */

ak_result ak_noise_grid_job_validate(const ak_noise_grid_job* job) {
    if (!job || !job->noise || !job->out_values.ptr) return AK_ERR_NULL_ARG;
    if (job->width == 0 || job->height == 0 || job->thread_count > 64 || (unsigned)job->simd_limit >= AK_NOISE_SIMD_COUNT)
        return AK_ERR_BAD_ARG;
    if (!isfinite(job->origin_x) || !isfinite(job->origin_y) || !isfinite(job->spacing_x) || !isfinite(job->spacing_y))
        return AK_ERR_BAD_ARG;
    if (ak_fractal_desc_validate(&job->fractal) != AK_OK) return AK_ERR_BAD_ARG;
    if ((job->out_gradient_x.ptr != NULL) != (job->out_gradient_y.ptr != NULL)) return AK_ERR_NULL_ARG;
    const size_t n = (size_t)job->width * job->height;
    if (n / job->width != job->height) return AK_ERR_BAD_ARG;
    if (job->out_values.count < n) return AK_ERR_SPAN_SMALL;
    if (job->out_gradient_x.ptr && (job->out_gradient_x.count < n || job->out_gradient_y.count < n))
        return AK_ERR_SPAN_SMALL;
    return AK_OK;
}

static void* grid_thread(void* arg) {
    const range_task* t = (const range_task*)arg;
    const ak_noise_grid_job* job = (const ak_noise_grid_job*)t->job;
    const float sx = job->spacing_x != 0.0f ? job->spacing_x : 1.0f;
    const float sy = job->spacing_y != 0.0f ? job->spacing_y : 1.0f;
    const bool want_grad = job->out_gradient_x.ptr != NULL;
    float bx[CHUNK], by[CHUNK];
    for (size_t j = t->begin; j < t->end; ++j) {
        const float y = job->origin_y + (float)j * sy;
        for (size_t i0 = 0; i0 < job->width; i0 += CHUNK) {
            const size_t count = job->width - i0 < CHUNK ? job->width - i0 : CHUNK;
            for (size_t i = 0; i < count; ++i) {
                bx[i] = job->origin_x + (float)(i0 + i) * sx;
                by[i] = y;
            }
            const size_t at = j * job->width + i0;
            const float* xs[4] = {bx, by, NULL, NULL};
            float* gs[4] = {want_grad ? job->out_gradient_x.ptr + at : NULL, want_grad ? job->out_gradient_y.ptr + at : NULL,
                            NULL, NULL};
            eval_chunk(t->ctx, xs, count, job->out_values.ptr + at, want_grad ? gs : NULL);
        }
    }
    return NULL;
}

ak_result ak_noise_grid_job_run(const ak_noise_grid_job* job) {
    const ak_result r = ak_noise_grid_job_validate(job);
    if (r != AK_OK) return r;
    eval_ctx ctx = {job->noise, ak_fractal_desc_resolved(&job->fractal), 2, PATH_SCALAR, false};
    ctx.path = pick_path(&ctx.desc, 2, job->skip_simd, job->simd_limit);
    ctx.alt = ctx.path == PATH_AVX512 ? akp_noise_have_avx512vbmi() : ctx.path == PATH_AVX2 && akp_noise_avx2_gather_preferred();
    const size_t rows = job->height;
    uint32_t threads = job->thread_count > 1 ? job->thread_count : 1;
    if (threads > rows) threads = (uint32_t)rows;
    range_task tasks[64];
    const size_t chunk = (rows + threads - 1) / threads;
    for (uint32_t t = 0; t < threads; ++t) {
        size_t b = (size_t)t * chunk, e = b + chunk;
        tasks[t] = (range_task){job, &ctx, b < rows ? b : rows, e < rows ? e : rows};
    }
    run_tasks(grid_thread, tasks, threads);
    return AK_OK;
}
