/* Wavefront OBJ writer for posed scenes: one `o` group per scene mesh, vertices in order,
 * no welding, so the output compares vertex by vertex with other tools. */
#include <errno.h>

#include "io_internal.h"

/* ---- static helpers ------------------------------------------------------------------ */

static bool finite3(ak_vec3 v) { return ak_vec3_is_finite(v); }

static bool mesh_textured(const ak_scene* s, size_t m) {
    const ak_scene_mesh* sm = &s->meshes[m];
    return sm->mesh && sm->mesh->uvs && sm->texture >= 0 && (size_t)sm->texture < s->texture_count &&
           s->textures[sm->texture].pixels && s->textures[sm->texture].width > 0 && s->textures[sm->texture].height > 0;
}

static bool mesh_has_mtl(const ak_scene* s, size_t m) {
    return s->meshes[m].mesh && (s->meshes[m].has_material || mesh_textured(s, m));
}

/* path "dir/name.obj" -> dir_len (bytes of "dir/") and stem "name". */
static void split_path(const char* path, size_t* dir_len, char* stem, size_t stem_size) {
    const char* slash = strrchr(path, '/');
    const char* base = slash ? slash + 1 : path;
    *dir_len = (size_t)(base - path);
    size_t n = strlen(base);
    if (n > 4 && (strcmp(base + n - 4, ".obj") == 0 || strcmp(base + n - 4, ".OBJ") == 0)) n -= 4;
    snprintf(stem, stem_size, "%.*s", (int)n, base);
}

/* The side files of an export: the .mtl and the textures' PNGs, each written to its own
 * temporary and renamed into place only once the .obj is complete too. */
typedef struct side_files {
    ak_atomic_file* files; /* [count] closed temporaries */
    size_t count;
} side_files;

static void side_abort(side_files* sf) {
    for (size_t i = 0; i < sf->count; ++i) ak_atomic_file_abort(&sf->files[i]);
    free(sf->files);
    sf->files = NULL;
    sf->count = 0;
}

/* Texture t of the scene as a PNG with its rows flipped (OBJ's v = 0 is the image's bottom,
 * animkit's is its top: the UVs are written unchanged), into a closed temporary. */
static ak_result write_texture_png(ak_atomic_file* out, const char* file, const ak_scene_texture* t, ak_diag* diag) {
    size_t row = (size_t)t->width * 4u;
    uint8_t* flipped = (uint8_t*)malloc(row * (size_t)t->height);
    if (!flipped) {
        akp_diag_set(diag, file, "out of memory");
        return AK_ERR_NO_MEMORY;
    }
    for (int y = 0; y < t->height; ++y)
        memcpy(flipped + (size_t)y * row, t->pixels + (size_t)(t->height - 1 - y) * row, row);
    uint8_t* png = NULL;
    size_t n = 0;
    ak_result r = akp_image_encode_png(flipped, t->width, t->height, &png, &n);
    free(flipped);
    if (r != AK_OK) {
        akp_diag_set(diag, file, "cannot encode the texture as PNG");
        return r;
    }
    if (ak_atomic_file_open(out, file) != AK_OK) {
        free(png);
        akp_diag_set(diag, file, "cannot create file (%s)", strerror(out->err));
        return AK_ERR_IO;
    }
    fwrite(png, 1, n, out->f);
    free(png);
    if (ak_atomic_file_close(out) != AK_OK) {
        akp_diag_set(diag, file, "cannot write file (%s)", strerror(out->err ? out->err : EIO));
        return AK_ERR_IO;
    }
    return AK_OK;
}

/* The .mtl beside the .obj (one material per mesh that has a material or a texture) and the
 * textures' PNG files it names ("<stem>_<texture index>.png"), as closed temporaries in sf. */
static ak_result write_materials(const char* path, const ak_scene* s, const char* mtl_file, const char* stem,
                                 size_t dir_len, side_files* sf, ak_diag* diag) {
    sf->files = (ak_atomic_file*)calloc(s->texture_count + 1, sizeof(ak_atomic_file));
    if (!sf->files) {
        akp_diag_set(diag, mtl_file, "out of memory");
        return AK_ERR_NO_MEMORY;
    }
    char file[4096];
    for (size_t t = 0; t < s->texture_count; ++t) {
        bool used = false;
        for (size_t m = 0; m < s->mesh_count && !used; ++m)
            used = mesh_textured(s, m) && (size_t)s->meshes[m].texture == t;
        if (!used) continue;
        snprintf(file, sizeof file, "%.*s%s_%zu.png", (int)dir_len, path, stem, t);
        ak_result r = write_texture_png(&sf->files[sf->count++], file, &s->textures[t], diag);
        if (r != AK_OK) return r;
    }
    ak_atomic_file* out = &sf->files[sf->count++];
    if (ak_atomic_file_open(out, mtl_file) != AK_OK) {
        akp_diag_set(diag, mtl_file, "cannot create file (%s)", strerror(out->err));
        return AK_ERR_IO;
    }
    fprintf(out->f, "# animkit MTL export: %s\n", s->name);
    for (size_t m = 0; m < s->mesh_count; ++m) {
        if (!mesh_has_mtl(s, m)) continue;
        const ak_scene_mesh* sm = &s->meshes[m];
        ak_vec4 c = sm->has_material ? sm->base_color : ak_vec4_make(1, 1, 1, 1);
        fprintf(out->f, "newmtl material_%zu\nKd %.9g %.9g %.9g\nd %.9g\n", m, (double)c.x, (double)c.y,
                (double)c.z, (double)c.w);
        if (mesh_textured(s, m)) fprintf(out->f, "map_Kd %s_%d.png\n", stem, (int)sm->texture);
    }
    if (ak_atomic_file_close(out) != AK_OK) {
        akp_diag_set(diag, mtl_file, "cannot write file (%s)", strerror(out->err ? out->err : EIO));
        return AK_ERR_IO;
    }
    return AK_OK;
}

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
    bool any_mtl = false;
    for (size_t m = 0; m < scene->mesh_count; ++m) any_mtl = any_mtl || mesh_has_mtl(scene, m);
    char stem[1024], mtl_file[4096];
    size_t dir_len = 0;
    split_path(path, &dir_len, stem, sizeof stem);
    side_files sf = {0};
    if (any_mtl) {
        snprintf(mtl_file, sizeof mtl_file, "%.*s%s.mtl", (int)dir_len, path, stem);
        ak_result r = write_materials(path, scene, mtl_file, stem, dir_len, &sf, diag);
        if (r != AK_OK) {
            side_abort(&sf);
            return r;
        }
    }
    ak_atomic_file out; /* a temporary renamed over path once complete (internal.h) */
    if (ak_atomic_file_open(&out, path) != AK_OK) {
        side_abort(&sf);
        akp_diag_set(diag, path, "cannot create file (%s)", strerror(out.err));
        return AK_ERR_IO;
    }
    FILE* f = out.f;
    fprintf(f, "# animkit OBJ export: %s, %zu meshes\n", scene->name, scene->mesh_count);
    if (any_mtl) fprintf(f, "mtllib %s.mtl\n", stem);
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
        if (mesh_has_mtl(scene, m)) fprintf(f, "usemtl material_%zu\n", m);
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
    if (ak_atomic_file_close(&out) != AK_OK) {
        side_abort(&sf);
        akp_diag_set(diag, path, "cannot write file (%s)", strerror(out.err ? out.err : EIO));
        return AK_ERR_IO;
    }
    /* everything complete: the side files first, then the .obj that names them */
    for (size_t i = 0; i < sf.count; ++i) {
        if (ak_atomic_file_rename(&sf.files[i]) != AK_OK) {
            akp_diag_set(diag, sf.files[i].path, "cannot rename into place (%s)",
                         strerror(sf.files[i].err ? sf.files[i].err : EIO));
            side_abort(&sf);
            ak_atomic_file_abort(&out);
            return AK_ERR_IO;
        }
    }
    side_abort(&sf); /* frees the array; the renamed files are left alone */
    if (ak_atomic_file_rename(&out) != AK_OK) {
        akp_diag_set(diag, path, "cannot write file (%s)", strerror(out.err ? out.err : EIO));
        return AK_ERR_IO;
    }
    return AK_OK;
}
