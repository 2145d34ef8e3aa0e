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

#include <stdbool.h>
#include <stdio.h>
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

#endif
