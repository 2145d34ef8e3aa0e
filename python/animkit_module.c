/* animkit._core: the CPython extension of the Python package `animkit` (docs/python.md).
 *
 * Thin glue over the public C API. Arrays cross as numpy arrays without copies: mesh data are
 * read-only views of the scene's own memory, poses are views of the Pose object's buffers, and
 * skinning and rendering write straight into the numpy array they return (or the caller's
 * `out=` array). Long calls (load, sample, skin, ik, render, retarget, save) release the GIL;
 * each scene serialises its posing state with its own lock, so threads may share a scene.
 *
 * Posing, skinning and the render framing are the command's own code (tools/animkit/pose.c and
 * render.c are compiled into the extension), so results equal `animkit export` and `animkit
 * render` bit for bit. The numpy C API is used (not the limited API): building an array over
 * foreign memory with a base object is the cheapest way to a zero-copy array, and the per-call
 * overhead target (2 us) rules out going through Python-level numpy calls. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <pythread.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <time.h>

#include <animkit/animkit.h>

#include "cli.h"    /* the posing pipeline shared with the command (tools/animkit/pose.c) */
#include "render.h" /* its framing and drawing (tools/animkit/render.c) */
#include "boids_run.h"     /* the simulations' runs (tools/animkit/ *_run.c) */
#include "cloth_run.h"
#include "particles_run.h"

/* ---- errors ------------------------------------------------------------------------------- */

static PyObject* Error;         /* animkit.Error */
static PyObject* FileError;     /* AK_ERR_IO: cannot open, read or write a file */
static PyObject* ParseError;    /* AK_ERR_PARSE: malformed file */
static PyObject* DataError;     /* bad values: NaN, bad indices, weights, hierarchy, keys */
static PyObject* NotFoundError; /* a named item (file, joint, clip, mesh, built-in) */
static PyObject* UnsupportedError; /* AK_ERR_UNSUPPORTED, AK_ERR_BUDGET */
static PyObject* ArgumentError; /* bad arguments (also a ValueError) */
static PyObject* NoMemoryError; /* AK_ERR_NO_MEMORY (also a MemoryError) */

static PyObject* error_type(ak_result r) {
    switch (r) {
    case AK_ERR_IO: return FileError;
    case AK_ERR_PARSE: return ParseError;
    case AK_ERR_BAD_DATA:
    case AK_ERR_BAD_WEIGHTS:
    case AK_ERR_BAD_INDEX:
    case AK_ERR_BAD_HIERARCHY:
    case AK_ERR_UNSORTED:
    case AK_ERR_DUPLICATE:
    case AK_ERR_EMPTY: return DataError;
    case AK_ERR_NOT_FOUND: return NotFoundError;
    case AK_ERR_UNSUPPORTED:
    case AK_ERR_BUDGET: return UnsupportedError;
    case AK_ERR_NULL_ARG:
    case AK_ERR_SPAN_SMALL:
    case AK_ERR_BAD_ARG: return ArgumentError;
    case AK_ERR_NO_MEMORY: return NoMemoryError;
    default: return Error;
    }
}

/* Raise type with str "PATH: MESSAGE" (or "MESSAGE") and attributes code, message, path.
 * Returns NULL. */
static PyObject* raise_as(PyObject* type, ak_result code, const char* path, const char* fmt, ...) {
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    PyObject* text = path && path[0] ? PyUnicode_FromFormat("%s: %s", path, msg) : PyUnicode_FromString(msg);
    if (!text) return NULL;
    PyObject* exc = PyObject_CallOneArg(type, text);
    Py_DECREF(text);
    if (!exc) return NULL;
    PyObject* m = PyUnicode_FromString(msg);
    PyObject* p = path ? PyUnicode_DecodeFSDefault(path) : (Py_INCREF(Py_None), Py_None);
    PyObject* c = PyUnicode_FromString(ak_result_name(code));
    if (m && p && c && PyObject_SetAttrString(exc, "message", m) == 0 && PyObject_SetAttrString(exc, "path", p) == 0 &&
        PyObject_SetAttrString(exc, "code", c) == 0)
        PyErr_SetObject(type, exc);
    Py_XDECREF(m);
    Py_XDECREF(p);
    Py_XDECREF(c);
    Py_DECREF(exc);
    return NULL;
}

/* The library's failure r, with the diag's message and path when it has them. */
static PyObject* raise_result(ak_result r, const char* path, const ak_diag* diag) {
    const char* where = diag && diag->path[0] ? diag->path : path;
    const char* what = diag && diag->message[0] ? diag->message : ak_result_string(r);
    return raise_as(error_type(r), r, where, "%s", what);
}

#define RAISE_ARG(...) raise_as(ArgumentError, AK_ERR_BAD_ARG, NULL, __VA_ARGS__)

/* ---- arrays ------------------------------------------------------------------------------- */

/* An array over data owned by owner (kept alive as the array's base); read-only unless
 * writable. strides NULL -> C order. */
static PyObject* view_array(PyObject* owner, int nd, npy_intp* dims, npy_intp* strides, int type, const void* data,
                            int writable) {
    PyObject* a = PyArray_New(&PyArray_Type, nd, dims, type, strides, (void*)data, 0, writable ? NPY_ARRAY_WRITEABLE : 0,
                              NULL);
    if (!a) return NULL;
    if (!data) return a; /* zero-sized: numpy owns its (empty) buffer */
    Py_INCREF(owner);
    if (PyArray_SetBaseObject((PyArrayObject*)a, owner) < 0) {
        Py_DECREF(a);
        return NULL;
    }
    return a;
}

/* A new C-order array, or out checked to be a writable C-contiguous array of that type and
 * shape (a new reference to it). */
static PyArrayObject* output_array(PyObject* out, int nd, npy_intp* dims, int type, const char* what) {
    if (!out || out == Py_None) return (PyArrayObject*)PyArray_SimpleNew(nd, dims, type);
    if (!PyArray_Check(out)) {
        PyErr_Format(PyExc_TypeError, "out= must be a numpy array for %s", what);
        return NULL;
    }
    PyArrayObject* a = (PyArrayObject*)out;
    bool shape_ok = PyArray_NDIM(a) == nd;
    for (int i = 0; shape_ok && i < nd; ++i) shape_ok = PyArray_DIM(a, i) == dims[i];
    if (PyArray_TYPE(a) != type || !shape_ok || !PyArray_IS_C_CONTIGUOUS(a) || !PyArray_ISWRITEABLE(a)) {
        PyArray_Descr* d = PyArray_DescrFromType(type);
        if (nd == 2)
            RAISE_ARG("out= for %s must be a writable C-contiguous %c%d array of shape (%zd, %zd)", what,
                      d ? d->kind : '?', d ? d->elsize * 8 : 0, (Py_ssize_t)dims[0], (Py_ssize_t)dims[1]);
        else
            RAISE_ARG("out= for %s must be a writable C-contiguous %c%d array of shape (%zd, %zd, %zd)", what,
                      d ? d->kind : '?', d ? d->elsize * 8 : 0, (Py_ssize_t)dims[0], (Py_ssize_t)dims[1],
                      (Py_ssize_t)dims[2]);
        Py_XDECREF(d);
        return NULL;
    }
    Py_INCREF(out);
    return a;
}

/* ---- Scene -------------------------------------------------------------------------------- */

typedef struct SceneObject {
    PyObject_HEAD
    ak_scene* scene;     /* owned, or &view */
    ak_scene view;       /* a retarget result: the target's scene with one clip */
    ak_clip* own_clip;   /* that clip (owned) */
    PyObject* base;      /* the Scene the view borrows from */
    cli_poser poser;     /* posing state, made on first use */
    bool poser_ready;
    PyThread_type_lock lock; /* serialises the poser */
} SceneObject;

typedef struct PoseObject {
    PyObject_HEAD
    SceneObject* scene;
    size_t joint_count;
    size_t morph_count;
    ak_transform* local; /* [joint_count] */
    ak_mat4* world;      /* [joint_count] */
    float* morph;        /* [morph_count] morph weights of the scene's flat morph index space */
} PoseObject;

typedef struct MeshObject {
    PyObject_HEAD
    SceneObject* scene;
    size_t index;
} MeshObject;

static PyTypeObject SceneType, PoseType, MeshType;

static SceneObject* scene_new(ak_scene* s) {
    SceneObject* o = PyObject_New(SceneObject, &SceneType);
    if (!o) {
        ak_scene_destroy(s);
        return NULL;
    }
    o->scene = s;
    memset(&o->view, 0, sizeof o->view);
    o->own_clip = NULL;
    o->base = NULL;
    memset(&o->poser, 0, sizeof o->poser);
    o->poser_ready = false;
    o->lock = PyThread_allocate_lock();
    if (!o->lock) {
        Py_DECREF(o);
        return (SceneObject*)PyErr_NoMemory();
    }
    return o;
}

static void scene_dealloc(SceneObject* o) {
    if (o->poser_ready) cli_poser_free(&o->poser);
    if (o->base) {
        Py_DECREF(o->base);
    } else {
        ak_scene_destroy(o->scene);
    }
    ak_clip_destroy(o->own_clip);
    if (o->lock) PyThread_free_lock(o->lock);
    PyObject_Free(o);
}

/* Lock the scene's poser (GIL released by the caller), making it on first use. */
static ak_result poser_acquire(SceneObject* o) {
    PyThread_acquire_lock(o->lock, WAIT_LOCK);
    if (!o->poser_ready) {
        if (cli_poser_init(&o->poser, o->scene) != CLI_OK) {
            PyThread_release_lock(o->lock);
            return AK_ERR_NO_MEMORY;
        }
        o->poser_ready = true;
        /* as `animkit render` for OBJ input: normals shared across unwelded seams */
        size_t nl = strlen(o->scene->name);
        o->poser.weld_normals = nl > 4 && strcasecmp(o->scene->name + nl - 4, ".obj") == 0;
    }
    return AK_OK;
}

static size_t scene_morph_count(const ak_scene* s) {
    size_t n = 0;
    for (size_t m = 0; m < s->mesh_count; ++m)
        if (s->meshes[m].mesh) n += s->meshes[m].mesh->morph_target_count;
    return n;
}

/* Clip argument: None -> -1 (rest pose) when allow_none, else an index or a name. */
static int clip_arg(SceneObject* o, PyObject* arg, int fallback, int* out) {
    const ak_scene* s = o->scene;
    if (!arg) {
        *out = fallback;
        return 0;
    }
    if (arg == Py_None) {
        *out = -1;
        return 0;
    }
    if (PyLong_Check(arg)) {
        long k = PyLong_AsLong(arg);
        if (k == -1 && PyErr_Occurred()) return -1;
        if (k < 0 || (size_t)k >= s->clip_count) {
            raise_as(NotFoundError, AK_ERR_NOT_FOUND, s->name, "no clip #%ld (the scene has %zu clip%s)", k, s->clip_count,
                     s->clip_count == 1 ? "" : "s");
            return -1;
        }
        *out = (int)k;
        return 0;
    }
    if (PyUnicode_Check(arg)) {
        const char* name = PyUnicode_AsUTF8(arg);
        if (!name) return -1;
        for (size_t c = 0; c < s->clip_count; ++c)
            if (strcmp(ak_clip_name(s->clips[c]), name) == 0) {
                *out = (int)c;
                return 0;
            }
        raise_as(NotFoundError, AK_ERR_NOT_FOUND, s->name, "no clip named '%s' (clip_names lists them)", name);
        return -1;
    }
    PyErr_SetString(PyExc_TypeError, "clip must be an index, a name or None");
    return -1;
}

static int method_arg(const char* s, cli_method* out) {
    if (!s) {
        *out = CLI_LBS;
        return 0;
    }
    if (!cli_method_parse(s, out)) {
        RAISE_ARG("method must be 'lbs', 'dqs', 'cor', 'implicit' or 'soft', not '%s'", s);
        return -1;
    }
    return 0;
}

static int finite_arg(double v, const char* what) {
    if (!isfinite(v) || fabs(v) > 3.0e38) {
        RAISE_ARG("%s must be a finite number, not %g", what, v);
        return -1;
    }
    return 0;
}

/* ---- Pose --------------------------------------------------------------------------------- */

static PoseObject* pose_new(SceneObject* scene) {
    PoseObject* p = PyObject_New(PoseObject, &PoseType);
    if (!p) return NULL;
    Py_INCREF(scene);
    p->scene = scene;
    p->joint_count = ak_scene_joint_count(scene->scene);
    p->morph_count = scene_morph_count(scene->scene);
    size_t jc = p->joint_count ? p->joint_count : 1, mc = p->morph_count ? p->morph_count : 1;
    /* one block: local transforms, world matrices, morph weights (all float-aligned); every
     * byte is written by the sample before it is read */
    p->local = PyMem_Malloc(jc * (sizeof(ak_transform) + sizeof(ak_mat4)) + mc * sizeof(float));
    if (!p->local) {
        p->world = NULL;
        p->morph = NULL;
        Py_DECREF(p);
        return (PoseObject*)PyErr_NoMemory();
    }
    p->world = (ak_mat4*)(void*)(p->local + jc);
    p->morph = (float*)(void*)(p->world + jc);
    memset(p->morph, 0, mc * sizeof(float));
    return p;
}

static void pose_dealloc(PoseObject* p) {
    PyMem_Free(p->local); /* world and morph live in the same block */
    Py_XDECREF(p->scene);
    PyObject_Free(p);
}

/* Sample clip at t (clip < 0 or bind: the rest pose) into pose's buffers, then FK. Called with
 * the poser locked: the poser works in the pose's own memory. */
static ak_result pose_sample_locked(cli_poser* pp, PoseObject* pose, int clip, float t, bool bind) {
    ak_transform* keep_local = pp->local;
    float* keep_morph = pp->morph_weights;
    pp->local = pose->local;
    pp->morph_weights = pose->morph;
    ak_result r = cli_poser_sample(pp, clip, t, bind);
    pp->local = keep_local;
    pp->morph_weights = keep_morph;
    if (r == AK_OK && pose->joint_count)
        r = ak_scene_world_matrices(pp->scene, (ak_transform_cspan){pose->local, pose->joint_count},
                                    (ak_mat4_span){pose->world, pose->joint_count});
    return r;
}

static PyObject* pose_local(PoseObject* p, void* closure) {
    (void)closure;
    npy_intp dims[2] = {(npy_intp)p->joint_count, 10};
    return view_array((PyObject*)p, 2, dims, NULL, NPY_FLOAT32, p->joint_count ? p->local : NULL, 1);
}

static PyObject* pose_model_matrices(PoseObject* p, void* closure) {
    (void)closure;
    const float* f = (const float*)p->local;
    for (size_t i = 0; i < p->joint_count * (sizeof(ak_transform) / sizeof(float)); ++i)
        if (!isfinite(f[i]))
            return raise_as(DataError, AK_ERR_BAD_DATA, p->scene->scene->name,
                            "pose.local holds NaN or infinity (joint %zu)", i / (sizeof(ak_transform) / sizeof(float)));
    if (p->joint_count) {
        ak_result r = ak_scene_world_matrices(p->scene->scene, (ak_transform_cspan){p->local, p->joint_count},
                                              (ak_mat4_span){p->world, p->joint_count});
        if (r != AK_OK) return raise_result(r, p->scene->scene->name, NULL);
    }
    /* column-major storage seen as [joint][row][column]: element (r, c) is m[c * 4 + r] */
    npy_intp dims[3] = {(npy_intp)p->joint_count, 4, 4};
    npy_intp strides[3] = {(npy_intp)sizeof(ak_mat4), (npy_intp)sizeof(float), 4 * (npy_intp)sizeof(float)};
    return view_array((PyObject*)p, 3, dims, strides, NPY_FLOAT32, p->joint_count ? p->world : NULL, 0);
}

static PyObject* pose_morph_weights(PoseObject* p, void* closure) {
    (void)closure;
    npy_intp dims[1] = {(npy_intp)p->morph_count};
    return view_array((PyObject*)p, 1, dims, NULL, NPY_FLOAT32, p->morph_count ? p->morph : NULL, 1);
}

static PyObject* pose_get_scene(PoseObject* p, void* closure) {
    (void)closure;
    Py_INCREF(p->scene);
    return (PyObject*)p->scene;
}

static PyGetSetDef pose_getset[] = {
    {"local", (getter)pose_local, NULL,
     "Local (parent-space) transforms, a writable (J, 10) float32 view: translation xyz, rotation "
     "quaternion xyzw, scale xyz per joint.",
     NULL},
    {"model_matrices", (getter)pose_model_matrices, NULL,
     "Model-space joint matrices (J, 4, 4) float32 (forward kinematics of `local`, recomputed on "
     "each access; m[j] @ (x, y, z, 1) maps joint space to model space). A read-only view.",
     NULL},
    {"morph_weights", (getter)pose_morph_weights, NULL,
     "Morph target weights in the scene's flat morph index space, a writable float32 view.", NULL},
    {"scene", (getter)pose_get_scene, NULL, "The Scene this pose belongs to.", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

static PyTypeObject PoseType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "animkit.Pose",
    .tp_basicsize = sizeof(PoseObject),
    .tp_dealloc = (destructor)pose_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "A pose of a scene's skeleton (Scene.sample, Scene.rest_pose, Scene.ik).",
    .tp_getset = pose_getset,
};

/* ---- Mesh --------------------------------------------------------------------------------- */

static const ak_mesh* mesh_of(MeshObject* m) { return m->scene->scene->meshes[m->index].mesh; }

static void mesh_dealloc(MeshObject* m) {
    Py_XDECREF(m->scene);
    PyObject_Free(m);
}

static PyObject* mesh_name(MeshObject* m, void* c) {
    (void)c;
    return PyUnicode_DecodeUTF8(mesh_of(m)->name, (Py_ssize_t)strlen(mesh_of(m)->name), "replace");
}

static PyObject* mesh_vec3(MeshObject* m, const ak_vec3* v) {
    if (!v) Py_RETURN_NONE;
    npy_intp dims[2] = {(npy_intp)mesh_of(m)->vertex_count, 3};
    return view_array((PyObject*)m->scene, 2, dims, NULL, NPY_FLOAT32, v, 0);
}

static PyObject* mesh_positions(MeshObject* m, void* c) {
    (void)c;
    return mesh_vec3(m, mesh_of(m)->positions);
}

static PyObject* mesh_normals(MeshObject* m, void* c) {
    (void)c;
    return mesh_vec3(m, mesh_of(m)->normals);
}

static PyObject* mesh_indices(MeshObject* m, void* c) {
    (void)c;
    const ak_mesh* mesh = mesh_of(m);
    npy_intp dims[2] = {(npy_intp)mesh->triangle_count, 3};
    return view_array((PyObject*)m->scene, 2, dims, NULL, NPY_UINT32, mesh->triangle_count ? mesh->indices : NULL, 0);
}

static PyObject* mesh_joints(MeshObject* m, void* c) {
    (void)c;
    const ak_mesh* mesh = mesh_of(m);
    npy_intp dims[2] = {(npy_intp)mesh->vertex_count, (npy_intp)mesh->influence_count};
    return view_array((PyObject*)m->scene, 2, dims, NULL, NPY_UINT16, mesh->influence_count ? mesh->joints : NULL, 0);
}

static PyObject* mesh_weights(MeshObject* m, void* c) {
    (void)c;
    const ak_mesh* mesh = mesh_of(m);
    npy_intp dims[2] = {(npy_intp)mesh->vertex_count, (npy_intp)mesh->influence_count};
    return view_array((PyObject*)m->scene, 2, dims, NULL, NPY_FLOAT32, mesh->influence_count ? mesh->weights : NULL, 0);
}

static PyObject* mesh_skin(MeshObject* m, void* c) {
    (void)c;
    return PyLong_FromLong(m->scene->scene->meshes[m->index].skin);
}

static PyObject* mesh_repr(MeshObject* m) {
    const ak_mesh* mesh = mesh_of(m);
    return PyUnicode_FromFormat("<animkit.Mesh '%s': %zu vertices, %zu triangles>", mesh->name, mesh->vertex_count,
                                mesh->triangle_count);
}

static PyGetSetDef mesh_getset[] = {
    {"name", (getter)mesh_name, NULL, "The mesh's name (str).", NULL},
    {"positions", (getter)mesh_positions, NULL, "Bind-space vertex positions, a read-only (N, 3) float32 view.", NULL},
    {"normals", (getter)mesh_normals, NULL, "Bind-space normals, a read-only (N, 3) float32 view, or None.", NULL},
    {"indices", (getter)mesh_indices, NULL, "Triangles, a read-only (T, 3) uint32 view.", NULL},
    {"joints", (getter)mesh_joints, NULL, "Skin slots per vertex, a read-only (N, K) uint16 view (K = 0 unskinned).",
     NULL},
    {"weights", (getter)mesh_weights, NULL, "Skin weights per vertex, a read-only (N, K) float32 view.", NULL},
    {"skin", (getter)mesh_skin, NULL, "Index of the scene skin driving the mesh, -1 when unskinned.", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

static PyTypeObject MeshType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "animkit.Mesh",
    .tp_basicsize = sizeof(MeshObject),
    .tp_dealloc = (destructor)mesh_dealloc,
    .tp_repr = (reprfunc)mesh_repr,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "One mesh of a scene (Scene.meshes[i]); its arrays are views of the scene's memory.",
    .tp_getset = mesh_getset,
};

/* ---- Scene methods ------------------------------------------------------------------------ */

static PyObject* scene_name(SceneObject* o, void* c) {
    (void)c;
    return PyUnicode_DecodeUTF8(o->scene->name, (Py_ssize_t)strlen(o->scene->name), "replace");
}

static PyObject* scene_joint_names(SceneObject* o, void* c) {
    (void)c;
    size_t n = ak_scene_joint_count(o->scene);
    PyObject* list = PyList_New((Py_ssize_t)n);
    for (size_t j = 0; list && j < n; ++j) {
        const char* name = ak_skeleton_joint_name(o->scene->skeleton, j);
        PyObject* s = PyUnicode_DecodeUTF8(name, (Py_ssize_t)strlen(name), "replace");
        if (!s) {
            Py_CLEAR(list);
            break;
        }
        PyList_SET_ITEM(list, (Py_ssize_t)j, s);
    }
    return list;
}

static PyObject* scene_parents(SceneObject* o, void* c) {
    (void)c;
    size_t n = ak_scene_joint_count(o->scene);
    npy_intp dims[1] = {(npy_intp)n};
    return view_array((PyObject*)o, 1, dims, NULL, NPY_INT32, n ? ak_skeleton_parents(o->scene->skeleton).ptr : NULL, 0);
}

static PyObject* scene_clip_names(SceneObject* o, void* c) {
    (void)c;
    PyObject* list = PyList_New((Py_ssize_t)o->scene->clip_count);
    for (size_t k = 0; list && k < o->scene->clip_count; ++k) {
        const char* name = ak_clip_name(o->scene->clips[k]);
        PyObject* s = PyUnicode_DecodeUTF8(name, (Py_ssize_t)strlen(name), "replace");
        if (!s) {
            Py_CLEAR(list);
            break;
        }
        PyList_SET_ITEM(list, (Py_ssize_t)k, s);
    }
    return list;
}

static PyObject* scene_clip_durations(SceneObject* o, void* c) {
    (void)c;
    PyObject* list = PyList_New((Py_ssize_t)o->scene->clip_count);
    for (size_t k = 0; list && k < o->scene->clip_count; ++k) {
        PyObject* d = PyFloat_FromDouble((double)ak_clip_duration(o->scene->clips[k]));
        if (!d) {
            Py_CLEAR(list);
            break;
        }
        PyList_SET_ITEM(list, (Py_ssize_t)k, d);
    }
    return list;
}

static PyObject* scene_meshes(SceneObject* o, void* c) {
    (void)c;
    PyObject* t = PyTuple_New((Py_ssize_t)o->scene->mesh_count);
    for (size_t m = 0; t && m < o->scene->mesh_count; ++m) {
        if (!o->scene->meshes[m].mesh) {
            Py_INCREF(Py_None);
            PyTuple_SET_ITEM(t, (Py_ssize_t)m, Py_None);
            continue;
        }
        MeshObject* mo = PyObject_New(MeshObject, &MeshType);
        if (!mo) {
            Py_CLEAR(t);
            break;
        }
        Py_INCREF(o);
        mo->scene = o;
        mo->index = m;
        PyTuple_SET_ITEM(t, (Py_ssize_t)m, (PyObject*)mo);
    }
    return t;
}

static PyObject* scene_skins(SceneObject* o, void* c) {
    (void)c;
    PyObject* list = PyList_New((Py_ssize_t)o->scene->skin_count);
    for (size_t k = 0; list && k < o->scene->skin_count; ++k) {
        const ak_scene_skin* sk = &o->scene->skins[k];
        npy_intp jd[1] = {(npy_intp)sk->joint_count};
        npy_intp md[3] = {(npy_intp)sk->joint_count, 4, 4};
        npy_intp ms[3] = {(npy_intp)sizeof(ak_mat4), (npy_intp)sizeof(float), 4 * (npy_intp)sizeof(float)};
        PyObject* joints = view_array((PyObject*)o, 1, jd, NULL, NPY_INT32, sk->joint_count ? sk->joints : NULL, 0);
        PyObject* binds = view_array((PyObject*)o, 3, md, ms, NPY_FLOAT32, sk->joint_count ? sk->inverse_binds : NULL, 0);
        PyObject* d = joints && binds ? Py_BuildValue("{s:s,s:O,s:O}", "name", sk->name, "joints", joints,
                                                      "inverse_binds", binds)
                                      : NULL;
        Py_XDECREF(joints);
        Py_XDECREF(binds);
        if (!d) {
            Py_CLEAR(list);
            break;
        }
        PyList_SET_ITEM(list, (Py_ssize_t)k, d);
    }
    return list;
}

static PyObject* scene_repr(SceneObject* o) {
    return PyUnicode_FromFormat("<animkit.Scene '%s': %zu joints, %zu meshes, %zu clips>", o->scene->name,
                                ak_scene_joint_count(o->scene), o->scene->mesh_count, o->scene->clip_count);
}

static PyObject* scene_sample(SceneObject* o, PyObject* args, PyObject* kw) {
    static char* kwlist[] = {"clip", "time", NULL};
    PyObject* clip_obj = NULL;
    double t = 0.0;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "|Od:sample", kwlist, &clip_obj, &t)) return NULL;
    int clip = -1;
    if (clip_arg(o, clip_obj, o->scene->clip_count ? 0 : -1, &clip) < 0 || finite_arg(t, "time") < 0) return NULL;
    PoseObject* pose = pose_new(o);
    if (!pose) return NULL;
    ak_result r;
    Py_BEGIN_ALLOW_THREADS
    r = poser_acquire(o);
    if (r == AK_OK) {
        r = pose_sample_locked(&o->poser, pose, clip, (float)t, clip < 0);
        PyThread_release_lock(o->lock);
    }
    Py_END_ALLOW_THREADS
    if (r != AK_OK) {
        Py_DECREF(pose);
        return raise_result(r, o->scene->name, NULL);
    }
    return (PyObject*)pose;
}

static PyObject* scene_rest_pose(SceneObject* o, PyObject* noargs) {
    (void)noargs;
    PyObject* args = PyTuple_Pack(1, Py_None);
    if (!args) return NULL;
    PyObject* res = scene_sample(o, args, NULL);
    Py_DECREF(args);
    return res;
}

static PyObject* scene_skin(SceneObject* o, PyObject* args, PyObject* kw) {
    static char* kwlist[] = {"pose", "method", "mesh", "out", NULL};
    PyObject* pose_obj = NULL;
    const char* method_name = NULL;
    Py_ssize_t mi = 0;
    PyObject* out = NULL;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O!|znO:skin", kwlist, &PoseType, &pose_obj, &method_name, &mi, &out))
        return NULL;
    PoseObject* pose = (PoseObject*)pose_obj;
    if (pose->scene != o) return RAISE_ARG("the pose belongs to another scene ('%s')", pose->scene->scene->name);
    cli_method method;
    if (method_arg(method_name, &method) < 0) return NULL;
    if (mi < 0 || (size_t)mi >= o->scene->mesh_count)
        return raise_as(NotFoundError, AK_ERR_NOT_FOUND, o->scene->name, "no mesh #%zd (the scene has %zu mesh%s)", mi,
                        o->scene->mesh_count, o->scene->mesh_count == 1 ? "" : "es");
    const ak_mesh* mesh = o->scene->meshes[mi].mesh;
    if (!mesh) return raise_as(DataError, AK_ERR_EMPTY, o->scene->name, "mesh #%zd is empty", mi);
    npy_intp dims[2] = {(npy_intp)mesh->vertex_count, 3};
    PyArrayObject* res = output_array(out, 2, dims, NPY_FLOAT32, "skin");
    if (!res) return NULL;
    ak_result r;
    Py_BEGIN_ALLOW_THREADS
    r = poser_acquire(o);
    if (r == AK_OK) {
        cli_poser* pp = &o->poser;
        ak_transform* keep_local = pp->local;
        float* keep_morph = pp->morph_weights;
        ak_vec3* keep_pos = pp->positions[mi];
        pp->local = pose->local;
        pp->morph_weights = pose->morph;
        pp->positions[mi] = (ak_vec3*)PyArray_DATA(res); /* skin straight into the array */
        r = cli_poser_deform(pp, false, method);
        pp->local = keep_local;
        pp->morph_weights = keep_morph;
        pp->positions[mi] = keep_pos;
        PyThread_release_lock(o->lock);
    }
    Py_END_ALLOW_THREADS
    if (r != AK_OK) {
        Py_DECREF(res);
        return raise_result(r, o->scene->name, NULL);
    }
    return (PyObject*)res;
}

static int find_joint(const ak_scene* s, const char* name) {
    return s->skeleton ? ak_skeleton_find_joint(s->skeleton, name) : -1;
}

static bool ik_is_joint(const ak_scene* s, bool all, int j) { return all || !s->is_joint || s->is_joint[j]; }

/* The default chain root of `animkit ik` for the iterative solvers (tools/animkit/cmd_ik.c
 * states the rule): walk up from the effector through joints a skin uses, stopping below the
 * first ancestor with more than one child joint once the chain has two joints. */
static int ik_default_root(const ak_scene* s, int eff) {
    ak_i32_cspan parents = ak_skeleton_parents(s->skeleton);
    const bool all = !ik_is_joint(s, false, eff);
    size_t size = 1;
    int root = eff;
    for (;;) {
        const int p = parents.ptr[root];
        if (p < 0 || !ik_is_joint(s, all, p)) break;
        if (size >= 2) {
            size_t kids = 0;
            for (size_t j = (size_t)p + 1; j < parents.count && kids < 2; ++j)
                if (parents.ptr[j] == p && ik_is_joint(s, all, (int)j)) ++kids;
            if (kids > 1) break;
        }
        root = p;
        ++size;
    }
    return root;
}

static PyObject* chain_names(const ak_scene* s, const int16_t* chain, size_t n) {
    PyObject* list = PyList_New((Py_ssize_t)n);
    for (size_t i = 0; list && i < n; ++i) {
        const char* name = ak_skeleton_joint_name(s->skeleton, (size_t)chain[i]);
        PyObject* str = PyUnicode_DecodeUTF8(name, (Py_ssize_t)strlen(name), "replace");
        if (!str) {
            Py_CLEAR(list);
            break;
        }
        PyList_SET_ITEM(list, (Py_ssize_t)i, str);
    }
    return list;
}

static PyObject* scene_ik(SceneObject* o, PyObject* args, PyObject* kw) {
    static char* kwlist[] = {"effector", "target", "solver", "root", "iterations", "tolerance", "clip", "time", NULL};
    const char *eff_name = NULL, *solver_name = NULL, *root_name = NULL;
    double tx, ty, tz, tolerance = 0.0, t = 0.0;
    Py_ssize_t iterations = 0;
    PyObject* clip_obj = Py_None;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "s(ddd)|zzndOd:ik", kwlist, &eff_name, &tx, &ty, &tz, &solver_name,
                                     &root_name, &iterations, &tolerance, &clip_obj, &t))
        return NULL;
    const ak_scene* s = o->scene;
    if (!(fabs(tx) <= 1e37 && fabs(ty) <= 1e37 && fabs(tz) <= 1e37)) return RAISE_ARG("target must be finite, within +-1e37");
    ak_ik_solver solver = AK_IK_SOLVER_FABRIK;
    if (solver_name && ak_ik_solver_parse(solver_name, &solver) != AK_OK)
        return RAISE_ARG("solver must be 'ccd', 'fabrik', 'twobone' or 'dls', not '%s'", solver_name);
    if (iterations < 0 || iterations > 1000000) return RAISE_ARG("iterations must be in 0..1000000 (0: the default, 50)");
    if (!(tolerance >= 0.0) || !isfinite(tolerance)) return RAISE_ARG("tolerance must be a number >= 0");
    if (finite_arg(t, "time") < 0) return NULL;
    int clip = -1;
    if (clip_arg(o, clip_obj, -1, &clip) < 0) return NULL;
    int eff = find_joint(s, eff_name);
    if (eff < 0) return raise_as(NotFoundError, AK_ERR_NOT_FOUND, s->name, "no joint named '%s'", eff_name);
    ak_i32_cspan parents = ak_skeleton_parents(s->skeleton);
    int root;
    if (root_name) {
        root = find_joint(s, root_name);
        if (root < 0) return raise_as(NotFoundError, AK_ERR_NOT_FOUND, s->name, "no joint named '%s'", root_name);
    } else if (solver == AK_IK_SOLVER_TWO_BONE) {
        root = eff;
        for (int k = 0; k < 2 && parents.ptr[root] >= 0; ++k) root = parents.ptr[root];
    } else {
        root = ik_default_root(s, eff);
    }
    PoseObject* pose = pose_new(o);
    if (!pose) return NULL;
    size_t n = pose->joint_count, chain_count = 0;
    int16_t* chain = PyMem_Calloc(n, sizeof(int16_t));
    ak_vec3* before = PyMem_Calloc(n, sizeof(ak_vec3));
    ak_vec3* after = PyMem_Calloc(n, sizeof(ak_vec3));
    if (!chain || !before || !after) {
        PyMem_Free(chain);
        PyMem_Free(before);
        PyMem_Free(after);
        Py_DECREF(pose);
        return PyErr_NoMemory();
    }
    ak_result r = ak_ik_chain_build(s->skeleton, root, eff, (ak_i16_span){chain, n}, &chain_count);
    PyObject* res = NULL;
    if (r == AK_ERR_NOT_FOUND) {
        raise_as(NotFoundError, r, s->name, "joint '%s' is not an ancestor of '%s'", root_name ? root_name : "?", eff_name);
        goto done;
    }
    if (r == AK_OK && solver == AK_IK_SOLVER_TWO_BONE && chain_count != 3) {
        RAISE_ARG("twobone needs a chain of 3 joints, '%s'..'%s' has %zu", ak_skeleton_joint_name(s->skeleton, (size_t)root),
                  eff_name, chain_count);
        goto done;
    }
    bool reached = false;
    float error = 0.0f;
    size_t used = 0;
    Py_BEGIN_ALLOW_THREADS
    if (r == AK_OK) r = poser_acquire(o);
    if (r == AK_OK) {
        r = pose_sample_locked(&o->poser, pose, clip, (float)t, clip < 0);
        PyThread_release_lock(o->lock);
    }
    ak_i16_cspan ch = {chain, chain_count};
    ak_transform_span lp = {pose->local, n};
    if (r == AK_OK) r = ak_ik_chain_positions(s->skeleton, (ak_transform_cspan){pose->local, n}, ch, (ak_vec3_span){before, n});
    size_t ss = ak_ik_chain_scratch_size(solver, chain_count);
    void* scratch = r == AK_OK ? malloc(ss ? ss : 1) : NULL;
    if (r == AK_OK && !scratch) r = AK_ERR_NO_MEMORY;
    if (r == AK_OK) {
        ak_ik_chain_job job = {
            .skeleton = s->skeleton, .pose = lp, .chain = ch, .target = ak_vec3_make((float)tx, (float)ty, (float)tz),
            .solver = solver, .max_iterations = (size_t)iterations, .tolerance = (float)tolerance,
            .scratch = {scratch, ss}, .out_reached = &reached, .out_error = &error, .out_iterations = &used,
        };
        r = ak_ik_chain_run(&job);
    }
    free(scratch);
    if (r == AK_OK) r = ak_ik_chain_positions(s->skeleton, (ak_transform_cspan){pose->local, n}, ch, (ak_vec3_span){after, n});
    if (r == AK_OK)
        r = ak_scene_world_matrices(s, (ak_transform_cspan){pose->local, n}, (ak_mat4_span){pose->world, n});
    Py_END_ALLOW_THREADS
    if (r != AK_OK) {
        raise_result(r, s->name, NULL);
        goto done;
    }
    npy_intp dims[2] = {(npy_intp)chain_count, 3};
    PyArrayObject* pa = (PyArrayObject*)PyArray_SimpleNew(2, dims, NPY_FLOAT32);
    PyArrayObject* pb = (PyArrayObject*)PyArray_SimpleNew(2, dims, NPY_FLOAT32);
    PyObject* names = chain_names(s, chain, chain_count);
    if (pa && pb && names) {
        memcpy(PyArray_DATA(pa), after, chain_count * sizeof(ak_vec3));
        memcpy(PyArray_DATA(pb), before, chain_count * sizeof(ak_vec3));
        res = Py_BuildValue("{s:O,s:d,s:n,s:s,s:O,s:O,s:O,s:O}", "reached", reached ? Py_True : Py_False, "error",
                            (double)error, "iterations", (Py_ssize_t)used, "solver", ak_ik_solver_name(solver), "joints",
                            names, "positions", (PyObject*)pa, "initial", (PyObject*)pb, "pose", (PyObject*)pose);
    }
    Py_XDECREF(pa);
    Py_XDECREF(pb);
    Py_XDECREF(names);
done:
    PyMem_Free(chain);
    PyMem_Free(before);
    PyMem_Free(after);
    Py_DECREF(pose);
    return res;
}

/* One frame as `animkit render FILE --time T --size WxH [--clip C] [--method M] [--camera ..]
 * [--fov F] [--skeleton]` draws it (tools/animkit/cmd_render.c), into pixels. */
static ak_result render_frame(SceneObject* o, int clip, float t, cli_method method, const cli_camera* cam,
                              bool skeleton, int w, int h, uint8_t* pixels) {
    const ak_scene* s = o->scene;
    cli_poser* p = &o->poser;
    cli_frame f;
    memset(&f, 0, sizeof f);
    ak_result r = cli_poser_pose(p, clip, t, false, CLI_LBS);
    if (r != AK_OK) return r;
    ak_vec3 lo = ak_vec3_splat(INFINITY), hi = ak_vec3_splat(-INFINITY);
    cli_bounds_add_visible(p, NULL, &lo, &hi);
    if (!ak_vec3_is_finite(lo) || !ak_vec3_is_finite(hi)) lo = hi = ak_vec3_zero();
    if (cli_frame_init_camera(&f, s, w, h, lo, hi, cam)) {
        cli_frame_free(&f);
        return AK_ERR_NO_MEMORY;
    }
    bool skinned = false;
    for (size_t m = 0; m < s->mesh_count; ++m) skinned = skinned || (s->meshes[m].skin >= 0 && s->meshes[m].mesh->influence_count);
    static const char* const labels[3] = {"LBS", "DQS", "CoR"};
    char strip[160], title[200];
    snprintf(strip, sizeof strip, "%s%s%s", s->name, clip >= 0 ? "  " : "", clip >= 0 ? ak_clip_name(s->clips[clip]) : "");
    snprintf(title, sizeof title, "%s  t=%.2fs  %s", strip, (double)t, skinned ? labels[method] : "");
    r = cli_poser_pose(p, clip, t, false, method);
    ak_image img = {.pixels = pixels, .width = w, .height = h, .stride = (size_t)w * 4};
    cli_draw_opts opts = {.skeleton = skeleton, .title = title};
    if (r == AK_OK) r = cli_frame_draw(&f, p, &opts, &img);
    cli_frame_free(&f);
    return r;
}

static PyObject* scene_render(SceneObject* o, PyObject* args, PyObject* kw) {
    static char* kwlist[] = {"time", "size", "clip", "method", "camera", "fov", "skeleton", "out", NULL};
    double t = 0.0, fov = 0.0;
    int w = 640, h = 480, skeleton = 0;
    PyObject *clip_obj = NULL, *cam_obj = Py_None, *out = NULL;
    const char* method_name = NULL;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "|d(ii)OzOdpO:render", kwlist, &t, &w, &h, &clip_obj, &method_name, &cam_obj,
                                     &fov, &skeleton, &out))
        return NULL;
    if (finite_arg(t, "time") < 0) return NULL;
    if (w < 8 || h < 8 || w > 8192 || h > 8192) return RAISE_ARG("size (%d, %d) must be 8..8192 pixels each", w, h);
    cli_method method;
    if (method_arg(method_name, &method) < 0) return NULL;
    int clip = -1;
    if (clip_arg(o, clip_obj, o->scene->clip_count ? 0 : -1, &clip) < 0) return NULL;
    cli_camera cam = {0};
    if (cam_obj != Py_None) {
        double yaw = 0, pitch = 0, dist = 0;
        if (!PyArg_ParseTuple(cam_obj, "dd|d:camera", &yaw, &pitch, &dist)) return NULL;
        if (!isfinite(yaw) || fabs(yaw) > 3e38 || !(pitch >= -85.0 && pitch <= 85.0) ||
            (PyTuple_GET_SIZE(cam_obj) == 3 && !(dist > 0.0 && dist <= 1e9)))
            return RAISE_ARG("camera must be (yaw, pitch[, distance]): degrees, pitch in -85..85, distance in (0, 1e9]");
        cam.has_angles = true;
        cam.yaw = (float)yaw;
        cam.pitch = (float)pitch;
        cam.distance = (float)dist;
    }
    if (fov != 0.0 && !(fov >= 1.0 && fov <= 170.0)) return RAISE_ARG("fov must be 1..170 degrees, not %g", fov);
    cam.fov = (float)fov;
    npy_intp dims[3] = {h, w, 4};
    PyArrayObject* img = output_array(out, 3, dims, NPY_UINT8, "render");
    if (!img) return NULL;
    ak_result r;
    Py_BEGIN_ALLOW_THREADS
    r = poser_acquire(o);
    if (r == AK_OK) {
        r = render_frame(o, clip, (float)t, method, &cam, skeleton != 0, w, h, PyArray_DATA(img));
        PyThread_release_lock(o->lock);
    }
    Py_END_ALLOW_THREADS
    if (r != AK_OK) {
        Py_DECREF(img);
        return raise_result(r, o->scene->name, NULL);
    }
    return (PyObject*)img;
}

static void save_warn(ak_log_level level, const char* message, void* user) {
    (void)level;
    (void)user;
    /* called without the GIL: warnings go to stderr as the command's do */
    fprintf(stderr, "animkit: warning: %s\n", message);
}

static PyObject* scene_save(SceneObject* o, PyObject* args, PyObject* kw) {
    static char* kwlist[] = {"path", NULL};
    PyObject* path_bytes = NULL;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O&:save", kwlist, PyUnicode_FSConverter, &path_bytes)) return NULL;
    const char* path = PyBytes_AS_STRING(path_bytes);
    ak_diag diag;
    memset(&diag, 0, sizeof diag);
    ak_io_save_desc desc = {.logger = {.func = save_warn}};
    ak_result r;
    Py_BEGIN_ALLOW_THREADS
    r = ak_io_save(path, o->scene, &desc, &diag);
    Py_END_ALLOW_THREADS
    if (r != AK_OK) raise_result(r, path, &diag);
    Py_DECREF(path_bytes);
    if (r != AK_OK) return NULL;
    Py_RETURN_NONE;
}

static PyMethodDef scene_methods[] = {
    {"sample", (PyCFunction)(void (*)(void))scene_sample, METH_VARARGS | METH_KEYWORDS,
     "sample(clip=0, time=0.0) -> Pose\n\n"
     "The local pose of clip (an index or a name; None: the rest pose; default the first clip, the "
     "rest pose when there is none) at time seconds (clamped to the clip), with morph weights, and "
     "its model matrices. As `animkit export --clip C --time T` poses the scene."},
    {"rest_pose", (PyCFunction)scene_rest_pose, METH_NOARGS, "rest_pose() -> Pose\n\nThe skeleton's rest pose."},
    {"skin", (PyCFunction)(void (*)(void))scene_skin, METH_VARARGS | METH_KEYWORDS,
     "skin(pose, method='lbs', mesh=0, out=None) -> numpy.ndarray\n\n"
     "World-space vertex positions (N, 3) float32 of scene mesh `mesh` in `pose`: morphed, then "
     "skinned with 'lbs', 'dqs', 'cor', 'implicit' or 'soft' (an unskinned mesh is moved by its node). Bit for bit the "
     "vertices `animkit export --time T --method M` writes. out: a writable C-contiguous (N, 3) "
     "float32 array to write into (no allocation)."},
    {"ik", (PyCFunction)(void (*)(void))scene_ik, METH_VARARGS | METH_KEYWORDS,
     "ik(effector, target, solver='fabrik', root=None, iterations=0, tolerance=0.0, clip=None, time=0.0) -> dict\n\n"
     "Solve the chain root..effector towards target (x, y, z), from the rest pose (clip None) or "
     "clip at time, as `animkit ik` does (same default root, iteration budget 50 and tolerance "
     "1e-4 x chain length when 0). Returns {'reached', 'error', 'iterations', 'solver', 'joints' "
     "(chain names), 'positions' (chain joints after, (n, 3)), 'initial' (before), 'pose' (the "
     "solved Pose)}."},
    {"render", (PyCFunction)(void (*)(void))scene_render, METH_VARARGS | METH_KEYWORDS,
     "render(time=0.0, size=(640, 480), clip=0, method='lbs', camera=None, fov=0.0, skeleton=False, out=None)"
     " -> numpy.ndarray\n\n"
     "One frame (H, W, 4) uint8 RGBA, the pixels `animkit render --time T --size WxH` writes. "
     "camera: (yaw, pitch[, distance]) in degrees; fov: degrees (0: 40); out: a writable (H, W, 4) "
     "uint8 array to draw into."},
    {"save", (PyCFunction)(void (*)(void))scene_save, METH_VARARGS | METH_KEYWORDS,
     "save(path) -> None\n\nWrite the scene as glTF 2.0 (.glb, or .gltf + .bin), atomically."},
    {NULL, NULL, 0, NULL},
};

static PyGetSetDef scene_getset[] = {
    {"name", (getter)scene_name, NULL, "File name or 'builtin:NAME'.", NULL},
    {"joint_names", (getter)scene_joint_names, NULL, "Names of the skeleton's joints (list of str), parents first.",
     NULL},
    {"parents", (getter)scene_parents, NULL, "Parent index per joint (-1 for roots), a read-only int32 view.", NULL},
    {"clip_names", (getter)scene_clip_names, NULL, "Names of the clips (list of str), file order.", NULL},
    {"clip_durations", (getter)scene_clip_durations, NULL, "Duration of each clip in seconds (list of float).", NULL},
    {"meshes", (getter)scene_meshes, NULL, "The scene's meshes (tuple of Mesh), file order.", NULL},
    {"skins", (getter)scene_skins, NULL,
     "The skins (list of dict: name, joints (skeleton joint per slot, int32 view), inverse_binds "
     "((n, 4, 4) float32 view))).",
     NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

static PyTypeObject SceneType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "animkit.Scene",
    .tp_basicsize = sizeof(SceneObject),
    .tp_dealloc = (destructor)scene_dealloc,
    .tp_repr = (reprfunc)scene_repr,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "A skeleton, its meshes, skins and clips (animkit.load, animkit.retarget). Read-only; "
              "safe to share between threads.",
    .tp_methods = scene_methods,
    .tp_getset = scene_getset,
};

/* ---- simulations (cloth, particles, boids, fluid) --------------------------------------------
 * A scene file or preset loaded by the library (ak_<module>_scene_load_file / _preset) and
 * stepped by the command's own run code (tools/animkit/cloth_run.c, particles_run.c,
 * boids_run.c; fluid's loop is ak_fluid_step_run as `animkit fluid` calls it), so a Sim's state
 * after n steps is the command's after --steps n. */

typedef enum sim_kind { SIM_CLOTH, SIM_PARTICLES, SIM_BOIDS, SIM_FLUID } sim_kind;
static const char* const sim_kind_names[] = {"cloth", "particles", "boids", "fluid"};

typedef struct fluid_state {
    ak_fluid_scene scene;
    ak_vec3 *pos, *vel;
    uint8_t* flags;
    float *rho, *pres;
    void* scratch;
    size_t cap, n;
    ak_fluid_stats stats;
    ak_fluid_step_job job;
} fluid_state;

typedef struct sim_data {
    ak_cloth_scene cloth_scene;
    cloth_run cloth;
    ak_particles_scene particles_scene;
    particles_run particles;
    particles_character character;
    bool has_character;
    ak_boids_scene boids_scene;
    boids_run boids;
    fluid_state fluid;
} sim_data;

typedef struct SimObject {
    PyObject_HEAD
    sim_kind kind;
    char name[256];
    sim_data* d;     /* PyMem_Calloc'ed: the run structs point into it */
    bool ready;      /* the run is initialised (free it) */
    bool scene_ready;/* the scene is loaded (free it) */
    long steps_done;
    long default_steps;
    float dt;
    PyThread_type_lock lock;
} SimObject;

static PyTypeObject SimType;

static void sim_free_data(SimObject* o) {
    sim_data* d = o->d;
    if (!d) return;
    switch (o->kind) {
    case SIM_CLOTH:
        if (o->ready) cloth_run_free(&d->cloth);
        if (o->scene_ready) ak_cloth_scene_free(&d->cloth_scene);
        break;
    case SIM_PARTICLES:
        if (o->ready) particles_run_free(&d->particles);
        if (d->has_character) particles_character_free(&d->character);
        if (o->scene_ready) ak_particles_scene_free(&d->particles_scene);
        break;
    case SIM_BOIDS:
        if (o->ready) boids_run_free(&d->boids);
        if (o->scene_ready) ak_boids_scene_free(&d->boids_scene);
        break;
    case SIM_FLUID:
        free(d->fluid.pos);
        free(d->fluid.vel);
        free(d->fluid.flags);
        free(d->fluid.rho);
        free(d->fluid.pres);
        free(d->fluid.scratch);
        if (o->scene_ready) ak_fluid_scene_free(&d->fluid.scene);
        break;
    }
    PyMem_Free(d);
    o->d = NULL;
}

static void sim_dealloc(SimObject* o) {
    sim_free_data(o);
    if (o->lock) PyThread_free_lock(o->lock);
    PyObject_Free(o);
}

static int fluid_init(fluid_state* f, uint32_t threads) {
    ak_fluid_scene* s = &f->scene;
    s->steps = ak_fluid_scene_steps(s);
    f->cap = ak_fluid_scene_capacity(s);
    size_t c = f->cap ? f->cap : 1;
    f->pos = calloc(c, sizeof(ak_vec3));
    f->vel = calloc(c, sizeof(ak_vec3));
    f->flags = calloc(c, 1);
    f->rho = calloc(c, sizeof(float));
    f->pres = calloc(c, sizeof(float));
    const size_t bytes = ak_fluid_scratch_size(f->cap, &s->desc);
    f->scratch = malloc(bytes ? bytes : 1);
    if (!f->pos || !f->vel || !f->flags || !f->rho || !f->pres || !f->scratch) return -1;
    f->n = ak_fluid_scene_fill(s, f->pos, f->vel, f->cap);
    f->job = (ak_fluid_step_job){.desc = &s->desc, .dt = s->dt, .positions = {f->pos, f->cap}, .velocities = {f->vel, f->cap},
                                 .particle_count = &f->n, .colliders = {s->colliders, s->collider_count},
                                 .emitters = {s->emitters, s->emitter_count}, .sinks = {s->sinks, s->sink_count},
                                 .thread_count = threads, .scratch = {f->scratch, bytes}, .out_flags = {f->flags, f->cap},
                                 .out_densities = {f->rho, f->cap}, .out_pressures = {f->pres, f->cap},
                                 .out_stats = &f->stats};
    return 0;
}

/* One step of the fluid as `animkit fluid` runs it (colliders with a velocity move after it). */
static ak_result fluid_step(fluid_state* f, long k) {
    ak_fluid_scene* s = &f->scene;
    f->job.time = (float)((double)k * s->dt);
    ak_result r = ak_fluid_step_run(&f->job);
    if (r != AK_OK) return r;
    for (size_t c = 0; c < s->collider_count; ++c) {
        ak_vec3 dv = ak_vec3_scale(s->colliders[c].velocity, s->dt);
        s->colliders[c].a = ak_vec3_add(s->colliders[c].a, dv);
        s->colliders[c].b = ak_vec3_add(s->colliders[c].b, dv);
    }
    return AK_OK;
}

static int kind_arg(const char* name, sim_kind* out) {
    for (int k = 0; k < 4; ++k)
        if (strcmp(name, sim_kind_names[k]) == 0) {
            *out = (sim_kind)k;
            return 0;
        }
    RAISE_ARG("unknown simulation '%s' (cloth, particles, boids, fluid)", name);
    return -1;
}

/* sim_make(kind, source, is_file, count=0, seed=-1, threads=1) */
static PyObject* sim_make(sim_kind kind, const char* source, bool is_file, long count, long seed, int threads) {
    SimObject* o = PyObject_New(SimObject, &SimType);
    if (!o) return NULL;
    o->kind = kind;
    snprintf(o->name, sizeof o->name, "%s", source);
    o->d = PyMem_Calloc(1, sizeof(sim_data));
    o->ready = o->scene_ready = false;
    o->steps_done = 0;
    o->default_steps = 0;
    o->dt = 0.0f;
    o->lock = PyThread_allocate_lock();
    if (!o->d || !o->lock) {
        Py_DECREF(o);
        return PyErr_NoMemory();
    }
    sim_data* d = o->d;
    ak_diag diag;
    memset(&diag, 0, sizeof diag);
    ak_result r = AK_OK;
    int rc = 0;
    const char* presets = "";
    Py_BEGIN_ALLOW_THREADS
    switch (kind) {
    case SIM_CLOTH:
        presets = AK_CLOTH_SCENE_PRESETS;
        r = is_file ? ak_cloth_scene_load_file(source, &d->cloth_scene, &diag)
                    : ak_cloth_scene_preset(source, &d->cloth_scene, &diag);
        if (r == AK_OK) {
            o->scene_ready = true;
            d->cloth_scene.thread_count = threads;
            rc = cloth_run_init(&d->cloth, &d->cloth_scene, "cloth", o->name);
            o->ready = true;
            o->default_steps = d->cloth_scene.steps;
            o->dt = d->cloth_scene.dt;
        }
        break;
    case SIM_PARTICLES:
        presets = AK_PARTICLES_SCENE_PRESETS;
        r = is_file ? ak_particles_scene_load_file(source, &d->particles_scene, &diag)
                    : ak_particles_scene_preset(source, &d->particles_scene, &diag);
        if (r == AK_OK) {
            o->scene_ready = true;
            if (!is_file && strcmp(source, "character") == 0) {
                d->has_character = true;
                rc = particles_character_init(&d->character, &rc);
            }
            if (!rc) {
                rc = particles_run_init(&d->particles, &d->particles_scene, d->has_character ? &d->character : NULL,
                                        (uint64_t)(seed >= 0 ? seed : 1), (uint32_t)threads);
                o->ready = true;
            }
            o->default_steps = 200; /* `animkit particles` --steps default */
            o->dt = d->particles_scene.dt;
        }
        break;
    case SIM_BOIDS:
        presets = AK_BOIDS_SCENE_PRESETS;
        ak_boids_scene_defaults(&d->boids_scene);
        r = is_file ? ak_boids_scene_load_file(source, &d->boids_scene, &diag)
                    : ak_boids_scene_preset(source, &d->boids_scene, &diag);
        if (r == AK_OK) {
            o->scene_ready = true;
            ak_boids_scene* sc = &d->boids_scene;
            if (count > 0 && sc->agent_count == 0) sc->count = (size_t)count;
            if (seed >= 0) sc->seed = seed;
            if (sc->agent_count == 0) ak_boids_scene_scale_bounds(sc, sc->count);
            rc = boids_run_init(&d->boids, sc, "boids", o->name, (uint32_t)threads, false);
            o->ready = true;
            o->default_steps = sc->steps;
            o->dt = sc->dt;
        }
        break;
    case SIM_FLUID:
        presets = AK_FLUID_SCENE_PRESETS;
        r = is_file ? ak_fluid_scene_load_file(source, &d->fluid.scene, &diag)
                    : ak_fluid_scene_preset(source, count, &d->fluid.scene, &diag);
        if (r == AK_OK) {
            o->scene_ready = true;
            rc = fluid_init(&d->fluid, (uint32_t)threads) ? CLI_BAD_INPUT : 0;
            o->ready = true;
            o->default_steps = d->fluid.scene.steps;
            o->dt = d->fluid.scene.dt;
        }
        break;
    }
    Py_END_ALLOW_THREADS
    if (r == AK_ERR_NOT_FOUND && !is_file) {
        Py_DECREF(o);
        return raise_as(NotFoundError, r, source, "unknown %s preset (%s)", sim_kind_names[kind], presets);
    }
    if (r != AK_OK) {
        Py_DECREF(o);
        return raise_result(r, is_file ? source : NULL, &diag);
    }
    if (rc) {
        Py_DECREF(o);
        return raise_as(DataError, AK_ERR_BAD_DATA, source, "the %s run could not start (the reason is on stderr)",
                        sim_kind_names[kind]);
    }
    return (PyObject*)o;
}

static PyObject* mod_sim_preset(PyObject* self, PyObject* args, PyObject* kw) {
    (void)self;
    static char* kwlist[] = {"kind", "name", "count", "seed", "threads", NULL};
    const char *kind_name, *name;
    long count = 0, seed = -1;
    int threads = 1;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "ss|lli:sim_preset", kwlist, &kind_name, &name, &count, &seed, &threads))
        return NULL;
    sim_kind kind;
    if (kind_arg(kind_name, &kind) < 0) return NULL;
    if (threads < 1 || threads > 64) return RAISE_ARG("threads must be 1..64");
    if (count < 0 || count > 10000000) return RAISE_ARG("count must be 0..10000000 (0: the preset's)");
    return sim_make(kind, name, false, count, seed, threads);
}

static PyObject* mod_sim_load(PyObject* self, PyObject* args, PyObject* kw) {
    (void)self;
    static char* kwlist[] = {"kind", "path", "seed", "threads", NULL};
    const char* kind_name;
    PyObject* path_bytes = NULL;
    long seed = -1;
    int threads = 1;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "sO&|li:sim_load", kwlist, &kind_name, PyUnicode_FSConverter, &path_bytes,
                                     &seed, &threads))
        return NULL;
    sim_kind kind;
    PyObject* res = NULL;
    if (kind_arg(kind_name, &kind) == 0) {
        if (threads < 1 || threads > 64) RAISE_ARG("threads must be 1..64");
        else res = sim_make(kind, PyBytes_AS_STRING(path_bytes), true, 0, seed, threads);
    }
    Py_DECREF(path_bytes);
    return res;
}

static PyObject* sim_step(SimObject* o, PyObject* args, PyObject* kw) {
    static char* kwlist[] = {"steps", NULL};
    long n = 1;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "|l:step", kwlist, &n)) return NULL;
    if (n < 0 || n > 100000000L) return RAISE_ARG("steps must be 0..100000000, not %ld", n);
    ak_result r = AK_OK;
    int rc = 0;
    long failed = -1;
    sim_data* d = o->d;
    Py_BEGIN_ALLOW_THREADS
    PyThread_acquire_lock(o->lock, WAIT_LOCK);
    for (long i = 0; i < n && r == AK_OK && rc == 0; ++i) {
        const long k = o->steps_done;
        switch (o->kind) {
        case SIM_CLOTH: rc = cloth_run_step(&d->cloth, "cloth", o->name); break;
        case SIM_PARTICLES: rc = particles_run_step(&d->particles, (int)k); break;
        case SIM_BOIDS: r = boids_run_step(&d->boids, k); break;
        case SIM_FLUID: r = fluid_step(&d->fluid, k); break;
        }
        if (r != AK_OK || rc) failed = k + 1;
        else ++o->steps_done;
    }
    PyThread_release_lock(o->lock);
    Py_END_ALLOW_THREADS
    if (o->kind == SIM_BOIDS && r != AK_OK)
        return raise_as(error_type(r), r, o->name, "step %ld: %s", failed, boids_run_error(r));
    if (r == AK_ERR_NO_CONVERGENCE)
        return raise_as(Error, r, o->name, "blow-up at step %ld: a particle became non-finite or moved too far; lower dt",
                        failed);
    if (r != AK_OK) return raise_as(error_type(r), r, o->name, "step %ld: %s", failed, ak_result_string(r));
    if (rc) return raise_as(Error, AK_ERR_NO_CONVERGENCE, o->name, "step %ld failed (the reason is on stderr)", failed);
    Py_RETURN_NONE;
}

/* Current positions (or velocities) and their count. */
static const ak_vec3* sim_vectors(SimObject* o, bool velocities, size_t* out_count) {
    sim_data* d = o->d;
    switch (o->kind) {
    case SIM_CLOTH: *out_count = d->cloth.n; return velocities ? d->cloth.vel : d->cloth.x;
    case SIM_PARTICLES: {
        ak_particles_state st = ak_particles_get_state(d->particles.ps);
        *out_count = st.count;
        return velocities ? st.velocity : st.position;
    }
    case SIM_BOIDS: *out_count = d->boids.n; return velocities ? d->boids.v : d->boids.p;
    case SIM_FLUID: *out_count = d->fluid.n; return velocities ? d->fluid.vel : d->fluid.pos;
    }
    *out_count = 0;
    return NULL;
}

static PyObject* sim_array(SimObject* o, bool velocities) {
    size_t n = 0;
    const ak_vec3* v;
    Py_BEGIN_ALLOW_THREADS
    PyThread_acquire_lock(o->lock, WAIT_LOCK); /* a step running in another thread */
    v = sim_vectors(o, velocities, &n);
    PyThread_release_lock(o->lock);
    Py_END_ALLOW_THREADS
    npy_intp dims[2] = {(npy_intp)n, 3};
    return view_array((PyObject*)o, 2, dims, NULL, NPY_FLOAT32, n ? v : NULL, 0);
}

static PyObject* sim_positions(SimObject* o, void* c) {
    (void)c;
    return sim_array(o, false);
}

static PyObject* sim_velocities(SimObject* o, void* c) {
    (void)c;
    return sim_array(o, true);
}

static PyObject* sim_get_kind(SimObject* o, void* c) {
    (void)c;
    return PyUnicode_FromString(sim_kind_names[o->kind]);
}

static PyObject* sim_get_name(SimObject* o, void* c) {
    (void)c;
    return PyUnicode_DecodeFSDefault(o->name);
}

static PyObject* sim_get_steps_done(SimObject* o, void* c) {
    (void)c;
    return PyLong_FromLong(o->steps_done);
}

static PyObject* sim_get_steps(SimObject* o, void* c) {
    (void)c;
    return PyLong_FromLong(o->default_steps);
}

static PyObject* sim_get_dt(SimObject* o, void* c) {
    (void)c;
    return PyFloat_FromDouble((double)o->dt);
}

static PyObject* sim_repr(SimObject* o) {
    size_t n = 0;
    sim_vectors(o, false, &n);
    return PyUnicode_FromFormat("<animkit.Sim %s '%s': %zu points, %ld steps run>", sim_kind_names[o->kind], o->name, n,
                                o->steps_done);
}

static PyMethodDef sim_methods[] = {
    {"step", (PyCFunction)(void (*)(void))sim_step, METH_VARARGS | METH_KEYWORDS,
     "step(steps=1) -> None\n\nAdvance the simulation by `steps` steps of dt (the GIL is released). "
     "After n steps from the start the state is the one `animkit cloth|particles|boids|fluid "
     "--steps n` ends with."},
    {NULL, NULL, 0, NULL},
};

static PyGetSetDef sim_getset[] = {
    {"positions", (getter)sim_positions, NULL,
     "Current positions (N, 3) float32: a read-only view of the simulation's memory (it changes "
     "with each step; copy it to keep a frame). Particles and fluid: the live particles.",
     NULL},
    {"velocities", (getter)sim_velocities, NULL, "Current velocities (N, 3) float32, a read-only view.", NULL},
    {"kind", (getter)sim_get_kind, NULL, "'cloth', 'particles', 'boids' or 'fluid'.", NULL},
    {"name", (getter)sim_get_name, NULL, "The preset name or scene file.", NULL},
    {"steps_done", (getter)sim_get_steps_done, NULL, "Steps run so far.", NULL},
    {"steps", (getter)sim_get_steps, NULL, "The scene's own step count (what the command runs by default).", NULL},
    {"dt", (getter)sim_get_dt, NULL, "Seconds per step.", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

static PyTypeObject SimType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "animkit.Sim",
    .tp_basicsize = sizeof(SimObject),
    .tp_dealloc = (destructor)sim_dealloc,
    .tp_repr = (reprfunc)sim_repr,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "A running simulation (animkit.cloth / particles / boids / fluid .preset or .load).",
    .tp_methods = sim_methods,
    .tp_getset = sim_getset,
};

/* ---- module functions --------------------------------------------------------------------- */

static PyObject* mod_load(PyObject* self, PyObject* args, PyObject* kw) {
    (void)self;
    static char* kwlist[] = {"path", NULL};
    PyObject* path_bytes = NULL;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O&:load", kwlist, PyUnicode_FSConverter, &path_bytes)) return NULL;
    const char* spec = PyBytes_AS_STRING(path_bytes);
    ak_scene* s = NULL;
    ak_result r;
    ak_diag diag;
    memset(&diag, 0, sizeof diag);
    PyObject* res = NULL;
    if (!spec[0]) {
        RAISE_ARG("empty path (a FILE or builtin:NAME)");
        goto done;
    }
    if (strncmp(spec, "builtin:", 8) == 0) {
        Py_BEGIN_ALLOW_THREADS
        r = ak_builtin_create(spec, NULL, NULL, &s);
        Py_END_ALLOW_THREADS
        if (r == AK_ERR_NOT_FOUND)
            raise_as(NotFoundError, r, spec, "unknown built-in model (try builtin:humanoid or builtin:cylinder)");
        else if (r != AK_OK)
            raise_result(r, spec, NULL);
        else
            res = (PyObject*)scene_new(s);
        goto done;
    }
    struct stat st;
    if (stat(spec, &st) != 0) {
        raise_as(FileError, AK_ERR_IO, spec, "no such file");
        goto done;
    }
    if (S_ISDIR(st.st_mode)) {
        raise_as(FileError, AK_ERR_IO, spec, "is a directory, not a model file");
        goto done;
    }
    Py_BEGIN_ALLOW_THREADS
    r = ak_io_load(spec, NULL, NULL, &s, &diag);
    Py_END_ALLOW_THREADS
    if (r != AK_OK)
        raise_result(r, spec, &diag);
    else
        res = (PyObject*)scene_new(s);
done:
    Py_DECREF(path_bytes);
    return res;
}

#define MAX_MAP_SIZE (1u << 20) /* as `animkit retarget --map` */

/* A map file's text (PyMem_Malloc'ed) or NULL with an exception. */
static char* read_map_file(const char* path, size_t* out_size) {
    FILE* f = fopen(path, "rb");
    if (!f) {
        raise_as(FileError, AK_ERR_IO, path, "cannot read the map file (%s)", strerror(errno));
        return NULL;
    }
    char* text = PyMem_Malloc(MAX_MAP_SIZE + 1);
    size_t n = text ? fread(text, 1, MAX_MAP_SIZE + 1, f) : 0;
    bool err = ferror(f) != 0;
    fclose(f);
    if (!text) return (char*)PyErr_NoMemory();
    if (err || n > MAX_MAP_SIZE) {
        PyMem_Free(text);
        if (err) raise_as(FileError, AK_ERR_IO, path, "cannot read the map file");
        else raise_as(UnsupportedError, AK_ERR_UNSUPPORTED, path, "the map file is larger than %u bytes", MAX_MAP_SIZE);
        return NULL;
    }
    *out_size = n;
    return text;
}

static PyObject* mod_retarget(PyObject* self, PyObject* args, PyObject* kw) {
    (void)self;
    static char* kwlist[] = {"source", "target", "map", "clip", "fps", "feet", "scaled", NULL};
    PyObject *src_obj, *dst_obj, *map_obj = Py_None, *clip_obj = NULL;
    double fps = 30.0;
    int feet = 1, scaled = 1;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O!O!|OOdpp:retarget", kwlist, &SceneType, &src_obj, &SceneType, &dst_obj,
                                     &map_obj, &clip_obj, &fps, &feet, &scaled))
        return NULL;
    SceneObject* src = (SceneObject*)src_obj;
    SceneObject* dst = (SceneObject*)dst_obj;
    if (!(fps >= 1.0 && fps <= 1000.0)) return RAISE_ARG("fps must be in [1, 1000], not %g", fps);
    if (!src->scene->skeleton || !dst->scene->skeleton)
        return raise_as(DataError, AK_ERR_EMPTY, !src->scene->skeleton ? src->scene->name : dst->scene->name,
                        "has no skeleton");
    int ci = -1;
    if (clip_arg(src, clip_obj, src->scene->clip_count ? 0 : -1, &ci) < 0) return NULL;
    if (ci < 0) return raise_as(NotFoundError, AK_ERR_NOT_FOUND, src->scene->name, "the source has no clip");
    size_t nt = ak_scene_joint_count(dst->scene);
    int32_t* map = PyMem_Malloc(nt * sizeof *map);
    if (!map) return PyErr_NoMemory();
    PyObject* res = NULL;
    ak_diag diag;
    memset(&diag, 0, sizeof diag);
    if (map_obj == Py_None) {
        /* as `animkit retarget` without --map: the humanoid template, or names when neither is one */
        ak_result r = ak_retarget_map_auto(src->scene->skeleton, dst->scene->skeleton, NULL, (ak_i32_span){map, nt},
                                           NULL, NULL, &diag);
        if (r != AK_OK) {
            raise_result(r, dst->scene->name, &diag);
            goto done;
        }
    } else {
        PyObject* path_bytes = NULL;
        if (!PyUnicode_FSConverter(map_obj, &path_bytes)) goto done;
        const char* path = PyBytes_AS_STRING(path_bytes);
        size_t size = 0, mapped = 0;
        char* text = read_map_file(path, &size);
        if (text) {
            ak_result r = ak_retarget_map_parse(text, size, src->scene->skeleton, dst->scene->skeleton, (ak_i32_span){map, nt},
                                                &mapped, &diag);
            PyMem_Free(text);
            if (r != AK_OK) raise_result(r, path, &diag);
            else res = Py_None; /* marker: parsed */
        }
        Py_DECREF(path_bytes);
        if (!res) goto done;
        res = NULL;
    }
    ak_retarget_desc d = {.source = src->scene->skeleton, .clip = src->scene->clips[ci], .target = dst->scene->skeleton,
                          .source_of_target = {map, nt}, .frame_rate = (float)fps, .unscaled_root_motion = !scaled,
                          .skip_foot_contacts = !feet};
    ak_retarget_stats st;
    ak_clip* clip = NULL;
    ak_result r;
    Py_BEGIN_ALLOW_THREADS
    r = ak_retarget_clip(&d, NULL, &clip, &st, &diag);
    Py_END_ALLOW_THREADS
    if (r != AK_OK) {
        char where[600];
        snprintf(where, sizeof where, "%s -> %s", src->scene->name, dst->scene->name);
        raise_as(error_type(r), r, where, "%s", diag.message[0] ? diag.message : ak_result_string(r));
        goto done;
    }
    SceneObject* view = scene_new(NULL);
    if (!view) {
        ak_clip_destroy(clip);
        goto done;
    }
    /* the target with this one clip (a shallow copy: the target keeps its own clips) */
    view->view = *dst->scene;
    view->own_clip = clip;
    view->view.clips = &view->own_clip;
    view->view.clip_count = 1;
    view->scene = &view->view;
    view->base = (PyObject*)dst;
    Py_INCREF(dst);
    res = (PyObject*)view;
done:
    PyMem_Free(map);
    return res;
}

static PyObject* mod_builtin_names(PyObject* self, PyObject* noargs) {
    (void)self;
    (void)noargs;
    size_t n = 0;
    const char* const* names = ak_builtin_names(&n);
    PyObject* list = PyList_New((Py_ssize_t)n);
    for (size_t i = 0; list && i < n; ++i) {
        PyObject* s = PyUnicode_FromString(names[i]);
        if (!s) {
            Py_CLEAR(list);
            break;
        }
        PyList_SET_ITEM(list, (Py_ssize_t)i, s);
    }
    return list;
}

static double now_seconds(void) {
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts); /* CPU time: steadier than wall time on a shared machine */
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The C side of bench/bench_python.py: the work of scene.sample(clip, time) followed by
 * scene.skin(pose, method, mesh, out=...) run count times in a C loop (the same functions, no
 * Python in between); seconds per iteration. */
static PyObject* mod_bench_c(PyObject* self, PyObject* args) {
    (void)self;
    PyObject* scene_obj;
    int clip;
    double t;
    const char* method_name;
    Py_ssize_t mi, count;
    if (!PyArg_ParseTuple(args, "O!idsnn:_bench_c", &SceneType, &scene_obj, &clip, &t, &method_name, &mi, &count))
        return NULL;
    SceneObject* o = (SceneObject*)scene_obj;
    cli_method method;
    if (method_arg(method_name, &method) < 0) return NULL;
    if (mi < 0 || (size_t)mi >= o->scene->mesh_count || !o->scene->meshes[mi].mesh || count < 1 ||
        clip >= (int)o->scene->clip_count)
        return RAISE_ARG("bad mesh, clip or count");
    PoseObject* pose = pose_new(o);
    if (!pose) return NULL;
    ak_vec3* out = PyMem_Calloc(o->scene->meshes[mi].mesh->vertex_count, sizeof(ak_vec3));
    if (!out) {
        Py_DECREF(pose);
        return PyErr_NoMemory();
    }
    ak_result r;
    double secs = 0.0;
    Py_BEGIN_ALLOW_THREADS
    r = poser_acquire(o);
    if (r == AK_OK) {
        cli_poser* pp = &o->poser;
        ak_transform* keep_local = pp->local;
        float* keep_morph = pp->morph_weights;
        ak_vec3* keep_pos = pp->positions[mi];
        double t0 = now_seconds();
        for (Py_ssize_t i = 0; i < count && r == AK_OK; ++i) {
            r = pose_sample_locked(pp, pose, clip, (float)t, clip < 0);
            pp->local = pose->local;
            pp->morph_weights = pose->morph;
            pp->positions[mi] = out;
            if (r == AK_OK) r = cli_poser_deform(pp, false, method);
            pp->local = keep_local;
            pp->morph_weights = keep_morph;
            pp->positions[mi] = keep_pos;
        }
        secs = (now_seconds() - t0) / (double)count;
        PyThread_release_lock(o->lock);
    }
    Py_END_ALLOW_THREADS
    PyMem_Free(out);
    Py_DECREF(pose);
    if (r != AK_OK) return raise_result(r, o->scene->name, NULL);
    return PyFloat_FromDouble(secs);
}

/* write_png(path, image): an (H, W, 4) uint8 array to a PNG file (atomically). */
static PyObject* mod_write_png(PyObject* self, PyObject* args, PyObject* kw) {
    (void)self;
    static char* kwlist[] = {"path", "image", NULL};
    PyObject *path_bytes = NULL, *img_obj;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O&O:write_png", kwlist, PyUnicode_FSConverter, &path_bytes, &img_obj))
        return NULL;
    PyArrayObject* a = (PyArrayObject*)PyArray_FROMANY(img_obj, NPY_UINT8, 3, 3, NPY_ARRAY_C_CONTIGUOUS | NPY_ARRAY_ALIGNED);
    PyObject* res = NULL;
    const char* path = PyBytes_AS_STRING(path_bytes);
    if (!a) {
        PyErr_Clear();
        RAISE_ARG("image must be an (H, W, 4) uint8 array");
    } else if (PyArray_DIM(a, 2) != 4 || PyArray_DIM(a, 0) < 1 || PyArray_DIM(a, 1) < 1 || PyArray_DIM(a, 0) > 65535 ||
               PyArray_DIM(a, 1) > 65535) {
        RAISE_ARG("image must be an (H, W, 4) uint8 array with 1..65535 pixels per side");
    } else {
        ak_image img = {.pixels = PyArray_DATA(a), .width = (int)PyArray_DIM(a, 1), .height = (int)PyArray_DIM(a, 0)};
        ak_result r;
        Py_BEGIN_ALLOW_THREADS
        r = ak_png_write(path, &img);
        Py_END_ALLOW_THREADS
        if (r != AK_OK) raise_as(error_type(r), r, path, "cannot write the PNG: %s", ak_result_string(r));
        else res = (Py_INCREF(Py_None), Py_None);
    }
    Py_XDECREF(a);
    Py_DECREF(path_bytes);
    return res;
}

#if defined(__has_include)
#if __has_include(<animkit/batch.h>)
#define AK_PY_HAVE_BATCH 1
#endif
#endif

#ifdef AK_PY_HAVE_BATCH
/* batch_run_job(line, name=None, input_dir=None, output_dir=None, index=0, force=False) -> str:
 * ak_batch_run_job (animkit/batch.h) on one job line; the row's JSON. */
static PyObject* mod_batch_run_job(PyObject* self, PyObject* args, PyObject* kw) {
    (void)self;
    static char* kwlist[] = {"line", "name", "input_dir", "output_dir", "index", "force", NULL};
    const char *line, *name = NULL, *in_dir = NULL, *out_dir = NULL;
    Py_ssize_t size;
    long index = 0;
    int force = 0;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "s#|zzzlp:batch_run_job", kwlist, &line, &size, &name, &in_dir, &out_dir,
                                     &index, &force))
        return NULL;
    ak_batch_row* row = PyMem_Calloc(1, sizeof *row);
    if (!row) return PyErr_NoMemory();
    ak_batch_desc d = {.name = name, .input_dir = in_dir, .output_dir = out_dir, .index = index, .force = force != 0};
    Py_BEGIN_ALLOW_THREADS
    (void)ak_batch_run_job(line, (size_t)size, &d, row);
    Py_END_ALLOW_THREADS
    PyObject* res = PyUnicode_FromString(row->json);
    PyMem_Free(row);
    return res;
}
#endif

/* fnv1a64_file(path) -> str: FNV-1a 64 of a file's bytes as 16 hex digits (animkit.batch's
 * input hashes; the offset basis and prime of animkit/batch.h). */
static PyObject* mod_fnv1a64_file(PyObject* self, PyObject* args) {
    (void)self;
    PyObject* path_bytes = NULL;
    if (!PyArg_ParseTuple(args, "O&:fnv1a64_file", PyUnicode_FSConverter, &path_bytes)) return NULL;
    const char* path = PyBytes_AS_STRING(path_bytes);
    uint64_t h = 0xcbf29ce484222325ull;
    bool ok = false;
    Py_BEGIN_ALLOW_THREADS
    FILE* f = fopen(path, "rb");
    if (f) {
        unsigned char buf[1 << 16];
        size_t n;
        while ((n = fread(buf, 1, sizeof buf, f)) > 0)
            for (size_t i = 0; i < n; ++i) h = (h ^ buf[i]) * 0x100000001b3ull;
        ok = !ferror(f);
        fclose(f);
    }
    Py_END_ALLOW_THREADS
    PyObject* res = NULL;
    if (!ok) raise_as(FileError, AK_ERR_IO, path, "cannot read the file (%s)", strerror(errno));
    else res = PyUnicode_FromFormat("%08x%08x", (unsigned)(h >> 32), (unsigned)(h & 0xffffffffu));
    Py_DECREF(path_bytes);
    return res;
}

static PyMethodDef module_methods[] = {
    {"fnv1a64_file", (PyCFunction)mod_fnv1a64_file, METH_VARARGS,
     "fnv1a64_file(path) -> str\n\nFNV-1a 64 of a file's bytes as 16 hex digits."},
#ifdef AK_PY_HAVE_BATCH
    {"batch_run_job", (PyCFunction)(void (*)(void))mod_batch_run_job, METH_VARARGS | METH_KEYWORDS,
     "batch_run_job(line, name=None, input_dir=None, output_dir=None, index=0, force=False) -> str\n\n"
     "Run one batch job line (docs/batch.md) with the library's runner; its manifest row as JSON. "
     "Never raises for a bad job: errors are rows."},
#endif
    {"write_png", (PyCFunction)(void (*)(void))mod_write_png, METH_VARARGS | METH_KEYWORDS,
     "write_png(path, image) -> None\n\nWrite an (H, W, 4) uint8 RGBA array as a PNG file, atomically."},
    {"sim_preset", (PyCFunction)(void (*)(void))mod_sim_preset, METH_VARARGS | METH_KEYWORDS,
     "sim_preset(kind, name, count=0, seed=-1, threads=1) -> Sim\n\n"
     "A simulation preset of kind 'cloth', 'particles', 'boids' or 'fluid' (animkit.cloth.preset and "
     "friends call it). count: boids agents / fluid particles (0: the preset's); seed: random seed "
     "of particles and boids (-1: the scene's)."},
    {"sim_load", (PyCFunction)(void (*)(void))mod_sim_load, METH_VARARGS | METH_KEYWORDS,
     "sim_load(kind, path, seed=-1, threads=1) -> Sim\n\n"
     "A simulation scene file (the JSON formats of docs/cloth.md, particles.md, boids.md, fluid.md); "
     "errors name the key path."},
    {"_bench_c", (PyCFunction)mod_bench_c, METH_VARARGS,
     "_bench_c(scene, clip, time, method, mesh, count) -> float\n\n"
     "Seconds per iteration of sample + skin (out= a fixed buffer) in a C loop: the reference "
     "of bench/bench_python.py."},
    {"load", (PyCFunction)(void (*)(void))mod_load, METH_VARARGS | METH_KEYWORDS,
     "load(path) -> Scene\n\nLoad a model file (.glb, .gltf, .bvh; FBX/Collada/OBJ through Assimp "
     "when built with it) or a built-in model ('builtin:humanoid', 'builtin:cylinder'). Raises "
     "FileError, ParseError, DataError, NotFoundError or UnsupportedError with the loader's message "
     "and path."},
    {"retarget", (PyCFunction)(void (*)(void))mod_retarget, METH_VARARGS | METH_KEYWORDS,
     "retarget(source, target, map=None, clip=0, fps=30.0, feet=True, scaled=True) -> Scene\n\n"
     "Retarget a clip of source onto target's skeleton, as `animkit retarget` does: joints matched "
     "automatically (both fitted to the humanoid template, by name when neither is a humanoid; "
     "NotFoundError when only one is), or by a map file (map=PATH, 'TARGET = SOURCE' lines); baked at fps; foot contacts "
     "pinned unless feet=False; root motion scaled unless scaled=False. Returns the target with "
     "the one retargeted clip (save it with .save('out.glb'))."},
    {"builtin_names", (PyCFunction)mod_builtin_names, METH_NOARGS,
     "builtin_names() -> list[str]\n\nNames of the built-in models ('humanoid', 'cylinder')."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module_def = {
    PyModuleDef_HEAD_INIT, .m_name = "animkit._core",
    .m_doc = "animkit's C extension (use the package `animkit`).", .m_size = -1, .m_methods = module_methods,
};

static PyObject* new_error(PyObject* m, const char* name, PyObject* bases, const char* doc) {
    char full[64];
    snprintf(full, sizeof full, "animkit.%s", name);
    PyObject* e = PyErr_NewExceptionWithDoc(full, doc, bases, NULL);
    if (!e) return NULL;
    Py_INCREF(e);
    if (PyModule_AddObject(m, name, e) < 0) {
        Py_DECREF(e);
        Py_DECREF(e);
        return NULL;
    }
    return e;
}

static PyObject* sub_error(PyObject* m, const char* name, PyObject* also, const char* doc) {
    PyObject* bases = also ? PyTuple_Pack(2, Error, also) : PyTuple_Pack(1, Error);
    if (!bases) return NULL;
    PyObject* e = new_error(m, name, bases, doc);
    Py_DECREF(bases);
    return e;
}

PyMODINIT_FUNC PyInit__core(void) {
    import_array();
    if (PyType_Ready(&SceneType) < 0 || PyType_Ready(&PoseType) < 0 || PyType_Ready(&MeshType) < 0 ||
        PyType_Ready(&SimType) < 0)
        return NULL;
    PyObject* m = PyModule_Create(&module_def);
    if (!m) return NULL;
    if (!(Error = new_error(m, "Error", PyExc_Exception,
                            "An animkit failure. Attributes: message (the library's message), path (the file or "
                            "item it is about, or None) and code (the ak_result name, e.g. 'AK_ERR_PARSE').")) ||
        !(FileError = sub_error(m, "FileError", NULL, "A file could not be opened, read or written (AK_ERR_IO).")) ||
        !(ParseError = sub_error(m, "ParseError", NULL, "A file is malformed (AK_ERR_PARSE).")) ||
        !(DataError = sub_error(m, "DataError", NULL,
                                "Bad values: NaN or infinity, indices out of range, bad weights, hierarchy or keys.")) ||
        !(NotFoundError = sub_error(m, "NotFoundError", NULL, "A named item (joint, clip, mesh, built-in) is not there.")) ||
        !(UnsupportedError = sub_error(m, "UnsupportedError", NULL,
                                       "A feature animkit does not support, or a work or memory budget exceeded.")) ||
        !(ArgumentError = sub_error(m, "ArgumentError", PyExc_ValueError, "An argument outside its documented range.")) ||
        !(NoMemoryError = sub_error(m, "NoMemoryError", PyExc_MemoryError, "Out of memory.")))
        goto fail;
    Py_INCREF(&SceneType);
    Py_INCREF(&PoseType);
    Py_INCREF(&MeshType);
    Py_INCREF(&SimType);
    if (PyModule_AddObject(m, "Scene", (PyObject*)&SceneType) < 0 || PyModule_AddObject(m, "Pose", (PyObject*)&PoseType) < 0 ||
        PyModule_AddObject(m, "Mesh", (PyObject*)&MeshType) < 0 || PyModule_AddObject(m, "Sim", (PyObject*)&SimType) < 0 ||
        PyModule_AddStringConstant(m, "__version__", ak_version_string()) < 0)
        goto fail;
    return m;
fail:
    Py_DECREF(m);
    return NULL;
}
