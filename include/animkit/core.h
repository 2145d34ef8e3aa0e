/* animkit core: result codes, allocator, spans, diagnostics, random numbers.
 *
 * What it does: the few types every other module shares. Every fallible call in animkit
 * returns an ak_result; ak_result_string() turns one into a message (never NULL).
 * Objects that allocate take an optional ak_allocator (NULL -> malloc/free). Arrays cross
 * the API as spans: a pointer plus an element count. Randomness comes from an explicit
 * ak_rng that the caller seeds; the library has no global state.
 *
 * What it does NOT do: logging. The library prints nothing; modules that want to report
 * progress or warnings take an ak_log callback in their desc.
 *
 * Usage:
 *     float buf[64];
 *     ak_f32_span out = AK_SPAN(buf);
 *     ak_rng rng = ak_rng_make(42);
 *     for (size_t i = 0; i < out.count; ++i) out.ptr[i] = ak_rng_float(&rng);
 *     ak_result r = ak_something_run(&job);
 *     if (r != AK_OK) fprintf(stderr, "animkit: %s\n", ak_result_string(r));
 *
 * Threading: everything here is reentrant; an ak_rng must not be shared between threads
 * without a lock (give each thread its own, e.g. ak_rng_make(seed + thread_index)).
 */
#ifndef ANIMKIT_CORE_H
#define ANIMKIT_CORE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h> /* FILE: ak_atomic_file */

#ifdef __cplusplus
extern "C" {
#endif

#if defined(_WIN32) && defined(AK_SHARED)
#if defined(AK_BUILDING)
#define AK_API __declspec(dllexport)
#else
#define AK_API __declspec(dllimport)
#endif
#elif defined(__GNUC__) && defined(AK_BUILDING)
#define AK_API __attribute__((visibility("default")))
#else
#define AK_API
#endif

/* ---- results ------------------------------------------------------------------------ */

/* The single list of outcomes. Codes are stable: new ones are only appended. */
#define AK_RESULT_LIST(X)                                                                  \
    X(OK, "success")                                                                       \
    X(ERR_NULL_ARG, "a required pointer or span is empty")                                 \
    X(ERR_SPAN_SMALL, "an output span is shorter than required")                           \
    X(ERR_BAD_DATA, "input holds NaN, infinity or out-of-range values")                    \
    X(ERR_NO_MEMORY, "the allocator returned NULL")                                        \
    X(ERR_UNSORTED, "key times are not strictly increasing")                               \
    X(ERR_DUPLICATE, "two keys share a time, or two joints share a name")                  \
    X(ERR_EMPTY, "a track, clip or mesh has no elements")                                  \
    X(ERR_BAD_INDEX, "an index is out of range")                                           \
    X(ERR_BAD_HIERARCHY, "a parent index is not before its child, or the hierarchy loops") \
    X(ERR_BAD_WEIGHTS, "skin weights are negative, NaN or do not sum to one")              \
    X(ERR_BAD_ARG, "an argument is outside its documented range")                          \
    X(ERR_IO, "a file could not be opened, read or written")                               \
    X(ERR_PARSE, "a file is malformed")                                                    \
    X(ERR_UNSUPPORTED, "the input uses a feature animkit does not support")                \
    X(ERR_NOT_FOUND, "a named item (joint, clip, mesh) was not found")                     \
    X(ERR_NO_CONVERGENCE, "an iterative solver did not converge")                          \
    X(ERR_BUDGET, "the input asks for more work than the documented budget")

typedef enum ak_result {
#define AK_RESULT_ENUM_(name, msg) AK_##name,
    AK_RESULT_LIST(AK_RESULT_ENUM_)
#undef AK_RESULT_ENUM_
        AK_RESULT_COUNT
} ak_result;

/* Message for a result code; never NULL ("unknown result" for out-of-range values). */
AK_API const char* ak_result_string(ak_result result);

/* Short symbolic name ("AK_ERR_BAD_DATA"); never NULL. */
AK_API const char* ak_result_name(ak_result result);

/* ---- allocation --------------------------------------------------------------------- */

/* Custom allocator. Either both functions are set or both are NULL (-> malloc/free).
 * alloc must return memory aligned to at least 16 bytes. */
typedef struct ak_allocator {
    void* (*alloc)(size_t size, void* user); /* bytes -> pointer or NULL */
    void (*free)(void* ptr, void* user);     /* NULL ptr never passed */
    void* user;                              /* passed through unchanged */
} ak_allocator;

/* ---- logging ------------------------------------------------------------------------ */

typedef enum ak_log_level { AK_LOG_INFO = 0, AK_LOG_WARN, AK_LOG_ERROR } ak_log_level;

/* Log callback installed in a desc. The library never prints on its own. */
typedef struct ak_logger {
    void (*func)(ak_log_level level, const char* message, void* user); /* NULL -> silent */
    void* user;
} ak_logger;

/* ---- diagnostics -------------------------------------------------------------------- */

/* Filled by parsers (optional): where the input is wrong, in words a person can act on. */
typedef struct ak_diag {
    char path[256];     /* file the message is about ("" when not a file) */
    long line;          /* 1-based line, or 0 when not line-based */
    long byte_offset;   /* byte offset into the file, or -1 when unknown */
    char message[512];  /* one line, no trailing newline */
} ak_diag;

/* ---- spans -------------------------------------------------------------------------- */

#define AK_DEFINE_SPAN(name, type)                                                         \
    typedef struct ak_##name##_span {                                                      \
        type* ptr;                                                                         \
        size_t count;                                                                      \
    } ak_##name##_span;                                                                    \
    typedef struct ak_##name##_cspan {                                                     \
        const type* ptr;                                                                   \
        size_t count;                                                                      \
    } ak_##name##_cspan;

AK_DEFINE_SPAN(f32, float)
AK_DEFINE_SPAN(i16, int16_t)
AK_DEFINE_SPAN(u16, uint16_t)
AK_DEFINE_SPAN(u32, uint32_t)
AK_DEFINE_SPAN(i32, int32_t)
AK_DEFINE_SPAN(u8, uint8_t)

/* Span over a fixed-size array (never a pointer). */
#define AK_SPAN(array) {(array), sizeof(array) / sizeof((array)[0])}

/* Interleaved data: count elements, stride bytes apart. stride 0 -> tightly packed. */
typedef struct ak_stream {
    void* ptr;
    size_t count;
    size_t stride;
} ak_stream;
typedef struct ak_cstream {
    const void* ptr;
    size_t count;
    size_t stride;
} ak_cstream;

/* ---- random numbers ----------------------------------------------------------------- */

/* xoshiro128** generator; explicit state, so runs are reproducible from the seed. */
typedef struct ak_rng {
    uint32_t s[4];
} ak_rng;

/* Internal to ak_rng_u32: rotate x left by k bits (0 < k < 32). */
static inline uint32_t ak_rng_rotl_(uint32_t x, int k) { return (x << k) | (x >> (32 - k)); }

/* Seed a generator (splitmix64 expansion; every seed, including 0, is valid). */
static inline ak_rng ak_rng_make(uint64_t seed) {
    ak_rng r;
    for (int i = 0; i < 4; ++i) {
        uint64_t z = (seed += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        r.s[i] = (uint32_t)((z ^ (z >> 31)) >> 16);
    }
    if ((r.s[0] | r.s[1] | r.s[2] | r.s[3]) == 0) r.s[0] = 1u;
    return r;
}

/* Next 32 random bits. */
static inline uint32_t ak_rng_u32(ak_rng* r) {
    const uint32_t result = ak_rng_rotl_(r->s[1] * 5u, 7) * 9u;
    const uint32_t t = r->s[1] << 9;
    r->s[2] ^= r->s[0];
    r->s[3] ^= r->s[1];
    r->s[1] ^= r->s[2];
    r->s[0] ^= r->s[3];
    r->s[2] ^= t;
    r->s[3] = ak_rng_rotl_(r->s[3], 11);
    return result;
}

/* Uniform float in [0, 1). */
static inline float ak_rng_float(ak_rng* r) { return (float)(ak_rng_u32(r) >> 8) * (1.0f / 16777216.0f); }

/* Uniform float in [lo, hi). */
static inline float ak_rng_range(ak_rng* r, float lo, float hi) {
    return lo + (hi - lo) * ak_rng_float(r);
}

/* Uniform double in [0, 1) with 53 random bits. */
static inline double ak_rng_double(ak_rng* r) {
    uint64_t hi = ak_rng_u32(r) >> 5, lo = ak_rng_u32(r) >> 6;
    return (double)(hi * 67108864ull + lo) * (1.0 / 9007199254740992.0);
}

/* Size of the fixed name buffers in joints, meshes, clips (names are truncated to fit). */
#define AK_NAME_SIZE 64

/* ---- output files written whole or not at all ---------------------------------------------
 * The library's writers (PNG, GIF, OBJ, glTF, terrain, weights) and the command line write
 * every output through this: a temporary ".NAME.XXXXXXX" is created beside the named path (the
 * same directory, so the rename stays on one file system) and renamed over the path only after
 * every write, the flush and the close succeeded. On any failure the temporary is removed and
 * the named path is never touched: an existing file keeps its contents, and a symlink named as
 * the output survives. On success the rename replaces what the path names: a symlink there is
 * replaced by the new file (its target is left alone). The new file gets 0666 less the umask,
 * or the mode of the regular file it replaces. No fsync: this guards against failed writes
 * (full disk, file size limit, EIO), not against power loss.
 *
 *     ak_atomic_file out;
 *     if (ak_atomic_file_open(&out, "scene.json") != AK_OK) -> strerror(out.err)
 *     fprintf(out.f, ...);
 *     if (ak_atomic_file_commit(&out) != AK_OK) -> strerror(out.err); nothing left behind */
#define AK_ATOMIC_FILE_PATH_SIZE 4096
typedef struct ak_atomic_file {
    FILE* f;                                /* the temporary, open "wb" (ak_atomic_file_open only) */
    int err;                                /* errno of the first failure (0 when none known) */
    char path[AK_ATOMIC_FILE_PATH_SIZE];    /* the named output */
    char tmp[AK_ATOMIC_FILE_PATH_SIZE + 32]; /* the temporary; "" once renamed or removed */
} ak_atomic_file;

/* Create the temporary and open it as a->f. AK_ERR_IO (a->err says why; nothing created). */
AK_API ak_result ak_atomic_file_open(ak_atomic_file* a, const char* path);
/* The same with a plain descriptor (a->f stays NULL) for writers that take an fd and close it
 * themselves (giflib); returns it, or -1 (a->err says why). */
AK_API int ak_atomic_file_open_fd(ak_atomic_file* a, const char* path);
/* Flush, check and close a->f (when open); on failure remove the temporary. AK_OK or AK_ERR_IO. */
AK_API ak_result ak_atomic_file_close(ak_atomic_file* a);
/* Rename the closed temporary over the path; on failure remove it. AK_OK or AK_ERR_IO. */
AK_API ak_result ak_atomic_file_rename(ak_atomic_file* a);
/* close, then rename. */
AK_API ak_result ak_atomic_file_commit(ak_atomic_file* a);
/* Close a->f (when open) and remove the temporary (when there is one); idempotent, and fine on
 * a zeroed ak_atomic_file. */
AK_API void ak_atomic_file_abort(ak_atomic_file* a);

/* ---- version ------------------------------------------------------------------------ */

#define AK_VERSION_MAJOR 0
#define AK_VERSION_MINOR 1
#define AK_VERSION_PATCH 0

/* "0.1.0" */
AK_API const char* ak_version_string(void);

/* Bytes of the valid UTF-8 character at p (RFC 3629: no overlong form, no surrogate, at most
 * U+10FFFF), reading at most avail bytes; 0 when the bytes there are not one (a NUL inside a
 * multi-byte sequence included) or avail is 0. The one UTF-8 check of the readers (glTF, BVH,
 * OBJ names; JSON scene files) and of the command's printing. Pure. */
AK_API size_t ak_utf8_char(const void* p, size_t avail);

#ifdef __cplusplus
}
#endif
#endif /* ANIMKIT_CORE_H */
