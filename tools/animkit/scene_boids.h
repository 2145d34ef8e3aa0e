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
} cli_boids_scene;

/* Defaults of every key (the scene without a file). */
void cli_boids_scene_defaults(cli_boids_scene* s);

/* Parse text[0, size) over the defaults already in s. Returns 0, or 1 with "FILE: KEY PATH:
 * problem" in message (size bytes). s owns its arrays afterwards in both cases: free with
 * cli_boids_scene_free. */
int cli_boids_scene_parse(const char* file, const char* text, size_t size, cli_boids_scene* s, char* message,
                          size_t message_size);

void cli_boids_scene_free(cli_boids_scene* s);

#endif
