/* Every rigid shape drawn as itself: ak_rigid_body_mesh against the shapes' own geometry (a
 * hull's mesh is closed, encloses the hull's volume and has the hull's points as vertices; a
 * compound's is its children's; heightfields and trimeshes keep their samples and triangles),
 * and `animkit rigid -o OUT.png` drawing a hull as the box it is, not as a sphere. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <animkit/animkit.h>
#include <cjson/cJSON.h>

#include "ak_test.h"
#include "cli_test.h"
#include "gltf_validate.h"

typedef struct mesh_buf {
    ak_vec3 *p, *n;
    uint32_t* t;
    size_t nv, ni;
} mesh_buf;

static bool body_mesh(const ak_rigid_model* m, size_t i, mesh_buf* out) {
    memset(out, 0, sizeof *out);
    ak_rigid_body_mesh_size(m, i, &out->nv, &out->ni);
    out->p = malloc((out->nv + 1) * sizeof(ak_vec3));
    out->n = malloc((out->nv + 1) * sizeof(ak_vec3));
    out->t = malloc((out->ni + 1) * sizeof(uint32_t));
    if (!out->p || !out->n || !out->t) return false;
    return ak_rigid_body_mesh(m, i, 0.0f, (ak_vec3_span){out->p, out->nv},
                              (ak_vec3_span){out->n, out->nv},
                              (ak_u32_span){out->t, out->ni}) == AK_OK;
}

static void mesh_buf_free(mesh_buf* b) { free(b->p), free(b->n), free(b->t); }

/* Volume enclosed by a triangle mesh (divergence theorem, double precision). */
static double mesh_volume(const mesh_buf* b) {
    double v = 0.0;
    for (size_t k = 0; k < b->ni; k += 3) {
        ak_vec3 a = b->p[b->t[k]], c = b->p[b->t[k + 1]], d = b->p[b->t[k + 2]];
        v += ((double)a.x * ((double)c.y * d.z - (double)c.z * d.y) -
              (double)a.y * ((double)c.x * d.z - (double)c.z * d.x) +
              (double)a.z * ((double)c.x * d.y - (double)c.y * d.x)) /
             6.0;
    }
    return v;
}

/* Closed and consistently oriented once equal positions are merged: every directed edge (a, b)
 * appears exactly once and its reverse (b, a) exactly once. */
static bool mesh_closed(const mesh_buf* b) {
    size_t nv = b->nv;
    uint32_t* weld = malloc((nv + 1) * sizeof *weld);
    if (!weld) return false;
    for (size_t i = 0; i < nv; ++i) {
        weld[i] = (uint32_t)i;
        for (size_t j = 0; j < i; ++j)
            if (b->p[j].x == b->p[i].x && b->p[j].y == b->p[i].y && b->p[j].z == b->p[i].z) {
                weld[i] = weld[j];
                break;
            }
    }
    bool ok = true;
    for (size_t k = 0; ok && k < b->ni; ++k) {
        uint32_t a = weld[b->t[k]], c = weld[b->t[k % 3 == 2 ? k - 2 : k + 1]];
        if (a == c) continue; /* a degenerate edge */
        int same = 0, rev = 0;
        for (size_t m = 0; m < b->ni; ++m) {
            uint32_t x = weld[b->t[m]], y = weld[b->t[m % 3 == 2 ? m - 2 : m + 1]];
            same += x == a && y == c;
            rev += x == c && y == a;
        }
        ok = same == 1 && rev == 1;
    }
    free(weld);
    return ok;
}

AK_TEST(hull_mesh_is_closed_holds_the_volume_and_the_points) {
    /* 26 points of a squashed, tilted ellipsoid plus interior points: the hull's vertices are a
     * subset of them, in the body frame after ak_rigid_body_shape_frame */
    ak_vec3 pts[40];
    size_t np = 0;
    for (int i = 0; i < 26; ++i) {
        float th = 0.7f * (float)i, z = -1.0f + 2.0f * ((float)i + 0.5f) / 26.0f;
        float r = sqrtf(1.0f - z * z);
        pts[np++] =
            ak_vec3_make(1.3f * r * cosf(th) + 0.2f * z, 0.6f * r * sinf(th), 0.9f * z + 0.5f);
    }
    for (int i = 0; i < 6; ++i) pts[np++] = ak_vec3_make(0.1f * (float)i - 0.3f, 0.05f, 0.4f);
    ak_rigid_body_desc b = {.shape = {.type = AK_RIGID_HULL, .points = {pts, np}},
                            .position = {1, 2, 3},
                            .orientation = {0.1f, 0.2f, 0.3f, 0.9f}};
    ak_rigid_model* m = NULL;
    AK_CHECK_EQ(ak_rigid_model_create(&(ak_rigid_model_desc){.bodies = {&b, 1}}, NULL, &m), AK_OK);
    if (!m) return;
    mesh_buf mb;
    AK_CHECK(body_mesh(m, 0, &mb));
    AK_CHECK(mb.nv >= 4 && mb.ni >= 12 && mb.ni % 3 == 0);
    AK_CHECK_MSG(mesh_closed(&mb), "the hull's mesh is not closed");
    const double vol = ak_rigid_body_volume(m, 0), mv = mesh_volume(&mb);
    AK_CHECK_MSG(vol > 0.1 && fabs(mv - vol) < 1e-4 * vol, "mesh volume %g, hull %g", mv, vol);
    /* every vertex is one of the given points (moved into the body frame) */
    const ak_transform sf = ak_rigid_body_shape_frame(m, 0);
    size_t off = 0;
    for (size_t v = 0; v < mb.nv; ++v) {
        float best = INFINITY;
        for (size_t k = 0; k < np; ++k) {
            ak_vec3 pb = ak_vec3_add(sf.translation, ak_quat_rotate(sf.rotation, pts[k]));
            best = fminf(best, ak_vec3_distance(pb, mb.p[v]));
        }
        off += best > 1e-5f;
        /* unit normal pointing away from the centre of mass (the body frame's origin) */
        AK_CHECK_NEAR(ak_vec3_length(mb.n[v]), 1.0f, 1e-5f);
    }
    AK_CHECK_MSG(off == 0, "%zu vertices are not hull points", off);
    /* the normal is the face's: outward, and every triangle's own normal agrees with it */
    size_t bad = 0;
    for (size_t k = 0; k < mb.ni; k += 3) {
        ak_vec3 a = mb.p[mb.t[k]], c = mb.p[mb.t[k + 1]], d = mb.p[mb.t[k + 2]];
        ak_vec3 g = ak_vec3_cross(ak_vec3_sub(c, a), ak_vec3_sub(d, a));
        bad += ak_vec3_dot(g, mb.n[mb.t[k]]) <= 0.0f || ak_vec3_dot(mb.n[mb.t[k]], a) <= 0.0f;
    }
    AK_CHECK_EQ(bad, 0u);
    /* the primitive-only function draws no hull (it has no faces to draw from) */
    size_t snv = 1, sni = 1;
    ak_rigid_shape_mesh_size(&b.shape, &snv, &sni);
    AK_CHECK_EQ(snv, 0u);
    /* errors */
    AK_CHECK_EQ(ak_rigid_body_mesh(m, 1, 0.0f, (ak_vec3_span){mb.p, mb.nv},
                                   (ak_vec3_span){mb.n, mb.nv}, (ak_u32_span){mb.t, mb.ni}),
                AK_ERR_BAD_INDEX);
    AK_CHECK_EQ(ak_rigid_body_mesh(m, 0, 0.0f, (ak_vec3_span){mb.p, mb.nv - 1},
                                   (ak_vec3_span){mb.n, mb.nv}, (ak_u32_span){mb.t, mb.ni}),
                AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_rigid_body_mesh(m, 0, NAN, (ak_vec3_span){mb.p, mb.nv},
                                   (ak_vec3_span){mb.n, mb.nv}, (ak_u32_span){mb.t, mb.ni}),
                AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_rigid_body_mesh(NULL, 0, 0.0f, (ak_vec3_span){mb.p, mb.nv},
                                   (ak_vec3_span){mb.n, mb.nv}, (ak_u32_span){mb.t, mb.ni}),
                AK_ERR_NULL_ARG);
    mesh_buf_free(&mb);
    ak_rigid_model_destroy(m);
}

AK_TEST(compound_mesh_is_its_children) {
    /* two boxes apart and a tetrahedron hull: the mesh encloses the summed volume (the children do
     * not overlap) and is closed; the boxes' corners are where the children put them */
    const ak_vec3 tet[4] = {{0, 0, 0}, {0.4f, 0, 0}, {0, 0.4f, 0}, {0, 0, 0.4f}};
    const ak_rigid_child kids[3] = {
        {.shape = {.type = AK_RIGID_BOX, .half_extents = {0.5f, 0.1f, 0.2f}},
         .position = {-1, 0, 0}},
        {.shape = {.type = AK_RIGID_BOX, .half_extents = {0.1f, 0.3f, 0.1f}},
         .position = {1, 0.5f, 0},
         .orientation = {0, 0, 0.38268343f, 0.92387953f}},
        {.shape = {.type = AK_RIGID_HULL, .points = {tet, 4}}, .position = {0, 1.5f, 0}},
    };
    ak_rigid_body_desc b = {
        .shape = {.type = AK_RIGID_COMPOUND, .children = kids, .child_count = 3}};
    ak_rigid_model* m = NULL;
    AK_CHECK_EQ(ak_rigid_model_create(&(ak_rigid_model_desc){.bodies = {&b, 1}}, NULL, &m), AK_OK);
    if (!m) return;
    mesh_buf mb;
    AK_CHECK(body_mesh(m, 0, &mb));
    AK_CHECK_EQ(mb.nv, 24u + 24u + 12u);
    const double want = 8.0 * 0.5 * 0.1 * 0.2 + 8.0 * 0.1 * 0.3 * 0.1 + 0.4 * 0.4 * 0.4 / 6.0;
    AK_CHECK_NEAR(mesh_volume(&mb), want, 1e-5 * want);
    AK_CHECK_NEAR(ak_rigid_body_volume(m, 0), want, 1e-5 * want);
    AK_CHECK(mesh_closed(&mb));
    /* in the shape frame, the first box spans x in [-1.5, -0.5] */
    const ak_transform sf = ak_rigid_body_shape_frame(m, 0);
    const ak_quat inv = ak_quat_conjugate(sf.rotation);
    float lo = INFINITY, hi = -INFINITY;
    for (size_t v = 0; v < 24; ++v) {
        ak_vec3 ps = ak_quat_rotate(inv, ak_vec3_sub(mb.p[v], sf.translation));
        lo = fminf(lo, ps.x), hi = fmaxf(hi, ps.x);
    }
    AK_CHECK_NEAR(lo, -1.5f, 1e-5f);
    AK_CHECK_NEAR(hi, -0.5f, 1e-5f);
    mesh_buf_free(&mb);
    ak_rigid_model_destroy(m);
}

AK_TEST(heightfield_and_trimesh_meshes_keep_their_geometry) {
    enum { R = 3, C = 4 };
    float h[R * C];
    for (int j = 0; j < R; ++j)
        for (int i = 0; i < C; ++i) h[j * C + i] = 0.1f * (float)(i * i) - 0.2f * (float)j;
    const ak_vec3 tv[4] = {{0, 0, 0}, {0, 0, 2}, {2, 0, 0}, {2, 1, 2}};
    const uint32_t ti[6] = {0, 1, 2, 2, 1, 3};
    ak_rigid_body_desc b[2] = {
        {.shape = {.type = AK_RIGID_HEIGHTFIELD,
                   .heights = {h, R * C},
                   .rows = R,
                   .cols = C,
                   .spacing = 0.5f},
         .position = {5, 0, 0}},
        {.shape = {.type = AK_RIGID_TRIMESH, .vertices = {tv, 4}, .indices = {ti, 6}}}};
    ak_rigid_model* m = NULL;
    AK_CHECK_EQ(ak_rigid_model_create(&(ak_rigid_model_desc){.bodies = {b, 2}}, NULL, &m), AK_OK);
    if (!m) return;
    mesh_buf hf, tm;
    AK_CHECK(body_mesh(m, 0, &hf));
    AK_CHECK(body_mesh(m, 1, &tm));
    AK_CHECK_EQ(hf.nv, (size_t)R * C);
    AK_CHECK_EQ(hf.ni, 6u * (R - 1) * (C - 1));
    /* sample (i, j) at (i s, h, j s); every triangle faces up; they tile the grid's area */
    for (int j = 0; j < R; ++j)
        for (int i = 0; i < C; ++i) {
            ak_vec3 p = hf.p[j * C + i];
            AK_CHECK(p.x == 0.5f * (float)i && p.z == 0.5f * (float)j && p.y == h[j * C + i]);
            AK_CHECK(hf.n[j * C + i].y > 0.5f);
        }
    double area = 0.0;
    for (size_t k = 0; k < hf.ni; k += 3) {
        ak_vec3 a = hf.p[hf.t[k]], c = hf.p[hf.t[k + 1]], d = hf.p[hf.t[k + 2]];
        ak_vec3 g = ak_vec3_cross(ak_vec3_sub(c, a), ak_vec3_sub(d, a));
        AK_CHECK(g.y > 0.0f);
        area += 0.5 * g.y;
    }
    AK_CHECK_NEAR(area, (R - 1) * (C - 1) * 0.25, 1e-6);
    /* the trimesh: its two triangles, in order, with their face normals */
    AK_CHECK_EQ(tm.nv, 6u);
    AK_CHECK_EQ(tm.ni, 6u);
    for (size_t k = 0; k < 6; ++k) {
        AK_CHECK(ak_vec3_distance(tm.p[tm.t[k]], tv[ti[k]]) == 0.0f);
        AK_CHECK(tm.n[tm.t[k]].y > 0.0f);
    }
    /* the world mesh: both, moved by their poses (the heightfield by its position) */
    size_t wv, wi;
    ak_rigid_world_mesh_size(m, &wv, &wi);
    AK_CHECK_EQ(wv, hf.nv + tm.nv);
    AK_CHECK_EQ(wi, hf.ni + tm.ni);
    ak_vec3 wp[32], wn[32], x[2] = {{5, 0, 0}, {0, 0, 0}};
    uint32_t wt[64];
    ak_quat q[2] = {ak_quat_identity(), ak_quat_identity()};
    AK_CHECK_EQ(ak_rigid_world_mesh(m, (ak_vec3_cspan){x, 2}, (ak_quat_cspan){q, 2},
                                    (ak_vec3_span){wp, 32}, (ak_vec3_span){wn, 32},
                                    (ak_u32_span){wt, 64}),
                AK_OK);
    AK_CHECK_NEAR(wp[C + 1].x, 5.5f, 1e-6f);
    AK_CHECK_EQ(wt[hf.ni], (uint32_t)hf.nv + tm.t[0]);
    mesh_buf_free(&hf);
    mesh_buf_free(&tm);
    ak_rigid_model_destroy(m);
}

/* Pixels of img that differ from ref (the same scene without the body). */
static long silhouette(const char* path, const char* ref_path) {
    int w, h, w2, h2;
    if (ak_png_info(path, &w, &h) != AK_OK || ak_png_info(ref_path, &w2, &h2) != AK_OK || w != w2 ||
        h != h2)
        return -1;
    ak_image a = {.pixels = malloc((size_t)w * h * 4), .width = w, .height = h};
    ak_image b = {.pixels = malloc((size_t)w * h * 4), .width = w, .height = h};
    long n = -1;
    if (a.pixels && b.pixels && ak_png_read(path, &a) == AK_OK &&
        ak_png_read(ref_path, &b) == AK_OK) {
        n = 0;
        for (size_t i = 0; i < (size_t)w * h; ++i)
            n += memcmp(a.pixels + 4 * i, b.pixels + 4 * i, 3) != 0;
    }
    free(a.pixels), free(b.pixels);
    return n;
}

/* A tall box given as a hull of its 8 corners is drawn as that box: its silhouette matches the
 * box shape's (the established drawing) within 2%, and is far from the sphere it was drawn as
 * before (a sphere of the hull's bounding radius covers more than twice the area). No steps: the
 * start state, framed on the same [-1, 1]^3 bounds. */
AK_TEST(cli_draws_a_hull_as_itself) {
    const char* body_hull =
        "{\"shape\": {\"type\": \"hull\", \"points\": [[-0.3,-0.9,-0.2],[0.3,-0.9,-0.2],"
        "[-0.3,0.9,-0.2],[0.3,0.9,-0.2],[-0.3,-0.9,0.2],[0.3,-0.9,0.2],[-0.3,0.9,0.2],"
        "[0.3,0.9,0.2]]}, \"position\": [0, 0, 0], \"orientation\": [0, 0.2588190, 0, 0.9659258]}";
    const char* body_box =
        "{\"shape\": {\"type\": \"box\", \"half_extents\": [0.3, 0.9, 0.2]}, "
        "\"position\": [0, 0, 0], \"orientation\": [0, 0.2588190, 0, 0.9659258]}";
    const char* body_sphere = "{\"shape\": {\"type\": \"sphere\", \"radius\": 0.9695}, "
                              "\"position\": [0, 0, 0]}";
    const char* far_sphere = "{\"shape\": {\"type\": \"sphere\", \"radius\": 0.01}, "
                             "\"position\": [0, 0, 0], \"static\": true}";
    const char* bodies[4] = {body_hull, body_box, body_sphere, far_sphere};
    const char* names[4] = {"draw_hull", "draw_box", "draw_sphere", "draw_none"};
    for (int k = 0; k < 4; ++k) {
        char scene[1024], path[64], cmd[160];
        snprintf(scene, sizeof scene, "{\"gravity\": [0, 0, 0], \"bodies\": [%s]}", bodies[k]);
        snprintf(path, sizeof path, "%s.json", names[k]);
        AK_CHECK(write_file(path, scene));
        snprintf(cmd, sizeof cmd, "rigid %s.json --steps 0 -o %s.png", names[k], names[k]);
        AK_CHECK_MSG(run(cmd, true) == 0, "%s", out_buf);
    }
    long hull = silhouette("draw_hull.png", "draw_none.png");
    long box = silhouette("draw_box.png", "draw_none.png");
    long sphere = silhouette("draw_sphere.png", "draw_none.png");
    AK_CHECK_MSG(hull > 1000 && box > 1000, "hull %ld box %ld pixels", hull, box);
    AK_CHECK_MSG(labs(hull - box) <= box / 50, "hull %ld pixels, box %ld", hull, box);
    AK_CHECK_MSG(sphere > 2 * hull, "sphere %ld pixels, hull %ld", sphere, hull);
}

/* examples/rigid_shapes.json (a heightfield, a trimesh, a hull, a compound, a sphere) baked by
 * `animkit rigid -o X.glb`: one mesh per body, each with the vertex and triangle counts of the
 * body's ak_rigid_body_mesh (before: hulls, compounds and meshes came out empty). */
AK_TEST(glb_carries_every_shape) {
    AK_CHECK_MSG(run("rigid " AK_SOURCE_DIR
                     "/examples/rigid_shapes.json --steps 10 -o draw_shapes.glb",
                     true) == 0,
                 "%s", out_buf);
    ak_rigid_scene sc;
    ak_rigid_scene_run rr;
    memset(&rr, 0, sizeof rr);
    ak_diag diag;
    ak_rigid_scene_defaults(&sc);
    AK_CHECK_EQ(ak_rigid_scene_load_file(AK_SOURCE_DIR "/examples/rigid_shapes.json", &sc, &diag),
                AK_OK);
    AK_CHECK_EQ(ak_rigid_scene_run_init(&rr, &sc, "shapes", &diag), AK_OK);
    ak_scene* s = NULL;
    AK_CHECK_EQ(ak_io_load("draw_shapes.glb", NULL, NULL, &s, &diag), AK_OK);
    if (s && rr.model) {
        AK_CHECK_EQ(s->mesh_count, rr.body_count);
        for (size_t i = 0; i < s->mesh_count && i < rr.body_count; ++i) {
            size_t nv, ni;
            ak_rigid_body_mesh_size(rr.model, i, &nv, &ni);
            AK_CHECK(nv > 0);
            AK_CHECK_EQ(s->meshes[i].mesh->vertex_count, nv);
            AK_CHECK_EQ(3 * s->meshes[i].mesh->triangle_count, ni);
        }
    }
    ak_scene_destroy(s);
    ak_rigid_scene_run_free(&rr);
    ak_rigid_scene_free(&sc);
}

/* The Khronos validator on that file (slow: node starts; SKIP without it). */
AK_TEST(glb_of_every_shape_validates) {
    AK_CHECK_MSG(run("rigid " AK_SOURCE_DIR
                     "/examples/rigid_shapes.json --steps 10 -o draw_shapes_v.glb",
                     true) == 0,
                 "%s", out_buf);
    const char* files[1] = {"draw_shapes_v.glb"};
    ak_test_gltf_validate(files, 1, "every shape baked");
}

int main(void) {
    AK_RUN(hull_mesh_is_closed_holds_the_volume_and_the_points);
    AK_RUN(compound_mesh_is_its_children);
    AK_RUN(heightfield_and_trimesh_meshes_keep_their_geometry);
    AK_RUN(cli_draws_a_hull_as_itself);
    AK_RUN(glb_carries_every_shape);
    AK_RUN_SLOW(glb_of_every_shape_validates);
    return ak_test_finish();
}
