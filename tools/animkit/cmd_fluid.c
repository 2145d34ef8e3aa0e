/* animkit fluid: run a particle liquid (PBF, SPH or WCSPH) from a scene file or a preset, write
 * its final state as JSON, render it (PNG, GIF) or mesh its surface (OBJ). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "outfile.h"

static const char* const usage =
    "usage: animkit fluid [SCENE.json | --preset dam|pour|splash] [--solver sph|pbf] [--count N]\n"
    "                     [--steps S] [--dt DT] [--threads T] [--json OUT.json] [-o OUT.gif|OUT.png|OUT.obj]\n"
    "Simulate a particle liquid (docs/fluid.md lists the scene keys):\n"
    "  --preset   dam (a block released in a box), pour (a nozzle over a sphere), splash (a cube\n"
    "             dropped into a pool across a capsule); default dam when no scene is given\n"
    "  --solver   pbf (position-based fluids, default) or sph (Mueller et al. 2003); a scene may\n"
    "             also choose wcsph (Becker & Teschner 2007)\n"
    "  --count    particles of a preset, 8 to 2000000 (default 4000): rounded up to fill the preset's\n"
    "             whole block of lattice cells, so the run may have a few more\n"
    "  --steps    time steps, 0 to 10000000 (default: the scene's \"steps\", else its \"duration\"\n"
    "             (1 s) divided by the step)\n"
    "  --dt       step in seconds, [1e-7, 1] (default 1/400 for PBF, 0.001 for SPH)\n"
    "  --threads  1 to 64 (default 1); results are identical for any count\n"
    "  --json     final state {\"time\", \"particles\": [{\"p\", \"v\", \"rho\", \"pressure\"}],\n"
    "             \"max_density_error\", \"mean_density_error\"} (SI units; errors relative to rest\n"
    "             density, over particles with full neighbourhoods)\n"
    "  -o         OUT.png (last step), OUT.gif (up to 60 frames), OUT.obj (surface mesh of the\n"
    "             smoothed density, marching tetrahedra)\n"
    "Prints one summary line. Exit 1 for a bad scene or a liquid that blows up, collapses onto\n"
    "itself or explodes (the step and the symptom are named).\n";

/* ---- rendering: particles as shaded spheres ---------------------------------------------- */

/* An octahedron subdivided once and projected on the unit sphere, as 32 separate triangles. */
#define SPHERE_TRIS 32
static void unit_sphere(ak_vec3 out[SPHERE_TRIS * 3]) {
    const ak_vec3 v[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    const int f[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    int k = 0;
    for (int t = 0; t < 8; ++t) {
        ak_vec3 a = v[f[t][0]], b = v[f[t][1]], c = v[f[t][2]];
        ak_vec3 ab = ak_vec3_normalize(ak_vec3_add(a, b)), bc = ak_vec3_normalize(ak_vec3_add(b, c)),
                ca = ak_vec3_normalize(ak_vec3_add(c, a));
        const ak_vec3 tri[4][3] = {{a, ab, ca}, {ab, b, bc}, {ca, bc, c}, {ab, bc, ca}};
        for (int q = 0; q < 4; ++q)
            for (int e = 0; e < 3; ++e) out[k++] = tri[q][e];
    }
}

typedef struct renderer {
    int w, h;
    ak_raster* raster;
    ak_raster_camera cam;
    ak_vec3* pos;
    ak_vec3* nrm;
    ak_vec4* col;
    uint8_t* px;
    size_t cap;
    float radius;
    float floor_y;
    ak_vec3 centre;
    float extent;
} renderer;

static int renderer_init(renderer* r, const ak_fluid_scene* s, size_t cap, const ak_vec3* p, size_t n, bool gif) {
    memset(r, 0, sizeof *r);
    r->w = gif ? 480 : 800;
    r->h = gif ? 360 : 600;
    r->cap = cap;
    r->radius = 0.5f * ak_fluid_rest_spacing(&s->desc);
    ak_vec3 lo = s->desc.box_min, hi = s->desc.box_max;
    if (!(lo.x < hi.x)) { /* no box: frame the initial particles */
        lo = hi = n ? p[0] : ak_vec3_make(0, 0, 0);
        for (size_t i = 1; i < n; ++i) {
            lo = ak_vec3_make(fminf(lo.x, p[i].x), fminf(lo.y, p[i].y), fminf(lo.z, p[i].z));
            hi = ak_vec3_make(fmaxf(hi.x, p[i].x), fmaxf(hi.y, p[i].y), fmaxf(hi.z, p[i].z));
        }
    }
    r->floor_y = lo.y;
    r->centre = ak_vec3_scale(ak_vec3_add(lo, hi), 0.5f);
    r->extent = fmaxf(ak_vec3_length(ak_vec3_sub(hi, lo)), 1e-3f);
    ak_vec3 eye = ak_vec3_add(r->centre, ak_vec3_scale(ak_vec3_make(0.45f, 0.55f, 1.0f), 1.1f * r->extent));
    r->cam = ak_raster_camera_perspective(eye, r->centre, 0.7f, (float)r->w / (float)r->h, 0.01f * r->extent,
                                          10.0f * r->extent);
    if (cap > 200000) return cli_fail("fluid", "%zu particles: renders take at most 200000 (use --json or OBJ)", cap);
    r->pos = malloc(cap * SPHERE_TRIS * 3 * sizeof(ak_vec3));
    r->nrm = malloc(cap * SPHERE_TRIS * 3 * sizeof(ak_vec3));
    r->col = malloc(cap * SPHERE_TRIS * 3 * sizeof(ak_vec4));
    r->px = malloc((size_t)r->w * r->h * 4);
    if (!r->pos || !r->nrm || !r->col || !r->px) return cli_fail("fluid", "out of memory for the render");
    ak_result res = ak_raster_create(&(ak_raster_desc){.width = r->w, .height = r->h, .supersample = 2, .thread_count = 2},
                                     NULL, &r->raster);
    if (res != AK_OK) return cli_fail("fluid", "cannot create the render target: %s", ak_result_string(res));
    return CLI_OK;
}

static void renderer_free(renderer* r) {
    ak_raster_destroy(r->raster);
    free(r->pos), free(r->nrm), free(r->col), free(r->px);
}

/* An oriented box collider as 12 triangles (36 corners, flat normals). */
static void box_tris(const ak_fluid_collider* k, ak_vec3* pos, ak_vec3* nrm) {
    const ak_quat q = ak_quat_dot(k->orientation, k->orientation) > 0.0f
                          ? ak_quat_normalize(k->orientation)
                          : ak_quat_identity();
    int v = 0;
    for (int axis = 0; axis < 3; ++axis)
        for (int sign = -1; sign <= 1; sign += 2) {
            const int u = (axis + 1) % 3, w = (axis + 2) % 3;
            const float cu[6] = {-1, 1, 1, -1, 1, -1}, cw[6] = {-1, -1, 1, -1, 1, 1};
            for (int c = 0; c < 6; ++c) {
                const int cc = sign > 0 ? c : (c % 3 == 1 ? c + 1 : c % 3 == 2 ? c - 1 : c);
                float p[3], n[3] = {0, 0, 0};
                p[axis] = (float)sign, n[axis] = (float)sign;
                p[u] = cu[cc], p[w] = cw[cc];
                const ak_vec3 local = ak_vec3_make(
                    p[0] * k->half_extents.x, p[1] * k->half_extents.y, p[2] * k->half_extents.z);
                pos[v] = ak_vec3_add(k->a, ak_quat_rotate(q, local));
                nrm[v++] = ak_quat_rotate(q, ak_vec3_make(n[0], n[1], n[2]));
            }
        }
}

/* Spheres, capsules (as spheres along the segment) and boxes in grey; planes are not drawn. */
static ak_result draw_colliders(renderer* r, const ak_fluid_scene* s) {
    ak_vec3 unit[SPHERE_TRIS * 3], pos[SPHERE_TRIS * 3];
    unit_sphere(unit);
    for (size_t c = 0; c < s->collider_count; ++c) {
        const ak_fluid_collider* k = &s->colliders[c];
        if (k->shape == AK_FLUID_BOX) {
            ak_vec3 bp[36], bn[36];
            box_tris(k, bp, bn);
            ak_raster_mesh m = {.positions = {bp, 36},
                                .normals = {bn, 36},
                                .material = {.color = ak_vec4_make(0.75f, 0.72f, 0.68f, 1)},
                                .shading = AK_SHADING_PHONG};
            ak_result res = ak_raster_draw_mesh(r->raster, &r->cam, &m);
            if (res != AK_OK) return res;
            continue;
        }
        if (k->shape == AK_FLUID_PLANE || !(k->radius > 0.0f)) continue;
        const int parts = k->shape == AK_FLUID_CAPSULE ? 16 : 1;
        for (int q = 0; q < parts; ++q) {
            const float t = parts > 1 ? (float)q / (float)(parts - 1) : 0.0f;
            const ak_vec3 centre = ak_vec3_add(k->a, ak_vec3_scale(ak_vec3_sub(k->b, k->a), t));
            for (int v = 0; v < SPHERE_TRIS * 3; ++v) pos[v] = ak_vec3_add(centre, ak_vec3_scale(unit[v], k->radius));
            ak_raster_mesh m = {.positions = {pos, SPHERE_TRIS * 3}, .normals = {unit, SPHERE_TRIS * 3},
                                .material = {.color = ak_vec4_make(0.75f, 0.72f, 0.68f, 1)}, .shading = AK_SHADING_PHONG};
            ak_result res = ak_raster_draw_mesh(r->raster, &r->cam, &m);
            if (res != AK_OK) return res;
        }
    }
    return AK_OK;
}

/* The tank: the box's four side walls as faint glass (alpha-blended over the particles behind
 * them, depth tested, not hiding what is in front) and its twelve edges as dark lines. */
static ak_result draw_tank(renderer* r, const ak_fluid_scene* s) {
    const ak_vec3 lo = s->desc.box_min, hi = s->desc.box_max;
    if (!(lo.x < hi.x) || !(lo.y < hi.y) || !(lo.z < hi.z)) return AK_OK;
    ak_vec3 c[8];
    for (int k = 0; k < 8; ++k) c[k] = ak_vec3_make(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z);
    static const uint32_t walls[24] = {0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5,  /* z = lo, z = hi */
                                       0, 2, 6, 0, 6, 4, 1, 5, 7, 1, 7, 3}; /* x = lo, x = hi */
    static const uint32_t edges[24] = {0, 1, 2, 3, 4, 5, 6, 7, 0, 2, 1, 3, 4, 6, 5, 7, 0, 4, 1, 5, 2, 6, 3, 7};
    ak_raster_mesh glass = {.positions = {c, 8}, .indices = {walls, 24},
                            .material = {.color = ak_vec4_make(0.80f, 0.90f, 1.0f, 0.18f)},
                            .shading = AK_SHADING_UNLIT, .blend = AK_BLEND_ALPHA};
    ak_result res = ak_raster_draw_mesh(r->raster, &r->cam, &glass);
    ak_raster_lines lines = {.positions = {c, 8}, .indices = {edges, 24}, .color = ak_vec4_make(0.25f, 0.30f, 0.38f, 1),
                             .width = 2.0f};
    if (res == AK_OK) res = ak_raster_draw_lines(r->raster, &r->cam, &lines);
    return res;
}

static ak_result render_frame(renderer* r, const ak_fluid_scene* s, const ak_vec3* p, const uint8_t* flags, size_t n,
                              ak_image* out) {
    ak_vec3 unit[SPHERE_TRIS * 3];
    unit_sphere(unit);
    const size_t nv = SPHERE_TRIS * 3;
    for (size_t i = 0; i < n; ++i) {
        const ak_vec4 c = (flags[i] & AK_FLUID_FLAG_SURFACE) ? ak_vec4_make(0.55f, 0.78f, 0.95f, 1)
                                                             : ak_vec4_make(0.15f, 0.42f, 0.80f, 1);
        for (size_t k = 0; k < nv; ++k) {
            r->pos[i * nv + k] = ak_vec3_add(p[i], ak_vec3_scale(unit[k], r->radius));
            r->nrm[i * nv + k] = unit[k];
            r->col[i * nv + k] = c;
        }
    }
    ak_raster_clear(r->raster, ak_vec4_make(0.85f, 0.88f, 0.93f, 1), ak_vec4_make(0.55f, 0.58f, 0.64f, 1));
    ak_raster_mesh m = {.positions = {r->pos, n * nv}, .normals = {r->nrm, n * nv}, .colors = {r->col, n * nv},
                        .shading = AK_SHADING_PHONG};
    ak_raster_ground g = {.height = r->floor_y, .center = r->centre, .half_extent = r->extent,
                          .casters = n ? &m : NULL, .caster_count = n ? 1 : 0};
    ak_result res = ak_raster_draw_ground(r->raster, &r->cam, &g);
    if (res == AK_OK && n) res = ak_raster_draw_mesh(r->raster, &r->cam, &m);
    if (res == AK_OK) res = draw_colliders(r, s);
    if (res == AK_OK) res = draw_tank(r, s);
    *out = (ak_image){.pixels = r->px, .width = r->w, .height = r->h};
    if (res == AK_OK) res = ak_raster_resolve(r->raster, out);
    return res;
}

/* ---- surface mesh: marching tetrahedra over a smoothed density field ---------------------- */

typedef struct mesh_out {
    FILE* f;
    size_t vertex_count;
} mesh_out;

static ak_vec3 lerp_iso(ak_vec3 a, ak_vec3 b, float fa, float fb, float iso) {
    float t = (fb != fa) ? (iso - fa) / (fb - fa) : 0.5f;
    t = t < 0.0f ? 0.0f : t > 1.0f ? 1.0f : t;
    return ak_vec3_add(a, ak_vec3_scale(ak_vec3_sub(b, a), t));
}

/* One tetrahedron: up to two triangles where the field crosses iso (inside: f > iso). The
 * triangle is oriented so its normal points from inside to outside. */
static void tet(mesh_out* o, const ak_vec3 p[4], const float f[4], float iso) {
    int in[4], out[4], ni = 0, no = 0;
    for (int k = 0; k < 4; ++k) {
        if (f[k] > iso) in[ni++] = k;
        else out[no++] = k;
    }
    if (ni == 0 || no == 0) return;
    ak_vec3 v[4];
    int vc = 0;
    if (ni == 1 || no == 1) {
        const int lone = ni == 1 ? in[0] : out[0];
        const int* others = ni == 1 ? out : in;
        for (int k = 0; k < 3; ++k) v[vc++] = lerp_iso(p[lone], p[others[k]], f[lone], f[others[k]], iso);
    } else {
        v[vc++] = lerp_iso(p[in[0]], p[out[0]], f[in[0]], f[out[0]], iso);
        v[vc++] = lerp_iso(p[in[0]], p[out[1]], f[in[0]], f[out[1]], iso);
        v[vc++] = lerp_iso(p[in[1]], p[out[1]], f[in[1]], f[out[1]], iso);
        v[vc++] = lerp_iso(p[in[1]], p[out[0]], f[in[1]], f[out[0]], iso);
    }
    /* outward direction: from the inside corners' centroid to the outside corners' */
    ak_vec3 ci = {0, 0, 0}, co = {0, 0, 0};
    for (int k = 0; k < ni; ++k) ci = ak_vec3_add(ci, ak_vec3_scale(p[in[k]], 1.0f / ni));
    for (int k = 0; k < no; ++k) co = ak_vec3_add(co, ak_vec3_scale(p[out[k]], 1.0f / no));
    const ak_vec3 outward = ak_vec3_sub(co, ci);
    for (int t = 0; t < vc - 2; ++t) { /* (v0, v1, v2), and (v0, v2, v3) for a quad */
        ak_vec3 a = v[0], b = v[t + 1], c = v[t + 2];
        ak_vec3 nrm = ak_vec3_cross(ak_vec3_sub(b, a), ak_vec3_sub(c, a));
        if (ak_vec3_dot(nrm, outward) < 0.0f) {
            ak_vec3 tmp = b;
            b = c;
            c = tmp;
        }
        fprintf(o->f, "v %.6g %.6g %.6g\nv %.6g %.6g %.6g\nv %.6g %.6g %.6g\nf %zu %zu %zu\n", a.x, a.y, a.z, b.x,
                b.y, b.z, c.x, c.y, c.z, o->vertex_count + 1, o->vertex_count + 2, o->vertex_count + 3);
        o->vertex_count += 3;
    }
}

static int write_obj(const char* path, const ak_fluid_scene* s, const ak_vec3* p, size_t n) {
    if (n == 0) return cli_fail("fluid", "%s: no particles left to mesh", path);
    const float h = s->desc.h, cell = 0.5f * ak_fluid_rest_spacing(&s->desc);
    ak_vec3 lo = p[0], hi = p[0];
    for (size_t i = 1; i < n; ++i) {
        lo = ak_vec3_make(fminf(lo.x, p[i].x), fminf(lo.y, p[i].y), fminf(lo.z, p[i].z));
        hi = ak_vec3_make(fmaxf(hi.x, p[i].x), fmaxf(hi.y, p[i].y), fmaxf(hi.z, p[i].z));
    }
    lo = ak_vec3_sub(lo, ak_vec3_make(h, h, h));
    hi = ak_vec3_add(hi, ak_vec3_make(h, h, h));
    const double gx = ceil((hi.x - lo.x) / cell) + 1, gy = ceil((hi.y - lo.y) / cell) + 1,
                 gz = ceil((hi.z - lo.z) / cell) + 1;
    if (gx * gy * gz > 64e6) return cli_fail("fluid", "%s: the liquid spans too large a grid to mesh", path);
    const size_t nx = (size_t)gx, ny = (size_t)gy, nz = (size_t)gz;
    float* field = calloc(nx * ny * nz, sizeof *field);
    ak_grid_desc gd = {.cell_size = h};
    size_t gbytes = ak_grid_memory_size(n, &gd);
    void* gmem = malloc(gbytes);
    uint32_t near[512];
    if (!field || !gmem) {
        free(field), free(gmem);
        return cli_fail("fluid", "out of memory for the surface grid");
    }
    ak_grid grid;
    ak_grid_build(&gd, (ak_vec3_cspan){p, n}, (ak_u8_span){gmem, gbytes}, &grid);
    /* smoothed density / rest density: 1 inside the liquid, 0 outside; the surface is at 0.5 */
    const float scale = s->desc.particle_mass / s->desc.rest_density;
    for (size_t z = 0; z < nz; ++z)
        for (size_t y = 0; y < ny; ++y)
            for (size_t x = 0; x < nx; ++x) {
                ak_vec3 q = ak_vec3_make(lo.x + cell * x, lo.y + cell * y, lo.z + cell * z);
                size_t k = ak_grid_query(&grid, q, h, (ak_u32_span)AK_SPAN(near));
                if (k > 512) k = 512;
                float sum = 0.0f;
                for (size_t m = 0; m < k; ++m) sum += ak_fluid_poly6(ak_vec3_length_sq(ak_vec3_sub(q, p[near[m]])), h);
                field[(z * ny + y) * nx + x] = sum * scale;
            }
    cli_outfile out; /* a temporary renamed over path once complete */
    if (cli_outfile_open(&out, "fluid", path)) {
        free(field), free(gmem);
        return CLI_BAD_INPUT;
    }
    FILE* f = out.f;
    fprintf(f, "# animkit fluid: surface of the smoothed density at half the rest density\n");
    mesh_out o = {f, 0};
    /* six tetrahedra around the cube diagonal 0-7 */
    static const int tets[6][4] = {{0, 5, 1, 7}, {0, 1, 3, 7}, {0, 3, 2, 7}, {0, 2, 6, 7}, {0, 6, 4, 7}, {0, 4, 5, 7}};
    for (size_t z = 0; z + 1 < nz; ++z)
        for (size_t y = 0; y + 1 < ny; ++y)
            for (size_t x = 0; x + 1 < nx; ++x) {
                ak_vec3 cp[8];
                float cf[8];
                for (int c = 0; c < 8; ++c) {
                    size_t ix = x + (c & 1), iy = y + ((c >> 1) & 1), iz = z + ((c >> 2) & 1);
                    cp[c] = ak_vec3_make(lo.x + cell * ix, lo.y + cell * iy, lo.z + cell * iz);
                    cf[c] = field[(iz * ny + iy) * nx + ix];
                }
                for (int t = 0; t < 6; ++t) {
                    ak_vec3 tp[4];
                    float tf[4];
                    for (int k = 0; k < 4; ++k) tp[k] = cp[tets[t][k]], tf[k] = cf[tets[t][k]];
                    tet(&o, tp, tf, 0.5f);
                }
            }
    free(field), free(gmem);
    return cli_outfile_commit(&out, "fluid");
}

/* ---- health: a liquid that collapses or explodes fails like a blow-up ---------------------- */

/* Mechanical energy E = sum m (|v|^2 / 2 - g . x) may only fall, apart from what emitters bring
 * in (each emitted particle counted at its nozzle with its exit speed) and what moving colliders
 * can give; a liquid whose energy rises above the start's by more than the slack has exploded.
 * Slack: the mass of the largest particle count times (|g| L + 2 v^2), L the diagonal of the box
 * (or of the initial particles and nozzles), v the fastest initial particle, nozzle or collider:
 * the energy a liquid could gain falling across the whole scene and being struck by a collider. */
typedef struct health {
    double e0;        /* energy at the start plus what emitters brought in */
    double emit_e;    /* largest energy per kg of an emitted particle */
    double per_kg;    /* slack per kg */
    size_t peak;      /* largest particle count so far */
} health;

static double energy(const ak_fluid_scene* s, const ak_vec3* p, const ak_vec3* v, size_t n) {
    const ak_vec3 g = s->desc.gravity;
    double e = 0.0;
    for (size_t i = 0; i < n; ++i)
        e += 0.5 * ak_vec3_dot(v[i], v[i]) - ((double)g.x * p[i].x + (double)g.y * p[i].y + (double)g.z * p[i].z);
    return e * s->desc.particle_mass;
}

static void health_start(health* hl, const ak_fluid_scene* s, const ak_vec3* p, const ak_vec3* v, size_t n) {
    const ak_vec3 g = s->desc.gravity;
    ak_vec3 lo = s->desc.box_min, hi = s->desc.box_max;
    const bool box = lo.x < hi.x;
    if (!box) lo = hi = n ? p[0] : s->emitter_count ? s->emitters[0].position : ak_vec3_make(0, 0, 0);
    double vmax = 0.0;
    hl->emit_e = -INFINITY;
    for (size_t i = 0; i < n; ++i) {
        vmax = fmax(vmax, ak_vec3_length(v[i]));
        if (!box) lo = ak_vec3_min(lo, p[i]), hi = ak_vec3_max(hi, p[i]);
    }
    for (size_t k = 0; k < s->emitter_count; ++k) {
        const ak_fluid_emitter* m = &s->emitters[k];
        vmax = fmax(vmax, m->speed);
        if (!box) lo = ak_vec3_min(lo, m->position), hi = ak_vec3_max(hi, m->position);
        hl->emit_e = fmax(hl->emit_e, 0.5 * (double)m->speed * m->speed - ak_vec3_dot(g, m->position) +
                                          ak_vec3_length(g) * m->radius);
    }
    for (size_t k = 0; k < s->collider_count; ++k) vmax = fmax(vmax, ak_vec3_length(s->colliders[k].velocity));
    const double L = ak_vec3_length(ak_vec3_sub(hi, lo)) + 2.0 * s->desc.h;
    hl->per_kg = ak_vec3_length(g) * L + 2.0 * vmax * vmax;
    hl->e0 = energy(s, p, v, n);
    hl->peak = n;
}

static int health_check(health* hl, const ak_fluid_scene* s, const ak_vec3* p, const ak_vec3* v, size_t n,
                        const ak_fluid_stats* st, long step) {
    const double t = (double)step * s->dt;
    if (st->emitted_count) hl->e0 += (double)st->emitted_count * s->desc.particle_mass * hl->emit_e;
    hl->peak = n > hl->peak ? n : hl->peak;
    /* a collapse: more than 5% of the particles (and at least 8) sit on another one */
    if (st->coincident_count >= 8 && st->coincident_count * 20 > n)
        return cli_fail("fluid", "collapse at step %ld (t = %.4g s): %zu of %zu particles sit on another particle "
                        "(closer than 1%% of the rest spacing); lower --dt (now %g s)%s", step, t, st->coincident_count, n,
                        (double)s->dt, s->desc.bilateral && s->desc.scorr ? " or scorr_k (bilateral + s_corr)" : "");
    const double e = energy(s, p, v, n), slack = hl->per_kg * (double)hl->peak * s->desc.particle_mass;
    if (e > hl->e0 + slack)
        return cli_fail("fluid", "explosion at step %ld (t = %.4g s): the mechanical energy rose from %.4g J to %.4g J, "
                        "more than gravity and the scene's speeds can give (%.4g J); lower --dt (now %g s)%s", step, t,
                        hl->e0, e, slack, (double)s->dt,
                        s->desc.bilateral && s->desc.scorr ? " or scorr_k (bilateral + s_corr)" : "");
    return CLI_OK;
}

/* ---- the command ------------------------------------------------------------------------- */

static int write_json(const char* path, float t, const ak_vec3* p, const ak_vec3* v, const float* rho, const float* pres,
                      size_t n, const ak_fluid_stats* st) {
    /* "-": stdout; a file: a temporary renamed over path once complete */
    cli_outfile out;
    memset(&out, 0, sizeof out);
    const bool to_stdout = strcmp(path, "-") == 0;
    if (!to_stdout && cli_outfile_open(&out, "fluid", path)) return CLI_BAD_INPUT;
    FILE* f = to_stdout ? stdout : out.f;
    fprintf(f, "{\"time\": ");
    cli_json_write_number(f, t);
    fprintf(f, ", \"particles\": [");
    for (size_t i = 0; i < n; ++i) {
        fprintf(f, "%s{\"p\": [%.9g, %.9g, %.9g], \"v\": [%.9g, %.9g, %.9g], \"rho\": ", i ? ", " : "", p[i].x, p[i].y,
                p[i].z, v[i].x, v[i].y, v[i].z);
        cli_json_write_number(f, rho[i]);
        fprintf(f, ", \"pressure\": ");
        cli_json_write_number(f, pres[i]);
        fputc('}', f);
    }
    fprintf(f, "], \"max_density_error\": ");
    cli_json_write_number(f, st->max_density_error);
    fprintf(f, ", \"mean_density_error\": ");
    cli_json_write_number(f, st->mean_density_error);
    fprintf(f, "}\n");
    if (!to_stdout) return cli_outfile_commit(&out, "fluid");
    if (fflush(stdout) != 0 || ferror(stdout)) return cli_fail("fluid", "-: cannot write to stdout");
    return CLI_OK;
}

int cmd_fluid(int argc, char** argv) {
    static const cli_opt opts[] = {
        {"--preset", NULL, true}, {"--solver", NULL, true},  {"--count", NULL, true}, {"--steps", NULL, true},
        {"--dt", NULL, true},     {"--threads", NULL, true}, {"--json", NULL, true},  {"--output", "-o", true},
    };
    cli_args a;
    int rc = cli_parse("fluid", argc, argv, opts, sizeof opts / sizeof opts[0], &a);
    if (rc) return rc;
    if (a.help) {
        fputs(usage, stdout);
        return CLI_OK;
    }
    if (a.pos_count > 1) return cli_usage("fluid", "expected at most one scene file");
    const char* preset = CLI_GET(&a, "--preset");
    if (a.pos_count == 1 && preset) return cli_usage("fluid", "give a scene file or --preset, not both");
    long count = 0, steps = -1, threads = 1;
    float dt = 0.0f;
    const char* sv = CLI_GET(&a, "--count");
    if (sv && !cli_parse_int(sv, 8, AK_FLUID_SCENE_MAX_PARTICLES, &count))
        return cli_usage("fluid", "--count '%s': allowed 8 to %u", sv, AK_FLUID_SCENE_MAX_PARTICLES);
    if (sv && a.pos_count == 1) return cli_usage("fluid", "--count applies to presets (a scene file sets its blocks)");
    sv = CLI_GET(&a, "--steps");
    if (sv && !cli_parse_int(sv, 0, AK_FLUID_SCENE_MAX_STEPS, &steps))
        return cli_usage("fluid", "--steps '%s': allowed 0 to %ld", sv, AK_FLUID_SCENE_MAX_STEPS);
    sv = CLI_GET(&a, "--dt");
    if (sv && (!cli_parse_float(sv, &dt) || !(dt >= 1e-7f) || dt > 1.0f))
        return cli_usage("fluid", "--dt '%s': allowed [1e-07, 1] seconds", sv);
    sv = CLI_GET(&a, "--threads");
    if (sv && !cli_parse_int(sv, 1, 64, &threads)) return cli_usage("fluid", "--threads '%s': allowed 1 to 64", sv);
    const char* solver = CLI_GET(&a, "--solver");
    if (solver && strcmp(solver, "sph") != 0 && strcmp(solver, "pbf") != 0)
        return cli_usage("fluid", "--solver '%s': allowed sph, pbf", solver);
    const char* out = CLI_GET(&a, "--output");
    const bool gif = out && cli_has_ext(out, ".gif"), png = out && cli_has_ext(out, ".png"),
               obj = out && cli_has_ext(out, ".obj");
    if (out && !gif && !png && !obj) return cli_usage("fluid", "-o '%s': expected a .gif, .png or .obj file", out);

    ak_fluid_scene* s = malloc(sizeof *s);
    if (!s) return cli_fail("fluid", "out of memory");
    ak_diag diag;
    if (a.pos_count == 1) {
        if (ak_fluid_scene_load_file(a.pos[0], s, &diag) != AK_OK) {
            free(s);
            return cli_fail("fluid", "%s", diag.message);
        }
    } else if (ak_fluid_scene_preset(preset ? preset : "dam", count, s, &diag) != AK_OK) {
        free(s);
        return cli_usage("fluid", "--preset '%s': allowed " AK_FLUID_SCENE_PRESETS, preset);
    }
    if (solver) {
        s->desc.solver = strcmp(solver, "sph") == 0 ? AK_FLUID_SPH : AK_FLUID_PBF;
        if (!s->dt_set) s->dt = ak_fluid_scene_default_dt(s->desc.solver);
        if (s->desc.solver == AK_FLUID_SPH && s->desc.viscosity == 0.0f) s->desc.viscosity = 0.02f;
    }
    if (dt > 0.0f) s->dt = dt;
    if (steps >= 0) s->steps = steps;
    s->steps = ak_fluid_scene_steps(s);

    const size_t cap = ak_fluid_scene_capacity(s);
    {
        const double iters = s->desc.solver == AK_FLUID_PBF ? (s->desc.iterations ? s->desc.iterations : 4) : 1;
        int wrc = cli_work_check("fluid", (double)cap * (double)s->steps * iters,
                                 "particle updates (particles x steps x solver iterations)",
                                 "--steps, --count or the scene's \"iterations\"");
        if (wrc) {
            free(s);
            return wrc;
        }
    }
    ak_vec3* pos = calloc(cap ? cap : 1, sizeof *pos);
    ak_vec3* vel = calloc(cap ? cap : 1, sizeof *vel);
    uint8_t* flags = calloc(cap ? cap : 1, 1);
    float* rho = calloc(cap ? cap : 1, sizeof *rho);
    float* pres = calloc(cap ? cap : 1, sizeof *pres);
    const size_t bytes = ak_fluid_scratch_size(cap, &s->desc);
    void* scratch = bytes ? malloc(bytes) : NULL;
    renderer ren;
    memset(&ren, 0, sizeof ren);
    ak_gif_writer* gw = NULL;
    if (!pos || !vel || !flags || !rho || !pres || !scratch) {
        rc = cli_fail("fluid", "out of memory for %zu particles", cap);
        goto done;
    }
    size_t n = ak_fluid_scene_fill(s, pos, vel, cap);
    if (gif || png) {
        rc = renderer_init(&ren, s, cap, pos, n, gif);
        if (rc) goto done;
    }
    if (gif) {
        ak_result res = ak_gif_writer_create(out, &(ak_gif_desc){.width = ren.w, .height = ren.h, .delay_cs = 4}, NULL, &gw);
        if (res != AK_OK) {
            rc = cli_fail("fluid", "%s: %s", out, ak_result_string(res));
            goto done;
        }
    }
    ak_fluid_stats st;
    memset(&st, 0, sizeof st);
    ak_fluid_step_job job = {.desc = &s->desc, .dt = s->dt, .positions = {pos, cap}, .velocities = {vel, cap},
                             .particle_count = &n, .colliders = {s->colliders, s->collider_count},
                             .emitters = {s->emitters, s->emitter_count}, .sinks = {s->sinks, s->sink_count},
                             .thread_count = (uint32_t)threads, .scratch = {scratch, bytes}, .out_flags = {flags, cap},
                             .out_densities = {rho, cap}, .out_pressures = {pres, cap}, .out_stats = &st};
    health hl;
    health_start(&hl, s, pos, vel, n);
    const long frame_every = s->steps > 60 ? (s->steps + 59) / 60 : 1;
    const double t0 = cli_now();
    for (long k = 0; k < s->steps; ++k) {
        job.time = (float)((double)k * s->dt);
        ak_result res = ak_fluid_step_run(&job);
        if (res == AK_ERR_NO_CONVERGENCE) {
            rc = cli_fail("fluid", "blow-up at step %ld (t = %.4g s): a particle moved more than 100 h in one step or "
                          "became non-finite; lower --dt (now %g s)", k + 1, (k + 1) * (double)s->dt, (double)s->dt);
            goto done;
        }
        if (res != AK_OK) {
            rc = cli_fail("fluid", "step %ld: %s", k + 1, ak_result_string(res));
            goto done;
        }
        rc = health_check(&hl, s, pos, vel, n, &st, k + 1);
        if (rc) goto done;
        /* colliders with a velocity move with it */
        for (size_t c = 0; c < s->collider_count; ++c) {
            ak_vec3 dv = ak_vec3_scale(s->colliders[c].velocity, s->dt);
            s->colliders[c].a = ak_vec3_add(s->colliders[c].a, dv);
            s->colliders[c].b = ak_vec3_add(s->colliders[c].b, dv);
        }
        if (gw && ((k + 1) % frame_every == 0 || k + 1 == s->steps)) {
            ak_image img;
            res = render_frame(&ren, s, pos, flags, n, &img);
            if (res == AK_OK) res = ak_gif_writer_add_frame(gw, &img);
            if (res != AK_OK) {
                rc = cli_fail("fluid", "%s: %s", out, ak_result_string(res));
                goto done;
            }
        }
        cli_progress("fluid", (size_t)k + 1, (size_t)s->steps);
    }
    const double wall = cli_now() - t0;
    const float t_end = (float)((double)s->steps * s->dt);
    if (gw) {
        ak_result res = ak_gif_writer_finish(gw);
        gw = NULL;
        if (res != AK_OK) {
            rc = cli_fail("fluid", "%s: %s", out, ak_result_string(res));
            goto done;
        }
        cli_wrote(out, "%zu particles over %ld steps", n, s->steps);
    }
    if (png) {
        ak_image img;
        ak_result res = render_frame(&ren, s, pos, flags, n, &img);
        if (res == AK_OK) res = ak_png_write(out, &img);
        if (res != AK_OK) {
            rc = cli_fail("fluid", "%s: %s", out, ak_result_string(res));
            goto done;
        }
        cli_wrote(out, "the last step");
    }
    if (obj) {
        rc = write_obj(out, s, pos, n);
        if (rc) goto done;
        cli_wrote(out, "the liquid's surface");
    }
    const char* json = CLI_GET(&a, "--json");
    if (json) {
        rc = write_json(json, t_end, pos, vel, rho, pres, n, &st);
        if (rc) goto done;
        if (strcmp(json, "-") != 0) cli_wrote(json, "%zu particles", n);
    }
    static const char* const names[] = {"pbf", "sph", "wcsph"};
    fprintf(json && strcmp(json, "-") == 0 ? stderr : stdout,
            "fluid: %s, %zu particles, %ld steps of %g s (t = %.4g s) in %.2f s; density error mean %.4f max %.4f over "
            "%zu particles\n",
            names[s->desc.solver], n, s->steps, (double)s->dt, (double)t_end, wall, (double)st.mean_density_error,
            (double)st.max_density_error, st.full_count);
done:
    ak_gif_writer_discard(gw); /* a failed run leaves no partial GIF */
    renderer_free(&ren);
    free(pos), free(vel), free(flags), free(rho), free(pres), free(scratch), free(s);
    return rc;
}
