/* Stand-in for <setjmp.h> in the WebAssembly build (clang 14 has no setjmp for wasm32).
 * Only the libpng error path uses it, and the web build's libpng stand-in (web/shim/png.h)
 * fails before any jump can happen: setjmp returns 0 and longjmp traps. Never installed. */
#ifndef ANIMKIT_WEB_SETJMP_H
#define ANIMKIT_WEB_SETJMP_H

typedef int jmp_buf[1];
#define setjmp(env) ((void)(env), 0)
static inline _Noreturn void longjmp(jmp_buf env, int value) {
    (void)env, (void)value;
    __builtin_trap();
}

#endif
