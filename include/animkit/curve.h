/* animkit curve: keyframe tracks and interpolation.
 * (Header being completed by the keyframe module; the interpolation enum below is a contract
 * shared with clip.h and io.h and must keep these values.) */
#ifndef ANIMKIT_CURVE_H
#define ANIMKIT_CURVE_H

#include "math.h"

#ifdef __cplusplus
extern "C" {
#endif

/* How values between keys are computed. */
typedef enum ak_interp {
    AK_INTERP_DEFAULT = 0,  /* -> LINEAR (SLERP for rotations) */
    AK_INTERP_STEP,         /* hold the previous key's value */
    AK_INTERP_LINEAR,       /* lerp; for rotation tracks SLERP (glTF LINEAR) */
    AK_INTERP_CUBICSPLINE,  /* glTF CUBICSPLINE: (in-tangent, value, out-tangent) per key,
                               tangents per second, scaled by the key interval */
    AK_INTERP_HERMITE,      /* explicit in/out tangents per key (per second) */
    AK_INTERP_CARDINAL,     /* cardinal spline, tension mu (1 -> Catmull-Rom), non-uniform times */
    AK_INTERP_BEZIER,       /* cubic Bezier: (value, out-control, in-control of next) */
    AK_INTERP_NATURAL,      /* natural C2 cubic spline (global tridiagonal solve) */
    AK_INTERP_LAGRANGE,     /* one polynomial through all keys (teaching; oscillates) */
    AK_INTERP_NLERP,        /* rotations: normalised lerp, shortest path */
    AK_INTERP_SQUAD,        /* rotations: C1 spherical cubic (SQUAD) */
    AK_INTERP_COUNT
} ak_interp;

#ifdef __cplusplus
}
#endif
#endif
