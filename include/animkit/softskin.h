/* animkit softskin: volumetric (soft-tissue) skinning: a tetrahedral lattice inside the mesh,
 * bones inside it driving the flesh around them, the flesh simulated with XPBD.
 *
 * What it does:
 *   - builds a tetrahedral lattice inside a closed triangle mesh: a regular grid of cubes over
 *     the mesh's bounds (`resolution` cubes along the longest side), keeping the cubes whose
 *     centre is inside the mesh (signed crossings of a ray along +X: the winding number of a
 *     closed mesh) or that hold a surface vertex, each cube split into 6 tetrahedra (Kuhn:
 *     consistent across neighbouring cubes); a cube whose corners lie nearest to bones more
 *     than two skeleton steps apart (one step: bones that meet at an end or share a joint) is
 *     dropped, so the two thighs, or a hanging forearm and the chest, are not joined;
 *   - embeds each surface vertex barycentrically in the tetrahedron that holds it (a vertex in
 *     no kept cube: the nearest tetrahedron, with extrapolated barycentrics);
 *   - each bone that owns surface vertices (their largest weight is its joint's; nearest bone of
 *     that joint) gets a capsule around its segment: radius bone_radius times the median
 *     distance of those vertices from the segment, at least 1.2 lattice cubes. Every node gets
 *     inverse-distance weights to these bones (ak_skin_weights_compute's DISTANCE method). A node
 *     inside its own bone's capsule, bound to one joint (largest weight >= 0.99) and farther than
 *     joint_zone capsule radii from every other bone is kinematic: it follows the skeleton by linear
 *     blend skinning of the node (the bone; the flesh around a joint stays free, so that the
 *     two bones' cores do not crush it at a deep bend); a connected piece of the lattice with no
 *     kinematic node is kinematic whole;
 *   - the other nodes are flesh, simulated with XPBD (Macklin, Mueller, Chentanez 2016) and the
 *     stable Neo-Hookean constraints of Macklin & Mueller 2021 per tetrahedron: deviatoric
 *     C_D = |F|_F with compliance 1 / (mu V), hydrostatic C_H = det F - (1 + mu / lambda) with
 *     compliance 1 / (lambda V), solved together as one 2x2 system (their coupled solve), with
 *     stiffness-proportional (Rayleigh) damping of the deviatoric constraint (XPBD eq. 26 with
 *     gamma = damping / h; each row damps motion along its own gradient, so the stress-free
 *     rest stays a fixed point), `substeps` substeps of one Gauss-Seidel sweep per step (8
 *     tetrahedra of a colour at once with AVX2 where the CPU has it: the same bits), lumped
 *     masses from the density, and jiggle damping: each substep the flesh's velocity relative
 *     to its skinned velocity (from previous_palette) decays by exp(-jiggle_damping h);
 *   - collisions between body parts, two kinds: (1) where a bone starts at another's end (a
 *     knee, an elbow), the flesh of each side (nodes whose largest weight is that side's joint,
 *     on that side at the bind pose, within the longer bone plus two flesh radii of the joint)
 *     stays on its side of the plane through the joint that bisects the two posed bones, so
 *     the two sides press flat against each other instead of passing through; at a joint
 *     bent past 90 deg (and not at the bind pose) the plane also holds, for that step, the
 *     nodes of the parts beyond the two bones (the joint above the upper bone, every joint
 *     below the lower one: the hips and the foot at a knee) whose skinned positions lie within
 *     3 lattice cubes of the other side's (the heel against the buttock); (2) a flesh node
 *     stays outside the core (bone_radius x its flesh radius) of every other joint's bone that
 *     it was outside of at the bind pose;
 *   - determinism and threads: tetrahedra are coloured at build time (no two of a colour share
 *     a node) and solved colour by colour, so the result is bit-identical for every
 *     thread_count; threads split each colour and the per-node phases.
 *
 * What it does NOT do: general self-collision of the surface (only the two kinds above),
 * continuous collision detection, morph targets (the bind positions are embedded), or separate
 * lattice copies for parts that one cube spans (parts at most two skeleton steps apart stay
 * joined; farther ones are cut apart, their surface vertices extrapolated from a neighbouring
 * cube of their own part). The lattice is coarse next to the mesh (resolution 32: two to four cubes across
 * a limb), so the surface follows the tetrahedra's piecewise-linear motion: visible facets at
 * strong deformations. Normals: compute them from the deformed surface (ak_normals_compute).
 *
 * Usage (palette indexed like the mesh's joint indices, see skin.h):
 *     ak_skin_soft_desc d = { .positions = {mesh->positions, n},
 *                             .indices = {mesh->indices, 3 * mesh->triangle_count},
 *                             .joints = {mesh->joints, n * k}, .weights = {mesh->weights, n * k},
 *                             .influence_count = k, .bones = {bones, bone_count} };
 *     ak_skin_soft* soft = NULL;
 *     if (ak_skin_soft_create(&d, NULL, &soft) != AK_OK) return 1;
 *     size_t nodes = ak_skin_soft_node_count(soft);
 *     ak_vec3 *x = malloc(nodes * sizeof *x), *v = malloc(nodes * sizeof *v);
 *     ak_skin_soft_state_init(soft, first_palette, (ak_vec3_span){x, nodes}, (ak_vec3_span){v, nodes});
 *     ak_skin_soft_step_job job = { .soft = soft, .dt = 1.0f / 60,
 *                                   .node_positions = {x, nodes}, .node_velocities = {v, nodes},
 *                                   .scratch = {scratch, ak_skin_soft_step_scratch_size(soft)},
 *                                   .out_positions = {out, n} };
 *     each frame: job.previous_palette = job.palette; job.palette = palette;
 *                 ak_skin_soft_step_run(&job);
 *     ak_skin_soft_destroy(soft);
 *
 * Ownership and threading: the built ak_skin_soft is immutable and may be shared between
 * threads; the state (node positions and velocities) belongs to the caller. Create allocates
 * through the optional allocator; the step never allocates (thread_count > 1 starts pthreads).
 */
#ifndef ANIMKIT_SOFTSKIN_H
#define ANIMKIT_SOFTSKIN_H

#include "skin.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ak_skin_soft ak_skin_soft;

typedef struct ak_skin_soft_desc {
    ak_vec3_cspan positions;   /* required: bind-space surface positions */
    ak_u32_cspan indices;      /* required: triangles, 3 per, counter-clockwise from outside;
                                  the mesh should be closed (the inside test) */
    ak_u16_cspan joints;       /* required: vertex_count * influence_count palette indices */
    ak_f32_cspan weights;      /* required: same layout (decides which joint owns a vertex) */
    uint32_t influence_count;  /* required: 1..AK_MAX_INFLUENCES */
    ak_skin_bone_cspan bones;  /* required, >= 1: bind-space bones (ak_skin_bones_from_joints);
                                  joint_index is a palette index */
    uint32_t resolution;       /* lattice cubes along the longest side of the bounds, 2..256;
                                  0 -> 32 (CesiumMan: 1660 nodes, 5226 tetrahedra) */
    float youngs_modulus;      /* E in pascals, > 0; 0 -> 5e4 (soft tissue: 1e4 .. 1e5) */
    float poisson_ratio;       /* nu in (0, 0.4999]; 0 -> 0.499 (nearly incompressible: the
                                  volume holds within 1% at a 150-degree bend) */
    float density;             /* kg / m^3, > 0; 0 -> 1000 */
    float damping;             /* Rayleigh stiffness-proportional damping of the deviatoric
                                  constraint in seconds; 0 -> 0.1; negative -> none */
    uint32_t substeps;         /* per step, 1..1000; 0 -> 40 (one Gauss-Seidel sweep each:
                                  the finer lattice needs them to keep its volume) */
    float bone_radius;         /* kinematic capsule radius as a fraction of the median flesh
                                  radius of the bone, in (0, 1]; 0 -> 0.5 */
    size_t memory_budget;      /* most bytes create may allocate; 0 -> 512 MiB */
    float jiggle_damping;      /* 1/s: the flesh's velocity relative to the skinned motion
                                  (see previous_palette) decays as exp(-jiggle_damping t);
                                  0 -> 5; negative -> none */
    float joint_zone;          /* flesh zone around a joint, in kinematic capsule radii (at
                                  most half the bone's length), in (0, 100]; 0 -> 1.5, and at
                                  least 2 flesh radii of a bone whose capsule (bone_radius x
                                  flesh radius) is above the 1.2-cube floor (a limb the lattice
                                  resolves: the fat builtin cylinder; tuned on it and on
                                  CesiumMan's knee and elbow at 130 degrees, docs/softskin.md).
                                  Explicit: capsule radii only. Smaller: more of the limb near
                                  a joint follows the bone */
    bool join_distant_parts;   /* false (default): drop the lattice cells whose corners lie
                                  nearest to bones that share no joint (keeps the two legs,
                                  an arm and the chest apart); true: keep them (limbs closer
                                  than a cube are joined; the behaviour before, for comparison) */
} ak_skin_soft_desc;

/* The desc with every zero field replaced by its documented default. */
AK_API ak_skin_soft_desc ak_skin_soft_desc_resolved(const ak_skin_soft_desc* desc);

/* Build the lattice, the embedding, the kinematic flags and node weights, rest shapes, masses
 * and the tetrahedron colouring. Returns AK_ERR_NULL_ARG, AK_ERR_EMPTY (no vertices, no
 * triangles or no bones; or no cube kept), AK_ERR_BAD_ARG (a parameter outside its range,
 * indices.count % 3, influence_count, more than 2^31 vertices or 65535 bones, an allocator
 * with only one function), AK_ERR_SPAN_SMALL (joints or weights shorter than vertex_count *
 * influence_count), AK_ERR_BAD_INDEX (a triangle index >= vertex count), AK_ERR_BAD_WEIGHTS (a
 * NaN or negative weight), AK_ERR_BAD_DATA (NaN or infinite position or bone, a mesh with zero
 * extent), AK_ERR_BUDGET (the lattice would take more than memory_budget, checked before
 * allocating), AK_ERR_UNSUPPORTED (the tetrahedra need more than 128 colours: not seen for the
 * lattice), AK_ERR_NO_MEMORY. Joint indices are checked against the palette by the step.
 * Create costs O(cubes + triangles x ray columns they cover + nodes x bones). On failure
 * *out_soft is NULL. */
AK_API ak_result ak_skin_soft_create(const ak_skin_soft_desc* desc, const ak_allocator* alloc,
                                     ak_skin_soft** out_soft);
/* Free; NULL is a no-op. */
AK_API void ak_skin_soft_destroy(ak_skin_soft* soft);

/* Lattice nodes (the length of the state arrays); 0 for NULL. */
AK_API size_t ak_skin_soft_node_count(const ak_skin_soft* soft);
/* Tetrahedra; 0 for NULL. */
AK_API size_t ak_skin_soft_tet_count(const ak_skin_soft* soft);
/* Kinematic nodes (inside a bone capsule); 0 for NULL. */
AK_API size_t ak_skin_soft_kinematic_count(const ak_skin_soft* soft);
/* Surface vertices embedded (the vertex count of the desc); 0 for NULL. */
AK_API size_t ak_skin_soft_vertex_count(const ak_skin_soft* soft);
/* Lattice cells dropped because their corners belong to bones that share no joint (see
 * join_distant_parts); 0 for NULL. */
AK_API size_t ak_skin_soft_cut_cell_count(const ak_skin_soft* soft);
/* Bind-space node positions into out (count >= node count). AK_ERR_NULL_ARG,
 * AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_skin_soft_rest_nodes(const ak_skin_soft* soft, ak_vec3_span out_positions);
/* 1 for each kinematic node, 0 for flesh, into out (count >= node count). AK_ERR_NULL_ARG,
 * AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_skin_soft_kinematic_flags(const ak_skin_soft* soft, ak_u8_span out_flags);
/* Node indices of the tetrahedra, 4 per, into out (count >= 4 * tet count). AK_ERR_NULL_ARG,
 * AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_skin_soft_tets(const ak_skin_soft* soft, ak_u32_span out_indices);

/* Put the state at rest under a palette: every node at its linear-blend-skinned position,
 * velocities zero. palette.count must exceed every bone's joint_index. Returns AK_ERR_NULL_ARG,
 * AK_ERR_SPAN_SMALL (a state span or the palette), AK_ERR_BAD_DATA (non-finite palette). */
AK_API ak_result ak_skin_soft_state_init(const ak_skin_soft* soft, ak_mat4_cspan palette,
                                         ak_vec3_span out_node_positions, ak_vec3_span out_node_velocities);

/* Surface positions from node positions (barycentric embedding): out.count >= vertex count.
 * Returns AK_ERR_NULL_ARG, AK_ERR_SPAN_SMALL. */
AK_API ak_result ak_skin_soft_surface(const ak_skin_soft* soft, ak_vec3_cspan node_positions,
                                      ak_vec3_span out_positions);

/* Bytes of scratch one step needs. */
AK_API size_t ak_skin_soft_step_scratch_size(const ak_skin_soft* soft);

/* Advance the state by dt towards the pose of `palette` (the kinematic nodes move linearly
 * from where they are to their skinned positions across the substeps). */
typedef struct ak_skin_soft_step_job {
    const ak_skin_soft* soft;       /* required */
    ak_mat4_cspan palette;          /* required: this step's end pose; count > every bone's
                                       joint_index */
    ak_mat4_cspan previous_palette; /* optional (ptr NULL -> none): the previous step's palette
                                       (count >= palette.count): jiggle damping then damps the
                                       flesh's motion relative to the skinned motion; without it,
                                       the absolute velocity (a drag). The colliders (bone cores,
                                       joint planes) also move from its pose to palette's across
                                       the substeps, so it must be the previous step's: a stale
                                       one (a held pose passing an older palette) makes them jump
                                       back at every step */
    float dt;                       /* seconds, in (0, 1]; 0 -> 1/60 */
    ak_vec3 gravity;                /* m/s^2 on the flesh; zero -> none */
    ak_vec3_span node_positions;    /* required: state, in and out (count >= node count) */
    ak_vec3_span node_velocities;   /* required: state, in and out */
    ak_u8_span scratch;             /* required: >= ak_skin_soft_step_scratch_size bytes */
    ak_vec3_span out_positions;     /* optional (ptr NULL -> none): the surface afterwards */
    float* out_kinetic_energy;      /* optional: joules of the flesh nodes afterwards */
    uint32_t thread_count;          /* 0 or 1 -> calling thread; n (<= 64) -> up to n threads,
                                       at most one per 4096 nodes (a barrier per colour and
                                       substep: worth it from a few thousand nodes) */
} ak_skin_soft_step_job;

/* Check the job: AK_ERR_NULL_ARG (soft, palette, a state span or scratch NULL), AK_ERR_BAD_ARG
 * (dt outside [0, 1], thread_count > 64, non-finite gravity), AK_ERR_SPAN_SMALL (state,
 * palette or previous_palette, scratch or out_positions), AK_ERR_BAD_DATA (non-finite
 * palette or previous palette). */
AK_API ak_result ak_skin_soft_step_validate(const ak_skin_soft_step_job* job);
/* Validate, then step (writing nothing when validation fails). A state that went non-finite
 * (it cannot from finite input) is reset to the skinned rest. Returns the validate codes. */
AK_API ak_result ak_skin_soft_step_run(const ak_skin_soft_step_job* job);

#ifdef __cplusplus
}
#endif
#endif /* ANIMKIT_SOFTSKIN_H */
