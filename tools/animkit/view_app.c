/* animkit view: state, input, posing (sample, morph overrides, IK, FK, skinning), drawing
 * and the frame loop. The window itself lives in view_sdl.c. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h> /* lstat: a script's screenshot path must not pass a symlink */

#include "view_app.h"

#define FIXED_STEP (1.0 / 30.0)
#define PICK_RADIUS 12.0f

const view_help_entry view_help[] = {
    {"space", "play / pause"},
    {"left", "back one frame (1/30 s)"},
    {"right", "forward one frame (1/30 s)"},
    {"up", "play faster (x2)"},
    {"down", "play slower (/2)"},
    {"tab", "next clip"},
    {"l", "loop on / off"},
    {"b", "bind pose on / off"},
    {"f", "frame all (reset the camera)"},
    {"1", "LBS skinning"},
    {"2", "DQS skinning"},
    {"3", "CoR skinning"},
    {"4", "LBS | DQS | CoR side by side"},
    {"5", "implicit skinning"},
    {"6", "soft (volumetric) skinning"},
    {"w", "weight heatmap: next bone"},
    {"n", "normals overlay"},
    {"k", "skeleton overlay"},
    {"i", "next IK solver (CCD..DLS)"},
    {"r", "IK chain root one joint up"},
    {"a", "IK target left"},
    {"d", "IK target right"},
    {"e", "IK target up"},
    {"q", "IK target down"},
    {"z", "IK target towards the camera"},
    {"x", "IK target away from camera"},
    {"j", "joint limits of the IK chain"},
    {"escape", "drop the IK effector / quit"},
    {"m", "next morph target"},
    {"[", "morph weight -0.1"},
    {"]", "morph weight +0.1"},
    {"p", "screenshot (view_NNNN.png)"},
    {"h", "this help"},
};
const size_t view_help_count = sizeof view_help / sizeof view_help[0];

static const char* const mouse_help[] = {
    "left drag: orbit the camera",
    "left on a joint: IK effector, drag target",
    "middle / shift+left drag: pan",
    "wheel: zoom; bottom bar: drag to scrub",
};
#define MOUSE_HELP_COUNT (sizeof mouse_help / sizeof mouse_help[0])

static ak_vec4 rgba(float r, float g, float b, float a) { return ak_vec4_make(r, g, b, a); }

static int text_scale(const view_app* a) { return a->width >= 960 ? 2 : 1; }

/* ---- targets ---- */

static int make_frame(view_app* a, cli_frame* f, ak_image* img, int w, int h) {
    if (cli_frame_init(f, a->scene, w, h, a->box_lo, a->box_hi, 0.55f)) return CLI_BAD_INPUT;
    /* the viewer's own raster settings (cli_frame_init makes supersample 2, 2 threads) */
    ak_raster_desc d = {.width = w, .height = h, .supersample = a->opt.supersample, .thread_count = a->opt.threads};
    ak_raster_destroy(f->raster);
    f->raster = NULL;
    free(img->pixels);
    img->pixels = NULL;
    if (ak_raster_create(&d, NULL, &f->raster) != AK_OK || cli_image_alloc(img, w, h)) return CLI_BAD_INPUT;
    return CLI_OK;
}

/* The camera's position: -R^T t of the rigid view matrix. */
static ak_vec3 camera_eye(const ak_raster_camera* c) {
    const float* m = c->view.m;
    return ak_vec3_make(-(m[0] * m[12] + m[1] * m[13] + m[2] * m[14]), -(m[4] * m[12] + m[5] * m[13] + m[6] * m[14]),
                        -(m[8] * m[12] + m[9] * m[13] + m[10] * m[14]));
}

/* Where the eye may not go below: the floor (the ground is drawn at the framed box's bottom)
 * and a simulation's surface under it (terrain), plus 1% of the box's diagonal. */
static float camera_min_height(const view_app* a, ak_vec3 eye) {
    const float clearance = 0.01f * ak_vec3_length(ak_vec3_sub(a->box_hi, a->box_lo));
    float floor_y = a->box_lo.y, surface = 0.0f;
    if (a->sim && a->sim->surface && a->sim->surface(a->sim_state, eye.x, eye.z, &surface) && surface > floor_y)
        floor_y = surface;
    return floor_y + clearance;
}

/* The orbit camera; orbiting or panning never takes it under the floor or the terrain: the
 * elevation is raised (in steps of 0.01 rad, up to the orbit's 1.45 limit) until the eye is
 * above both, and kept, so dragging further down leaves the view where it is. */
static void camera_update(view_app* a, cli_frame* f) {
    ak_view_orbit o = a->orbit;
    o.aspect = (float)f->width / (float)f->height;
    o.margin = 1.08f * a->zoom;
    for (int k = 0; k < 400; ++k) {
        f->camera = ak_view_orbit_camera(ak_vec3_add(a->box_lo, a->pan), ak_vec3_add(a->box_hi, a->pan), &o);
        const ak_vec3 eye = camera_eye(&f->camera);
        if (!(eye.y < camera_min_height(a, eye)) || o.elevation >= 1.45f) break;
        o.elevation = ak_minf(o.elevation + 0.01f, 1.45f);
    }
    a->orbit.elevation = o.elevation;
    f->bmin = a->box_lo;
    f->bmax = a->box_hi;
}

int view_app_resize(view_app* a, int w, int h) {
    if (w < 8 || h < 8) return CLI_OK; /* keep the old targets for a degenerate size */
    cli_frame_free(&a->frame);
    cli_frame_free(&a->panel);
    free(a->panel_image.pixels);
    memset(&a->panel_image, 0, sizeof a->panel_image);
    a->width = w;
    a->height = h;
    if (make_frame(a, &a->frame, &a->image, w, h) == CLI_OK) return CLI_OK;
    a->quit = true;
    a->exit_code = cli_fail("view", "out of memory for a %dx%d view", w, h);
    return a->exit_code;
}

/* ---- IK ---- */

static const ak_skeleton* skel(const view_app* a) { return a->scene->skeleton; }

static int joint_parent(const view_app* a, int j) {
    ak_i32_cspan par = ak_skeleton_parents(skel(a));
    return j >= 0 && (size_t)j < par.count ? par.ptr[j] : -1;
}

static void ik_rebuild(view_app* a) {
    a->chain_count = 0;
    a->ik_valid = false;
    if (a->effector < 0) return;
    size_t n = a->poser.joint_count;
    if (ak_ik_chain_build(skel(a), a->root, a->effector, (ak_i16_span){a->chain, n}, &a->chain_count) != AK_OK)
        a->chain_count = 0;
}

static ak_vec3 joint_pos(const view_app* a, int j) { return ak_mat4_get_translation(a->poser.world[j]); }

static void ik_select(view_app* a, int joint) {
    a->effector = joint;
    int root = joint;
    for (int k = 0; k < 2 && joint_parent(a, root) >= 0; ++k) root = joint_parent(a, root);
    a->root = root;
    a->target = joint_pos(a, joint);
    ik_rebuild(a);
}

static void ik_drop(view_app* a) {
    a->effector = a->root = -1;
    a->chain_count = 0;
    a->ik_valid = false;
    a->ik_problem = NULL;
}

/* The chain a solve uses: the two-bone solver takes the last three joints. */
static bool ik_chain(const view_app* a, const int16_t** ch, size_t* count) {
    *ch = a->chain;
    *count = a->chain_count;
    if (a->solver == AK_IK_SOLVER_TWO_BONE) {
        if (*count < 3) return false;
        *ch += *count - 3;
        *count = 3;
    }
    return *count > 0;
}

static void ik_apply(view_app* a) {
    a->ik_problem = NULL;
    if (a->effector < 0 || a->chain_count == 0) return;
    const int16_t* ch;
    size_t cc;
    if (!ik_chain(a, &ch, &cc)) {
        a->ik_problem = "two-bone needs 3 joints";
        return;
    }
    ak_transform* local = a->poser.local;
    bool same = a->ik_valid && a->ik_target_solved.x == a->target.x && a->ik_target_solved.y == a->target.y &&
                a->ik_target_solved.z == a->target.z && a->ik_time_solved == a->time && a->ik_clip_solved == a->clip &&
                a->ik_solver_solved == (int)a->solver && a->ik_root_solved == a->root && a->ik_bind_solved == a->bind;
    if (same) {
        for (size_t k = 0; k < cc; ++k) local[ch[k]] = a->ik_solved[k];
        return;
    }
    ak_ik_chain_job job = {
        .skeleton = skel(a),
        .pose = {local, a->poser.joint_count},
        .chain = {ch, cc},
        .target = a->target,
        .solver = a->solver,
        .scratch = {a->ik_scratch, a->ik_scratch_size},
        .out_reached = &a->ik_reached,
        .out_error = &a->ik_error,
    };
    ak_result r = ak_ik_chain_run(&job);
    if (r != AK_OK) {
        a->ik_problem = ak_result_string(r);
        a->ik_valid = false;
        return;
    }
    for (size_t k = 0; k < cc; ++k) a->ik_solved[k] = local[ch[k]];
    a->ik_valid = true;
    a->ik_target_solved = a->target;
    a->ik_time_solved = a->time;
    a->ik_clip_solved = a->clip;
    a->ik_solver_solved = (int)a->solver;
    a->ik_root_solved = a->root;
    a->ik_bind_solved = a->bind;
    if (a->opt.ik_log) {
        FILE* f = a->opt.ik_log;
        fprintf(f, "{\"frame\": %ld, \"solver\": \"%s\", \"effector\": ", a->frame_index, ak_ik_solver_name(a->solver));
        cli_json_string(f, ak_skeleton_joint_name(skel(a), (size_t)a->effector));
        fprintf(f, ", \"target\": [%.9g, %.9g, %.9g], \"reached\": %s, \"error\": %.9g}\n", (double)a->target.x,
                (double)a->target.y, (double)a->target.z, a->ik_reached ? "true" : "false", (double)a->ik_error);
        fflush(f);
    }
}

/* ---- posing ---- */

static double clip_duration(const view_app* a) {
    return a->clip >= 0 ? (double)ak_clip_duration(a->scene->clips[a->clip]) : 0.0;
}

/* Sample, user morph weights, IK and FK into the poser (no skinning yet). */
static ak_result pose_sample(view_app* a) {
    cli_poser* p = &a->poser;
    ak_result r = cli_poser_sample(p, a->bind ? -1 : a->clip, (float)a->time, a->bind);
    if (r != AK_OK) return r;
    for (size_t k = 0; k < a->morph_count; ++k)
        if (a->morph_set[k]) p->morph_weights[k] = a->morph_user[k];
    if (p->joint_count) {
        ik_apply(a);
        r = ak_scene_world_matrices(a->scene, (ak_transform_cspan){p->local, p->joint_count},
                                    (ak_mat4_span){p->world, p->joint_count});
    }
    return r;
}

/* ---- 2D helpers ---- */

static bool project(const cli_frame* f, ak_vec3 w, ak_vec2* out) {
    ak_vec3 px;
    if (!ak_raster_camera_project(&f->camera, f->width, f->height, w, &px)) return false;
    *out = (ak_vec2){px.x, px.y};
    return true;
}

/* World point under image position (x, y) on the plane through `through` facing the camera. */
static ak_vec3 plane_point(const cli_frame* f, float x, float y, ak_vec3 through) {
    ak_mat4 inv = ak_mat4_inverse(ak_mat4_mul(f->camera.projection, f->camera.view));
    float nx = 2.0f * x / (float)f->width - 1.0f, ny = 1.0f - 2.0f * y / (float)f->height;
    ak_vec3 p0 = ak_mat4_project_point(inv, ak_vec3_make(nx, ny, -1.0f));
    ak_vec3 p1 = ak_mat4_project_point(inv, ak_vec3_make(nx, ny, 1.0f));
    ak_vec3 dir = ak_vec3_sub(p1, p0);
    const float* v = f->camera.view.m;
    ak_vec3 n = ak_vec3_make(v[2], v[6], v[10]);
    float den = ak_vec3_dot(dir, n);
    if (!(fabsf(den) > 1e-12f)) return through;
    ak_vec3 q = ak_vec3_madd(p0, dir, ak_vec3_dot(ak_vec3_sub(through, p0), n) / den);
    return ak_vec3_is_finite(q) ? q : through;
}

/* ---- overlays ---- */

static void draw_normals(const view_app* a, const cli_frame* f, const ak_image* img) {
    const ak_scene* s = a->scene;
    ak_vec3 size = ak_vec3_sub(a->box_hi, a->box_lo);
    float len = 0.03f * ak_vec3_length(size);
    ak_mat4 inv_view = ak_mat4_inverse_affine(f->camera.view);
    ak_vec3 eye = ak_mat4_get_translation(inv_view);
    for (size_t m = 0; m < s->mesh_count; ++m) {
        const ak_mesh* mesh = s->meshes[m].mesh;
        if (!mesh || !mesh->vertex_count) continue;
        size_t step = (mesh->vertex_count + 2999) / 3000;
        for (size_t i = 0; i < mesh->vertex_count; i += step) {
            ak_vec3 p = a->poser.positions[m][i], n = a->poser.normals[m][i];
            if (ak_vec3_dot(n, ak_vec3_sub(eye, p)) <= 0.0f) continue; /* facing away */
            ak_vec2 p0, p1;
            if (project(f, p, &p0) && project(f, ak_vec3_madd(p, n, len), &p1))
                ak_image_draw_line(img, p0, p1, 1.0f, rgba(0.1f, 0.35f, 0.95f, 0.9f));
        }
    }
}

static void draw_arc(const cli_frame* f, const ak_image* img, ak_vec3 c, ak_quat frame, ak_vec3 axis, ak_vec3 ref,
                     float a0, float a1, ak_vec4 color) {
    ak_vec2 prev = {0, 0};
    bool have = false;
    const int steps = 24;
    for (int k = 0; k <= steps; ++k) {
        float t = a0 + (a1 - a0) * (float)k / (float)steps;
        ak_vec3 d = ak_quat_rotate(frame, ak_quat_rotate(ak_quat_from_axis_angle(axis, t), ref));
        ak_vec2 q;
        bool ok = project(f, ak_vec3_add(c, d), &q);
        if (ok && have) ak_image_draw_line(img, prev, q, 2.0f, color);
        have = ok;
        prev = q;
    }
}

/* Limits of the chain's joints: hinges as an arc of the child bone's reach, balls as the
 * cone of the twist axis (both in the joint's rest frame under its current parent). */
static void draw_limits(const view_app* a, const cli_frame* f, const ak_image* img) {
    const ak_skeleton* sk = skel(a);
    ak_transform_cspan rest = ak_skeleton_rest_pose(sk);
    for (size_t k = 0; k < a->chain_count; ++k) {
        int j = a->chain[k];
        ak_joint_type type = ak_skeleton_joint_type(sk, (size_t)j);
        if (type != AK_JOINT_HINGE && type != AK_JOINT_BALL) continue;
        ak_joint_limits l = ak_skeleton_joint_limits(sk, (size_t)j);
        int parent = joint_parent(a, j);
        ak_quat pr = parent >= 0 ? ak_quat_from_mat3(ak_mat4_to_mat3(a->poser.world[parent])) : ak_quat_identity();
        ak_quat frame = ak_quat_normalize(ak_quat_mul(pr, rest.ptr[j].rotation));
        ak_vec3 c = joint_pos(a, j);
        /* reference direction: the child bone in the chain, else the bone from the parent */
        ak_vec3 ref;
        if (k + 1 < a->chain_count) ref = rest.ptr[a->chain[k + 1]].translation;
        else ref = ak_vec3_scale(ak_quat_rotate(ak_quat_conjugate(rest.ptr[j].rotation), rest.ptr[j].translation), 0.5f);
        float len = ak_vec3_length(ref);
        if (!(len > 0.0f)) continue;
        ref = ak_vec3_scale(ref, 0.6f);
        if (type == AK_JOINT_HINGE) {
            float lo = l.min, hi = l.max;
            if (lo == 0.0f && hi == 0.0f) lo = -AK_PI, hi = AK_PI;
            draw_arc(f, img, c, frame, l.axis, ref, lo, hi, rgba(1.0f, 0.55f, 0.1f, 0.95f));
        } else if (l.cone_angle > 0.0f) {
            /* the cone: the twist axis tipped by cone_angle, swept around the axis */
            ak_vec3 ax = ak_vec3_scale(l.axis, 0.6f * len);
            ak_vec3 perp = ak_vec3_normalize(ak_vec3_cross(l.axis, fabsf(l.axis.x) < 0.9f ? ak_vec3_make(1, 0, 0) : ak_vec3_make(0, 1, 0)));
            ak_vec3 rim = ak_quat_rotate(ak_quat_from_axis_angle(perp, l.cone_angle), ax);
            draw_arc(f, img, c, frame, l.axis, rim, 0.0f, 2.0f * AK_PI, rgba(1.0f, 0.55f, 0.1f, 0.95f));
            ak_vec2 p0, p1;
            if (project(f, c, &p0) && project(f, ak_vec3_add(c, ak_quat_rotate(frame, ax)), &p1))
                ak_image_draw_line(img, p0, p1, 1.5f, rgba(1.0f, 0.55f, 0.1f, 0.95f));
        }
    }
}

static void draw_ik(const view_app* a, const cli_frame* f, const ak_image* img) {
    if (a->effector < 0) return;
    ak_vec4 blue = rgba(0.1f, 0.55f, 1.0f, 1), black = rgba(0, 0, 0, 1);
    ak_vec2 prev = {0, 0};
    for (size_t i = 0; i < a->chain_count; ++i) {
        ak_vec2 q;
        if (!project(f, joint_pos(a, a->chain[i]), &q)) continue;
        if (i) ak_image_draw_line(img, prev, q, 3.0f, blue);
        ak_image_draw_disc(img, q, 4.5f, blue, 1.5f, black);
        prev = q;
    }
    ak_vec2 t;
    if (project(f, a->target, &t)) {
        ak_vec4 c = a->ik_valid && a->ik_reached ? rgba(0.15f, 0.85f, 0.3f, 1) : rgba(0.95f, 0.15f, 0.2f, 1);
        ak_image_draw_disc(img, t, 7.0f, c, 2.0f, rgba(1, 1, 1, 1));
        char label[64];
        if (a->ik_problem) snprintf(label, sizeof label, "%s", a->ik_problem);
        else if (a->ik_valid) snprintf(label, sizeof label, "%s %.3g", a->ik_reached ? "reached" : "error", (double)a->ik_error);
        else label[0] = '\0';
        ak_image_draw_text(img, (int)(t.x + 11.0f), (int)(t.y - 4.0f), label, 1, rgba(0.05f, 0.05f, 0.08f, 1));
    }
}

/* ---- HUD ---- */

static void timeline_rect(const view_app* a, float* x, float* y, float* w, float* h) {
    int s = text_scale(a);
    *x = 8.0f;
    *w = (float)a->width - 16.0f;
    *h = 8.0f * (float)s;
    *y = (float)a->height - *h - 6.0f * (float)s;
}

/* Name of morph target k in the scene's flat morph index (mesh order), "" when unnamed. */
static const char* morph_name(const view_app* a, size_t k) {
    const ak_scene* s = a->scene;
    for (size_t m = 0; m < s->mesh_count; ++m) {
        const ak_mesh* mesh = s->meshes[m].mesh;
        if (!mesh) continue;
        if (k < mesh->morph_target_count) return mesh->morph_names ? mesh->morph_names[k] : "";
        k -= mesh->morph_target_count;
    }
    return "";
}

/* The viewer's keys that still apply with a simulation (the rest are about the model). */
static bool sim_help_key(const char* k) {
    return !strcmp(k, "space") || !strcmp(k, "f") || !strcmp(k, "p") || !strcmp(k, "h");
}

size_t view_help_list(const view_sim* sim, const view_help_entry** out, size_t capacity) {
    static const view_help_entry sim_escape = {"escape", "quit"};
    size_t n = 0;
    for (size_t i = 0; sim && i < sim->key_count && n < capacity; ++i) out[n++] = &sim->keys[i];
    for (size_t i = 0; i < view_help_count && n < capacity; ++i) {
        if (sim && !strcmp(view_help[i].key, "escape")) out[n++] = &sim_escape; /* there is no IK effector */
        else if (!sim || sim_help_key(view_help[i].key)) out[n++] = &view_help[i];
    }
    return n;
}

static void draw_hud(view_app* a) {
    const ak_image* img = &a->image;
    const ak_scene* s = a->scene;
    int sc = text_scale(a);
    float lh = (float)(AK_FONT_ADVANCE_Y * sc);
    char line1[256], line2[320], fps[32];
    if (a->opt.scripted) snprintf(fps, sizeof fps, "%.0f fps (fixed step)", 1.0 / FIXED_STEP);
    else snprintf(fps, sizeof fps, "%.1f fps", a->fps);
    double dur = clip_duration(a);
    const char* method = a->side_by_side ? "LBS|DQS|CoR" : cli_method_name(a->method);
    if (a->sim)
        snprintf(line1, sizeof line1, "%s | %s%s", fps, a->sim->name, a->playing ? "" : " paused");
    else if (a->bind)
        snprintf(line1, sizeof line1, "%s | bind pose | %s", fps, method);
    else if (a->clip >= 0)
        snprintf(line1, sizeof line1, "%s | %s %.2f/%.2fs x%g %s%s | %s", fps, ak_clip_name(s->clips[a->clip]), a->time,
                 dur, a->speed, a->loop ? "loop" : "once", a->playing ? "" : " paused", method);
    else
        snprintf(line1, sizeof line1, "%s | no clip | %s", fps, method);
    size_t o = 0;
    line2[0] = '\0';
#define APPEND(...)                                                                                    \
    do {                                                                                               \
        if (o < sizeof line2) o += (size_t)snprintf(line2 + o, sizeof line2 - o, __VA_ARGS__);           \
    } while (0)
    if (a->message_frames > 0) APPEND("%s | ", a->message);
    if (a->sim && a->sim->status) {
        char st[200];
        st[0] = '\0';
        a->sim->status(a->sim_state, st, sizeof st);
        APPEND("%s | ", st);
    }
    if (a->weight_bone >= 0)
        APPEND("weights %s | ", ak_skeleton_joint_name(skel(a), (size_t)a->weight_joints[a->weight_bone]));
    if (a->effector >= 0) {
        APPEND("IK %s %s..%s: ", ak_ik_solver_name(a->solver), ak_skeleton_joint_name(skel(a), (size_t)a->root),
               ak_skeleton_joint_name(skel(a), (size_t)a->effector));
        if (a->ik_problem) APPEND("%s | ", a->ik_problem);
        else APPEND("%s, error %.4g | ", a->ik_reached ? "reached" : "not reached", (double)a->ik_error);
    } else if (!a->sim) {
        APPEND("IK %s | ", ak_ik_solver_name(a->solver));
    }
    if (a->morph_count)
        APPEND("morph %d %s: %.2f | ", a->morph_index, morph_name(a, (size_t)a->morph_index),
               (double)a->poser.morph_weights[a->morph_index]);
    if (a->show_skeleton) APPEND("skeleton | ");
    if (a->show_normals) APPEND("normals | ");
    if (a->show_limits) APPEND("limits | ");
    APPEND("h: help");
#undef APPEND
    ak_image_fill_rect(img, 0, 0, (float)a->width, 2.0f * lh + 6.0f, rgba(0.05f, 0.06f, 0.08f, 0.72f));
    ak_image_draw_text(img, 6, 3, line1, sc, rgba(1, 1, 1, 1));
    ak_image_draw_text(img, 6, 3 + (int)lh, line2, sc, rgba(0.85f, 0.9f, 1, 1));
    /* timeline */
    float x, y, w, h;
    timeline_rect(a, &x, &y, &w, &h);
    ak_image_fill_rect(img, 0, y - 4.0f * (float)sc, (float)a->width, (float)a->height - y + 4.0f * (float)sc,
                       rgba(0.05f, 0.06f, 0.08f, 0.6f));
    ak_image_fill_rect(img, x, y, w, h, rgba(0.3f, 0.32f, 0.36f, 1));
    if (dur > 0 && !a->bind) {
        float u = (float)(a->time / dur);
        u = ak_clampf(u, 0.0f, 1.0f);
        ak_image_fill_rect(img, x, y, w * u, h, rgba(0.35f, 0.65f, 1.0f, 1));
        ak_image_fill_rect(img, x + w * u - 2.0f, y - 2.0f, 4.0f, h + 4.0f, rgba(1, 1, 1, 1));
    }
    if (a->morph_count) {
        /* the selected morph target's weight as a slider under the status band ([ and ] move it) */
        float sw = 120.0f * (float)sc, sh = 6.0f * (float)sc, sx = (float)a->width - sw - 10.0f, sy = 2.0f * lh + 12.0f;
        float u = ak_clampf(a->poser.morph_weights[a->morph_index], 0.0f, 1.0f);
        ak_image_fill_rect(img, sx, sy, sw, sh, rgba(0.3f, 0.32f, 0.36f, 0.9f));
        ak_image_fill_rect(img, sx, sy, sw * u, sh, rgba(1.0f, 0.6f, 0.2f, 1));
        ak_image_fill_rect(img, sx + sw * u - 1.5f, sy - 2.0f, 3.0f, sh + 4.0f, rgba(1, 1, 1, 1));
    }
    if (a->side_by_side) {
        static const char* const names[3] = {"LBS", "DQS", "CoR"};
        int pw = a->width / 3;
        for (int k = 0; k < 3; ++k) {
            int tw, th;
            ak_text_size(names[k], sc * 2, &tw, &th);
            ak_image_draw_text(img, k * pw + (pw - tw) / 2, (int)(2.0f * lh + 12.0f), names[k], sc * 2, rgba(0.08f, 0.09f, 0.12f, 1));
        }
    }
    if (a->show_help) {
        /* one column when it fits, else two; each column 41 characters */
        float top = 2.0f * lh + 8.0f, avail = (float)a->height - top - 24.0f * (float)sc;
        /* a simulation's keys, then the viewer's that apply to it; else the viewer's */
        const view_help_entry* list[64];
        size_t nkeys = view_help_list(a->sim, list, 64);
        int cols = ((float)(nkeys + MOUSE_HELP_COUNT + 2) * lh + 16.0f <= avail) ? 1 : 2;
        size_t rows = (nkeys + (size_t)cols - 1) / (size_t)cols;
        float cw = (float)(41 * AK_FONT_ADVANCE_X * sc);
        float bw = (float)cols * cw + 16.0f, bh = (float)(rows + MOUSE_HELP_COUNT + 2) * lh + 16.0f;
        float bx = ak_maxf(0.0f, ((float)a->width - bw) * 0.5f), by = ak_maxf(top, top + (avail - bh) * 0.5f);
        ak_image_fill_rect(img, bx, by, bw, bh, rgba(0.05f, 0.06f, 0.08f, 0.85f));
        int ty = (int)by + 8;
        ak_image_draw_text(img, (int)bx + 8, ty, "keys (h closes)", sc, rgba(1, 0.85f, 0.3f, 1));
        ty += (int)lh;
        for (size_t i = 0; i < nkeys; ++i) {
            const view_help_entry* e = list[i];
            char l[128];
            snprintf(l, sizeof l, "%-7s %s", e->key, e->what);
            int col = (int)(i / rows), row = (int)(i % rows);
            ak_image_draw_text(img, (int)(bx + 8.0f + (float)col * cw), ty + row * (int)lh, l, sc, rgba(1, 1, 1, 1));
        }
        ty += (int)((float)(rows + 1) * lh);
        for (size_t i = 0; i < MOUSE_HELP_COUNT; ++i, ty += (int)lh)
            ak_image_draw_text(img, (int)bx + 8, ty, a->sim && i == 1 ? (a->sim->grab ? (a->sim->grab_help ? a->sim->grab_help : "left on a sphere: drag the collider") : "") : mouse_help[i],
                               sc, rgba(0.8f, 0.9f, 1, 1));
    }
}

/* ---- drawing ---- */

static ak_result draw_view(view_app* a, cli_frame* f, const ak_image* img) {
    ak_raster_mesh extra[CLI_MAX_EXTRA];
    size_t extra_count = 0;
    if (a->sim && a->sim->meshes) extra_count = a->sim->meshes(a->sim_state, extra, CLI_MAX_EXTRA);
    cli_draw_opts o = {
        .skeleton = a->show_skeleton,
        .colors = a->weight_bone >= 0 ? a->colors : NULL,
        .extra = extra,
        .extra_count = extra_count,
        .draw = a->sim ? a->sim->draw : NULL,
        .draw_user = a->sim_state,
    };
    if (a->sim && a->sim->sky && !a->sim->sky(a->sim_state, &o.sky_top, &o.sky_bottom))
        o.sky_top = o.sky_bottom = ak_vec4_make(0, 0, 0, 0);
    ak_result r = cli_frame_draw(f, &a->poser, &o, img);
    if (r != AK_OK) return r;
    if (a->show_normals) draw_normals(a, f, img);
    if (a->show_limits) draw_limits(a, f, img);
    draw_ik(a, f, img);
    if (a->sim && a->sim->overlay) a->sim->overlay(a->sim_state, &f->camera, img);
    return AK_OK;
}

ak_result view_app_render(view_app* a) {
    double t0 = cli_now();
    ak_result r = pose_sample(a);
    double t1 = cli_now();
    a->stats.sample += t1 - t0;
    if (r != AK_OK) return r;
    camera_update(a, &a->frame);
    if (!a->side_by_side) {
        r = cli_poser_deform(&a->poser, false, a->method);
        double t2 = cli_now();
        a->stats.skin += t2 - t1;
        if (r == AK_OK) r = draw_view(a, &a->frame, &a->image);
        if (r == AK_OK) draw_hud(a);
        a->stats.raster += cli_now() - t2;
    } else {
        int pw = a->width / 3;
        if (!a->panel.raster && make_frame(a, &a->panel, &a->panel_image, pw, a->height)) return AK_ERR_NO_MEMORY;
        camera_update(a, &a->panel);
        ak_image_fill(&a->image, rgba(0.83f, 0.87f, 0.93f, 1));
        for (int k = 0; k < 3 && r == AK_OK; ++k) {
            double t2 = cli_now();
            r = cli_poser_deform(&a->poser, false, (cli_method)k);
            double t3 = cli_now();
            a->stats.skin += t3 - t2;
            if (r == AK_OK) r = draw_view(a, &a->panel, &a->panel_image);
            if (r == AK_OK) r = ak_image_blit(&a->image, k * pw, 0, &a->panel_image);
            a->stats.raster += cli_now() - t3;
        }
        if (r == AK_OK) draw_hud(a);
    }
    a->stats.frames++;
    return r;
}

int view_app_screenshot(view_app* a, const char* path) {
    ak_result r = view_app_render(a);
    if (r == AK_OK) r = ak_png_write(path, &a->image);
    if (r != AK_OK) return cli_fail("view", "%s: cannot write the screenshot: %s", path, ak_result_string(r));
    return CLI_OK;
}

int view_app_script_screenshot(view_app* a, const view_event* ev) {
    const char* dir = a->opt.shot_dir ? a->opt.shot_dir : ".";
    const char* script = a->opt.script_name ? a->opt.script_name : "script";
    char full[4096];
    int n = snprintf(full, sizeof full, "%s/%s", dir, ev->path);
    if (n < 0 || (size_t)n >= sizeof full)
        return cli_fail("view", "%s: line %d: screenshot path '%s' is too long", script, ev->line, ev->path);
    /* The parser refused absolute paths and '..'; what is left is a symlink under the shot
     * directory that leads elsewhere. Each component is checked without following it (the
     * PNG writer renames a temporary over the last one, which never follows a link either). */
    for (size_t i = strlen(dir) + 1;; ++i) {
        if (full[i] != '/' && full[i] != '\0') continue;
        const char c = full[i];
        full[i] = '\0';
        struct stat st;
        const bool link = lstat(full, &st) == 0 && S_ISLNK(st.st_mode);
        if (link)
            return cli_fail("view", "%s: line %d: screenshot '%s': %s is a symlink; screenshots stay inside the shot "
                                    "directory %s",
                            script, ev->line, ev->path, full, dir);
        full[i] = c;
        if (!c) break;
    }
    return view_app_screenshot(a, full);
}

void view_app_frame_all(view_app* a) {
    ak_vec3 lo = ak_vec3_splat(INFINITY), hi = ak_vec3_splat(-INFINITY);
    if (pose_sample(a) == AK_OK && cli_poser_deform(&a->poser, false, a->method) == AK_OK) cli_bounds_add_pose(&a->poser, &lo, &hi);
    if (a->sim && a->sim->bounds) a->sim->bounds(a->sim_state, &lo, &hi);
    if (!ak_vec3_is_finite(lo) || !ak_vec3_is_finite(hi)) lo = hi = ak_vec3_zero();
    a->box_lo = lo;
    a->box_hi = hi;
    a->pan = ak_vec3_zero();
    a->zoom = 1.0f;
    a->orbit = (ak_view_orbit){.azimuth = 0.55f, .elevation = 0.22f};
}

/* ---- input ---- */

static void message(view_app* a, const char* text) {
    size_t n = strlen(text);
    if (n >= sizeof a->message) n = sizeof a->message - 1; /* long paths are cut */
    memcpy(a->message, text, n);
    a->message[n] = '\0';
    a->message_frames = 60;
}

static void set_weights(view_app* a) {
    const ak_scene* s = a->scene;
    for (size_t m = 0; m < s->mesh_count; ++m) {
        free(a->colors[m]);
        a->colors[m] = NULL;
    }
    if (a->weight_bone < 0) return;
    int found = 0;
    const char* name = ak_skeleton_joint_name(skel(a), (size_t)a->weight_joints[a->weight_bone]);
    if (cli_weights_colors(s, name, a->colors, &found)) {
        message(a, "out of memory for the heatmap");
        a->weight_bone = -1;
    }
}

static void move_target(view_app* a, int axis, float sign) {
    if (a->effector < 0) {
        message(a, "no IK effector: click a joint first");
        return;
    }
    const float* v = a->frame.camera.view.m;
    ak_vec3 dir = ak_vec3_make(v[axis], v[axis + 4], v[axis + 8]); /* row `axis` of the view: right, up, back */
    float step = 0.02f * ak_vec3_length(ak_vec3_sub(a->box_hi, a->box_lo));
    if (!(step > 0.0f)) step = 0.02f;
    a->target = ak_vec3_madd(a->target, dir, sign * step);
}

static void morph_step(view_app* a, float delta) {
    if (!a->morph_count) {
        message(a, "this model has no morph targets");
        return;
    }
    size_t k = (size_t)a->morph_index;
    a->morph_user[k] = ak_clampf(a->poser.morph_weights[k] + delta, 0.0f, 1.0f);
    a->morph_set[k] = true;
    a->poser.morph_weights[k] = a->morph_user[k];
}

/* Keys a simulation takes: its own first, then R / tab reset and the right arrow steps. */
static bool sim_key(view_app* a, int k) {
    char m[160];
    m[0] = '\0';
    if (a->sim->key && a->sim->key(a->sim_state, k, m, sizeof m)) {
        if (m[0]) message(a, m);
        return true;
    }
    if (k == 'r' || k == '\t') {
        if (a->sim->reset) a->sim->reset(a->sim_state); /* the status line shows t 0 */
        return true;
    }
    if (k == VIEW_KEY_RIGHT) {
        a->playing = false;
        if (a->sim->step) a->sim->step(a->sim_state, (float)FIXED_STEP);
        return true;
    }
    return false;
}

static void key(view_app* a, int k) {
    double dur = clip_duration(a);
    if (a->sim && sim_key(a, k)) return;
    switch (k) {
    case ' ':
        a->playing = !a->playing;
        if (a->playing) a->bind = false;
        break;
    case VIEW_KEY_LEFT:
    case VIEW_KEY_RIGHT:
        a->playing = false;
        a->bind = false;
        a->time += k == VIEW_KEY_LEFT ? -FIXED_STEP : FIXED_STEP;
        if (a->time < 0) a->time = 0;
        if (a->time > dur) a->time = dur;
        break;
    case VIEW_KEY_UP: a->speed = a->speed * 2 > 16 ? 16 : a->speed * 2; break;
    case VIEW_KEY_DOWN: a->speed = a->speed / 2 < 1.0 / 16 ? 1.0 / 16 : a->speed / 2; break;
    case '\t':
        if (a->scene->clip_count) {
            a->clip = (a->clip + 1) % (int)a->scene->clip_count;
            a->time = 0;
            a->bind = false;
            if (a->sim && a->sim->reset) a->sim->reset(a->sim_state);
        } else {
            message(a, "this model has no clips");
        }
        break;
    case 'l': a->loop = !a->loop; break;
    case 'b': a->bind = !a->bind; break;
    case 'f': view_app_frame_all(a); break;
    case '1': a->method = CLI_LBS, a->side_by_side = false; break;
    case '2': a->method = CLI_DQS, a->side_by_side = false; break;
    case '3': a->method = CLI_COR, a->side_by_side = false; break;
    case '6': a->method = CLI_SOFT, a->side_by_side = false; break;
    case '4': a->side_by_side = !a->side_by_side; break;
    case '5': a->method = CLI_IMPLICIT, a->side_by_side = false; break;
    case 'w':
        if (!a->weight_joint_count) {
            message(a, "this model has no skin weights");
            break;
        }
        a->weight_bone = a->weight_bone + 1 >= (int)a->weight_joint_count ? -1 : a->weight_bone + 1;
        set_weights(a);
        break;
    case 'n': a->show_normals = !a->show_normals; break;
    case 'k': a->show_skeleton = !a->show_skeleton; break;
    case 'i':
        a->solver = a->solver == AK_IK_SOLVER_CCD        ? AK_IK_SOLVER_FABRIK
                    : a->solver == AK_IK_SOLVER_FABRIK   ? AK_IK_SOLVER_TWO_BONE
                    : a->solver == AK_IK_SOLVER_TWO_BONE ? AK_IK_SOLVER_DLS
                                                         : AK_IK_SOLVER_CCD;
        break;
    case 'r':
        if (a->effector < 0) {
            message(a, "no IK effector: click a joint first");
        } else {
            int up = joint_parent(a, a->root);
            a->root = up >= 0 ? up : (joint_parent(a, a->effector) >= 0 ? joint_parent(a, a->effector) : a->effector);
            ik_rebuild(a);
        }
        break;
    case 'a': move_target(a, 0, -1); break;
    case 'd': move_target(a, 0, 1); break;
    case 'e': move_target(a, 1, 1); break;
    case 'q': move_target(a, 1, -1); break;
    case 'z': move_target(a, 2, 1); break;
    case 'x': move_target(a, 2, -1); break;
    case 'j':
        a->show_limits = !a->show_limits;
        if (a->show_limits && a->effector < 0) message(a, "limits show on the IK chain: click a joint");
        break;
    case VIEW_KEY_ESCAPE:
        if (a->effector >= 0) ik_drop(a);
        else a->quit = true;
        break;
    case 'm':
        if (a->morph_count) a->morph_index = (a->morph_index + 1) % (int)a->morph_count;
        else message(a, "this model has no morph targets");
        break;
    case '[': morph_step(a, -0.1f); break;
    case ']': morph_step(a, 0.1f); break;
    case 'p': {
        char path[1100];
        snprintf(path, sizeof path, "%s/view_%04d.png", a->opt.shot_dir ? a->opt.shot_dir : ".", a->shot_count++);
        char m[1200];
        if (ak_png_write(path, &a->image) == AK_OK) snprintf(m, sizeof m, "wrote %s", path);
        else snprintf(m, sizeof m, "cannot write %s", path);
        message(a, m);
        break;
    }
    case 'h': a->show_help = !a->show_help; break;
    default: break;
    }
}

/* The target under the mouse: the full frame, or the side-by-side panel it is over. */
static cli_frame* frame_at(view_app* a, float* x) {
    if (!a->side_by_side || !a->panel.raster) return &a->frame;
    int pw = a->width / 3;
    int k = (int)(*x / (float)pw);
    if (k < 0) k = 0;
    if (k > 2) k = 2;
    *x -= (float)(k * pw);
    return &a->panel;
}

static int pick_joint(view_app* a, cli_frame* f, float x, float y) {
    int best = -1;
    float best_d = PICK_RADIUS * (float)text_scale(a);
    for (size_t k = 0; k < a->frame.joint_count; ++k) {
        int j = a->frame.joint_list[k];
        ak_vec2 q;
        if (!project(f, joint_pos(a, j), &q)) continue;
        float d = hypotf(q.x - x, q.y - y);
        if (d < best_d) best_d = d, best = j;
    }
    return best;
}

static void scrub(view_app* a, float x) {
    float bx, by, bw, bh;
    timeline_rect(a, &bx, &by, &bw, &bh);
    double dur = clip_duration(a);
    a->time = dur * (double)ak_clampf((x - bx) / bw, 0.0f, 1.0f);
    a->playing = false;
    a->bind = false;
}

void view_app_event(view_app* a, const view_event* ev) {
    switch (ev->type) {
    case VIEW_EV_KEY: key(a, ev->key); break;
    case VIEW_EV_WHEEL: a->zoom = ak_clampf(a->zoom * powf(0.9f, ev->dy), 0.02f, 50.0f); break;
    case VIEW_EV_MOUSE_DOWN: {
        a->mouse_x = ev->x;
        a->mouse_y = ev->y;
        float bx, by, bw, bh;
        timeline_rect(a, &bx, &by, &bw, &bh);
        if (ev->button == VIEW_BUTTON_MIDDLE || (ev->button == VIEW_BUTTON_LEFT && ev->shift)) {
            a->drag = VIEW_DRAG_PAN;
            break;
        }
        if (ev->button == VIEW_BUTTON_RIGHT && a->sim && a->sim->shoot && !a->side_by_side) {
            char m[160] = "";
            if (a->sim->shoot(a->sim_state, &a->frame.camera, a->frame.width, a->frame.height, ev->x, ev->y, m,
                              sizeof m) &&
                m[0])
                message(a, m);
            break;
        }
        if (ev->button != VIEW_BUTTON_LEFT) break;
        if (a->sim && a->sim->grab && !a->side_by_side &&
            a->sim->grab(a->sim_state, &a->frame.camera, a->frame.width, a->frame.height, ev->x, ev->y, &a->sim_anchor)) {
            a->drag = VIEW_DRAG_SIM;
            break;
        }
        if (a->clip >= 0 && ev->y >= by - 6.0f && ev->y <= by + bh + 6.0f) {
            a->drag = VIEW_DRAG_TIMELINE;
            scrub(a, ev->x);
            break;
        }
        float x = ev->x;
        cli_frame* f = frame_at(a, &x);
        /* the pose on screen is the last drawn one (poser.world) */
        ak_vec2 t;
        if (a->effector >= 0 && project(f, a->target, &t) && hypotf(t.x - x, t.y - ev->y) <= PICK_RADIUS * (float)text_scale(a)) {
            a->drag = VIEW_DRAG_TARGET;
            break;
        }
        int j = pick_joint(a, f, x, ev->y);
        if (j >= 0) {
            ik_select(a, j);
            a->drag = VIEW_DRAG_TARGET;
        } else {
            a->drag = VIEW_DRAG_ORBIT;
        }
        break;
    }
    case VIEW_EV_MOUSE_MOVE: {
        float dx = ev->x - a->mouse_x, dy = ev->y - a->mouse_y;
        if (a->drag == VIEW_DRAG_ORBIT) {
            a->orbit.azimuth -= dx * 0.01f;
            a->orbit.elevation = ak_clampf(a->orbit.elevation + dy * 0.01f, -1.45f, 1.45f);
        } else if (a->drag == VIEW_DRAG_PAN) {
            float x0 = a->mouse_x, x1 = ev->x;
            cli_frame* f = frame_at(a, &x0);
            frame_at(a, &x1);
            ak_vec3 c = ak_vec3_scale(ak_vec3_add(ak_vec3_add(a->box_lo, a->box_hi), ak_vec3_scale(a->pan, 2.0f)), 0.5f);
            ak_vec3 d = ak_vec3_sub(plane_point(f, x1, ev->y, c), plane_point(f, x0, a->mouse_y, c));
            a->pan = ak_vec3_sub(a->pan, d);
        } else if (a->drag == VIEW_DRAG_TARGET) {
            float x = ev->x;
            cli_frame* f = frame_at(a, &x);
            a->target = plane_point(f, x, ev->y, a->target);
        } else if (a->drag == VIEW_DRAG_TIMELINE) {
            scrub(a, ev->x);
        } else if (a->drag == VIEW_DRAG_SIM) {
            ak_vec3 to = plane_point(&a->frame, ev->x, ev->y, a->sim_anchor);
            if (a->sim->drag) a->sim->drag(a->sim_state, ak_vec3_sub(to, a->sim_anchor));
            a->sim_anchor = to;
        }
        a->mouse_x = ev->x;
        a->mouse_y = ev->y;
        break;
    }
    case VIEW_EV_MOUSE_UP: a->drag = VIEW_DRAG_NONE; break;
    default: break;
    }
}

void view_app_advance(view_app* a, double dt) {
    if (a->playing && !a->bind && a->clip >= 0) {
        double dur = clip_duration(a);
        a->time += dt * a->speed;
        if (a->time > dur) {
            if (a->loop && dur > 0) {
                a->time = fmod(a->time, dur);
            } else {
                a->time = dur;
                a->playing = false;
            }
        }
    }
    if (a->playing && a->sim && a->sim->step) a->sim->step(a->sim_state, (float)dt);
    if (a->message_frames > 0) --a->message_frames;
}

/* ---- lifetime ---- */

int view_app_init(view_app* a, const ak_scene* s, const view_options* opt) {
    memset(a, 0, sizeof(*a));
    a->scene = s;
    a->opt = *opt;
    a->clip = opt->clip;
    a->speed = 1.0;
    a->loop = true;
    a->playing = a->clip >= 0;
    a->weight_bone = -1;
    a->effector = a->root = -1;
    a->solver = AK_IK_SOLVER_FABRIK;
    a->zoom = 1.0f;
    if (opt->sim) {
        char err[640];
        err[0] = '\0';
        int rc = opt->sim->init(&a->sim_state, opt->sim_spec ? opt->sim_spec : "", &opt->sim_opts, err, sizeof err);
        if (rc) {
            fprintf(stderr, "animkit view: %s\n", err[0] ? err : "cannot start the simulation");
            memset(a, 0, sizeof(*a));
            return rc;
        }
        a->sim = opt->sim;
        a->playing = true;
    }
    if (cli_poser_init(&a->poser, s)) {
        view_app_free(a);
        return cli_fail("view", "out of memory");
    }
    size_t n = a->poser.joint_count ? a->poser.joint_count : 1;
    for (size_t m = 0; m < s->mesh_count; ++m)
        if (s->meshes[m].mesh) a->morph_count += s->meshes[m].mesh->morph_target_count;
    a->colors = calloc(s->mesh_count + 1, sizeof(ak_vec4*));
    a->weight_joints = calloc(n, sizeof(int));
    a->chain = calloc(n, sizeof(int16_t));
    a->ik_solved = calloc(n, sizeof(ak_transform));
    a->morph_user = calloc(a->morph_count + 1, sizeof(float));
    a->morph_set = calloc(a->morph_count + 1, sizeof(bool));
    for (int sv = AK_IK_SOLVER_CCD; sv < AK_IK_SOLVER_COUNT; ++sv) {
        size_t sz = ak_ik_chain_scratch_size((ak_ik_solver)sv, n);
        if (sz > a->ik_scratch_size) a->ik_scratch_size = sz;
    }
    a->ik_scratch = malloc(a->ik_scratch_size);
    if (!a->colors || !a->weight_joints || !a->chain || !a->ik_solved || !a->morph_user || !a->morph_set || !a->ik_scratch) {
        view_app_free(a);
        return cli_fail("view", "out of memory");
    }
    /* bones some skin is weighted to, in joint order */
    for (size_t j = 0; j < a->poser.joint_count; ++j) {
        bool used = false;
        for (size_t k = 0; k < s->skin_count && !used; ++k)
            for (size_t q = 0; q < s->skins[k].joint_count && !used; ++q) used = s->skins[k].joints[q] == (int)j;
        if (used) a->weight_joints[a->weight_joint_count++] = (int)j;
    }
    view_app_frame_all(a);
    if (view_app_resize(a, opt->width, opt->height)) {
        view_app_free(a);
        return CLI_BAD_INPUT;
    }
    return CLI_OK;
}

void view_app_free(view_app* a) {
    if (a->sim && a->sim->destroy) a->sim->destroy(a->sim_state);
    for (size_t m = 0; a->colors && m < a->scene->mesh_count; ++m) free(a->colors[m]);
    free(a->colors);
    free(a->weight_joints);
    free(a->chain);
    free(a->ik_solved);
    free(a->morph_user);
    free(a->morph_set);
    free(a->ik_scratch);
    free(a->image.pixels);
    free(a->panel_image.pixels);
    cli_frame_free(&a->frame);
    cli_frame_free(&a->panel);
    cli_poser_free(&a->poser);
    memset(a, 0, sizeof(*a));
}

/* ---- the loop ---- */

/* A simulation whose step or reset failed (it printed why) ends the run with exit status 1
 * before anything else is drawn or written. */
static bool sim_failed(const view_app* a) { return a->sim && a->sim->failed && a->sim->failed(a->sim_state); }

int view_app_run(view_app* a, const view_script* script, long max_frames, const view_platform* pl) {
    size_t next = 0;
    long pending = 0, done = 0;
    int rc = CLI_OK;
    double last = cli_now();
    while (rc == CLI_OK && !a->quit) {
        while (script && pending == 0 && next < script->count && !a->quit && rc == CLI_OK) {
            const view_event* ev = &script->events[next++];
            if (ev->type == VIEW_EV_WAIT) pending = ev->frames;
            else if (ev->type == VIEW_EV_SCREENSHOT) rc = view_app_script_screenshot(a, ev);
            else if (ev->type == VIEW_EV_QUIT) a->quit = true;
            else view_app_event(a, ev);
            if (sim_failed(a)) rc = CLI_BAD_INPUT; /* a key stepped or reset it */
        }
        if (rc != CLI_OK || a->quit) break;
        if (script && pending == 0) break; /* the script ran out */
        if (!script && !pl && done >= max_frames) break;
        bool visible = true;
        if (pl) {
            visible = pl->poll(pl->user, a);
            if (a->quit) break;
        }
        double now = cli_now(), wall = now - last;
        last = now;
        if (wall > 0) a->fps = a->fps > 0 ? 0.9 * a->fps + 0.1 / wall : 1.0 / wall;
        double dt = (a->opt.scripted || !pl) ? FIXED_STEP : (wall < 0.1 ? wall : 0.1);
        view_app_advance(a, dt);
        if (sim_failed(a)) {
            rc = CLI_BAD_INPUT;
            break;
        }
        if (visible) {
            ak_result r = view_app_render(a);
            if (r != AK_OK) {
                rc = cli_fail("view", "%s: cannot draw: %s", a->scene->name, ak_result_string(r));
                break;
            }
            if (pl) {
                double t0 = cli_now();
                rc = pl->present(pl->user, a);
                a->stats.present += cli_now() - t0;
            }
        }
        ++a->frame_index;
        ++done;
        if (pending > 0) --pending;
    }
    return rc != CLI_OK ? rc : a->exit_code;
}
