/* Result strings, version; output files written whole or not at all (ak_atomic_file). */
#include <errno.h>
#include <fcntl.h>    /* open: O_EXCL for the temporary */
#include <stdint.h>
#include <sys/stat.h> /* lstat, fchmod: keep the mode of the file replaced */
#include <time.h>     /* clock_gettime: the temporary's name */
#include <unistd.h>   /* getpid, close, unlink */

#include <animkit/core.h>

#include "internal.h"

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

size_t ak_utf8_char(const void* ptr, size_t avail) {
    const unsigned char* p = (const unsigned char*)ptr;
    if (!p || !avail) return 0;
    const unsigned char c = p[0];
    if (c < 0x80) return 1;
    const size_t len = c >= 0xC2 && c <= 0xDF ? 2 : c >= 0xE0 && c <= 0xEF ? 3 : c >= 0xF0 && c <= 0xF4 ? 4 : 0;
    if (!len || len > avail) return 0;
    for (size_t k = 1; k < len; ++k) /* stops at a NUL too: it is no continuation byte */
        if ((p[k] & 0xC0) != 0x80) return 0;
    if (len == 3 && ((c == 0xE0 && p[1] < 0xA0) || (c == 0xED && p[1] >= 0xA0))) return 0; /* overlong, surrogate */
    if (len == 4 && ((c == 0xF0 && p[1] < 0x90) || (c == 0xF4 && p[1] >= 0x90))) return 0; /* overlong, > U+10FFFF */
    return len;
}

/* ---- atomic output files -------------------------------------------------------------------- */

/* "DIR/.BASE.XXXXXX" for path "DIR/BASE" (or ".BASE.XXXXXX" without a slash); false when the
 * name does not fit or path names a directory (ends in '/'). */
static bool temp_name(const char* path, uint64_t salt, char* out, size_t cap) {
    const char* slash = strrchr(path, '/');
    const char* base = slash ? slash + 1 : path;
    if (!*base) return false;
    size_t dir_len = (size_t)(base - path);
    static const char digits[] = "0123456789abcdefghijklmnopqrstuv";
    char suffix[8];
    for (int i = 0; i < 7; ++i) suffix[i] = digits[(salt >> (5 * i)) & 31u];
    suffix[7] = '\0';
    int n = snprintf(out, cap, "%.*s.%s.%s", (int)dir_len, path, base, suffix);
    return n > 0 && (size_t)n < cap;
}

int ak_atomic_file_open_fd(ak_atomic_file* a, const char* path) {
    memset(a, 0, sizeof *a);
    if (!path || strlen(path) >= sizeof a->path) {
        a->err = ENAMETOOLONG;
        return -1;
    }
    memcpy(a->path, path, strlen(path) + 1);
    struct timespec ts = {0, 0};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    uint64_t salt = (uint64_t)getpid() * 0x9E3779B97F4A7C15u ^ (uint64_t)ts.tv_nsec ^ ((uint64_t)ts.tv_sec << 30) ^
                    (uint64_t)(uintptr_t)a;
    for (int attempt = 0; attempt < 100; ++attempt) {
        salt = salt * 6364136223846793005u + 1442695040888963407u; /* a new name per attempt */
        if (!temp_name(path, salt >> 20, a->tmp, sizeof a->tmp)) {
            a->err = path[0] && path[strlen(path) - 1] == '/' ? EISDIR : ENAMETOOLONG;
            a->tmp[0] = '\0';
            return -1;
        }
        /* O_EXCL: never an existing file, never through a symlink planted at the name */
        int fd = open(a->tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd >= 0) {
            struct stat st;
            if (lstat(path, &st) == 0 && S_ISREG(st.st_mode)) (void)fchmod(fd, st.st_mode & 07777);
            return fd;
        }
        if (errno != EEXIST) {
            a->err = errno;
            a->tmp[0] = '\0';
            return -1;
        }
    }
    a->err = EEXIST;
    a->tmp[0] = '\0';
    return -1;
}

ak_result ak_atomic_file_open(ak_atomic_file* a, const char* path) {
    int fd = ak_atomic_file_open_fd(a, path);
    if (fd < 0) return AK_ERR_IO;
    a->f = fdopen(fd, "wb");
    if (!a->f) {
        a->err = errno;
        close(fd);
        ak_atomic_file_abort(a);
        return AK_ERR_IO;
    }
    return AK_OK;
}

ak_result ak_atomic_file_close(ak_atomic_file* a) {
    if (!a->f) return a->tmp[0] ? AK_OK : AK_ERR_IO;
    bool ok = true;
    if (fflush(a->f) != 0) ok = false, a->err = a->err ? a->err : errno;
    if (ferror(a->f)) ok = false, a->err = a->err ? a->err : EIO;
    if (fclose(a->f) != 0) ok = false, a->err = a->err ? a->err : errno;
    a->f = NULL;
    if (!ok) {
        ak_atomic_file_abort(a);
        return AK_ERR_IO;
    }
    return AK_OK;
}

ak_result ak_atomic_file_rename(ak_atomic_file* a) {
    if (!a->tmp[0]) return AK_ERR_IO;
    if (rename(a->tmp, a->path) != 0) {
        a->err = errno;
        ak_atomic_file_abort(a);
        return AK_ERR_IO;
    }
    a->tmp[0] = '\0';
    return AK_OK;
}

ak_result ak_atomic_file_commit(ak_atomic_file* a) {
    ak_result r = ak_atomic_file_close(a);
    return r == AK_OK ? ak_atomic_file_rename(a) : r;
}

void ak_atomic_file_abort(ak_atomic_file* a) {
    if (a->f) fclose(a->f);
    a->f = NULL;
    if (a->tmp[0]) unlink(a->tmp);
    a->tmp[0] = '\0';
}
