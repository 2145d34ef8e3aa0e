/* animkit command line: shared glue (argument parsing, errors, scene loading, JSON, progress).
 * The CLI includes only public headers. Exit codes: 0 ok, 1 bad input, 2 bad usage. */
#ifndef ANIMKIT_CLI_H
#define ANIMKIT_CLI_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include <animkit/animkit.h>

enum { CLI_OK = 0, CLI_BAD_INPUT = 1, CLI_BAD_USAGE = 2 };

/* One option a command accepts. */
typedef struct cli_opt {
    const char* name;  /* "--time" */
    const char* alias; /* "-t" or NULL */
    bool has_value;    /* takes the next argument as its value */
} cli_opt;

#define CLI_MAX_OPTS 32
#define CLI_MAX_POS 8

typedef struct cli_args {
    const char* cmd;                  /* "render" */
    const char* values[CLI_MAX_OPTS]; /* value per option (or "1" for flags); NULL when absent */
    const char* pos[CLI_MAX_POS];     /* positional arguments */
    int pos_count;
    bool help;                        /* --help / -h seen */
    /* every option occurrence in order (repeatable options such as render --mesh) */
#define CLI_MAX_ALL 64
    const char* all_values[CLI_MAX_ALL];
    int all_opt[CLI_MAX_ALL];
    int all_count;
} cli_args;

/* Parse argv (after the command word) against opts. Prints a usage error and returns
 * CLI_BAD_USAGE on an unknown option, a missing value (naming the option as typed), too many
 * positionals or more than CLI_MAX_ALL options. */
int cli_parse(const char* cmd, int argc, char** argv, const cli_opt* opts, size_t opt_count, cli_args* out);
/* Value of option name ("--time"), or NULL. */
const char* cli_get(const cli_args* a, const cli_opt* opts, size_t opt_count, const char* name);
#define CLI_GET(args, name) cli_get((args), opts, sizeof(opts) / sizeof(opts[0]), (name))
/* Every value given to a repeatable option, in order (at most cap); returns the count. */
size_t cli_get_all(const cli_args* a, const cli_opt* opts, size_t opt_count, const char* name, const char** out,
                   size_t cap);

/* s with control bytes (< 0x20, 0x7f), C1 controls (U+0080..U+009F) and invalid UTF-8 bytes
 * written as \xHH / \u00HH into out (cap bytes, always NUL-terminated, cut at a whole
 * character); returns the length. Every message quoting input goes through it. */
size_t cli_escape(char* out, size_t cap, const char* s);

/* The one rule for what a command says on success: every file it writes is announced once on
 * stderr as "wrote PATH" or "wrote PATH: DETAILS" (cli_wrote); stdout carries the results asked
 * for (info, a solve, the summary line a run without outputs prints). --quiet (or -q), taken
 * by main before the command sees its arguments, silences the announcements, notes and
 * progress bars; errors always print. */
extern bool cli_quiet;
void cli_wrote(const char* path, const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* "FILE: no clip 'WANTED'; its clips (by name or number): #0 'walk', #1 'wave'" (or "the file
 * has no clips"); returns CLI_BAD_INPUT. */
int cli_no_clip(const char* cmd, const char* file, const char* wanted, const ak_scene* s);

/* A time outside [0, duration] is clamped by the clip (each channel holds its first or last
 * key): say so on stderr, as "note: --time T is past the end of clip 'C' (0 to D s): its last
 * pose is used". Nothing for a time inside the clip or a NULL clip. */
void cli_time_note(const char* cmd, float t, const ak_clip* clip);

/* The documented work budget of a simulation command (docs/cli.md, "Work budgets"): the run's
 * work in "particle updates" (cloth: particles x steps x substeps x iterations; fluid: particles
 * x steps x solver iterations; particles: capacity x steps; boids: agents x steps), refused above
 * CLI_WORK_BUDGET (2e10, a few minutes on one core) unless the environment variable
 * ANIMKIT_MAX_WORK sets another. Returns CLI_OK, or CLI_BAD_INPUT after printing
 * "the run asks for W WHAT, above the work budget of B; lower LOWER". */
#define CLI_WORK_BUDGET 2e10
int cli_work_check(const char* cmd, double work, const char* what, const char* lower);

/* "animkit CMD: message" on stderr (control bytes escaped: cli_escape); returns CLI_BAD_INPUT. */
int cli_fail(const char* cmd, const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/* "animkit CMD: message" (escaped) + "try 'animkit CMD --help'" on stderr; returns CLI_BAD_USAGE. */
int cli_usage(const char* cmd, const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* Strict number parsing: the whole string, finite. */
bool cli_parse_float(const char* s, float* out);
bool cli_parse_int(const char* s, long lo, long hi, long* out);
/* The usage error for an integer flag cli_parse_int refused: "FLAG VALUE is out of range:
 * expected a whole number in LO..HI" when VALUE is written as a whole number, else "FLAG
 * 'VALUE' is not a whole number (expected LO..HI)". Returns CLI_BAD_USAGE. */
int cli_usage_int(const char* cmd, const char* flag, const char* value, long lo, long hi);
/* "X,Y,Z" */
bool cli_parse_vec3(const char* s, ak_vec3* out);
/* "WxH" */
bool cli_parse_size(const char* s, int* w, int* h);
/* True when path ends with ext (case-insensitive, ext like ".png"). */
bool cli_has_ext(const char* path, const char* ext);

/* Load FILE or builtin:NAME. On failure prints "animkit CMD: SPEC: problem" and returns
 * CLI_BAD_INPUT. */
int cli_load_scene(const char* cmd, const char* spec, ak_scene** out);

/* Channels as the file declares them. The glTF reader splits a weights channel on a node whose
 * mesh has several primitives into one channel per primitive (each writes that primitive's morph
 * range, with the same keys); cli_clip_channel_repeats is true for the second and later of those,
 * and cli_clip_file_channel_count counts each file channel once. info and curves use both. */
bool cli_clip_channel_repeats(const ak_scene* s, const ak_clip* clip, size_t channel_index);
size_t cli_clip_file_channel_count(const ak_scene* s, const ak_clip* clip);
/* "s" when n != 1, else "": "%zu chart%s". */
static inline const char* cli_plural(size_t n) { return n == 1 ? "" : "s"; }

/* "note: PATH: OBJ is geometry only ..." on stderr, naming a MakeHuman .mhskel rig beside the
 * file when there is one (animkit does not read it). */
void cli_obj_rig_note(const char* cmd, const char* path);

/* JSON string literal with escapes. */
void cli_json_string(FILE* f, const char* s);
/* JSON number: "%.9g" for a finite value; `null` for NaN or infinity (JSON has no token for
 * them), so what --json prints always parses. Readers of our JSON treat null as "no value". */
void cli_json_write_number(FILE* f, double v);

/* Progress bar on stderr when it is a terminal; silent otherwise. done == total ends it. */
void cli_progress(const char* label, size_t done, size_t total);

/* Seconds since an arbitrary epoch (monotonic). */
double cli_now(void);

/* Make a directory (and parents); true when it exists afterwards. */
bool cli_mkdir_p(const char* path);

/* ---- posing: sample a clip, FK, morph, skin (the pipeline every command shares) ---- */

typedef enum cli_method { CLI_LBS = 0, CLI_DQS, CLI_COR, CLI_IMPLICIT, CLI_SOFT } cli_method;

/* Volumetric skinning state of one mesh (softskin.h), built on first CLI_SOFT use. */
typedef struct cli_soft_mesh {
    ak_skin_soft* soft;
    ak_vec3 *x, *v;       /* node state */
    uint8_t* scratch;
    ak_mat4* previous;    /* the palette of the previous step */
    bool started;         /* false: the next deform starts at rest under its pose */
    bool failed;          /* the build failed (not a closed mesh...): deform with DQS */
} cli_soft_mesh;

/* Per-scene working state for posing. */
typedef struct cli_poser {
    const ak_scene* scene;
    size_t joint_count;
    ak_transform* local;      /* [joint_count] */
    ak_mat4* world;           /* [joint_count] */
    ak_mat4* palette;         /* [max skin joints] */
    float* morph_weights;     /* [max morph targets] */
    ak_vec3** positions;      /* per mesh: posed positions */
    ak_vec3** normals;        /* per mesh: posed normals */
    ak_vec3* morphed;         /* scratch [max vertices] */
    ak_vec3* morphed_normals; /* scratch [max vertices] */
    ak_vec3** cor_centers;    /* per mesh, computed on first CoR use; NULL until then */
    ak_skin_implicit** implicit; /* per mesh, precomputed on first implicit use */
    uint8_t* implicit_scratch;   /* grown on use */
    size_t implicit_scratch_size;
    uint8_t* skin_scratch;    /* DQS/CoR scratch for the largest skin, allocated once */
    size_t skin_scratch_size;
    /* Set by the caller after init: unskinned meshes without stored normals get normals shared
     * by the vertices at one position (ak_normals_compute_welded: smooth across an OBJ's
     * unwelded seams) instead of per vertex (faceted, glTF's rule for meshes without normals). */
    bool weld_normals;
    uint32_t* weld_scratch; /* allocated on first use */
    size_t weld_scratch_count;
    /* CLI_SOFT: the flesh is simulated from one deform to the next by the time between their
     * samples (sample_time, set by cli_poser_sample): 0 -> no step; negative or above 0.5 s
     * -> restart at rest under the pose; steps of at most 1/60 s */
    cli_soft_mesh* soft;    /* [mesh_count], NULL until the first CLI_SOFT deform */
    float sample_time, soft_time;
    uint32_t soft_resolution; /* lattice resolution; 0 -> the library default */
} cli_poser;

bool cli_method_parse(const char* s, cli_method* out);
const char* cli_method_name(cli_method m);
int cli_poser_init(cli_poser* p, const ak_scene* scene);
void cli_poser_free(cli_poser* p);
/* Pose at time t of clip (clip < 0 or bind -> rest pose); results in p->positions/normals
 * and p->world. Returns AK_OK or the first failing code. */
ak_result cli_poser_pose(cli_poser* p, int clip, float t, bool bind, cli_method method);
/* The two halves of cli_poser_pose: fill p->local (rest pose + clip) and default morph
 * weights; then FK, morph and skin from whatever p->local holds. */
ak_result cli_poser_sample(cli_poser* p, int clip, float t, bool bind);
ak_result cli_poser_deform(cli_poser* p, bool bind, cli_method method);
/* Restart the soft simulation at the next CLI_SOFT deform. */
void cli_poser_soft_reset(cli_poser* p);
/* Bind-space bones of a skin: one segment from each slot's joint to each child slot's joint,
 * a point bone for slots without a child slot; out holds 2 * skin->joint_count. */
size_t cli_skin_bones(const ak_scene* s, const ak_scene_skin* skin, ak_skin_bone* out);

/* Commands. */
int cmd_demo(int argc, char** argv);
int cmd_info(int argc, char** argv);
int cmd_export(int argc, char** argv);
int cmd_render(int argc, char** argv);
int cmd_curves(int argc, char** argv);
/* cmd_curves without its "wrote ..." line (demo prints its own list). */
int cli_curves_run(int argc, char** argv, bool quiet);
int cmd_weights(int argc, char** argv);
int cmd_skin(int argc, char** argv);
int cmd_ik(int argc, char** argv);
int cmd_noise(int argc, char** argv);
int cmd_terrain(int argc, char** argv);
int cmd_particles(int argc, char** argv);
int cmd_boids(int argc, char** argv);
int cmd_crowd(int argc, char** argv);
int cmd_view(int argc, char** argv);
int cmd_cloth(int argc, char** argv);
int cmd_rigid(int argc, char** argv);
int cmd_retarget(int argc, char** argv);
int cmd_fluid(int argc, char** argv);
int cmd_batch(int argc, char** argv);

#endif
