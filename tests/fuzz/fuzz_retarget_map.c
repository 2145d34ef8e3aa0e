/* libFuzzer harness for retarget map files (ak_retarget_map_parse, src/retarget.c), the parser
 * behind `animkit retarget --map FILE`; built by scripts/fuzz.sh with the library.
 *
 * Each input is parsed against two small hand-made skeletons (a humanoid-ish source and
 * target whose names overlap). A parse must either fail with a documented code, a message and
 * the map left all -1, or succeed with every entry -1 or a source joint, no more mapped
 * entries than it reports, and a non-zero count. Any crash, leak or sanitizer report is a bug. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <animkit/retarget.h>

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

enum { NS = 6, NT = 5 };

static ak_skeleton* make(const char* const* names, const int* parents, size_t n) {
    ak_joint_desc j[8];
    for (size_t i = 0; i < n; ++i)
        j[i] = (ak_joint_desc){.name = names[i], .parent = parents[i],
                               .rest = ak_transform_make(ak_vec3_make(0, 0.2f, 0), ak_quat_identity(), ak_vec3_make(1, 1, 1))};
    ak_skeleton* s = NULL;
    if (ak_skeleton_create(&(ak_skeleton_desc){.joints = j, .joint_count = n}, NULL, &s, NULL) != AK_OK) abort();
    return s;
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const char* const src_names[NS] = {"Hips", "Spine", "Neck", "Head", "LeftUpLeg", "mixamorig:LeftArm"};
    static const int src_parents[NS] = {-1, 0, 1, 2, 0, 1};
    static const char* const dst_names[NT] = {"pelvis", "spine_01", "neck", "head", "Hips"};
    static const int dst_parents[NT] = {-1, 0, 1, 2, 0};
    ak_skeleton* src = make(src_names, src_parents, NS);
    ak_skeleton* dst = make(dst_names, dst_parents, NT);
    int32_t map[NT];
    size_t mapped = 12345;
    ak_diag diag;
    ak_result r = ak_retarget_map_parse((const char*)data, size, src, dst, (ak_i32_span){map, NT}, &mapped, &diag);
    if (r == AK_OK) {
        size_t n = 0;
        for (size_t k = 0; k < NT; ++k) {
            if (map[k] < -1 || map[k] >= NS) abort();
            n += map[k] >= 0;
        }
        if (mapped == 0 || mapped != n) abort();
    } else {
        if (r != AK_ERR_PARSE && r != AK_ERR_NOT_FOUND && r != AK_ERR_DUPLICATE && r != AK_ERR_EMPTY) abort();
        if (mapped != 0 || !diag.message[0] || diag.line < 0) abort();
        if ((r == AK_ERR_EMPTY) != (diag.line == 0)) abort();
        for (size_t k = 0; k < NT; ++k)
            if (map[k] != -1) abort();
    }
    ak_skeleton_destroy(src);
    ak_skeleton_destroy(dst);
    return 0;
}
