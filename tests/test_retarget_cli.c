/* animkit retarget --map on the builtin rigs (no assets needed): a map file is read only when
 * it is a regular file (a FIFO used to block the command forever), and the map parser's
 * messages (ak_retarget_map_parse) reach the command line with the file named. The map cases
 * on real rigs are in test_retarget_assets.c. */
#include <stdlib.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "ak_test.h"
#include "cli_test.h"

/* "animkit ARGS" under timeout(1): 124 when it ran past `seconds`. Output in out_buf. */
static int run_timed(const char* args, int seconds) {
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "timeout %d %s %s 2>&1", seconds, AK_CLI_PATH, args);
    FILE* p = popen(cmd, "r");
    if (!p) return -1;
    size_t n = fread(out_buf, 1, sizeof out_buf - 1, p);
    out_buf[n] = '\0';
    int st = pclose(p);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

AK_TEST(map_file_kinds) {
    char dir[] = "/tmp/test_retarget_cli.XXXXXX";
    if (!mkdtemp(dir)) {
        AK_FAIL_("mkdtemp");
        return;
    }
    char path[512], out[512], args[2048];
    snprintf(out, sizeof out, "%s/out.glb", dir);
    /* a good map */
    snprintf(path, sizeof path, "%s/ok.map", dir);
    AK_CHECK(write_file(path, "# target = source\npelvis = pelvis\nspine_01 = spine_01\n"));
    snprintf(args, sizeof args, "retarget builtin:humanoid builtin:humanoid --map '%s' -o '%s'", path, out);
    AK_CHECK_MSG(run_timed(args, 120) == 0, "%s", out_buf);
    /* a FIFO: refused at once, not read (nobody writes to it) */
    snprintf(path, sizeof path, "%s/fifo.map", dir);
    AK_CHECK_EQ(mkfifo(path, 0600), 0);
    snprintf(args, sizeof args, "retarget builtin:humanoid builtin:humanoid --map '%s' -o '%s'", path, out);
    double t0 = (double)time(NULL);
    int rc = run_timed(args, 60);
    AK_CHECK_MSG(rc == 1, "FIFO map: exit %d (124: it blocked): %s", rc, out_buf);
    AK_CHECK_MSG(strstr(out_buf, "fifo.map") && strstr(out_buf, "not a regular file"), "FIFO map: %s", out_buf);
    AK_CHECK((double)time(NULL) - t0 < 30.0);
    /* a directory */
    snprintf(args, sizeof args, "retarget builtin:humanoid builtin:humanoid --map '%s' -o '%s'", dir, out);
    AK_CHECK_EQ(run_timed(args, 60), 1);
    AK_CHECK(strstr(out_buf, "not a regular file") != NULL);
    /* a NUL byte: named as such, with its line (it used to read as a line too long) */
    snprintf(path, sizeof path, "%s/nul.map", dir);
    FILE* f = fopen(path, "wb");
    AK_CHECK(f != NULL);
    if (f) {
        fwrite("pelvis = pelvis\nspine_01\0 = spine_01\n", 1, 37, f);
        fclose(f);
    }
    snprintf(args, sizeof args, "retarget builtin:humanoid builtin:humanoid --map '%s' -o '%s'", path, out);
    AK_CHECK_EQ(run_timed(args, 60), 1);
    AK_CHECK_MSG(strstr(out_buf, "nul.map") && strstr(out_buf, "line 2 holds a NUL byte"), "%s", out_buf);
    /* an unknown joint: the parser's line and the rigs named */
    snprintf(path, sizeof path, "%s/bad.map", dir);
    AK_CHECK(write_file(path, "pelvis = pelvis\ntail = pelvis\n"));
    snprintf(args, sizeof args, "retarget builtin:humanoid builtin:humanoid --map '%s' -o '%s'", path, out);
    AK_CHECK_EQ(run_timed(args, 60), 1);
    AK_CHECK_MSG(strstr(out_buf, "bad.map") && strstr(out_buf, "line 2") && strstr(out_buf, "no joint 'tail'"), "%s",
                 out_buf);
    snprintf(args, sizeof args, "rm -rf '%s'", dir);
    AK_CHECK_EQ(system(args), 0);
}

int main(void) {
    AK_RUN_SLOW(map_file_kinds);
    return ak_test_finish();
}
