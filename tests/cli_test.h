/* Helpers for the tests that run the animkit executable (tests/test_*_cli.c, test_cli*.c):
 * run a command line and capture what it prints, write a small input file, read an output
 * file back. Include after ak_test.h (and after <cjson/cJSON.h> for read_json).
 *
 *     AK_CHECK_EQ(run("particles --frames 0", true), 2);   // exit status, output in out_buf
 *     AK_CHECK(strstr(out_buf, "--frames") != NULL);
 *
 * AK_CLI_PATH (set by tests/CMakeLists.txt) names the executable. out_buf holds
 * CLI_TEST_OUT_SIZE - 1 bytes at most (define it before the include for more); longer output
 * is cut there. Single-threaded: the buffers are static. */
#ifndef ANIMKIT_CLI_TEST_H
#define ANIMKIT_CLI_TEST_H

#include <animkit/animkit.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#ifndef AK_CLI_PATH
#error "AK_CLI_PATH must name the animkit executable"
#endif

#ifndef CLI_TEST_OUT_SIZE
#define CLI_TEST_OUT_SIZE (1 << 20)
#endif

/* What the last run() printed, NUL-terminated. */
static char out_buf[CLI_TEST_OUT_SIZE];

/* Run "animkit ARGS" through the shell, capture its stdout in out_buf (stderr appended when
 * merge, discarded otherwise); return the exit status, -1 when it did not exit normally. */
static inline int run(const char* args, bool merge) {
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "%s %s %s", AK_CLI_PATH, args, merge ? "2>&1" : "2>/dev/null");
    FILE* p = popen(cmd, "r");
    if (!p) return -1;
    size_t n = fread(out_buf, 1, sizeof out_buf - 1, p);
    out_buf[n] = '\0';
    int st = pclose(p);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* Write text to path (replacing it); false when it cannot be written. */
static inline bool write_file(const char* path, const char* text) {
    FILE* f = fopen(path, "w");
    if (!f) return false;
    fputs(text, f);
    return fclose(f) == 0;
}

/* The first 1 MiB - 1 bytes of a file, NUL-terminated, in a static buffer that the next call
 * reuses; NULL when it cannot be opened. */
static inline char* read_file(const char* path) {
    static char buf[1 << 20];
    FILE* f = fopen(path, "rb");
    if (!f) return NULL;
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = '\0';
    fclose(f);
    return buf;
}

#ifdef cJSON__h
/* A JSON file parsed (the caller deletes it); NULL when absent or invalid. */
static inline cJSON* read_json(const char* path) {
    const char* text = read_file(path);
    return text ? cJSON_Parse(text) : NULL;
}
#endif

/* Two same-size renders of a crowd: *people_a and *people_b count each one's saturated pixels
 * (the people: ground, grid, sky and walls are greys and a pale blue), *differ the pixels
 * where a channel differs by more than 64. */
static inline void crowd_people_pixels(const ak_image* a, const ak_image* b, size_t* people_a, size_t* people_b,
                                       size_t* differ) {
    *people_a = *people_b = *differ = 0;
    const size_t n = (size_t)a->width * (size_t)a->height;
    for (size_t i = 0; i < n; ++i) {
        const uint8_t *p = a->pixels + 4 * i, *q = b->pixels + 4 * i;
        int d = 0, lo_a = 255, hi_a = 0, lo_b = 255, hi_b = 0;
        for (int k = 0; k < 3; ++k) {
            d = abs(p[k] - q[k]) > d ? abs(p[k] - q[k]) : d;
            lo_a = p[k] < lo_a ? p[k] : lo_a, hi_a = p[k] > hi_a ? p[k] : hi_a;
            lo_b = q[k] < lo_b ? q[k] : lo_b, hi_b = q[k] > hi_b ? q[k] : hi_b;
        }
        *differ += d > 64;
        *people_a += hi_a - lo_a > 40;
        *people_b += hi_b - lo_b > 40;
    }
}

#endif
