/* Internal types of the rigid-body module shared by rigid.c, collide.c and step.c. */
#ifndef AK_RIGID_IMPL_H
#define AK_RIGID_IMPL_H

#include <math.h>

#include <animkit/rigid.h>

/* What the solver reads per body, resolved once at build time. */
typedef struct rigid_body {
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

/* Pose of a body as the narrow phase reads it. */
typedef struct rigid_pose {
    ak_vec3 x;
    ak_quat q;
} rigid_pose;

/* Contact points between bodies a and b (a dynamic or both any; never two planes) into out (at
 * most cap, returns how many were written; *out_wanted counts every point found). n of each
 * points from b to a. Only points with separation < margin are reported. */
int akp_rigid_collide(const ak_rigid_model* m, uint32_t a, uint32_t b, rigid_pose pa, rigid_pose pb,
                      float margin, rigid_contact* out, int cap);

#define AKP_RIGID_MAX_PAIR_CONTACTS 8

#endif
