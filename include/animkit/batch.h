/* animkit batch: one job of a batch manifest (JSON lines), run to its output file with a record
 * of what made it, so that a scheduler can run a manifest in shards and re-run it idempotently.
 *
 * `animkit batch MANIFEST.jsonl --shard i/n` (schedulers without Python: Slurm job arrays,
 * Kubernetes indexed jobs) and the Python package's Dask layer call the same function,
 * ak_batch_run_job, once per line. docs/batch.md describes the job format, the rows, sharding
 * and idempotence. A job line:
 *     {"kind": "retarget", "inputs": {"source": "walk.bvh", "target": "builtin:humanoid"},
 *      "parameters": {"fps": 30}, "output": "out/walk_humanoid.glb"}
 *     {"kind": "bake", "inputs": {"scene": "preset:dam"}, "parameters": {"sim": "fluid",
 *      "steps": 200, "count": 2000}, "output": "out/dam.glb"}
 *
 *     ak_batch_row row;
 *     ak_batch_desc d = {.name = "jobs.jsonl:3", .input_dir = "jobs", .output_dir = "out", .index = 2};
 *     ak_batch_run_job(line, strlen(line), &d, &row);  // row.json: one JSON object, never a crash
 *
 * Idempotence: a job that ran writes its output, then OUTPUT.batch.json (its row). A later run of
 * the same job skips it (status "skipped") when the output exists and that record holds the same
 * job hash: FNV-1a 64 over the animkit version, the kind, each input's role and content hash and
 * the parameters (so a changed input file, parameter or animkit version runs it again). */
#ifndef ANIMKIT_BATCH_H
#define ANIMKIT_BATCH_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "core.h"

#ifdef __cplusplus
extern "C" {
#endif

#define AK_BATCH_MAX_LINE_SIZE ((size_t)1 << 16) /* bytes of one job line */
#define AK_BATCH_MAX_PATH 1024                   /* bytes of a path in a job, NUL included */
#define AK_BATCH_ROW_SIZE 16384                  /* bytes of a row (JSON), NUL included */
#define AK_BATCH_RECORD_SUFFIX ".batch.json"     /* the record beside an output */

typedef enum ak_batch_kind {
    AK_BATCH_KIND_NONE = 0,
    AK_BATCH_RETARGET, /* a clip of inputs.source put on inputs.target: .glb / .gltf */
    AK_BATCH_BAKE,     /* a simulation scene run and baked (points, or the cloth mesh): .glb / .gltf */
    AK_BATCH_RENDER    /* a model's skeleton at a time drawn to a .png */
} ak_batch_kind;

/* A parsed job line (ak_batch_job_parse). Paths are as written (not yet resolved). */
typedef struct ak_batch_job {
    ak_batch_kind kind;
    char id[128];                    /* "id" when given, else "" */
    char output[AK_BATCH_MAX_PATH];  /* required */
    /* retarget: inputs.source (a model with a clip: BVH, glTF, ...), inputs.target (a file or
     * builtin:NAME), inputs.map (optional joint map file, retarget.h's format) */
    char source[AK_BATCH_MAX_PATH], target[AK_BATCH_MAX_PATH], map[AK_BATCH_MAX_PATH];
    char clip[128];                  /* parameters.clip: name or index; "" -> the first */
    float fps;                       /* parameters.fps [1, 1000]; default 30 */
    bool unscaled, no_feet;          /* parameters.unscaled_root_motion, skip_foot_contacts */
    /* bake: inputs.scene (a scene file of the simulation, or "preset:NAME") */
    char scene[AK_BATCH_MAX_PATH];
    int sim;                         /* parameters.sim (required): 0 "fluid", 1 "particles", 2 "cloth", 3 "boids" */
    long steps;                      /* parameters.steps [1, 100000]; 0 -> the scene's (particles: 200) */
    long count;                      /* parameters.count [0, 16384]: a fluid preset's particles (0 -> 2000),
                                        random boids (0 -> the scene's) */
    long frame_every;                /* parameters.frame_every [1, 100000]: steps per baked frame; 0 -> so that <= 240 frames */
    /* render: inputs.model (a file or builtin:NAME) */
    char model[AK_BATCH_MAX_PATH];
    float time;                      /* parameters.time, seconds [0, 1e6]; default 0 */
    int width, height;               /* parameters.size [w, h], 8..4096 each; default 320 x 240 */
} ak_batch_job;

/* Parse one job line, bytes[0, size) (strict JSON; every key checked, unknown keys are errors).
 * name (NULL -> "job") starts every message: "NAME: inputs.source: is required". Returns AK_OK,
 * AK_ERR_PARSE or AK_ERR_NULL_ARG (with out_diag, when not NULL, holding the message). */
AK_API ak_result ak_batch_job_parse(const char* bytes, size_t size, const char* name, ak_batch_job* out_job,
                                    ak_diag* out_diag);

typedef struct ak_batch_desc {
    const char* name;       /* starts messages, e.g. "jobs.jsonl:3"; NULL -> "job" */
    const char* input_dir;  /* relative input paths are taken from here; NULL or "" -> as written */
    const char* output_dir; /* relative output paths go here; NULL or "" -> as written. The
                               folders above an output are created when missing */
    long index;             /* the job's 0-based index in its manifest (copied into the row) */
    bool force;             /* run even when the output and its record match */
} ak_batch_desc;

typedef enum ak_batch_status { AK_BATCH_FAILED = 0, AK_BATCH_RAN, AK_BATCH_SKIPPED } ak_batch_status;

/* The outcome of one job. json is the row: one JSON object on one line, e.g.
 * {"index":2,"id":"","kind":"retarget","status":"ran","output":"out/a.glb",
 *  "inputs":{"source":{"path":"a.bvh","fnv1a64":"9ae1..."},...},"parameters":{...},
 *  "animkit_version":"0.1.0","job_hash":"5c0f...","seconds":0.21,"frames":120,"error":null} */
typedef struct ak_batch_row {
    ak_batch_status status;
    double seconds;                /* wall time of the job (hashing included) */
    uint64_t job_hash;             /* 0 when the line did not parse or an input was unreadable */
    char error[512];               /* "" unless FAILED */
    char output[AK_BATCH_MAX_PATH + 512]; /* the output path, resolved ("" when the line did not parse) */
    char json[AK_BATCH_ROW_SIZE];
} ak_batch_row;

/* Parse and run one job line: hash the inputs, skip the job when its output and record match
 * (unless desc->force), else run it and write the output and its record (both atomically).
 * Never crashes on bad input: a line that does not parse, a missing input, a failed step all
 * give status FAILED with the message in error and in the row. Returns AK_OK (ran or skipped)
 * or the failure's code; AK_ERR_NULL_ARG when line (with a size), desc or out_row is NULL. */
AK_API ak_result ak_batch_run_job(const char* line, size_t size, const ak_batch_desc* desc, ak_batch_row* out_row);

/* FNV-1a 64 of a file's bytes (offset basis 0xcbf29ce484222325, prime 0x100000001b3), read in
 * blocks. AK_ERR_NULL_ARG, AK_ERR_IO. */
AK_API ak_result ak_batch_hash_file(const char* path, uint64_t* out_hash);
#define AK_BATCH_FNV_BASIS 0xcbf29ce484222325ull
/* FNV-1a 64 of bytes[0, size), continuing from hash (pass AK_BATCH_FNV_BASIS to start). */
AK_API uint64_t ak_batch_hash_bytes(uint64_t hash, const void* bytes, size_t size);

/* Shard i of n (0 <= i < n) runs the jobs whose 0-based index k has k % n == i. */
AK_API bool ak_batch_in_shard(long index, long shard_index, long shard_count);

#ifdef __cplusplus
}
#endif
#endif /* ANIMKIT_BATCH_H */
