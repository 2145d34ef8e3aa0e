/* Rigid bodies as one-way colliders of the fluid (ak_rigid_fluid_colliders): each body's shape
 * as the fluid's own collider shapes, at the bodies' state, with the bodies' velocities. */
#include <animkit/fluid.h>

#include "rigid_impl.h"

/* Colliders and planes one shape needs (0 for a trimesh: not passed). */
static void shape_need(const ak_rigid_shape* s, const akp_hull* hull, const akp_compound* comp,
                       size_t* nc, size_t* np) {
    switch (s->type) {
    case AK_RIGID_SPHERE:
    case AK_RIGID_BOX:
    case AK_RIGID_CAPSULE:
    case AK_RIGID_PLANE:
    case AK_RIGID_HEIGHTFIELD:
        *nc += 1;
        break;
    case AK_RIGID_HULL:
        if (hull) *nc += 1, *np += hull->nf;
        break;
    case AK_RIGID_COMPOUND:
        if (comp)
            for (uint32_t k = 0; k < comp->count; ++k)
                shape_need(&comp->kids[k].shape, comp->kids[k].hull, NULL, nc, np);
        break;
    default:
        break;
    }
}

void ak_rigid_fluid_colliders_size(const ak_rigid_model* model, size_t* out_collider_count,
                                   size_t* out_plane_count) {
    size_t nc = 0, np = 0;
    for (size_t i = 0; model && i < model->body_count; ++i) {
        const rigid_body* b = &model->bodies[i];
        shape_need(&b->shape, b->hull, b->compound, &nc, &np);
    }
    if (out_collider_count) *out_collider_count = nc;
    if (out_plane_count) *out_plane_count = np;
}

typedef struct emit_ctx {
    ak_fluid_collider* out;
    ak_vec4* planes;
    size_t nc, np;
    ak_vec3 x, v, w; /* the body's centre of mass, velocity and angular velocity */
} emit_ctx;

/* One shape posed at (px, pq) in the world. */
static void emit_shape(emit_ctx* e, const ak_rigid_shape* s, const akp_hull* hull,
                       const akp_compound* comp, ak_vec3 px, ak_quat pq) {
    if (s->type == AK_RIGID_COMPOUND) {
        if (!comp) return;
        for (uint32_t k = 0; k < comp->count; ++k) {
            const rigid_pose cp = comp->poses[k];
            emit_shape(e, &comp->kids[k].shape, comp->kids[k].hull, NULL,
                       ak_vec3_add(px, ak_quat_rotate(pq, cp.x)), ak_quat_mul(pq, cp.q));
        }
        return;
    }
    if (s->type == AK_RIGID_TRIMESH || (s->type == AK_RIGID_HULL && !hull)) return;
    ak_fluid_collider c = {.a = px, .orientation = pq, .angular_velocity = e->w};
    switch (s->type) {
    case AK_RIGID_SPHERE:
        c.shape = AK_FLUID_SPHERE;
        c.radius = s->radius;
        break;
    case AK_RIGID_CAPSULE: {
        const ak_vec3 axis = ak_quat_rotate(pq, ak_vec3_make(0.0f, s->half_height, 0.0f));
        c.shape = AK_FLUID_CAPSULE;
        c.a = ak_vec3_sub(px, axis);
        c.b = ak_vec3_add(px, axis);
        c.radius = s->radius;
        break;
    }
    case AK_RIGID_BOX:
        c.shape = AK_FLUID_BOX;
        c.half_extents = s->half_extents;
        break;
    case AK_RIGID_HEIGHTFIELD: /* the model's copy of the samples */
        c.shape = AK_FLUID_HEIGHTFIELD;
        c.heights = s->heights.ptr;
        c.rows = s->rows;
        c.cols = s->cols;
        c.spacing = s->spacing;
        break;
    case AK_RIGID_PLANE:
        c.shape = AK_FLUID_PLANE;
        c.normal = s->normal;
        c.orientation = ak_quat_identity();
        break;
    default: /* hull: its faces' planes in the body frame */
        c.shape = AK_FLUID_CONVEX;
        c.planes = e->planes + e->np;
        c.plane_count = hull->nf;
        for (uint32_t f = 0; f < hull->nf; ++f) {
            const akp_hull_face* fc = &hull->faces[f];
            e->planes[e->np++] = ak_vec4_make(fc->n.x, fc->n.y, fc->n.z, fc->d);
        }
        break;
    }
    /* the velocity of the point a: the body's at its centre plus w x (a - x) */
    c.velocity = ak_vec3_add(e->v, ak_vec3_cross(e->w, ak_vec3_sub(c.a, e->x)));
    e->out[e->nc++] = c;
}

ak_result ak_rigid_fluid_colliders(const ak_rigid_model* model, ak_vec3_cspan positions,
                                   ak_quat_cspan orientations, ak_vec3_cspan velocities,
                                   ak_vec3_cspan angular_velocities,
                                   ak_fluid_collider_span out_colliders, ak_vec4_span out_planes,
                                   size_t* out_collider_count) {
    if (out_collider_count) *out_collider_count = 0;
    if (!model || !positions.ptr || !orientations.ptr || !velocities.ptr ||
        !angular_velocities.ptr || !out_colliders.ptr || (!out_planes.ptr && out_planes.count))
        return AK_ERR_NULL_ARG;
    const size_t n = model->body_count;
    size_t nc, np;
    ak_rigid_fluid_colliders_size(model, &nc, &np);
    if (positions.count < n || orientations.count < n || velocities.count < n ||
        angular_velocities.count < n || out_colliders.count < nc || out_planes.count < np)
        return AK_ERR_SPAN_SMALL;
    if (np && !out_planes.ptr) return AK_ERR_NULL_ARG;
    for (size_t i = 0; i < n; ++i)
        if (!ak_vec3_is_finite(positions.ptr[i]) || !ak_quat_is_finite(orientations.ptr[i]) ||
            !ak_vec3_is_finite(velocities.ptr[i]) || !ak_vec3_is_finite(angular_velocities.ptr[i]))
            return AK_ERR_BAD_DATA;
    emit_ctx e = {.out = out_colliders.ptr, .planes = out_planes.ptr};
    for (size_t i = 0; i < n; ++i) {
        const rigid_body* b = &model->bodies[i];
        const bool moves = b->inv_mass > 0.0f;
        e.x = positions.ptr[i];
        e.v = moves ? velocities.ptr[i] : ak_vec3_zero();
        e.w = moves ? angular_velocities.ptr[i] : ak_vec3_zero();
        emit_shape(&e, &b->shape, b->hull, b->compound, positions.ptr[i],
                   ak_quat_normalize(orientations.ptr[i]));
    }
    if (out_collider_count) *out_collider_count = e.nc;
    return AK_OK;
}
