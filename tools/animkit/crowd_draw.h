/* The crowd's characters and drawing, shared by `animkit crowd` (PNG, GIF, glTF) and
 * `animkit view crowd`: builtin:humanoid walking per agent (crowd.h's characters), posed and
 * skinned per agent up to CROWD_CHARACTERS_MAX agents; above, both share the skinned poses
 * (crowd.h's ak_crowd_character_bucket: one pose per phase and weight bucket, each agent drawn
 * as its bucket's mesh under its root matrix); the obstacles as walls. */
#ifndef ANIMKIT_CLI_CROWD_DRAW_H
#define ANIMKIT_CLI_CROWD_DRAW_H

#include "cli.h"

#define CROWD_CHARACTER_CELL 0.08f /* builtin:humanoid's grid: about 2,300 triangles */
#define CROWD_CHARACTERS_MAX 500u  /* posed per agent up to this many agents; shared poses above */
#define CROWD_SHARED_CHUNK 128u    /* shared poses: agents per draw call */

extern const ak_vec4 crowd_palette[4]; /* colour per group (group % 4) */

typedef struct crowd_chars {
    ak_scene* scene;
    ak_crowd_gait gait;
    ak_crowd_character* ch;
    size_t n;
    cli_poser poser;
    bool poser_ready;
    ak_vec2* rec_pos; /* recorded frames (glTF): [frame_cap * n] */
    ak_crowd_character* rec_ch;
    size_t frames, frame_cap;
    uint8_t* plant_scratch; /* ak_crowd_characters_scratch_size: foot planting */
    size_t plant_bytes;
    bool unplanted; /* crowd_chars_update without foot planting (shared poses have none) */
} crowd_chars;

/* The humanoid, its gait, one character per agent facing its first waypoint (phases spread),
 * and room to record frame_cap frames (0: none). */
ak_result crowd_chars_init(crowd_chars* c, const ak_crowd_scene* sc, size_t frame_cap, ak_diag* diag);
/* Room to record frame_cap frames (> 0), replacing any recorded. */
ak_result crowd_chars_record_reserve(crowd_chars* c, size_t frame_cap);
void crowd_chars_free(crowd_chars* c);
/* Back to the start: every character facing its first waypoint, standing; no recorded frame. */
void crowd_chars_reset(crowd_chars* c, const ak_crowd_scene* sc);
/* Advance the characters by dt from the agents' velocities, their feet planted at the agents'
 * new positions. */
ak_result crowd_chars_update(crowd_chars* c, const ak_vec2* velocities, const ak_vec2* positions, float dt);
/* Record the current frame (positions of the n agents, the characters); no-op when full. */
void crowd_chars_record(crowd_chars* c, const ak_vec2* positions);

/* World-space triangles of every agent, rebuilt each frame; with shared poses, the buckets'
 * skinned meshes (model space), each agent's bucket and root matrix, and world-space
 * triangles for CROWD_SHARED_CHUNK agents at a time. */
typedef struct crowd_people {
    ak_vec3 *pos, *nrm;
    ak_vec4* col;
    size_t vcount;
    uint32_t* idx; /* characters: indexed; prisms: none */
    size_t icount;
    bool shared;
    size_t n, bucket_count, mesh_vertices;
    ak_vec3 *bpos, *bnrm;    /* [bucket_count * mesh_vertices] */
    uint32_t* bucket_frame;  /* [bucket_count]: the frame it was last posed in (0: never) */
    uint32_t frame;
    uint32_t* agent_bucket;  /* [n] */
    ak_mat4* roots;          /* [n] */
    ak_vec4* agent_col;      /* [n] */
    ak_raster_mesh* casters; /* [n + 1]: each agent's bucket mesh under its root (shadows);
                                the last slot is the caller's */
    size_t posed;            /* buckets posed in the last update */
} crowd_people;

/* Room for n agents, each posed and skinned on its own (chars required). Returns false when
 * out of memory. */
bool crowd_people_init(crowd_people* pp, size_t n, const crowd_chars* chars);
/* Room for n agents as characters with shared poses (chars required). */
bool crowd_people_init_shared(crowd_people* pp, size_t n, const crowd_chars* chars);
void crowd_people_free(crowd_people* pp);
/* Pose and place every agent (positions: [n]; group from sc) and return the mesh (colours per
 * vertex; empty with shared poses, which crowd_people_draw places). */
ak_result crowd_people_update(crowd_people* pp, const ak_crowd_scene* sc, const ak_vec2* positions, crowd_chars* chars,
                              ak_raster_mesh* out);
/* Draw the people: the mesh crowd_people_update returned, or with shared poses every agent
 * (CROWD_SHARED_CHUNK at a time). */
ak_result crowd_people_draw(crowd_people* pp, ak_raster* raster, const ak_raster_camera* cam,
                            const ak_raster_mesh* people);

/* The obstacles' edges as 1.2 m high walls: 6 vertices per edge into *out (malloc; NULL when
 * there is none). Returns false when out of memory. */
bool crowd_walls(const ak_crowd_scene* sc, ak_vec3** out, size_t* out_vertex_count);

#endif
