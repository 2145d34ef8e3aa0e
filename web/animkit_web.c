/* The page's entry points: animkit in a browser (docs/web.md).
 *
 * The page (web/index.html, web/animkit.js) is a platform for the viewer's state machine
 * (tools/animkit/view_app.h), as the SDL window (tools/animkit/view_sdl.c) is on a desktop:
 * it feeds mouse and key events in, calls akw_frame once per animation frame, and copies the
 * RGBA framebuffer animkit's own rasterizer drew onto a canvas. Everything runs on the page's
 * one thread (thread counts 1; web/shim/pthread.h). Besides the viewer, two hooks serve the
 * browser tests (tests/web/): the IK effector's model-space position computed by forward
 * kinematics from the drawn pose, and a cloth scene stepped with the library's scene runner
 * (the same steps as `animkit cloth SCENE --json`), so the test can compare its positions with
 * the native build's.
 *
 * Strings and byte buffers cross the boundary as pointers into the module's memory: the page
 * allocates them with akw_alloc and frees them with akw_free. Errors: a function returns
 * nonzero and akw_error() holds the message. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <animkit/animkit.h>

#include "view_app.h"
#include "web.h"

#define AKW_EXPORT(name) __attribute__((export_name(#name)))

/* Largest file the page accepts from a drop: glTF/BVH files of a course fit many times over. */
#define AKW_MAX_FILE_SIZE (64u << 20)
/* Most decoded images the page hands over for one file, and their largest side (the library's
 * own limit, AKP_IO_MAX_IMAGE_SIDE, is 16384; a course's textures are 4096 at most). */
#define AKW_MAX_IMAGES 64
#define AKW_MAX_IMAGE_SIDE 8192

static struct {
    bool open;
    view_app app;
    ak_scene* scene;
    uint8_t* file;            /* the dropped file's bytes (akw_file_set) */
    size_t file_size;
    char file_name[256];
    char error[512];
    /* hooks */
    float effector[3], target[3], screen[2];
    ak_cloth_scene cloth_scene;
    ak_cloth_scene_run cloth_run;
    bool cloth_loaded;
    /* images the browser decoded for the dropped file (akw_image_add), served to the glTF
     * reader through ak_io_desc.image_decoder: the encoded bytes (the key) and RGBA8 pixels */
    struct akw_image {
        uint8_t* encoded;
        size_t encoded_size;
        uint8_t* rgba;
        int width, height;
    } images[AKW_MAX_IMAGES];
    int image_count;
    int images_served; /* how many the last load took from the table */
} g;

static int fail(const char* fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(g.error, sizeof g.error, fmt, ap);
    va_end(ap);
    return 1;
}

/* ---- memory ---- */

/* size bytes for the page to fill (strings, a dropped file); NULL when out of memory. */
AKW_EXPORT(akw_alloc) void* akw_alloc(size_t size) { return malloc(size ? size : 1); }
AKW_EXPORT(akw_free) void akw_free(void* p) { free(p); }
/* The last error message (NUL-terminated). */
AKW_EXPORT(akw_error) const char* akw_error(void) { return g.error; }

/* ---- the viewer ---- */

static void close_view(void) {
    if (g.open) view_app_free(&g.app);
    memset(&g.app, 0, sizeof g.app);
    ak_scene_destroy(g.scene);
    g.scene = NULL;
    g.open = false;
}

/* ---- texture images, decoded by the browser ---- */

/* Forget the decoded images (akw_image_add). */
AKW_EXPORT(akw_images_clear) void akw_images_clear(void) {
    for (int i = 0; i < g.image_count; ++i) {
        free(g.images[i].encoded);
        free(g.images[i].rgba);
    }
    memset(g.images, 0, sizeof g.images);
    g.image_count = 0;
}

/* Hand over one texture image of the file akw_file_set holds, as the browser decoded it:
 * encoded[encoded_size] is the image as the file stores it (a glTF image's bufferView or data:
 * URI bytes: PNG or JPEG), rgba its width x height RGBA8 pixels (straight alpha, rows top to
 * bottom). Both are copied. When akw_open("file:") loads the file, the glTF reader's image
 * decoder (ak_io_desc.image_decoder) serves each image whose bytes equal an encoded[] given
 * here, so the library samples these pixels exactly as it samples libpng's and libjpeg's in
 * the native build. Returns 0, or 1 with akw_error() set. */
AKW_EXPORT(akw_image_add)
int akw_image_add(const uint8_t* encoded, size_t encoded_size, const uint8_t* rgba, int width,
                  int height) {
    if (!encoded || !rgba || encoded_size == 0) return fail("no image");
    if (g.image_count >= AKW_MAX_IMAGES) return fail("more than %d texture images", AKW_MAX_IMAGES);
    if (width <= 0 || height <= 0 || width > AKW_MAX_IMAGE_SIDE || height > AKW_MAX_IMAGE_SIDE)
        return fail("texture image of %d x %d pixels (1..%d per side)", width, height,
                    AKW_MAX_IMAGE_SIDE);
    if (encoded_size > AKW_MAX_FILE_SIZE) return fail("texture image of %zu bytes", encoded_size);
    size_t px = (size_t)width * (size_t)height * 4u; /* <= 2^28 */
    struct akw_image im = {malloc(encoded_size), encoded_size, malloc(px), width, height};
    if (!im.encoded || !im.rgba) {
        free(im.encoded);
        free(im.rgba);
        return fail("texture image of %d x %d pixels: out of memory", width, height);
    }
    memcpy(im.encoded, encoded, encoded_size);
    memcpy(im.rgba, rgba, px);
    g.images[g.image_count++] = im;
    return 0;
}

/* ak_io_image_decoder over the table: the image whose encoded bytes are data[size]; others
 * (none handed over) go to the library's decoder, which in this build has none: a warning,
 * drawn untextured. */
static ak_result serve_image(void* user, const void* data, size_t size, ak_io_image_view* out) {
    (void)user;
    for (int i = 0; i < g.image_count; ++i) {
        const struct akw_image* im = &g.images[i];
        if (im->encoded_size == size && memcmp(im->encoded, data, size) == 0) {
            out->pixels = im->rgba;
            out->width = im->width;
            out->height = im->height;
            ++g.images_served;
            return AK_OK;
        }
    }
    return AK_ERR_UNSUPPORTED;
}

/* How many texture images the last akw_open("file:") took from akw_image_add's table. */
AKW_EXPORT(akw_images_served) int akw_images_served(void) { return g.images_served; }

/* Texture t of the open scene: its width, height and the FNV-1a 32-bit hash of its RGBA8 pixels
 * (rows top to bottom) in out[0..2]; returns out, or NULL when there is no such texture (the
 * tests compare the hash with the native build's decode). */
AKW_EXPORT(akw_texture_info) const double* akw_texture_info(int t) {
    static double out[3];
    if (!g.open || t < 0 || (size_t)t >= g.scene->texture_count || !g.scene->textures[t].pixels)
        return NULL;
    const ak_scene_texture* st = &g.scene->textures[t];
    uint32_t h = 2166136261u;
    size_t n = (size_t)st->width * (size_t)st->height * 4u;
    for (size_t i = 0; i < n; ++i) h = (h ^ st->pixels[i]) * 16777619u;
    out[0] = st->width;
    out[1] = st->height;
    out[2] = h;
    return out;
}

/* Keep the bytes of a dropped file (copied) under name, for akw_open("file:NAME"). The texture
 * images handed over for the previous file are forgotten (akw_image_add after this call). */
AKW_EXPORT(akw_file_set) int akw_file_set(const uint8_t* bytes, size_t size, const char* name) {
    if (!bytes || !name) return fail("no file");
    if (size > AKW_MAX_FILE_SIZE) return fail("%s: %zu bytes, larger than the page's %u MiB", name, size, AKW_MAX_FILE_SIZE >> 20);
    uint8_t* copy = malloc(size ? size : 1);
    if (!copy) return fail("%s: out of memory", name);
    memcpy(copy, bytes, size);
    akw_images_clear();
    free(g.file);
    g.file = copy;
    g.file_size = size;
    snprintf(g.file_name, sizeof g.file_name, "%s", name);
    return 0;
}

/* Open what the viewer shows: "builtin:humanoid", "builtin:cylinder", "file:" (the file given to
 * akw_file_set), or a simulation as `animkit view` names it ("particles:preset:fountain",
 * "cloth:preset:flag", "boids", "boids:preset:predator", "fluid:preset:dam", "terrain" ...),
 * drawn at width x height pixels. Returns 0, or 1 with akw_error() set (the previous view is
 * closed either way). */
AKW_EXPORT(akw_open) int akw_open(const char* what, int width, int height) {
    close_view();
    if (!what) return fail("nothing to open");
    if (width < 8 || height < 8 || width > 8192 || height > 8192) return fail("size %dx%d is not 8..8192 pixels each", width, height);
    view_options vo = {.width = width, .height = height, .clip = -1, .supersample = 1, .threads = 1};
    vo.sim_opts.threads = 1;
    const char* spec = NULL;
    vo.sim = view_sim_find(what, &spec);
    if (!vo.sim && strncmp(what, "fluid", 5) == 0 && (what[5] == 0 || what[5] == ':')) {
        vo.sim = &web_fluid_sim;
        spec = what[5] ? what + 6 : "";
    }
    vo.sim_spec = spec;
    if (vo.sim) {
        if (ak_scene_alloc(0, 0, 0, NULL, &g.scene) != AK_OK) return fail("out of memory");
        snprintf(g.scene->name, sizeof g.scene->name, "%s", what);
    } else if (strcmp(what, "file:") == 0) {
        if (!g.file) return fail("no file was dropped");
        ak_diag diag;
        memset(&diag, 0, sizeof diag);
        ak_io_desc desc = {.image_decoder = serve_image};
        g.images_served = 0;
        ak_result r =
            ak_io_load_memory(g.file, g.file_size, g.file_name, NULL, &desc, NULL, &g.scene, &diag);
        if (r != AK_OK)
            return fail("%s: %s", g.file_name, diag.message[0] ? diag.message : ak_result_string(r));
    } else if (strncmp(what, "builtin:", 8) == 0) {
        if (cli_load_scene("view", what, &g.scene)) return fail("%s: cannot build it", what);
    } else {
        return fail("'%s' is neither builtin:NAME, file: nor a simulation (%s, fluid)", what, view_sim_kinds);
    }
    if (g.scene->clip_count) vo.clip = 0;
    if (view_app_init(&g.app, g.scene, &vo)) {
        memset(&g.app, 0, sizeof g.app);
        ak_scene_destroy(g.scene);
        g.scene = NULL;
        return fail("%s: the viewer could not start (see the console)", what);
    }
    g.open = true;
    return 0;
}

/* One input event; type: 0 key, 1 mouse down, 2 mouse move, 3 mouse up, 4 wheel (view_ev_type).
 * key: a lowercase ASCII key or a VIEW_KEY_* code; button: 1 left, 2 middle, 3 right. */
AKW_EXPORT(akw_event) void akw_event(int type, int key, int button, float x, float y, float dy, int shift) {
    if (!g.open || type < VIEW_EV_KEY || type > VIEW_EV_WHEEL) return;
    view_event ev = {.type = (view_ev_type)type, .key = key, .button = button, .x = x, .y = y, .dy = dy, .shift = shift != 0};
    view_app_event(&g.app, &ev);
}

/* Advance dt seconds (the page's wall time, at most 0.1 s) and draw. Returns the RGBA8 pixels
 * (akw_width x akw_height, rows top-down), or NULL with akw_error() set. */
AKW_EXPORT(akw_frame) const uint8_t* akw_frame(double dt) {
    if (!g.open) {
        fail("nothing is open");
        return NULL;
    }
    view_app* a = &g.app;
    if (dt > 0.0) a->fps = a->fps > 0 ? 0.9 * a->fps + 0.1 / dt : 1.0 / dt;
    view_app_advance(a, dt > 0.1 ? 0.1 : dt < 0.0 ? 0.0 : dt);
    if (a->sim && a->sim->failed && a->sim->failed(a->sim_state)) {
        fail("%s: the simulation failed (see the console)", g.scene->name);
        return NULL;
    }
    ak_result r = view_app_render(a);
    if (r != AK_OK) {
        fail("%s: cannot draw: %s", g.scene->name, ak_result_string(r));
        return NULL;
    }
    ++a->frame_index;
    return a->image.pixels;
}

AKW_EXPORT(akw_width) int akw_width(void) { return g.open ? g.app.width : 0; }
AKW_EXPORT(akw_height) int akw_height(void) { return g.open ? g.app.height : 0; }

/* Resize the frame (the canvas changed size). */
AKW_EXPORT(akw_resize) int akw_resize(int width, int height) {
    if (!g.open) return fail("nothing is open");
    if (view_app_resize(&g.app, width, height)) return fail("cannot resize to %dx%d", width, height);
    return 0;
}

/* ---- state for the page's controls and the tests ---- */

/* 0 LBS, 1 DQS, 2 CoR (cli_method), 3 side by side. */
AKW_EXPORT(akw_method) int akw_method(void) { return !g.open ? -1 : g.app.side_by_side ? 3 : (int)g.app.method; }
AKW_EXPORT(akw_time) double akw_time(void) { return g.open ? g.app.time : 0.0; }
AKW_EXPORT(akw_playing) int akw_playing(void) { return g.open && g.app.playing; }
AKW_EXPORT(akw_duration) double akw_duration(void) {
    if (!g.open || g.app.clip < 0 || (size_t)g.app.clip >= g.scene->clip_count) return 0.0;
    return (double)ak_clip_duration(g.scene->clips[g.app.clip]);
}
/* Set the time (seconds, clamped to the clip) and pause, as scrubbing the timeline does. */
AKW_EXPORT(akw_set_time) void akw_set_time(double t) {
    if (!g.open || g.app.clip < 0) return;
    double d = akw_duration();
    g.app.time = t < 0.0 ? 0.0 : t > d ? d : t;
    g.app.playing = false;
    g.app.bind = false;
}
AKW_EXPORT(akw_joint_count) int akw_joint_count(void) { return g.open ? (int)g.app.poser.joint_count : 0; }
/* Index of the joint named name, or -1. */
AKW_EXPORT(akw_joint_find) int akw_joint_find(const char* name) {
    if (!g.open || !g.scene->skeleton || !name) return -1;
    for (size_t j = 0; j < g.app.poser.joint_count; ++j)
        if (strcmp(ak_skeleton_joint_name(g.scene->skeleton, j), name) == 0) return (int)j;
    return -1;
}
/* Where joint j of the last drawn pose is on screen: pointer to (x, y) pixels, or NULL when it
 * is behind the camera. */
AKW_EXPORT(akw_joint_screen) const float* akw_joint_screen(int j) {
    if (!g.open || j < 0 || (size_t)j >= g.app.poser.joint_count) return NULL;
    ak_vec3 p = ak_mat4_get_translation(g.app.poser.world[j]), px;
    if (!ak_raster_camera_project(&g.app.frame.camera, g.app.frame.width, g.app.frame.height, p, &px)) return NULL;
    g.screen[0] = px.x;
    g.screen[1] = px.y;
    return g.screen;
}
/* The IK effector joint (-1: none) and its target (model space: pointer to x, y, z). */
AKW_EXPORT(akw_ik_effector) int akw_ik_effector(void) { return g.open ? g.app.effector : -1; }
AKW_EXPORT(akw_ik_target) const float* akw_ik_target(void) {
    if (!g.open) return NULL;
    g.target[0] = g.app.target.x;
    g.target[1] = g.app.target.y;
    g.target[2] = g.app.target.z;
    return g.target;
}
/* The effector's model-space position in the last drawn pose, from the joints' local transforms
 * through forward kinematics (ak_skeleton_local_to_model): the tests compare it with the target,
 * so the check does not rest on the IK solver's own error report. NULL when there is no effector. */
AKW_EXPORT(akw_ik_effector_position) const float* akw_ik_effector_position(void) {
    if (!g.open || g.app.effector < 0 || !g.scene->skeleton) return NULL;
    size_t n = g.app.poser.joint_count;
    ak_mat4* model = malloc(n * sizeof *model);
    if (!model) return NULL;
    ak_result r = ak_skeleton_local_to_model(g.scene->skeleton, (ak_transform_cspan){g.app.poser.local, n},
                                             (ak_mat4_span){model, n});
    ak_vec3 p = ak_mat4_get_translation(model[g.app.effector]);
    free(model);
    if (r != AK_OK) return NULL;
    g.effector[0] = p.x;
    g.effector[1] = p.y;
    g.effector[2] = p.z;
    return g.effector;
}
/* Average frame-time breakdown so far (ms): sample+IK, skinning, raster; frames drawn. */
AKW_EXPORT(akw_stats) double akw_stats(int which) {
    if (!g.open || g.app.stats.frames == 0) return 0.0;
    double k = 1e3 / (double)g.app.stats.frames;
    switch (which) {
    case 0: return g.app.stats.sample * k;
    case 1: return g.app.stats.skin * k;
    case 2: return g.app.stats.raster * k;
    default: return (double)g.app.stats.frames;
    }
}

/* ---- cloth, stepped as `animkit cloth SCENE.json --threads 1 --json` steps it ---- */

/* Load a cloth scene file's text (json, size bytes) and step it steps times (-1: the scene's own
 * count) on one thread. Returns 0, or 1 with akw_error() set. akw_cloth_positions then holds the
 * vertex positions (x, y, z floats) and akw_cloth_vertex_count their count. Scenes with a
 * character (attachments to a model file) are refused: the page has no files. */
AKW_EXPORT(akw_cloth_run) int akw_cloth_run(const char* json, size_t size, long steps) {
    if (g.cloth_loaded) {
        ak_cloth_scene_run_free(&g.cloth_run);
        ak_cloth_scene_free(&g.cloth_scene);
        g.cloth_loaded = false;
    }
    ak_diag diag;
    memset(&diag, 0, sizeof diag);
    ak_result r = ak_cloth_scene_load_bytes(json, size, "scene.json", &g.cloth_scene, &diag);
    if (r != AK_OK) return fail("%s", diag.message[0] ? diag.message : ak_result_string(r));
    g.cloth_loaded = true;
    if (g.cloth_scene.model[0]) return fail("scene.json: a scene with a character needs its model file; the page has none");
    if (steps >= 0) g.cloth_scene.steps = steps;
    g.cloth_scene.thread_count = 1;
    memset(&g.cloth_run, 0, sizeof g.cloth_run);
    if ((r = ak_cloth_scene_run_init(&g.cloth_run, &g.cloth_scene, NULL, &diag)) != AK_OK)
        return fail("%s", diag.message[0] ? diag.message : ak_result_string(r));
    for (long k = 0; k < g.cloth_scene.steps; ++k)
        if ((r = ak_cloth_scene_run_step(&g.cloth_run, "scene.json", &diag)) != AK_OK)
            return fail("%s", diag.message[0] ? diag.message : ak_result_string(r));
    return 0;
}
AKW_EXPORT(akw_cloth_positions) const float* akw_cloth_positions(void) {
    return g.cloth_loaded && g.cloth_run.positions ? &g.cloth_run.positions[0].x : NULL;
}
AKW_EXPORT(akw_cloth_vertex_count) int akw_cloth_vertex_count(void) {
    return g.cloth_loaded ? (int)g.cloth_run.vertex_count : 0;
}
