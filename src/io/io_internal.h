/* Helpers shared by the io readers (src/io.c, src/io/gltf.c, src/io/bvh.c, src/io/obj.c,
 * src/io/assimp.c); never installed. */
#ifndef ANIMKIT_IO_INTERNAL_H
#define ANIMKIT_IO_INTERNAL_H

#include <animkit/clip.h>
#include <animkit/io.h>

#include "../internal.h"

/* Most nodes a file may have: the most joints a skeleton holds. */
#define AKP_IO_MAX_NODES AK_SKELETON_MAX_JOINTS
/* Most elements an accessor (or Assimp array) may declare; guards allocations against
 * absurd counts in corrupt files. */
#define AKP_IO_MAX_ELEMENTS (1u << 26)

/* Largest texture image side the decoders accept (the pixels are also charged to the budget). */
#define AKP_IO_MAX_IMAGE_SIDE 16384

/* Memory budget of one load: every large allocation is charged before it is made. */
typedef struct akp_budget {
    size_t limit, used;
} akp_budget;

/* The budget of a load whose input is input_size bytes: desc->memory_budget, or when 0
 * the larger of AK_IO_DEFAULT_BUDGET and AK_IO_BUDGET_INPUT_FACTOR x input_size. */
akp_budget akp_io_budget(const ak_io_desc* desc, size_t input_size);

/* Charge n bytes (a * b, checked for overflow) to the budget. false -> over budget (nothing
 * charged); the caller reports it as AK_ERR_UNSUPPORTED. */
bool akp_budget_take(akp_budget* b, size_t a, size_t n);

/* Read a file through alloc (a NUL byte is appended). want 0: the whole file, which must fit
 * the budget (charged); want > 0: exactly the first want bytes (charged), and a file shorter
 * than that is AK_ERR_PARSE. Returns AK_ERR_IO (diag names the file), AK_ERR_UNSUPPORTED
 * (over budget), AK_ERR_NO_MEMORY. */
ak_result akp_io_read_file(const char* path, const ak_allocator* alloc, size_t want, akp_budget* budget,
                           uint8_t** out_data, size_t* out_size, ak_diag* diag);

/* Nodes of a file in file order: name (NULL or "" -> "node_<i>"), parent (-1 root, any order),
 * rest transform, optional inverse bind. Builds scene->skeleton (parents first, unique names:
 * a repeated name becomes "<name>#<i>") and writes out_joint_of_node[i] (count entries).
 * Returns the codes of ak_skeleton_reorder / ak_skeleton_create. */
typedef struct akp_io_node {
    const char* name;
    int32_t parent;
    ak_transform rest;
    const ak_mat4* inverse_bind; /* NULL -> inverse of the rest world matrix */
} akp_io_node;
ak_result akp_io_build_skeleton(ak_scene* scene, const akp_io_node* nodes, size_t count, int32_t* out_joint_of_node,
                                const char* path, ak_diag* diag);

/* Split an affine matrix into T * R * S (no shear assumed; a negative determinant flips the
 * x scale). Degenerate columns give scale 0 and the rotation of the remaining frame. */
ak_transform akp_io_decompose(ak_mat4 m);

/* Clean skin weights read with stride src_influences (joints/weights arrays of
 * vertex_count * src_influences, modified) into mesh (already created with
 * influence_count <= src_influences): limit, renormalise, copy. */
void akp_io_store_weights(ak_mesh* mesh, uint16_t* joints, float* weights, uint32_t src_influences,
                          const ak_io_desc* desc);

/* Resolve path (relative to base_dir, or absolute) to a canonical path in out, following
 * "..", "." and symlinks component by component, and looking at nothing outside base_dir and
 * desc->extra_roots (unless desc->allow_any_path): a path that leaves them is refused before
 * anything there is stat'ed or opened, so the answer does not depend on what exists outside.
 * Returns AK_OK, AK_ERR_IO with *out_leaves true (the path leaves the model's folder) or
 * false (missing inside the folder, a symlink loop, too long). */
ak_result akp_io_resolve_inside(const char* base_dir, const char* path, const ak_io_desc* desc, char* out,
                                size_t out_size, bool* out_leaves);

/* Rewrite a message in place so that it holds only printable ASCII and valid UTF-8 (other
 * bytes become "\xNN", truncated to size): messages quote the file's own words, and a
 * file's raw bytes must never reach a terminal or a JSON report. */
void akp_io_sanitize(char* msg, size_t size);

/* Is s (n bytes) valid UTF-8 (no overlong forms, no surrogates, at most U+10FFFF)? */
bool akp_io_utf8_valid(const char* s, size_t n);

/* Copy a name into a fixed buffer, truncating. */
void akp_io_copy_name(char dst[AK_NAME_SIZE], const char* src);

ak_result akp_io_load_gltf(const uint8_t* data, size_t size, const char* name, const char* base_dir,
                           const ak_io_desc* desc, const ak_allocator* alloc, ak_scene** out_scene, ak_diag* diag);
/* BVH from a file (streamed, path != NULL) or from memory (data, size). */
ak_result akp_io_load_bvh(const char* path, const uint8_t* data, size_t size, const char* name,
                          const ak_io_desc* desc, const ak_allocator* alloc, ak_scene** out_scene, ak_diag* diag);
/* OBJ (+ MTL) from memory (data[size] must be 0); base_dir NULL -> mtllib not read. */
ak_result akp_io_load_obj(const uint8_t* data, size_t size, const char* name, const char* base_dir,
                          const ak_io_desc* desc, const ak_allocator* alloc, ak_scene** out_scene, ak_diag* diag);
ak_result akp_io_load_assimp(const char* path, const ak_io_desc* desc, const ak_allocator* alloc,
                             ak_scene** out_scene, ak_diag* diag);

/* Decode a PNG or JPEG (told apart by the signature) into RGBA8 rows top to bottom, allocated
 * through alloc after the header's size was checked (at most AKP_IO_MAX_IMAGE_SIDE per side) and
 * charged to budget (NULL -> not charged). msg (msg_size bytes) says what is wrong on failure.
 * Returns AK_ERR_PARSE (not an image, or broken), AK_ERR_UNSUPPORTED (too large, over budget,
 * CMYK JPEG, no JPEG decoder in this build), AK_ERR_NO_MEMORY. (src/io/image.c) */
ak_result akp_image_decode(const uint8_t* data, size_t size, akp_budget* budget, const ak_allocator* alloc,
                           uint8_t** out_pixels, int* out_width, int* out_height, char* msg, size_t msg_size);
/* akp_image_decode behind the caller's decoder: desc->image_decoder (when set) first; it returning
 * AK_ERR_UNSUPPORTED (or no decoder) -> akp_image_decode. Same contract and results as
 * akp_image_decode; a decoded image's size is checked and charged before the copy. (src/io.c) */
ak_result akp_io_image_decode(const ak_io_desc* desc, const uint8_t* data, size_t size,
                              akp_budget* budget, const ak_allocator* alloc, uint8_t** out_pixels,
                              int* out_width, int* out_height, char* msg, size_t msg_size);
/* Encode RGBA8 (rows top to bottom, tightly packed) as a PNG in a malloc'ed buffer.
 * Returns AK_ERR_BAD_ARG (libpng refused), AK_ERR_NO_MEMORY. */
ak_result akp_image_encode_png(const uint8_t* rgba, int width, int height, uint8_t** out_data, size_t* out_size);

#endif
