/* Result strings, version. */
#include <animkit/core.h>

static const char* const result_messages[] = {
#define AK_RESULT_MSG_(name, msg) msg,
    AK_RESULT_LIST(AK_RESULT_MSG_)
#undef AK_RESULT_MSG_
};

static const char* const result_names[] = {
#define AK_RESULT_NAME_(name, msg) "AK_" #name,
    AK_RESULT_LIST(AK_RESULT_NAME_)
#undef AK_RESULT_NAME_
};

const char* ak_result_string(ak_result result) {
    if ((int)result < 0 || result >= AK_RESULT_COUNT) return "unknown result";
    return result_messages[result];
}

const char* ak_result_name(ak_result result) {
    if ((int)result < 0 || result >= AK_RESULT_COUNT) return "AK_UNKNOWN";
    return result_names[result];
}

const char* ak_version_string(void) { return "0.1.0"; }
