/* `animkit view rigid`, headless with a script: the stack preset (as rigid:preset:stack and as
 * rigid --preset stack) runs the same with and without a right click until the click (the run
 * is deterministic), and a right click left of the stack throws a sphere from the camera that
 * shows up in the picture (the pixels differ from the run without it); the default is the
 * ragdoll preset and it plays; a bad preset exits 2 naming the presets, a missing scene file
 * 1, a scene file and --preset together 2. */
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <animkit/animkit.h>

#include "ak_test.h"
#include "cli_test.h"

#define W 240
#define H 180
#define HUD_TOP 32
#define HUD_BOTTOM 28

static char g_dir[1024];

/* Pixels that differ by more than 8 in a channel between two screenshots, rows [y0, y1). */
static long count_diff(const char* a, const char* b, int y0, int y1) {
    char pa[1200], pb[1200];
    snprintf(pa, sizeof pa, "%s/%s", g_dir, a);
    snprintf(pb, sizeof pb, "%s/%s", g_dir, b);
    ak_image ia = {.width = W, .height = H}, ib = {.width = W, .height = H};
    ia.pixels = calloc((size_t)W * H, 4);
    ib.pixels = calloc((size_t)W * H, 4);
    long n = -1;
    if (ia.pixels && ib.pixels && ak_png_read(pa, &ia) == AK_OK && ak_png_read(pb, &ib) == AK_OK) {
        n = 0;
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < W; ++x) {
                const uint8_t *p = ak_image_pixel(&ia, x, y), *q = ak_image_pixel(&ib, x, y);
                int m = 0;
                for (int c = 0; c < 3; ++c) m = abs(p[c] - q[c]) > m ? abs(p[c] - q[c]) : m;
                n += m > 8;
            }
    }
    free(ia.pixels), free(ib.pixels);
    return n;
}

static int view(const char* spec, const char* script_name, const char* script) {
    char path[1200], args[3000];
    snprintf(path, sizeof path, "%s/%s", g_dir, script_name);
    write_file(path, script);
    snprintf(args, sizeof args, "view %s --headless --size %dx%d --shot-dir '%s' --script '%s'",
             spec, W, H, g_dir, path);
    return run(args, true);
}

AK_TEST(right_click_throws_a_sphere) {
    AK_CHECK_EQ(view("rigid:preset:stack", "shoot.txt",
                     "wait 3\nscreenshot s0.png\nmouse_down right 60 50\nmouse_up right 60 50\n"
                     "wait 20\nscreenshot s1.png\n"),
                0);
    /* the same preset named the other way: `view rigid --preset stack` */
    AK_CHECK_EQ(view("rigid --preset stack", "still.txt",
                     "wait 3\nscreenshot n0.png\nwait 20\nscreenshot n1.png\n"),
                0);
    long before = count_diff("s0.png", "n0.png", 0, H);
    long after = count_diff("s1.png", "n1.png", HUD_TOP, H - HUD_BOTTOM);
    printf("  stack: %ld pixels differ before the click, %ld after it (the thrown sphere)\n",
           before, after);
    AK_CHECK_MSG(before == 0, "the two runs differ before the click (%ld pixels)", before);
    AK_CHECK_MSG(after > 20, "the thrown sphere changed only %ld pixels", after);
}

AK_TEST(ragdoll_default_plays) {
    AK_CHECK_EQ(view("rigid", "play.txt", "screenshot p0.png\nwait 20\nscreenshot p1.png\n"), 0);
    long moved = count_diff("p0.png", "p1.png", HUD_TOP, H - HUD_BOTTOM);
    AK_CHECK_MSG(moved > 50, "the ragdoll did not move (%ld pixels)", moved);
}

AK_TEST(bad_spec_errors) {
    AK_CHECK_EQ(run("view rigid:preset:nope --headless", true), 2);
    AK_CHECK(strstr(out_buf, "stack, pyramid") != NULL);
    AK_CHECK_EQ(run("view rigid:no_such_rigid_scene.json --headless", true), 1);
    AK_CHECK(strstr(out_buf, "no_such_rigid_scene.json") != NULL);
    AK_CHECK_EQ(run("view rigid no_such_rigid_scene.json --headless", true), 1);
    AK_CHECK_EQ(run("view rigid --preset nope --headless", true), 2);
    AK_CHECK_EQ(run("view rigid x.json --preset stack --headless", true), 2);
    AK_CHECK(strstr(out_buf, "not both") != NULL);
}

int main(void) {
    snprintf(g_dir, sizeof g_dir, "%s/test_rigid_view.XXXXXX",
             getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    if (!mkdtemp(g_dir)) {
        printf("cannot create a temporary directory\n");
        return 1;
    }
    AK_RUN(right_click_throws_a_sphere);
    AK_RUN_SLOW(ragdoll_default_plays); /* a second session of the viewer */
    AK_RUN(bad_spec_errors);
    static const char* const files[] = {"shoot.txt", "still.txt", "play.txt", "s0.png", "s1.png",
                                        "n0.png",    "n1.png",    "p0.png",   "p1.png"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; ++i) {
        char p[1200];
        snprintf(p, sizeof p, "%s/%s", g_dir, files[i]);
        remove(p);
    }
    rmdir(g_dir);
    return ak_test_finish();
}
