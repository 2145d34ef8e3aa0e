/* Time: wrapping, easing, user warps, and the arc-length table of a 3D path. */
#include <animkit/curve.h>

#include "curve/track.h"
#include "internal.h"

/* ---- private types ------------------------------------------------------------------- */

struct ak_arc_table {
    ak_allocator alloc;
    size_t cell_count;
    float length;
    float* t;     /* [cell_count + 1] path time at each node */
    float* s;     /* [cell_count + 1] distance at each node */
    float* v0;    /* [cell_count] speed at the cell's start, from inside the cell */
    float* v1;    /* [cell_count] speed at the cell's end, from inside the cell */
};

/* ---- static helpers ------------------------------------------------------------------ */

static double speed_at(const ak_track* path, size_t seg, double t) {
    float v[3];
    akp_track_velocity(path, seg, (float)t, v);
    return sqrt((double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2]);
}

/* Cubic Hermite on [0, 1] from values y0, y1 and end slopes m0, m1 (already scaled). */
static double hermite1(double u, double y0, double y1, double m0, double m1) {
    double u2 = u * u, u3 = u2 * u;
    return (2 * u3 - 3 * u2 + 1) * y0 + (u3 - 2 * u2 + u) * m0 + (-2 * u3 + 3 * u2) * y1 + (u3 - u2) * m1;
}

/* Index i with a[i] <= x < a[i+1] over [0, count - 1] nodes (clamped). */
static size_t node_search(const float* a, size_t count, float x) {
    size_t lo = 0, hi = count - 2;
    while (lo < hi) {
        size_t mid = lo + (hi - lo + 1) / 2;
        if (a[mid] <= x) lo = mid;
        else hi = mid - 1;
    }
    return lo;
}

static double ease_d(ak_ease_kind kind, double u) {
    const double pi = 3.14159265358979323846;
    switch (kind) {
    case AK_EASE_LINEAR: return u;
    case AK_EASE_SMOOTHSTEP: return u * u * (3.0 - 2.0 * u);
    case AK_EASE_SMOOTHERSTEP: return u * u * u * (u * (6.0 * u - 15.0) + 10.0);
    case AK_EASE_SINE_IN: return 1.0 - cos(0.5 * pi * u);
    case AK_EASE_SINE_OUT: return sin(0.5 * pi * u);
    case AK_EASE_SINE_IN_OUT: return 0.5 * (1.0 - cos(pi * u));
    case AK_EASE_QUAD_IN: return u * u;
    case AK_EASE_QUAD_OUT: return 1.0 - (1.0 - u) * (1.0 - u);
    case AK_EASE_QUAD_IN_OUT: return u < 0.5 ? 2.0 * u * u : 1.0 - 2.0 * (1.0 - u) * (1.0 - u);
    case AK_EASE_CUBIC_IN: return u * u * u;
    case AK_EASE_CUBIC_OUT: return 1.0 - pow(1.0 - u, 3.0);
    case AK_EASE_CUBIC_IN_OUT: return u < 0.5 ? 4.0 * u * u * u : 1.0 - 4.0 * pow(1.0 - u, 3.0);
    case AK_EASE_QUART_IN: return pow(u, 4.0);
    case AK_EASE_QUART_OUT: return 1.0 - pow(1.0 - u, 4.0);
    case AK_EASE_QUART_IN_OUT: return u < 0.5 ? 8.0 * pow(u, 4.0) : 1.0 - 8.0 * pow(1.0 - u, 4.0);
    case AK_EASE_EXPO_IN: return (pow(2.0, 10.0 * u) - 1.0) / 1023.0;
    case AK_EASE_EXPO_OUT: return 1.0 - (pow(2.0, 10.0 * (1.0 - u)) - 1.0) / 1023.0;
    case AK_EASE_COUNT: break;
    }
    return u;
}

static double ease_deriv_d(ak_ease_kind kind, double u) {
    const double pi = 3.14159265358979323846, ln2 = 0.69314718055994530942;
    switch (kind) {
    case AK_EASE_LINEAR: return 1.0;
    case AK_EASE_SMOOTHSTEP: return 6.0 * u * (1.0 - u);
    case AK_EASE_SMOOTHERSTEP: return 30.0 * u * u * (u - 1.0) * (u - 1.0);
    case AK_EASE_SINE_IN: return 0.5 * pi * sin(0.5 * pi * u);
    case AK_EASE_SINE_OUT: return 0.5 * pi * cos(0.5 * pi * u);
    case AK_EASE_SINE_IN_OUT: return 0.5 * pi * sin(pi * u);
    case AK_EASE_QUAD_IN: return 2.0 * u;
    case AK_EASE_QUAD_OUT: return 2.0 * (1.0 - u);
    case AK_EASE_QUAD_IN_OUT: return u < 0.5 ? 4.0 * u : 4.0 * (1.0 - u);
    case AK_EASE_CUBIC_IN: return 3.0 * u * u;
    case AK_EASE_CUBIC_OUT: return 3.0 * (1.0 - u) * (1.0 - u);
    case AK_EASE_CUBIC_IN_OUT: return u < 0.5 ? 12.0 * u * u : 12.0 * (1.0 - u) * (1.0 - u);
    case AK_EASE_QUART_IN: return 4.0 * u * u * u;
    case AK_EASE_QUART_OUT: return 4.0 * pow(1.0 - u, 3.0);
    case AK_EASE_QUART_IN_OUT: return u < 0.5 ? 32.0 * u * u * u : 32.0 * pow(1.0 - u, 3.0);
    case AK_EASE_EXPO_IN: return 10.0 * ln2 * pow(2.0, 10.0 * u) / 1023.0;
    case AK_EASE_EXPO_OUT: return 10.0 * ln2 * pow(2.0, 10.0 * (1.0 - u)) / 1023.0;
    case AK_EASE_COUNT: break;
    }
    return 1.0;
}

static double clamp01(float u) { return u > 0.0f ? (u < 1.0f ? (double)u : 1.0) : 0.0; }

/* ---- time --------------------------------------------------------------------------- */

float ak_time_wrap(float t, float duration, ak_wrap_mode mode) {
    if (!(duration > 0.0f) || !ak_finitef(duration) || t != t) return 0.0f;
    if (mode == AK_WRAP_DEFAULT || (unsigned)mode >= (unsigned)AK_WRAP_COUNT) mode = AK_WRAP_CLAMP;
    if (mode == AK_WRAP_CLAMP) return t < 0.0f ? 0.0f : (t > duration ? duration : t);
    if (!ak_finitef(t)) return 0.0f;
    if (mode == AK_WRAP_LOOP) {
        float r = fmodf(t, duration);
        if (r < 0.0f) r += duration;
        return r >= duration ? 0.0f : r;
    }
    float period = 2.0f * duration;
    float r = fmodf(t, period);
    if (r < 0.0f) r += period;
    if (r >= period) r = 0.0f;
    return r <= duration ? r : period - r;
}

float ak_ease(ak_ease_kind kind, float u) { return (float)ease_d(kind, clamp01(u)); }

float ak_ease_derivative(ak_ease_kind kind, float u) { return (float)ease_deriv_d(kind, clamp01(u)); }

float ak_ease_time(ak_ease_kind kind, float t, float duration) {
    if (!(duration > 0.0f) || !ak_finitef(duration)) return t;
    return (float)((double)duration * ease_d(kind, clamp01(t / duration)));
}

float ak_time_warp(const ak_track* warp, float t) {
    if (!warp || warp->component_count != 1 || warp->is_rotation) return t;
    float v;
    akp_track_eval(warp, akp_track_find(warp, t), t, &v);
    return v;
}

bool ak_track_is_monotonic(const ak_track* tr) {
    if (!tr || tr->component_count != 1 || tr->is_rotation) return false;
    size_t n = tr->key_count;
    float prev = 0.0f;
    bool first = true;
    for (size_t k = 0; k + 1 < n || (k == 0 && n == 1); ++k) {
        int steps = n == 1 ? 1 : 16;
        for (int j = 0; j <= steps; ++j) {
            float t = n == 1 ? tr->times[0]
                             : tr->times[k] + (tr->times[k + 1] - tr->times[k]) * ((float)j / (float)steps);
            float v;
            akp_track_eval(tr, k, t, &v);
            if (!first && v < prev) return false;
            prev = v;
            first = false;
        }
        if (n == 1) break;
    }
    return true;
}

/* ---- arc length --------------------------------------------------------------------- */

ak_arc_table_desc ak_arc_table_desc_resolved(const ak_arc_table_desc* desc) {
    ak_arc_table_desc d;
    memset(&d, 0, sizeof d);
    if (desc) d = *desc;
    if (d.cell_count == 0) d.cell_count = 256u;
    return d;
}

ak_result ak_arc_table_create(const ak_arc_table_desc* desc, const ak_allocator* alloc, ak_arc_table** out) {
    if (out) *out = NULL;
    if (!desc || !desc->path || !out) return AK_ERR_NULL_ARG;
    const ak_track* path = desc->path;
    if (path->component_count != 3 || path->is_rotation) return AK_ERR_BAD_ARG;
    if (desc->cell_count > ((size_t)1 << 20)) return AK_ERR_BAD_ARG;
    size_t want = ak_arc_table_desc_resolved(desc).cell_count;
    size_t n = path->key_count, segs = n > 1 ? n - 1 : 1;
    double total_time = n > 1 ? (double)path->times[n - 1] - (double)path->times[0] : 0.0;
    /* Cells per segment proportional to its duration, at least one. */
    size_t cells = 0;
    for (size_t k = 0; k < segs; ++k) {
        double share = n > 1 ? ((double)path->times[k + 1] - (double)path->times[k]) / total_time : 1.0;
        size_t c = (size_t)ceil(share * (double)want - 1e-9);
        cells += c < 1 ? 1 : c;
    }
    size_t head = akp_align16(sizeof(ak_arc_table));
    size_t nodes = akp_align16((cells + 1) * sizeof(float));
    char* mem = (char*)akp_calloc(alloc, head + 4 * nodes);
    if (!mem) return AK_ERR_NO_MEMORY;
    ak_arc_table* tab = (ak_arc_table*)mem;
    if (alloc) tab->alloc = *alloc;
    tab->cell_count = cells;
    tab->t = (float*)(mem + head);
    tab->s = (float*)(mem + head + nodes);
    tab->v0 = (float*)(mem + head + 2 * nodes);
    tab->v1 = (float*)(mem + head + 3 * nodes);
    /* 5-point Gauss-Legendre on [-1, 1]. */
    static const double gx[5] = {0.0, -0.5384693101056831, 0.5384693101056831, -0.9061798459386640,
                                 0.9061798459386640};
    static const double gw[5] = {0.5688888888888889, 0.4786286704993665, 0.4786286704993665, 0.2369268850561891,
                                 0.2369268850561891};
    size_t cell = 0;
    double s = 0.0;
    tab->t[0] = path->times[0];
    tab->s[0] = 0.0f;
    for (size_t k = 0; k < segs; ++k) {
        double t0 = path->times[k], t1 = n > 1 ? path->times[k + 1] : t0;
        double share = n > 1 ? (t1 - t0) / total_time : 1.0;
        size_t c = (size_t)ceil(share * (double)want - 1e-9);
        if (c < 1) c = 1;
        for (size_t j = 0; j < c; ++j, ++cell) {
            double a = t0 + (t1 - t0) * (double)j / (double)c;
            double b = j + 1 == c ? t1 : t0 + (t1 - t0) * (double)(j + 1) / (double)c;
            double half = 0.5 * (b - a), mid = 0.5 * (a + b), len = 0.0;
            for (int g = 0; g < 5; ++g) len += gw[g] * speed_at(path, k, mid + half * gx[g]);
            s += len * half;
            tab->t[cell + 1] = (float)b;
            tab->s[cell + 1] = (float)s;
            tab->v0[cell] = (float)speed_at(path, k, a);
            tab->v1[cell] = (float)speed_at(path, k, b);
        }
    }
    tab->length = (float)s;
    *out = tab;
    return AK_OK;
}

void ak_arc_table_destroy(ak_arc_table* table) {
    if (!table) return;
    ak_allocator a = table->alloc;
    akp_free(&a, table);
}

float ak_arc_table_length(const ak_arc_table* table) { return table ? table->length : 0.0f; }

float ak_arc_table_time_at(const ak_arc_table* tab, float distance) {
    if (!tab) return 0.0f;
    if (!(distance > 0.0f) || !(tab->length > 0.0f)) return tab->t[0];
    if (distance >= tab->length) return tab->t[tab->cell_count];
    size_t i = node_search(tab->s, tab->cell_count + 1, distance);
    double s0 = tab->s[i], s1 = tab->s[i + 1], t0 = tab->t[i], t1 = tab->t[i + 1];
    double ls = s1 - s0, lt = t1 - t0;
    if (!(ls > 0.0)) return (float)t0;
    double u = ((double)distance - s0) / ls;
    u = u < 0.0 ? 0.0 : (u > 1.0 ? 1.0 : u);
    /* dt/ds = 1/speed at the ends, scaled to the cell: m = ls / (v lt) relative to the chord.
     * Cells where that leaves the monotone range (slow spots) fall back to the chord. */
    double r0 = tab->v0[i] > 0.0f ? ls / ((double)tab->v0[i] * lt) : 1e30;
    double r1 = tab->v1[i] > 0.0f ? ls / ((double)tab->v1[i] * lt) : 1e30;
    double t;
    if (r0 > 3.0 || r1 > 3.0) t = t0 + lt * u;
    else t = t0 + lt * hermite1(u, 0.0, 1.0, r0, r1);
    if (t < t0) t = t0;
    if (t > t1) t = t1;
    return (float)t;
}

float ak_arc_table_distance_at(const ak_arc_table* tab, float time) {
    if (!tab) return 0.0f;
    if (!(time > tab->t[0])) return 0.0f;
    if (time >= tab->t[tab->cell_count]) return tab->length;
    size_t i = node_search(tab->t, tab->cell_count + 1, time);
    double s0 = tab->s[i], s1 = tab->s[i + 1], t0 = tab->t[i], t1 = tab->t[i + 1];
    double lt = t1 - t0, ls = s1 - s0;
    if (!(lt > 0.0) || !(ls > 0.0)) return (float)s0;
    double u = ((double)time - t0) / lt;
    double s = s0 + ls * hermite1(u, 0.0, 1.0, (double)tab->v0[i] * lt / ls, (double)tab->v1[i] * lt / ls);
    if (s < s0) s = s0;
    if (s > s1) s = s1;
    return (float)s;
}
