/* animkit view --script: input events replayed from a text file, one per line:
 *   key NAME | mouse_down BUTTON X Y | mouse_move X Y | mouse_up BUTTON X Y | wheel DY |
 *   wait FRAMES | screenshot PATH | quit
 * Blank lines and lines starting with '#' are skipped. BUTTON is left, middle or right (or
 * 1, 2, 3). Numbers are strict (the whole token, finite). A screenshot PATH is relative to the
 * shot directory and stays inside it: not absolute, no ".." component (the viewer also
 * refuses a symlink on the way when it writes, view_app.c). */
#include <stdlib.h>
#include <string.h>

#include "view_app.h"

#define MAX_TOKENS 5

static const struct {
    const char* name;
    int key;
} named_keys[] = {
    {"space", ' '},           {"tab", '\t'},          {"escape", VIEW_KEY_ESCAPE}, {"left", VIEW_KEY_LEFT},
    {"right", VIEW_KEY_RIGHT}, {"up", VIEW_KEY_UP},   {"down", VIEW_KEY_DOWN},     {"leftbracket", '['},
    {"rightbracket", ']'},
};

const char* view_key_name(int key) {
    static const char single[] = "abcdefghijklmnopqrstuvwxyz0123456789";
    for (size_t i = 0; i < sizeof named_keys / sizeof named_keys[0]; ++i)
        if (named_keys[i].key == key) return named_keys[i].name;
    const char* p = key > 0 && key < 128 ? strchr(single, key) : NULL;
    if (!p) return NULL;
    /* a pointer into a constant table of one-character strings */
    static const char* const one[] = {"a", "b", "c", "d", "e", "f", "g", "h", "i", "j", "k", "l",
                                      "m", "n", "o", "p", "q", "r", "s", "t", "u", "v", "w", "x",
                                      "y", "z", "0", "1", "2", "3", "4", "5", "6", "7", "8", "9"};
    return one[p - single];
}

int view_key_parse(const char* name) {
    for (size_t i = 0; i < sizeof named_keys / sizeof named_keys[0]; ++i)
        if (strcmp(named_keys[i].name, name) == 0) return named_keys[i].key;
    if (strlen(name) == 1) {
        char c = name[0];
        if (c >= 'A' && c <= 'Z') c = (char)(c - 'A' + 'a');
        if ((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9')) return c;
        if (c == '[' || c == ']') return c;
    }
    return 0;
}

static int parse_button(const char* s) {
    if (strcmp(s, "left") == 0 || strcmp(s, "1") == 0) return VIEW_BUTTON_LEFT;
    if (strcmp(s, "middle") == 0 || strcmp(s, "2") == 0) return VIEW_BUTTON_MIDDLE;
    if (strcmp(s, "right") == 0 || strcmp(s, "3") == 0) return VIEW_BUTTON_RIGHT;
    return 0;
}

/* Pixel coordinate: finite and within +-1e6. */
static bool parse_coord(const char* s, float* out) { return cli_parse_float(s, out) && *out >= -1e6f && *out <= 1e6f; }

void view_script_free(view_script* s) {
    free(s->text);
    free(s->events);
    memset(s, 0, sizeof(*s));
}

/* Relative, without a ".." component: a path that stays inside the directory it is joined to
 * (as far as the text goes; symlinks are the writer's check). */
static bool path_stays_inside(const char* path) {
    if (path[0] == '/') return false;
    for (const char* c = path; *c;) {
        const char* end = strchr(c, '/');
        size_t n = end ? (size_t)(end - c) : strlen(c);
        if (n == 2 && c[0] == '.' && c[1] == '.') return false;
        c += n;
        if (*c == '/') ++c;
    }
    return true;
}

static int bad(char* err, size_t n, int line, const char* what, const char* tok) {
    snprintf(err, n, "line %d: %s%s%s%s", line, what, tok ? " '" : "", tok ? tok : "", tok ? "'" : "");
    return CLI_BAD_USAGE;
}

int view_script_parse(const char* text, size_t size, view_script* out, char* err, size_t err_size) {
    memset(out, 0, sizeof(*out));
    size_t lines = 1;
    for (size_t i = 0; i < size; ++i) lines += text[i] == '\n';
    out->text = malloc(size + 1);
    out->events = calloc(lines, sizeof(view_event));
    if (!out->text || !out->events) {
        view_script_free(out);
        snprintf(err, err_size, "out of memory");
        return CLI_BAD_INPUT;
    }
    memcpy(out->text, text, size);
    out->text[size] = '\0';
    const char* nul = memchr(text, '\0', size);
    if (nul) {
        int line = 1;
        for (const char* c = text; c < nul; ++c) line += *c == '\n';
        view_script_free(out);
        return bad(err, err_size, line, "contains a NUL byte", NULL);
    }
    char* p = out->text;
    int rc = CLI_OK;
    for (int line = 1; p && rc == CLI_OK; ++line) {
        char* next = strchr(p, '\n');
        if (next) *next++ = '\0';
        char* tok[MAX_TOKENS + 1];
        int n = 0;
        for (char* s = p; *s;) {
            while (*s == ' ' || *s == '\t' || *s == '\r') *s++ = '\0';
            if (!*s) break;
            if (n == MAX_TOKENS + 1) {
                ++n;
                break;
            }
            tok[n++] = s;
            while (*s && *s != ' ' && *s != '\t' && *s != '\r') ++s;
        }
        p = next;
        if (n == 0 || tok[0][0] == '#') continue;
        if (n > MAX_TOKENS) {
            rc = bad(err, err_size, line, "too many words", NULL);
            break;
        }
        view_event ev = {.line = line};
        const char* cmd = tok[0];
        int want = -1;
        if (strcmp(cmd, "key") == 0) {
            want = 2;
            ev.type = VIEW_EV_KEY;
            if (n == want && !(ev.key = view_key_parse(tok[1]))) rc = bad(err, err_size, line, "unknown key", tok[1]);
        } else if (strcmp(cmd, "mouse_down") == 0 || strcmp(cmd, "mouse_up") == 0) {
            want = 4;
            ev.type = cmd[6] == 'd' ? VIEW_EV_MOUSE_DOWN : VIEW_EV_MOUSE_UP;
            if (n == want) {
                if (!(ev.button = parse_button(tok[1]))) rc = bad(err, err_size, line, "unknown mouse button", tok[1]);
                else if (!parse_coord(tok[2], &ev.x)) rc = bad(err, err_size, line, "bad X", tok[2]);
                else if (!parse_coord(tok[3], &ev.y)) rc = bad(err, err_size, line, "bad Y", tok[3]);
            }
        } else if (strcmp(cmd, "mouse_move") == 0) {
            want = 3;
            ev.type = VIEW_EV_MOUSE_MOVE;
            if (n == want) {
                if (!parse_coord(tok[1], &ev.x)) rc = bad(err, err_size, line, "bad X", tok[1]);
                else if (!parse_coord(tok[2], &ev.y)) rc = bad(err, err_size, line, "bad Y", tok[2]);
            }
        } else if (strcmp(cmd, "wheel") == 0) {
            want = 2;
            ev.type = VIEW_EV_WHEEL;
            if (n == want && (!cli_parse_float(tok[1], &ev.dy) || ev.dy < -1000 || ev.dy > 1000))
                rc = bad(err, err_size, line, "bad wheel amount (a number in [-1000, 1000])", tok[1]);
        } else if (strcmp(cmd, "wait") == 0) {
            want = 2;
            ev.type = VIEW_EV_WAIT;
            if (n == want && !cli_parse_int(tok[1], 0, 1000000, &ev.frames))
                rc = bad(err, err_size, line, "bad frame count (a whole number in [0, 1000000])", tok[1]);
        } else if (strcmp(cmd, "screenshot") == 0) {
            want = 2;
            ev.type = VIEW_EV_SCREENSHOT;
            ev.path = n == want ? tok[1] : NULL;
            if (n == want && !cli_has_ext(tok[1], ".png")) rc = bad(err, err_size, line, "screenshot path must end in .png", tok[1]);
            else if (n == want && !path_stays_inside(tok[1]))
                rc = bad(err, err_size, line,
                         "screenshot path must stay inside the shot directory (--shot-dir, default .): "
                         "no absolute path, no '..'",
                         tok[1]);
        } else if (strcmp(cmd, "quit") == 0) {
            want = 1;
            ev.type = VIEW_EV_QUIT;
        } else {
            rc = bad(err, err_size, line, "unknown command", cmd);
        }
        if (rc == CLI_OK && n != want) {
            char what[64];
            snprintf(what, sizeof what, "'%s' takes %d argument%s, not %d", cmd, want - 1, want == 2 ? "" : "s", n - 1);
            rc = bad(err, err_size, line, what, NULL);
        }
        if (rc == CLI_OK) out->events[out->count++] = ev;
    }
    if (rc != CLI_OK) view_script_free(out);
    return rc;
}
