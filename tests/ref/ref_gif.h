/* GIF frame delays read straight from a file with giflib, independently of animkit's GIF
 * writer, for tests that check what it wrote. Header-only. */
#ifndef ANIMKIT_REF_GIF_H
#define ANIMKIT_REF_GIF_H

#include <gif_lib.h>
#include <string.h>

/* Delays (1/100 s) of the first cap frames of the GIF at path into delays; returns the frame
 * count (which may exceed cap), or -1 when the file cannot be read. */
static inline int ref_gif_delays(const char* path, int* delays, int cap) {
    int err = 0;
    GifFileType* g = DGifOpenFileName(path, &err);
    if (!g) return -1;
    if (DGifSlurp(g) != GIF_OK) {
        DGifCloseFile(g, &err);
        return -1;
    }
    int n = g->ImageCount;
    for (int i = 0; i < n && i < cap; ++i) {
        GraphicsControlBlock gcb;
        memset(&gcb, 0, sizeof gcb);
        DGifSavedExtensionToGCB(g, i, &gcb);
        delays[i] = gcb.DelayTime;
    }
    DGifCloseFile(g, &err);
    return n;
}

#endif
