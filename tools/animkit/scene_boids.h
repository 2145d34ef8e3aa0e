/* animkit boids: the scene file (JSON), parsed from memory so a fuzz target can call it.
 * Every key, its default and its range are in docs/boids.md. */
#ifndef ANIMKIT_CLI_SCENE_BOIDS_H
#define ANIMKIT_CLI_SCENE_BOIDS_H

#include <stddef.h>

#include <animkit/boids.h>

#define CLI_BOIDS_MAX_AGENTS 10000000u  /* agents in a file or from --count */
#define CLI_BOIDS_MAX_OBSTACLES 1024u

typedef struct cli_boids_scene {
    ak_boids_species species[AK_BOIDS_MAX_SPECIES];
    float fraction[AK_BOIDS_MAX_SPECIES]; /* share of the random agents (species 0 takes the rest) */
    ak_vec4 color[AK_BOIDS_MAX_SPECIES];  /* sRGB body colour when rendering */
    ak_boids_obstacle* obstacles;         /* [params.obstacle_count], malloc */
    ak_boids_params params;               /* points into species / obstacles */
    ak_vec3* positions;                   /* [agent_count] from "agents" (malloc), or NULL */
    ak_vec3* velocities;
    uint8_t* agent_species;
    size_t agent_count;                   /* 0: place `count` agents at random */
    size_t count;                         /* random agents */
    long steps;
    float dt;
    long seed;
    float shape_size;                     /* metres, length of a rendered bird */
    int shape;                            /* 0 bird, 1 fish */
    bool bounds_given;                    /* the scene set bounds.min or bounds.max */
} cli_boids_scene;

/* Defaults of every key (the scene without a file). */
void cli_boids_scene_defaults(cli_boids_scene* s);

/* Parse text[0, size) over the defaults already in s. Returns 0, or 1 with "FILE: KEY PATH:
 * problem" in message (size bytes). s owns its arrays afterwards in both cases: free with
 * cli_boids_scene_free. */
int cli_boids_scene_parse(const char* file, const char* text, size_t size, cli_boids_scene* s, char* message,
                          size_t message_size);

void cli_boids_scene_free(cli_boids_scene* s);

/* The built-in scene NAME over the defaults already in s (nothing else set yet): "flock" (the
 * defaults themselves), "obstacles" (a sphere and four pillars in the flock's way) or "predator"
 * (a second species, 0.6% of the agents, that chases the flock, which flees). Returns 0, -1 for
 * another name, 1 when out of memory; free s with cli_boids_scene_free in every case. */
#define CLI_BOIDS_PRESETS "flock, obstacles, predator"
int cli_boids_scene_preset(const char* name, cli_boids_scene* s);

/* The default box for `count` random agents (call after --count and --2d are applied, only when
 * the scene lists no agents): unless the scene set bounds.min or bounds.max, the 20 m box of the
 * defaults grows beyond CLI_BOIDS_BOX_AGENTS agents by cbrt(count / CLI_BOIDS_BOX_AGENTS) on every
 * axis (sqrt in 2D), so the density, and the neighbours per agent, stay those of 500 agents. */
#define CLI_BOIDS_BOX_AGENTS 500u
void cli_boids_scene_scale_bounds(cli_boids_scene* s, size_t count);

#endif
