/* PNG (libpng's simplified API) and animated GIF (giflib) writing and reading. The GIF colour
 * quantizer (median cut over a 15-bit histogram, ordered dithering) and the delta frames
 * (unchanged pixels transparent, palette kept while it fits) are animkit's own. */
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h> /* close */

#include <gif_lib.h> /* giflib 5: EGif* writer, DGif* reader */
#include <png.h>     /* libpng 1.6 simplified API: png_image */

#include <animkit/raster.h>

#include "../internal.h"

/* ---- private types ------------------------------------------------------------------------- */

#define HIST_SIZE 32768 /* 5 bits per channel */

typedef struct box {
    size_t first, count; /* range in the cell list */
    uint32_t pixels;
} box;

struct ak_gif_writer {
    ak_allocator alloc;
    bool has_alloc;
    GifFileType* gif;
    ak_gif_desc desc;
    int frames;
    bool failed;
    uint8_t* indices;    /* width * height */
    uint32_t* hist;      /* [HIST_SIZE] pixel counts */
    uint32_t* sum;       /* [HIST_SIZE * 3] sums of the 8-bit channels */
    uint16_t* cells;     /* [HIST_SIZE] non-empty cells */
    uint16_t* map;       /* [HIST_SIZE] cell -> palette index, 0xFFFF unknown */
    uint8_t* prev;       /* width * height * 4: the previous frame (delta frames), else NULL */
    GifColorType pal[256]; /* delta frames: the palette in use, kept while it fits the changes */
    int pal_n;
    double pal_err;      /* its mean error on the frame it was built from */
    double shown_cs;     /* frame_rate: hundredths of a second written so far */
    ak_atomic_file out; /* the temporary giflib writes; renamed over the path by finish */
};

/* ---- helpers ------------------------------------------------------------------------------- */

static bool image_valid(const ak_image* im) {
    return im && im->pixels && im->width > 0 && im->height > 0 &&
           (im->stride == 0 || im->stride >= (size_t)im->width * 4u);
}

static size_t image_stride(const ak_image* im) { return im->stride ? im->stride : (size_t)im->width * 4u; }

static inline int cell_channel(uint16_t cell, int ch) { return (cell >> (10 - 5 * ch)) & 31; }

/* Sort key for qsort: the channel is chosen by which comparator is passed. */
static int cmp_r(const void* a, const void* b) {
    return cell_channel(*(const uint16_t*)a, 0) - cell_channel(*(const uint16_t*)b, 0);
}
static int cmp_g(const void* a, const void* b) {
    return cell_channel(*(const uint16_t*)a, 1) - cell_channel(*(const uint16_t*)b, 1);
}
static int cmp_b(const void* a, const void* b) {
    return cell_channel(*(const uint16_t*)a, 2) - cell_channel(*(const uint16_t*)b, 2);
}

static void box_extent(const ak_gif_writer* w, const box* bx, int* out_axis, int* out_range) {
    int lo[3] = {31, 31, 31}, hi[3] = {0, 0, 0};
    for (size_t i = 0; i < bx->count; ++i) {
        uint16_t c = w->cells[bx->first + i];
        for (int ch = 0; ch < 3; ++ch) {
            int v = cell_channel(c, ch);
            if (v < lo[ch]) lo[ch] = v;
            if (v > hi[ch]) hi[ch] = v;
        }
    }
    int axis = 0;
    for (int ch = 1; ch < 3; ++ch)
        if (hi[ch] - lo[ch] > hi[axis] - lo[axis]) axis = ch;
    *out_axis = axis;
    *out_range = hi[axis] - lo[axis];
}

/* Median cut: at most max_colors palette entries from the histogram. Returns the entry count. */
static int median_cut(ak_gif_writer* w, GifColorType* palette, int max_colors) {
    size_t ncell = 0;
    for (uint32_t c = 0; c < HIST_SIZE; ++c)
        if (w->hist[c]) w->cells[ncell++] = (uint16_t)c;
    box boxes[256];
    int nbox = 1;
    boxes[0].first = 0;
    boxes[0].count = ncell;
    boxes[0].pixels = 0;
    for (size_t i = 0; i < ncell; ++i) boxes[0].pixels += w->hist[w->cells[i]];
    while (nbox < max_colors) {
        /* split the box with the largest range weighted by its share of pixels */
        int best = -1, best_axis = 0;
        double best_score = 0.0;
        for (int b = 0; b < nbox; ++b) {
            if (boxes[b].count < 2) continue;
            int axis, range;
            box_extent(w, &boxes[b], &axis, &range);
            double score = (double)range * sqrt((double)boxes[b].pixels);
            if (range > 0 && score > best_score) {
                best_score = score;
                best = b;
                best_axis = axis;
            }
        }
        if (best < 0) break;
        box* bx = &boxes[best];
        qsort(w->cells + bx->first, bx->count, sizeof(uint16_t), best_axis == 0 ? cmp_r : (best_axis == 1 ? cmp_g : cmp_b));
        uint32_t half = bx->pixels / 2, acc = 0;
        size_t split = 1;
        for (size_t i = 0; i < bx->count - 1; ++i) {
            acc += w->hist[w->cells[bx->first + i]];
            split = i + 1;
            if (acc >= half) break;
        }
        box nb;
        nb.first = bx->first + split;
        nb.count = bx->count - split;
        nb.pixels = bx->pixels - acc;
        bx->count = split;
        bx->pixels = acc;
        boxes[nbox++] = nb;
    }
    for (int b = 0; b < nbox; ++b) {
        double s[3] = {0, 0, 0}, n = 0;
        for (size_t i = 0; i < boxes[b].count; ++i) {
            uint16_t c = w->cells[boxes[b].first + i];
            for (int ch = 0; ch < 3; ++ch) s[ch] += w->sum[(size_t)c * 3 + (size_t)ch];
            n += w->hist[c];
        }
        if (n <= 0) n = 1;
        palette[b].Red = (GifByteType)(s[0] / n + 0.5);
        palette[b].Green = (GifByteType)(s[1] / n + 0.5);
        palette[b].Blue = (GifByteType)(s[2] / n + 0.5);
    }
    if (nbox == 0) nbox = 1;
    return nbox;
}

static uint8_t nearest(const GifColorType* pal, int n, int r, int g, int b) {
    int best = 0, bd = 1 << 30;
    for (int i = 0; i < n; ++i) {
        int dr = r - pal[i].Red, dg = g - pal[i].Green, db = b - pal[i].Blue;
        int d = 2 * dr * dr + 4 * dg * dg + db * db;
        if (d < bd) {
            bd = d;
            best = i;
        }
    }
    return (uint8_t)best;
}

/* ---- public: formats ------------------------------------------------------------------------- */

bool ak_image_format_available(ak_image_format format) {
    return format == AK_IMAGE_FORMAT_PNG || format == AK_IMAGE_FORMAT_GIF;
}

const char* ak_image_formats_string(void) { return "png gif"; }

/* ---- public: PNG --------------------------------------------------------------------------- */

ak_result ak_png_write(const char* path, const ak_image* image) {
    if (!path || !image || !image->pixels) return AK_ERR_NULL_ARG;
    if (!image_valid(image)) return AK_ERR_BAD_ARG;
    png_image pi;
    memset(&pi, 0, sizeof pi);
    pi.version = PNG_IMAGE_VERSION;
    pi.width = (png_uint_32)image->width;
    pi.height = (png_uint_32)image->height;
    pi.format = PNG_FORMAT_RGBA;
    /* to a temporary renamed into place (internal.h): png_image_write_to_file would leave a
     * partial file, or remove whatever path named (a symlink included) when it fails */
    ak_atomic_file out;
    if (ak_atomic_file_open(&out, path) != AK_OK) return AK_ERR_IO;
    int ok = png_image_write_to_stdio(&pi, out.f, 0, image->pixels, (png_int_32)image_stride(image), NULL);
    png_image_free(&pi);
    if (!ok) {
        ak_atomic_file_abort(&out);
        return AK_ERR_IO;
    }
    return ak_atomic_file_commit(&out);
}

static ak_result png_open(const char* path, png_image* pi) {
    memset(pi, 0, sizeof *pi);
    pi->version = PNG_IMAGE_VERSION;
    FILE* f = fopen(path, "rb");
    if (!f) return AK_ERR_IO;
    fclose(f);
    if (!png_image_begin_read_from_file(pi, path)) {
        png_image_free(pi);
        return AK_ERR_PARSE;
    }
    return AK_OK;
}

ak_result ak_png_info(const char* path, int* out_width, int* out_height) {
    if (!path || !out_width || !out_height) return AK_ERR_NULL_ARG;
    png_image pi;
    ak_result r = png_open(path, &pi);
    if (r != AK_OK) return r;
    *out_width = (int)pi.width;
    *out_height = (int)pi.height;
    png_image_free(&pi);
    return AK_OK;
}

ak_result ak_png_read(const char* path, const ak_image* out) {
    if (!path || !out || !out->pixels) return AK_ERR_NULL_ARG;
    if (!image_valid(out)) return AK_ERR_BAD_ARG;
    png_image pi;
    ak_result r = png_open(path, &pi);
    if (r != AK_OK) return r;
    if ((int)pi.width != out->width || (int)pi.height != out->height) {
        png_image_free(&pi);
        return AK_ERR_BAD_ARG;
    }
    pi.format = PNG_FORMAT_RGBA;
    int ok = png_image_finish_read(&pi, NULL, out->pixels, (png_int_32)image_stride(out), NULL);
    png_image_free(&pi);
    return ok ? AK_OK : AK_ERR_PARSE;
}

/* ---- public: GIF writer -------------------------------------------------------------------- */

ak_result ak_gif_writer_create(const char* path, const ak_gif_desc* desc, const ak_allocator* alloc,
                               ak_gif_writer** out_writer) {
    if (out_writer) *out_writer = NULL;
    if (!path || !desc || !out_writer) return AK_ERR_NULL_ARG;
    if (desc->width < 1 || desc->width > 65535 || desc->height < 1 || desc->height > 65535 || desc->delay_cs < 0 ||
        desc->loop_count < 0 || desc->loop_count > 65535)
        return AK_ERR_BAD_ARG;
    if (alloc && (!alloc->alloc != !alloc->free)) return AK_ERR_BAD_ARG;
    size_t npx = (size_t)desc->width * (size_t)desc->height;
    size_t o_idx = akp_align16(sizeof(ak_gif_writer));
    size_t o_hist = o_idx + akp_align16(npx);
    size_t o_sum = o_hist + akp_align16(HIST_SIZE * sizeof(uint32_t));
    size_t o_cells = o_sum + akp_align16(HIST_SIZE * 3 * sizeof(uint32_t));
    size_t o_map = o_cells + akp_align16(HIST_SIZE * sizeof(uint16_t));
    size_t o_prev = o_map + akp_align16(HIST_SIZE * sizeof(uint16_t));
    size_t total = o_prev + (desc->no_delta ? 0 : npx * 4);
    uint8_t* mem = (uint8_t*)akp_alloc(alloc, total);
    if (!mem) return AK_ERR_NO_MEMORY;
    ak_gif_writer* w = (ak_gif_writer*)mem;
    memset(w, 0, sizeof *w);
    if (alloc && alloc->alloc) {
        w->alloc = *alloc;
        w->has_alloc = true;
    }
    w->desc = *desc;
    if (w->desc.delay_cs == 0) w->desc.delay_cs = 4;
    w->indices = mem + o_idx;
    w->hist = (uint32_t*)(void*)(mem + o_hist);
    w->sum = (uint32_t*)(void*)(mem + o_sum);
    w->cells = (uint16_t*)(void*)(mem + o_cells);
    w->map = (uint16_t*)(void*)(mem + o_map);
    w->prev = desc->no_delta ? NULL : mem + o_prev;
    if (!(w->desc.frame_rate > 0.0f && w->desc.frame_rate <= 100.0f)) w->desc.frame_rate = 0.0f;
    int err = 0;
    /* Open the file ourselves: EGifOpenFileName creates it with mode 0600; users expect the
     * same permissions as any other output (0666 less the umask, as fopen gives). giflib
     * writes a temporary that finish renames over path (internal.h), so a failed run leaves
     * no partial GIF and never touches what path names. */
    int fd = ak_atomic_file_open_fd(&w->out, path);
    w->gif = fd >= 0 ? EGifOpenFileHandle(fd, &err) : NULL;
    if (!w->gif && fd >= 0) close(fd);
    if (!w->gif) {
        ak_atomic_file_abort(&w->out);
        akp_free(w->has_alloc ? &w->alloc : NULL, mem);
        return AK_ERR_IO;
    }
    EGifSetGifVersion(w->gif, true);
    bool ok = EGifPutScreenDesc(w->gif, desc->width, desc->height, 8, 0, NULL) == GIF_OK;
    /* Netscape application extension: loop count */
    unsigned char app[11] = {'N', 'E', 'T', 'S', 'C', 'A', 'P', 'E', '2', '.', '0'};
    unsigned char loop[3] = {1, (unsigned char)(desc->loop_count & 0xFF), (unsigned char)(desc->loop_count >> 8)};
    ok = ok && EGifPutExtensionLeader(w->gif, APPLICATION_EXT_FUNC_CODE) == GIF_OK;
    ok = ok && EGifPutExtensionBlock(w->gif, 11, app) == GIF_OK;
    ok = ok && EGifPutExtensionBlock(w->gif, 3, loop) == GIF_OK;
    ok = ok && EGifPutExtensionTrailer(w->gif) == GIF_OK;
    if (!ok) {
        EGifCloseFile(w->gif, &err);
        ak_atomic_file_abort(&w->out);
        akp_free(w->has_alloc ? &w->alloc : NULL, mem);
        return AK_ERR_IO;
    }
    *out_writer = w;
    return AK_OK;
}

/* Histogram of 15-bit cells (w->hist, w->sum) over the pixels of rows y0..y1, columns x0..x1;
 * with skip_unchanged, pixels equal to the previous frame's are left out. */
static void histogram(ak_gif_writer* w, const ak_image* frame, int x0, int y0, int x1, int y1, bool skip_unchanged);

/* Mean weighted squared distance (nearest's metric) from the histogram's pixels to their
 * palette entries, through w->map (filled as needed). */
static double hist_error(ak_gif_writer* w, const GifColorType* pal, int n) {
    double err = 0.0, count = 0.0;
    for (uint32_t c = 0; c < HIST_SIZE; ++c) {
        if (!w->hist[c]) continue;
        int r = (int)(((c >> 10) & 31) << 3) | 4, g = (int)(((c >> 5) & 31) << 3) | 4, b = (int)((c & 31) << 3) | 4;
        if (w->map[c] == 0xFFFF) w->map[c] = nearest(pal, n, r, g, b);
        const GifColorType* q = &pal[w->map[c]];
        double h = w->hist[c];
        double mr = w->sum[(size_t)c * 3] / h - q->Red, mg = w->sum[(size_t)c * 3 + 1] / h - q->Green,
               mb = w->sum[(size_t)c * 3 + 2] / h - q->Blue;
        err += h * (2.0 * mr * mr + 4.0 * mg * mg + mb * mb);
        count += h;
    }
    return count > 0.0 ? err / count : 0.0;
}

/* Same source RGB at (x, y) in frame and the writer's copy of the previous frame. */
static bool unchanged(const ak_gif_writer* w, const uint8_t* p, int x, int y) {
    const uint8_t* q = w->prev + ((size_t)y * (size_t)w->desc.width + (size_t)x) * 4u;
    return p[0] == q[0] && p[1] == q[1] && p[2] == q[2];
}

static void histogram(ak_gif_writer* w, const ak_image* frame, int x0, int y0, int x1, int y1, bool skip_unchanged) {
    memset(w->hist, 0, HIST_SIZE * sizeof(uint32_t));
    memset(w->sum, 0, HIST_SIZE * 3 * sizeof(uint32_t));
    for (int y = y0; y <= y1; ++y) {
        const uint8_t* p = ak_image_pixel(frame, x0, y);
        for (int x = x0; x <= x1; ++x, p += 4) {
            if (skip_unchanged && unchanged(w, p, x, y)) continue;
            uint16_t c = (uint16_t)(((p[0] >> 3) << 10) | ((p[1] >> 3) << 5) | (p[2] >> 3));
            w->hist[c]++;
            w->sum[(size_t)c * 3] += p[0];
            w->sum[(size_t)c * 3 + 1] += p[1];
            w->sum[(size_t)c * 3 + 2] += p[2];
        }
    }
}

ak_result ak_gif_writer_add_frame(ak_gif_writer* w, const ak_image* frame) {
    if (!w || !frame || !frame->pixels) return AK_ERR_NULL_ARG;
    if (!image_valid(frame) || frame->width != w->desc.width || frame->height != w->desc.height) return AK_ERR_BAD_ARG;
    if (w->failed) return AK_ERR_IO;
    const int W = frame->width, H = frame->height;
    const bool delta = w->prev && w->frames > 0;
    /* the rectangle that changed since the previous frame (all of it for the first) */
    int x0 = 0, y0 = 0, x1 = W - 1, y1 = H - 1;
    if (delta) {
        x0 = W, y0 = H, x1 = -1, y1 = -1;
        for (int y = 0; y < H; ++y) {
            const uint8_t* p = ak_image_pixel(frame, 0, y);
            for (int x = 0; x < W; ++x, p += 4) {
                if (unchanged(w, p, x, y)) continue;
                if (x < x0) x0 = x;
                if (x > x1) x1 = x;
                if (y < y0) y0 = y;
                y1 = y;
            }
        }
        if (x1 < 0) x0 = y0 = x1 = y1 = 0; /* nothing changed: one transparent pixel keeps the timing */
    }
    const int RW = x1 - x0 + 1, RH = y1 - y0 + 1;
    GifColorType palette[256];
    int n;
    const int transparent = delta ? 255 : NO_TRANSPARENT_COLOR;
    histogram(w, frame, x0, y0, x1, y1, delta);
    if (delta && hist_error(w, w->pal, w->pal_n) <= 2.0 * w->pal_err + 100.0) {
        /* the palette in use still fits what changed: keep it, so a pixel that returns to an
         * earlier colour gets the index it had (no patchwork of palettes on smooth areas) */
        memcpy(palette, w->pal, sizeof palette);
        n = w->pal_n;
    } else {
        /* a palette for the whole frame (255 entries when later frames need a transparent one) */
        if (delta) histogram(w, frame, 0, 0, W - 1, H - 1, false);
        memset(palette, 0, sizeof palette);
        n = median_cut(w, palette, w->prev ? 255 : 256);
        for (size_t i = 0; i < HIST_SIZE; ++i) w->map[i] = 0xFFFF;
        if (w->prev) {
            memcpy(w->pal, palette, sizeof palette);
            w->pal_n = n;
            w->pal_err = hist_error(w, palette, n);
        }
    }
    static const int bayer[4][4] = {{0, 8, 2, 10}, {12, 4, 14, 6}, {3, 11, 1, 9}, {15, 7, 13, 5}};
    for (int y = y0; y <= y1; ++y) {
        const uint8_t* p = ak_image_pixel(frame, x0, y);
        uint8_t* out = w->indices + (size_t)(y - y0) * (size_t)RW;
        for (int x = x0; x <= x1; ++x, p += 4) {
            if (delta && unchanged(w, p, x, y)) {
                out[x - x0] = (uint8_t)transparent;
                continue;
            }
            int d = w->desc.no_dither ? 0 : (bayer[y & 3][x & 3] - 8) / 2; /* -4..3 */
            int r = p[0] + d, g = p[1] + d, b = p[2] + d;
            r = r < 0 ? 0 : (r > 255 ? 255 : r);
            g = g < 0 ? 0 : (g > 255 ? 255 : g);
            b = b < 0 ? 0 : (b > 255 ? 255 : b);
            uint16_t c = (uint16_t)(((r >> 3) << 10) | ((g >> 3) << 5) | (b >> 3));
            if (w->map[c] == 0xFFFF) w->map[c] = nearest(palette, n, (r & ~7) | 4, (g & ~7) | 4, (b & ~7) | 4);
            out[x - x0] = (uint8_t)w->map[c];
        }
    }
    if (w->prev)
        for (int y = 0; y < H; ++y) memcpy(w->prev + (size_t)y * (size_t)W * 4u, ak_image_pixel(frame, 0, y), (size_t)W * 4u);
    GraphicsControlBlock gcb;
    memset(&gcb, 0, sizeof gcb);
    gcb.DisposalMode = DISPOSE_DO_NOT;
    gcb.DelayTime = w->desc.delay_cs;
    if (w->desc.frame_rate > 0.0f) {
        /* frame k ends at round(100 k / rate): delays alternate around 100 / rate */
        double end = floor(100.0 * (double)(w->frames + 1) / (double)w->desc.frame_rate + 0.5);
        int delay = (int)(end - w->shown_cs);
        if (delay < 1) delay = 1;
        gcb.DelayTime = delay;
        w->shown_cs += delay;
    }
    gcb.TransparentColor = transparent;
    GifByteType ext[4];
    size_t len = EGifGCBToExtension(&gcb, ext);
    ColorMapObject* cm = GifMakeMapObject(256, palette);
    if (!cm) return AK_ERR_NO_MEMORY;
    bool ok = EGifPutExtension(w->gif, GRAPHICS_EXT_FUNC_CODE, (int)len, ext) == GIF_OK;
    ok = ok && EGifPutImageDesc(w->gif, x0, y0, RW, RH, false, cm) == GIF_OK;
    for (int y = 0; ok && y < RH; ++y) ok = EGifPutLine(w->gif, w->indices + (size_t)y * (size_t)RW, RW) == GIF_OK;
    GifFreeMapObject(cm);
    if (!ok) {
        w->failed = true;
        return AK_ERR_IO;
    }
    ++w->frames;
    return AK_OK;
}

ak_result ak_gif_writer_finish(ak_gif_writer* w) {
    if (!w) return AK_ERR_NULL_ARG;
    ak_result res = AK_OK;
    if (w->frames == 0 && !w->failed) {
        /* keep the file decodable: one black frame */
        size_t npx = (size_t)w->desc.width * (size_t)w->desc.height;
        memset(w->indices, 0, npx);
        GifColorType pal[2] = {{0, 0, 0}, {0, 0, 0}};
        ColorMapObject* cm = GifMakeMapObject(2, pal);
        bool ok = cm && EGifPutImageDesc(w->gif, 0, 0, w->desc.width, w->desc.height, false, cm) == GIF_OK;
        for (int y = 0; ok && y < w->desc.height; ++y)
            ok = EGifPutLine(w->gif, w->indices + (size_t)y * (size_t)w->desc.width, w->desc.width) == GIF_OK;
        if (cm) GifFreeMapObject(cm);
        if (!ok) w->failed = true;
        res = AK_ERR_EMPTY;
    }
    int err = 0;
    bool complete = EGifCloseFile(w->gif, &err) == GIF_OK && !w->failed;
    if (!complete) res = AK_ERR_IO;
    /* a complete file (the blank one of AK_ERR_EMPTY too) goes into place; the rest is removed */
    if (complete && ak_atomic_file_rename(&w->out) != AK_OK) res = AK_ERR_IO;
    ak_atomic_file_abort(&w->out);
    ak_allocator a = w->alloc;
    akp_free(w->has_alloc ? &a : NULL, w);
    return res;
}

void ak_gif_writer_discard(ak_gif_writer* w) {
    if (!w) return;
    int err = 0;
    EGifCloseFile(w->gif, &err);
    ak_atomic_file_abort(&w->out);
    ak_allocator a = w->alloc;
    akp_free(w->has_alloc ? &a : NULL, w);
}

/* ---- public: GIF reader -------------------------------------------------------------------- */

static ak_result gif_slurp(const char* path, GifFileType** out) {
    FILE* f = fopen(path, "rb");
    if (!f) return AK_ERR_IO;
    fclose(f);
    int err = 0;
    GifFileType* g = DGifOpenFileName(path, &err);
    if (!g) return err == D_GIF_ERR_OPEN_FAILED ? AK_ERR_IO : AK_ERR_PARSE;
    if (DGifSlurp(g) != GIF_OK || g->ImageCount < 1 || g->SWidth < 1 || g->SHeight < 1) {
        DGifCloseFile(g, &err);
        return AK_ERR_PARSE;
    }
    *out = g;
    return AK_OK;
}

ak_result ak_gif_info(const char* path, int* out_width, int* out_height, int* out_frame_count) {
    if (!path || !out_width || !out_height || !out_frame_count) return AK_ERR_NULL_ARG;
    GifFileType* g = NULL;
    ak_result r = gif_slurp(path, &g);
    if (r != AK_OK) return r;
    *out_width = g->SWidth;
    *out_height = g->SHeight;
    *out_frame_count = g->ImageCount;
    int err = 0;
    DGifCloseFile(g, &err);
    return AK_OK;
}

ak_result ak_gif_read_frame(const char* path, int frame_index, const ak_image* out) {
    if (!path || !out || !out->pixels) return AK_ERR_NULL_ARG;
    if (!image_valid(out)) return AK_ERR_BAD_ARG;
    GifFileType* g = NULL;
    ak_result r = gif_slurp(path, &g);
    if (r != AK_OK) return r;
    int err = 0;
    if (frame_index < 0 || frame_index >= g->ImageCount) {
        DGifCloseFile(g, &err);
        return AK_ERR_BAD_INDEX;
    }
    if (g->SWidth != out->width || g->SHeight != out->height) {
        DGifCloseFile(g, &err);
        return AK_ERR_BAD_ARG;
    }
    uint8_t bg[4] = {0, 0, 0, 255};
    if (g->SColorMap && g->SBackGroundColor < g->SColorMap->ColorCount) {
        GifColorType c = g->SColorMap->Colors[g->SBackGroundColor];
        bg[0] = c.Red;
        bg[1] = c.Green;
        bg[2] = c.Blue;
    }
    for (int y = 0; y < out->height; ++y)
        for (int x = 0; x < out->width; ++x) memcpy(ak_image_pixel(out, x, y), bg, 4);
    for (int i = 0; i <= frame_index; ++i) {
        const SavedImage* si = &g->SavedImages[i];
        const ColorMapObject* cm = si->ImageDesc.ColorMap ? si->ImageDesc.ColorMap : g->SColorMap;
        GraphicsControlBlock gcb;
        memset(&gcb, 0, sizeof gcb);
        gcb.TransparentColor = NO_TRANSPARENT_COLOR;
        DGifSavedExtensionToGCB(g, i, &gcb);
        if (!cm || !si->RasterBits) continue;
        const GifImageDesc* d = &si->ImageDesc;
        for (int y = 0; y < d->Height; ++y) {
            int py = d->Top + y;
            if (py < 0 || py >= out->height) continue;
            for (int x = 0; x < d->Width; ++x) {
                int px = d->Left + x;
                if (px < 0 || px >= out->width) continue;
                int ci = si->RasterBits[(size_t)y * (size_t)d->Width + (size_t)x];
                if (ci == gcb.TransparentColor || ci >= cm->ColorCount) continue;
                uint8_t* p = ak_image_pixel(out, px, py);
                p[0] = cm->Colors[ci].Red;
                p[1] = cm->Colors[ci].Green;
                p[2] = cm->Colors[ci].Blue;
                p[3] = 255;
            }
        }
        if (i < frame_index && gcb.DisposalMode == DISPOSE_BACKGROUND) {
            for (int y = 0; y < d->Height; ++y)
                for (int x = 0; x < d->Width; ++x) {
                    int px = d->Left + x, py = d->Top + y;
                    if (px >= 0 && py >= 0 && px < out->width && py < out->height) memcpy(ak_image_pixel(out, px, py), bg, 4);
                }
        }
    }
    DGifCloseFile(g, &err);
    return AK_OK;
}
