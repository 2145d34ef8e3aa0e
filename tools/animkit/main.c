/* animkit: the command-line tool. Each subcommand lives in its own cmd_*.c file. */
#include <signal.h> /* SIGXFSZ */
#include <stdio.h>
#include <string.h>

#include "cli.h"

typedef struct command {
    const char* name;
    int (*run)(int argc, char** argv);
    const char* summary;
} command;

static const command commands[] = {
    {"demo", cmd_demo, "render the built-in characters (no files needed) to DIR/demo.gif and PNGs"},
    {"info", cmd_info, "print a model's skeleton, meshes and clips (--json for scripts)"},
    {"export", cmd_export, "write the posed meshes as OBJ, or the scene as glTF 2.0"},
    {"render", cmd_render, "render a posed or animated model to PNG or GIF"},
    {"curves", cmd_curves, "plot a clip's animation curves to PNG (a read-only curve editor)"},
    {"weights", cmd_weights, "compute automatic skin weights (inverse distance or bone heat)"},
    {"skin", cmd_skin, "compare LBS, DQS and CoR skinning: volume and bulge"},
    {"ik", cmd_ik, "solve inverse kinematics for a joint chain"},
    {"noise", cmd_noise, "evaluate Perlin, simplex, value or Worley noise (or a fractal sum) at a point"},
    {"terrain", cmd_terrain, "generate a fractal terrain: OBJ, 16-bit PNG heightmap, render or GIF flight"},
    {"particles", cmd_particles, "simulate a particle system (scene file or preset) to JSON, PNG or GIF"},
    {"boids", cmd_boids, "flocking: Reynolds boids with obstacles and predators (JSON, PNG, GIF)"},
    {"view", cmd_view, "interactive viewer: play clips, compare skinning, drag IK targets (--headless, --script)"},
    {"cloth", cmd_cloth, "simulate cloth (XPBD or mass-spring): flag, curtain, drape, cape"},
    {"rigid", cmd_rigid, "rigid bodies and ragdolls (XPBD): stack, pyramid, dominoes, avalanche, ragdoll, incline"},
    {"retarget", cmd_retarget, "put a clip (e.g. BVH mocap) on another character; glTF or GIF out"},
    {"fluid", cmd_fluid, "simulate a particle liquid (PBF, SPH, WCSPH): JSON state, PNG/GIF render, OBJ surface"},
    {"batch", cmd_batch, "run a manifest of retarget/bake/render jobs (JSON lines), one --shard I/N of it, idempotently"},
};
#define COMMAND_COUNT (sizeof(commands) / sizeof(commands[0]))

static void print_help(FILE* f) {
    fprintf(f, "animkit %s: character animation and deformation\n\n", ak_version_string());
    fprintf(f, "usage: animkit COMMAND [ARGS] [--quiet]   (animkit COMMAND --help for details)\n"
               "Every file a command writes is announced on stderr as 'wrote PATH'; --quiet (-q) silences\n"
               "those lines, notes and progress bars (errors still print).\n\n");
    for (size_t i = 0; i < COMMAND_COUNT; ++i) fprintf(f, "  %-9s %s\n", commands[i].name, commands[i].summary);
    fprintf(f, "\nMODEL arguments are a file (glTF/GLB, BVH, FBX, Collada, OBJ) or builtin:humanoid,\n"
               "builtin:cylinder. Exit status: 0 success, 1 bad input, 2 bad usage.\n");
}

int main(int argc, char** argv) {
    /* Past a file size limit (ulimit -f) a write then fails with EFBIG, which every writer
     * reports (naming the file) and cleans up after, instead of the signal killing the
     * process and leaving a temporary file behind. */
    signal(SIGXFSZ, SIG_IGN);
    if (argc < 2) {
        print_help(stderr);
        return CLI_BAD_USAGE;
    }
    const char* name = argv[1];
    if (strcmp(name, "help") == 0 || strcmp(name, "--help") == 0 || strcmp(name, "-h") == 0) {
        if (argc >= 3) {
            for (size_t i = 0; i < COMMAND_COUNT; ++i) {
                if (strcmp(argv[2], commands[i].name) == 0) {
                    char help[] = "--help";
                    char* hv[] = {help};
                    return commands[i].run(1, hv);
                }
            }
            fprintf(stderr, "animkit: unknown command '%s'\n", argv[2]);
            return CLI_BAD_USAGE;
        }
        print_help(stdout);
        return CLI_OK;
    }
    if (strcmp(name, "--version") == 0 || strcmp(name, "version") == 0) {
        printf("animkit %s\n", ak_version_string());
        return CLI_OK;
    }
    /* --quiet / -q, anywhere after the command: no "wrote ..." lines, notes or progress */
    int kept = 2;
    for (int i = 2; i < argc; ++i) {
        if (strcmp(argv[i], "--quiet") == 0 || strcmp(argv[i], "-q") == 0) cli_quiet = true;
        else argv[kept++] = argv[i];
    }
    argc = kept;
    argv[argc] = NULL;
    for (size_t i = 0; i < COMMAND_COUNT; ++i)
        if (strcmp(name, commands[i].name) == 0) return commands[i].run(argc - 2, argv + 2);
    fprintf(stderr, "animkit: unknown command '%s'\ntry 'animkit help'\n", name);
    return CLI_BAD_USAGE;
}
