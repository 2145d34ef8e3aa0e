/* The many-character frame of bench/bench_crowd_frame.c (bench/crowd_frame.h): the same bits
 * for any thread count, and each character's skinned vertices equal to an independent
 * double-precision path (clip sampled without a cursor, FK, palette and LBS with normals in
 * double). CesiumMan joins builtin:humanoid when $ANIMKIT_ASSETS (or ../shared/assets) has it. */
#include "ak_test.h"
#include "../bench/crowd_frame.h"

static const char* cesium_path(void) {
    static char path[2048];
    return ak_test_asset(path, sizeof path, "gltf/CesiumMan/glTF-Binary/CesiumMan.glb");
}

/* Every output of every character, concatenated (positions, then normals, per character). */
static size_t crowd_outputs(const crowd* c, float* out) {
    size_t n = 0;
    for (size_t i = 0; i < c->count; ++i) {
        const size_t v = c->chars[i].m->mesh->vertex_count * 3;
        if (out) memcpy(out + n, c->chars[i].out_p, v * sizeof(float)), memcpy(out + n + v, c->chars[i].out_n, v * sizeof(float));
        n += 2 * v;
    }
    return n;
}

AK_TEST(threads_bit_identical) {
    enum { CHARS = 24, FRAMES = 3 };
    /* static ranges on 1, 2, 3 and 16 threads, then the dynamic schedule on 2, 3 and 16; one
     * crowd, its outputs zeroed before each run (the cursors carry over: where a cursor stood
     * must not change the bits either) */
    const uint32_t threads[] = {1, 2, 3, 16, 2, 3, 16};
    crowd c;
    bool missing = false;
    AK_CHECK(crowd_init(&c, CHARS, cesium_path(), &missing));
    if (missing) printf("  (CesiumMan not found: builtin:humanoid only)\n");
    const size_t n = crowd_outputs(&c, NULL);
    float* ref = malloc(n * sizeof(float));
    float* got = malloc(n * sizeof(float));
    AK_CHECK(ref && got);
    for (size_t k = 0; ref && got && k < sizeof threads / sizeof threads[0]; ++k) {
        c.dynamic = k >= 4;
        /* the static partition covers every character once, in order */
        size_t prev = 0;
        for (uint32_t t = 0; t <= threads[k]; ++t) {
            const size_t b = crowd_split(&c, t, threads[k]);
            AK_CHECK(b >= prev);
            prev = b;
        }
        AK_CHECK_EQ(prev, (size_t)CHARS);
        for (size_t i = 0; i < c.count; ++i) {
            const size_t v = c.chars[i].m->mesh->vertex_count;
            memset(c.chars[i].out_p, 0, v * sizeof(ak_vec3)), memset(c.chars[i].out_n, 0, v * sizeof(ak_vec3));
        }
        bool ok = true;
        for (uint64_t f = 0; f < FRAMES; ++f) ok = crowd_frame(&c, f * 7, threads[k], f == 0) && ok;
        AK_CHECK(ok);
        crowd_outputs(&c, k == 0 ? ref : got);
        if (k > 0)
            AK_CHECK_MSG(memcmp(got, ref, n * sizeof(float)) == 0, "%u threads (%s): bits differ from 1 thread",
                         threads[k], c.dynamic ? "dynamic" : "static");
    }
    free(ref), free(got);
    crowd_fini(&c);
}

/* ---- the independent path, in double ---- */

typedef struct dmat4 { double m[16]; } dmat4; /* column-major, as ak_mat4 */

static dmat4 dmul(const dmat4* a, const dmat4* b) {
    dmat4 r;
    for (int c = 0; c < 4; ++c)
        for (int row = 0; row < 4; ++row) {
            double s = 0.0;
            for (int k = 0; k < 4; ++k) s += a->m[k * 4 + row] * b->m[c * 4 + k];
            r.m[c * 4 + row] = s;
        }
    return r;
}

/* T * R * S of a transform, in double. */
static dmat4 dtrs(const ak_transform* t) {
    const double x = t->rotation.x, y = t->rotation.y, z = t->rotation.z, w = t->rotation.w;
    const double l = sqrt(x * x + y * y + z * z + w * w);
    const double qx = x / l, qy = y / l, qz = z / l, qw = w / l;
    const double R[9] = {1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy + qz * qw), 2 * (qx * qz - qy * qw),
                         2 * (qx * qy - qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz + qx * qw),
                         2 * (qx * qz + qy * qw), 2 * (qy * qz - qx * qw), 1 - 2 * (qx * qx + qy * qy)};
    const double s[3] = {t->scale.x, t->scale.y, t->scale.z};
    dmat4 m = {{0}};
    for (int c = 0; c < 3; ++c)
        for (int row = 0; row < 3; ++row) m.m[c * 4 + row] = R[c * 3 + row] * s[c];
    m.m[12] = t->translation.x, m.m[13] = t->translation.y, m.m[14] = t->translation.z, m.m[15] = 1.0;
    return m;
}

/* Compare character ch's outputs after frame with the double path; returns the largest
 * position error (metres) and writes the largest normal error (unit vectors, both normalised). */
static double reference_error(const crowd_character* ch, uint64_t frame, double* out_normal_err) {
    const crowd_model* m = ch->m;
    const ak_scene* sc = m->scene;
    const size_t nj = m->joints;
    ak_transform* local = malloc(nj * sizeof *local);
    dmat4* world = malloc(nj * sizeof *world);
    dmat4* pal = malloc(m->palette_count * sizeof *pal);
    double err = INFINITY;
    *out_normal_err = INFINITY;
    if (!local || !world || !pal) goto done;
    /* the clip's time, independently: offset + frame / 60 looped over the duration */
    const double dur = ak_clip_duration(ch->clip);
    const float t = (float)fmod(ch->offset + (double)frame / 60.0, dur);
    ak_scene_rest_pose(sc, (ak_transform_span){local, nj});
    ak_clip_sample(ch->clip, t, NULL, (ak_transform_span){local, nj}, (ak_f32_span){0}, (ak_f32_span){0});
    const ak_i32_cspan parents = ak_skeleton_parents(sc->skeleton);
    for (size_t j = 0; j < nj; ++j) {
        const dmat4 l = dtrs(&local[j]);
        world[j] = parents.ptr[j] < 0 ? l : dmul(&world[parents.ptr[j]], &l);
    }
    const ak_scene_skin* sk = &sc->skins[m->sm->skin];
    for (size_t k = 0; k < m->palette_count; ++k) {
        dmat4 ib;
        for (int e = 0; e < 16; ++e) ib.m[e] = sk->inverse_binds[k].m[e];
        pal[k] = dmul(&world[sk->joints[k]], &ib);
    }
    const ak_mesh* mesh = m->mesh;
    const uint32_t ni = mesh->influence_count;
    err = 0.0, *out_normal_err = 0.0;
    for (size_t v = 0; v < mesh->vertex_count; ++v) {
        double A[16] = {0};
        for (uint32_t k = 0; k < ni; ++k) {
            const double w = mesh->weights[v * ni + k];
            const dmat4* M = &pal[mesh->joints[v * ni + k]];
            for (int e = 0; e < 16; ++e) A[e] += w * M->m[e];
        }
        const double p[3] = {mesh->positions[v].x, mesh->positions[v].y, mesh->positions[v].z};
        double q[3];
        for (int r = 0; r < 3; ++r) q[r] = A[r] * p[0] + A[4 + r] * p[1] + A[8 + r] * p[2] + A[12 + r];
        const ak_vec3 o = ch->out_p[v];
        const double e = fmax(fabs(o.x - q[0]), fmax(fabs(o.y - q[1]), fabs(o.z - q[2])));
        if (!(e <= err)) err = e; /* NaN sticks */
        if (!mesh->normals) continue;
        /* the inverse transpose of the blended 3x3, up to scale: its cofactor matrix */
        const double a = A[0], b = A[4], c = A[8], d = A[1], ee = A[5], f = A[9], g = A[2], h = A[6], i = A[10];
        const double C[9] = {ee * i - f * h, -(d * i - f * g), d * h - ee * g,   /* row 0 */
                             -(b * i - c * h), a * i - c * g, -(a * h - b * g), /* row 1 */
                             b * f - c * ee, -(a * f - c * d), a * ee - b * d}; /* row 2 */
        const double nn[3] = {mesh->normals[v].x, mesh->normals[v].y, mesh->normals[v].z};
        double r[3];
        for (int row = 0; row < 3; ++row) r[row] = C[row * 3] * nn[0] + C[row * 3 + 1] * nn[1] + C[row * 3 + 2] * nn[2];
        const double rl = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
        const ak_vec3 on = ch->out_n[v];
        const double ol = sqrt((double)on.x * on.x + (double)on.y * on.y + (double)on.z * on.z);
        const double ne = fmax(fabs(on.x / ol - r[0] / rl), fmax(fabs(on.y / ol - r[1] / rl), fabs(on.z / ol - r[2] / rl)));
        if (!(ne <= *out_normal_err)) *out_normal_err = ne;
    }
done:
    free(local), free(world), free(pal);
    return err;
}

AK_TEST(characters_match_double_reference) {
    crowd c;
    bool missing = false;
    AK_CHECK(crowd_init(&c, 6, cesium_path(), &missing));
    if (missing) printf("  (CesiumMan not found: builtin:humanoid only)\n");
    /* frames 0, 1, then 83 (past a loop of the 1 s walk), on 2 threads */
    const uint64_t frames[] = {0, 1, 83};
    double worst_p = 0.0, worst_n = 0.0;
    for (size_t k = 0; k < 3; ++k) {
        AK_CHECK(crowd_frame(&c, frames[k], 2, k == 0));
        for (size_t i = 0; i < c.count; ++i) {
            double nerr = 0.0;
            const double perr = reference_error(&c.chars[i], frames[k], &nerr);
            worst_p = fmax(worst_p, perr), worst_n = fmax(worst_n, nerr);
            AK_CHECK_MSG(perr < 1e-5, "frame %llu character %zu (%s): position error %g m",
                         (unsigned long long)frames[k], i, c.chars[i].m->scene->name, perr);
            AK_CHECK_MSG(nerr < 1e-5, "frame %llu character %zu (%s): normal error %g",
                         (unsigned long long)frames[k], i, c.chars[i].m->scene->name, nerr);
        }
    }
    printf("  largest error: position %.3g m, normal %.3g\n", worst_p, worst_n);
    crowd_fini(&c);
}

int main(void) {
    AK_RUN(threads_bit_identical);
    AK_RUN(characters_match_double_reference);
    return ak_test_finish();
}
