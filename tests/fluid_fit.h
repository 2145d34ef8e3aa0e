/* Shared by the fluid tests: the hydrostatic pressure gradient of a settled column, fitted in
 * double precision. Header-only (static), so each test binary keeps its own copy. */
#ifndef AK_TESTS_FLUID_FIT_H
#define AK_TESTS_FLUID_FIT_H

#include <stdbool.h>
#include <stddef.h>

#include <animkit/math.h>

/* -dp/dy by least squares over the particles from y_lo up to the free surface less h (the top
 * particle's height minus h): the layers near the floor and the surface, where the kernel is
 * cut off, are left out. False (and *slope untouched) with 10 or fewer particles in the band. */
static inline bool fluid_pressure_slope(const ak_vec3* pos, const float* pres, size_t n, double y_lo,
                                        double h, double* slope) {
    float top = 0.0f;
    for (size_t i = 0; i < n; ++i) top = pos[i].y > top ? pos[i].y : top;
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int cnt = 0;
    for (size_t i = 0; i < n; ++i) {
        const double y = pos[i].y;
        if (y < y_lo || y > top - h) continue;
        sx += y, sy += pres[i], sxx += y * y, sxy += y * pres[i], ++cnt;
    }
    if (cnt <= 10) return false;
    *slope = -(cnt * sxy - sx * sy) / (cnt * sxx - sx * sx);
    return true;
}

#endif
