/* animkit skin: automatic skin weights and skinning (LBS, dual quaternions, centers of rotation).
 *
 * What it does:
 *   - automatic weights from a mesh and its bones: inverse distance to the bone segments, or
 *     bone heat (Baran & Popovic 2007: one sparse Cholesky factorization of the cotangent
 *     Laplacian, reused for every joint), then "keep the k largest, drop tiny, renormalise";
 *   - a compact weights file format (encode/decode to memory, thin file wrappers);
 *   - one skinning job for three methods: linear blend (LBS), dual quaternions (DQS, Kavan et
 *     al. 2008) and optimized centers of rotation (CoR, Le & Hodgins 2016), vectorized across
 *     vertices (AVX-512 or AVX2+FMA chosen at run time; scalar reference always built, forced by
 *     AK_NO_SIMD or job.skip_simd);
 *   - the CoR precomputation (per-vertex centers), pruned by bone pair and multithreaded, with
 *     a cache format keyed by a hash of the mesh and weights;
 *   - implicit skinning (Vaillant et al. 2013/2014): per-bone HRBF fields composed with a
 *     contact operator, vertices projected from DQS onto their rest iso-values
 *     (ak_skin_implicit_*, cached like CoR's centers).
 *
 * What it does NOT do: build the palette (scene.h's ak_scene_skin_palette does for a scene:
 * M_k = world(skin.joints[k]) * skin.inverse_binds[k]), read asset files (io.h), or measure
 * volume (ak_volume_compute in mesh.h).
 *
 * The palette is indexed the way the mesh's joint indices are. For a scene (ak_io_load,
 * ak_builtin_create) those are the slots of the mesh's skin, so its palette comes from
 * ak_scene_skin_palette, never from ak_skeleton_skinning_matrices (indexed by skeleton joint,
 * which a loaded skeleton refuses with AK_ERR_UNSUPPORTED; it only fits meshes whose joint
 * indices are skeleton joints). examples/skin_gltf_minimal.c is this note as a program.
 *
 * Usage (scene mesh m posed by local transforms `local`; deform every frame):
 *     const ak_scene_mesh* sm = &scene->meshes[m];
 *     const ak_mesh* mesh = sm->mesh;
 *     size_t joint_count = scene->skins[sm->skin].joint_count;   // palette size: skin slots
 *     ak_scene_world_matrices(scene, local, world);              // FK of every node
 *     ak_scene_skin_palette(scene, (size_t)sm->skin, world, (ak_mat4_span){palette, joint_count});
 *     ak_skin_job job = {
 *         .method = AK_SKIN_DQS,
 *         .influence_count = mesh->influence_count,
 *         .palette   = { palette, joint_count },
 *         .joints    = { mesh->joints,  mesh->vertex_count, 0 },
 *         .weights   = { mesh->weights, mesh->vertex_count, 0 },
 *         .positions = { mesh->positions, mesh->vertex_count, 0 },
 *         .normals   = { mesh->normals, mesh->vertex_count, 0 },
 *         .out_positions = { out_pos, mesh->vertex_count, 0 },
 *         .out_normals   = { out_nrm, mesh->vertex_count, 0 },
 *         .scratch = { scratch, sizeof scratch },  // >= ak_skin_job_scratch_size(&job)
 *     };
 *     ak_result r = ak_skin_job_validate(&job);   // once, with the data check
 *     job.skip_data_check = true;                 // then per frame: O(1) validation only
 *     r = ak_skin_job_run(&job);
 *
 * Ownership and threading: every function works on caller-owned arrays and keeps no pointer
 * after it returns. ak_skin_job_run never allocates (job.thread_count > 1 starts pthreads,
 * whose stacks the C library allocates; use ak_skin_job_split with your own job system to
 * avoid that). Jobs whose outputs do not overlap may run concurrently. The weight and CoR
 * precomputations allocate temporaries through the optional allocator (NULL -> malloc).
 */
#ifndef ANIMKIT_SKIN_H
#define ANIMKIT_SKIN_H

#include "mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- bones ---------------------------------------------------------------------------- */

/* A bone as a segment in bind (model) space, and the joint that receives its weight. */
typedef struct ak_skin_bone {
    ak_vec3 head;          /* model space: the joint's bind position */
    ak_vec3 tail;          /* model space: the child's bind position; == head for a point bone */
    uint16_t joint_index;  /* joint (palette entry) that this segment's weight goes to */
} ak_skin_bone;

AK_DEFINE_SPAN(skin_bone, ak_skin_bone)

/* Most bones ak_skin_bones_from_joints writes for joint_count joints (2 * joint_count). */
AK_API size_t ak_skin_bones_from_joints_bound(size_t joint_count);

/* Bones of a skeleton given as bind-space joint positions and parents (parent[i] < i, -1 for
 * roots; e.g. ak_skeleton_parents): one segment joint -> child per child, owned by the joint;
 * a leaf joint becomes a point bone at its position unless skip_leaf_joints.
 * Needs parents.count >= joint_positions.count, out_bones.count >= the bound above.
 * Returns AK_ERR_NULL_ARG, AK_ERR_EMPTY (no joints), AK_ERR_BAD_ARG (more than 65535 joints),
 * AK_ERR_BAD_HIERARCHY (parent >= own index or < -1), AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_skin_bones_from_joints(ak_vec3_cspan joint_positions, ak_i32_cspan parents,
                                           bool skip_leaf_joints, ak_skin_bone_span out_bones,
                                           size_t* out_bone_count);

/* ---- automatic weights ---------------------------------------------------------------- */

typedef enum ak_weights_method {
    AK_WEIGHTS_HEAT = 0, /* default: bone heat diffusion on the surface (needs triangles) */
    AK_WEIGHTS_DISTANCE, /* inverse distance to the bone segments (triangles unused) */
    AK_WEIGHTS_METHOD_COUNT
} ak_weights_method;

typedef struct ak_weights_desc {
    ak_weights_method method; /* 0 -> AK_WEIGHTS_HEAT */
    ak_vec3_cspan positions;  /* required: bind-space vertex positions */
    ak_u32_cspan indices;     /* triangles, 3 per, counter-clockwise; required for HEAT */
    ak_skin_bone_cspan bones; /* required, >= 1 (see ak_skin_bones_from_joints) */
    uint32_t max_influences;  /* k, 1..AK_MAX_INFLUENCES; 0 -> 4. Also the output stride */
    float min_weight;         /* weights below this (after the first renormalisation) are
                                 dropped; 0 -> 0.001; negative -> keep every weight > 0 */
    float distance_power;     /* DISTANCE: exponent n of (1/d)^n; 0 -> 4. Larger n gives
                                 sharper transitions (n -> inf: rigid nearest bone); n = 2
                                 bleeds noticeably between nearby limbs */
    float heat_strength;      /* HEAT: c in H_ii = c / d_i^2; 0 -> 1 (Baran & Popovic's value) */
    bool skip_visibility;     /* HEAT: false -> a vertex only heats from the nearest bone it
                                 can see (segment to the bone not blocked by the mesh) */
} ak_weights_desc;

/* The desc with every zero field replaced by its documented default. */
AK_API ak_weights_desc ak_weights_desc_resolved(const ak_weights_desc* desc);

/* Compute skin weights. Writes k = resolved max_influences slots per vertex, sorted by
 * decreasing weight; unused slots get joint 0 and weight 0. Every vertex's weights are >= 0
 * and sum to 1 within 1e-6. Needs out_joints.count and out_weights.count >= vertex_count * k.
 * Robustness: a vertex on a bone (d = 0) gets weight only from the bones it touches, a vertex
 * far from every bone still gets finite weights; a vertex no bone can see (HEAT) falls back to
 * its nearest bone; a vertex on no triangle (HEAT) gets its nearest bone with weight 1.
 * Heat solves (L + A H) w_j = A H p_j (L the symmetric cotangent Laplacian, A the barycentric
 * vertex areas) with one CHOLMOD factorization and one multi-column solve.
 * Returns AK_ERR_NULL_ARG, AK_ERR_EMPTY (no vertices or no bones; HEAT: no triangles),
 * AK_ERR_BAD_ARG (method, max_influences > 8, indices.count % 3, distance_power <= 0 after
 * defaults), AK_ERR_BAD_INDEX (a triangle index >= vertex count), AK_ERR_BAD_DATA (NaN or
 * infinite position or bone), AK_ERR_SPAN_SMALL, AK_ERR_NO_MEMORY, AK_ERR_NO_CONVERGENCE
 * (the sparse factorization failed). */
AK_API ak_result ak_skin_weights_compute(const ak_weights_desc* desc, const ak_allocator* alloc,
                                         ak_u16_span out_joints, ak_f32_span out_weights);

/* Check weights: each finite and >= 0, per-vertex sum within tolerance of 1 (tolerance 0 ->
 * 1e-3), joint indices < joint_count. joints/weights hold vertex_count * influence_count.
 * Returns AK_ERR_NULL_ARG, AK_ERR_BAD_ARG (influence_count 0 or > 8), AK_ERR_SPAN_SMALL,
 * AK_ERR_BAD_WEIGHTS (the first bad vertex goes to *out_bad_vertex, optional),
 * AK_ERR_BAD_INDEX (idem). */
AK_API ak_result ak_skin_weights_validate(ak_u16_cspan joints, ak_f32_cspan weights, size_t vertex_count,
                                          uint32_t influence_count, size_t joint_count, float tolerance,
                                          size_t* out_bad_vertex);

/* ---- weights file format ----------------------------------------------------------------
 * Little-endian binary, 16-byte header then two arrays:
 *   bytes 0..3   magic "AKWT"
 *   bytes 4..7   u32 version (1)
 *   bytes 8..11  u32 vertex_count
 *   bytes 12..15 u32 influence_count (1..8)
 *   then u16 joints[vertex_count * influence_count], zero-padded to a multiple of 4 bytes,
 *   then f32 weights[vertex_count * influence_count] (IEEE 754 binary32).
 * Vertex-major: the influences of vertex v are at [v * influence_count, ...). */

/* Bytes of an encoded weights buffer (0 when the counts overflow). */
AK_API size_t ak_skin_weights_encoded_size(size_t vertex_count, uint32_t influence_count);
/* Encode into out_buffer (count >= the size above); *out_size (optional) gets the bytes
 * written. Returns AK_ERR_NULL_ARG, AK_ERR_BAD_ARG (influence_count 0 or > 8, vertex_count
 * >= 2^32), AK_ERR_SPAN_SMALL (either input or the buffer). */
AK_API ak_result ak_skin_weights_encode(ak_u16_cspan joints, ak_f32_cspan weights, size_t vertex_count,
                                        uint32_t influence_count, ak_u8_span out_buffer, size_t* out_size);
/* Read the counts from an encoded buffer. Returns AK_ERR_NULL_ARG, AK_ERR_PARSE (bad magic,
 * version or truncated buffer; diag optional). */
AK_API ak_result ak_skin_weights_decode_info(ak_u8_cspan buffer, size_t* out_vertex_count,
                                             uint32_t* out_influence_count, ak_diag* diag);
/* Decode into caller arrays (count >= vertex_count * influence_count). The weights are not
 * validated (use ak_skin_weights_validate). Returns the decode_info codes, AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_skin_weights_decode(ak_u8_cspan buffer, ak_u16_span out_joints, ak_f32_span out_weights,
                                        ak_diag* diag);
/* ak_skin_weights_encode to a file (built in memory with malloc first). Adds AK_ERR_IO,
 * AK_ERR_NO_MEMORY. The file wrappers use malloc, not an ak_allocator. */
AK_API ak_result ak_skin_weights_write_file(const char* path, ak_u16_cspan joints, ak_f32_cspan weights,
                                            size_t vertex_count, uint32_t influence_count);
/* Counts of a weights file (reads the header only). Adds AK_ERR_IO to decode_info's codes. */
AK_API ak_result ak_skin_weights_read_file_info(const char* path, size_t* out_vertex_count,
                                                uint32_t* out_influence_count, ak_diag* diag);
/* Read a weights file into caller arrays. Adds AK_ERR_IO to decode's codes. */
AK_API ak_result ak_skin_weights_read_file(const char* path, ak_u16_span out_joints, ak_f32_span out_weights,
                                           ak_diag* diag);

/* ---- optimized centers of rotation (precomputation) ------------------------------------ */

typedef struct ak_skin_cor_desc {
    ak_vec3_cspan positions;   /* required: bind-space positions */
    ak_u32_cspan indices;      /* required: triangles, 3 per */
    ak_u16_cspan joints;       /* required: vertex_count * influence_count */
    ak_f32_cspan weights;      /* required: same layout, valid (ak_skin_weights_validate) */
    uint32_t influence_count;  /* required: 1..AK_MAX_INFLUENCES */
    float sigma;               /* similarity kernel width; 0 -> 0.1 (the paper's value) */
    float subdivision_threshold; /* split an edge while the L2 distance of its end weights
                                    exceeds this; 0 -> 0.1 */
    uint32_t thread_count;     /* 0 -> 2; 1 -> calling thread only */
    bool naive;                /* false -> triangles indexed by bone pair, vertices with
                                  equal weights computed once; true -> the plain
                                  O(vertices x triangles) reference loop (tests) */
} ak_skin_cor_desc;

/* The desc with every zero field replaced by its documented default. */
AK_API ak_skin_cor_desc ak_skin_cor_desc_resolved(const ak_skin_cor_desc* desc);

/* 64-bit FNV-1a hash of positions, indices, joints, weights, influence_count, sigma and the
 * subdivision threshold: the key of a cached centers file. 0 for a NULL desc. */
AK_API uint64_t ak_skin_cor_key(const ak_skin_cor_desc* desc);

/* One center of rotation per vertex (Le & Hodgins 2016): p*_i = sum_t s(w_i, w_t) a_t c_t /
 * sum_t s(w_i, w_t) a_t over the triangles t of the mesh after subdividing edges (until end
 * weights differ by at most the threshold; at most 12 levels), a_t the area, c_t the centroid,
 * w_t the mean of the corner weights, s(w_p, w_v) = sum_{j != k} w_pj w_pk w_vj w_vk
 * exp(-(w_pj w_vk - w_pk w_vj)^2 / sigma^2). Accumulated in double precision.
 * Fallback: a vertex with a single influence, or whose similarity with every triangle is 0,
 * gets its own position (CoR then equals rigid / LBS skinning for it).
 * Needs out_centers.count >= vertex_count. Returns AK_ERR_NULL_ARG, AK_ERR_EMPTY,
 * AK_ERR_BAD_ARG (influence_count, indices.count % 3, sigma or threshold <= 0, more than 64
 * threads),
 * AK_ERR_SPAN_SMALL, AK_ERR_BAD_INDEX (triangle index), AK_ERR_BAD_WEIGHTS (NaN or negative
 * weight), AK_ERR_BAD_DATA (NaN position), AK_ERR_NO_MEMORY. */
AK_API ak_result ak_skin_cor_centers_compute(const ak_skin_cor_desc* desc, const ak_allocator* alloc,
                                             ak_vec3_span out_centers);

/* CoR centers file: 24-byte header then the centers.
 *   bytes 0..3 magic "AKCR", 4..7 u32 version (1), 8..11 u32 vertex_count, 12..15 zero,
 *   16..23 u64 key (ak_skin_cor_key), then f32 xyz[vertex_count], little-endian. */
/* Bytes of an encoded centers buffer: 24 + 12 * vertex_count (0 when vertex_count >= 2^32). */
AK_API size_t ak_skin_cor_centers_encoded_size(size_t vertex_count);
/* Encode centers.count centers with their key into out_buffer (count >= the size above);
 * *out_size (optional) gets the bytes written. Returns AK_ERR_NULL_ARG, AK_ERR_BAD_ARG
 * (vertex_count >= 2^32), AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_skin_cor_centers_encode(ak_vec3_cspan centers, uint64_t key, ak_u8_span out_buffer,
                                            size_t* out_size);
/* Decode centers whose key equals key into out_centers (count >= the stored vertex count).
 * Returns AK_ERR_NULL_ARG, AK_ERR_PARSE (bad magic, version or truncated buffer),
 * AK_ERR_NOT_FOUND (the key differs: the cache is stale), AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_skin_cor_centers_decode(ak_u8_cspan buffer, uint64_t key, ak_vec3_span out_centers);
/* ak_skin_cor_centers_encode to a file (the whole buffer is built in memory with malloc
 * first). Encode's codes plus AK_ERR_IO, AK_ERR_NO_MEMORY. */
AK_API ak_result ak_skin_cor_centers_write_file(const char* path, ak_vec3_cspan centers, uint64_t key);
/* Read and decode a centers file. Decode's codes plus AK_ERR_IO (missing or unreadable file),
 * AK_ERR_NO_MEMORY. */
AK_API ak_result ak_skin_cor_centers_read_file(const char* path, uint64_t key, ak_vec3_span out_centers);
/* Read the centers from cache_path when its key matches, else compute them and write the file
 * (a failed write is not an error: the centers are still returned). *out_from_cache
 * (optional) says which happened. Codes of ak_skin_cor_centers_compute. */
AK_API ak_result ak_skin_cor_centers_cached(const ak_skin_cor_desc* desc, const char* cache_path,
                                            const ak_allocator* alloc, ak_vec3_span out_centers,
                                            bool* out_from_cache);

/* ---- the skinning job ------------------------------------------------------------------- */

typedef enum ak_skin_method {
    AK_SKIN_LBS = 0, /* default: p' = sum_j w_j M_j p; normals by the inverse transpose of the
                        blended matrix (exact for non-rigid blends) */
    AK_SKIN_DQS,     /* dual quaternions: blend the rigid parts, each aligned to the hemisphere
                        of the most influential joint's rotation, normalise, transform. Joints
                        with scale or shear: M_j = [R_j | t_j] S_j (polar decomposition); the
                        stretch S = sum_j w_j S_j is applied first (matrix blend in bind space),
                        then the rigid dual-quaternion blend. */
    AK_SKIN_COR,     /* optimized centers: p' = R (S (p - p*)) + LBS(p*), R the normalised
                        hemisphere-aligned quaternion blend, S the blended stretch (identity
                        for rigid palettes), p* from ak_skin_cor_centers_compute */
    AK_SKIN_METHOD_COUNT
} ak_skin_method;

/* Upper limit on the SIMD kernel ak_skin_job_run may pick (the fastest this CPU has up to the
 * limit is used; tests and benchmarks run every path side by side with it). Every kernel gives
 * the scalar reference's results up to float rounding. */
typedef enum ak_skin_simd {
    AK_SKIN_SIMD_DEFAULT = 0, /* -> the fastest kernel this CPU has (AK_SKIN_SIMD_AVX512) */
    AK_SKIN_SIMD_SCALAR,      /* scalar code (as skip_simd) */
    AK_SKIN_SIMD_AVX2,        /* AVX2+FMA, 8 vertices per block, where the CPU has it */
    AK_SKIN_SIMD_AVX512,      /* AVX-512 (F, VL, DQ, BW), 16 vertices per block, where the CPU
                                 has it, else AVX2 */
    AK_SKIN_SIMD_COUNT
} ak_skin_simd;

/* Streams hold float or uint16_t components: positions/normals 3 floats, tangents 4 floats
 * (xyz direction, w handedness copied), joints influence_count uint16_t, weights
 * influence_count floats. A stride of 0 means tightly packed. Pointers need only the natural
 * alignment of their component type. Speed: the SIMD LBS kernels load palette matrices in
 * 32-byte halves (AVX2) or whole (AVX-512); palettes of up to 128 joints that are not 64-byte
 * aligned are copied to an aligned stack buffer (8 KiB) for meshes of at least 16 vertices per
 * joint; a larger palette is fastest when the caller aligns it to 64 bytes (about 1.1-1.15x).
 * LBS with 1 influence skips the blend (p' = w (M p)), and with normals also the normal's
 * cofactor and renormalisation when every palette matrix is a rotation plus translation
 * (checked per run, O(palette.count)). */
typedef struct ak_skin_job {
    ak_skin_method method;      /* 0 -> AK_SKIN_LBS */
    uint32_t influence_count;   /* required: joints per vertex, 1..AK_MAX_INFLUENCES */
    ak_mat4_cspan palette;      /* required: skinning matrices M_j, affine (bottom row ignored) */
    ak_cstream positions;       /* required: bind-space positions; count = the vertex count */
    ak_cstream joints;          /* required: count >= vertex count */
    ak_cstream weights;         /* required: count >= vertex count */
    ak_cstream normals;         /* optional (ptr NULL -> none): unit bind-space normals
                                   (DQS/CoR rotate them: unit in, unit out) */
    ak_cstream tangents;        /* optional (ptr NULL -> none) */
    ak_cstream cor_centers;     /* AK_SKIN_COR: required, 3 floats per vertex; else unused */
    ak_u32_cspan indices;       /* triangles; only read when normals_from_faces */
    bool normals_from_faces;    /* false -> normals by the skinning transform; true ->
                                   out_normals = area-weighted normals of the deformed
                                   triangles (normals input unused; vertices on no triangle get
                                   (0, 1, 0)) */
    bool skip_data_check;       /* false -> validate also checks every weight, joint index,
                                   position and triangle index (O(n)); true -> only the O(1)
                                   rules. Unchecked joint indices are clamped to the palette,
                                   so bad data never reads out of bounds. The O(n) check reads
                                   the inputs once more (~2 ns per vertex; run splits it over
                                   thread_count threads from 65,536 vertices): per-frame
                                   skinning of data checked once should set true. */
    bool skip_simd;             /* false -> fastest kernel for this CPU (tangents, and DQS/CoR
                                   with scaled or sheared joints, always run the scalar code);
                                   true -> scalar code */
    ak_skin_simd simd_limit;    /* 0 -> no limit (fastest kernel for this CPU); else the
                                   fastest up to this one (out of range: AK_ERR_BAD_ARG) */
    uint32_t thread_count;      /* 0 or 1 -> calling thread; n (<= 64) -> n contiguous ranges,
                                   n - 1 of them on new pthreads (falls back to the calling
                                   thread when a thread cannot start) */
    ak_u8_span scratch;         /* DQS/COR: >= ak_skin_job_scratch_size(job) bytes, any
                                   alignment; LBS: unused */
    ak_stream out_positions;    /* required: count >= vertex count; must not overlap inputs */
    ak_stream out_normals;      /* required when normals.ptr or normals_from_faces */
    ak_stream out_tangents;     /* required when tangents.ptr */
} ak_skin_job;

/* Bytes of scratch the job needs: 0 for LBS, 64 + 128 * palette.count for DQS,
 * 64 + 192 * palette.count for CoR. */
AK_API size_t ak_skin_job_scratch_size(const ak_skin_job* job);

/* Check the job. Rules, in order (the first that fails is returned):
 *  1. AK_ERR_NULL_ARG: job, positions.ptr, palette.ptr, joints.ptr, weights.ptr or
 *     out_positions.ptr is NULL (a zero-initialised job fails here);
 *  2. AK_ERR_BAD_ARG: method out of range, influence_count 0 or > 8, thread_count > 64,
 *     simd_limit out of range, a nonzero stride smaller than its element;
 *  3. AK_ERR_NULL_ARG: normals or normals_from_faces without out_normals.ptr, tangents without
 *     out_tangents.ptr, COR without cor_centers.ptr, normals_from_faces without indices.ptr;
 *  4. AK_ERR_BAD_ARG: indices.count % 3 != 0 (when normals_from_faces);
 *  5. AK_ERR_SPAN_SMALL: any input stream or output shorter than the vertex count, scratch
 *     smaller than ak_skin_job_scratch_size;
 *  6. AK_ERR_BAD_DATA: a palette matrix holds NaN or infinity;
 *  7. (unless skip_data_check) AK_ERR_BAD_WEIGHTS: a weight is NaN or negative, or a vertex's
 *     weights do not sum to 1 within 1e-3; AK_ERR_BAD_INDEX: a joint index >= palette.count;
 *     AK_ERR_BAD_DATA: a position, normal or center is not finite; AK_ERR_BAD_INDEX: a
 *     triangle index >= vertex count. */
AK_API ak_result ak_skin_job_validate(const ak_skin_job* job);

/* Validate, then deform (writing nothing when validation fails). Degenerate blends never
 * give NaN: a normal whose transform vanishes comes out (0, 0, 0). Returns the validate codes. */
AK_API ak_result ak_skin_job_run(const ak_skin_job* job);

/* A copy of job restricted to vertices [first_vertex, first_vertex + vertex_count): every
 * per-vertex stream is offset, palette and scratch are shared (scratch is only read after
 * ak_skin_job_run's per-call preparation, so give each part its own scratch when running
 * parts concurrently). normals_from_faces is not splittable: the part gets AK_ERR_BAD_ARG.
 * Returns AK_ERR_NULL_ARG, AK_ERR_BAD_ARG (range beyond positions.count, normals_from_faces). */
AK_API ak_result ak_skin_job_split(const ak_skin_job* job, size_t first_vertex, size_t vertex_count,
                                   ak_skin_job* out_part);

/* Name of the fastest kernel ak_skin_job_run can use on this CPU: "avx512", "avx2" or
 * "scalar" (AK_NO_SIMD builds: "scalar"). */
AK_API const char* ak_skin_simd_name(void);

/* ---- implicit skinning ------------------------------------------------------------------
 * Vaillant et al. 2013 ("Implicit Skinning: Real-Time Skin Deformation with Contact
 * Modeling") and 2014 ("Robust Iso-Surface Tracking for Interactive Character Skinning").
 *
 * Precompute (ak_skin_implicit_create): the mesh is segmented by dominant joint; each part
 * gets a Hermite RBF implicit (phi(r) = r^3 plus a linear polynomial) fitted to up to
 * samples_per_bone of its vertices (farthest-point sampled, welded area-weighted normals) and
 * one cap sample per hole where it meets another part (the hole's centre, normal pointing out
 * of the part), closing it as the paper does; the HRBF distance d is reparameterised to
 * compact support f = t(d / r) in [0, 1] (1 inside, 0.5 on the surface, 0 beyond r outside;
 * t a C2 quintic; r = support_scale times the part's mean distance to its principal axis).
 * Each vertex keeps its rest iso-value F(v) of the composed field.
 *
 * Per frame (ak_skin_implicit_run): field j moves rigidly with palette matrix M_j (evaluated
 * at M_j^-1 x); fields compose by union (max), plus, where the two strongest fields meet
 * with opposing gradients (a contact: elbow, knee), a bulge term bulge * w * min(f1, f2)^2,
 * w = max(0, -cos angle(grad f1, grad f2)), that swells the skin beside the contact instead
 * of letting it sink. Vertices start from DQS, march along the gradient to their rest
 * iso-value (Newton steps), stop where the gradient turns by more than 55 degrees (the 2014
 * rule at gradient discontinuities: the contact surface), then alternate tangential
 * relaxation (towards the one-ring centroid, in the tangent plane) and re-projection (a step
 * that a later round evaluates anyway is not re-evaluated).
 * Vertices whose DQS position is already at their iso-value (within 1e-4) keep it, so the
 * bind pose reproduces the mesh exactly. Split vertices (same bind position) move together.
 * The fields are sampled once into a grid per bone in bone space (distance and gradient,
 * trilinear per frame: the paper's 3D textures; grid_resolution) behind a per-frame broad
 * phase of the bones' posed boxes.
 * Contact at folded joints (pairs of parts sharing a seam): the contact surface is the plane
 * through the joint bisecting the two parts' posed axes; near it vertices go back to DQS, none
 * passes it (beyond its rest offset), and the touched region is smoothed; on closed meshes the
 * skin beside each folded joint then swells along the volume gradient until the enclosed volume
 * is the rest volume (the bulge on contact). See docs/implicit.md.
 * Multithreaded by vertex ranges with the same result on any thread count. */

typedef struct ak_skin_implicit ak_skin_implicit;

typedef struct ak_skin_implicit_desc {
    ak_vec3_cspan positions;  /* required: bind-space positions */
    ak_u32_cspan indices;     /* required: triangles, 3 per, counter-clockwise from outside */
    ak_u16_cspan joints;      /* required: vertex_count * influence_count */
    ak_f32_cspan weights;     /* required: same layout, valid (ak_skin_weights_validate) */
    uint32_t influence_count; /* required: 1..AK_MAX_INFLUENCES */
    size_t joint_count;       /* required: palette size (joint indices are below it) */
    uint32_t samples_per_bone; /* HRBF samples per part, caps included; 0 -> 48; 8..256 */
    float support_scale;      /* r relative to the part's mean radius; 0 -> 0.5 */
    uint32_t thread_count;    /* fitting threads; 0 -> 2; 1 -> calling thread only */
    float bulge;              /* contact bulge strength; 0 -> 0.5; negative -> none (plain
                                 union); at most 10 */
    uint32_t grid_resolution; /* each part's field is sampled (value and gradient) on a 3D grid
                                 in bone space with this many nodes along the box's longest
                                 side, and evaluated per frame by trilinear interpolation (the
                                 paper's 3D textures); 0 -> 40; 8..128; UINT32_MAX -> no grid:
                                 the HRBFs evaluated directly (hundreds of times slower; a
                                 reference for tests) */
} ak_skin_implicit_desc;

/* The desc with every zero field replaced by its documented default. */
AK_API ak_skin_implicit_desc ak_skin_implicit_desc_resolved(const ak_skin_implicit_desc* desc);

/* 64-bit FNV-1a hash of the inputs and resolved parameters: the key of a cached precompute.
 * 0 for a NULL desc. */
AK_API uint64_t ak_skin_implicit_key(const ak_skin_implicit_desc* desc);

/* Segment, fit one HRBF per part and store the rest iso-values (one allocation; the object
 * keeps copies of the arrays it needs and is then read-only, shareable between threads).
 * Returns AK_ERR_NULL_ARG, AK_ERR_EMPTY (no vertices or triangles), AK_ERR_BAD_ARG
 * (influence_count, indices.count % 3, samples_per_bone, support_scale or bulge out of range,
 * joint_count 0 or > 65535, more than 64 threads), AK_ERR_SPAN_SMALL, AK_ERR_BAD_INDEX
 * (triangle or joint index), AK_ERR_BAD_WEIGHTS, AK_ERR_BAD_DATA (NaN position),
 * AK_ERR_BUDGET (more than 2^24 vertices), AK_ERR_NO_MEMORY. *out is NULL on failure. */
AK_API ak_result ak_skin_implicit_create(const ak_skin_implicit_desc* desc, const ak_allocator* alloc,
                                         ak_skin_implicit** out_implicit);
/* NULL is a no-op. */
AK_API void ak_skin_implicit_destroy(ak_skin_implicit* implicit);
/* Vertex count and part (dominant joint) of vertex v, for viewers and tests; UINT16_MAX when
 * v is out of range. */
AK_API size_t ak_skin_implicit_vertex_count(const ak_skin_implicit* implicit);
AK_API uint16_t ak_skin_implicit_part(const ak_skin_implicit* implicit, size_t vertex_index);
/* Rest iso-value of vertex v (0 when out of range). */
AK_API float ak_skin_implicit_iso(const ak_skin_implicit* implicit, size_t vertex_index);
/* The composed field and its gradient at point x under palette (palette.count >= the
 * object's joint_count); the bind pose when palette.ptr is NULL. */
AK_API float ak_skin_implicit_field(const ak_skin_implicit* implicit, ak_mat4_cspan palette, ak_vec3 x,
                                    ak_vec3* out_gradient);

/* Serialise the object with its key into a file ("AKIS" v1, little-endian; malloc'd buffer)
 * and read it back: read gives AK_ERR_NOT_FOUND when the stored key differs (a stale
 * cache), AK_ERR_PARSE for a malformed file, AK_ERR_IO, AK_ERR_NO_MEMORY. */
AK_API ak_result ak_skin_implicit_write_file(const ak_skin_implicit* implicit, uint64_t key, const char* path);
AK_API ak_result ak_skin_implicit_read_file(const char* path, uint64_t key, const ak_allocator* alloc,
                                            ak_skin_implicit** out_implicit);
/* Read the object from cache_path when its key matches ak_skin_implicit_key(desc), else
 * create it and write the file (a failed write is not an error). *out_from_cache (optional)
 * says which happened. Codes of ak_skin_implicit_create. */
AK_API ak_result ak_skin_implicit_cached(const ak_skin_implicit_desc* desc, const char* cache_path,
                                         const ak_allocator* alloc, ak_skin_implicit** out_implicit,
                                         bool* out_from_cache);

typedef struct ak_skin_implicit_job {
    const ak_skin_implicit* implicit; /* required */
    ak_mat4_cspan palette;       /* required: skinning matrices (count >= joint_count) */
    uint32_t iterations;         /* Newton steps per projection; 0 -> 10 */
    uint32_t relax_rounds;       /* relaxation + re-projection rounds; 0 -> 3 (UINT32_MAX -> none);
                                    the rounds before the last re-project with one Newton step
                                    (checked by the next round), the last converges */
    uint32_t thread_count;       /* 0 or 1 -> calling thread; n (<= 64) -> n vertex ranges */
    ak_skin_simd simd_limit;     /* the projections' field kernel: 0 -> the fastest this CPU has
                                    (16 vertices at once with AVX-512, 8 with AVX2); else the
                                    fastest up to this one (AK_SKIN_SIMD_SCALAR: one vertex at a
                                    time). Every kernel gives the same bits; out of range:
                                    AK_ERR_BAD_ARG */
    ak_u8_span scratch;          /* >= ak_skin_implicit_scratch_size(implicit, palette.count) */
    ak_vec3_span out_positions;  /* required: count >= vertex count */
    ak_vec3_cspan normals;       /* optional: unit bind-space normals (count >= vertex count),
                                    rotated by DQS where the projection leaves the surface as
                                    it is */
    ak_vec3_span out_normals;    /* optional: normals of the result: area-weighted face normals
                                    (welded) around moved vertices, elsewhere the rotated input
                                    normals (all face normals without input normals) */
    size_t* out_moved;           /* optional: vertices the projection moved */
} ak_skin_implicit_job;

/* Bytes of scratch a run needs (0 for a NULL object). */
AK_API size_t ak_skin_implicit_scratch_size(const ak_skin_implicit* implicit, size_t palette_count);

/* Deform. Returns AK_ERR_NULL_ARG, AK_ERR_BAD_ARG (thread_count > 64, simd_limit out of range),
 * AK_ERR_SPAN_SMALL (palette, scratch, normals or an output), AK_ERR_BAD_DATA (a palette matrix
 * not finite or not invertible); writes nothing on error. Never allocates except thread stacks. */
AK_API ak_result ak_skin_implicit_run(const ak_skin_implicit_job* job);

#ifdef __cplusplus
}
#endif
#endif /* ANIMKIT_SKIN_H */
