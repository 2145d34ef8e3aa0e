/* libFuzzer harness for the web build's JSON parser (web/cjson.c: the part of cJSON's API the
 * WebAssembly page links instead of Debian's libcjson, docs/web.md), built natively by
 * scripts/fuzz.sh. web/cjson.c is compiled into this target, so its definitions take the place
 * of libcjson's for the whole process (the executable's symbols come first).
 *
 * Each input is parsed with a length (as src/json.c and the glTF reader call it). A parse that
 * succeeds must print (compact and indented), and the compact text must parse again to a tree
 * that prints to the same compact text (printing is a fixed point); the end pointer must lie in
 * the input. Any crash, leak or sanitizer report is a bug. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "../../web/cjson.c"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const char* text = (const char*)data;
    const char* end = NULL;
    cJSON* root = cJSON_ParseWithLengthOpts(text, size, &end, 0);
    if (!end || end < text || end > text + size) abort();
    if (!root) return 0;
    char* compact = cJSON_PrintUnformatted(root);
    char* pretty = cJSON_Print(root);
    if (!compact || !pretty) abort(); /* only out of memory may fail, and inputs are small */
    cJSON* again = cJSON_ParseWithLengthOpts(compact, strlen(compact), &end, 0);
    if (!again) abort();
    char* compact2 = cJSON_PrintUnformatted(again);
    if (!compact2 || strcmp(compact, compact2) != 0) abort();
    cJSON* again_pretty = cJSON_ParseWithLengthOpts(pretty, strlen(pretty), &end, 0);
    if (!again_pretty) abort();
    char* compact3 = cJSON_PrintUnformatted(again_pretty);
    if (!compact3 || strcmp(compact, compact3) != 0) abort();
    free(compact3);
    cJSON_Delete(again_pretty);
    free(compact2);
    cJSON_Delete(again);
    free(pretty);
    free(compact);
    cJSON_Delete(root);
    return 0;
}
