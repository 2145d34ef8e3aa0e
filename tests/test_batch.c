/* animkit batch (ak_batch_run_job): FNV-1a 64 against its published test vectors and a loop
 * written here, job lines with errors naming key paths, shards covering every job once, a
 * retarget of CMU BVH onto builtin:humanoid whose output re-loads with the source clip's
 * duration, re-runs that skip, changed parameters that run again, a bake whose clip lasts its
 * steps, and bad jobs that are rows with an error, never a crash. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <animkit/batch.h>
#include <animkit/builtin.h>
#include <animkit/clip.h>
#include <animkit/raster.h>
#include <animkit/view.h>
#include <animkit/io.h>
#include <animkit/scene.h>
#include <cjson/cJSON.h>

#include "ak_test.h"

/* FNV-1a 64 written out here (the reference: offset basis and prime of the FNV specification). */
static uint64_t fnv_reference(const unsigned char* p, size_t n) {
    uint64_t h = 14695981039346656037ull;
    for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

static ak_batch_row row; /* large: static */

static ak_result run_line(const char* line, const char* out_dir, bool force) {
    ak_batch_desc d = {.name = "m.jsonl:1", .output_dir = out_dir, .force = force, .index = 7};
    return ak_batch_run_job(line, strlen(line), &d, &row);
}

/* The row parsed (NULL with a failed check when it is not JSON). */
static cJSON* row_json(void) {
    cJSON* o = cJSON_Parse(row.json);
    AK_CHECK_MSG(o != NULL, "row is not JSON: %s", row.json);
    return o;
}

static const char* str_at(const cJSON* o, const char* a, const char* b, const char* c) {
    const cJSON* v = cJSON_GetObjectItemCaseSensitive(o, a);
    if (b) v = cJSON_GetObjectItemCaseSensitive(v, b);
    if (c) v = cJSON_GetObjectItemCaseSensitive(v, c);
    return cJSON_IsString(v) ? v->valuestring : NULL;
}

AK_TEST(fnv1a_vectors_and_files) {
    /* published FNV-1a 64 vectors */
    AK_CHECK_EQ(ak_batch_hash_bytes(AK_BATCH_FNV_BASIS, "", 0), 0xcbf29ce484222325ull);
    AK_CHECK_EQ(ak_batch_hash_bytes(AK_BATCH_FNV_BASIS, "a", 1), 0xaf63dc4c8601ec8cull);
    AK_CHECK_EQ(ak_batch_hash_bytes(AK_BATCH_FNV_BASIS, "foobar", 6), 0x85944171f73967e8ull);
    /* a file of 200 KB (more than one read block) against the loop above */
    const size_t n = 200000;
    unsigned char* buf = malloc(n);
    AK_CHECK(buf != NULL);
    if (!buf) return;
    for (size_t i = 0; i < n; ++i) buf[i] = (unsigned char)(i * 2654435761u >> 13);
    FILE* f = fopen("test_batch_hash.bin", "wb");
    AK_CHECK(f && fwrite(buf, 1, n, f) == n);
    if (f) fclose(f);
    uint64_t h = 0;
    AK_CHECK_EQ(ak_batch_hash_file("test_batch_hash.bin", &h), AK_OK);
    AK_CHECK_EQ(h, fnv_reference(buf, n));
    AK_CHECK_EQ(ak_batch_hash_file("test_batch_missing.bin", &h), AK_ERR_IO);
    remove("test_batch_hash.bin");
    free(buf);
}

AK_TEST(job_lines_with_errors) {
    static const struct {
        const char* line;
        const char* message;
    } cases[] = {
        {"{\"inputs\": {}, \"output\": \"a.glb\"}", "j: kind: is required"},
        {"{\"kind\": \"retarget\", \"inputs\": {\"source\": \"a.bvh\", \"target\": \"builtin:humanoid\"}}",
         "j: output: is required"},
        {"{\"kind\": \"retarget\", \"inputs\": {\"source\": \"a.bvh\"}, \"output\": \"a.glb\"}",
         "j: inputs.target: is required"},
        {"{\"kind\": \"retarget\", \"inputs\": {\"source\": \"a.bvh\", \"target\": \"b\"}, \"parameters\": {\"fps\": 0},"
         " \"output\": \"a.glb\"}",
         "j: parameters.fps: 0 is outside [1, 1000]"},
        {"{\"kind\": \"bake\", \"inputs\": {\"scene\": \"preset:dam\"}, \"parameters\": {\"sim\": \"fluid\", \"speed\": 1},"
         " \"output\": \"a.glb\"}",
         "j: parameters: unknown key \"speed\" (allowed: sim, steps, count, frame_every)"},
        {"{\"kind\": \"bake\", \"inputs\": {\"scene\": \"s.json\"}, \"output\": \"a.glb\"}",
         "j: parameters.sim: is required (fluid, particles, cloth or boids)"},
        {"{\"kind\": \"render\", \"inputs\": {\"model\": 3}, \"output\": \"a.png\"}",
         "j: inputs.model: expected a string, got a number"},
        {"{\"kind\": \"render\", \"inputs\": {\"model\": \"m\"}, \"parameters\": {\"size\": [8.5, 9]}, \"output\": \"a.png\"}",
         "j: parameters.size: expected whole pixels"},
        {"[]", "j: the top level is not an object (got an array)"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        ak_batch_job job;
        ak_diag d;
        AK_CHECK_EQ(ak_batch_job_parse(cases[k].line, strlen(cases[k].line), "j", &job, &d), AK_ERR_PARSE);
        AK_CHECK_STREQ(d.message, cases[k].message);
        AK_CHECK_EQ(job.kind, AK_BATCH_KIND_NONE);
    }
    /* a good line: values and defaults */
    const char* ok = "{\"kind\": \"retarget\", \"id\": \"w\", \"inputs\": {\"source\": \"a.bvh\", \"target\": \"builtin:humanoid\"},"
                     " \"parameters\": {\"clip\": 2}, \"output\": \"o/a.glb\"}";
    ak_batch_job job;
    AK_CHECK_EQ(ak_batch_job_parse(ok, strlen(ok), "j", &job, NULL), AK_OK);
    AK_CHECK_EQ(job.kind, AK_BATCH_RETARGET);
    AK_CHECK_STREQ(job.clip, "2");
    AK_CHECK_STREQ(job.id, "w");
    AK_CHECK_NEAR(job.fps, 30.0f, 0.0f);
    /* a line over the budget is refused before parsing */
    size_t big = AK_BATCH_MAX_LINE_SIZE + 10;
    char* line = malloc(big);
    AK_CHECK(line != NULL);
    if (line) {
        memset(line, ' ', big);
        ak_diag d;
        AK_CHECK_EQ(ak_batch_job_parse(line, big, "j", &job, &d), AK_ERR_PARSE);
        AK_CHECK(strstr(d.message, "longer than 65536 bytes") != NULL);
        free(line);
    }
}

AK_TEST(shards_cover_each_job_once) {
    for (long n = 1; n <= 7; ++n)
        for (long k = 0; k < 100; ++k) {
            int hits = 0;
            for (long i = 0; i < n; ++i) hits += ak_batch_in_shard(k, i, n);
            AK_CHECK_MSG(hits == 1, "job %ld in %d of %ld shards", k, hits, n);
        }
    AK_CHECK(!ak_batch_in_shard(0, 1, 1) && !ak_batch_in_shard(0, -1, 2) && !ak_batch_in_shard(0, 0, 0));
}

AK_TEST(retarget_bvh_rerun_skips) {
    char bvh[1200];
    if (!ak_test_asset(bvh, sizeof bvh, "bvh/49_04.bvh")) {
        AK_SKIP("bvh/49_04.bvh absent (set ANIMKIT_ASSETS)");
        return;
    }
    char line[2000];
    snprintf(line, sizeof line,
             "{\"kind\": \"retarget\", \"inputs\": {\"source\": \"%s\", \"target\": \"builtin:humanoid\"},"
             " \"parameters\": {\"skip_foot_contacts\": true}, \"output\": \"walk.glb\"}",
             bvh);
    remove("test_batch_out/walk.glb");
    remove("test_batch_out/walk.glb" AK_BATCH_RECORD_SUFFIX);
    AK_CHECK_EQ(run_line(line, "test_batch_out", false), AK_OK);
    AK_CHECK_EQ(row.status, AK_BATCH_RAN);
    AK_CHECK_STREQ(row.output, "test_batch_out/walk.glb");
    /* the row: the source's hash is FNV-1a 64 of its bytes, the index and version as given */
    cJSON* o = row_json();
    FILE* f = fopen(bvh, "rb");
    static unsigned char buf[1 << 21];
    size_t n = f ? fread(buf, 1, sizeof buf, f) : 0;
    if (f) fclose(f);
    char want[17];
    snprintf(want, sizeof want, "%016llx", (unsigned long long)fnv_reference(buf, n));
    const char* got = str_at(o, "inputs", "source", "fnv1a64");
    AK_CHECK(got && strcmp(got, want) == 0);
    AK_CHECK_STREQ(str_at(o, "status", NULL, NULL), "ran");
    AK_CHECK_STREQ(str_at(o, "animkit_version", NULL, NULL), ak_version_string());
    AK_CHECK(cJSON_IsNull(cJSON_GetObjectItemCaseSensitive(o, "error")));
    AK_CHECK_EQ(cJSON_GetObjectItemCaseSensitive(o, "index")->valuedouble, 7.0);
    cJSON_Delete(o);
    /* the output re-loads: the target's joints, one clip as long as the source's */
    ak_scene *out = NULL, *src = NULL;
    AK_CHECK_EQ(ak_io_load("test_batch_out/walk.glb", NULL, NULL, &out, NULL), AK_OK);
    AK_CHECK_EQ(ak_io_load(bvh, NULL, NULL, &src, NULL), AK_OK);
    if (out && src) {
        AK_CHECK_EQ(out->clip_count, 1u);
        if (out->clip_count == 1 && src->clip_count >= 1)
            AK_CHECK_MSG(fabsf(ak_clip_duration(out->clips[0]) - ak_clip_duration(src->clips[0])) <= 1.0f / 30.0f + 1e-4f,
                         "%g s vs %g s", (double)ak_clip_duration(out->clips[0]), (double)ak_clip_duration(src->clips[0]));
    }
    ak_scene_destroy(out);
    ak_scene_destroy(src);
    /* a re-run skips it (other parameters run it again: bake_lasts_its_steps) */
    struct stat st0, st1;
    stat("test_batch_out/walk.glb", &st0);
    double frames_ran = -1.0;
    cJSON* o1 = row_json();
    if (o1 && cJSON_IsNumber(cJSON_GetObjectItemCaseSensitive(o1, "frames")))
        frames_ran = cJSON_GetObjectItemCaseSensitive(o1, "frames")->valuedouble;
    cJSON_Delete(o1);
    AK_CHECK_EQ(run_line(line, "test_batch_out", false), AK_OK);
    AK_CHECK_EQ(row.status, AK_BATCH_SKIPPED);
    /* the skipped row repeats the frame count of the run that wrote the output */
    cJSON* o2 = row_json();
    const cJSON* f2 = o2 ? cJSON_GetObjectItemCaseSensitive(o2, "frames") : NULL;
    AK_CHECK_MSG(frames_ran > 0.0 && cJSON_IsNumber(f2) && f2->valuedouble == frames_ran, "frames %g then %g", frames_ran,
                 cJSON_IsNumber(f2) ? f2->valuedouble : -1.0);
    cJSON_Delete(o2);
    stat("test_batch_out/walk.glb", &st1);
    AK_CHECK(st0.st_ino == st1.st_ino); /* not rewritten (a rewrite renames a new file over it) */
}

AK_TEST(bake_lasts_its_steps) {
    const char* line = "{\"kind\": \"bake\", \"inputs\": {\"scene\": \"preset:dam\"},"
                       " \"parameters\": {\"sim\": \"fluid\", \"steps\": 8, \"count\": 200}, \"output\": \"dam.glb\"}";
    AK_CHECK_EQ(run_line(line, "test_batch_out", true), AK_OK);
    AK_CHECK_EQ(row.status, AK_BATCH_RAN);
    ak_scene* out = NULL;
    AK_CHECK_EQ(ak_io_load("test_batch_out/dam.glb", NULL, NULL, &out, NULL), AK_OK);
    if (out) {
        AK_CHECK_EQ(out->clip_count, 1u);
        /* 8 steps of the preset's 1/400 s */
        if (out->clip_count == 1) AK_CHECK_NEAR(ak_clip_duration(out->clips[0]), 8.0f / 400.0f, 1e-5f);
    }
    ak_scene_destroy(out);
    /* a particle scene (the fountain example, dt 0.01) runs as `animkit particles` runs it */
    const char* pl = "{\"kind\": \"bake\", \"inputs\": {\"scene\": \"" AK_SOURCE_DIR "/examples/particles_fountain.json\"},"
                     " \"parameters\": {\"sim\": \"particles\", \"steps\": 30, \"frame_every\": 5}, \"output\": \"fountain.glb\"}";
    AK_CHECK_EQ(run_line(pl, "test_batch_out", true), AK_OK);
    AK_CHECK_MSG(row.status == AK_BATCH_RAN, "%s", row.error);
    AK_CHECK(strstr(row.json, "\"frames\":7") != NULL); /* steps 0, 5, ..., 30 */
    out = NULL;
    AK_CHECK_EQ(ak_io_load("test_batch_out/fountain.glb", NULL, NULL, &out, NULL), AK_OK);
    if (out && out->clip_count == 1) AK_CHECK_NEAR(ak_clip_duration(out->clips[0]), 0.30f, 1e-5f);
    ak_scene_destroy(out);
    /* cloth (the flag preset, dt 1/60) and boids (the predator preset, dt 0.02) run as their
     * commands run them; a cloth scene with a character is the command's */
    const char* cl = "{\"kind\": \"bake\", \"inputs\": {\"scene\": \"preset:flag\"},"
                     " \"parameters\": {\"sim\": \"cloth\", \"steps\": 12, \"frame_every\": 3}, \"output\": \"flag.glb\"}";
    AK_CHECK_EQ(run_line(cl, "test_batch_out", true), AK_OK);
    AK_CHECK_MSG(row.status == AK_BATCH_RAN && strstr(row.json, "\"frames\":5"), "%s", row.json);
    out = NULL;
    AK_CHECK_EQ(ak_io_load("test_batch_out/flag.glb", NULL, NULL, &out, NULL), AK_OK);
    if (out && out->clip_count == 1) AK_CHECK_NEAR(ak_clip_duration(out->clips[0]), 12.0f / 60.0f, 1e-5f);
    if (out) AK_CHECK(out->mesh_count == 1 && out->meshes[0].mesh && out->meshes[0].mesh->vertex_count == 640);
    ak_scene_destroy(out);
    const char* bo = "{\"kind\": \"bake\", \"inputs\": {\"scene\": \"preset:predator\"},"
                     " \"parameters\": {\"sim\": \"boids\", \"steps\": 10, \"count\": 100}, \"output\": \"boids.glb\"}";
    AK_CHECK_EQ(run_line(bo, "test_batch_out", true), AK_OK);
    AK_CHECK_MSG(row.status == AK_BATCH_RAN && strstr(row.json, "\"frames\":11"), "%s", row.json);
    out = NULL;
    AK_CHECK_EQ(ak_io_load("test_batch_out/boids.glb", NULL, NULL, &out, NULL), AK_OK);
    if (out && out->clip_count == 1) AK_CHECK_NEAR(ak_clip_duration(out->clips[0]), 10.0f * 0.02f, 1e-5f);
    ak_scene_destroy(out);
    const char* cape = "{\"kind\": \"bake\", \"inputs\": {\"scene\": \"preset:cape\"}, \"parameters\": {\"sim\": \"cloth\"},"
                       " \"output\": \"cape.glb\"}";
    AK_CHECK(run_line(cape, "test_batch_out", true) != AK_OK);
    AK_CHECK(strstr(row.error, "character") != NULL);
    /* the same job skips; other parameters run; a record of another job does not count */
    AK_CHECK_EQ(run_line(line, "test_batch_out", false), AK_OK);
    AK_CHECK_EQ(row.status, AK_BATCH_SKIPPED);
    const char* ten = "{\"kind\": \"bake\", \"inputs\": {\"scene\": \"preset:dam\"},"
                      " \"parameters\": {\"sim\": \"fluid\", \"steps\": 4, \"count\": 200}, \"output\": \"dam.glb\"}";
    AK_CHECK_EQ(run_line(ten, "test_batch_out", false), AK_OK);
    AK_CHECK_EQ(row.status, AK_BATCH_RAN);
    AK_CHECK_EQ(run_line(line, "test_batch_out", false), AK_OK);
    AK_CHECK_EQ(row.status, AK_BATCH_RAN);
    /* force runs an up-to-date job */
    AK_CHECK_EQ(run_line(line, "test_batch_out", true), AK_OK);
    AK_CHECK_EQ(row.status, AK_BATCH_RAN);
    /* the output gone: the job runs again although its record is there */
    remove("test_batch_out/dam.glb");
    AK_CHECK_EQ(run_line(line, "test_batch_out", false), AK_OK);
    AK_CHECK_EQ(row.status, AK_BATCH_RAN);
}

AK_TEST(bad_jobs_are_rows) {
    const char* lines[] = {
        ("{\"kind\": \"retarget\", \"inputs\": {\"source\": \"no/such.bvh\", \"target\": \"builtin:humanoid\"},"
         " \"output\": \"x.glb\"}"),
        "{\"kind\": \"render\", \"inputs\": {\"model\": \"builtin:nobody\"}, \"output\": \"x.png\"}",
        "{\"kind\": \"bake\", \"inputs\": {\"scene\": \"preset:lake\"}, \"parameters\": {\"sim\": \"fluid\"}, \"output\": \"x.glb\"}",
        "{\"kind\": \"retarget\"",
        "",
    };
    const char* expect[] = {"inputs.source", "inputs.model", "inputs.scene", "invalid JSON", "invalid JSON"};
    for (size_t k = 0; k < sizeof lines / sizeof lines[0]; ++k) {
        AK_CHECK(run_line(lines[k], "test_batch_out", false) != AK_OK);
        AK_CHECK_EQ(row.status, AK_BATCH_FAILED);
        AK_CHECK_MSG(strstr(row.error, expect[k]) != NULL, "%s", row.error);
        cJSON* o = row_json();
        AK_CHECK_STREQ(str_at(o, "status", NULL, NULL), "failed");
        AK_CHECK_STREQ(str_at(o, "error", NULL, NULL), row.error);
        cJSON_Delete(o);
    }
    struct stat st;
    AK_CHECK(stat("test_batch_out/x.glb", &st) != 0 && stat("test_batch_out/x.png", &st) != 0);
    AK_CHECK_EQ(ak_batch_run_job(NULL, 3, NULL, &row), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(row.status, AK_BATCH_FAILED);
    AK_CHECK_EQ(ak_batch_run_job("{}", 2, NULL, NULL), AK_ERR_NULL_ARG);
}

/* ---- render: the skinned meshes, posed ---------------------------------------------------- */

/* The model posed at time t with a naive LBS written here (per vertex sum_k w_k M_k p, normals
 * by the palette's 3x3 part), drawn by the view module with the job's documented framing
 * (docs/batch.md: an orbit at azimuth 0.5 rad, elevation 0.25 rad over the posed bounds). */
static void reference_render(const ak_scene* sc, float t, bool posed, const ak_image* img) {
    const size_t nj = ak_scene_joint_count(sc);
    ak_transform* local = calloc(nj, sizeof *local);
    ak_mat4* world = calloc(nj, sizeof *world);
    ak_scene_rest_pose(sc, (ak_transform_span){local, nj});
    if (posed) ak_clip_sample(sc->clips[0], t, NULL, (ak_transform_span){local, nj}, (ak_f32_span){0}, (ak_f32_span){0});
    ak_scene_world_matrices(sc, (ak_transform_cspan){local, nj}, (ak_mat4_span){world, nj});
    ak_raster_mesh draws[8];
    ak_vec3* bufs[8] = {NULL};
    size_t count = 0;
    for (size_t m = 0; m < sc->mesh_count && count < 8; ++m) {
        const ak_scene_mesh* sm = &sc->meshes[m];
        const ak_mesh* mesh = sm->mesh;
        const ak_scene_skin* skin = &sc->skins[sm->skin];
        ak_mat4* pal = calloc(skin->joint_count, sizeof *pal);
        for (size_t k = 0; k < skin->joint_count; ++k) pal[k] = ak_mat4_mul(world[skin->joints[k]], skin->inverse_binds[k]);
        const size_t v = mesh->vertex_count;
        ak_vec3* b = bufs[count] = calloc(2 * v, sizeof(ak_vec3));
        for (size_t i = 0; i < v; ++i) {
            ak_vec3 p = {0, 0, 0}, n = {0, 0, 0};
            for (uint32_t k = 0; k < mesh->influence_count; ++k) {
                const float w = mesh->weights[i * mesh->influence_count + k];
                const float* M = pal[mesh->joints[i * mesh->influence_count + k]].m;
                const ak_vec3 q = mesh->positions[i], o = mesh->normals[i];
                p.x += w * (M[0] * q.x + M[4] * q.y + M[8] * q.z + M[12]);
                p.y += w * (M[1] * q.x + M[5] * q.y + M[9] * q.z + M[13]);
                p.z += w * (M[2] * q.x + M[6] * q.y + M[10] * q.z + M[14]);
                n.x += w * (M[0] * o.x + M[4] * o.y + M[8] * o.z);
                n.y += w * (M[1] * o.x + M[5] * o.y + M[9] * o.z);
                n.z += w * (M[2] * o.x + M[6] * o.y + M[10] * o.z);
            }
            b[i] = p, b[v + i] = ak_vec3_normalize(n);
        }
        free(pal);
        draws[count] = ak_view_raster_mesh(mesh);
        draws[count].positions = (ak_vec3_cspan){b, v};
        draws[count].normals = (ak_vec3_cspan){b + v, v};
        if (sm->has_material) draws[count].material.color = sm->base_color;
        count++;
    }
    ak_view_scene view = {.meshes = draws, .mesh_count = count};
    ak_vec3 lo, hi;
    ak_view_scene_bounds(&view, &lo, &hi);
    ak_view_orbit orbit = {.azimuth = 0.5f, .elevation = 0.25f, .aspect = (float)img->width / (float)img->height};
    ak_raster_camera cam = ak_view_orbit_camera(lo, hi, &orbit);
    ak_raster_desc rd = {.width = img->width, .height = img->height, .supersample = 2};
    ak_raster* ras = NULL;
    AK_CHECK_EQ(ak_raster_create(&rd, NULL, &ras), AK_OK);
    if (ras) AK_CHECK_EQ(ak_view_render(ras, &cam, &view, img), AK_OK);
    ak_raster_destroy(ras);
    for (size_t k = 0; k < count; ++k) free(bufs[k]);
    free(local), free(world);
}

/* Share of pixels whose colour differs by more than 16 in some channel. */
static double differing(const ak_image* a, const ak_image* b) {
    size_t n = (size_t)a->width * (size_t)a->height, d = 0;
    for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c)
            if (abs((int)a->pixels[4 * i + (size_t)c] - (int)b->pixels[4 * i + (size_t)c]) > 16) {
                ++d;
                break;
            }
    return (double)d / (double)n;
}

AK_TEST(render_draws_the_skinned_mesh) {
    const float t = 0.5f;
    AK_CHECK_EQ(run_line("{\"kind\": \"render\", \"inputs\": {\"model\": \"builtin:cylinder\"},"
                         " \"parameters\": {\"time\": 0.5, \"size\": [160, 120]}, \"output\": \"render_cylinder.png\"}",
                         "test_batch_out", true),
                AK_OK);
    ak_scene* sc = NULL;
    AK_CHECK_EQ(ak_builtin_create("builtin:cylinder", NULL, NULL, &sc), AK_OK);
    if (!sc) return;
    AK_CHECK(sc->clip_count > 0 && sc->mesh_count > 0 && sc->meshes[0].skin >= 0);
    static uint8_t job_px[160 * 120 * 4], ref_px[160 * 120 * 4], rest_px[160 * 120 * 4];
    ak_image job = {job_px, 160, 120, 0}, ref = {ref_px, 160, 120, 0}, rest = {rest_px, 160, 120, 0};
    AK_CHECK_EQ(ak_png_read("test_batch_out/render_cylinder.png", &job), AK_OK);
    reference_render(sc, t, true, &ref);
    reference_render(sc, t, false, &rest);
    const double same = differing(&job, &ref), moved = differing(&job, &rest);
    /* the job's picture is the posed skinned mesh (SIMD skinning rounds differently: a few edge
     * pixels), and the pose shows: the rest pose's picture differs much more */
    AK_CHECK_MSG(same < 0.005, "job vs posed reference: %.4f of the pixels differ", same);
    AK_CHECK_MSG(moved > 0.02, "job vs rest pose: only %.4f of the pixels differ", moved);
    ak_scene_destroy(sc);
}

int main(void) {
    AK_RUN(fnv1a_vectors_and_files);
    AK_RUN(job_lines_with_errors);
    AK_RUN(shards_cover_each_job_once);
    AK_RUN(retarget_bvh_rerun_skips);
    AK_RUN(bake_lasts_its_steps);
    AK_RUN(bad_jobs_are_rows);
    AK_RUN(render_draws_the_skinned_mesh);
    return ak_test_finish();
}
