/* animkit view: the SDL2 window. Built with SDL2 when CMake finds it (AK_HAVE_SDL2); without
 * it view_window_available() is false and `animkit view` needs --headless. The image is
 * animkit's own software rasterizer output, copied to the window surface each frame. */
#include "view_app.h"

#ifdef AK_HAVE_SDL2
#include <SDL.h>
#include <stdlib.h> /* getenv */
#include <string.h>

typedef struct sdl_window {
    SDL_Window* window;
    bool minimised;
    double last_present; /* cli_now() of the last present, for the 60 fps cap */
} sdl_window;

static int map_key(SDL_Keycode k) {
    switch (k) {
    case SDLK_ESCAPE: return VIEW_KEY_ESCAPE;
    case SDLK_LEFT: return VIEW_KEY_LEFT;
    case SDLK_RIGHT: return VIEW_KEY_RIGHT;
    case SDLK_UP: return VIEW_KEY_UP;
    case SDLK_DOWN: return VIEW_KEY_DOWN;
    case SDLK_SPACE: return ' ';
    case SDLK_TAB: return '\t';
    case SDLK_LEFTBRACKET: return '[';
    case SDLK_RIGHTBRACKET: return ']';
    default: break;
    }
    if ((k >= SDLK_a && k <= SDLK_z) || (k >= SDLK_0 && k <= SDLK_9)) return (int)k;
    return 0;
}

static int map_button(Uint8 b) {
    return b == SDL_BUTTON_LEFT ? VIEW_BUTTON_LEFT : b == SDL_BUTTON_MIDDLE ? VIEW_BUTTON_MIDDLE : b == SDL_BUTTON_RIGHT ? VIEW_BUTTON_RIGHT : 0;
}

static bool sdl_poll(void* user, view_app* a) {
    sdl_window* w = user;
    SDL_Event e;
    /* live (not scripted): at most 60 frames a second, so an idle viewer leaves the CPU alone */
    double since = cli_now() - w->last_present;
    if (!a->opt.scripted && since >= 0.0 && since < 1.0 / 60.0) SDL_Delay((Uint32)((1.0 / 60.0 - since) * 1000.0));
    /* minimised: sleep in the event queue instead of drawing */
    if (w->minimised && SDL_WaitEventTimeout(NULL, 100) == 0) return false;
    while (SDL_PollEvent(&e)) {
        view_event ev = {.type = VIEW_EV_KEY};
        switch (e.type) {
        case SDL_QUIT: a->quit = true; break;
        case SDL_WINDOWEVENT:
            if (e.window.event == SDL_WINDOWEVENT_MINIMIZED || e.window.event == SDL_WINDOWEVENT_HIDDEN) w->minimised = true;
            else if (e.window.event == SDL_WINDOWEVENT_RESTORED || e.window.event == SDL_WINDOWEVENT_SHOWN ||
                     e.window.event == SDL_WINDOWEVENT_EXPOSED)
                w->minimised = false;
            else if (e.window.event == SDL_WINDOWEVENT_SIZE_CHANGED) {
                w->minimised = false;
                view_app_resize(a, e.window.data1, e.window.data2); /* sets quit on failure */
            }
            break;
        case SDL_KEYDOWN:
            if ((ev.key = map_key(e.key.keysym.sym))) view_app_event(a, &ev);
            break;
        case SDL_MOUSEBUTTONDOWN:
        case SDL_MOUSEBUTTONUP:
            ev.type = e.type == SDL_MOUSEBUTTONDOWN ? VIEW_EV_MOUSE_DOWN : VIEW_EV_MOUSE_UP;
            ev.button = map_button(e.button.button);
            ev.x = (float)e.button.x;
            ev.y = (float)e.button.y;
            ev.shift = (SDL_GetModState() & KMOD_SHIFT) != 0;
            if (ev.button) view_app_event(a, &ev);
            break;
        case SDL_MOUSEMOTION:
            ev.type = VIEW_EV_MOUSE_MOVE;
            ev.x = (float)e.motion.x;
            ev.y = (float)e.motion.y;
            view_app_event(a, &ev);
            break;
        case SDL_MOUSEWHEEL:
            ev.type = VIEW_EV_WHEEL;
            ev.dy = (float)e.wheel.y;
            view_app_event(a, &ev);
            break;
        default: break;
        }
    }
    return !w->minimised;
}

/* The frame goes to the window surface (converted from RGBA8 to its format): no renderer, so
 * no GL context on machines whose only GL is a software one (Xvfb, llvmpipe). */
static int sdl_present(void* user, const view_app* a) {
    sdl_window* w = user;
    SDL_Surface* surf = SDL_GetWindowSurface(w->window); /* re-fetched: a resize invalidates it */
    if (!surf) return cli_fail("view", "cannot draw into the window: %s", SDL_GetError());
    int cw = surf->w < a->width ? surf->w : a->width, ch = surf->h < a->height ? surf->h : a->height;
    if (SDL_MUSTLOCK(surf) && SDL_LockSurface(surf) != 0) return cli_fail("view", "cannot lock the window: %s", SDL_GetError());
    int r = SDL_ConvertPixels(cw, ch, SDL_PIXELFORMAT_RGBA32, a->image.pixels, a->width * 4, surf->format->format, surf->pixels,
                              surf->pitch);
    if (SDL_MUSTLOCK(surf)) SDL_UnlockSurface(surf);
    if (r != 0 || SDL_UpdateWindowSurface(w->window) != 0)
        return cli_fail("view", "cannot update the window: %s", SDL_GetError());
    w->last_present = cli_now();
    return CLI_OK;
}

bool view_window_available(void) { return true; }

int view_window_run(view_app* a, const view_script* script) {
    /* Without a display SDL falls back to a driver that draws nowhere (after printing its own
     * complaint about XDG_RUNTIME_DIR), and the viewer ran forever with no window. A user who
     * wants such a driver names it in SDL_VIDEODRIVER. */
    const char* x11 = getenv("DISPLAY");
    const char* wl = getenv("WAYLAND_DISPLAY");
    const char* drv = getenv("SDL_VIDEODRIVER");
    if ((!x11 || !*x11) && (!wl || !*wl) && (!drv || !*drv))
        return cli_fail("view", "no display (DISPLAY and WAYLAND_DISPLAY are not set): use --headless, or set "
                        "SDL_VIDEODRIVER to choose a video driver");
    if (SDL_Init(SDL_INIT_VIDEO) != 0)
        return cli_fail("view", "cannot open a window (%s); use --headless where there is no display", SDL_GetError());
    sdl_window w = {0};
    int rc = CLI_OK;
    char title[300];
    snprintf(title, sizeof title, "animkit view - %s", a->scene->name);
    const char* cur = SDL_GetCurrentVideoDriver();
    if (cur && (!drv || !*drv) && (strcmp(cur, "offscreen") == 0 || strcmp(cur, "dummy") == 0)) {
        SDL_Quit();
        return cli_fail("view", "no display (SDL found only its '%s' video driver): use --headless", cur);
    }
    w.window = SDL_CreateWindow(title, SDL_WINDOWPOS_UNDEFINED, SDL_WINDOWPOS_UNDEFINED, a->width, a->height,
                                SDL_WINDOW_RESIZABLE);
    if (!w.window) {
        rc = cli_fail("view", "cannot open a window (%s); use --headless where there is no display", SDL_GetError());
    } else {
        view_platform pl = {.user = &w, .poll = sdl_poll, .present = sdl_present};
        rc = view_app_run(a, script, 0, &pl);
    }
    if (w.window) SDL_DestroyWindow(w.window);
    SDL_Quit();
    return rc;
}

#else

bool view_window_available(void) { return false; }

int view_window_run(view_app* a, const view_script* script) {
    (void)a;
    (void)script;
    return cli_fail("view", "this build has no window (SDL2 was not found); use --headless");
}

#endif
