/* Wavefront OBJ writer for posed scenes: one `o` group per scene mesh, vertices in order,
 * no welding, so the output compares vertex by vertex with other tools. */
#include <errno.h>

#include "io_internal.h"

/* ---- static helpers ------------------------------------------------------------------ */

static bool finite3(ak_vec3 v) { return ak_vec3_is_finite(v); }

/* ---- public -------------------------------------------------------------------------- */

ak_result ak_io_write_obj(const char* path, const ak_scene* scene, const ak_vec3* const* posed_positions,
                          const ak_vec3* const* posed_normals, ak_diag* diag) {
    if (!path || !scene) {
        akp_diag_set(diag, path, "path and scene are required");
        return AK_ERR_NULL_ARG;
    }
    /* Check everything first so a bad pose leaves no half-written file. */
    for (size_t m = 0; m < scene->mesh_count; ++m) {
        const ak_mesh* mesh = scene->meshes[m].mesh;
        if (!mesh) continue;
        const ak_vec3* p = posed_positions && posed_positions[m] ? posed_positions[m] : mesh->positions;
        const ak_vec3* n = posed_normals && posed_normals[m] ? posed_normals[m] : mesh->normals;
        for (size_t v = 0; v < mesh->vertex_count; ++v) {
            if (!finite3(p[v]) || (n && !finite3(n[v]))) {
                akp_diag_set(diag, path, "mesh %zu vertex %zu: position or normal is not finite", m, v);
                return AK_ERR_BAD_DATA;
            }
        }
    }
    ak_atomic_file out; /* a temporary renamed over path once complete (internal.h) */
    if (ak_atomic_file_open(&out, path) != AK_OK) {
        akp_diag_set(diag, path, "cannot create file (%s)", strerror(out.err));
        return AK_ERR_IO;
    }
    FILE* f = out.f;
    fprintf(f, "# animkit OBJ export: %s, %zu meshes\n", scene->name, scene->mesh_count);
    size_t base = 1, base_t = 1, base_n = 1; /* 1-based running offsets of v, vt, vn */
    for (size_t m = 0; m < scene->mesh_count; ++m) {
        const ak_mesh* mesh = scene->meshes[m].mesh;
        if (!mesh) continue;
        char name[AK_NAME_SIZE];
        if (mesh->name[0]) akp_io_copy_name(name, mesh->name);
        else snprintf(name, sizeof name, "mesh_%zu", m);
        for (char* ch = name; *ch; ++ch)
            if (*ch == ' ' || *ch == '\t' || *ch == '\r' || *ch == '\n') *ch = '_';
        fprintf(f, "o %s\n", name);
        const ak_vec3* p = posed_positions && posed_positions[m] ? posed_positions[m] : mesh->positions;
        const ak_vec3* n = posed_normals && posed_normals[m] ? posed_normals[m] : mesh->normals;
        for (size_t v = 0; v < mesh->vertex_count; ++v)
            fprintf(f, "v %.9g %.9g %.9g\n", (double)p[v].x, (double)p[v].y, (double)p[v].z);
        if (mesh->uvs)
            for (size_t v = 0; v < mesh->vertex_count; ++v)
                fprintf(f, "vt %.9g %.9g\n", (double)mesh->uvs[v].x, (double)mesh->uvs[v].y);
        if (n)
            for (size_t v = 0; v < mesh->vertex_count; ++v)
                fprintf(f, "vn %.9g %.9g %.9g\n", (double)n[v].x, (double)n[v].y, (double)n[v].z);
        for (size_t t = 0; t < mesh->triangle_count; ++t) {
            fputc('f', f);
            for (int k = 0; k < 3; ++k) {
                size_t idx = mesh->indices[3 * t + (size_t)k];
                size_t i = base + idx, it = base_t + idx, in = base_n + idx;
                if (mesh->uvs && n) fprintf(f, " %zu/%zu/%zu", i, it, in);
                else if (mesh->uvs) fprintf(f, " %zu/%zu", i, it);
                else if (n) fprintf(f, " %zu//%zu", i, in);
                else fprintf(f, " %zu", i);
            }
            fputc('\n', f);
        }
        base += mesh->vertex_count;
        if (mesh->uvs) base_t += mesh->vertex_count;
        if (n) base_n += mesh->vertex_count;
    }
    if (ak_atomic_file_commit(&out) != AK_OK) {
        akp_diag_set(diag, path, "cannot write file (%s)", strerror(out.err ? out.err : EIO));
        return AK_ERR_IO;
    }
    return AK_OK;
}
