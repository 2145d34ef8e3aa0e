/* animkit: character animation and deformation in C11. Umbrella header: includes every module.
 *
 * Configuration macros (define before including, or on the compiler command line):
 *   AK_NO_SIMD   build the library with its scalar reference paths only (set by the AK_NO_SIMD
 *                CMake option; headers are unaffected)
 *   AK_SHARED    (Windows) link against the DLL
 * Conventions: docs/conventions.md (right-handed, Y up, radians, seconds, column vectors,
 * column-major matrices, quaternions stored x,y,z,w, ak_quat_mul(a, b) applies b first). */
#ifndef ANIMKIT_H
#define ANIMKIT_H

#include "core.h"
#include "math.h"
#include "curve.h"
#include "clip.h"
#include "skeleton.h"
#include "mesh.h"
#include "scene.h"
#include "skin.h"
#include "softskin.h"
#include "ik.h"
#include "blendshape.h"
#include "deform.h"
#include "builtin.h"
#include "io.h"
#include "raster.h"
#include "view.h"
#include "noise.h"
#include "terrain.h"
#include "grid.h"
#include "particles.h"
#include "boids.h"
#include "cloth.h"
#include "retarget.h"
#include "fluid.h"
#include "crowd.h"
#include "rigid.h"
#include "batch.h"

#endif
