/* libFuzzer harness for `animkit view --script` (tools/animkit/view_script.c), built by
 * scripts/fuzz.sh with the library and every tools/animkit source except main.c.
 *
 * Each input is parsed as a script; a parse must either fail with CLI_BAD_USAGE and an error
 * naming a line ("line N: ..."), or succeed with events whose fields are in range (known key,
 * button 1..3, finite coordinates, wait 0..1e6, a .png screenshot path inside the text that
 * stays inside the shot directory: relative, no ".." component). Any crash, leak or sanitizer
 * report is a bug. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "view_app.h" /* tools/animkit, on the include path of scripts/fuzz.sh */

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

/* An independent check of the parser's rule: absolute, or a ".." component anywhere. */
static bool leaves_dir(const char* p) {
    if (p[0] == '/') return true;
    for (const char* c = p; (c = strstr(c, "..")); ++c)
        if ((c == p || c[-1] == '/') && (c[2] == '\0' || c[2] == '/')) return true;
    return false;
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    view_script s;
    char err[256];
    int rc = view_script_parse((const char*)data, size, &s, err, sizeof err);
    if (rc == CLI_BAD_USAGE) {
        if (strncmp(err, "line ", 5) != 0) abort();
        return 0;
    }
    if (rc != CLI_OK) return 0; /* out of memory */
    for (size_t i = 0; i < s.count; ++i) {
        const view_event* e = &s.events[i];
        switch (e->type) {
        case VIEW_EV_KEY:
            if (!view_key_name(e->key)) abort();
            break;
        case VIEW_EV_MOUSE_DOWN:
        case VIEW_EV_MOUSE_UP:
            if (e->button < 1 || e->button > 3) abort();
            /* fall through */
        case VIEW_EV_MOUSE_MOVE:
            if (!(e->x >= -1e6f && e->x <= 1e6f && e->y >= -1e6f && e->y <= 1e6f)) abort();
            break;
        case VIEW_EV_WHEEL:
            if (!(e->dy >= -1000.0f && e->dy <= 1000.0f)) abort();
            break;
        case VIEW_EV_WAIT:
            if (e->frames < 0 || e->frames > 1000000) abort();
            break;
        case VIEW_EV_SCREENSHOT:
            if (!e->path || e->path < s.text || e->path >= s.text + size || !cli_has_ext(e->path, ".png")) abort();
            if (leaves_dir(e->path)) abort();
            break;
        default: break;
        }
    }
    view_script_free(&s);
    return 0;
}
