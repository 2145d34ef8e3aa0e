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


/* Output files written whole or not at all: ak_atomic_file (animkit/core.h, src/core.c). */

#endif
