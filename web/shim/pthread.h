/* Single-threaded stand-in for <pthread.h> in the WebAssembly build (web/, docs/web.md).
 * Debian's wasi-libc (2022) has no threads. animkit starts worker threads only where a
 * thread count above 1 asks for them, and every caller falls back to the calling thread when
 * pthread_create fails: here it always fails (EAGAIN), so all the work runs on the one thread
 * the browser gives the module. Locks are no-ops; a wait that could only end by another
 * thread's action traps instead of hanging the page. Never installed, never used natively. */
#ifndef ANIMKIT_WEB_PTHREAD_H
#define ANIMKIT_WEB_PTHREAD_H

#include <errno.h>

/* wasi-libc's <sys/types.h> (musl) already declares the pthread types. */
#include <sys/types.h>

#define PTHREAD_BARRIER_SERIAL_THREAD (-1)

static inline int pthread_create(pthread_t* t, const pthread_attr_t* a, void* (*fn)(void*), void* arg) {
    (void)t, (void)a, (void)fn, (void)arg;
    return EAGAIN;
}
static inline int pthread_join(pthread_t t, void** ret) {
    (void)t, (void)ret;
    return ESRCH;
}
static inline int pthread_mutex_init(pthread_mutex_t* m, const pthread_mutexattr_t* a) { (void)m, (void)a; return 0; }
static inline int pthread_mutex_destroy(pthread_mutex_t* m) { (void)m; return 0; }
static inline int pthread_mutex_lock(pthread_mutex_t* m) { (void)m; return 0; }
static inline int pthread_mutex_unlock(pthread_mutex_t* m) { (void)m; return 0; }
static inline int pthread_cond_init(pthread_cond_t* c, const pthread_condattr_t* a) { (void)c, (void)a; return 0; }
static inline int pthread_cond_destroy(pthread_cond_t* c) { (void)c; return 0; }
static inline int pthread_cond_broadcast(pthread_cond_t* c) { (void)c; return 0; }
static inline int pthread_cond_signal(pthread_cond_t* c) { (void)c; return 0; }
/* Only another thread could wake this one: with one thread it would wait forever. */
static inline int pthread_cond_wait(pthread_cond_t* c, pthread_mutex_t* m) {
    (void)c, (void)m;
    __builtin_trap();
}
static inline int pthread_barrier_init(pthread_barrier_t* b, const pthread_barrierattr_t* a, unsigned count) {
    (void)a;
    if (count != 1) return EAGAIN; /* a barrier for several threads cannot be passed by one */
    (void)b;
    return 0;
}
static inline int pthread_barrier_destroy(pthread_barrier_t* b) { (void)b; return 0; }
static inline int pthread_barrier_wait(pthread_barrier_t* b) { (void)b; return PTHREAD_BARRIER_SERIAL_THREAD; }

#endif
