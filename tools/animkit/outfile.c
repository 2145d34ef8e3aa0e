/* Output files written whole or not at all (outfile.h). */
#include "outfile.h"

#include <errno.h>
#include <fcntl.h>    /* open: O_EXCL for the temporary */
#include <stdint.h>
#include <string.h>
#include <sys/stat.h> /* lstat, fchmod: keep the mode of the file replaced */
#include <time.h>     /* clock_gettime: the temporary's name */
#include <unistd.h>   /* getpid, close, unlink */

#include "cli.h"

/* "DIR/.BASE.XXXXXXX" for path "DIR/BASE"; false when it does not fit or path ends in '/'. */
static int temp_name(const char* path, uint64_t salt, char* out, size_t cap) {
    const char* slash = strrchr(path, '/');
    const char* base = slash ? slash + 1 : path;
    if (!*base) return EISDIR;
    static const char digits[] = "0123456789abcdefghijklmnopqrstuv";
    char suffix[8];
    for (int i = 0; i < 7; ++i) suffix[i] = digits[(salt >> (5 * i)) & 31u];
    suffix[7] = '\0';
    int n = snprintf(out, cap, "%.*s.%s.%s", (int)(base - path), path, base, suffix);
    return n > 0 && (size_t)n < cap ? 0 : ENAMETOOLONG;
}

static int create_temp(cli_outfile* o, const char* path) {
    if (strlen(path) >= sizeof o->path) return ENAMETOOLONG;
    memcpy(o->path, path, strlen(path) + 1);
    struct timespec ts = {0, 0};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    uint64_t salt = (uint64_t)getpid() * 0x9E3779B97F4A7C15u ^ (uint64_t)ts.tv_nsec ^ ((uint64_t)ts.tv_sec << 30) ^
                    (uint64_t)(uintptr_t)o;
    for (int attempt = 0; attempt < 100; ++attempt) {
        salt = salt * 6364136223846793005u + 1442695040888963407u; /* a new name per attempt */
        int e = temp_name(path, salt >> 20, o->tmp, sizeof o->tmp);
        if (e) {
            o->tmp[0] = '\0';
            return e;
        }
        /* O_EXCL: never an existing file, never through a symlink planted at the name */
        int fd = open(o->tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd < 0) {
            if (errno == EEXIST) continue;
            e = errno;
            o->tmp[0] = '\0';
            return e;
        }
        struct stat st;
        if (lstat(path, &st) == 0 && S_ISREG(st.st_mode)) (void)fchmod(fd, st.st_mode & 07777);
        if (!(o->f = fdopen(fd, "w"))) {
            e = errno;
            close(fd);
            unlink(o->tmp);
            o->tmp[0] = '\0';
            return e;
        }
        return 0;
    }
    o->tmp[0] = '\0';
    return EEXIST;
}

int cli_outfile_open(cli_outfile* o, const char* cmd, const char* path) {
    memset(o, 0, sizeof *o);
    o->err = create_temp(o, path);
    if (o->err) return cli_fail(cmd, "%s: cannot create the file (%s)", path, strerror(o->err));
    return CLI_OK;
}

int cli_outfile_commit(cli_outfile* o, const char* cmd) {
    if (!o->f || !o->tmp[0]) {
        cli_outfile_abort(o);
        return cli_fail(cmd, "%s: cannot write the file", o->path);
    }
    bool ok = true;
    /* fwrite's errno is gone by now; fflush and fclose give their own, EIO otherwise */
    if (fflush(o->f) != 0) ok = false, o->err = o->err ? o->err : errno;
    if (ferror(o->f)) ok = false, o->err = o->err ? o->err : EIO;
    if (fclose(o->f) != 0) ok = false, o->err = o->err ? o->err : errno;
    o->f = NULL;
    if (ok && rename(o->tmp, o->path) != 0) ok = false, o->err = errno;
    if (ok) {
        o->tmp[0] = '\0';
        return CLI_OK;
    }
    cli_outfile_abort(o);
    return cli_fail(cmd, "%s: cannot write the file (%s)", o->path, strerror(o->err ? o->err : EIO));
}

void cli_outfile_abort(cli_outfile* o) {
    if (o->f) fclose(o->f);
    o->f = NULL;
    if (o->tmp[0]) unlink(o->tmp);
    o->tmp[0] = '\0';
}
