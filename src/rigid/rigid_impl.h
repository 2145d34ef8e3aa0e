/* Internal types of the rigid-body module shared by rigid.c, collide.c and step.c. */
#ifndef AK_RIGID_IMPL_H
#define AK_RIGID_IMPL_H

#include <math.h>

#include <animkit/rigid.h>

/* Pose of a body as the narrow phase reads it. */
typedef struct rigid_pose {
    ak_vec3 x;
    ak_quat q;
} rigid_pose;

/* A convex hull in its body's frame (centre of mass at the origin, principal axes). Faces are
 * convex polygons (coplanar triangles merged), their vertices counter-clockwise seen from
 * outside; edges join two faces (f0, f1). */
typedef struct akp_hull_face {
    ak_vec3 n;             /* outward unit normal */
    float d;               /* plane: n . x = d */
    uint32_t first, count; /* vertex indices idx[first .. first + count) */
} akp_hull_face;

typedef struct akp_hull_edge {
    uint32_t v0, v1, f0, f1;
} akp_hull_edge;

typedef struct akp_hull {
    const ak_vec3* verts;
    const akp_hull_face* faces;
    const uint32_t* idx;
    const akp_hull_edge* edges;
    uint32_t nv, nf, ne;
    ak_vec3 centroid; /* centre of mass in the shape frame */
    ak_quat frame;    /* principal axes in the shape frame (body = shape * frame) */
    double volume;    /* m^3 */
    ak_vec3 inertia_per_mass; /* principal moments / mass (m^2) */
    float bound_radius;       /* max |vertex| */
} akp_hull;

/* Bytes akp_rigid_hull_build writes for `count` points (an upper bound, 16-byte multiple) and
 * the scratch it needs. */
size_t akp_rigid_hull_size(size_t count);
size_t akp_rigid_hull_scratch_size(size_t count);
/* Build the hull of points into mem (akp_rigid_hull_size bytes, 16-aligned) with scratch
 * (akp_rigid_hull_scratch_size bytes, 8-aligned); *out_hull points into mem. AK_ERR_BAD_ARG /
 * AK_ERR_BAD_DATA with *out_problem saying why. */
ak_result akp_rigid_hull_build(ak_vec3_cspan points, void* mem, void* scratch, akp_hull** out_hull,
                               const char** out_problem);

/* Principal axes of a symmetric inertia tensor (modified): *out_frame's columns are the axes
 * (identity when the tensor is diagonal to 1e-6), *out_moments the moments about them. */
void akp_rigid_principal(double inert[3][3], ak_quat* out_frame, ak_vec3* out_moments);

/* A compound body's children in the body frame (centre of mass, principal axes). */
typedef struct akp_compound {
    uint32_t count;
    struct rigid_body* kids; /* shape, hull and bound radius of each child (no mass) */
    rigid_pose* poses;       /* each child's body frame in the compound's body frame */
    ak_vec3 centroid;        /* centre of mass in the shape frame */
    ak_quat frame;           /* principal axes in the shape frame */
    double volume;           /* summed over the children (m^3) */
    ak_vec3 inertia_per_mass;
    float bound_radius;
} akp_compound;

/* Distance between two convex shapes by GJK: the closest points pa (on a) and pb (on b) of the
 * shapes' cores (hull, box, a capsule's segment, a sphere's centre), radii not included. Returns
 * false when the cores overlap. Exposed for tests. */
bool akp_rigid_gjk(const ak_rigid_shape* sa, const akp_hull* ha, rigid_pose pa,
                   const ak_rigid_shape* sb, const akp_hull* hb, rigid_pose pb,
                   ak_vec3* out_pa, ak_vec3* out_pb);

/* A static heightfield or triangle mesh in its body's frame (copied into the model). */
typedef struct akp_bvh_node {
    ak_vec3 lo, hi;
    uint32_t first; /* leaf: into order; inner: the left child (the right is first + 1) */
    uint32_t count; /* triangles of a leaf; 0 for an inner node */
} akp_bvh_node;

typedef struct akp_mesh {
    bool is_heightfield;
    const float* heights; /* [rows * cols] */
    uint32_t rows, cols;
    float spacing;
    float min_height, max_height;
    const ak_vec3* verts; /* trimesh */
    const uint32_t* tris; /* [3 * nt] */
    uint32_t nv, nt;
    const akp_bvh_node* nodes; /* nodes[0] the root */
    const uint32_t* order;     /* triangle indices in leaf order */
    float bound_radius;        /* max distance of the mesh from the body's origin */
} akp_mesh;

/* Bytes akp_rigid_mesh_build writes for a heightfield or trimesh shape (16-byte multiple), the
 * scratch it needs, and the build into mem (16-aligned). The shape must be valid (checked by
 * akp_rigid_mesh_check). */
size_t akp_rigid_mesh_size(const ak_rigid_shape* s);
size_t akp_rigid_mesh_scratch_size(const ak_rigid_shape* s);
akp_mesh* akp_rigid_mesh_build(const ak_rigid_shape* s, void* mem, void* scratch);
ak_result akp_rigid_mesh_check(const ak_rigid_shape* s);

/* What the solver reads per body, resolved once at build time. */
typedef struct rigid_body {
    /* (a compound's children are rigid_body too: only shape, hull and bound_radius are set) */
    ak_rigid_shape shape;   /* resolved (plane normal normalised) */
    float inv_mass;         /* 1/kg; 0 static */
    ak_vec3 inv_inertia;    /* 1/(kg m^2) about the local axes; 0 static */
    ak_vec3 inertia;        /* kg m^2 (INFINITY static) */
    float mass;             /* kg (INFINITY static) */
    float friction;         /* static mu, resolved */
    float dynamic_friction; /* dynamic mu, resolved */
    float restitution;
    float bound_radius; /* metres from the centre that holds the shape (planes: INFINITY) */
    uint32_t group;     /* collision group (0: none) */
    const akp_hull* hull; /* AK_RIGID_HULL: the hull (in the model's allocation); else NULL */
    const akp_mesh* mesh; /* heightfield, trimesh: the mesh (in the model's allocation) */
    const akp_compound* compound; /* compound: its children (in the model's allocation) */
} rigid_body;

/* A joint with its anchors and axes in each body's frame (from the descs' poses). */
typedef struct rigid_joint {
    ak_rigid_joint_type type;
    uint32_t a, b;
    ak_vec3 la, lb;           /* anchors, local */
    ak_vec3 axis_a, axis_b;   /* the joint axis in each body's frame */
    ak_vec3 perp_a, perp_b;   /* a reference direction perpendicular to it, in each frame */
    ak_quat rel;              /* b's orientation in a's frame as built */
    ak_quat drive_target;     /* b's orientation in a's frame the drive aims at */
    ak_quat frame_a, frame_b; /* ball: joint frames (Y along the axis) in each body */
    bool limited, drive, twist_limited;
    float lower, upper, compliance, drive_compliance, angle_offset, twist_lower, twist_upper;
    float drive_damping; /* 1/s: the drive's relative angular velocity damped each substep */
    float cos_upper;     /* ball: cos(upper), -INFINITY when upper >= pi, INFINITY when < 0 */
    /* ball with a twist limit: the half-angle bounds L = (twist_lower - angle_offset) / 2 and
     * H = (twist_upper - angle_offset) / 2 as cosines and sines, used (twist_fast) when both
     * lie inside (-pi/2, pi/2) by 0.01 */
    bool twist_fast;
    float twist_cl, twist_sl, twist_ch, twist_sh;
} rigid_joint;

/* Signed angle (rad) of body b about the hinge axis relative to a, zero as built. */
static inline float akp_rigid_hinge_angle(const rigid_joint* j, ak_quat qa, ak_quat qb) {
    ak_vec3 n = ak_quat_rotate(qa, j->axis_a);
    ak_vec3 b1 = ak_quat_rotate(qa, j->perp_a), b2 = ak_quat_rotate(qb, j->perp_b);
    return atan2f(ak_vec3_dot(ak_vec3_cross(b1, b2), n), ak_vec3_dot(b1, b2));
}

/* Twist (rad) of b relative to a (ball joints), as a swing-twist decomposition measures it:
 * rel = (qa frame_a)^-1 (qb frame_b) = swing * twist with the twist about the frames' Y (the
 * joint axis); zero as built. *out_n gets the twist axis in the world (b's axis). */
static inline float akp_rigid_twist_angle(const rigid_joint* j, ak_quat qa, ak_quat qb,
                                          ak_vec3* out_n) {
    ak_quat fa = ak_quat_mul(qa, j->frame_a), fb = ak_quat_mul(qb, j->frame_b);
    ak_quat rel = ak_quat_mul(ak_quat_conjugate(fa), fb);
    *out_n = ak_quat_rotate(fb, ak_vec3_make(0.0f, 1.0f, 0.0f));
    float t = 2.0f * atan2f(rel.y, rel.w);
    if (t > 3.14159265f) t -= 6.2831853f;
    if (t < -3.14159265f) t += 6.2831853f;
    return t;
}

struct ak_rigid_model {
    ak_allocator alloc;
    ak_rigid_model_desc desc; /* resolved; bodies points at descs */
    size_t body_count;
    size_t plane_count;
    uint32_t* planes; /* [plane_count]: the planes' body indices, in order */
    rigid_body* bodies;
    ak_rigid_body_desc* descs;
    rigid_joint* joints;
    size_t joint_count;
};

/* One contact point found by the narrow phase. n points from body b to body a: pushing a along
 * +n separates them. la, lb are the contact points in each body's local frame (for a plane:
 * world). depth = (pb - pa) . n > 0 when the shapes overlap. */
typedef struct rigid_contact {
    uint32_t a, b;
    ak_vec3 n;
    ak_vec3 la, lb;
    float depth;
    float lambda_n;  /* accumulated normal position impulse (kg m) of this substep */
    float vn_before; /* relative normal velocity before the solve (m/s) */
    float friction, dynamic_friction, restitution;
} rigid_contact;


/* Contact points between bodies a and b (a dynamic or both any; never two planes) into out (at
 * most cap, returns how many were written; *out_wanted counts every point found). n of each
 * points from b to a. Only points with separation < margin are reported. */
int akp_rigid_collide(const ak_rigid_model* m, uint32_t a, uint32_t b, rigid_pose pa, rigid_pose pb,
                      float margin, rigid_contact* out, int cap);

#define AKP_RIGID_MAX_PAIR_CONTACTS 8

/* ak_rigid_step_run with the islands (bodies joined by contacts and joints, solved one after
 * another or on the worker team) allowed or not: the results are the same to the bit either
 * way, which the tests check. ak_rigid_step_run allows them. */
ak_result akp_rigid_step_run(const ak_rigid_step_job* job, bool islands);

#endif
