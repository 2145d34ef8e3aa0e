/* animkit crowd: the scene file (JSON) and the presets, parsed from memory so a fuzz target can
 * call it. Self-contained (this file and scene_crowd.c) so that it can move into the library.
 * Every key, its default and its range are in docs/crowd.md. */
#ifndef ANIMKIT_CLI_SCENE_CROWD_H
#define ANIMKIT_CLI_SCENE_CROWD_H

#include <stddef.h>

#include <animkit/crowd.h>

#define CLI_CROWD_MAX_AGENTS 1000000u     /* agents in a file or from --agents */
#define CLI_CROWD_MAX_OBSTACLES 10000u
#define CLI_CROWD_MAX_VERTICES 100000u    /* obstacle vertices in all */
#define CLI_CROWD_MAX_PATH 1000u          /* waypoints of one agent */

typedef struct cli_crowd_scene {
    ak_crowd_agent defaults;     /* "agent_defaults" over ak_crowd_agent's zero defaults */
    ak_crowd_agent* agents;      /* [agent_count] (goals point into waypoints), malloc */
    ak_vec2* positions;          /* [agent_count] start positions */
    ak_vec2* velocities;         /* [agent_count] start velocities */
    uint8_t* group;              /* [agent_count] colour group when rendering */
    size_t agent_count;
    ak_vec2* waypoints;          /* all agents' goals, malloc */
    size_t waypoint_count;
    ak_crowd_obstacle* obstacles; /* [obstacle_count], vertices point into vertices */
    size_t obstacle_count;
    ak_vec2* vertices;
    size_t vertex_count;
    long steps;                  /* -1: the preset's own default */
    float dt;
    uint32_t contact_iterations;
    int method;                  /* 0 orca, 1 vision */
} cli_crowd_scene;

#define CLI_CROWD_PRESETS "circle, crossing, corridor, evacuation"

/* Defaults of every key (the scene without a file: no agents yet). */
void cli_crowd_scene_defaults(cli_crowd_scene* s);

/* Parse text[0, size) over the defaults already in s. Returns 0, or 1 with "FILE: KEY PATH:
 * problem" in message (message_size bytes). s owns its arrays afterwards in both cases: free
 * with cli_crowd_scene_free. */
int cli_crowd_scene_parse(const char* file, const char* text, size_t size, cli_crowd_scene* s, char* message,
                          size_t message_size);

/* The preset NAME with count agents (0 -> the preset's default) over the defaults in s.
 * Sets steps to a count long enough for every agent to reach its goal. Returns 0, -1 for an
 * unknown name, 1 when out of memory. */
int cli_crowd_scene_preset(const char* name, size_t count, cli_crowd_scene* s);

void cli_crowd_scene_free(cli_crowd_scene* s);

#endif
