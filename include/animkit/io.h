/* animkit io: import of real assets into an ak_scene; glTF and OBJ export.
 *
 * What it does:
 *   - glTF 2.0 (.gltf with data: URIs or external .bin files, .glb) through animkit's own
 *     reader on cJSON. Why not Assimp for glTF: Assimp 5.2.5's glTF importer keeps only the
 *     values of CUBICSPLINE keys (it drops the tangents), merges a node's translation,
 *     rotation and scale channels into one, and adds synthetic root nodes; glTF is judged
 *     exactly, so it gets a reader that keeps the file's data as the specification defines
 *     it (accessors with byteStride, sparse accessors, normalized integers, every component
 *     type, matrix or TRS nodes, skins, morph targets, TANGENT (VEC4, w = +1 or -1, else
 *     AK_ERR_BAD_DATA), STEP/LINEAR/CUBICSPLINE samplers).
 *   - BVH through animkit's own streaming reader (src/io/bvh.c): bounded nesting, the frame
 *     count checked against the data present, the same scene layout Assimp gave (docs/io.md).
 *   - Wavefront OBJ (+ the .mtl files it names, for base colours and map_Kd textures) through
 *     animkit's own reader (src/io/obj.c), with the scene layout Assimp gave (docs/io.md).
 *   - Everything else (FBX, Collada, ...) through Assimp's C API, run in a forked child
 *     process under resource limits (a crash there is AK_ERR_IO): the node tree
 *     becomes the skeleton, aiAnimation channels become clips (ticks -> seconds), meshes with
 *     bones get skins.
 *   - ak_io_save: glTF 2.0 (.glb, or .gltf + .bin) of a whole scene: nodes, skins, meshes,
 *     morph targets and clips (src/io/gltf_write.c); it passes the Khronos glTF validator.
 *   - ak_io_write_obj: Wavefront OBJ of a scene's meshes at positions the caller computed
 *     (one `o` group per scene mesh, vertices in the scene's order, no welding), with an .mtl
 *     and PNG files for materials and textures.
 *   - Base-colour textures (glTF pbrMetallicRoughness.baseColorTexture with TEXCOORD_0, its
 *     sampler's wrap modes and filters; OBJ map_Kd): PNG through libpng, JPEG through
 *     libjpeg-turbo (ak_io_image_decode), decoded into scene->textures; an image that cannot be
 *     read is a warning and the mesh stays untextured (the load succeeds).
 *
 * What it does NOT do: materials beyond a primitive's base colour factor and texture (ak_scene_mesh
 * base_color, texture): no normal, metallic-roughness, occlusion or emissive maps, no
 * KHR_texture_transform, no texture coordinate set other than 0, no mipmaps; cameras, lights, glTF extensions (a file whose
 * extensionsRequired names one that changes geometry or animation, e.g. Draco, is refused),
 * morph targets through Assimp, posing (scene.h, skin.h, blendshape.h). It never prints;
 * warnings go to desc->logger.
 *
 * How a glTF file maps to the scene (docs/io.md has the details):
 *   - every node (also nodes outside the default scene) is one skeleton joint, reordered
 *     parents-before-children (a stable sort: file order where the hierarchy allows). Joint
 *     names identify nodes: the node's name, "node_<i>" when it has none, "<name>#<i>" when
 *     an earlier node already took the name (i = node index; names cut to AK_NAME_SIZE-1);
 *   - one ak_scene_mesh per (mesh, instancing node, primitive): meshes in file order, then
 *     the nodes that instance the mesh in node order, then primitives; a mesh no node uses
 *     appears once with node -1;
 *   - skin i of the scene is glTF skin i; mesh->joints hold skin slots;
 *   - morph weights: scene mesh m's target t has morph weight index
 *     sum_{k<m} meshes[k].mesh->morph_target_count + t; a glTF "weights" channel becomes
 *     one AK_CHANNEL_MORPH_WEIGHTS channel per scene mesh the node carries;
 *   - clip i is animation i, named by its name or "animation_<i>", duration = the largest
 *     sampler input time; interpolation kept (rotation LINEAR = SLERP; CUBICSPLINE keys keep
 *     their (in-tangent, value, out-tangent) triples).
 *
 * Usage:
 *     ak_scene* scene = NULL;
 *     ak_diag diag;
 *     ak_io_desc desc = { .max_influences = 4 };
 *     ak_result r = ak_io_load("Fox.glb", &desc, NULL, &scene, &diag);
 *     if (r != AK_OK) {
 *         fprintf(stderr, "%s: %s (%s)\n", diag.path, diag.message, ak_result_string(r));
 *         return 1;
 *     }
 *     printf("%zu joints, %zu meshes, %zu clips\n", ak_scene_joint_count(scene),
 *            scene->mesh_count, scene->clip_count);
 *     // ... pose, skin, then write what was computed:
 *     ak_io_write_obj("mesh.obj", scene, NULL, NULL, &diag);  // NULL: positions as stored
 *     ak_scene_destroy(scene);
 *
 * Untrusted input: glTF, BVH and OBJ are safe to load from untrusted sources (memory bounded by
 * desc->memory_budget, checked before allocating, texture images included: their size is read
 * from the image header and charged before the pixels are allocated, at most 16384 per side; recursion bounded (cJSON stops at 1000
 * nesting levels, the BVH and OBJ readers do not recurse); external glTF buffers and OBJ
 * mtllib files only inside the model's directory unless desc->extra_roots/allow_any_path say
 * otherwise, and a path that leaves it is refused without looking at what is there; texture
 * images (glTF image uris, OBJ map_Kd) under the same rule; names must be valid UTF-8 without control bytes; error messages escape raw
 * bytes). Assimp formats (FBX, Collada, ...) are contained, not hardened: Assimp runs in a
 * child process with RLIMIT_AS/CPU/FSIZE/NOFILE limits and a wall-clock limit
 * (AK_IO_ASSIMP_SECONDS); a crash or a timeout there is AK_ERR_IO, and the scene it sends
 * back is checked before use. docs/io.md lists every limit and its default.
 *
 * Ownership and threading: the scene returned belongs to the caller (ak_scene_destroy).
 * The library keeps no pointer to the caller's data. The glTF and BVH paths are reentrant: the JSON
 * parse tree comes from cJSON's own malloc (animkit never sets cJSON's global hooks) and
 * animkit never reads cJSON's global last-error pointer. The Assimp path forks a child
 * process per load (Assimp's global error message lives there).
 */
#ifndef ANIMKIT_IO_H
#define ANIMKIT_IO_H

#include "scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Default and largest number of skin influences kept per vertex. */
#define AK_IO_DEFAULT_INFLUENCES 4
/* Default memory budget of one load (ak_io_desc.memory_budget = 0): the larger of 1 GiB and
 * AK_IO_BUDGET_INPUT_FACTOR times the size of the file (or memory block) being loaded. */
#define AK_IO_DEFAULT_BUDGET ((size_t)1 << 30)
#define AK_IO_BUDGET_INPUT_FACTOR 16u
/* Deepest ROOT/JOINT nesting animkit's BVH reader accepts. */
#define AK_IO_BVH_MAX_DEPTH 256u
/* CPU seconds Assimp may spend on one file, in its child process (the parent waits 5 s of
 * wall time more, then kills it). */
#define AK_IO_ASSIMP_SECONDS 60
/* Deepest element/brace nesting the pre-check lets through to Assimp (Collada, ASCII FBX). */
#define AK_IO_ASSIMP_MAX_DEPTH 1024u

/* An image decoded by a caller-supplied decoder (ak_io_desc.image_decoder): RGBA8, sRGB colour as
 * stored, straight (not premultiplied) alpha, rows top to bottom, width * 4 bytes per row. The
 * pixels stay the decoder's: the loader copies them (after charging width * height * 4 bytes to
 * the load's memory budget) before it calls the decoder again or returns. */
typedef struct ak_io_image_view {
    const uint8_t* pixels;
    int width, height; /* 1..16384 each, else the image is refused (a warning, drawn untextured) */
} ak_io_image_view;

/* A caller-supplied texture image decoder: decode data[size] (the image's encoded bytes as the
 * file holds them: a PNG, a JPEG, ...) into *out. Return AK_OK with *out filled; AK_ERR_UNSUPPORTED
 * to let the library's own decoder (libpng/libjpeg, ak_io_image_decode) try it instead; any other
 * code refuses the image (a warning; the meshes using it are drawn untextured). Called on the
 * loading thread, at most once per texture image, with user as given in ak_io_desc. Used where
 * the library has no decoder but the host has one: the WebAssembly page (docs/web.md) hands
 * over what the browser decoded. */
typedef ak_result (*ak_io_image_decoder)(void* user, const void* data, size_t size,
                                         ak_io_image_view* out);

/* Which reader handles a file. */
typedef enum ak_io_format {
    AK_IO_FORMAT_AUTO = 0, /* default: a .gltf/.glb extension or the GLB magic -> GLTF, .bvh -> BVH,
                              .obj -> OBJ, else ASSIMP */
    AK_IO_FORMAT_GLTF,     /* animkit's glTF 2.0 reader (.gltf or .glb, decided by the bytes) */
    AK_IO_FORMAT_ASSIMP,   /* Assimp's importer in a child process (FBX, Collada, ...; OBJ and
                              BVH only when named explicitly) */
    AK_IO_FORMAT_BVH,      /* animkit's BVH reader (AUTO picks it for .bvh and for data that
                              starts with HIERARCHY) */
    AK_IO_FORMAT_OBJ,      /* animkit's Wavefront OBJ reader, with the .mtl files it names
                              (base colours only); AUTO picks it for .obj */
    AK_IO_FORMAT_COUNT
} ak_io_format;

typedef struct ak_io_desc {
    uint32_t max_influences; /* skin influences kept per vertex (largest weights, then
                                renormalised); 0 -> AK_IO_DEFAULT_INFLUENCES, at most
                                AK_MAX_INFLUENCES */
    float min_weight;        /* influences below this are dropped before renormalising;
                                0 -> keep every positive weight */
    ak_io_format format;     /* 0 -> AK_IO_FORMAT_AUTO */
    bool skip_animations;    /* true -> no clips */
    bool keep_bvh_mesh;      /* only for BVH read through Assimp (format AK_IO_FORMAT_ASSIMP):
                                Assimp builds a bone-visualisation mesh; false (default) drops it.
                                animkit's own BVH reader never makes a mesh */
    ak_logger logger;        /* warnings (ignored extensions, dropped keys); zero -> silent */
    size_t memory_budget;    /* most bytes one load may allocate for file data, the JSON tree
                                and arrays, checked before each allocation (a conservative sum,
                                the peak is lower); over it -> AK_ERR_UNSUPPORTED.
                                0 -> max(AK_IO_DEFAULT_BUDGET, AK_IO_BUDGET_INPUT_FACTOR x input
                                size). Assimp formats: the file size must fit it */
    const char* const* extra_roots; /* directories that external glTF buffer URIs (and files
                                an Assimp model names) may also resolve into (after
                                percent-decoding, normalising and resolving symlinks);
                                NULL -> only the model's own directory */
    size_t extra_root_count;
    bool allow_any_path;     /* true -> external buffer URIs may resolve anywhere (only for
                                trusted files); false (default) -> outside the model's directory
                                and extra_roots is AK_ERR_IO (an Assimp model's own files: not
                                opened, a warning) */
    ak_io_image_decoder image_decoder; /* glTF and OBJ texture images go to it first (see
                                ak_io_image_decoder); NULL (default) -> the built-in decoder */
    void* image_decoder_user;          /* passed to image_decoder */
} ak_io_desc;

/* The desc with its zero fields replaced by their defaults (NULL -> all defaults).
 * max_influences above AK_MAX_INFLUENCES is clamped to it; a negative or NaN min_weight -> 0. */
AK_API ak_io_desc ak_io_desc_resolved(const ak_io_desc* desc);

/* Load a file into a new scene (*out_scene, freed with ak_scene_destroy).
 * desc NULL -> defaults; alloc NULL -> malloc/free (used for the scene, everything in it and
 * the temporary arrays; only cJSON's parse tree and Assimp's scene use their own malloc). diag (optional) names the file and the problem.
 * Returns AK_ERR_NULL_ARG (path or out_scene NULL), AK_ERR_IO (cannot open or read the file
 * or an external buffer, or an external buffer URI that resolves outside the model's directory:
 * diag names the uri; Assimp crashed or ran out of its time limit in its child process), AK_ERR_PARSE (malformed JSON/GLB, a glTF rule broken, an Assimp
 * failure: diag holds Assimp's message), AK_ERR_BAD_INDEX (an index out of range: accessor,
 * node, vertex index, joint slot), AK_ERR_BAD_DATA (NaN or infinity in positions, transforms,
 * inverse binds or key values), AK_ERR_BAD_WEIGHTS (a negative skin weight),
 * AK_ERR_BAD_HIERARCHY (node cycle or a node with two parents), AK_ERR_UNSORTED (sampler
 * times not strictly increasing), AK_ERR_DUPLICATE (two channels animate one node path),
 * AK_ERR_UNSUPPORTED (a required extension, glTF 1.x, more than AK_SKELETON_MAX_JOINTS nodes, a skin of more
 * than 65535 joints, an animation with no usable channel, the memory budget exceeded, BVH
 * nesting deeper than AK_IO_BVH_MAX_DEPTH or Assimp input nested deeper than
 * AK_IO_ASSIMP_MAX_DEPTH), AK_ERR_NOT_FOUND (Assimp: a bone
 * or channel names no node), AK_ERR_EMPTY (Assimp: a mesh without vertices), AK_ERR_BAD_ARG
 * (desc->format out of range), AK_ERR_NO_MEMORY. On failure *out_scene is NULL. */
AK_API ak_result ak_io_load(const char* path, const ak_io_desc* desc, const ak_allocator* alloc,
                            ak_scene** out_scene, ak_diag* diag);

/* Load a glTF 2.0 document (.gltf JSON text or .glb bytes, told apart by the "glTF" magic) or
 * a BVH file (desc->format BVH, or AUTO and the data starts with "HIERARCHY") from memory.
 * name (NULL -> "memory") is used for the scene name and in diag; base_dir (NULL -> external
 * buffers are refused with AK_ERR_IO) is the directory external buffer URIs are relative to
 * and must stay inside (see ak_io_desc.extra_roots). data is read only during the call.
 * Returns the codes of ak_io_load, and AK_ERR_NULL_ARG when data is NULL with size > 0.
 * desc->format must be AUTO, GLTF, BVH or OBJ (OBJ only when named; its mtllib files are read
 * relative to base_dir, none without one); AK_ERR_UNSUPPORTED otherwise. */
AK_API ak_result ak_io_load_memory(const void* data, size_t size, const char* name, const char* base_dir,
                                   const ak_io_desc* desc, const ak_allocator* alloc, ak_scene** out_scene,
                                   ak_diag* diag);

/* Write the scene's meshes as Wavefront OBJ: for each scene mesh in order, "o <name>"
 * (the mesh name, or "mesh_<index>", whitespace replaced by '_'), its vertices in order
 * ("v x y z", 9 significant digits), "vt" when the mesh has UVs, "vn" when normals are
 * available, and its triangles as "f" lines (1-based, offset by the vertices written
 * before). No welding, no reordering: UVs are written as the mesh stores them (for glTF,
 * origin at the top left, so tools that assume OBJ's bottom-left origin show textures
 * flipped), and triangles keep the file's index order, also under a mirroring node.
 * Materials: when a scene mesh has a material or a texture (with UVs), "<stem>.mtl" is written
 * beside path (stem: path's file name without ".obj") with one "material_<mesh index>" per such
 * mesh (Kd and d from base_color, white without one; map_Kd "<stem>_<texture index>.png"),
 * each texture used as such a PNG beside it, its rows flipped so that other tools, which take
 * v = 0 as the image's bottom, show it the right way up with the UVs as stored (animkit's OBJ
 * reader flips map_Kd images back); the .obj names them with mtllib and usemtl. These files
 * go to temporaries too, renamed into place (before the .obj) only once the .obj is complete:
 * a failure while writing leaves none of them (only a failed rename of the .obj after theirs
 * can leave new side files beside the old .obj).
 * posed_positions: NULL, or an array of scene->mesh_count pointers, each to vertex_count
 * positions (NULL entry -> that mesh's own bind-space positions, as stored).
 * posed_normals: same shape; NULL or a NULL entry -> the mesh's own normals when it has them,
 * else no "vn" for that mesh. Point clouds (no triangles) write only vertices.
 * The file is written whole or not at all: to a temporary ".NAME.XXXXXX" beside path, renamed
 * over path once complete (a symlink at path is replaced, not followed); on any failure the
 * temporary is removed and whatever path named is left untouched.
 * Returns AK_ERR_NULL_ARG (path or scene NULL), AK_ERR_BAD_DATA (a non-finite coordinate:
 * nothing is written), AK_ERR_IO (cannot create or write the file; diag names it). */
AK_API ak_result ak_io_write_obj(const char* path, const ak_scene* scene, const ak_vec3* const* posed_positions,
                                 const ak_vec3* const* posed_normals, ak_diag* diag);

/* Decode a PNG (libpng) or JPEG (libjpeg-turbo; a build without it refuses JPEG with
 * AK_ERR_UNSUPPORTED) held in memory, told apart by its signature, into RGBA8 pixels (sRGB
 * colour as stored, straight alpha, rows top to bottom, width * 4 bytes per row) allocated
 * through alloc (NULL -> malloc) once the size in the header is checked: at most 16384 pixels
 * per side and width * height * 4 bytes within memory_budget (0 -> AK_IO_DEFAULT_BUDGET).
 * Free the pixels with ak_io_image_free (same alloc). This is the decoder the glTF and OBJ
 * readers use for base-colour textures. Returns AK_ERR_NULL_ARG, AK_ERR_PARSE (neither
 * format, or a broken image: diag says what libpng or libjpeg reported), AK_ERR_UNSUPPORTED
 * (too large, CMYK JPEG, no JPEG decoder), AK_ERR_NO_MEMORY. On failure *out_pixels is NULL. */
AK_API ak_result ak_io_image_decode(const void* data, size_t size, size_t memory_budget, const ak_allocator* alloc,
                                    uint8_t** out_pixels, int* out_width, int* out_height, ak_diag* diag);
/* Free pixels from ak_io_image_decode (alloc as given to it); NULL is a no-op. */
AK_API void ak_io_image_free(const ak_allocator* alloc, uint8_t* pixels);

/* Default memory budget of one ak_io_save (ak_io_save_desc.memory_budget = 0): 1 GiB of output. */
#define AK_IO_SAVE_DEFAULT_BUDGET ((size_t)1 << 30)

/* How ak_io_save writes (all fields zero -> defaults). */
typedef struct ak_io_save_desc {
    ak_logger logger;     /* warnings (scalar channels and clips glTF cannot hold); zero -> silent */
    size_t memory_budget; /* most bytes of output (JSON text + binary chunk: the .glb, or the
                             .gltf and its .bin, exactly as ak_io_save_size counts them) one save
                             may produce; over it -> AK_ERR_UNSUPPORTED before any file is
                             created. 0 -> AK_IO_SAVE_DEFAULT_BUDGET */
} ak_io_save_desc;

/* Write a scene as glTF 2.0: a path ending in .glb (any case) gives one binary GLB file; .gltf
 * gives the JSON file plus "<same name>.bin" beside it (uri relative, percent-encoded).
 * What is written (docs/io.md "Writing glTF" has every rule):
 *   - every skeleton joint as a node, in skeleton order (parents before children), named by
 *     the joint name, with its rest transform as translation/rotation/scale (defaults left out;
 *     the rotation written normalised), scenes[0] holding the roots;
 *   - skins with their joints and inverse bind matrices (float MAT4);
 *   - scene meshes as mesh primitives: POSITION (with min/max), NORMAL (renormalised where a
 *     normal is off unit length by more than 1e-5; a zero normal -> +Y), TANGENT (only with
 *     NORMAL, as glTF requires: xyz renormalised the same way, a zero one -> +X, w = the sign
 *     of the stored w as exactly +1 or -1), TEXCOORD_0, COLOR_0,
 *     JOINTS_0/WEIGHTS_0 and, above 4 influences, JOINTS_1/WEIGHTS_1 (joints unsigned byte,
 *     or unsigned short when a slot is above 255; a zero weight's joint written as 0),
 *     indices (unsigned short below 65535 vertices, else unsigned int), morph targets
 *     (POSITION deltas with min/max, NORMAL and TANGENT deltas), default weights in mesh.weights and
 *     target names in mesh.extras.targetNames. Consecutive scene meshes on one node with the
 *     same skin, morph target count, default weights and morph animation become primitives
 *     of one glTF mesh (as the reader split them); any other mesh gets its own node with an
 *     identity transform ("<mesh name>_node"): a root for skinned meshes (their node's
 *     transform is ignored, and glTF warns about skinned meshes below other nodes), a child
 *     of the mesh's node otherwise, so posed results are unchanged;
 *   - each clip as an animation (clips with nothing glTF can hold are skipped with a warning):
 *     translation/rotation/scale channels per joint and one "weights" channel per glTF mesh
 *     (targets the clip does not animate hold their default weight); STEP, LINEAR and
 *     CUBICSPLINE keys are written as stored; HERMITE, and CARDINAL/NATURAL/BEZIER on
 *     non-rotation channels, become CUBICSPLINE with the per-second tangents of
 *     ak_track_key (the same curve); SCALAR channels are skipped with a warning.
 *   - each distinct (base colour, texture) of the scene meshes as a material holding only
 *     pbrMetallicRoughness.baseColorFactor (channels clamped to [0, 1]) and, for a mesh with
 *     a texture and UVs, baseColorTexture: each texture used is written once as an image
 *     (PNG, lossless, embedded in the buffer through a bufferView, also for .gltf), a sampler
 *     (its wrap modes; filters NEAREST or LINEAR, no mipmap filters) and a texture.
 * Simulations: scene.h's ak_scene_bake_mesh_frames (a cloth as morph-target animation) and
 * ak_scene_bake_point_frames (particles as one animated node each) build the scene to write.
 * Not written: other material properties and maps, the clip duration (a
 * reader takes the last key time), ak_skeleton joint types and limits.
 * Layout: one buffer, one bufferView per accessor (4-byte aligned, zero padded, so no
 * byteStride), GLB JSON chunk padded with spaces and BIN chunk with zeros.
 * Memory: two passes over the scene. The first builds the JSON document (a cJSON tree) with
 * the binary chunk only counted, prints it and frees the tree: that gives the exact output size
 * (ak_io_save_size), checked against desc->memory_budget before a file is created. The second
 * builds the document again and streams each bufferView's data straight to the file (.glb: after
 * the JSON chunk, whose text is freed first; .gltf: to the .bin), so the binary chunk is never
 * held whole; the peak is about the cJSON tree plus the JSON text (docs/io.md has measurements).
 * Returns AK_ERR_NULL_ARG (path or scene NULL, a scene mesh without data), AK_ERR_BAD_ARG
 * (another extension), AK_ERR_BAD_DATA (a non-finite position, normal, UV, colour, morph
 * delta, default weight, rest transform, inverse bind or key), AK_ERR_BAD_WEIGHTS (a
 * negative weight), AK_ERR_BAD_INDEX (a triangle index, skin joint, channel joint, or a
 * scene mesh's skin or node out of range), AK_ERR_UNSUPPORTED (an interpolation glTF cannot express: NLERP, SQUAD, LAGRANGE,
 * or a cubic mode other than HERMITE on a rotation: bake the clip first; two channels
 * animating one mesh's morph weights; more than 4 GiB in a GLB; output larger than
 * desc->memory_budget: diag names both sizes, no file is created), AK_ERR_IO (cannot create or
 * write a file), AK_ERR_NO_MEMORY. diag (optional) names the file and the problem. Temporary
 * memory comes from malloc. Files are written whole or not at all: each to a temporary
 * ".NAME.XXXXXX" beside it, renamed into place (a symlink there is replaced, not followed)
 * only once both a .gltf and its .bin are complete (the .bin first); on a failure the
 * temporaries are removed and the named files are left untouched (only a failed rename of
 * the .gltf after its .bin's can leave a new .bin beside the old .gltf). */
AK_API ak_result ak_io_save(const char* path, const ak_scene* scene, const ak_io_save_desc* desc, ak_diag* diag);

/* The exact number of bytes ak_io_save(path, scene, desc) would write (the .glb; or the .gltf
 * plus its .bin), into *out_bytes, without writing anything: the first of ak_io_save's two passes
 * (it builds and prints the JSON document, so it costs about that pass's time and memory).
 * desc->memory_budget is not applied. Returns ak_io_save's codes other than AK_ERR_IO, and
 * AK_ERR_NULL_ARG when out_bytes is NULL; on failure *out_bytes is 0. */
AK_API ak_result ak_io_save_size(const char* path, const ak_scene* scene, const ak_io_save_desc* desc,
                                 size_t* out_bytes, ak_diag* diag);

#ifdef __cplusplus
}
#endif
#endif /* ANIMKIT_IO_H */
