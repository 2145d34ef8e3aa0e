/* Helpers shared between animkit's .c files; never installed. */
#ifndef ANIMKIT_INTERNAL_H
#define ANIMKIT_INTERNAL_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <animkit/core.h>

/* Internal invariants only; caller input is checked and reported with ak_result. */
#ifndef AK_ASSERT
#ifdef NDEBUG
#define AK_ASSERT(cond) ((void)0)
#else
#define AK_ASSERT(cond)                                                                    \
    ((cond) ? (void)0                                                                      \
            : (fprintf(stderr, "animkit: internal assertion failed: %s (%s:%d)\n", #cond,  \
                       __FILE__, __LINE__),                                                \
               abort()))
#endif
#endif

/* Allocate through an optional allocator (NULL -> malloc). Returns NULL on failure or size 0. */
static inline void* akp_alloc(const ak_allocator* a, size_t size) {
    if (size == 0) return NULL;
    if (a && a->alloc) return a->alloc(size, a->user);
    return malloc(size);
}
static inline void* akp_calloc(const ak_allocator* a, size_t size) {
    void* p = akp_alloc(a, size);
    if (p) memset(p, 0, size);
    return p;
}
static inline void akp_free(const ak_allocator* a, void* p) {
    if (!p) return;
    if (a && a->free) a->free(p, a->user);
    else free(p);
}

/* Round up to a multiple of 16 (for carving one allocation into several arrays). */
static inline size_t akp_align16(size_t n) { return (n + 15u) & ~(size_t)15u; }

/* Fill an optional diag with a formatted message. */
#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
static inline void akp_diag_set(ak_diag* d, const char* path, const char* fmt, ...);

#include <stdarg.h>
static inline void akp_diag_set(ak_diag* d, const char* path, const char* fmt, ...) {
    if (!d) return;
    memset(d, 0, sizeof(*d));
    d->byte_offset = -1;
    if (path) snprintf(d->path, sizeof(d->path), "%s", path);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(d->message, sizeof(d->message), fmt, ap);
    va_end(ap);
}

static inline void akp_log(const ak_logger* l, ak_log_level level, const char* msg) {
    if (l && l->func) l->func(level, msg, l->user);
}


/* ---- output files: written whole or not at all (src/core.c) ------------------------------
 * Every writer creates a temporary ".NAME.XXXXXX" beside the named path (the same directory,
 * so the rename stays on one file system) and renames it over the path only after every
 * write, the flush and the close succeeded. On any failure the temporary is removed and the
 * named path is never touched: an existing file keeps its contents, and a symlink named as
 * the output survives. On success the rename replaces what the path names: a symlink there
 * is replaced by the new file (its target is left alone). The new file gets 0666 less the
 * umask, or the mode of the regular file it replaces. No fsync: this guards against failed
 * writes (full disk, file size limit, EIO), not against power loss. */
#define AKP_PATH_SIZE 4096

typedef struct akp_file_atomic {
    FILE* f;                       /* the temporary, open "wb" (akp_file_atomic_open only) */
    int err;                       /* errno of the first failure (0 when none known) */
    char path[AKP_PATH_SIZE];      /* the named output */
    char tmp[AKP_PATH_SIZE + 32];  /* the temporary; "" once renamed or removed */
} akp_file_atomic;

/* Create the temporary and open it as a->f. AK_ERR_IO (a->err says why; nothing created). */
ak_result akp_file_atomic_open(akp_file_atomic* a, const char* path);
/* The same with a plain descriptor (a->f stays NULL) for writers that take an fd and close it
 * themselves (giflib); returns it, or -1 (a->err says why). */
int akp_file_atomic_open_fd(akp_file_atomic* a, const char* path);
/* Flush, check and close a->f (when open); on failure remove the temporary. AK_OK or AK_ERR_IO. */
ak_result akp_file_atomic_close(akp_file_atomic* a);
/* Rename the closed temporary over the path; on failure remove it. AK_OK or AK_ERR_IO. */
ak_result akp_file_atomic_rename(akp_file_atomic* a);
/* close, then rename. */
ak_result akp_file_atomic_commit(akp_file_atomic* a);
/* Close a->f (when open) and remove the temporary (when there is one); idempotent. */
void akp_file_atomic_abort(akp_file_atomic* a);

#endif
