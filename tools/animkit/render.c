/* Rendering glue for the commands: a fixed camera and ground framed on a whole animation,
 * posed meshes, skeleton overlays, heatmaps, IK overlays, frames to PNG or GIF. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "render.h"

static ak_vec4 rgba(float r, float g, float b, float a) { return ak_vec4_make(r, g, b, a); }

/* the scene's texture enums are cast to the raster's */
_Static_assert((int)AK_TEXTURE_WRAP_CLAMP == (int)AK_RASTER_WRAP_CLAMP && (int)AK_TEXTURE_WRAP_MIRROR == (int)AK_RASTER_WRAP_MIRROR &&
                   (int)AK_TEXTURE_FILTER_NEAREST == (int)AK_RASTER_FILTER_NEAREST,
               "texture enums");

void cli_bounds_add_pose(const cli_poser* p, ak_vec3* lo, ak_vec3* hi) { cli_bounds_add_visible(p, NULL, lo, hi); }

void cli_bounds_add_visible(const cli_poser* p, const bool* hidden, ak_vec3* lo, ak_vec3* hi) {
    const ak_scene* s = p->scene;
    bool any = false;
    for (size_t m = 0; m < s->mesh_count; ++m) {
        const ak_mesh* mesh = s->meshes[m].mesh;
        if (!mesh || mesh->vertex_count == 0 || (hidden && hidden[m])) continue;
        ak_vec3 a, b;
        ak_points_bounds((ak_vec3_cspan){p->positions[m], mesh->vertex_count}, &a, &b);
        *lo = ak_vec3_min(*lo, a);
        *hi = ak_vec3_max(*hi, b);
        any = true;
    }
    if (!any) {
        for (size_t j = 0; j < p->joint_count; ++j) {
            if (s->is_joint && !s->is_joint[j]) continue;
            ak_vec3 t = ak_mat4_get_translation(p->world[j]);
            if (!ak_vec3_is_finite(t)) continue;
            *lo = ak_vec3_min(*lo, t);
            *hi = ak_vec3_max(*hi, t);
        }
    }
}

void cli_frame_aim(cli_frame* f, ak_vec3 lo, ak_vec3 hi, const cli_camera* cam) {
    cli_camera c = cam ? *cam : (cli_camera){0};
    if (!c.has_angles) {
        c.yaw = ak_degrees(0.55f);
        c.pitch = ak_degrees(0.22f);
    }
    float fovy = c.fov > 0.0f && c.fov < 170.0f ? ak_radians(c.fov) : ak_radians(40.0f);
    float az = ak_radians(c.yaw), el = ak_radians(ak_clampf(c.pitch, -85.0f, 85.0f));
    float aspect = (float)f->width / (float)f->height;
    ak_view_orbit orbit = {.azimuth = az, .elevation = el, .fovy = fovy, .aspect = aspect, .margin = 1.08f};
    f->camera = ak_view_orbit_camera(lo, hi, &orbit);
    if (c.distance > 0.0f && ak_finitef(c.distance) && ak_vec3_is_finite(lo) && ak_vec3_is_finite(hi)) {
        /* the same direction as the orbit camera, at the distance asked for */
        ak_vec3 centre = ak_vec3_scale(ak_vec3_add(lo, hi), 0.5f);
        float R = ak_maxf(0.5f * ak_vec3_length(ak_vec3_sub(hi, lo)), 1e-4f);
        ak_vec3 dir = ak_vec3_make(cosf(el) * sinf(az), sinf(el), cosf(el) * cosf(az));
        ak_vec3 eye = ak_vec3_madd(centre, dir, c.distance);
        float near_z = ak_maxf(0.001f * c.distance, ak_minf(0.1f * c.distance, 0.5f * (c.distance - R)));
        f->camera = ak_raster_camera_perspective(eye, centre, fovy, aspect, near_z, c.distance + 6.0f * R);
    }
}

int cli_frame_init(cli_frame* f, const ak_scene* s, int width, int height, ak_vec3 lo, ak_vec3 hi, float azimuth) {
    cli_camera cam = {.has_angles = true, .yaw = ak_degrees(azimuth), .pitch = ak_degrees(0.22f)};
    return cli_frame_init_camera(f, s, width, height, lo, hi, &cam);
}

int cli_frame_init_camera(cli_frame* f, const ak_scene* s, int width, int height, ak_vec3 lo, ak_vec3 hi,
                          const cli_camera* cam) {
    memset(f, 0, sizeof(*f));
    f->width = width;
    f->height = height;
    f->bmin = lo;
    f->bmax = hi;
    ak_raster_desc d = {.width = width, .height = height, .supersample = 2, .thread_count = 2};
    if (ak_raster_create(&d, NULL, &f->raster) != AK_OK) return CLI_BAD_INPUT;
    cli_frame_aim(f, lo, hi, cam);
    /* skeleton overlay arrays: the skin joints only, parents remapped to listed ancestors */
    size_t n = s ? ak_scene_joint_count(s) : 0;
    f->draw_capacity = (s ? s->mesh_count : 0) + CLI_MAX_EXTRA;
    f->draw = calloc(f->draw_capacity, sizeof(ak_raster_mesh));
    f->tex = calloc(f->draw_capacity, sizeof(ak_raster_texture));
    f->joint_list = calloc(n + 1, sizeof(int));
    f->joint_parent = calloc(n + 1, sizeof(int32_t));
    f->joint_model = calloc(n + 1, sizeof(ak_mat4));
    int* map = calloc(n + 1, sizeof(int));
    if (!f->draw || !f->tex || !f->joint_list || !f->joint_parent || !f->joint_model || !map) {
        free(map);
        cli_frame_free(f);
        return CLI_BAD_INPUT;
    }
    if (n) {
        ak_i32_cspan parents = ak_skeleton_parents(s->skeleton);
        for (size_t j = 0; j < n; ++j) {
            map[j] = -1;
            if (s->is_joint && !s->is_joint[j]) continue;
            int p = parents.ptr[j];
            while (p >= 0 && map[p] < 0) p = parents.ptr[p];
            map[j] = (int)f->joint_count;
            f->joint_list[f->joint_count] = (int)j;
            f->joint_parent[f->joint_count] = (int32_t)(p >= 0 ? map[p] : -1);
            ++f->joint_count;
        }
    }
    free(map);
    return CLI_OK;
}

void cli_frame_free(cli_frame* f) {
    ak_raster_destroy(f->raster);
    free(f->joint_list);
    free(f->joint_parent);
    free(f->joint_model);
    free(f->draw);
    free(f->tex);
    memset(f, 0, sizeof(*f));
}

ak_result cli_frame_draw(cli_frame* f, const cli_poser* p, const cli_draw_opts* o, const ak_image* out) {
    const ak_scene* s = p ? p->scene : NULL;
    ak_raster* r = f->raster;
    if (o && (o->sky_top.w > 0.0f || o->sky_bottom.w > 0.0f))
        ak_raster_clear(r, o->sky_top, o->sky_bottom);
    else
        ak_raster_clear(r, rgba(0.83f, 0.87f, 0.93f, 1), rgba(0.48f, 0.51f, 0.58f, 1));
    ak_raster_mesh* meshes = f->draw;
    size_t mc = 0;
    ak_vec4 clay = rgba(0.80f, 0.74f, 0.68f, 1);
    for (size_t m = 0; s && m < s->mesh_count && mc < f->draw_capacity; ++m) {
        const ak_mesh* mesh = s->meshes[m].mesh;
        if (!mesh || mesh->triangle_count == 0 || (o && o->hidden && o->hidden[m])) continue;
        ak_raster_mesh rm = {
            .positions = {p->positions[m], mesh->vertex_count},
            .normals = {p->normals[m], mesh->vertex_count},
            .indices = {mesh->indices, mesh->triangle_count * 3},
            .material = {.color = o && o->tint.w > 0 ? o->tint : clay},
        };
        if (o && o->colors && o->colors[m]) {
            rm.colors = (ak_vec4_cspan){o->colors[m], mesh->vertex_count};
            rm.material.color = rgba(1, 1, 1, 1);
            rm.material.specular = 0.15f;
        } else if (!(o && o->tint.w > 0) && mesh->uvs && s->meshes[m].texture >= 0 &&
                   (size_t)s->meshes[m].texture < s->texture_count && s->textures[s->meshes[m].texture].pixels) {
            /* glTF: base colour = baseColorFactor (linear) x the sRGB texture, so the factor goes
             * to the raster as an sRGB colour and the texel multiplies it in linear light */
            const ak_scene_texture* st = &s->textures[s->meshes[m].texture];
            ak_vec4 bc = s->meshes[m].has_material ? s->meshes[m].base_color : rgba(1, 1, 1, 1);
            ak_raster_texture* t = &f->tex[mc];
            *t = (ak_raster_texture){
                .image = {.pixels = st->pixels, .width = st->width, .height = st->height},
                .wrap_u = (ak_raster_wrap)st->wrap_s,
                .wrap_v = (ak_raster_wrap)st->wrap_t,
                .mag_filter = (ak_raster_filter)st->mag_filter,
                .min_filter = (ak_raster_filter)st->min_filter,
            };
            rm.uvs = (ak_vec2_cspan){mesh->uvs, mesh->vertex_count};
            rm.texture = t;
            rm.material.color = rgba(ak_linear_to_srgb(ak_clampf(bc.x, 0, 1)), ak_linear_to_srgb(ak_clampf(bc.y, 0, 1)),
                                     ak_linear_to_srgb(ak_clampf(bc.z, 0, 1)), 1);
            if (rm.material.color.x == 0 && rm.material.color.y == 0 && rm.material.color.z == 0)
                rm.material.color.w = 1; /* black factor: not the "all zero -> clay" default */
            rm.material.specular = 0.15f;
        }
        meshes[mc++] = rm;
    }
    for (size_t e = 0; o && e < o->extra_count && mc < f->draw_capacity; ++e) meshes[mc++] = o->extra[e];
    ak_vec3 size = ak_vec3_sub(f->bmax, f->bmin);
    float extent = ak_maxf(ak_maxf(1.3f * ak_maxf(size.x, size.z), 0.9f * size.y), 1e-3f);
    float step = powf(10.0f, floorf(log10f(extent / 4.0f)));
    ak_raster_ground g = {
        .height = f->bmin.y,
        .center = ak_vec3_scale(ak_vec3_add(f->bmin, f->bmax), 0.5f),
        .half_extent = extent,
        .grid_spacing = step,
        .casters = meshes,
        .caster_count = mc,
    };
    ak_result res = ak_raster_draw_ground(r, &f->camera, &g);
    for (size_t m = 0; res == AK_OK && m < mc; ++m) res = ak_raster_draw_mesh(r, &f->camera, &meshes[m]);
    bool skeleton = (o && o->skeleton) || mc == 0;
    if (res == AK_OK && skeleton && p && f->joint_count) {
        for (size_t k = 0; k < f->joint_count; ++k) f->joint_model[k] = p->world[f->joint_list[k]];
        ak_view_skeleton sk = {
            .joint_model = {f->joint_model, f->joint_count},
            .parents = {f->joint_parent, f->joint_count},
            .depth_tested = mc == 0,
        };
        res = ak_view_draw_skeleton(r, &f->camera, &sk);
    }
    if (res == AK_OK && o && o->draw) res = o->draw(o->draw_user, r, &f->camera, f->width, f->height);
    if (res == AK_OK && o && o->title) res = ak_raster_draw_text(r, 10, 10, o->title, f->height >= 300 ? 2 : 1, rgba(0.08f, 0.09f, 0.12f, 1));
    if (res == AK_OK) res = ak_raster_resolve(r, out);
    return res;
}

int cli_image_alloc(ak_image* img, int w, int h) {
    img->width = w;
    img->height = h;
    img->stride = 0;
    img->pixels = calloc((size_t)w * (size_t)h, 4);
    return img->pixels ? CLI_OK : CLI_BAD_INPUT;
}

/* Heatmap colours of one skin slot's weights on mesh m (the rest of the meshes clay). */
static int heat_colors(const ak_scene* s, size_t mesh_index, const uint16_t* joints, const float* weights, uint32_t k,
                       int slot, ak_vec4** out) {
    const ak_mesh* mesh = s->meshes[mesh_index].mesh;
    size_t n = mesh->vertex_count;
    float* w = calloc(n, sizeof(float));
    ak_vec4* c = calloc(n, sizeof(ak_vec4));
    if (!w || !c) {
        free(w), free(c);
        return CLI_BAD_INPUT;
    }
    for (size_t v = 0; v < n; ++v)
        for (uint32_t i = 0; i < k; ++i)
            if (joints[v * k + i] == slot) w[v] += weights[v * k + i];
    ak_view_heatmap_colors((ak_f32_cspan){w, n}, 0.0f, 1.0f, (ak_vec4_span){c, n});
    free(w);
    *out = c;
    return CLI_OK;
}

int cli_weights_colors(const ak_scene* s, const char* bone, ak_vec4** colors, int* out_found) {
    *out_found = 0;
    int j = s->skeleton ? ak_skeleton_find_joint(s->skeleton, bone) : -1;
    for (size_t m = 0; m < s->mesh_count; ++m) {
        const ak_scene_mesh* sm = &s->meshes[m];
        colors[m] = NULL;
        if (sm->skin < 0 || !sm->mesh->influence_count || j < 0) continue;
        const ak_scene_skin* skin = &s->skins[sm->skin];
        int slot = -1;
        for (size_t q = 0; q < skin->joint_count; ++q)
            if (skin->joints[q] == j) slot = (int)q;
        if (slot < 0) continue;
        if (heat_colors(s, m, sm->mesh->joints, sm->mesh->weights, sm->mesh->influence_count, slot, &colors[m])) return CLI_BAD_INPUT;
        *out_found = 1;
    }
    return CLI_OK;
}


/* Render one still of the scene at its rest pose with colours on mesh_index; legend: up to
 * legend_count names with swatches down the left side. */
static int render_colored_png(const char* path, const ak_scene* s, size_t mesh_index, ak_vec4* mesh_colors,
                              const char* title, const char* const* legend, const ak_vec4* legend_colors,
                              size_t legend_count) {
    cli_poser p;
    cli_frame f;
    ak_image img = {0};
    ak_vec4** colors = calloc(s->mesh_count + 1, sizeof(ak_vec4*));
    int rc = CLI_OK;
    if (!colors || cli_poser_init(&p, s)) {
        free(colors);
        return cli_fail("weights", "out of memory");
    }
    cli_poser_pose(&p, -1, 0.0f, false, CLI_LBS);
    ak_vec3 lo = ak_vec3_splat(INFINITY), hi = ak_vec3_splat(-INFINITY);
    cli_bounds_add_pose(&p, &lo, &hi);
    if (mesh_index < s->mesh_count) colors[mesh_index] = mesh_colors;
    if (cli_frame_init(&f, s, 640, 640, lo, hi, 0.5f) == CLI_OK) {
        cli_draw_opts o = {.colors = colors, .title = title};
        if (cli_image_alloc(&img, 640, 640) || cli_frame_draw(&f, &p, &o, &img) != AK_OK) {
            rc = cli_fail("weights", "%s: cannot write the image", path);
        } else {
            /* legend: one row per bone, as many as fit */
            int rows = (640 - 50) / 12;
            for (size_t i = 0; i < legend_count && (int)i < rows; ++i) {
                int y = 40 + 12 * (int)i;
                const char* name = (int)i == rows - 1 && legend_count > (size_t)rows ? "..." : legend[i];
                ak_image_fill_rect(&img, 10, (float)y, 9, 9, legend_colors[i]);
                ak_image_draw_text(&img, 23, y + 1, name, 1, rgba(0.08f, 0.09f, 0.12f, 1));
            }
            if (ak_png_write(path, &img) != AK_OK) rc = cli_fail("weights", "%s: cannot write the image", path);
        }
        cli_frame_free(&f);
    } else {
        rc = cli_fail("weights", "out of memory");
    }
    free(colors);
    free(img.pixels);
    cli_poser_free(&p);
    return rc;
}

/* Render one still of the scene at its rest pose with heat colours on mesh_index. */
int cli_render_weights_png(const char* path, const ak_scene* s, size_t mesh_index, const uint16_t* joints,
                           const float* weights, uint32_t k, int slot, const char* bone_name) {
    ak_vec4* c = NULL;
    if (mesh_index < s->mesh_count && heat_colors(s, mesh_index, joints, weights, k, slot, &c))
        return cli_fail("weights", "out of memory");
    char title[160];
    snprintf(title, sizeof title, "weights of %s", bone_name ? bone_name : "?");
    int rc = render_colored_png(path, s, mesh_index, c, title, NULL, NULL, 0);
    free(c);
    return rc;
}

int cli_render_bones_png(const char* path, const ak_scene* s, size_t mesh_index, const uint16_t* joints,
                         const float* weights, uint32_t k, size_t slot_count, const char* const* slot_names) {
    const ak_mesh* mesh = s->meshes[mesh_index].mesh;
    size_t n = mesh->vertex_count;
    ak_vec4* c = calloc(n + 1, sizeof(ak_vec4));
    ak_vec4* sw = calloc(slot_count + 1, sizeof(ak_vec4));
    const char** names = calloc(slot_count + 1, sizeof(char*));
    size_t* dominant = calloc(slot_count + 1, sizeof(size_t));
    size_t* top_of = calloc(n + 1, sizeof(size_t));
    if (!c || !sw || !names || !dominant || !top_of) {
        free(c), free(sw), free(names), free(dominant), free(top_of);
        return cli_fail("weights", "out of memory");
    }
    for (size_t v = 0; v < n; ++v) {
        float best = 0.0f;
        size_t top = slot_count;
        for (uint32_t i = 0; i < k; ++i) {
            float wi = weights[v * k + i];
            size_t q = joints[v * k + i];
            if (wi > best && q < slot_count) best = wi, top = q;
        }
        top_of[v] = top;
        if (top < slot_count) ++dominant[top];
    }
    /* legend: the bones that dominate some vertex, in slot order, coloured with the first
     * colours of ak_view_distinct_colors (each one far from all before it in OKLab), so the
     * colours shown are as distinct as the palette allows; dominant[] becomes the legend row */
    size_t shown = 0;
    for (size_t q = 0; q < slot_count; ++q) {
        if (!dominant[q]) continue;
        dominant[q] = shown;
        names[shown++] = slot_names[q];
    }
    ak_view_distinct_colors((ak_vec4_span){sw, shown});
    for (size_t v = 0; v < n; ++v)
        c[v] = top_of[v] < slot_count ? sw[dominant[top_of[v]]] : rgba(0.5f, 0.5f, 0.5f, 1);
    free(top_of);
    char title[160];
    snprintf(title, sizeof title, "dominant bone per vertex (%zu bone%s)", shown, cli_plural(shown));
    int rc = render_colored_png(path, s, mesh_index, c, title, names, sw, shown);
    free(c), free(sw), free(names), free(dominant);
    return rc;
}

int cli_render_ik_png(const char* path, cli_poser* p, const int16_t* chain, size_t n, ak_vec3 target) {
    cli_frame f;
    ak_image img = {0};
    int rc = CLI_OK;
    ak_vec3 lo = target, hi = target;
    cli_bounds_add_pose(p, &lo, &hi);
    if (cli_frame_init(&f, p->scene, 640, 640, lo, hi, 0.5f) || cli_image_alloc(&img, 640, 640)) {
        cli_frame_free(&f);
        free(img.pixels);
        return cli_fail("ik", "out of memory");
    }
    cli_draw_opts o = {.skeleton = true, .title = "IK solve"};
    ak_result r = cli_frame_draw(&f, p, &o, &img);
    /* the chain and the target, drawn over the picture */
    ak_vec2 prev = {0, 0};
    for (size_t i = 0; r == AK_OK && i < n; ++i) {
        ak_vec3 px;
        if (!ak_raster_camera_project(&f.camera, 640, 640, ak_mat4_get_translation(p->world[chain[i]]), &px)) continue;
        ak_vec2 q = {px.x, px.y};
        if (i) ak_image_draw_line(&img, prev, q, 4.0f, rgba(0.1f, 0.55f, 1.0f, 1));
        ak_image_draw_disc(&img, q, 5.0f, rgba(0.1f, 0.55f, 1.0f, 1), 1.5f, rgba(0, 0, 0, 1));
        prev = q;
    }
    ak_vec3 tp;
    if (r == AK_OK && ak_raster_camera_project(&f.camera, 640, 640, target, &tp))
        ak_image_draw_disc(&img, (ak_vec2){tp.x, tp.y}, 7.0f, rgba(0.95f, 0.15f, 0.2f, 1), 2.0f, rgba(1, 1, 1, 1));
    if (r != AK_OK || ak_png_write(path, &img) != AK_OK) rc = cli_fail("ik", "%s: cannot write the image", path);
    cli_frame_free(&f);
    free(img.pixels);
    return rc;
}
