/* The Khronos glTF validator (scripts/gltf_validate.js under node, installed into
 * build-tools/node_modules by scripts/install-deps.sh) on files written by a test: include after
 * ak_test.h. */
#ifndef ANIMKIT_TEST_GLTF_VALIDATE_H
#define ANIMKIT_TEST_GLTF_VALIDATE_H

#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>

/* Validates files[0..count): each must report 0 errors and 0 warnings, and each must report
 * (failed checks otherwise; the validator's other lines are printed). what names the files in
 * the messages ("baked files"). Returns false after a SKIP line when node or the validator is
 * absent. */
static inline bool ak_test_gltf_validate(const char* const* files, int count, const char* what) {
    char mod[1024];
    snprintf(mod, sizeof mod, "%s/build-tools/node_modules/gltf-validator", AK_SOURCE_DIR);
    struct stat st;
    if (stat(mod, &st) != 0 || system("node --version >/dev/null 2>&1") != 0) {
        AK_SKIP("glTF validator absent (needs node and %s; scripts/install-deps.sh installs it when npm is "
                "available): %d %s not validated",
                mod, count, what);
        return false;
    }
    AK_CHECK(count > 0);
    size_t cap = 1024 + 2 * strlen(AK_SOURCE_DIR);
    for (int i = 0; i < count; ++i) cap += strlen(files[i]) + 3;
    char* cmd = malloc(cap);
    AK_CHECK(cmd != NULL);
    if (!cmd) return true;
    int o = snprintf(cmd, cap, "NODE_PATH='%s/build-tools/node_modules' node '%s/scripts/gltf_validate.js'",
                     AK_SOURCE_DIR, AK_SOURCE_DIR);
    for (int i = 0; i < count; ++i) o += snprintf(cmd + o, cap - (size_t)o, " '%s'", files[i]);
    snprintf(cmd + o, cap - (size_t)o, " 2>&1");
    FILE* p = popen(cmd, "r");
    free(cmd);
    AK_CHECK(p != NULL);
    if (!p) return true;
    char line[1024];
    int reported = 0;
    while (fgets(line, sizeof line, p)) {
        int errors = -1, warnings = -1;
        if (line[0] != ' ' && sscanf(line, "%d %d", &errors, &warnings) == 2) {
            ++reported;
            AK_CHECK_MSG(errors == 0 && warnings == 0, "validator: %s", line);
        } else {
            printf("%s", line);
        }
    }
    pclose(p);
    AK_CHECK_EQ(reported, count);
    printf("  gltf-validator: %d %s, 0 errors, 0 warnings expected each\n", reported, what);
    return true;
}

#endif
