/* animkit raster: a small software renderer that writes PNG and animated GIF files.
 *
 * What it does: the classic projection pipeline on the CPU. A look-at camera with a
 * perspective or orthographic projection, clipping against the near plane (crossing triangles
 * are cut, not dropped), optional back-face culling, a float z-buffer, perspective-correct
 * attribute interpolation and the top-left fill rule (adjacent triangles never leave a gap or
 * draw a pixel twice). Shading is unlit, flat, Gouraud or Phong with ambient + diffuse +
 * specular terms from a directional key light and a fill light, computed in linear light and
 * stored as sRGB. Per-vertex colours (weight heatmaps), depth-tested lines and points (bones,
 * joints, targets, particles), a ground plane with a grid and a soft shadow, supersampling
 * anti-aliasing, a built-in 5x7 bitmap font, simple 2D drawing on RGBA8 images (plots),
 * PNG read/write (libpng) and animated GIF read/write (giflib, own palette quantizer).
 *
 * Base-colour textures: per-vertex UVs (texture coordinate (0, 0) at the image's top-left
 * corner, glTF's rule) interpolated perspective-correctly, REPEAT / CLAMP / MIRROR wrapping,
 * nearest or bilinear filtering (filtered in linear light for lit shading), chosen per
 * triangle between a minification and a magnification filter (no mipmaps).
 *
 * Camera-facing textured sprites (billboards: particles, fire, smoke) with sprite sheets,
 * alpha or additive blending and a back-to-front sort.
 *
 * What it does NOT do: mipmaps, normal or other maps, sorting of transparent meshes, shadows
 * other than on the ground plane, MP4 output (ak_image_format_available says what this build
 * can write), windows.
 *
 * Usage:
 *     ak_raster* r = NULL;
 *     ak_raster_desc d = { .width = 640, .height = 480, .supersample = 2 };
 *     if (ak_raster_create(&d, NULL, &r) != AK_OK) return 1;
 *     ak_raster_camera cam = ak_raster_camera_perspective(ak_vec3_make(3, 2, 4), ak_vec3_zero(),
 *                                                         ak_radians(40), 640.0f / 480.0f, 0.1f, 100);
 *     ak_raster_clear(r, ak_vec4_make(0.85f, 0.88f, 0.93f, 1), ak_vec4_make(0.55f, 0.58f, 0.64f, 1));
 *     ak_raster_mesh m = { .positions = pos, .normals = nrm, .indices = idx };   // spans
 *     ak_raster_draw_ground(r, &cam, &(ak_raster_ground){ .casters = &m, .caster_count = 1 });
 *     ak_raster_draw_mesh(r, &cam, &m);
 *     uint8_t* px = malloc(640 * 480 * 4);
 *     ak_image img = { .pixels = px, .width = 640, .height = 480 };
 *     ak_raster_resolve(r, &img);                 // box-filters the supersamples into img
 *     ak_png_write("out.png", &img);
 *     ak_raster_destroy(r); free(px);
 *
 * Colours: every colour in this API is an sRGB display value in [0, 1] (what a colour picker
 * shows), alpha linear. Lighting converts to linear light, shades, and converts back.
 *
 * Coordinates: world space is right-handed, Y up. Image pixel (0, 0) is the top-left corner;
 * pixel (x, y) covers [x, x+1) x [y, y+1) and is sampled at its centre (x + 0.5, y + 0.5).
 *
 * Ownership and threading: ak_raster is a render target: it owns its colour, depth and
 * scratch buffers (allocated once by create, never afterwards) and draw calls change it, so
 * one thread at a time may use a given target; different targets are independent. A draw
 * call may split its work over desc.thread_count threads that it starts and joins before
 * returning. ak_image pixels are always caller-owned. Nothing keeps a caller pointer after a
 * call returns, except ak_gif_writer, which keeps its open file until ak_gif_writer_finish.
 */
#ifndef ANIMKIT_RASTER_H
#define ANIMKIT_RASTER_H

#include "math.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- images --------------------------------------------------------------------------- */

/* A caller-owned RGBA8 image (sRGB colour, straight alpha), rows top to bottom. */
typedef struct ak_image {
    uint8_t* pixels; /* required; at least stride * height bytes */
    int width;       /* pixels, > 0 */
    int height;      /* pixels, > 0 */
    size_t stride;   /* bytes from one row to the next; 0 -> width * 4 */
} ak_image;

/* Pointer to pixel (x, y) (no bounds check; callers keep 0 <= x < width, 0 <= y < height). */
static inline uint8_t* ak_image_pixel(const ak_image* image, int x, int y) {
    size_t stride = image->stride ? image->stride : (size_t)image->width * 4u;
    return image->pixels + (size_t)y * stride + (size_t)x * 4u;
}

/* Pack an sRGB colour in [0,1] (clamped; NaN -> 0) as bytes r, g, b, a. */
AK_API void ak_color_to_rgba8(ak_vec4 color, uint8_t out_rgba[4]);
/* sRGB display value -> linear light (the exact piecewise sRGB curve), and back. */
AK_API float ak_srgb_to_linear(float srgb);
AK_API float ak_linear_to_srgb(float linear);

/* Fill the whole image with one colour. AK_ERR_NULL_ARG / AK_ERR_BAD_ARG (size <= 0). */
AK_API ak_result ak_image_fill(const ak_image* image, ak_vec4 color);
/* Alpha-blend a filled axis-aligned rectangle [x, x+w) x [y, y+h), clipped to the image, with
 * fractional edge coverage. Non-finite values draw nothing. AK_ERR_NULL_ARG, AK_ERR_BAD_ARG
 * (image size <= 0). The other 2D calls below return the same codes. */
AK_API ak_result ak_image_fill_rect(const ak_image* image, float x, float y, float w, float h, ak_vec4 color);
/* Alpha-blend an anti-aliased line segment between pixel-space points (pixel centres at
 * +0.5) of the given width in pixels (<= 0 -> 1). Non-finite endpoints draw nothing. */
AK_API ak_result ak_image_draw_line(const ak_image* image, ak_vec2 a, ak_vec2 b, float width, ak_vec4 color);
/* Alpha-blend an anti-aliased filled disc (radius in pixels); outline_width > 0 also draws a
 * ring of outline_color around it. */
AK_API ak_result ak_image_draw_disc(const ak_image* image, ak_vec2 center, float radius, ak_vec4 color,
                                    float outline_width, ak_vec4 outline_color);
/* Copy src into dst with its top-left corner at (x, y), clipped; alpha ignored (opaque copy). */
AK_API ak_result ak_image_blit(const ak_image* dst, int x, int y, const ak_image* src);

/* ---- text ----------------------------------------------------------------------------- */

/* Glyph cell of the built-in font: 5x7 pixels in a 6x9 advance, printable ASCII only
 * (other bytes draw as '?'). '\n' starts a new line. */
#define AK_FONT_GLYPH_WIDTH 5
#define AK_FONT_GLYPH_HEIGHT 7
#define AK_FONT_ADVANCE_X 6
#define AK_FONT_ADVANCE_Y 9

/* The 7 row bitmaps of an ASCII character; bit 4 is the leftmost column. Non-printable ->
 * the '?' glyph. out_rows needs 7 bytes. */
AK_API void ak_font_glyph(char c, uint8_t out_rows[7]);
/* Size in pixels of text drawn at an integer scale (0 -> 1, above 64 -> 64): the widest line times
 * AK_FONT_ADVANCE_X * scale (minus the trailing gap) and the line count times
 * AK_FONT_ADVANCE_Y * scale (minus the gap). NULL or "" -> 0 x 0. */
AK_API void ak_text_size(const char* text, int scale, int* out_width, int* out_height);
/* Alpha-blend text with its top-left corner at pixel (x, y), each font pixel a scale x scale
 * block (0 -> 1, above 64 -> 64). Clipped to the image. AK_ERR_NULL_ARG for a NULL image or text. */
AK_API ak_result ak_image_draw_text(const ak_image* image, int x, int y, const char* text, int scale,
                                    ak_vec4 color);

/* ---- camera --------------------------------------------------------------------------- */

/* World -> clip transform pair (OpenGL conventions: the camera looks down -Z in view space,
 * clip-space depth maps to NDC z in [-1, 1]). The viewport maps NDC x in [-1,1] to image
 * x in [0, width] and NDC y in [-1,1] to image y in [height, 0]. */
typedef struct ak_raster_camera {
    ak_mat4 view;       /* world -> view (rigid) */
    ak_mat4 projection; /* view -> clip */
} ak_raster_camera;

/* Look-at camera at eye with a perspective projection (fovy in radians, aspect = width /
 * height). Degenerate values get math.h's documented fallbacks. */
AK_API ak_raster_camera ak_raster_camera_perspective(ak_vec3 eye, ak_vec3 target, float fovy, float aspect,
                                                     float near_z, float far_z);
/* Look-at camera with an orthographic projection showing half_height world units above and
 * below the target (half width = half_height * aspect). */
AK_API ak_raster_camera ak_raster_camera_orthographic(ak_vec3 eye, ak_vec3 target, float half_height,
                                                      float aspect, float near_z, float far_z);
/* Image-space position of a world point: x, y in pixels (image of width x height, pixel
 * centres at +0.5) and z the depth in [0, 1] (0 near plane, 1 far plane). Returns false (and
 * writes nothing) when the point is behind the near plane or not finite. */
AK_API bool ak_raster_camera_project(const ak_raster_camera* camera, int width, int height, ak_vec3 world,
                                     ak_vec3* out_pixel);

/* ---- render target -------------------------------------------------------------------- */

typedef struct ak_raster_desc {
    int width;        /* output image width in pixels; required, 1..8192 */
    int height;       /* output image height in pixels; required, 1..8192 */
    int supersample;  /* samples per pixel along each axis, 1..4; 0 -> 1 (no anti-aliasing) */
    int thread_count; /* threads a draw call may use, 1..64; 0 -> 1 (the calling thread only);
                         draws of fewer than 256 primitives always use one */
} ak_raster_desc;

typedef struct ak_raster ak_raster;

/* desc with its zero fields replaced by their documented defaults (not range-checked). */
AK_API ak_raster_desc ak_raster_desc_resolved(const ak_raster_desc* desc);
/* Create a render target (one allocation: RGBA8 colour + float depth at width*supersample x
 * height*supersample, a 2 x 256 KiB shadow map, and about 1.2 MiB of set-up scratch per thread
 * when thread_count > 1). The target starts cleared to opaque black.
 * Returns AK_ERR_NULL_ARG, AK_ERR_BAD_ARG (a field out of range), AK_ERR_NO_MEMORY;
 * *out_raster is NULL on failure. */
AK_API ak_result ak_raster_create(const ak_raster_desc* desc, const ak_allocator* alloc, ak_raster** out_raster);
/* The bytes of that one allocation for desc (what ak_raster_create asks alloc for: callers
 * that create targets from their own scratch, through an allocator over it); 0 when desc is
 * NULL or a field is out of range. */
AK_API size_t ak_raster_memory_size(const ak_raster_desc* desc);
/* Free a target; NULL is a no-op. */
AK_API void ak_raster_destroy(ak_raster* raster);
/* The resolved desc the target was created with (zeros if raster is NULL). */
AK_API ak_raster_desc ak_raster_get_desc(const ak_raster* raster);

/* Reset depth to the far plane and fill colour with a vertical gradient from top to bottom
 * (pass the same colour twice for a flat fill). NULL raster is a no-op. */
AK_API void ak_raster_clear(ak_raster* raster, ak_vec4 top_color, ak_vec4 bottom_color);
/* Reset only the depth buffer (draw an overlay that must not be hidden). NULL is a no-op. */
AK_API void ak_raster_clear_depth(ak_raster* raster);

/* Box-filter the supersamples into out (out->width/height must equal the desc's) averaging in
 * linear light. Returns AK_ERR_NULL_ARG or AK_ERR_BAD_ARG (size mismatch). */
AK_API ak_result ak_raster_resolve(const ak_raster* raster, const ak_image* out);

/* Copy the target's sample buffers out, unfiltered (width * supersample by height *
 * supersample samples, rows top to bottom): out_color gets RGBA8 sRGB bytes (4 per sample),
 * out_depth the depth per sample in [0, 1] (1: cleared, nothing drawn). Either span may be
 * empty (not read). With UNLIT shading and per-vertex or material colours that are exact
 * bytes (k / 255), opaque samples hold those bytes exactly: flat colours can carry integer ids
 * (an id buffer; see crowd.h's raster view). Depth is NDC z * 0.5 + 0.5; for a perspective
 * projection (near n, far f) the distance along the view axis is 2 n f / (f + n - (2 d - 1)
 * (f - n)). Returns AK_ERR_NULL_ARG (raster NULL, or a non-empty span without ptr),
 * AK_ERR_SPAN_SMALL (a non-empty span shorter than the sample count, times 4 for colour). */
AK_API ak_result ak_raster_read_samples(const ak_raster* raster, ak_u8_span out_color, ak_f32_span out_depth);

/* ---- lighting and materials ----------------------------------------------------------- */

typedef enum ak_shading {
    AK_SHADING_DEFAULT = 0, /* -> PHONG */
    AK_SHADING_PHONG,       /* per-pixel normal and lighting */
    AK_SHADING_GOURAUD,     /* lighting at the vertices, colour interpolated */
    AK_SHADING_FLAT,        /* one face normal per triangle */
    AK_SHADING_UNLIT        /* colour written as given (no lighting, no gamma round trip) */
} ak_shading;

typedef enum ak_blend {
    AK_BLEND_DEFAULT = 0, /* -> OPAQUE */
    AK_BLEND_OPAQUE,      /* replace colour, write depth */
    AK_BLEND_ALPHA,       /* src * a + dst * (1 - a) on sRGB bytes, depth tested, not written */
    AK_BLEND_ADD          /* dst + src byte-wise, saturating, depth tested, not written
                             (with UNLIT colour 1/255 each write adds exactly 1: a coverage
                             counter for tests) */
} ak_blend;

/* Two directional lights plus ambient. Directions point FROM the light (the way the light
 * travels), world space, need not be unit. Colours are linear intensities. */
typedef struct ak_raster_lighting {
    ak_vec3 key_direction;  /* zero -> (0.4, -0.6, -0.7): from the upper left, in front */
    ak_vec3 key_color;      /* zero -> (1.05, 1.0, 0.94), warm white */
    ak_vec3 fill_direction; /* zero -> (-0.7, -0.25, -0.3): from the right, low */
    ak_vec3 fill_color;     /* zero -> (0.30, 0.34, 0.44), cool; a tiny value for none */
    ak_vec3 ambient_color;  /* zero -> (0.20, 0.22, 0.26), times 0.6..1 by normal.y */
} ak_raster_lighting;

/* The lighting with zero fields replaced by defaults; NULL gives the full default rig. */
AK_API ak_raster_lighting ak_raster_lighting_resolved(const ak_raster_lighting* lighting);

typedef struct ak_raster_material {
    ak_vec4 color;    /* sRGB base colour; all zero -> clay (0.78, 0.74, 0.70, 1) */
    float specular;   /* specular strength 0..1; 0 -> 0.25 (use a negative value for none) */
    float shininess;  /* Phong exponent; 0 -> 32 */
} ak_raster_material;

/* How texture coordinates outside [0, 1] map to texels. */
typedef enum ak_raster_wrap {
    AK_RASTER_WRAP_REPEAT = 0, /* the fractional part (default) */
    AK_RASTER_WRAP_CLAMP,      /* clamped to the edge texels */
    AK_RASTER_WRAP_MIRROR      /* repeated, every other copy mirrored */
} ak_raster_wrap;

typedef enum ak_raster_filter {
    AK_RASTER_FILTER_LINEAR = 0, /* bilinear between the 4 nearest texel centres (default) */
    AK_RASTER_FILTER_NEAREST     /* the texel that holds the point */
} ak_raster_filter;

/* A base-colour texture: the caller's RGBA8 image (sRGB colour, straight alpha), read during
 * draw calls only. Texel (i, j) covers u in [i/width, (i+1)/width) and v in [j/height,
 * (j+1)/height): (u, v) = (0, 0) is the image's top-left corner. */
typedef struct ak_raster_texture {
    ak_image image;             /* required */
    ak_raster_wrap wrap_u, wrap_v;
    ak_raster_filter mag_filter; /* a triangle showing fewer texels than samples it covers */
    ak_raster_filter min_filter; /* a triangle showing more texels than samples it covers */
} ak_raster_texture;

/* ---- draw calls ----------------------------------------------------------------------- */

/* A triangle mesh. Triangles are counter-clockwise seen from their front. */
typedef struct ak_raster_mesh {
    ak_vec3_cspan positions; /* required; model space */
    ak_vec3_cspan normals;   /* model space, count == positions.count; empty -> face normals
                                (every shading mode then looks flat) */
    ak_vec4_cspan colors;    /* per-vertex sRGB colours multiplying material.color; empty -> none */
    ak_u32_cspan indices;    /* 3 per triangle; empty -> positions taken three at a time */
    const ak_mat4* model;    /* model -> world; NULL -> identity */
    ak_raster_material material;
    const ak_raster_lighting* lighting; /* NULL -> ak_raster_lighting_resolved(NULL) */
    ak_shading shading;      /* DEFAULT -> PHONG */
    ak_blend blend;          /* DEFAULT -> OPAQUE */
    bool cull_back_faces;    /* false -> both sides drawn and lit on the side facing the camera */
    bool no_depth_test;      /* false -> z-buffered; true -> always drawn (depth still written when opaque) */
    ak_vec2_cspan uvs;       /* texture coordinates, count == positions.count; used with texture */
    const ak_raster_texture* texture; /* base colour texture (with uvs; NULL or no uvs -> none):
                                the colour is material.color x vertex colour x texel, multiplied
                                in linear light when lit (PHONG exactly: the texel scales the
                                albedo; GOURAUD and FLAT scale the lit colour), as sRGB values
                                when UNLIT; the texel's alpha multiplies the alpha */
} ak_raster_mesh;

/* Draw a triangle mesh. Triangles with a non-finite vertex are skipped (counted nowhere, no
 * error: the rest still draws). Returns AK_ERR_NULL_ARG (raster, camera or mesh NULL, or
 * positions empty), AK_ERR_BAD_ARG (indices.count not a multiple of 3, normals/colours count
 * mismatch, bad enum, a uvs count other than positions.count, a texture whose image has no
 * pixels, a size <= 0, a stride below width * 4 or a bad wrap/filter), AK_ERR_BAD_INDEX (an
 * index >= positions.count), AK_ERR_BAD_DATA (a non-finite camera or model matrix); nothing is
 * drawn on error. A non-finite UV reads as (0, 0). */
AK_API ak_result ak_raster_draw_mesh(ak_raster* raster, const ak_raster_camera* camera, const ak_raster_mesh* mesh);

/* Depth-tested (or on-top) lines: screen-space ribbons of constant pixel width. */
typedef struct ak_raster_lines {
    ak_vec3_cspan positions; /* required; model space */
    ak_u32_cspan indices;    /* 2 per segment; empty -> positions taken two at a time */
    ak_vec4_cspan colors;    /* per-vertex sRGB colours; empty -> color */
    ak_vec4 color;           /* sRGB; all zero -> opaque black */
    float width;             /* pixels of the output image; 0 -> 2, at most 256 */
    const ak_mat4* model;    /* NULL -> identity */
    bool on_top;             /* false -> depth-tested; true -> drawn over everything */
} ak_raster_lines;

/* Draw line segments, clipped against the near plane. Non-finite segments are skipped; without
 * indices an odd last position is ignored. Returns AK_ERR_NULL_ARG, AK_ERR_BAD_ARG (odd
 * indices.count, colour count mismatch), AK_ERR_BAD_INDEX, AK_ERR_BAD_DATA (non-finite camera
 * or model matrix). */
AK_API ak_result ak_raster_draw_lines(ak_raster* raster, const ak_raster_camera* camera, const ak_raster_lines* lines);

/* Depth-tested round points (joints, targets, particles) with a darker outline. */
typedef struct ak_raster_points {
    ak_vec3_cspan positions; /* required; model space */
    ak_vec4_cspan colors;    /* per-point sRGB colours; empty -> color */
    ak_vec4 color;           /* sRGB; all zero -> opaque black */
    float radius;            /* pixels of the output image; 0 -> 4, at most 256 */
    float outline;           /* outline width in pixels; 0 -> none, at most 256 */
    const ak_mat4* model;    /* NULL -> identity */
    bool on_top;             /* false -> depth-tested; true -> drawn over everything */
} ak_raster_points;

/* Draw points; points behind the near plane or non-finite are skipped.
 * Returns AK_ERR_NULL_ARG, AK_ERR_BAD_ARG (colour count mismatch), AK_ERR_BAD_DATA (non-finite
 * camera or model matrix). */
AK_API ak_result ak_raster_draw_points(ak_raster* raster, const ak_raster_camera* camera,
                                       const ak_raster_points* points);

/* A horizontal ground plane with a grid and a soft shadow of the casters, fading out into
 * the background towards its edge. Draw it after clear and before the meshes. */
typedef struct ak_raster_ground {
    float height;           /* world Y of the plane; 0 is the usual floor */
    ak_vec3 center;         /* world; only x and z are used */
    float half_extent;      /* metres from center to the fade-out edge; 0 -> 4 */
    float grid_spacing;     /* metres between grid lines; 0 -> half_extent / 8 */
    ak_vec4 color;          /* sRGB plane colour; all zero -> (0.80, 0.80, 0.78) */
    ak_vec4 line_color;     /* sRGB grid lines; all zero -> (0.55, 0.56, 0.58) */
    const ak_raster_mesh* casters; /* meshes whose shadow falls on the plane; NULL -> none */
    size_t caster_count;
    float shadow_softness;  /* blur radius in metres; 0 -> half_extent / 40 */
    float shadow_strength;  /* darkening under a touching caster, 0..1; 0 -> 0.55 */
    const ak_raster_lighting* lighting; /* key light direction casts the shadow; NULL -> default */
} ak_raster_ground;

/* Draw the ground. Returns AK_ERR_NULL_ARG, AK_ERR_BAD_ARG (a non-finite or negative size
 * field), AK_ERR_BAD_DATA (non-finite camera), and AK_ERR_NULL_ARG / AK_ERR_BAD_ARG /
 * AK_ERR_BAD_INDEX / AK_ERR_BAD_DATA for a bad caster (as ak_raster_draw_mesh). The shadow map
 * is 256x256 texels over the plane, rendered on the calling thread. */
AK_API ak_result ak_raster_draw_ground(ak_raster* raster, const ak_raster_camera* camera,
                                       const ak_raster_ground* ground);

/* Text in output-image pixels (top-left corner at x, y) drawn into the target over
 * everything (scale 0 -> 1). AK_ERR_NULL_ARG for NULL raster or text. */
AK_API ak_result ak_raster_draw_text(ak_raster* raster, int x, int y, const char* text, int scale, ak_vec4 color);

/* ---- sprites (camera-facing billboards) ------------------------------------------------- */

/* Built-in sprite textures (ak_sprite_texture_generate). */
typedef enum ak_sprite_texture {
    AK_SPRITE_TEXTURE_DISC = 0, /* white soft disc: alpha (1 - r^2)^2 inside the unit circle */
    AK_SPRITE_TEXTURE_PUFF,     /* white puff: the soft disc times seeded lumpy value noise,
                                   for smoke and vegetation-like clumps */
    AK_SPRITE_TEXTURE_SOLID,    /* opaque white square (tests, debugging) */
    AK_SPRITE_TEXTURE_COUNT
} ak_sprite_texture;

/* Fill out (any size, RGBA8 straight alpha, white colour) with a built-in sprite texture; seed
 * varies the puff's lumps. AK_ERR_NULL_ARG, AK_ERR_BAD_ARG (size <= 0, bad kind). */
AK_API ak_result ak_sprite_texture_generate(ak_sprite_texture kind, uint32_t seed, const ak_image* out);

/* Camera-facing square quads (spherical billboards: their sides follow the camera's right and
 * up axes, so a sprite's projection is an axis-aligned square in the image), textured and
 * tinted, depth tested against what is drawn, blended in the given order. */
typedef struct ak_raster_sprites {
    ak_vec3_cspan positions;  /* required; world-space centres */
    ak_f32_cspan sizes;       /* per-sprite side length in metres (count == positions.count);
                                 empty -> size */
    float size;               /* metres; 0 -> 0.1 */
    ak_vec4_cspan colors;     /* per-sprite sRGB tint, alpha multiplies the texture's; empty -> color */
    ak_vec4 color;            /* all zero -> opaque white */
    ak_u32_cspan frames;      /* per-sprite sprite-sheet frame (row-major from the top left,
                                 taken modulo the frame count); empty -> frame 0 */
    ak_u32_cspan order;       /* indices into positions in drawing order (ak_raster_sprites_sort
                                 gives back to front); empty -> 0, 1, ..., count - 1 */
    const ak_image* texture;  /* RGBA8 straight alpha, sampled bilinearly; NULL -> the DISC
                                 texture computed per sample */
    int sheet_columns;        /* frames across the texture; 0 -> 1 */
    int sheet_rows;           /* frames down the texture; 0 -> 1 */
    ak_blend blend;           /* DEFAULT -> ALPHA (src * a + dst * (1 - a) on sRGB bytes, depth
                                 tested, not written); ADD (dst + src * a, saturating, not
                                 written); OPAQUE (alpha-tested at 0.5, depth written) */
} ak_raster_sprites;

/* Draw sprites; sprites with a non-finite centre, size or colour, of size <= 0, or reaching
 * behind the near plane are skipped. Runs on the calling thread (blending needs the order).
 * Returns AK_ERR_NULL_ARG (raster, camera or sprites NULL, positions empty), AK_ERR_BAD_ARG
 * (a count mismatch, sheet size outside 1..4096, a texture without pixels or smaller than the
 * sheet, bad blend), AK_ERR_BAD_INDEX (an order entry >= positions.count), AK_ERR_BAD_DATA
 * (non-finite camera). Nothing is drawn on error. */
AK_API ak_result ak_raster_draw_sprites(ak_raster* raster, const ak_raster_camera* camera,
                                        const ak_raster_sprites* sprites);

/* Back-to-front order of positions for the camera: out_order gets 0..count-1 sorted by
 * decreasing distance along the view direction (ties by index; non-finite points first).
 * scratch_depth and out_order need positions.count entries. Never allocates.
 * AK_ERR_NULL_ARG, AK_ERR_BAD_ARG (a span too small), AK_ERR_BAD_DATA (non-finite camera). */
AK_API ak_result ak_raster_sprites_sort(const ak_raster_camera* camera, ak_vec3_cspan positions,
                                        ak_f32_span scratch_depth, ak_u32_span out_order);

/* ---- files ---------------------------------------------------------------------------- */

typedef enum ak_image_format {
    AK_IMAGE_FORMAT_PNG = 0, /* libpng: write and read */
    AK_IMAGE_FORMAT_GIF,     /* giflib: animated write and read */
    AK_IMAGE_FORMAT_MP4      /* never available in this build (no encoder linked) */
} ak_image_format;

/* Whether this build can write the format. */
AK_API bool ak_image_format_available(ak_image_format format);
/* Space-separated list of writable formats, e.g. "png gif"; never NULL. */
AK_API const char* ak_image_formats_string(void);

/* Write an RGBA8 PNG, whole or not at all: to a temporary ".NAME.XXXXXX" beside path, renamed
 * over path once complete (a symlink at path is replaced, not followed); on a failure the
 * temporary is removed and path is left untouched. AK_ERR_NULL_ARG, AK_ERR_BAD_ARG
 * (size <= 0), AK_ERR_IO. */
AK_API ak_result ak_png_write(const char* path, const ak_image* image);
/* Size of a PNG file. AK_ERR_NULL_ARG, AK_ERR_IO (cannot open), AK_ERR_PARSE (not a PNG). */
AK_API ak_result ak_png_info(const char* path, int* out_width, int* out_height);
/* Decode a PNG (any colour type, converted to RGBA8) into out, whose size must match the file
 * (see ak_png_info). AK_ERR_NULL_ARG, AK_ERR_IO, AK_ERR_PARSE, AK_ERR_BAD_ARG (size mismatch). */
AK_API ak_result ak_png_read(const char* path, const ak_image* out);

typedef struct ak_gif_writer ak_gif_writer;

typedef struct ak_gif_desc {
    int width;          /* required, 1..65535 */
    int height;         /* required, 1..65535 */
    int delay_cs;       /* delay between frames in 1/100 s; 0 -> 4 (25 fps) */
    int loop_count;     /* 0 -> loop forever (GIF's own meaning of 0); N -> play N+1 times */
    bool no_dither;     /* false -> 4x4 ordered dithering hides palette banding */
    float frame_rate;   /* > 0 (up to 100): frames per second, delay_cs ignored; GIF delays are whole
                           1/100 s, so frame k (from 1) ends at round(100 k / frame_rate) and the
                           delays alternate (24 fps: 4,4,5,4,4,4 cs; average 1/24 s), each at
                           least 1; 0 or not finite -> delay_cs */
    bool no_delta;      /* false -> after the first frame, pixels equal to the previous frame's
                           (source RGB) are written transparent, each frame is cropped to the
                           rectangle that changed, and its palette is built from the changed
                           pixels only: a still background costs almost nothing. true -> every
                           frame whole and opaque */
} ak_gif_desc;

/* Start a GIF for path and write its header. AK_ERR_NULL_ARG, AK_ERR_BAD_ARG, AK_ERR_IO,
 * AK_ERR_NO_MEMORY. The frames go to a temporary ".NAME.XXXXXX" beside path, which the writer
 * owns until ak_gif_writer_finish; path itself is not touched before then. */
AK_API ak_result ak_gif_writer_create(const char* path, const ak_gif_desc* desc, const ak_allocator* alloc,
                                      ak_gif_writer** out_writer);
/* Quantize frame to its own 256-colour palette (median cut; 255 and a transparent entry for
 * delta frames, see ak_gif_desc) and append it. The frame's size must equal the desc's; alpha
 * is ignored. AK_ERR_NULL_ARG, AK_ERR_BAD_ARG, AK_ERR_IO,
 * AK_ERR_NO_MEMORY (giflib's colour map). */
AK_API ak_result ak_gif_writer_add_frame(ak_gif_writer* writer, const ak_image* frame);
/* Close the file and free the writer (always, even on error). A complete file is renamed over
 * path (a symlink there is replaced, not followed); otherwise the temporary is removed and
 * path is left untouched. AK_ERR_IO when the file could not be completed (a write failed
 * earlier, or now), AK_ERR_EMPTY when no frame was added (the file is still valid-ish: one
 * blank frame is written, and it is renamed into place). NULL -> AK_ERR_NULL_ARG. */
AK_API ak_result ak_gif_writer_finish(ak_gif_writer* writer);
/* Abandon the file: close it, remove the temporary and free the writer; path is left untouched
 * (for a run that failed after some frames: a partial animation must not take the output's
 * place). NULL is a no-op. */
AK_API void ak_gif_writer_discard(ak_gif_writer* writer);
/* Size and frame count of a GIF file. AK_ERR_NULL_ARG, AK_ERR_IO, AK_ERR_PARSE. */
AK_API ak_result ak_gif_info(const char* path, int* out_width, int* out_height, int* out_frame_count);
/* Decode frame frame_index (composited over the earlier frames as a viewer shows it) into out
 * (size must match). AK_ERR_NULL_ARG, AK_ERR_IO, AK_ERR_PARSE, AK_ERR_BAD_INDEX, AK_ERR_BAD_ARG. */
AK_API ak_result ak_gif_read_frame(const char* path, int frame_index, const ak_image* out);

#ifdef __cplusplus
}
#endif
#endif /* ANIMKIT_RASTER_H */
