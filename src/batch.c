/* animkit batch: one manifest job run to its output with a record (see animkit/batch.h and
 * docs/batch.md). Job lines are read with the strict JSON reader of the scene files. */
#include <animkit/batch.h>

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h> /* mkdir, stat */
#include <time.h>

#include <animkit/boids.h>
#include <animkit/builtin.h>
#include <animkit/cloth.h>
#include <animkit/fluid.h>
#include <animkit/particles.h>
#include <animkit/io.h>
#include <animkit/raster.h>
#include <animkit/retarget.h>
#include <animkit/scene.h>
#include <animkit/skin.h>
#include <animkit/view.h>

#include "json.h"

#define MAX_INPUTS 3
#define BAKE_MAX_POINTS 16384u
#define BAKE_DEFAULT_FRAMES 240
#define MAP_MAX_SIZE ((size_t)1 << 20)

static const char* const kind_names[] = {"retarget", "bake", "render", NULL};

/* ---- hashing ------------------------------------------------------------------------------ */

uint64_t ak_batch_hash_bytes(uint64_t h, const void* bytes, size_t size) {
    const unsigned char* p = bytes;
    for (size_t i = 0; i < size; ++i) {
        h ^= p[i];
        h *= 0x100000001b3ull;
    }
    return h;
}

ak_result ak_batch_hash_file(const char* path, uint64_t* out_hash) {
    if (!path || !out_hash) return AK_ERR_NULL_ARG;
    FILE* f = fopen(path, "rb");
    if (!f) return AK_ERR_IO;
    unsigned char buf[1 << 16];
    uint64_t h = AK_BATCH_FNV_BASIS;
    size_t got;
    while ((got = fread(buf, 1, sizeof buf, f)) > 0) h = ak_batch_hash_bytes(h, buf, got);
    const bool bad = ferror(f) != 0;
    fclose(f);
    if (bad) return AK_ERR_IO;
    *out_hash = h;
    return AK_OK;
}

bool ak_batch_in_shard(long index, long shard_index, long shard_count) {
    return shard_count > 0 && index >= 0 && shard_index >= 0 && shard_index < shard_count &&
           index % shard_count == shard_index;
}

/* ---- parsing ------------------------------------------------------------------------------ */

/* A required (or optional) string member copied into dst; too long or empty is an error. */
static void read_path(akp_json* j, const cJSON* obj, const char* path, const char* key, bool required, char* dst,
                      size_t size) {
    const char* s = NULL;
    if (!akp_json_str(j, obj, path, key, &s)) return;
    if (!s) {
        if (required) akp_json_fail(j, path, key, "is required");
        return;
    }
    if (!s[0]) {
        akp_json_fail(j, path, key, "is empty");
        return;
    }
    if (strlen(s) >= size) {
        akp_json_fail(j, path, key, "is longer than %zu bytes", size - 1);
        return;
    }
    memcpy(dst, s, strlen(s) + 1);
}

static void parse_job(akp_json* j, const cJSON* root, ak_batch_job* job) {
    static const char* const keys[] = {"kind", "id", "inputs", "parameters", "output", NULL};
    akp_json_object(j, root, "", keys);
    int kind = -1;
    if (!j->failed && !cJSON_GetObjectItemCaseSensitive(root, "kind")) akp_json_fail(j, "", "kind", "is required");
    akp_json_enum(j, root, "", "kind", kind_names, &kind);
    job->kind = (ak_batch_kind)(kind + 1);
    read_path(j, root, "", "id", false, job->id, sizeof job->id);
    read_path(j, root, "", "output", true, job->output, sizeof job->output);
    const cJSON* in = akp_json_member(j, root, "", "inputs");
    const cJSON* par = akp_json_member(j, root, "", "parameters");
    if (!j->failed && !in) akp_json_fail(j, "", "inputs", "is required");
    if (j->failed) return;
    static const cJSON empty_object = {.type = cJSON_Object};
    if (!par) par = &empty_object;
    if (job->kind == AK_BATCH_RETARGET) {
        static const char* const ik[] = {"source", "target", "map", NULL};
        static const char* const pk[] = {"clip", "fps", "unscaled_root_motion", "skip_foot_contacts", NULL};
        akp_json_object(j, in, "inputs", ik);
        akp_json_object(j, par, "parameters", pk);
        read_path(j, in, "inputs", "source", true, job->source, sizeof job->source);
        read_path(j, in, "inputs", "target", true, job->target, sizeof job->target);
        read_path(j, in, "inputs", "map", false, job->map, sizeof job->map);
        const cJSON* c = cJSON_GetObjectItemCaseSensitive(par, "clip");
        if (c && cJSON_IsNumber(c)) {
            long ci = 0;
            if (akp_json_int(j, par, "parameters", "clip", 0, 1000000, &ci))
                snprintf(job->clip, sizeof job->clip, "%ld", ci);
        } else {
            read_path(j, par, "parameters", "clip", false, job->clip, sizeof job->clip);
        }
        akp_json_float(j, par, "parameters", "fps", 1.0f, 1000.0f, &job->fps);
        akp_json_bool(j, par, "parameters", "unscaled_root_motion", &job->unscaled);
        akp_json_bool(j, par, "parameters", "skip_foot_contacts", &job->no_feet);
    } else if (job->kind == AK_BATCH_BAKE) {
        static const char* const ik[] = {"scene", NULL};
        static const char* const pk[] = {"sim", "steps", "count", "frame_every", NULL};
        static const char* const sims[] = {"fluid", "particles", "cloth", "boids", NULL};
        akp_json_object(j, in, "inputs", ik);
        akp_json_object(j, par, "parameters", pk);
        read_path(j, in, "inputs", "scene", true, job->scene, sizeof job->scene);
        if (!j->failed && !cJSON_GetObjectItemCaseSensitive(par, "sim"))
            akp_json_fail(j, "parameters", "sim", "is required (fluid, particles, cloth or boids)");
        akp_json_enum(j, par, "parameters", "sim", sims, &job->sim);
        akp_json_int(j, par, "parameters", "steps", 1, 100000, &job->steps);
        akp_json_int(j, par, "parameters", "count", 0, BAKE_MAX_POINTS, &job->count); /* fluid presets, boids */
        akp_json_int(j, par, "parameters", "frame_every", 1, 100000, &job->frame_every);
    } else if (job->kind == AK_BATCH_RENDER) {
        static const char* const ik[] = {"model", NULL};
        static const char* const pk[] = {"clip", "time", "size", NULL};
        akp_json_object(j, in, "inputs", ik);
        akp_json_object(j, par, "parameters", pk);
        read_path(j, in, "inputs", "model", true, job->model, sizeof job->model);
        read_path(j, par, "parameters", "clip", false, job->clip, sizeof job->clip);
        akp_json_float(j, par, "parameters", "time", 0.0f, 1e6f, &job->time);
        float size[2] = {(float)job->width, (float)job->height};
        akp_json_floats(j, par, "parameters", "size", 2, 8.0f, 4096.0f, size);
        if (!j->failed && (size[0] != floorf(size[0]) || size[1] != floorf(size[1])))
            akp_json_fail(j, "parameters", "size", "expected whole pixels");
        job->width = (int)size[0], job->height = (int)size[1];
    }
}

ak_result ak_batch_job_parse(const char* bytes, size_t size, const char* name, ak_batch_job* out_job,
                             ak_diag* out_diag) {
    akp_json j = {.file = name ? name : "job"};
    if (!out_job || (!bytes && size)) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, j.file, "no line or job");
    memset(out_job, 0, sizeof *out_job);
    out_job->fps = 30.0f;
    out_job->width = 320, out_job->height = 240;
    if (size > AK_BATCH_MAX_LINE_SIZE)
        return akp_diag_set(out_diag, AK_ERR_PARSE, j.file, "the line is longer than %zu bytes", AK_BATCH_MAX_LINE_SIZE);
    cJSON* root = akp_json_parse(&j, bytes ? bytes : "", size);
    if (root) parse_job(&j, root, out_job);
    cJSON_Delete(root);
    if (j.failed) {
        out_job->kind = AK_BATCH_KIND_NONE;
        return akp_json_diag(&j, AK_ERR_PARSE, out_diag);
    }
    if (out_diag) memset(out_diag, 0, sizeof *out_diag);
    return AK_OK;
}

/* ---- running ------------------------------------------------------------------------------ */

typedef struct job_ctx {
    const ak_batch_job* job;
    const char* name;
    char output[AK_BATCH_MAX_PATH + 512];
    char record[AK_BATCH_MAX_PATH + 512 + 16];
    struct {
        const char* role;
        const char* as_written;
        char path[AK_BATCH_MAX_PATH + 512];
        uint64_t hash;
    } inputs[MAX_INPUTS];
    int input_count;
    char error[512];
    long frames; /* frames written (retarget, bake), -1 when none */
} job_ctx;

static ak_result fail(job_ctx* c, ak_result code, const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static ak_result fail(job_ctx* c, ak_result code, const char* fmt, ...) {
    char what[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    snprintf(c->error, sizeof c->error, "%.100s: %.400s", c->name, what);
    for (char* p = c->error; *p; ++p)
        if ((unsigned char)*p < 0x20 || *p == 0x7f) *p = '?';
    return code;
}

static void join(char* dst, size_t size, const char* dir, const char* path) {
    if (!dir || !dir[0] || path[0] == '/' || strncmp(path, "builtin:", 8) == 0 || strncmp(path, "preset:", 7) == 0)
        snprintf(dst, size, "%s", path);
    else
        snprintf(dst, size, "%s%s%s", dir, dir[strlen(dir) - 1] == '/' ? "" : "/", path);
}

static void add_input(job_ctx* c, const char* role, const char* as_written, const char* dir) {
    if (!as_written[0] || c->input_count >= MAX_INPUTS) return;
    c->inputs[c->input_count].role = role;
    c->inputs[c->input_count].as_written = as_written;
    join(c->inputs[c->input_count].path, sizeof c->inputs[c->input_count].path, dir, as_written);
    ++c->input_count;
}

static ak_result save_scene(job_ctx* c, ak_scene* out) {
    ak_diag d;
    memset(&d, 0, sizeof d);
    ak_io_save_desc sd = {0};
    const ak_result r = ak_io_save(c->output, out, &sd, &d);
    return r == AK_OK ? AK_OK : fail(c, r, "output: %s: %s", c->output, d.message[0] ? d.message : ak_result_string(r));
}

/* Bake point frames (fluid, particles, boids) into a scene and write it to the job's output;
 * c->frames = the frames written. */
static ak_result save_points(job_ctx* c, const ak_scene_bake_points_desc* bd) {
    ak_scene* out = NULL;
    ak_diag d;
    memset(&d, 0, sizeof d);
    ak_result r = ak_scene_bake_point_frames(bd, NULL, &out, &d);
    if (r != AK_OK) {
        r = fail(c, r, "bake: %s", d.message[0] ? d.message : ak_result_string(r));
    } else if ((r = save_scene(c, out)) == AK_OK) {
        c->frames = (long)bd->frame_count;
    }
    ak_scene_destroy(out);
    return r;
}

/* The inputs' hashes (built-in names and presets hash their name) and the job hash. */
static ak_result hash_job(job_ctx* c, uint64_t* out) {
    const ak_batch_job* job = c->job;
    uint64_t h = AK_BATCH_FNV_BASIS;
    const char* v = ak_version_string();
    h = ak_batch_hash_bytes(h, v, strlen(v) + 1);
    h = ak_batch_hash_bytes(h, kind_names[job->kind - 1], strlen(kind_names[job->kind - 1]) + 1);
    for (int i = 0; i < c->input_count; ++i) {
        const char* p = c->inputs[i].path;
        if (strncmp(p, "builtin:", 8) == 0 || strncmp(p, "preset:", 7) == 0) {
            c->inputs[i].hash = ak_batch_hash_bytes(AK_BATCH_FNV_BASIS, p, strlen(p));
        } else {
            const ak_result r = ak_batch_hash_file(p, &c->inputs[i].hash);
            if (r != AK_OK) return fail(c, r, "inputs.%s: %s: cannot read the file", c->inputs[i].role, p);
        }
        h = ak_batch_hash_bytes(h, c->inputs[i].role, strlen(c->inputs[i].role) + 1);
        h = ak_batch_hash_bytes(h, &c->inputs[i].hash, sizeof c->inputs[i].hash);
    }
    /* the parameters as parsed (defaults filled in), field by field */
    char par[1024];
    snprintf(par, sizeof par, "clip=%s;fps=%.9g;u=%d;f=%d;sim=%d;steps=%ld;count=%ld;every=%ld;t=%.9g;%dx%d", job->clip,
             (double)job->fps, job->unscaled, job->no_feet, job->sim, job->steps, job->count, job->frame_every,
             (double)job->time, job->width, job->height);
    h = ak_batch_hash_bytes(h, par, strlen(par) + 1);
    *out = h;
    return AK_OK;
}

static ak_result load_model(job_ctx* c, const char* role, const char* path, ak_scene** out) {
    *out = NULL;
    ak_diag d;
    memset(&d, 0, sizeof d);
    ak_result r;
    if (strncmp(path, "builtin:", 8) == 0)
        r = ak_builtin_create(path, NULL, NULL, out);
    else
        r = ak_io_load(path, NULL, NULL, out, &d);
    if (r != AK_OK)
        return fail(c, r, "inputs.%s: %s: %s", role, path, d.message[0] ? d.message : ak_result_string(r));
    if (!(*out)->skeleton) return fail(c, AK_ERR_EMPTY, "inputs.%s: %s: has no skeleton", role, path);
    return AK_OK;
}

static ak_result run_retarget(job_ctx* c) {
    const ak_batch_job* job = c->job;
    ak_scene *src = NULL, *dst = NULL;
    ak_clip* clip = NULL;
    int32_t* map = NULL;
    char* text = NULL;
    ak_result r = load_model(c, "source", c->inputs[0].path, &src);
    if (r == AK_OK) r = load_model(c, "target", c->inputs[1].path, &dst);
    if (r != AK_OK) goto done;
    int ci = src->clip_count ? 0 : -1;
    if (job->clip[0]) ci = ak_scene_find_clip(src, job->clip);
    if (ci < 0) {
        if (job->clip[0])
            r = fail(c, AK_ERR_NOT_FOUND, "parameters.clip: '%s' is not a clip of the source", job->clip);
        else
            r = fail(c, AK_ERR_NOT_FOUND, "inputs.source: %s: has no clip", c->inputs[0].path);
        goto done;
    }
    const size_t nt = ak_scene_joint_count(dst);
    if (!(map = malloc((nt ? nt : 1) * sizeof *map))) {
        r = fail(c, AK_ERR_NO_MEMORY, "out of memory");
        goto done;
    }
    size_t mapped = 0;
    ak_diag d;
    memset(&d, 0, sizeof d);
    if (job->map[0]) {
        akp_json rd = {.file = c->inputs[2].path};
        size_t size = 0;
        text = akp_json_read_file(&rd, c->inputs[2].path, MAP_MAX_SIZE, &size);
        if (!text) {
            r = fail(c, AK_ERR_IO, "inputs.map: %s", rd.message);
            goto done;
        }
        r = ak_retarget_map_parse(text, size, src->skeleton, dst->skeleton, (ak_i32_span){map, nt}, &mapped, &d);
        if (r != AK_OK) {
            r = fail(c, r, "inputs.map: %s: %s", c->inputs[2].path, d.message[0] ? d.message : ak_result_string(r));
            goto done;
        }
    } else {
        /* as `animkit retarget` without --map: the humanoid template (names when neither is one) */
        r = ak_retarget_map_auto(src->skeleton, dst->skeleton, NULL, (ak_i32_span){map, nt}, &mapped, NULL, &d);
        if (r != AK_OK) {
            r = fail(c, r, "%s; give inputs.map", d.message[0] ? d.message : ak_result_string(r));
            goto done;
        }
    }
    ak_retarget_desc rd = {.source = src->skeleton, .clip = src->clips[ci], .target = dst->skeleton,
                           .source_of_target = {map, nt}, .frame_rate = job->fps,
                           .unscaled_root_motion = job->unscaled, .skip_foot_contacts = job->no_feet};
    ak_retarget_stats st;
    memset(&st, 0, sizeof st);
    r = ak_retarget_clip(&rd, NULL, &clip, &st, &d);
    if (r != AK_OK) {
        r = fail(c, r, "retarget: %s", d.message[0] ? d.message : ak_result_string(r));
        goto done;
    }
    ak_scene view = *dst; /* the target with this one clip (a shallow copy) */
    view.clips = &clip;
    view.clip_count = 1;
    ak_io_save_desc sd = {0};
    r = ak_io_save(c->output, &view, &sd, &d);
    if (r != AK_OK) r = fail(c, r, "output: %s: %s", c->output, d.message[0] ? d.message : ak_result_string(r));
    c->frames = (long)st.frame_count;
done:
    free(text);
    ak_clip_destroy(clip);
    free(map);
    ak_scene_destroy(src);
    ak_scene_destroy(dst);
    return r;
}

static ak_result run_bake(job_ctx* c) {
    const ak_batch_job* job = c->job;
    ak_fluid_scene* s = malloc(sizeof *s);
    if (!s) return fail(c, AK_ERR_NO_MEMORY, "out of memory");
    ak_diag d;
    const char* in = c->inputs[0].path;
    ak_result r = strncmp(in, "preset:", 7) == 0 ? ak_fluid_scene_preset(in + 7, job->count ? job->count : 2000, s, &d)
                                                 : ak_fluid_scene_load_file(in, s, &d);
    if (r != AK_OK) {
        free(s);
        return fail(c, r, "inputs.scene: %s", d.message);
    }
    if (job->steps > 0) s->steps = job->steps;
    const long steps = ak_fluid_scene_steps(s) > 100000 ? 100000 : ak_fluid_scene_steps(s);
    const size_t cap = ak_fluid_scene_capacity(s);
    if (cap > BAKE_MAX_POINTS) {
        free(s);
        return fail(c, AK_ERR_BUDGET, "inputs.scene: %zu particles, more than the %u a bake holds", cap, BAKE_MAX_POINTS);
    }
    const long every = job->frame_every ? job->frame_every : (steps + BAKE_DEFAULT_FRAMES - 1) / BAKE_DEFAULT_FRAMES;
    const size_t frames = (size_t)(steps / every) + 1;
    const size_t scratch_size = ak_fluid_scratch_size(cap, &s->desc);
    ak_vec3* pos = calloc(cap + 1, sizeof *pos);
    ak_vec3* vel = calloc(cap + 1, sizeof *vel);
    ak_vec3* baked = calloc(frames * (cap + 1), sizeof *baked);
    uint32_t* ids = calloc(cap + 1, sizeof *ids);
    ak_scene_bake_points* fr = calloc(frames, sizeof *fr);
    void* scratch = scratch_size ? malloc(scratch_size) : NULL;
    if (!pos || !vel || !baked || !ids || !fr || !scratch) {
        r = scratch_size ? fail(c, AK_ERR_NO_MEMORY, "out of memory") : fail(c, AK_ERR_BAD_ARG, "no valid solver setup");
        goto done;
    }
    for (size_t i = 0; i <= cap; ++i) ids[i] = (uint32_t)i; /* a fluid particle keeps its index */
    size_t n = ak_fluid_scene_fill(s, pos, vel, cap);
    ak_fluid_step_job sj = {.desc = &s->desc, .dt = s->dt, .positions = {pos, cap}, .velocities = {vel, cap},
                            .particle_count = &n, .colliders = {s->colliders, s->collider_count},
                            .emitters = {s->emitters, s->emitter_count}, .sinks = {s->sinks, s->sink_count},
                            .scratch = {scratch, scratch_size}};
    size_t f = 0;
    for (long k = 0; k <= steps && r == AK_OK; ++k) {
        if (k % every == 0 && f < frames) {
            memcpy(baked + f * (cap + 1), pos, n * sizeof *pos);
            fr[f] = (ak_scene_bake_points){.positions = baked + f * (cap + 1), .ids = ids, .count = n};
            ++f;
        }
        if (k == steps) break;
        sj.time = (float)k * s->dt;
        r = ak_fluid_step_run(&sj);
        if (r != AK_OK) r = fail(c, r, "step %ld: %s", k, ak_result_string(r));
    }
    if (r != AK_OK) goto done;
    ak_scene_bake_points_desc bd = {.name = "fluid", .frames = fr, .frame_count = f,
                                    .frame_time = (float)every * s->dt, .marker_size = 0.5f * ak_fluid_rest_spacing(&s->desc)};
    r = save_points(c, &bd);
done:
    free(scratch), free(fr), free(ids), free(baked), free(vel), free(pos), free(s);
    return r;
}

/* A particle scene (file or preset:NAME) run as `animkit particles` runs it, baked every
 * frame_every steps (points keep their system ids: births and deaths show as scale steps). */
static ak_result run_bake_particles(job_ctx* c) {
    const ak_batch_job* job = c->job;
    ak_particles_scene s;
    ak_particles_scene_run run;
    memset(&run, 0, sizeof run);
    ak_diag d;
    const char* in = c->inputs[0].path;
    if (strcmp(in, "preset:character") == 0)
        return fail(c, AK_ERR_UNSUPPORTED, "inputs.scene: preset:character needs the command (a posed character)");
    ak_result r = strncmp(in, "preset:", 7) == 0 ? ak_particles_scene_preset(in + 7, &s, &d)
                                                 : ak_particles_scene_load_file(in, &s, &d);
    if (r != AK_OK) return fail(c, r, "inputs.scene: %s", d.message);
    const long steps = job->steps ? job->steps : 200;
    const long every = job->frame_every ? job->frame_every : (steps + BAKE_DEFAULT_FRAMES - 1) / BAKE_DEFAULT_FRAMES;
    const size_t frames = (size_t)(steps / every) + 1;
    if (s.capacity > BAKE_MAX_POINTS) s.capacity = BAKE_MAX_POINTS > s.particle_count ? BAKE_MAX_POINTS : (uint32_t)s.particle_count;
    const size_t cap = s.capacity;
    ak_vec3* baked = calloc(frames * (cap + 1), sizeof *baked);
    uint32_t* ids = calloc(frames * (cap + 1), sizeof *ids);
    ak_scene_bake_points* fr = calloc(frames, sizeof *fr);
    if (!baked || !ids || !fr) {
        r = fail(c, AK_ERR_NO_MEMORY, "out of memory");
        goto done;
    }
    if ((r = ak_particles_scene_run_init(&run, &s, &(ak_particles_scene_run_desc){.seed = 1}, &d)) != AK_OK) {
        r = fail(c, r, "%s", d.message);
        goto done;
    }
    size_t f = 0;
    for (long k = 0; k <= steps; ++k) {
        if (k % every == 0 && f < frames) {
            const ak_particles_state st = ak_particles_get_state(run.system);
            const size_t n = st.count < cap ? st.count : cap;
            memcpy(baked + f * (cap + 1), st.position, n * sizeof *baked);
            memcpy(ids + f * (cap + 1), st.id, n * sizeof *ids);
            fr[f] = (ak_scene_bake_points){.positions = baked + f * (cap + 1), .ids = ids + f * (cap + 1), .count = n};
            ++f;
        }
        if (k == steps) break;
        if ((r = ak_particles_scene_run_step(&run, &d)) != AK_OK) {
            r = fail(c, r, "%s", d.message);
            goto done;
        }
    }
    ak_scene_bake_points_desc bd = {.name = "particles", .frames = fr, .frame_count = f, .interp = AK_INTERP_STEP,
                                    .frame_time = (float)every * s.dt, .marker_size = 0.025f};
    r = save_points(c, &bd);
done:
    ak_particles_scene_run_free(&run);
    ak_particles_scene_free(&s);
    free(fr), free(ids), free(baked);
    return r;
}

/* Steps and frames of a bake: every `every` steps from 0 to steps. */
static long bake_every(const ak_batch_job* job, long steps) {
    return job->frame_every ? job->frame_every : (steps + BAKE_DEFAULT_FRAMES - 1) / BAKE_DEFAULT_FRAMES;
}

/* A cloth scene (file or preset) without a character, run as `animkit cloth` runs it and baked
 * as a deforming mesh. */
static ak_result run_bake_cloth(job_ctx* c) {
    const ak_batch_job* job = c->job;
    ak_cloth_scene s;
    ak_cloth_scene_run run;
    memset(&run, 0, sizeof run);
    ak_diag d;
    const char* in = c->inputs[0].path;
    ak_result r = strncmp(in, "preset:", 7) == 0 ? ak_cloth_scene_preset(in + 7, &s, &d) : ak_cloth_scene_load_file(in, &s, &d);
    if (r != AK_OK) return fail(c, r, "inputs.scene: %s", d.message);
    ak_vec3* frames_pos = NULL;
    ak_scene* out = NULL;
    if (s.model[0]) {
        r = fail(c, AK_ERR_UNSUPPORTED, "inputs.scene: a scene with a character (%s) needs the command", s.model);
        goto done;
    }
    const long steps = job->steps ? job->steps : s.steps;
    const long every = bake_every(job, steps > 0 ? steps : 1);
    const size_t frames = (size_t)(steps / every) + 1;
    if ((r = ak_cloth_scene_run_init(&run, &s, &(ak_cloth_scene_run_desc){.name = in}, &d)) != AK_OK) {
        r = fail(c, r, "%s", d.message);
        goto done;
    }
    const size_t n = run.vertex_count;
    if ((double)frames * (double)n * sizeof(ak_vec3) > (double)AK_SCENE_BAKE_DEFAULT_BUDGET) {
        r = fail(c, AK_ERR_BUDGET, "%zu frames of %zu vertices are over the bake's memory budget", frames, n);
        goto done;
    }
    if (!(frames_pos = malloc(frames * n * sizeof *frames_pos))) {
        r = fail(c, AK_ERR_NO_MEMORY, "out of memory");
        goto done;
    }
    size_t f = 0;
    for (long k = 0; k <= steps; ++k) {
        if (k % every == 0 && f < frames) memcpy(frames_pos + f++ * n, run.positions, n * sizeof *frames_pos);
        if (k == steps) break;
        if ((r = ak_cloth_scene_run_step(&run, in, &d)) != AK_OK) {
            r = fail(c, r, "%s", d.message);
            goto done;
        }
    }
    ak_scene_bake_mesh_desc bd = {.name = "cloth", .vertex_count = n, .frame_count = f, .positions = frames_pos,
                                  .indices = ak_cloth_indices(run.cloth), .frame_time = (float)every * s.dt,
                                  .base_color = {0.8f, 0.25f, 0.2f, 1.0f}};
    memset(&d, 0, sizeof d);
    if ((r = ak_scene_bake_mesh_frames(&bd, NULL, &out, &d)) != AK_OK) {
        r = fail(c, r, "bake: %s", d.message[0] ? d.message : ak_result_string(r));
        goto done;
    }
    r = save_scene(c, out);
    c->frames = (long)f;
done:
    ak_scene_destroy(out);
    free(frames_pos);
    ak_cloth_scene_run_free(&run);
    ak_cloth_scene_free(&s);
    return r;
}

/* A boids scene (file or preset) run as `animkit boids` runs it, baked as points (agent index
 * = id). */
static ak_result run_bake_boids(job_ctx* c) {
    const ak_batch_job* job = c->job;
    ak_boids_scene s;
    ak_boids_scene_run run;
    memset(&run, 0, sizeof run);
    ak_diag d;
    const char* in = c->inputs[0].path;
    ak_boids_scene_defaults(&s);
    ak_result r = strncmp(in, "preset:", 7) == 0 ? ak_boids_scene_preset(in + 7, &s, &d) : ak_boids_scene_load_file(in, &s, &d);
    ak_vec3* pos = NULL;
    uint32_t* ids = NULL;
    ak_scene_bake_points* fr = NULL;
    if (r != AK_OK) {
        r = fail(c, r, "inputs.scene: %s", d.message);
        goto done;
    }
    if (job->count) s.count = (size_t)job->count;
    if (s.agent_count == 0) ak_boids_scene_scale_bounds(&s, s.count);
    const long steps = job->steps ? job->steps : s.steps;
    const long every = bake_every(job, steps > 0 ? steps : 1);
    const size_t frames = (size_t)(steps / every) + 1;
    if ((r = ak_boids_scene_run_init(&run, &s, &(ak_boids_scene_run_desc){.name = in}, &d)) != AK_OK) {
        r = fail(c, r, "%s", d.message);
        goto done;
    }
    const size_t n = run.agent_count;
    if (n > BAKE_MAX_POINTS) {
        r = fail(c, AK_ERR_BUDGET, "%zu agents, more than the %u a bake holds", n, BAKE_MAX_POINTS);
        goto done;
    }
    pos = malloc(frames * (n + 1) * sizeof *pos);
    ids = malloc((n + 1) * sizeof *ids);
    fr = calloc(frames, sizeof *fr);
    if (!pos || !ids || !fr) {
        r = fail(c, AK_ERR_NO_MEMORY, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < n; ++i) ids[i] = (uint32_t)i;
    size_t f = 0;
    for (long k = 0; k <= steps; ++k) {
        if (k % every == 0 && f < frames) {
            memcpy(pos + f * (n + 1), run.positions, n * sizeof *pos);
            fr[f] = (ak_scene_bake_points){.positions = pos + f * (n + 1), .ids = ids, .count = n};
            ++f;
        }
        if (k == steps) break;
        if ((r = ak_boids_scene_run_step(&run)) != AK_OK) {
            r = fail(c, r, "step %ld: %s", k, ak_boids_scene_run_error(r));
            goto done;
        }
    }
    ak_scene_bake_points_desc bd = {.name = "boids", .frames = fr, .frame_count = f,
                                    .frame_time = (float)every * s.dt, .marker_size = 0.5f * s.shape_size};
    r = save_points(c, &bd);
done:
    free(fr), free(ids), free(pos);
    ak_boids_scene_run_free(&run);
    ak_boids_scene_free(&s);
    return r;
}

/* The posed meshes of a render job: skinned meshes by LBS from the pose's palette, the others
 * carried by their node; base colour and texture from the material. */
typedef struct posed_meshes {
    ak_raster_mesh* draws;
    ak_raster_texture* textures;
    ak_mat4* models;
    ak_vec3** buffers; /* per mesh: positions then normals, skinned meshes only */
    size_t count;
} posed_meshes;

static void posed_free(posed_meshes* pm) {
    for (size_t m = 0; pm->buffers && m < pm->count; ++m) free(pm->buffers[m]);
    free(pm->buffers), free(pm->draws), free(pm->textures), free(pm->models);
    memset(pm, 0, sizeof *pm);
}

static ak_result pose_meshes(job_ctx* c, const ak_scene* sc, const ak_mat4* world, size_t nj, posed_meshes* pm) {
    const size_t n = sc->mesh_count;
    pm->draws = calloc(n + 1, sizeof *pm->draws);
    pm->textures = calloc(n + 1, sizeof *pm->textures);
    pm->models = calloc(n + 1, sizeof *pm->models);
    pm->buffers = calloc(n + 1, sizeof *pm->buffers);
    if (!pm->draws || !pm->textures || !pm->models || !pm->buffers) return fail(c, AK_ERR_NO_MEMORY, "out of memory");
    for (size_t m = 0; m < n; ++m) {
        const ak_scene_mesh* sm = &sc->meshes[m];
        const ak_mesh* mesh = sm->mesh;
        if (!mesh || mesh->vertex_count == 0 || mesh->triangle_count == 0) continue;
        ak_raster_mesh* d = &pm->draws[pm->count];
        *d = ak_view_raster_mesh(mesh);
        const size_t v = mesh->vertex_count;
        if (sm->skin >= 0 && (size_t)sm->skin < sc->skin_count && mesh->influence_count > 0) {
            const ak_scene_skin* skin = &sc->skins[sm->skin];
            ak_mat4* palette = malloc((skin->joint_count + 1) * sizeof *palette);
            ak_vec3* buf = pm->buffers[pm->count] = malloc(2 * v * sizeof(ak_vec3));
            if (!palette || !buf) {
                free(palette);
                return fail(c, AK_ERR_NO_MEMORY, "out of memory");
            }
            ak_result r = ak_scene_skin_palette(sc, (size_t)sm->skin, (ak_mat4_cspan){world, nj},
                                                (ak_mat4_span){palette, skin->joint_count});
            ak_skin_job job = {.method = AK_SKIN_LBS, .influence_count = mesh->influence_count,
                               .palette = {palette, skin->joint_count}, .positions = {mesh->positions, v, 0},
                               .joints = {mesh->joints, v, mesh->influence_count * sizeof(uint16_t)},
                               .weights = {mesh->weights, v, mesh->influence_count * sizeof(float)},
                               .out_positions = {buf, v, 0}};
            if (mesh->normals) job.normals = (ak_cstream){mesh->normals, v, 0}, job.out_normals = (ak_stream){buf + v, v, 0};
            if (r == AK_OK) r = ak_skin_job_run(&job);
            free(palette);
            if (r != AK_OK) return fail(c, r, "skinning mesh %zu: %s", m, ak_result_string(r));
            d->positions = (ak_vec3_cspan){buf, v};
            if (mesh->normals) d->normals = (ak_vec3_cspan){buf + v, v};
        } else if (sm->node >= 0 && (size_t)sm->node < nj) {
            pm->models[pm->count] = world[sm->node];
            d->model = &pm->models[pm->count];
        }
        if (sm->has_material) d->material.color = sm->base_color;
        if (sm->texture >= 0 && (size_t)sm->texture < sc->texture_count && mesh->uvs) {
            const ak_scene_texture* t = &sc->textures[sm->texture];
            if (t->pixels && t->width > 0 && t->height > 0) {
                pm->textures[pm->count] = (ak_raster_texture){
                    .image = {t->pixels, t->width, t->height, 0}, .wrap_u = (ak_raster_wrap)t->wrap_s,
                    .wrap_v = (ak_raster_wrap)t->wrap_t, .mag_filter = (ak_raster_filter)t->mag_filter,
                    .min_filter = (ak_raster_filter)t->min_filter};
                d->texture = &pm->textures[pm->count];
                d->uvs = (ak_vec2_cspan){mesh->uvs, v};
            }
        }
        pm->count++;
    }
    return AK_OK;
}

static ak_result run_render(job_ctx* c) {
    const ak_batch_job* job = c->job;
    ak_scene* sc = NULL;
    ak_raster* ras = NULL;
    posed_meshes pm = {0};
    ak_result r = load_model(c, "model", c->inputs[0].path, &sc);
    const size_t nj = sc ? ak_scene_joint_count(sc) : 0;
    ak_transform* local = calloc(nj + 1, sizeof *local);
    ak_mat4* world = calloc(nj + 1, sizeof *world);
    int32_t* parents = calloc(nj + 1, sizeof *parents);
    uint8_t* px = calloc((size_t)job->width * (size_t)job->height, 4);
    if (r != AK_OK) goto done;
    if (!local || !world || !parents || !px) {
        r = fail(c, AK_ERR_NO_MEMORY, "out of memory");
        goto done;
    }
    int ci = sc->clip_count ? 0 : -1;
    if (job->clip[0] && (ci = ak_scene_find_clip(sc, job->clip)) < 0) {
        r = fail(c, AK_ERR_NOT_FOUND, "parameters.clip: '%s' is not a clip of the model", job->clip);
        goto done;
    }
    if ((r = ak_scene_rest_pose(sc, (ak_transform_span){local, nj})) == AK_OK && ci >= 0 &&
        ak_clip_joint_count(sc->clips[ci]) > 0)
        r = ak_clip_sample(sc->clips[ci], job->time, NULL, (ak_transform_span){local, nj}, (ak_f32_span){NULL, 0},
                           (ak_f32_span){NULL, 0});
    if (r == AK_OK) r = ak_scene_world_matrices(sc, (ak_transform_cspan){local, nj}, (ak_mat4_span){world, nj});
    if (r != AK_OK) {
        r = fail(c, r, "pose: %s", ak_result_string(r));
        goto done;
    }
    if ((r = pose_meshes(c, sc, world, nj, &pm)) != AK_OK) goto done;
    const ak_i32_cspan par = ak_skeleton_parents(sc->skeleton);
    for (size_t i = 0; i < nj; ++i) parents[i] = i < par.count ? par.ptr[i] : -1;
    /* the skeleton over a model without meshes (a BVH); with meshes, the meshes alone */
    ak_view_skeleton vs = {.joint_model = {world, nj}, .parents = {parents, nj}};
    ak_view_scene view = {.meshes = pm.draws, .mesh_count = pm.count, .skeleton = pm.count ? NULL : &vs};
    ak_vec3 lo, hi;
    ak_view_scene_bounds(&view, &lo, &hi);
    ak_view_orbit orbit = {.azimuth = 0.5f, .elevation = 0.25f, .aspect = (float)job->width / (float)job->height};
    ak_raster_camera cam = ak_view_orbit_camera(lo, hi, &orbit);
    ak_raster_desc rdesc = {.width = job->width, .height = job->height, .supersample = 2};
    ak_image img = {.pixels = px, .width = job->width, .height = job->height};
    if ((r = ak_raster_create(&rdesc, NULL, &ras)) != AK_OK || (r = ak_view_render(ras, &cam, &view, &img)) != AK_OK) {
        r = fail(c, r, "render: %s", ak_result_string(r));
        goto done;
    }
    if ((r = ak_png_write(c->output, &img)) != AK_OK) r = fail(c, r, "output: %s: cannot write the PNG", c->output);
done:
    ak_raster_destroy(ras);
    posed_free(&pm);
    free(px), free(parents), free(world), free(local);
    ak_scene_destroy(sc);
    return r;
}

/* "hex" of a 64-bit hash. */
static void hex64(char out[17], uint64_t h) { snprintf(out, 17, "%016llx", (unsigned long long)h); }

/* The record beside the output holds this job hash and the output exists; a skipped job's row
 * then repeats the record's frame count (c->frames). */
static bool up_to_date(job_ctx* c, uint64_t job_hash) {
    struct stat st;
    if (stat(c->output, &st) != 0 || !S_ISREG(st.st_mode)) return false;
    akp_json j = {.file = c->record};
    cJSON* root = akp_json_load(&j, c->record, AK_BATCH_ROW_SIZE * 2);
    if (!root) return false;
    const cJSON* h = cJSON_GetObjectItemCaseSensitive(root, "job_hash");
    const cJSON* s = cJSON_GetObjectItemCaseSensitive(root, "status");
    char want[17];
    hex64(want, job_hash);
    const bool ok = cJSON_IsString(h) && strcmp(h->valuestring, want) == 0 && cJSON_IsString(s) &&
                    strcmp(s->valuestring, "ran") == 0;
    const cJSON* f = cJSON_GetObjectItemCaseSensitive(root, "frames");
    if (ok && cJSON_IsNumber(f) && f->valuedouble >= 0.0 && f->valuedouble <= 1e9 && f->valuedouble == floor(f->valuedouble))
        c->frames = (long)f->valuedouble;
    cJSON_Delete(root);
    return ok;
}

static void make_row(const job_ctx* c, const ak_batch_desc* desc, const ak_batch_job* job, ak_batch_row* row) {
    cJSON* o = cJSON_CreateObject();
    if (!o) {
        snprintf(row->json, sizeof row->json, "{\"index\":%ld,\"status\":\"failed\",\"error\":\"out of memory\"}", desc->index);
        return;
    }
    static const char* const status[] = {"failed", "ran", "skipped"};
    char hx[17];
    cJSON_AddNumberToObject(o, "index", (double)desc->index);
    cJSON_AddStringToObject(o, "id", job ? job->id : "");
    cJSON_AddStringToObject(o, "kind", job && job->kind ? kind_names[job->kind - 1] : "");
    cJSON_AddStringToObject(o, "status", status[row->status]);
    cJSON_AddStringToObject(o, "output", c->output);
    cJSON* in = cJSON_AddObjectToObject(o, "inputs");
    for (int i = 0; in && i < c->input_count; ++i) {
        cJSON* e = cJSON_AddObjectToObject(in, c->inputs[i].role);
        if (!e) continue;
        cJSON_AddStringToObject(e, "path", c->inputs[i].path);
        hex64(hx, c->inputs[i].hash);
        if (row->job_hash) cJSON_AddStringToObject(e, "fnv1a64", hx);
    }
    cJSON* p = cJSON_AddObjectToObject(o, "parameters");
    if (p && job && job->kind == AK_BATCH_RETARGET) {
        cJSON_AddStringToObject(p, "clip", job->clip);
        cJSON_AddNumberToObject(p, "fps", (double)job->fps);
        cJSON_AddBoolToObject(p, "unscaled_root_motion", job->unscaled);
        cJSON_AddBoolToObject(p, "skip_foot_contacts", job->no_feet);
    } else if (p && job && job->kind == AK_BATCH_BAKE) {
        static const char* const sim_names[] = {"fluid", "particles", "cloth", "boids"};
        cJSON_AddStringToObject(p, "sim", sim_names[job->sim]);
        cJSON_AddNumberToObject(p, "steps", (double)job->steps);
        cJSON_AddNumberToObject(p, "count", (double)job->count);
        cJSON_AddNumberToObject(p, "frame_every", (double)job->frame_every);
    } else if (p && job && job->kind == AK_BATCH_RENDER) {
        cJSON_AddStringToObject(p, "clip", job->clip);
        cJSON_AddNumberToObject(p, "time", (double)job->time);
        cJSON* sz = cJSON_AddArrayToObject(p, "size");
        if (sz) {
            cJSON_AddItemToArray(sz, cJSON_CreateNumber(job->width));
            cJSON_AddItemToArray(sz, cJSON_CreateNumber(job->height));
        }
    }
    cJSON_AddStringToObject(o, "animkit_version", ak_version_string());
    hex64(hx, row->job_hash);
    if (row->job_hash)
        cJSON_AddStringToObject(o, "job_hash", hx);
    else
        cJSON_AddNullToObject(o, "job_hash");
    cJSON_AddNumberToObject(o, "seconds", floor(row->seconds * 1e4 + 0.5) / 1e4);
    if (c->frames >= 0) cJSON_AddNumberToObject(o, "frames", (double)c->frames);
    if (row->status == AK_BATCH_FAILED)
        cJSON_AddStringToObject(o, "error", row->error);
    else
        cJSON_AddNullToObject(o, "error");
    char* text = cJSON_PrintUnformatted(o);
    cJSON_Delete(o);
    if (text && strlen(text) < sizeof row->json) {
        memcpy(row->json, text, strlen(text) + 1);
    } else {
        /* over the row's size (paths full of escaped bytes): the essentials only */
        hex64(hx, row->job_hash);
        snprintf(row->json, sizeof row->json, "{\"index\":%ld,\"status\":\"%s\",\"job_hash\":\"%s\",\"error\":%s}",
                 desc->index, status[row->status], hx,
                 row->status == AK_BATCH_FAILED ? "\"the row is too long\"" : "null");
    }
    free(text);
}

/* Create the folders above path (like mkdir -p of its dirname); false when one cannot be made. */
static bool make_parents(const char* path) {
    char buf[AK_BATCH_MAX_PATH + 512];
    snprintf(buf, sizeof buf, "%s", path);
    for (char* p = buf + 1; *p; ++p) {
        if (*p != '/') continue;
        *p = '\0';
        struct stat st;
        if (stat(buf, &st) != 0 && mkdir(buf, 0777) != 0 && errno != EEXIST) return false;
        *p = '/';
    }
    return true;
}

static double now_seconds(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

ak_result ak_batch_run_job(const char* line, size_t size, const ak_batch_desc* desc, ak_batch_row* out_row) {
    if (!out_row) return AK_ERR_NULL_ARG;
    memset(out_row, 0, sizeof *out_row);
    static const ak_batch_desc none = {0};
    if (!desc) desc = &none;
    const double t0 = now_seconds();
    ak_batch_job* job = calloc(1, sizeof *job);
    job_ctx* c = calloc(1, sizeof *c);
    ak_result r = AK_OK;
    if (!job || !c) {
        free(job), free(c);
        out_row->status = AK_BATCH_FAILED;
        snprintf(out_row->error, sizeof out_row->error, "out of memory");
        snprintf(out_row->json, sizeof out_row->json, "{\"index\":%ld,\"status\":\"failed\",\"error\":\"out of memory\"}",
                 desc->index);
        return AK_ERR_NO_MEMORY;
    }
    c->job = job;
    c->name = desc->name ? desc->name : "job";
    c->frames = -1;
    ak_diag d;
    if (!line && size) {
        r = fail(c, AK_ERR_NULL_ARG, "no line");
        goto row;
    }
    if ((r = ak_batch_job_parse(line, size, c->name, job, &d)) != AK_OK) {
        snprintf(c->error, sizeof c->error, "%s", d.message);
        goto row;
    }
    join(c->output, sizeof c->output, desc->output_dir, job->output);
    snprintf(c->record, sizeof c->record, "%s%s", c->output, AK_BATCH_RECORD_SUFFIX);
    if (job->kind == AK_BATCH_RETARGET) {
        add_input(c, "source", job->source, desc->input_dir);
        add_input(c, "target", job->target, desc->input_dir);
        add_input(c, "map", job->map, desc->input_dir);
    } else if (job->kind == AK_BATCH_BAKE) {
        add_input(c, "scene", job->scene, desc->input_dir);
    } else {
        add_input(c, "model", job->model, desc->input_dir);
    }
    uint64_t h = 0;
    if ((r = hash_job(c, &h)) != AK_OK) goto row;
    out_row->job_hash = h;
    if (!desc->force && up_to_date(c, h)) {
        out_row->status = AK_BATCH_SKIPPED;
        goto row;
    }
    if (!make_parents(c->output)) {
        r = fail(c, AK_ERR_IO, "output: %s: cannot create its folder (%s)", c->output, strerror(errno));
        goto row;
    }
    remove(c->record); /* a record never describes an output it did not see written */
    if (job->kind == AK_BATCH_RETARGET)
        r = run_retarget(c);
    else if (job->kind == AK_BATCH_BAKE)
        r = job->sim == 1 ? run_bake_particles(c) : job->sim == 2 ? run_bake_cloth(c) : job->sim == 3 ? run_bake_boids(c) : run_bake(c);
    else
        r = run_render(c);
    if (r == AK_OK) out_row->status = AK_BATCH_RAN;
row:
    if (r != AK_OK) {
        out_row->status = AK_BATCH_FAILED;
        snprintf(out_row->error, sizeof out_row->error, "%s", c->error[0] ? c->error : ak_result_string(r));
    }
    out_row->seconds = now_seconds() - t0;
    snprintf(out_row->output, sizeof out_row->output, "%s", c->output);
    make_row(c, desc, job, out_row);
    if (out_row->status == AK_BATCH_RAN) {
        ak_atomic_file rec;
        if (ak_atomic_file_open(&rec, c->record) == AK_OK) {
            fprintf(rec.f, "%s\n", out_row->json);
            if (ak_atomic_file_commit(&rec) != AK_OK) remove(c->record);
        }
    }
    free(job);
    free(c);
    return r;
}
