/* libFuzzer target for `animkit ik` argument parsing and everything it drives (option
 * parsing, numbers, joint and clip lookup, the default chain, every solver, --json output).
 *
 * The input is the argument list, one argument per line (a NUL also ends one); the target
 * runs `animkit ik builtin:cylinder ARGS...` in process through cmd_ik. scripts/fuzz.sh
 * builds it with the whole library and the CLI's sources except main.c, and runs it:
 *     scripts/fuzz.sh 60 cli_ik      (seeds: tests/fuzz/cli_ik.seeds, dictionary cli_ik.dict)
 * The model is fixed (a positional argument from the input is a usage error), and arguments
 * naming an output (-o, --output, with or without =value) are dropped, so a run never reads
 * or writes files. stdout goes to /dev/null. Any crash, leak or sanitizer report is a bug;
 * exit codes 0, 1 and 2 are all fine. */
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "cli.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);
int LLVMFuzzerInitialize(int* argc, char*** argv);

enum { MAX_ARGS = 32, MAX_TEXT = 4096 };

int LLVMFuzzerInitialize(int* argc, char*** argv) {
    (void)argc, (void)argv;
    if (!freopen("/dev/null", "w", stdout)) return 0;
    return 0;
}

static int drop(const char* a) { return strncmp(a, "-o", 2) == 0 || strncmp(a, "--output", 8) == 0; }

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static char text[MAX_TEXT + 1];
    char* argv[MAX_ARGS + 3];
    int argc = 0;
    if (size > MAX_TEXT) size = MAX_TEXT;
    memcpy(text, data, size);
    text[size] = '\0';
    argv[argc++] = "builtin:cylinder";
    for (char* p = text; p < text + size && argc < MAX_ARGS + 1;) {
        char* end = p;
        while (end < text + size && *end != '\n' && *end != '\0') ++end;
        *end = '\0';
        if (!drop(p)) argv[argc++] = p;
        p = end + 1;
    }
    argv[argc] = NULL;
    (void)cmd_ik(argc, argv);
    return 0;
}
