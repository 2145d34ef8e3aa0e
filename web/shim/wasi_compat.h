/* Included first in every file of the WebAssembly build (scripts/build-web.sh, -include): the
 * POSIX calls the library names that Debian's wasi-libc (2022) lacks, as no-ops that keep the
 * native meaning where the browser has nothing to do. fchmod: the page's in-memory files have
 * no modes. realpath: the page has no directories, so a glTF's external files (a .gltf's .bin
 * or images) cannot be resolved and are reported missing; .glb and data: URIs need none. Never installed, never used natively. */
#ifndef ANIMKIT_WEB_WASI_COMPAT_H
#define ANIMKIT_WEB_WASI_COMPAT_H

#include <errno.h>
#include <stddef.h>
#include <sys/types.h>

static inline int fchmod(int fd, mode_t mode) {
    (void)fd, (void)mode;
    return 0;
}

static inline char* realpath(const char* path, char* resolved) {
    (void)path, (void)resolved;
    errno = ENOENT;
    return NULL;
}

#endif
