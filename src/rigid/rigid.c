/* Rigid-body model: validation, mass and inertia from shapes, queries. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rigid_impl.h"

static void* def_alloc(size_t size, void* user) {
    (void)user;
    return malloc(size);
}
static void def_free(void* ptr, void* user) {
    (void)user;
    free(ptr);
}

static bool vec_finite(ak_vec3 v) { return ak_vec3_is_finite(v); }

/* Mass (for density 1) and principal moments per unit mass of a shape. */
static void shape_unit_mass(const ak_rigid_shape* s, double* out_volume, ak_vec3* out_i_per_mass) {
    const double pi = 3.14159265358979323846;
    double r = s->radius;
    switch (s->type) {
    case AK_RIGID_SPHERE: {
        *out_volume = 4.0 / 3.0 * pi * r * r * r;
        float k = (float)(0.4 * r * r);
        *out_i_per_mass = ak_vec3_make(k, k, k);
        break;
    }
    case AK_RIGID_BOX: {
        double x = s->half_extents.x, y = s->half_extents.y, z = s->half_extents.z;
        *out_volume = 8.0 * x * y * z;
        /* solid box of sides 2x, 2y, 2z: I_x = m (4y^2 + 4z^2) / 12 */
        *out_i_per_mass =
            ak_vec3_make((float)((y * y + z * z) / 3.0), (float)((x * x + z * z) / 3.0),
                         (float)((x * x + y * y) / 3.0));
        break;
    }
    case AK_RIGID_CAPSULE: {
        double h = s->half_height;
        double vc = pi * r * r * 2.0 * h, vs = 4.0 / 3.0 * pi * r * r * r, v = vc + vs;
        /* cylinder (length 2h) plus two hemispheres whose centres of mass sit 3r/8 beyond the
         * cylinder's ends: about the long axis m r^2/2 and 2 m r^2/5; across it m (r^2/4 +
         * (2h)^2/12) and m (2r^2/5 + h^2 + 3hr/4) */
        double iy = vc * r * r / 2.0 + vs * 0.4 * r * r;
        double ix = vc * (r * r / 4.0 + h * h / 3.0) + vs * (0.4 * r * r + h * h + 0.75 * h * r);
        *out_volume = v;
        *out_i_per_mass = ak_vec3_make((float)(ix / v), (float)(iy / v), (float)(ix / v));
        break;
    }
    default:
        *out_volume = 0.0;
        *out_i_per_mass = ak_vec3_zero();
        break;
    }
}

ak_rigid_model_desc ak_rigid_model_desc_resolved(const ak_rigid_model_desc* desc) {
    ak_rigid_model_desc d;
    memset(&d, 0, sizeof d);
    if (desc) d = *desc;
    if (d.contact_offset == 0.0f) d.contact_offset = 0.01f;
    if (d.sleep_linear_speed == 0.0f) d.sleep_linear_speed = 0.05f;
    if (d.sleep_angular_speed == 0.0f) d.sleep_angular_speed = 0.05f;
    if (d.sleep_time == 0.0f) d.sleep_time = 0.5f;
    if (d.joint_tolerance == 0.0f) d.joint_tolerance = 1e-4f;
    if (d.contact_iterations == 0) d.contact_iterations = 1;
    if (d.max_contacts == 0) {
        size_t n = d.bodies.count > (1u << 24) ? (1u << 24) : d.bodies.count;
        d.max_contacts = (uint32_t)(16 * n + 64);
    }
    return d;
}

static ak_result check_friction(float f) {
    if (!ak_finitef(f)) return AK_ERR_BAD_DATA;
    if (f < 0.0f && f != AK_RIGID_FRICTIONLESS) return AK_ERR_BAD_ARG;
    return AK_OK;
}

static ak_result check_shape(const ak_rigid_shape* s, int depth) {
    if ((unsigned)s->type >= AK_RIGID_SHAPE_COUNT) return AK_ERR_BAD_ARG;
    if (!ak_finitef(s->radius) || !vec_finite(s->half_extents) || !ak_finitef(s->half_height) ||
        !vec_finite(s->normal))
        return AK_ERR_BAD_DATA;
    switch (s->type) {
    case AK_RIGID_SPHERE:
        if (!(s->radius > 0.0f)) return AK_ERR_BAD_ARG;
        break;
    case AK_RIGID_BOX:
        if (!(s->half_extents.x > 0.0f && s->half_extents.y > 0.0f && s->half_extents.z > 0.0f))
            return AK_ERR_BAD_ARG;
        break;
    case AK_RIGID_CAPSULE:
        if (!(s->radius > 0.0f) || s->half_height < 0.0f) return AK_ERR_BAD_ARG;
        break;
    case AK_RIGID_HEIGHTFIELD:
    case AK_RIGID_TRIMESH:
        return depth > 0 ? AK_ERR_BAD_ARG : akp_rigid_mesh_check(s);
    case AK_RIGID_HULL:
        if (s->points.count < 4 || s->points.count > AK_RIGID_HULL_MAX_POINTS) return AK_ERR_BAD_ARG;
        if (!s->points.ptr) return AK_ERR_NULL_ARG;
        for (size_t i = 0; i < s->points.count; ++i)
            if (!vec_finite(s->points.ptr[i])) return AK_ERR_BAD_DATA;
        break;
    case AK_RIGID_COMPOUND:
        /* children are one level deep: no compound or static-only shape inside */
        if (depth > 0 || s->child_count == 0 || s->child_count > AK_RIGID_COMPOUND_MAX_CHILDREN)
            return AK_ERR_BAD_ARG;
        if (!s->children) return AK_ERR_NULL_ARG;
        for (size_t i = 0; i < s->child_count; ++i) {
            const ak_rigid_child* c = &s->children[i];
            if (c->shape.type == AK_RIGID_PLANE) return AK_ERR_BAD_ARG;
            if (!vec_finite(c->position) || !ak_quat_is_finite(c->orientation)) return AK_ERR_BAD_DATA;
            ak_result r = check_shape(&c->shape, depth + 1);
            if (r != AK_OK) return r;
        }
        break;
    default:
        if (depth > 0) return AK_ERR_BAD_ARG;
        break;
    }
    return AK_OK;
}

static ak_result check_body(const ak_rigid_body_desc* b) {
    if (!vec_finite(b->position) || !ak_quat_is_finite(b->orientation) ||
        !vec_finite(b->velocity) || !vec_finite(b->angular_velocity) || !ak_finitef(b->density) ||
        !ak_finitef(b->mass) || !ak_finitef(b->restitution))
        return AK_ERR_BAD_DATA;
    ak_result r = check_shape(&b->shape, 0);
    if (r != AK_OK) return r;
    r = check_friction(b->friction);
    if (r == AK_OK) r = check_friction(b->dynamic_friction);
    if (r != AK_OK) return r;
    if (b->density < 0.0f || b->mass < 0.0f || b->restitution < 0.0f || b->restitution > 1.0f)
        return AK_ERR_BAD_ARG;
    return AK_OK;
}

static size_t align16(size_t s) { return (s + 15) & ~(size_t)15; }

static size_t compound_size(const ak_rigid_shape* s) {
    size_t total = align16(sizeof(akp_compound)) + align16(s->child_count * sizeof(rigid_body)) +
                   align16(s->child_count * sizeof(rigid_pose));
    for (size_t i = 0; i < s->child_count; ++i)
        if (s->children[i].shape.type == AK_RIGID_HULL)
            total += akp_rigid_hull_size(s->children[i].shape.points.count);
    return total;
}

static size_t compound_scratch_size(const ak_rigid_shape* s) {
    size_t most = 0;
    for (size_t i = 0; i < s->child_count; ++i)
        if (s->children[i].shape.type == AK_RIGID_HULL) {
            size_t k = akp_rigid_hull_scratch_size(s->children[i].shape.points.count);
            if (k > most) most = k;
        }
    return most;
}

static float shape_bound(const ak_rigid_shape* s, const akp_hull* h) {
    switch (s->type) {
    case AK_RIGID_SPHERE:
        return s->radius;
    case AK_RIGID_BOX:
        return ak_vec3_length(s->half_extents);
    case AK_RIGID_CAPSULE:
        return s->radius + s->half_height;
    case AK_RIGID_HULL:
        return h->bound_radius;
    default:
        return INFINITY;
    }
}

/* Build a compound's children into mem: each child's volume, centre and inertia summed by the
 * parallel axis theorem (one density), then the principal frame; the children re-expressed in
 * the body frame. */
static ak_result compound_build(const ak_rigid_shape* s, unsigned char* mem, void* scratch,
                                akp_compound** out) {
    akp_compound* c = (akp_compound*)mem;
    unsigned char* p = mem + align16(sizeof(akp_compound));
    rigid_body* kids = (rigid_body*)p;
    p += align16(s->child_count * sizeof(rigid_body));
    rigid_pose* poses = (rigid_pose*)p;
    p += align16(s->child_count * sizeof(rigid_pose));
    double vol = 0.0, cm[3] = {0, 0, 0};
    double vols[AK_RIGID_COMPOUND_MAX_CHILDREN];
    ak_vec3 ipms[AK_RIGID_COMPOUND_MAX_CHILDREN];
    for (size_t i = 0; i < s->child_count; ++i) {
        const ak_rigid_child* ch = &s->children[i];
        rigid_body* k = &kids[i];
        memset(k, 0, sizeof *k);
        k->shape = ch->shape;
        ak_quat q = ak_quat_dot(ch->orientation, ch->orientation) == 0.0f
                        ? ak_quat_identity()
                        : ak_quat_normalize(ch->orientation);
        poses[i] = (rigid_pose){ch->position, q};
        if (ch->shape.type == AK_RIGID_HULL) {
            akp_hull* h = NULL;
            const char* why;
            ak_result r = akp_rigid_hull_build(ch->shape.points, p, scratch, &h, &why);
            if (r != AK_OK) return r;
            p += akp_rigid_hull_size(ch->shape.points.count);
            k->hull = h;
            k->shape.points = (ak_vec3_cspan){h->verts, h->nv};
            poses[i].x = ak_vec3_add(ch->position, ak_quat_rotate(q, h->centroid));
            poses[i].q = ak_quat_normalize(ak_quat_mul(q, h->frame));
            vols[i] = h->volume;
            ipms[i] = h->inertia_per_mass;
        } else {
            shape_unit_mass(&ch->shape, &vols[i], &ipms[i]);
        }
        k->shape.children = NULL;
        k->shape.child_count = 0;
        k->bound_radius = shape_bound(&k->shape, k->hull);
        vol += vols[i];
        cm[0] += vols[i] * poses[i].x.x, cm[1] += vols[i] * poses[i].x.y, cm[2] += vols[i] * poses[i].x.z;
    }
    if (!(vol > 0.0)) return AK_ERR_BAD_ARG;
    for (int k = 0; k < 3; ++k) cm[k] /= vol;
    /* inertia per unit density about the centre of mass */
    double in[3][3] = {{0}};
    for (size_t i = 0; i < s->child_count; ++i) {
        ak_mat3 r = ak_mat3_from_quat(poses[i].q);
        double d[3] = {poses[i].x.x - cm[0], poses[i].x.y - cm[1], poses[i].x.z - cm[2]};
        double dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        const float* ip = &ipms[i].x;
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b) {
                /* R diag(I) R^T + m (|d|^2 E - d d^T) */
                double rot = 0.0;
                for (int k = 0; k < 3; ++k) rot += ak_mat3_at(&r, a, k) * ip[k] * ak_mat3_at(&r, b, k);
                in[a][b] += vols[i] * (rot + (a == b ? dd : 0.0) - d[a] * d[b]);
            }
    }
    ak_quat frame;
    ak_vec3 moments;
    akp_rigid_principal(in, &frame, &moments);
    ak_quat to_body = ak_quat_conjugate(frame);
    ak_vec3 centroid = ak_vec3_make((float)cm[0], (float)cm[1], (float)cm[2]);
    float bound = 0.0f;
    for (size_t i = 0; i < s->child_count; ++i) {
        poses[i].x = ak_quat_rotate(to_body, ak_vec3_sub(poses[i].x, centroid));
        poses[i].q = ak_quat_normalize(ak_quat_mul(to_body, poses[i].q));
        bound = ak_maxf(bound, ak_vec3_length(poses[i].x) + kids[i].bound_radius);
    }
    memset(c, 0, sizeof *c);
    c->count = (uint32_t)s->child_count;
    c->kids = kids;
    c->poses = poses;
    c->centroid = centroid;
    c->frame = frame;
    c->volume = vol;
    c->inertia_per_mass = ak_vec3_scale(moments, (float)(1.0 / vol));
    c->bound_radius = bound;
    *out = c;
    return AK_OK;
}

ak_result ak_rigid_model_create(const ak_rigid_model_desc* desc, const ak_allocator* alloc,
                                ak_rigid_model** out_model) {
    if (out_model) *out_model = NULL;
    if (!desc || !out_model) return AK_ERR_NULL_ARG;
    if (alloc && (!alloc->alloc) != (!alloc->free)) return AK_ERR_BAD_ARG;
    if (desc->bodies.count == 0 || !desc->bodies.ptr) return AK_ERR_EMPTY;
    if (desc->bodies.count > (1u << 24)) return AK_ERR_BAD_ARG;
    if (desc->contact_iterations > AK_RIGID_MAX_CONTACT_ITERATIONS) return AK_ERR_BAD_ARG;
    const float scalars[] = {desc->linear_damping,      desc->angular_damping,
                             desc->contact_offset,      desc->sleep_linear_speed,
                             desc->sleep_angular_speed, desc->sleep_time,
                             desc->joint_tolerance};
    for (size_t i = 0; i < sizeof scalars / sizeof scalars[0]; ++i) {
        if (!ak_finitef(scalars[i])) return AK_ERR_BAD_DATA;
        if (scalars[i] < 0.0f) return AK_ERR_BAD_ARG;
    }
    for (size_t i = 0; i < desc->bodies.count; ++i) {
        ak_result r = check_body(&desc->bodies.ptr[i]);
        if (r != AK_OK) return r;
    }
    size_t n = desc->bodies.count, nj = desc->joints.count;
    if (nj && !desc->joints.ptr) return AK_ERR_NULL_ARG;
    if (nj > (1u << 24)) return AK_ERR_BAD_ARG;
    for (size_t i = 0; i < nj; ++i) {
        const ak_rigid_joint_desc* jd = &desc->joints.ptr[i];
        if ((unsigned)jd->type >= AK_RIGID_JOINT_TYPE_COUNT) return AK_ERR_BAD_ARG;
        if (jd->body_a >= n || jd->body_b >= n || jd->body_a == jd->body_b) return AK_ERR_BAD_INDEX;
        if (!vec_finite(jd->anchor) || !vec_finite(jd->axis) || !ak_finitef(jd->lower) ||
            !ak_finitef(jd->upper) || !ak_finitef(jd->compliance) || !vec_finite(jd->axis_b) ||
            !ak_finitef(jd->angle_offset) || !ak_quat_is_finite(jd->drive_target) ||
            !ak_finitef(jd->drive_compliance) || !ak_finitef(jd->drive_damping))
            return AK_ERR_BAD_DATA;
        if (!ak_finitef(jd->twist_lower) || !ak_finitef(jd->twist_upper)) return AK_ERR_BAD_DATA;
        if ((jd->twist_limited && jd->twist_lower > jd->twist_upper) ||
            (jd->limited && jd->lower > jd->upper) || jd->compliance < 0.0f ||
            jd->drive_compliance < 0.0f || jd->drive_damping < 0.0f)
            return AK_ERR_BAD_ARG;
    }
    ak_allocator al = {def_alloc, def_free, NULL};
    if (alloc && alloc->alloc) al = *alloc;
    size_t head = (sizeof(ak_rigid_model) + 15) & ~(size_t)15;
    size_t bodies_size = ((n * sizeof(rigid_body)) + 15) & ~(size_t)15;
    size_t descs_size = ((n * sizeof(ak_rigid_body_desc)) + 15) & ~(size_t)15;
    size_t joints_size = ((nj * sizeof(rigid_joint)) + 15) & ~(size_t)15;
    size_t planes_size = ((n * sizeof(uint32_t)) + 15) & ~(size_t)15;
    size_t hulls_size = 0, hull_scratch_size = 0;
    for (size_t i = 0; i < n; ++i) {
        const ak_rigid_shape* s = &desc->bodies.ptr[i].shape;
        if (s->type != AK_RIGID_HULL) continue;
        hulls_size += akp_rigid_hull_size(s->points.count);
        size_t ss = akp_rigid_hull_scratch_size(s->points.count);
        if (ss > hull_scratch_size) hull_scratch_size = ss;
    }
    for (size_t i = 0; i < n; ++i) {
        const ak_rigid_shape* s = &desc->bodies.ptr[i].shape;
        if (s->type != AK_RIGID_COMPOUND) continue;
        hulls_size += compound_size(s);
        size_t ss = compound_scratch_size(s);
        if (ss > hull_scratch_size) hull_scratch_size = ss;
    }
    for (size_t i = 0; i < n; ++i) {
        const ak_rigid_shape* s = &desc->bodies.ptr[i].shape;
        if (s->type != AK_RIGID_HEIGHTFIELD && s->type != AK_RIGID_TRIMESH) continue;
        hulls_size += akp_rigid_mesh_size(s);
        size_t ss = akp_rigid_mesh_scratch_size(s);
        if (ss > hull_scratch_size) hull_scratch_size = ss;
    }
    size_t total = head + bodies_size + descs_size + joints_size + planes_size + hulls_size;
    unsigned char* mem = al.alloc(total, al.user);
    if (!mem) return AK_ERR_NO_MEMORY;
    memset(mem, 0, total);
    void* hull_scratch = NULL;
    if (hull_scratch_size) {
        hull_scratch = al.alloc(hull_scratch_size, al.user);
        if (!hull_scratch) {
            al.free(mem, al.user);
            return AK_ERR_NO_MEMORY;
        }
    }
    unsigned char* hull_mem = mem + head + bodies_size + descs_size + joints_size + planes_size;
    ak_rigid_model* m = (ak_rigid_model*)mem;
    m->alloc = al;
    m->body_count = n;
    m->bodies = (rigid_body*)(mem + head);
    m->descs = (ak_rigid_body_desc*)(mem + head + bodies_size);
    m->joints = (rigid_joint*)(mem + head + bodies_size + descs_size);
    m->joint_count = nj;
    m->planes = (uint32_t*)(mem + head + bodies_size + descs_size + joints_size);
    m->desc = ak_rigid_model_desc_resolved(desc);
    m->desc.bodies.ptr = m->descs;
    for (size_t i = 0; i < n; ++i) {
        ak_rigid_body_desc d = desc->bodies.ptr[i];
        rigid_body* b = &m->bodies[i];
        if (ak_quat_dot(d.orientation, d.orientation) == 0.0f) d.orientation = ak_quat_identity();
        d.orientation = ak_quat_normalize(d.orientation);
        if (d.shape.type == AK_RIGID_PLANE) {
            d.is_static = true;
            if (ak_vec3_length_sq(d.shape.normal) == 0.0f) d.shape.normal = ak_vec3_make(0, 1, 0);
            d.shape.normal = ak_vec3_normalize(d.shape.normal);
            d.orientation = ak_quat_identity();
            m->planes[m->plane_count++] = (uint32_t)i;
        }
        if (d.density == 0.0f) d.density = 1000.0f;
        if (d.friction == 0.0f) d.friction = 0.5f;
        if (d.dynamic_friction == 0.0f) d.dynamic_friction = d.friction;
        b->friction = d.friction == AK_RIGID_FRICTIONLESS ? 0.0f : d.friction;
        b->dynamic_friction =
            d.dynamic_friction == AK_RIGID_FRICTIONLESS ? 0.0f : d.dynamic_friction;
        b->restitution = d.restitution;
        b->group = d.collision_group;
        b->shape = d.shape;
        double volume;
        ak_vec3 ipm;
        shape_unit_mass(&d.shape, &volume, &ipm);
        if (d.shape.type == AK_RIGID_HULL) {
            akp_hull* h = NULL;
            const char* problem;
            ak_result hr = akp_rigid_hull_build(d.shape.points, hull_mem, hull_scratch, &h, &problem);
            if (hr != AK_OK) {
                if (hull_scratch) al.free(hull_scratch, al.user);
                al.free(mem, al.user);
                return hr;
            }
            hull_mem += akp_rigid_hull_size(d.shape.points.count);
            b->hull = h;
            volume = h->volume;
            ipm = h->inertia_per_mass;
            /* the desc places the shape frame: resolve it to the body frame (centre of mass,
             * principal axes) */
            d.position = ak_vec3_add(d.position, ak_quat_rotate(d.orientation, h->centroid));
            d.orientation = ak_quat_normalize(ak_quat_mul(d.orientation, h->frame));
            d.shape.points = (ak_vec3_cspan){h->verts, h->nv};
            b->shape = d.shape;
        }
        if (d.shape.type == AK_RIGID_COMPOUND) {
            akp_compound* c = NULL;
            ak_result cr = compound_build(&d.shape, hull_mem, hull_scratch, &c);
            if (cr != AK_OK) {
                if (hull_scratch) al.free(hull_scratch, al.user);
                al.free(mem, al.user);
                return cr;
            }
            hull_mem += compound_size(&d.shape);
            b->compound = c;
            volume = c->volume;
            ipm = c->inertia_per_mass;
            d.position = ak_vec3_add(d.position, ak_quat_rotate(d.orientation, c->centroid));
            d.orientation = ak_quat_normalize(ak_quat_mul(d.orientation, c->frame));
            d.shape.children = NULL; /* the caller's; the model's children are internal */
            d.shape.child_count = 0;
            b->shape = d.shape;
        }
        if (d.shape.type == AK_RIGID_HEIGHTFIELD || d.shape.type == AK_RIGID_TRIMESH) {
            akp_mesh* me = akp_rigid_mesh_build(&d.shape, hull_mem, hull_scratch);
            hull_mem += akp_rigid_mesh_size(&d.shape);
            b->mesh = me;
            d.is_static = true;
            if (me->is_heightfield) {
                d.shape.heights = (ak_f32_cspan){me->heights, (size_t)me->rows * me->cols};
            } else {
                d.shape.vertices = (ak_vec3_cspan){me->verts, me->nv};
                d.shape.indices = (ak_u32_cspan){me->tris, 3 * (size_t)me->nt};
            }
            b->shape = d.shape;
        }
        switch (d.shape.type) {
        case AK_RIGID_SPHERE:
            b->bound_radius = d.shape.radius;
            break;
        case AK_RIGID_BOX:
            b->bound_radius = ak_vec3_length(d.shape.half_extents);
            break;
        case AK_RIGID_CAPSULE:
            b->bound_radius = d.shape.radius + d.shape.half_height;
            break;
        case AK_RIGID_HULL:
            b->bound_radius = b->hull->bound_radius;
            break;
        case AK_RIGID_HEIGHTFIELD:
        case AK_RIGID_TRIMESH:
            b->bound_radius = b->mesh->bound_radius;
            break;
        case AK_RIGID_COMPOUND:
            b->bound_radius = b->compound->bound_radius;
            break;
        default:
            b->bound_radius = INFINITY;
            break;
        }
        if (d.is_static) {
            d.velocity = ak_vec3_zero();
            d.angular_velocity = ak_vec3_zero();
            b->mass = INFINITY;
            b->inertia = ak_vec3_make(INFINITY, INFINITY, INFINITY);
        } else {
            double mass = d.mass > 0.0f ? (double)d.mass : (double)d.density * volume;
            if (d.mass > 0.0f && volume > 0.0) d.density = (float)(mass / volume);
            d.mass = (float)mass;
            if (!(mass > 0.0) || !isfinite((float)mass)) {
                if (hull_scratch) al.free(hull_scratch, al.user);
                al.free(mem, al.user);
                return AK_ERR_BAD_ARG;
            }
            b->mass = (float)mass;
            b->inv_mass = (float)(1.0 / mass);
            b->inertia = ak_vec3_scale(ipm, (float)mass);
            b->inv_inertia =
                ak_vec3_make(1.0f / b->inertia.x, 1.0f / b->inertia.y, 1.0f / b->inertia.z);
            if (!vec_finite(b->inv_inertia)) {
                if (hull_scratch) al.free(hull_scratch, al.user);
                al.free(mem, al.user);
                return AK_ERR_BAD_ARG;
            }
        }
        m->descs[i] = d;
    }
    if (hull_scratch) al.free(hull_scratch, al.user);
    for (size_t i = 0; i < nj; ++i) {
        const ak_rigid_joint_desc* jd = &desc->joints.ptr[i];
        rigid_joint* j = &m->joints[i];
        const ak_rigid_body_desc* da = &m->descs[jd->body_a];
        const ak_rigid_body_desc* db = &m->descs[jd->body_b];
        ak_quat ia = ak_quat_conjugate(da->orientation), ib = ak_quat_conjugate(db->orientation);
        ak_vec3 axis = ak_vec3_length_sq(jd->axis) > 0.0f ? ak_vec3_normalize(jd->axis)
                                                          : ak_vec3_make(0, 0, 1);
        ak_vec3 perp = ak_vec3_normalize(ak_vec3_any_perpendicular(axis));
        j->type = jd->type;
        j->a = jd->body_a;
        j->b = jd->body_b;
        j->la = ak_quat_rotate(ia, ak_vec3_sub(jd->anchor, da->position));
        j->lb = ak_quat_rotate(ib, ak_vec3_sub(jd->anchor, db->position));
        j->axis_a = ak_quat_rotate(ia, axis);
        ak_vec3 axis2 = ak_vec3_length_sq(jd->axis_b) > 0.0f ? ak_vec3_normalize(jd->axis_b) : axis;
        j->axis_b = ak_quat_rotate(ib, jd->type == AK_RIGID_JOINT_BALL ? axis2 : axis);
        j->perp_a = ak_quat_rotate(ia, perp);
        /* b's reference direction: a's swung onto b's axis (the swing of a swing-twist split) */
        ak_vec3 perp2 = ak_vec3_normalize(ak_quat_rotate(ak_quat_from_to(axis, axis2), perp));
        j->perp_b = ak_quat_rotate(ib, jd->type == AK_RIGID_JOINT_BALL ? perp2 : perp);
        ak_quat fwa = ak_quat_from_mat3(ak_mat3_from_cols(perp, axis, ak_vec3_cross(perp, axis)));
        ak_quat fwb =
            ak_quat_from_mat3(ak_mat3_from_cols(perp2, axis2, ak_vec3_cross(perp2, axis2)));
        j->frame_a = ak_quat_normalize(ak_quat_mul(ia, fwa));
        j->frame_b = ak_quat_normalize(ak_quat_mul(ib, fwb));
        j->rel = ak_quat_normalize(ak_quat_mul(ia, db->orientation));
        j->drive_target = ak_quat_dot(jd->drive_target, jd->drive_target) > 0.0f
                              ? ak_quat_normalize(jd->drive_target)
                              : j->rel;
        j->limited = jd->limited;
        j->drive = jd->drive;
        j->lower = jd->lower;
        j->upper = jd->upper;
        /* the swing limit's cosine: a cone of pi or wider never binds, a negative one always */
        j->cos_upper =
            jd->upper >= 3.14159265f ? -INFINITY : (jd->upper < 0.0f ? INFINITY : cosf(jd->upper));
        j->compliance = jd->compliance;
        j->drive_compliance = jd->drive_compliance;
        j->drive_damping = jd->drive_damping;
        j->angle_offset = jd->angle_offset;
        j->twist_limited = jd->twist_limited;
        j->twist_lower = jd->twist_lower;
        j->twist_upper = jd->twist_upper;
        float hl = 0.5f * (jd->twist_lower - jd->angle_offset),
              hh = 0.5f * (jd->twist_upper - jd->angle_offset);
        j->twist_fast = fabsf(hl) < 1.5607963f && fabsf(hh) < 1.5607963f;
        j->twist_cl = cosf(hl), j->twist_sl = sinf(hl);
        j->twist_ch = cosf(hh), j->twist_sh = sinf(hh);
    }
    m->desc.joints = (ak_rigid_joint_desc_cspan){NULL, 0};
    *out_model = m;
    return AK_OK;
}

void ak_rigid_model_destroy(ak_rigid_model* model) {
    if (!model) return;
    model->alloc.free(model, model->alloc.user);
}

size_t ak_rigid_body_count(const ak_rigid_model* model) { return model ? model->body_count : 0; }

float ak_rigid_body_mass(const ak_rigid_model* model, size_t i) {
    return model && i < model->body_count ? model->bodies[i].mass : 0.0f;
}

ak_vec3 ak_rigid_body_inertia(const ak_rigid_model* model, size_t i) {
    return model && i < model->body_count ? model->bodies[i].inertia : ak_vec3_zero();
}

ak_transform ak_rigid_body_shape_frame(const ak_rigid_model* model, size_t i) {
    ak_transform t = ak_transform_identity();
    if (!model || i >= model->body_count) return t;
    const rigid_body* b = &model->bodies[i];
    if (!b->hull && !b->compound) return t;
    ak_quat frame = b->hull ? b->hull->frame : b->compound->frame;
    ak_vec3 centroid = b->hull ? b->hull->centroid : b->compound->centroid;
    t.rotation = ak_quat_conjugate(frame);
    t.translation = ak_vec3_neg(ak_quat_rotate(t.rotation, centroid));
    return t;
}

double ak_rigid_body_volume(const ak_rigid_model* model, size_t i) {
    if (!model || i >= model->body_count) return 0.0;
    const rigid_body* b = &model->bodies[i];
    if (b->hull) return b->hull->volume;
    if (b->compound) return b->compound->volume;
    double v;
    ak_vec3 ipm;
    shape_unit_mass(&b->shape, &v, &ipm);
    return v;
}

ak_rigid_body_desc ak_rigid_body_get_desc(const ak_rigid_model* model, size_t i) {
    ak_rigid_body_desc d;
    memset(&d, 0, sizeof d);
    if (model && i < model->body_count) d = model->descs[i];
    return d;
}

ak_result ak_rigid_initial_state(const ak_rigid_model* model, ak_vec3_span x, ak_quat_span q,
                                 ak_vec3_span v, ak_vec3_span w) {
    if (!model || !x.ptr || !q.ptr || !v.ptr || !w.ptr) return AK_ERR_NULL_ARG;
    size_t n = model->body_count;
    if (x.count < n || q.count < n || v.count < n || w.count < n) return AK_ERR_SPAN_SMALL;
    for (size_t i = 0; i < n; ++i) {
        x.ptr[i] = model->descs[i].position;
        q.ptr[i] = model->descs[i].orientation;
        v.ptr[i] = model->descs[i].velocity;
        w.ptr[i] = model->descs[i].angular_velocity;
    }
    return AK_OK;
}

ak_vec3 ak_rigid_angular_momentum(const ak_rigid_model* model, size_t i, ak_quat q, ak_vec3 w) {
    if (!model || i >= model->body_count || model->bodies[i].inv_mass == 0.0f)
        return ak_vec3_zero();
    ak_vec3 wl = ak_quat_rotate(ak_quat_conjugate(q), w);
    ak_vec3 ll = ak_vec3_mul(model->bodies[i].inertia, wl);
    return ak_quat_rotate(q, ll);
}

double ak_rigid_energy(const ak_rigid_model* model, ak_vec3 g, ak_vec3_cspan x, ak_quat_cspan q,
                       ak_vec3_cspan v, ak_vec3_cspan w) {
    if (!model) return 0.0;
    size_t n = model->body_count;
    if (x.count < n || q.count < n || v.count < n || w.count < n) return 0.0;
    double e = 0.0;
    for (size_t i = 0; i < n; ++i) {
        const rigid_body* b = &model->bodies[i];
        if (b->inv_mass == 0.0f) continue;
        double m = b->mass;
        ak_vec3 wl = ak_quat_rotate(ak_quat_conjugate(q.ptr[i]), w.ptr[i]);
        e += 0.5 * m * (double)ak_vec3_dot(v.ptr[i], v.ptr[i]);
        e += 0.5 * ((double)b->inertia.x * wl.x * wl.x + (double)b->inertia.y * wl.y * wl.y +
                    (double)b->inertia.z * wl.z * wl.z);
        e -= m * ((double)g.x * x.ptr[i].x + (double)g.y * x.ptr[i].y + (double)g.z * x.ptr[i].z);
    }
    return e;
}

size_t ak_rigid_joint_count(const ak_rigid_model* model) { return model ? model->joint_count : 0; }

ak_result ak_rigid_joint_error(const ak_rigid_model* model, size_t i, ak_vec3_cspan x,
                               ak_quat_cspan q, float* out_gap, float* out_limit_excess) {
    if (!model || !x.ptr || !q.ptr || !out_gap || !out_limit_excess) return AK_ERR_NULL_ARG;
    if (i >= model->joint_count) return AK_ERR_BAD_INDEX;
    if (x.count < model->body_count || q.count < model->body_count) return AK_ERR_SPAN_SMALL;
    const rigid_joint* j = &model->joints[i];
    ak_quat qa = ak_quat_normalize(q.ptr[j->a]), qb = ak_quat_normalize(q.ptr[j->b]);
    ak_vec3 pa = ak_vec3_add(x.ptr[j->a], ak_quat_rotate(qa, j->la));
    ak_vec3 pb = ak_vec3_add(x.ptr[j->b], ak_quat_rotate(qb, j->lb));
    ak_vec3 d = ak_vec3_sub(pb, pa);
    float excess = 0.0f;
    if (j->type == AK_RIGID_JOINT_PRISMATIC) {
        ak_vec3 ax = ak_quat_rotate(qa, j->axis_a);
        float s = ak_vec3_dot(d, ax);
        d = ak_vec3_madd(d, ax, -s);
        if (j->limited) excess = ak_maxf(j->lower - s, s - j->upper);
    } else if (j->type == AK_RIGID_JOINT_HINGE && j->limited) {
        float phi = akp_rigid_hinge_angle(j, qa, qb) + j->angle_offset;
        excess = ak_maxf(j->lower - phi, phi - j->upper);
    }
    if (j->type == AK_RIGID_JOINT_BALL && j->twist_limited) {
        ak_vec3 n;
        float tw = akp_rigid_twist_angle(j, qa, qb, &n) + j->angle_offset;
        excess = ak_maxf(excess, ak_maxf(j->twist_lower - tw, tw - j->twist_upper));
    }
    if (j->type == AK_RIGID_JOINT_BALL && j->limited) {
        ak_vec3 a1 = ak_quat_rotate(qa, j->axis_a), a2 = ak_quat_rotate(qb, j->axis_b);
        float swing = atan2f(ak_vec3_length(ak_vec3_cross(a1, a2)), ak_vec3_dot(a1, a2));
        excess = swing - j->upper;
    }
    *out_gap = ak_vec3_length(d);
    *out_limit_excess = ak_maxf(excess, 0.0f);
    return AK_OK;
}
