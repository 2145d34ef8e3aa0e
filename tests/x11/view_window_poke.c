/* An X11 client that does to `animkit view`'s window what a user and a window manager do:
 * resize it, unmap it (minimise) and map it again, resize it once more, then close it with
 * WM_DELETE_WINDOW (the title bar's close button). Run by view_window.sh under Xvfb.
 *
 *     view_window_poke            exit 0 when every request was sent, 1 when no window showed
 *
 * It finds the first window whose name starts with "animkit" (waiting up to 60 s for the viewer
 * to open it). The checks are the viewer's: it must keep running through the events, draw at the
 * new size and exit 0 on close (view_window.sh reads its --stats line). */
#include <X11/Xlib.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

static void pause_ms(long ms) {
    struct timespec ts = {ms / 1000, (ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

/* Depth-first search of the window tree for a name starting with "animkit". */
static Window find_viewer(Display* d, Window w, int depth) {
    char* name = NULL;
    if (XFetchName(d, w, &name) && name) {
        const int match = strncmp(name, "animkit", 7) == 0;
        XFree(name);
        if (match) return w;
    }
    if (depth > 8) return 0;
    Window root, parent, *kids = NULL;
    unsigned n = 0;
    if (!XQueryTree(d, w, &root, &parent, &kids, &n)) return 0;
    Window found = 0;
    for (unsigned i = 0; i < n && !found; ++i) found = find_viewer(d, kids[i], depth + 1);
    if (kids) XFree(kids);
    return found;
}

static Window wait_for_viewer(Display* d) {
    for (int i = 0; i < 600; ++i) {
        Window w = find_viewer(d, DefaultRootWindow(d), 0);
        if (w) return w;
        pause_ms(100);
    }
    return 0;
}

int main(void) {
    Display* d = XOpenDisplay(NULL);
    if (!d) {
        fprintf(stderr, "view_window_poke: cannot open the display\n");
        return 1;
    }
    Window w = wait_for_viewer(d);
    if (w) {
        pause_ms(2000); /* let it draw a few frames; SDL may replace its first window */
        w = wait_for_viewer(d);
    }
    if (!w) {
        fprintf(stderr, "view_window_poke: no window named animkit* within 60 s\n");
        XCloseDisplay(d);
        return 1;
    }
    XResizeWindow(d, w, 640, 360);
    XFlush(d);
    pause_ms(1000);
    XUnmapWindow(d, w);
    XFlush(d);
    pause_ms(1000);
    XMapWindow(d, w);
    XFlush(d);
    pause_ms(1000);
    XResizeWindow(d, w, 300, 200);
    XFlush(d);
    pause_ms(1500);
    XEvent e;
    memset(&e, 0, sizeof e);
    e.xclient.type = ClientMessage;
    e.xclient.window = w;
    e.xclient.message_type = XInternAtom(d, "WM_PROTOCOLS", False);
    e.xclient.format = 32;
    e.xclient.data.l[0] = (long)XInternAtom(d, "WM_DELETE_WINDOW", False);
    e.xclient.data.l[1] = CurrentTime;
    XSendEvent(d, w, False, NoEventMask, &e);
    XFlush(d);
    printf("view_window_poke: resized, unmapped, mapped, resized and closed window 0x%lx\n", (unsigned long)w);
    XCloseDisplay(d);
    return 0;
}
