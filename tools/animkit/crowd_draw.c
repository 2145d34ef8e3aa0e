/* The crowd's characters and drawing (crowd_draw.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "crowd_draw.h"

const ak_vec4 crowd_palette[4] = {{0.93f, 0.55f, 0.20f, 1}, {0.25f, 0.45f, 0.80f, 1}, {0.35f, 0.70f, 0.35f, 1},
                                  {0.75f, 0.30f, 0.55f, 1}};

/* ---- characters ------------------------------------------------------------------------------ */

void crowd_chars_free(crowd_chars* c) {
    if (c->poser_ready) cli_poser_free(&c->poser);
    ak_scene_destroy(c->scene);
    free(c->ch);
    free(c->rec_pos);
    free(c->rec_ch);
    free(c->plant_scratch);
    memset(c, 0, sizeof *c);
}

void crowd_chars_reset(crowd_chars* c, const ak_crowd_scene* sc) {
    for (size_t i = 0; i < c->n; ++i) {
        const ak_vec2 to = ak_vec2_sub(sc->agents[i].goals.ptr[0], sc->positions[i]);
        const float phase = (float)((i * 2654435761u) & 0xffffu) / 65536.0f; /* spread, reproducible */
        c->ch[i] = ak_crowd_character_init(&c->gait, to, phase);
    }
    c->frames = 0;
}

ak_result crowd_chars_init(crowd_chars* c, const ak_crowd_scene* sc, size_t frame_cap, ak_diag* diag) {
    memset(c, 0, sizeof *c);
    ak_builtin_desc bd = {.cell_size = CROWD_CHARACTER_CELL};
    ak_result r = ak_builtin_create("builtin:humanoid", &bd, NULL, &c->scene);
    if (r != AK_OK) return r;
    ak_crowd_gait_desc gd = {.scene = c->scene, .clip_index = ak_scene_find_clip(c->scene, "walk")};
    if ((r = ak_crowd_gait_measure(&gd, NULL, &c->gait, diag)) != AK_OK) return r;
    c->n = sc->agent_count;
    c->ch = malloc(c->n * sizeof *c->ch);
    if (!c->ch) return AK_ERR_NO_MEMORY;
    crowd_chars_reset(c, sc);
    c->plant_bytes = ak_crowd_characters_scratch_size(&c->gait);
    c->plant_scratch = malloc(c->plant_bytes);
    if (!c->plant_scratch) return AK_ERR_NO_MEMORY;
    if (cli_poser_init(&c->poser, c->scene)) return AK_ERR_NO_MEMORY;
    c->poser_ready = true;
    return frame_cap ? crowd_chars_record_reserve(c, frame_cap) : AK_OK;
}

ak_result crowd_chars_record_reserve(crowd_chars* c, size_t frame_cap) {
    free(c->rec_pos);
    free(c->rec_ch);
    c->frames = 0;
    c->frame_cap = frame_cap;
    c->rec_pos = malloc(frame_cap * c->n * sizeof *c->rec_pos);
    c->rec_ch = malloc(frame_cap * c->n * sizeof *c->rec_ch);
    return c->rec_pos && c->rec_ch ? AK_OK : AK_ERR_NO_MEMORY;
}

ak_result crowd_chars_update(crowd_chars* c, const ak_vec2* velocities, const ak_vec2* positions, float dt) {
    ak_crowd_characters_job job = {.gait = &c->gait, .dt = dt, .velocities = {velocities, c->n},
                                   .characters = {c->ch, c->n}, .positions = {positions, c->n},
                                   .scratch = {c->plant_scratch, c->plant_bytes}};
    if (c->unplanted) job.positions = (ak_vec2_cspan){0}, job.scratch = (ak_u8_span){0};
    return ak_crowd_characters_update(&job);
}

void crowd_chars_record(crowd_chars* c, const ak_vec2* positions) {
    if (c->frames >= c->frame_cap) return;
    memcpy(c->rec_pos + c->frames * c->n, positions, c->n * sizeof *positions);
    memcpy(c->rec_ch + c->frames * c->n, c->ch, c->n * sizeof *c->ch);
    ++c->frames;
}

/* ---- people ------------------------------------------------------------------------------------ */

void crowd_people_free(crowd_people* pp) {
    free(pp->bpos);
    free(pp->bnrm);
    free(pp->bucket_frame);
    free(pp->agent_bucket);
    free(pp->roots);
    free(pp->agent_col);
    free(pp->casters);
    free(pp->pos);
    free(pp->nrm);
    free(pp->col);
    free(pp->idx);
    memset(pp, 0, sizeof *pp);
}

bool crowd_people_init(crowd_people* pp, size_t n, const crowd_chars* chars) {
    memset(pp, 0, sizeof *pp);
    const ak_mesh* m = chars->scene->meshes[0].mesh;
    pp->vcount = n * m->vertex_count;
    pp->icount = n * m->triangle_count * 3;
    pp->idx = malloc(pp->icount * sizeof *pp->idx);
    if (!pp->idx) return false;
    for (size_t a = 0; a < n; ++a)
        for (size_t k = 0; k < m->triangle_count * 3; ++k)
            pp->idx[a * m->triangle_count * 3 + k] = (uint32_t)(a * m->vertex_count + m->indices[k]);
    pp->pos = malloc(pp->vcount * sizeof *pp->pos);
    pp->nrm = malloc(pp->vcount * sizeof *pp->nrm);
    pp->col = malloc(pp->vcount * sizeof *pp->col);
    return pp->pos && pp->nrm && pp->col;
}

bool crowd_people_init_shared(crowd_people* pp, size_t n, const crowd_chars* chars) {
    const size_t chunk = n < CROWD_SHARED_CHUNK ? n : CROWD_SHARED_CHUNK;
    if (!crowd_people_init(pp, chunk, chars)) return false;
    const ak_mesh* m = chars->scene->meshes[0].mesh;
    pp->shared = true;
    pp->n = n;
    pp->mesh_vertices = m->vertex_count;
    pp->bucket_count = ak_crowd_character_bucket_count(AK_CROWD_PHASE_BUCKETS, AK_CROWD_WEIGHT_LEVELS);
    pp->bpos = malloc(pp->bucket_count * m->vertex_count * sizeof *pp->bpos);
    pp->bnrm = malloc(pp->bucket_count * m->vertex_count * sizeof *pp->bnrm);
    pp->bucket_frame = calloc(pp->bucket_count, sizeof *pp->bucket_frame);
    pp->agent_bucket = malloc(n * sizeof *pp->agent_bucket);
    pp->roots = malloc(n * sizeof *pp->roots);
    pp->agent_col = malloc(n * sizeof *pp->agent_col);
    pp->casters = calloc(n + 1, sizeof *pp->casters);
    return pp->bpos && pp->bnrm && pp->bucket_frame && pp->agent_bucket && pp->roots && pp->agent_col && pp->casters;
}

/* Shared poses: each agent's bucket (ak_crowd_character_bucket), each bucket used this frame
 * posed (unplanted) and skinned once, each agent's root matrix and shadow caster. */
static ak_result share_characters(crowd_people* pp, const ak_crowd_scene* sc, const ak_vec2* positions,
                                  crowd_chars* c) {
    const ak_mesh* m = c->scene->meshes[0].mesh;
    const size_t J = ak_scene_joint_count(c->scene), V = pp->mesh_vertices;
    if (++pp->frame == 0) { /* wrapped: forget every stamp */
        memset(pp->bucket_frame, 0, pp->bucket_count * sizeof *pp->bucket_frame);
        pp->frame = 1;
    }
    pp->posed = 0;
    for (size_t i = 0; i < pp->n; ++i) {
        ak_crowd_character q;
        const size_t b = ak_crowd_character_bucket(&c->gait, &c->ch[i], AK_CROWD_PHASE_BUCKETS,
                                                   AK_CROWD_WEIGHT_LEVELS, &q);
        if (b >= pp->bucket_count) return AK_ERR_BAD_DATA;
        if (pp->bucket_frame[b] != pp->frame) {
            ak_result res = ak_crowd_character_pose(&c->gait, &q, (ak_transform_span){c->poser.local, J});
            if (res == AK_OK) res = cli_poser_deform(&c->poser, false, CLI_LBS);
            if (res != AK_OK) return res;
            memcpy(pp->bpos + b * V, c->poser.positions[0], V * sizeof *pp->bpos);
            memcpy(pp->bnrm + b * V, c->poser.normals[0], V * sizeof *pp->bnrm);
            pp->bucket_frame[b] = pp->frame;
            ++pp->posed;
        }
        pp->agent_bucket[i] = (uint32_t)b;
        pp->roots[i] = ak_crowd_character_root(&c->gait, &c->ch[i], positions[i]);
        pp->agent_col[i] = crowd_palette[sc->group[i] % 4];
        pp->casters[i] = (ak_raster_mesh){.positions = {pp->bpos + b * V, V}, .normals = {pp->bnrm + b * V, V},
                                          .indices = {m->indices, m->triangle_count * 3},
                                          .model = &pp->roots[i], .material = {.color = pp->agent_col[i]}};
    }
    return AK_OK;
}

ak_result crowd_people_draw(crowd_people* pp, ak_raster* raster, const ak_raster_camera* cam,
                            const ak_raster_mesh* people) {
    if (!pp->shared) return people->positions.count ? ak_raster_draw_mesh(raster, cam, people) : AK_OK;
    /* One colour per draw call (material colour: per-vertex colours would be converted to
     * linear light at every triangle's corners), CROWD_SHARED_CHUNK agents at a time. */
    const size_t V = pp->mesh_vertices, I = pp->icount / (pp->n < CROWD_SHARED_CHUNK ? pp->n : CROWD_SHARED_CHUNK);
    for (size_t g = 0; g < 4; ++g) {
        const ak_vec4 colour = crowd_palette[g];
        size_t i = 0;
        for (;;) {
            size_t cnt = 0;
            for (; i < pp->n && cnt < CROWD_SHARED_CHUNK; ++i) {
                if (memcmp(&pp->agent_col[i], &colour, sizeof colour) != 0) continue;
                const ak_mat4 root = pp->roots[i];
                const ak_vec3 *bp = pp->bpos + (size_t)pp->agent_bucket[i] * V, *bn = pp->bnrm + (size_t)pp->agent_bucket[i] * V;
                ak_vec3 *op = pp->pos + cnt * V, *on = pp->nrm + cnt * V;
                for (size_t v = 0; v < V; ++v) {
                    op[v] = ak_mat4_transform_point(root, bp[v]);
                    on[v] = ak_mat4_transform_vector(root, bn[v]);
                }
                ++cnt;
            }
            if (!cnt) break;
            const ak_raster_mesh mesh = {.positions = {pp->pos, cnt * V}, .normals = {pp->nrm, cnt * V},
                                         .indices = {pp->idx, cnt * I}, .material = {.color = colour}};
            const ak_result res = ak_raster_draw_mesh(raster, cam, &mesh);
            if (res != AK_OK) return res;
        }
    }
    return AK_OK;
}

/* Each character posed (its clip time and heading, its feet planted), skinned (LBS) and placed in the world. */
static ak_result pose_characters(crowd_people* pp, const ak_crowd_scene* sc, const ak_vec2* positions,
                                 crowd_chars* c) {
    const ak_mesh* m = c->scene->meshes[0].mesh;
    const size_t J = ak_scene_joint_count(c->scene);
    for (size_t i = 0; i < c->n; ++i) {
        ak_result res = ak_crowd_character_pose_planted(&c->gait, &c->ch[i], positions[i],
                                                        (ak_transform_span){c->poser.local, J});
        if (res == AK_OK) res = cli_poser_deform(&c->poser, false, CLI_LBS);
        if (res != AK_OK) return res;
        const ak_mat4 root = ak_crowd_character_root(&c->gait, &c->ch[i], positions[i]);
        const ak_vec4 col = crowd_palette[sc->group[i] % 4];
        for (size_t v = 0; v < m->vertex_count; ++v) {
            const size_t o = i * m->vertex_count + v;
            pp->pos[o] = ak_mat4_transform_point(root, c->poser.positions[0][v]);
            pp->nrm[o] = ak_mat4_transform_vector(root, c->poser.normals[0][v]);
            pp->col[o] = col;
        }
    }
    return AK_OK;
}

ak_result crowd_people_update(crowd_people* pp, const ak_crowd_scene* sc, const ak_vec2* positions, crowd_chars* chars,
                              ak_raster_mesh* out) {
    if (pp->shared) {
        const ak_result r = share_characters(pp, sc, positions, chars);
        if (r != AK_OK) return r;
        *out = (ak_raster_mesh){0};
        return AK_OK;
    }
    const ak_result r = pose_characters(pp, sc, positions, chars);
    if (r != AK_OK) return r;
    *out = (ak_raster_mesh){.positions = {pp->pos, pp->vcount}, .normals = {pp->nrm, pp->vcount},
                            .colors = {pp->col, pp->vcount}, .indices = {pp->idx, pp->icount},
                            .material = {.color = {1, 1, 1, 1}}};
    return AK_OK;
}

bool crowd_walls(const ak_crowd_scene* sc, ak_vec3** out, size_t* out_vertex_count) {
    *out = NULL;
    *out_vertex_count = 0;
    size_t edges = 0;
    for (size_t k = 0; k < sc->obstacle_count; ++k)
        edges += sc->obstacles[k].vertices.count == 2 ? 1 : sc->obstacles[k].vertices.count;
    if (!edges) return true;
    ak_vec3* w = malloc(edges * 6 * sizeof *w);
    if (!w) return false;
    size_t n = 0;
    for (size_t k = 0; k < sc->obstacle_count; ++k) {
        const ak_vec2_cspan v = sc->obstacles[k].vertices;
        const size_t m = v.count == 2 ? 1 : v.count;
        for (size_t e = 0; e < m; ++e) {
            const ak_vec2 a = v.ptr[e], b = v.ptr[(e + 1) % v.count];
            const ak_vec3 q[4] = {{a.x, 0, a.y}, {b.x, 0, b.y}, {b.x, 1.2f, b.y}, {a.x, 1.2f, a.y}};
            ak_vec3* o = w + n;
            o[0] = q[0], o[1] = q[1], o[2] = q[2], o[3] = q[0], o[4] = q[2], o[5] = q[3];
            n += 6;
        }
    }
    *out = w;
    *out_vertex_count = n;
    return true;
}
