/* mesh_volume: build closed meshes by hand and check them.
 * A unit cube and UV spheres of growing resolution: enclosed volume (divergence theorem)
 * against the exact 4/3 pi r^3, the closed/oriented check, and area-weighted normals. */
#include <stdio.h>

#include <animkit/mesh.h>

static ak_mesh* make_sphere(float r, uint32_t rings, uint32_t segs) {
    size_t vc = 2 + (size_t)(rings - 1) * segs;
    ak_mesh_desc d = {
        .vertex_count = vc, .triangle_count = 2 * (size_t)segs * (rings - 1), .has_normals = true};
    ak_mesh* m = NULL;
    if (ak_mesh_create(&d, NULL, &m) != AK_OK) return NULL;
    m->positions[0] = ak_vec3_make(0, r, 0);
    m->positions[vc - 1] = ak_vec3_make(0, -r, 0);
    for (uint32_t i = 1; i < rings; ++i)
        for (uint32_t j = 0; j < segs; ++j) {
            float th = AK_PI * (float)i / (float)rings, ph = AK_TWO_PI * (float)j / (float)segs;
            m->positions[1 + (i - 1) * segs + j] =
                ak_vec3_make(r * sinf(th) * cosf(ph), r * cosf(th), -r * sinf(th) * sinf(ph));
        }
    uint32_t* t = m->indices;
    uint32_t last = 1 + (rings - 2) * segs;
    for (uint32_t j = 0; j < segs; ++j) {
        *t++ = 0, *t++ = 1 + j, *t++ = 1 + (j + 1) % segs;
        *t++ = (uint32_t)vc - 1, *t++ = last + (j + 1) % segs, *t++ = last + j;
    }
    for (uint32_t i = 1; i + 1 < rings; ++i)
        for (uint32_t j = 0; j < segs; ++j) {
            uint32_t a = 1 + (i - 1) * segs + j, b = 1 + (i - 1) * segs + (j + 1) % segs;
            *t++ = a, *t++ = a + segs, *t++ = b + segs;
            *t++ = a, *t++ = b + segs, *t++ = b;
        }
    ak_mesh_compute_normals(m);
    return m;
}

int main(void) {
    /* Cube [0,1]^3: vertex index = x + 2y + 4z, two triangles per face, counter-clockwise. */
    static const uint32_t quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                         {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    ak_mesh_desc cd = {.vertex_count = 8, .triangle_count = 12, .name = "cube"};
    ak_mesh* cube = NULL;
    if (ak_mesh_create(&cd, NULL, &cube) != AK_OK) return 1;
    for (uint32_t i = 0; i < 8; ++i)
        cube->positions[i] =
            ak_vec3_make((float)(i & 1), (float)((i >> 1) & 1), (float)((i >> 2) & 1));
    for (int f = 0; f < 6; ++f) {
        uint32_t* t = cube->indices + 6 * f;
        t[0] = quads[f][0], t[1] = quads[f][1], t[2] = quads[f][2], t[3] = quads[f][0],
        t[4] = quads[f][2], t[5] = quads[f][3];
    }
    printf(
        "cube: volume %.6f, closed and oriented: %s\n",
        ak_volume_compute((ak_vec3_cspan){cube->positions, 8}, (ak_u32_cspan){cube->indices, 36}),
        ak_mesh_is_closed_oriented(cube) ? "yes" : "no");
    ak_mesh_destroy(cube);

    const double exact = 4.0 / 3.0 * 3.14159265358979323846;
    printf("unit sphere, exact volume %.6f\n  rings segs  triangles  volume    rel.error  closed  "
           "normal(+Y pole)\n",
           exact);
    for (uint32_t res = 4; res <= 128; res *= 2) {
        ak_mesh* s = make_sphere(1.0f, res, 2 * res);
        if (!s) return 1;
        double v = ak_volume_compute((ak_vec3_cspan){s->positions, s->vertex_count},
                                     (ak_u32_cspan){s->indices, 3 * s->triangle_count});
        printf("  %5u %4u %10zu  %.6f  %.2e   %-6s  (%.3f %.3f %.3f)\n", res, 2 * res,
               s->triangle_count, v, (exact - v) / exact,
               ak_mesh_is_closed_oriented(s) ? "yes" : "no", (double)s->normals[0].x,
               (double)s->normals[0].y, (double)s->normals[0].z);
        ak_mesh_destroy(s);
    }
    return 0;
}
