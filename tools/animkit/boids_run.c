/* The flock shared by `animkit boids` and `animkit view` (boids_run.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "boids_run.h"

int boids_run_init(boids_run* r, const ak_boids_scene* sc, const char* cmd, const char* file, uint32_t threads,
                   bool naive) {
    ak_diag diag;
    ak_boids_scene_run_desc d = {.name = file, .thread_count = threads, .naive = naive};
    if (ak_boids_scene_run_init(r, sc, &d, &diag) != AK_OK) return cli_fail(cmd, "%s", diag.message);
    return CLI_OK;
}

ak_result boids_run_step(boids_run* r, long step) {
    r->step_index = step;
    return ak_boids_scene_run_step(r);
}

const char* boids_run_error(ak_result res) { return ak_boids_scene_run_error(res); }

void boids_run_free(boids_run* r) { ak_boids_scene_run_free(r); }

/* ---- shapes ------------------------------------------------------------------------------- */

/* The flap: one scalar channel in [-1, 1] over a third of a second (wings up, a slow
 * downstroke, a quick recovery), Catmull-Rom through the keys. Each agent samples it at its
 * own phase. */
static ak_clip* make_beat_clip(void) {
    static const float times[] = {0.0f, 0.06f, 0.19f, 0.27f, 1.0f / 3.0f};
    static const float values[] = {1.0f, 0.7f, -1.0f, -0.3f, 1.0f};
    const ak_raw_channel ch = {.target = AK_CHANNEL_SCALAR, .index = 0, .component_count = 1,
                               .interp = AK_INTERP_CARDINAL, .key_count = 5, .times = times, .values = values};
    const ak_raw_clip raw = {.name = "beat", .channels = &ch, .channel_count = 1, .scalar_count = 1};
    ak_clip* clip = NULL;
    return ak_clip_build(&raw, NULL, &clip, NULL) == AK_OK ? clip : NULL;
}

/* A plane facing up: the renderer's ground plane shows it. */
bool boids_is_floor(const ak_boids_obstacle* o) {
    return o->kind == AK_BOIDS_PLANE && ak_vec3_normalize(o->normal).y > 0.999f;
}

/* Unit sphere (lat-long) and box triangles appended to the obstacle mesh. */
bool boids_shapes_obstacles(boids_shapes* r, const ak_boids_params* prm, float plane_size) {
    free(r->opos);
    free(r->oidx);
    r->overt = r->otri = 0;
    enum { LAT = 10, LON = 16 };
    size_t nv = 0, nt = 0;
    for (uint32_t k = 0; k < prm->obstacle_count; ++k) {
        const ak_boids_obstacle* o = &prm->obstacles[k];
        if (o->kind == AK_BOIDS_SPHERE) {
            nv += (LAT + 1) * (LON + 1);
            nt += LAT * LON * 2;
        } else {
            nv += 8;
            nt += 12;
        }
    }
    r->opos = malloc((nv + 1) * sizeof(ak_vec3));
    r->oidx = malloc((nt + 1) * 3 * sizeof(uint32_t));
    if (!r->opos || !r->oidx) return false;
    size_t v = 0, t = 0;
    for (uint32_t k = 0; k < prm->obstacle_count; ++k) {
        const ak_boids_obstacle* o = &prm->obstacles[k];
        const uint32_t base = (uint32_t)v;
        if (boids_is_floor(o)) continue; /* drawn as the ground itself */
        if (o->kind == AK_BOIDS_SPHERE) {
            for (int a = 0; a <= LAT; ++a)
                for (int b = 0; b <= LON; ++b) {
                    const float th = AK_PI * (float)a / LAT, ph = AK_TWO_PI * (float)b / LON;
                    r->opos[v++] = ak_vec3_madd(o->center, ak_vec3_make(sinf(th) * cosf(ph), cosf(th), sinf(th) * sinf(ph)),
                                                o->radius);
                }
            for (int a = 0; a < LAT; ++a)
                for (int b = 0; b < LON; ++b) {
                    const uint32_t i0 = base + (uint32_t)(a * (LON + 1) + b), i1 = i0 + 1, i2 = i0 + LON + 1, i3 = i2 + 1;
                    const uint32_t tri[6] = {i0, i1, i2, i1, i3, i2};
                    memcpy(r->oidx + 3 * t, tri, sizeof tri);
                    t += 2;
                }
            continue;
        }
        ak_vec3 c = o->center, h = o->half_extents;
        ak_vec3 ax = ak_vec3_make(1, 0, 0), ay = ak_vec3_make(0, 1, 0), az = ak_vec3_make(0, 0, 1);
        if (o->kind == AK_BOIDS_PLANE) {
            /* A thin slab along the plane, drawn as a box. */
            ay = ak_vec3_normalize(o->normal);
            ax = ak_vec3_normalize(ak_vec3_any_perpendicular(ay));
            az = ak_vec3_cross(ax, ay);
            h = ak_vec3_make(plane_size, 0.02f * plane_size, plane_size);
            c = ak_vec3_madd(c, ay, -h.y);
        }
        for (int q = 0; q < 8; ++q) {
            ak_vec3 p = c;
            p = ak_vec3_madd(p, ax, (q & 1) ? h.x : -h.x);
            p = ak_vec3_madd(p, ay, (q & 2) ? h.y : -h.y);
            p = ak_vec3_madd(p, az, (q & 4) ? h.z : -h.z);
            r->opos[v++] = p;
        }
        static const uint32_t faces[36] = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                                           2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
        for (int q = 0; q < 36; ++q) r->oidx[3 * t + (size_t)q] = base + faces[q];
        t += 12;
    }
    r->overt = v;
    r->otri = t;
    return true;
}

bool boids_shapes_init(boids_shapes* r, const ak_boids_scene* sc, size_t n, float plane_size) {
    memset(r, 0, sizeof *r);
    r->pos = malloc((n * 5 + 1) * sizeof(ak_vec3));
    r->col = malloc((n * 5 + 1) * sizeof(ak_vec4));
    r->idx = malloc((n * 12 + 1) * sizeof(uint32_t));
    if (!r->pos || !r->col || !r->idx) return false;
    for (size_t i = 0; i < n; ++i) {
        const uint32_t b = (uint32_t)(5 * i);
        const uint32_t tri[12] = {b, b + 1, b + 2, b, b + 2, b + 3, b, b + 4, b + 2, b + 1, b + 4, b + 3};
        memcpy(r->idx + 12 * i, tri, sizeof tri);
    }
    if (!boids_shapes_obstacles(r, &sc->params, plane_size)) return false;
    r->beat = make_beat_clip();
    return r->beat != NULL;
}

void boids_shapes_free(boids_shapes* r) {
    free(r->pos);
    free(r->col);
    free(r->idx);
    free(r->opos);
    free(r->oidx);
    ak_clip_destroy(r->beat);
    memset(r, 0, sizeof *r);
}

void boids_shapes_update(boids_shapes* r, const ak_boids_scene* sc, const boids_run* st, float time, ak_raster_mesh* out_birds,
                         ak_raster_mesh* out_obstacles) {
    const float L = sc->shape_size;
    for (size_t i = 0; i < st->agent_count; ++i) {
        ak_vec3 f = ak_vec3_normalize(st->velocities[i]);
        if (ak_vec3_length_sq(f) < 0.5f) f = ak_vec3_make(0, 0, 1);
        ak_vec3 right = ak_vec3_normalize(ak_vec3_cross(f, ak_vec3_make(0, 1, 0)));
        if (ak_vec3_length_sq(right) < 0.5f) right = ak_vec3_make(1, 0, 0);
        const ak_vec3 up = ak_vec3_cross(right, f);
        const float phase = (float)((i * 2654435761u) & 1023u) / 1024.0f;
        const float period = ak_clip_duration(r->beat);
        float beat = 0.0f;
        ak_clip_sample(r->beat, ak_time_wrap(time + phase * period, period, AK_WRAP_LOOP), NULL,
                       (ak_transform_span){NULL, 0}, (ak_f32_span){NULL, 0}, (ak_f32_span){&beat, 1});
        const ak_vec3 p = st->positions[i];
        ak_vec3* q = r->pos + 5 * i;
        if (sc->shape == 0) {
            q[0] = ak_vec3_madd(p, f, 0.5f * L);                                       /* beak */
            q[1] = ak_vec3_madd(ak_vec3_madd(p, right, -0.5f * L), up, 0.25f * L * beat); /* left wing tip */
            q[2] = ak_vec3_madd(p, f, -0.5f * L);                                      /* tail */
            q[3] = ak_vec3_madd(ak_vec3_madd(p, right, 0.5f * L), up, 0.25f * L * beat);  /* right wing tip */
            q[4] = ak_vec3_madd(p, up, -0.12f * L);                                    /* keel */
        } else {
            const ak_vec3 tail = ak_vec3_madd(ak_vec3_madd(p, f, -0.5f * L), right, 0.15f * L * beat);
            q[0] = ak_vec3_madd(p, f, 0.5f * L);
            q[1] = ak_vec3_madd(p, right, -0.08f * L);
            q[2] = tail;
            q[3] = ak_vec3_madd(p, right, 0.08f * L);
            q[4] = ak_vec3_madd(p, up, 0.18f * L);
        }
        const ak_vec4 c = sc->color[st->species[i]];
        for (int k = 0; k < 5; ++k) r->col[5 * i + (size_t)k] = c;
    }
    *out_birds = (ak_raster_mesh){.positions = {r->pos, 5 * st->agent_count}, .colors = {r->col, 5 * st->agent_count},
                            .indices = {r->idx, 12 * st->agent_count}, .shading = AK_SHADING_FLAT,
                            .material = {.color = {1, 1, 1, 1}, .specular = -1}};
    *out_obstacles = (ak_raster_mesh){.positions = {r->opos, r->overt}, .indices = {r->oidx, 3 * r->otri},
                          .material = {.color = {0.62f, 0.64f, 0.68f, 1}}};
}
