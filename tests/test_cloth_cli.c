/* The animkit cloth command: exit codes, the --json contract, and properties of the output
 * checked independently (max_stretch recomputed from the positions, no particle inside the
 * drape's sphere or floor, pinned particles at their rest positions). */
#include <animkit/animkit.h>
#include <cjson/cJSON.h>

#include "ak_test.h"
#include "cli_test.h"

/* positions[k] of a parsed output */
static ak_vec3 pos(const cJSON* ps, int k) {
    const cJSON* p = cJSON_GetArrayItem(ps, k);
    return ak_vec3_make((float)cJSON_GetArrayItem(p, 0)->valuedouble, (float)cJSON_GetArrayItem(p, 1)->valuedouble,
                        (float)cJSON_GetArrayItem(p, 2)->valuedouble);
}

AK_TEST(usage) {
    AK_CHECK_EQ(run("cloth --help", true), 0);
    AK_CHECK(strstr(out_buf, "usage: animkit cloth") != NULL);
    AK_CHECK_EQ(run("help cloth", true), 0);
    AK_CHECK_EQ(run("cloth", true), 2);
    AK_CHECK_EQ(run("cloth --preset nope", true), 2);
    AK_CHECK_EQ(run("cloth --preset flag --solver verlet", true), 2);
    AK_CHECK_EQ(run("cloth --preset flag --steps -3", true), 2);
    AK_CHECK_EQ(run("cloth --preset flag -o out.txt", true), 2);
    AK_CHECK_EQ(run("cloth --preset flag x.json", true), 2);
}

/* The implicit solver by flag and by scene key; the spring solver picks its stable substep count
 * (dt / (0.9 h)) and says so, unless --substeps is given. */
AK_TEST(solvers) {
    AK_CHECK_EQ(run("cloth --preset flag --solver implicit --steps 3", true), 0);
    AK_CHECK(strstr(out_buf, "implicit Euler") != NULL);
    write_file("implicit.json", "{\"solver\": \"implicit\", \"steps\": 3}");
    AK_CHECK_EQ(run("cloth implicit.json", true), 0);
    AK_CHECK(strstr(out_buf, "implicit Euler") != NULL);
    AK_CHECK_EQ(run("cloth --preset flag --solver springs --steps 2", true), 0);
    AK_CHECK(strstr(out_buf, "153 substeps per step instead of 10") != NULL);
    AK_CHECK_EQ(run("cloth --preset flag --solver springs --steps 2 --substeps 200", true), 0);
    AK_CHECK(strstr(out_buf, "instead of") == NULL && strstr(out_buf, "(200 substeps)") != NULL);
}

AK_TEST(drape_json_contract) {
    AK_CHECK_EQ(run("cloth --preset drape --steps 60 --threads 2 --json drape.json", true), 0);
    cJSON* j = read_json("drape.json");
    AK_CHECK(j != NULL);
    if (!j) return;
    int keys = 0;
    for (const cJSON* c = j->child; c; c = c->next) ++keys;
    AK_CHECK_EQ(keys, 4);
    const cJSON* t = cJSON_GetObjectItemCaseSensitive(j, "time");
    const cJSON* ps = cJSON_GetObjectItemCaseSensitive(j, "positions");
    const cJSON* ms = cJSON_GetObjectItemCaseSensitive(j, "max_stretch");
    const cJSON* e = cJSON_GetObjectItemCaseSensitive(j, "energy");
    AK_CHECK(cJSON_IsNumber(t) && cJSON_IsArray(ps) && cJSON_IsNumber(ms) && cJSON_IsNumber(e));
    if (!cJSON_IsArray(ps) || !cJSON_IsNumber(ms)) {
        cJSON_Delete(j);
        return;
    }
    AK_CHECK_NEAR(t->valuedouble, 1.0, 1e-4);
    AK_CHECK_EQ(cJSON_GetArraySize(ps), 32 * 32);
    /* max stretch over rows and columns, recomputed; nothing inside the sphere or the floor */
    const double rest = 1.0 / 31.0;
    double worst = 0.0;
    int inside = 0;
    for (int jj = 0; jj < 32; ++jj)
        for (int i = 0; i < 32; ++i) {
            const ak_vec3 p = pos(ps, jj * 32 + i);
            if (ak_vec3_distance(p, ak_vec3_make(0, 0.5f, 0)) < 0.3f || p.y < 0.0f) ++inside;
            if (i + 1 < 32) worst = fmax(worst, ak_vec3_distance(p, pos(ps, jj * 32 + i + 1)) / rest - 1.0);
            if (jj + 1 < 32) worst = fmax(worst, ak_vec3_distance(p, pos(ps, (jj + 1) * 32 + i)) / rest - 1.0);
        }
    AK_CHECK_EQ(inside, 0);
    AK_CHECK_NEAR(ms->valuedouble, worst, 1e-5);
    AK_CHECK(isfinite(e->valuedouble));
    cJSON_Delete(j);
}

AK_TEST(flag_pins_and_outputs) {
    AK_CHECK_EQ(run("cloth --preset flag --steps 30 --substeps 5 --json flag.json -o flag.obj", true), 0);
    cJSON* j = read_json("flag.json");
    AK_CHECK(j != NULL);
    if (j) {
        const cJSON* ps = cJSON_GetObjectItemCaseSensitive(j, "positions");
        for (int k = 0; k < 20; ++k) { /* the pole edge: particle (0, k) at (0, 2 - 0.05 k, 0) */
            const ak_vec3 p = pos(ps, k * 32);
            AK_CHECK_NEAR(p.x, 0.0f, 1e-7f);
            AK_CHECK_NEAR(p.y, 2.0f - 0.05f * (float)k, 1e-6f);
        }
        cJSON_Delete(j);
    }
    FILE* f = fopen("flag.obj", "r");
    AK_CHECK(f != NULL);
    if (f) {
        int v = 0, vn = 0, faces = 0;
        char line[256];
        while (fgets(line, sizeof line, f)) {
            v += strncmp(line, "v ", 2) == 0;
            vn += strncmp(line, "vn ", 3) == 0;
            faces += strncmp(line, "f ", 2) == 0;
        }
        fclose(f);
        AK_CHECK_EQ(v, 640);
        AK_CHECK_EQ(vn, 640);
        AK_CHECK_EQ(faces, 31 * 19 * 2);
    }
}

AK_TEST(bad_scenes_and_blow_up) {
    const struct {
        const char* text;
        const char* needle;
    } cases[] = {
        {"{\"grid\": {\"width\": 1}}", "grid.width"},
        {"{\"pins\": [0, 400]}", "pins[1]"},
        {"{\"material\": {\"stiffness\": 3}}", "unknown key \"stiffness\""},
        {"{\"colliders\": {\"spheres\": [{\"radius\": -1}]}}", "colliders.spheres[0].radius"},
        {"{\"solver\": \"verlet\"}", "solver"},
        {"{\"attachments\": [{\"vertex\": 0, \"joint\": \"spine_02\"}]}", "character"},
        {"{\"character\": {\"model\": \"builtin:humanoid\"}, \"attachments\": [{\"vertex\": 0, \"joint\": \"tail\"}]}",
         "attachments[0].joint"},
        {"{\"dt\": 0.01,", "invalid JSON"},
        {"{\"pins\": [0], \"pin_positions\": [[0, 0, 0], [1, 1, 1]]}", "pin_positions"},
        {"{\"pins\": [0], \"pin_positions\": [[0, 0]]}", "pin_positions[0]"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        write_file("bad.json", cases[k].text);
        AK_CHECK_MSG(run("cloth bad.json --steps 1", true) == 1 && strstr(out_buf, cases[k].needle) && strstr(out_buf, "bad.json"),
                     "case %zu: %s", k, out_buf);
    }
    AK_CHECK_EQ(run("cloth missing.json", true), 1);
    /* the spring solver with a tenth of the step it needs: a blow-up, named by its step, and
     * no JSON written */
    remove("blow.json");
    AK_CHECK_EQ(run("cloth --preset drape --solver springs --substeps 1 --steps 100 --json blow.json", true), 1);
    AK_CHECK(strstr(out_buf, "blow-up") && strstr(out_buf, "at step"));
    AK_CHECK(fopen("blow.json", "r") == NULL);
}

int main(void) {
    AK_RUN(usage);
    AK_RUN(solvers);
    AK_RUN(drape_json_contract);
    AK_RUN(flag_pins_and_outputs);
    AK_RUN(bad_scenes_and_blow_up);
    return ak_test_finish();
}
