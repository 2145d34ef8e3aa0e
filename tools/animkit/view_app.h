/* animkit view: the viewer's state machine, shared by the window (view_sdl.c) and the
 * headless loop (cmd_view.c). Input events go in, a frame comes out as an ak_image; nothing
 * here knows about SDL, so the same code runs scripted in CI and interactively in a window.
 *
 * Frame order (view_app_run): script commands up to the next `wait` are applied, the
 * platform's own events are polled, time advances by one step (fixed 1/30 s while scripted
 * or headless, wall time otherwise), the pose is computed (sample, morph overrides, IK,
 * FK + skinning), drawn, and presented. `screenshot` draws the current state first. */
#ifndef ANIMKIT_CLI_VIEW_APP_H
#define ANIMKIT_CLI_VIEW_APP_H

#include <stdio.h>

#include "cli.h"
#include "render.h"

/* ---- keys and events ---- */

/* Key codes: printable keys are their lowercase ASCII character; the rest are below. */
enum {
    VIEW_KEY_ESCAPE = 256,
    VIEW_KEY_LEFT,
    VIEW_KEY_RIGHT,
    VIEW_KEY_UP,
    VIEW_KEY_DOWN,
};

typedef enum view_ev_type {
    VIEW_EV_KEY = 0,
    VIEW_EV_MOUSE_DOWN,
    VIEW_EV_MOUSE_MOVE,
    VIEW_EV_MOUSE_UP,
    VIEW_EV_WHEEL,
    VIEW_EV_WAIT,
    VIEW_EV_SCREENSHOT,
    VIEW_EV_QUIT,
} view_ev_type;

enum { VIEW_BUTTON_LEFT = 1, VIEW_BUTTON_MIDDLE = 2, VIEW_BUTTON_RIGHT = 3 };

typedef struct view_event {
    view_ev_type type;
    int key;          /* KEY */
    int button;       /* MOUSE_DOWN / MOUSE_UP: VIEW_BUTTON_* */
    float x, y;       /* mouse events: window pixels, (0, 0) top-left */
    float dy;         /* WHEEL: notches, > 0 zooms in */
    long frames;      /* WAIT */
    bool shift;       /* mouse down: shift held (left drag pans) */
    const char* path; /* SCREENSHOT: points into the script's text */
    int line;         /* script line (1-based), 0 for live events */
} view_event;

/* Key name as scripts and the help write it ("space", "left", "a", "[" ...); NULL if none. */
const char* view_key_name(int key);
/* Key code from a script name; 0 when unknown. */
int view_key_parse(const char* name);

/* One help line per key: name as a script writes it, and what it does. */
typedef struct view_help_entry {
    const char* key;
    const char* what;
} view_help_entry;
extern const view_help_entry view_help[];
extern const size_t view_help_count;

/* ---- scripts (view_script.c) ---- */

typedef struct view_script {
    char* text; /* owned copy of the file, NUL-split into paths */
    view_event* events;
    size_t count;
} view_script;

/* Parse a script from memory. On a bad line returns CLI_BAD_USAGE with "LINE: problem" in
 * err (the caller prefixes the file name); CLI_BAD_INPUT when out of memory. */
int view_script_parse(const char* text, size_t size, view_script* out, char* err, size_t err_size);
void view_script_free(view_script* s);

/* ---- simulations (view_sims.c) ---- */

/* A live simulation the viewer steps and draws with the model's camera. The viewer calls
 * init once with the spec after "KIND:", step once per frame while playing (dt in seconds,
 * fixed while scripted; the right arrow runs one such frame while paused), reset on R or tab
 * (back to the state init made, colliders and wind included), meshes before drawing (extra
 * meshes added to the frame, casting shadows), draw after the meshes (points, arrows: in the
 * raster, depth tested), overlay after the resolve (2D marks), bounds for F, key for the
 * simulation's own keys (true when used; msg gets a status message), grab when the left button
 * goes down (true when a collider is under the pixel: *anchor is its centre) and drag with the
 * world-space move of the anchor, status for the second status line, destroy at exit, failed
 * after every step and reset: true once one failed (the simulation printed why), and the
 * viewer then ends with exit status 1 and writes no further screenshot. Any hook but init may
 * be NULL. */
/* What the command line sets for a simulation: --seed (has_seed false -> the scene's own seed,
 * or 1 where the scene has none) and --threads (the simulation's worker threads; results are
 * the same for any count). */
typedef struct view_sim_opts {
    uint64_t seed;
    bool has_seed;
    int threads;
} view_sim_opts;

typedef struct view_sim {
    const char* name;
    /* Returns CLI_OK, CLI_BAD_INPUT (bad file: message in err) or CLI_BAD_USAGE (bad spec). */
    int (*init)(void** state, const char* spec, const view_sim_opts* opts, char* err, size_t err_size);
    void (*step)(void* state, float dt);
    void (*reset)(void* state);
    size_t (*meshes)(void* state, ak_raster_mesh* out, size_t capacity);
    ak_result (*draw)(void* state, ak_raster* raster, const ak_raster_camera* camera, int width, int height);
    void (*overlay)(void* state, const ak_raster_camera* camera, const ak_image* image);
    void (*bounds)(void* state, ak_vec3* lo, ak_vec3* hi);
    /* Optional: height of the simulation's ground surface under (x, z) (terrain), false where
     * there is none; the orbit keeps the camera above it as above the floor. */
    bool (*surface)(void* state, float x, float z, float* out_height);
    /* Optional: a background gradient instead of the light sky (the fire preset's additive
     * sprites glow on a dark one); false -> the default. */
    bool (*sky)(void* state, ak_vec4* top, ak_vec4* bottom);
    bool (*key)(void* state, int key, char* msg, size_t msg_size);
    bool (*grab)(void* state, const ak_raster_camera* camera, int width, int height, float x, float y, ak_vec3* anchor);
    void (*drag)(void* state, ak_vec3 delta);
    /* Optional: the right button went down at (x, y) (rigid: throw a sphere from the camera
     * through that pixel); true when it did something (msg: a status message). */
    bool (*shoot)(void* state, const ak_raster_camera* camera, int width, int height, float x, float y, char* msg,
                  size_t msg_size);
    void (*status)(void* state, char* out, size_t out_size);
    void (*destroy)(void* state);
    bool (*failed)(void* state);
    const view_help_entry* keys; /* the simulation's keys for the help overlay */
    size_t key_count;
    const char* grab_help; /* the help overlay's line for a left click; NULL -> "left on a
                              sphere: drag the collider" */
} view_sim;

/* The simulation a `animkit view` argument names ("particles:...", "boids", "boids:...", "cloth:...",
 * "terrain", "terrain:..."), with *spec the text after the colon ("" when none); NULL when the argument
 * names no simulation (a model path or builtin:NAME). */
const view_sim* view_sim_find(const char* arg, const char** spec);
/* The simulation kinds in order (NULL past the last), for the help. */
const view_sim* view_sim_at(size_t index);
/* The keys the help overlay lists: a simulation's own keys, then the viewer's that apply to it
 * (space, f, escape, p, h); sim NULL -> the viewer's keys (view_help). Returns the count. */
size_t view_help_list(const view_sim* sim, const view_help_entry** out, size_t capacity);
/* The terrain plug-in (view_terrain.c). */
extern const view_sim view_terrain_sim;
/* The crowd plug-in (view_crowd.c). */
extern const view_sim view_crowd_sim;
/* The rigid-body plug-in (view_rigid.c). */
extern const view_sim view_rigid_sim;
/* The kinds, for messages ("particles, boids, cloth, terrain"). */
extern const char* const view_sim_kinds;

/* ---- the app ---- */

typedef struct view_options {
    int width, height;    /* window size */
    int clip;             /* first clip to play; -1 -> none */
    int supersample;      /* 1..4 */
    int threads;          /* raster threads */
    bool scripted;        /* fixed time step, deterministic status line */
    FILE* ik_log;         /* NULL -> none */
    const char* shot_dir; /* where P and a script's screenshots write; NULL -> "." */
    const char* script_name; /* the --script file, for messages; NULL -> "script" */
    const view_sim* sim;  /* NULL -> none; else initialised by view_app_init with sim_spec */
    const char* sim_spec;
    view_sim_opts sim_opts;
} view_options;

enum { VIEW_DRAG_NONE = 0, VIEW_DRAG_ORBIT, VIEW_DRAG_PAN, VIEW_DRAG_TARGET, VIEW_DRAG_TIMELINE, VIEW_DRAG_SIM };

/* Frame-time breakdown accumulated over rendered frames (seconds). */
typedef struct view_stats {
    double sample;  /* clip sampling, morph overrides, IK */
    double skin;    /* FK, morph targets, skinning */
    double raster;  /* ground, meshes, overlays, HUD */
    double present; /* handing the image to the window (0 headless) */
    long frames;
} view_stats;

typedef struct view_app {
    const ak_scene* scene;
    view_options opt;
    cli_poser poser;
    cli_frame frame;       /* full-size target */
    cli_frame panel;       /* side-by-side target (width / 3), created on first use */
    ak_image image, panel_image;
    int width, height;
    /* camera: ak_view_orbit_camera on the framed box, shifted by pan, margin scaled by zoom */
    ak_view_orbit orbit;
    ak_vec3 box_lo, box_hi, pan;
    float zoom;
    /* time */
    int clip;
    double time, speed;
    bool playing, loop, bind;
    /* drawing */
    cli_method method;
    bool side_by_side, show_normals, show_skeleton, show_help, show_limits;
    int weight_bone;         /* index into weight_joints, -1 -> off */
    int* weight_joints;      /* joints some skin uses */
    size_t weight_joint_count;
    ak_vec4** colors;        /* per mesh heat colours (NULL entries: clay) */
    /* IK */
    int effector, root;      /* joint indices, -1 -> none */
    ak_ik_solver solver;
    ak_vec3 target;          /* model space */
    int16_t* chain;
    size_t chain_count;
    ak_transform* ik_solved; /* cached chain transforms of the last solve */
    bool ik_valid;           /* the cache matches the inputs below */
    ak_vec3 ik_target_solved;
    double ik_time_solved;
    int ik_clip_solved, ik_solver_solved, ik_root_solved;
    bool ik_bind_solved;
    uint8_t* ik_scratch;
    size_t ik_scratch_size;
    bool ik_reached;
    float ik_error;
    const char* ik_problem; /* why no solve happened (two-bone on a short chain) */
    /* morph weights set by the user (flat index over the scene's meshes) */
    float* morph_user;
    bool* morph_set;
    size_t morph_count;
    int morph_index;
    /* mouse */
    int drag;
    float mouse_x, mouse_y;
    /* status */
    char message[160];
    long message_frames;
    double fps;
    long frame_index;
    int shot_count;
    view_stats stats;
    bool quit;
    int exit_code;           /* set with quit when the loop must end with an error */
    /* simulation plug-in (NULL: none) */
    const view_sim* sim;
    void* sim_state;
    ak_vec3 sim_anchor; /* the dragged collider's centre (VIEW_DRAG_SIM) */
} view_app;

int view_app_init(view_app* app, const ak_scene* scene, const view_options* opt);
void view_app_free(view_app* app);
/* Re-create the targets for a new window size (below 8 pixels: kept as they are). On failure
 * prints why and sets quit with exit_code CLI_BAD_INPUT. */
int view_app_resize(view_app* app, int width, int height);
/* Apply one input event (KEY, MOUSE_*, WHEEL). */
void view_app_event(view_app* app, const view_event* ev);
/* Advance time by dt seconds (playing, speed, loop). */
void view_app_advance(view_app* app, double dt);
/* Pose and draw the current state into app->image. */
ak_result view_app_render(view_app* app);
/* Write the current image as PNG. */
int view_app_screenshot(view_app* app, const char* path);
/* A script's `screenshot PATH` (ev): the image written to PATH under the shot directory.
 * A component of PATH that is a symlink (which could lead out of the directory) is refused:
 * exit status 1 with "SCRIPT: line N: ..." on stderr. */
int view_app_script_screenshot(view_app* app, const view_event* ev);
/* Frame the camera on the current pose (key F). */
void view_app_frame_all(view_app* app);

/* What the loop needs from a window; NULL platform -> headless. */
typedef struct view_platform {
    void* user;
    /* Feed pending window events to the app (view_app_event, view_app_resize, app->quit).
     * Returns false while the window is minimised (nothing is drawn then). */
    bool (*poll)(void* user, view_app* app);
    /* Show app->image; returns CLI_OK or an exit code. */
    int (*present)(void* user, const view_app* app);
} view_platform;

/* Run the loop: the script (NULL -> none), or max_frames frames when there is no script and
 * no platform (headless), or until the window closes. Returns an exit code. */
int view_app_run(view_app* app, const view_script* script, long max_frames, const view_platform* platform);

/* The window (view_sdl.c). view_window_available is false in builds without SDL2. */
bool view_window_available(void);
int view_window_run(view_app* app, const view_script* script);

#endif
