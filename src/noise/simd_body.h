/* The SIMD fractal kernels' body, written once over a small vector vocabulary and included by
 * batch_avx2.c (8 lanes) and batch_avx512.c (16 lanes), which define before including it:
 *   KI                 the function attribute (target + always_inline)
 *   AKP_W              lanes per vector; VF, VI, VM: float, int32 and mask vector types
 *   KERNEL_ENTRY       the name of the entry point (akp_noise_fractal_avx2 / ..._avx512)
 *   KERNEL_RUN         the target attribute of the non-inline per-dimension runners
 * and the static inline helpers used below (vf_add, vf_sel, m_lt, gather4, vf_lut16, ...).
 *
 * Each basis repeats its scalar reference operation for operation: Perlin (perlin.c lattice),
 * simplex (bases.c, Gustavson's formulation), value and Worley noise (bases.c) and the octave
 * loop (fractal.c): the same floor,
 * hash chain, the same evaluation order, no FMA, min/max where the scalar code has
 * fminf/fmaxf (equal for non-NaN values, and NaN never reaches them: out-of-range points are
 * masked to 0 first). So the results equal the scalar ones bit for bit; test_noise checks it
 * on every path the CPU has.
 *
 * Permutation lookups go through tab_pair(T, i), which gives perm[i] in the low byte and
 * perm[i + 1] (the upper corner's hash) in the next one, for 0 <= i <= 511 (the table is
 * doubled, so that is a function of i & 255): AVX2 gathers 32 bits at perm + i (or loads them
 * one lane at a time), AVX-512 looks i & 255 up in a 256-entry table held in registers
 * (PermTab, made once per call by tab_make). With VBMI, batch_avx512.c brings its own
 * cell_hashes (AKP_HAVE_CELL_HASHES): byte lookups, four corner hashes of a lane at once.
 * Never installed. */

/* Small fixed loops (dimensions, corners) are unrolled so that per-corner vectors stay in
 * registers. */
#define AKP_PRAGMA(x) _Pragma(#x)
#define AKP_UNROLL AKP_PRAGMA(GCC unroll 8)

/* ---- Perlin -------------------------------------------------------------------------------- */

/* Corner value (and gradient vector) for hash h and offsets d (dims 2 or 3). */
KI static inline VF corner_perlin(int dims, VI h, const VF* d, VF* g, bool want_grad) {
    const VF one = vf_set1(1.0f);
    const VF su = vf_cast(VI_SLLI(h, 31)); /* bit 0 of h as the sign */
    const VF sv = vf_cast(VI_SLLI(vi_and(h, vi_set1(2)), 30));
    if (dims == 2) {
        h = vi_and(h, vi_set1(7));
        const VM low = mi_lt(h, 4);
        const VM bit2 = mi_eq(vi_and(h, vi_set1(2)), 2);
        const VM u_is_y = m_andn(low, bit2);
        const VF u = vf_sel(u_is_y, d[1], d[0]);
        const VF v = vf_maskz(low, d[1]);
        if (want_grad) {
            const VF pu = vf_xor(one, su), pv = vf_xor(one, sv);
            g[0] = vf_maskz(m_not(u_is_y), pu);
            g[1] = vf_sel(low, pv, vf_maskz(u_is_y, pu));
        }
        return vf_add(vf_xor(u, su), vf_xor(v, sv));
    }
    /* over h & 15: u_is_x h < 8, v_is_y h < 4, v_is_x h in {12, 14} (h & 13 == 12), as bit tests */
    const VM u_is_x = mi_none(h, 8), v_is_y = mi_none(h, 12);
    const VM v_is_x = mi_eq(vi_and(h, vi_set1(13)), 12);
    const VF u = vf_sel(u_is_x, d[0], d[1]);
    const VF v = vf_sel(v_is_y, d[1], vf_sel(v_is_x, d[0], d[2]));
    if (want_grad) {
        const VF pu = vf_xor(one, su), pv = vf_xor(one, sv);
        const VM v_is_z = m_not(m_or(v_is_y, v_is_x));
        g[0] = vf_add(vf_maskz(u_is_x, pu), vf_maskz(v_is_x, pv));
        g[1] = vf_add(vf_maskz(m_not(u_is_x), pu), vf_maskz(v_is_y, pv));
        g[2] = vf_maskz(v_is_z, pv);
    }
    return vf_add(vf_xor(u, su), vf_xor(v, sv));
}

/* The hashes of the 2^dims lattice cell corners, corner c = sum_k bit_k(c) << k, by Perlin's
 * chain with the upper corner at index + 1 unwrapped (p[A + 1] in his code: the doubled table
 * makes it equal to the wrapped index): one 32-bit gather at perm + i reads perm[i] and
 * perm[i + 1] together, so 3D takes 1 + 2 + 4 gathers instead of 14. */
#if !defined(AKP_HAVE_CELL_HASHES) /* the vocabulary may bring its own (batch_avx512.c with VBMI) */
KI static inline void cell_hashes(const PermTab* perm, int dims, const VI* lo, VI* hash) {
    const VI m8 = vi_set1(255);
    {
        const VI g = tab_pair(perm, lo[0]);
        hash[0] = vi_and(g, m8);
        hash[1] = vi_and(VI_SRLI(g, 8), m8);
    }
    AKP_UNROLL
    for (int k = 1; k < dims; ++k) {
        const int half = 1 << k;
        AKP_UNROLL
        for (int c = 0; c < half; ++c) {
            const VI g = tab_pair(perm, vi_add(hash[c], lo[k]));
            hash[c] = vi_and(g, m8);
            hash[c + half] = vi_and(VI_SRLI(g, 8), m8);
        }
    }
}
#endif

KI static inline VM in_range(int dims, const VF* p) {
    const VF limit = vf_set1(AKP_NOISE_LIMIT);
    VM valid = m_lt(vf_abs(p[0]), limit);
    AKP_UNROLL
    for (int k = 1; k < dims; ++k) valid = m_and(valid, m_lt(vf_abs(p[k]), limit));
    return valid;
}

KI static inline VF fade_v(VF t) {
    const VF t3 = vf_mul(vf_mul(t, t), t);
    const VF in = vf_add(vf_mul(t, vf_sub(vf_mul(t, vf_set1(6.0f)), vf_set1(15.0f))), vf_set1(10.0f));
    return vf_mul(t3, in);
}

KI static inline VF dfade_v(VF t) {
    const VF a = vf_mul(vf_mul(vf_set1(30.0f), t), t);
    const VF b = vf_add(vf_mul(t, vf_sub(t, vf_set1(2.0f))), vf_set1(1.0f));
    return vf_mul(a, b);
}

KI static inline VF lerp_v(VF t, VF a, VF b) { return vf_add(a, vf_mul(t, vf_sub(b, a))); }

/* Perlin noise at W points p[0..dims-1]; value returned, gradient into grad when want_grad. */
/* The lattice cell of p: the fractional coordinates f and the 2^dims corner hashes (Perlin's
 * and value noise's permutation chain, the integer coordinates wrapped to 0..255). */
KI static inline void lattice_cell(const PermTab* perm, int dims, const VF* p, VF* f, VI* hash) {
    VI lo[3];
    AKP_UNROLL
    for (int k = 0; k < dims; ++k) {
        const VF fl = vf_floor(p[k]);
        f[k] = vf_sub(p[k], fl);
        lo[k] = vi_and(vf_cvtt(fl), vi_set1(255));
    }
    cell_hashes(perm, dims, lo, hash);
}

/* Blends the 2^dims corner values (and gradients) of a cell along each axis in turn with the
 * quintic fade of the fractional coordinates f: val[0] (gv[0]) ends as the cell's value
 * (gradient). Shared by Perlin and value noise; the operation order is the scalar reference's. */
KI static inline void lerp_corners(int dims, const VF* f, VF* val, VF (*gv)[3], bool want_grad) {
    const int corners = 1 << dims;
    AKP_UNROLL
    for (int k = 0; k < dims; ++k) {
        const VF t = fade_v(f[k]);
        const VF dt = want_grad ? dfade_v(f[k]) : vf_zero();
        const int step = 1 << k;
        AKP_UNROLL
        for (int c = 0; c < corners; c += 2 * step) {
            const VF a = val[c], b = val[c + step];
            val[c] = lerp_v(t, a, b);
            if (want_grad) {
                AKP_UNROLL
                for (int m = 0; m < dims; ++m) gv[c][m] = lerp_v(t, gv[c][m], gv[c + step][m]);
                gv[c][k] = vf_add(gv[c][k], vf_mul(vf_sub(b, a), dt));
            }
        }
    }
}

KI static inline VF perlin_v(const PermTab* perm, int dims, const VF* p, VF* grad, bool want_grad) {
    const VM valid = in_range(dims, p);
    VF f[3];
    VI hash[8];
    lattice_cell(perm, dims, p, f, hash);
    const int corners = 1 << dims;
    VF val[8], gv[8][3];
    AKP_UNROLL
    for (int c = 0; c < corners; ++c) {
        VF d[3];
        AKP_UNROLL
        for (int k = 0; k < dims; ++k) d[k] = ((c >> k) & 1) ? vf_sub(f[k], vf_set1(1.0f)) : f[k];
        val[c] = corner_perlin(dims, hash[c], d, gv[c], want_grad);
    }
    lerp_corners(dims, f, val, gv, want_grad);
    if (want_grad)
        AKP_UNROLL
        for (int m = 0; m < dims; ++m) grad[m] = vf_maskz(valid, gv[0][m]);
    return vf_maskz(valid, val[0]);
}

/* ---- simplex ------------------------------------------------------------------------------- */

/* The gradient tables of bases.c as 16-entry lanes (2D: entry i = simplex_g2[i & 7]). */
static const float simplex_g2x[16] = {1, -1, 1, -1, 1, -1, 0, 0, 1, -1, 1, -1, 1, -1, 0, 0};
static const float simplex_g2y[16] = {1, 1, -1, -1, 0, 0, 1, -1, 1, 1, -1, -1, 0, 0, 1, -1};
static const float simplex_g3x[16] = {1, -1, 1, -1, 1, -1, 1, -1, 0, 0, 0, 0, 1, 0, -1, 0};
static const float simplex_g3y[16] = {1, 1, -1, -1, 0, 0, 0, 0, 1, -1, 1, -1, 1, -1, 1, -1};
static const float simplex_g3z[16] = {0, 0, 0, 0, 1, 1, -1, -1, 1, 1, -1, -1, 0, 1, 0, -1};

/* One corner (bases.c simplex_corner with r0 = 0.5): (0.5 - |d|^2)^4 (g . d), its gradient
 * added to G where the kernel is positive. */
KI static inline VF corner_simplex(int dims, const VF* d, const VF* g, VF* G, bool want_grad) {
    const VF zero = vf_zero();
    VF r2 = zero, gd = zero;
    AKP_UNROLL
    for (int k = 0; k < dims; ++k) {
        r2 = vf_add(r2, vf_mul(d[k], d[k]));
        gd = vf_add(gd, vf_mul(g[k], d[k]));
    }
    const VF t = vf_sub(vf_set1(0.5f), r2);
    const VM pos = m_gt(t, zero);
    const VF t2 = vf_mul(t, t), t4 = vf_mul(t2, t2);
    if (want_grad) {
        const VF c = vf_mul(vf_mul(vf_mul(vf_set1(8.0f), t2), t), gd);
        AKP_UNROLL
        for (int k = 0; k < dims; ++k)
            G[k] = vf_sel(pos, vf_add(G[k], vf_sub(vf_mul(t4, g[k]), vf_mul(c, d[k]))), G[k]);
    }
    return vf_maskz(pos, vf_mul(t4, gd));
}

KI static inline VF simplex2_v(const PermTab* perm, const VF* p, VF* grad, bool want_grad) {
    const VM valid = in_range(2, p);
    const float F2 = 0.36602540378f, G2 = 0.2113248654f; /* as bases.c */
    const VF x = p[0], y = p[1];
    const VF s = vf_mul(vf_add(x, y), vf_set1(F2));
    const VF fi = vf_floor(vf_add(x, s)), fj = vf_floor(vf_add(y, s));
    const VF t = vf_mul(vf_add(fi, fj), vf_set1(G2));
    const VF x0 = vf_sub(x, vf_sub(fi, t)), y0 = vf_sub(y, vf_sub(fj, t));
    const VM i1 = m_gt(x0, y0);
    const VI lo[2] = {vi_and(vf_cvtt(fi), vi_set1(255)), vi_and(vf_cvtt(fj), vi_set1(255))};
    VI cube[4];
    cell_hashes(perm, 2, lo, cube);
    const VI h[3] = {cube[0], vi_sel(i1, cube[1], cube[2]), cube[3]};
    const VF one = vf_set1(1.0f), vg2 = vf_set1(G2), c2 = vf_set1(2.0f * G2);
    const VF i1f = vf_maskz(i1, one), j1f = vf_maskz(m_not(i1), one);
    const VF d[3][2] = {{x0, y0},
                        {vf_add(vf_sub(x0, i1f), vg2), vf_add(vf_sub(y0, j1f), vg2)},
                        {vf_add(vf_sub(x0, one), c2), vf_add(vf_sub(y0, one), c2)}};
    VF sum = vf_zero(), G[2] = {vf_zero(), vf_zero()};
    AKP_UNROLL
    for (int c = 0; c < 3; ++c) {
        /* vf_lut16 reads bits 0..3 of the index; entries 8..15 repeat 0..7: h & 7 needs no mask */
        const VF g[2] = {vf_lut16(simplex_g2x, h[c]), vf_lut16(simplex_g2y, h[c])};
        sum = vf_add(sum, corner_simplex(2, d[c], g, G, want_grad));
    }
    const VF scale = vf_set1(70.0f);
    if (want_grad)
        AKP_UNROLL
        for (int k = 0; k < 2; ++k) grad[k] = vf_maskz(valid, vf_mul(scale, G[k]));
    return vf_maskz(valid, vf_mul(scale, sum));
}

KI static inline VF simplex3_v(const PermTab* perm, const VF* p, VF* grad, bool want_grad) {
    const VM valid = in_range(3, p);
    const float F3 = 1.0f / 3.0f, G3 = 1.0f / 6.0f; /* as bases.c */
    const VF x = p[0], y = p[1], z = p[2];
    const VF s = vf_mul(vf_add(vf_add(x, y), z), vf_set1(F3));
    const VF fi = vf_floor(vf_add(x, s)), fj = vf_floor(vf_add(y, s)), fk = vf_floor(vf_add(z, s));
    const VF t = vf_mul(vf_add(vf_add(fi, fj), fk), vf_set1(G3));
    const VF x0 = vf_sub(x, vf_sub(fi, t)), y0 = vf_sub(y, vf_sub(fj, t)), z0 = vf_sub(z, vf_sub(fk, t));
    /* bases.c's branches on the order of x0, y0, z0 as lane masks: the second corner is the
     * axis o1, the third the pair o2 (x0 >= y0 is !(x0 < y0): no NaN reaches a valid lane) */
    const VM xy = m_ge(x0, y0), yz = m_ge(y0, z0), xz = m_ge(x0, z0);
    const VM o1x = m_and(xy, m_or(yz, xz)), o1y = m_andn(xy, yz), o1z = m_not(m_or(o1x, o1y));
    const VM o2x = m_or(xy, m_and(yz, xz)), o2y = m_or(yz, m_not(xy)), o2z = m_not(m_and(o2x, o2y));
    const VI lo[3] = {vi_and(vf_cvtt(fi), vi_set1(255)), vi_and(vf_cvtt(fj), vi_set1(255)),
                      vi_and(vf_cvtt(fk), vi_set1(255))};
    /* perm[perm[perm[i + a] + j + b] + k + c] is the cube corner hash a + 2b + 4c */
    VI cube[8];
    cell_hashes(perm, 3, lo, cube);
    const VI h[4] = {cube[0], vi_sel(o1x, cube[1], vi_sel(o1y, cube[2], cube[4])),
                     vi_sel(o2z, vi_sel(o2x, cube[5], cube[6]), cube[3]), cube[7]};
    const VF one = vf_set1(1.0f), zero = vf_zero();
    const VF off[4][3] = {{zero, zero, zero},
                          {vf_maskz(o1x, one), vf_maskz(o1y, one), vf_maskz(o1z, one)},
                          {vf_maskz(o2x, one), vf_maskz(o2y, one), vf_maskz(o2z, one)},
                          {one, one, one}};
    VF sum = zero, G[3] = {zero, zero, zero};
    AKP_UNROLL
    for (int c = 0; c < 4; ++c) {
        const VF k = vf_set1((float)c * G3);
        const VF d[3] = {vf_add(vf_sub(x0, off[c][0]), k), vf_add(vf_sub(y0, off[c][1]), k),
                         vf_add(vf_sub(z0, off[c][2]), k)};
        const VF g[3] = {vf_lut16(simplex_g3x, h[c]), vf_lut16(simplex_g3y, h[c]), vf_lut16(simplex_g3z, h[c])};
        sum = vf_add(sum, corner_simplex(3, d, g, G, want_grad));
    }
    const VF scale = vf_set1(76.0f);
    if (want_grad)
        AKP_UNROLL
        for (int k = 0; k < 3; ++k) grad[k] = vf_maskz(valid, vf_mul(scale, G[k]));
    return vf_maskz(valid, vf_mul(scale, sum));
}

/* ---- value noise --------------------------------------------------------------------------- */

/* bases.c ak_noise_value in 2D/3D: the corner hashes of Perlin's chain (bases.c walks
 * perm[h + ((i + 1) & 255)], which the doubled table makes perm[h + lo + 1]), corner values
 * hash / 127.5 - 1 (correctly rounded, as the scalar code's: a multiplication by 1 / 127.5 differs
 * in 111 of the 256 values; a Newton step after it does not), blended with the quintic fade, the gradient riding along. */
KI static inline VF value_v(const PermTab* perm, int dims, const VF* p, VF* grad, bool want_grad) {
    const VM valid = in_range(dims, p);
    VF f[3];
    VI hash[8];
    lattice_cell(perm, dims, p, f, hash);
    const int corners = 1 << dims;
    VF val[8], gv[8][3];
    const VF one = vf_set1(1.0f), den = vf_set1(127.5f), rcp = vf_set1(1.0f / 127.5f);
    AKP_UNROLL
    for (int c = 0; c < corners; ++c) {
        /* the correctly rounded hash / 127.5 without a division: q = h r, one Newton step
         * q + (h - q 127.5) r with fused operations; equal to the quotient for every h in
         * 0..255 (checked exhaustively offline, and by test_noise against the scalar code) */
        const VF h = vf_cvt(hash[c]);
        const VF q = vf_mul(h, rcp);
        val[c] = vf_sub(vf_fmadd(vf_fnmadd(q, den, h), rcp, q), one);
        if (want_grad)
            AKP_UNROLL
            for (int m = 0; m < dims; ++m) gv[c][m] = vf_zero();
    }
    lerp_corners(dims, f, val, gv, want_grad);
    if (want_grad)
        AKP_UNROLL
        for (int m = 0; m < dims; ++m) grad[m] = vf_maskz(valid, gv[0][m]);
    return vf_maskz(valid, vf_min(vf_max(val[0], vf_set1(-1.0f)), one));
}

/* ---- Worley -------------------------------------------------------------------------------- */

/* bases.c ak_noise_worley's F1 in 2D/3D. The scalar code searches ring 0 (the point's cell),
 * then ring 1 (the 3^dims - 1 neighbours in the order c = 0, 1, ... with x fastest), and
 * further rings while they may hold a closer point. Here every lane visits ring 0 and ring 1
 * in that order with the same strict "closer than" test, so it keeps the same nearest point
 * (ties included): the cells the scalar search skipped cannot beat F1 (their points are at
 * least margin + 1/2048 farther than the ring bound). Lanes whose F1 could still lose to a
 * ring-2 point ((1 + margin)^2 < F1^2: rare, the point far from every neighbour's feature
 * point) are recomputed with the scalar function itself. */
static const uint32_t worley_mul[3] = {0x8DA6B343u, 0xD8163841u, 0xCB1AB31Fu};

KI static inline VF worley_v(const ak_noise* noise, int dims, const VF* p, VF* grad, bool want_grad) {
    const VM valid = in_range(dims, p);
    const uint32_t seed_mix = (uint32_t)noise->seed * 0x9E3779B1u ^ (uint32_t)(noise->seed >> 32);
    const VF one = vf_set1(1.0f);
    VF f[3], margin = one;
    VI axis[3][3]; /* (base_k + o - 1) * mul_k for o = 0, 1, 2 */
    AKP_UNROLL
    for (int k = 0; k < dims; ++k) {
        const VF fl = vf_floor(p[k]);
        const VI b = vf_cvtt(fl);
        f[k] = vf_sub(p[k], fl);
        margin = vf_min(margin, vf_min(f[k], vf_sub(one, f[k])));
        AKP_UNROLL
        for (int o = 0; o < 3; ++o) axis[k][o] = vi_mullo(vi_add(b, vi_set1(o - 1)), vi_set1((int)worley_mul[k]));
    }
    const int cells = dims == 2 ? 9 : 27, center = dims == 2 ? 4 : 13;
    VF d1 = vf_set1(INFINITY), near[3] = {vf_zero(), vf_zero(), vf_zero()};
    AKP_PRAGMA(GCC unroll 27)
    for (int step = 0; step < cells; ++step) {
        /* ring 0 first, then ring 1 in scalar order */
        const int c = step == 0 ? center : step <= center ? step - 1 : step;
        const int o[3] = {c % 3, c / 3 % 3, c / 9};
        VI h = vi_set1((int)seed_mix);
        AKP_UNROLL
        for (int k = 0; k < dims; ++k) h = vi_xor(h, axis[k][o[k]]);
        h = vi_xor(h, VI_SRLI(h, 16));
        h = vi_mullo(h, vi_set1((int)0x85EBCA6Bu));
        h = vi_xor(h, VI_SRLI(h, 13));
        h = vi_mullo(h, vi_set1((int)0xC2B2AE35u));
        h = vi_xor(h, VI_SRLI(h, 16));
        VF dv[3], dist2 = vf_zero();
        AKP_UNROLL
        for (int k = 0; k < dims; ++k) {
            /* bases.c: (o - 1) + ((h >> 10 k & 1023) / 1024 + 0.5 / 1024), every step exact: the
             * same number is (1 + (2 m + 1) / 2048) - (2 - o), the first term built from the bits
             * of m = h >> 10 k & 1023 as a float with exponent 0 (m into mantissa bits 13..22) */
            const VI m13 = k == 0 ? VI_SLLI(h, 13) : k == 1 ? VI_SLLI(h, 3) : VI_SRLI(h, 7);
            VF fp = vf_cast(vi_or(vi_and(m13, vi_set1(1023 << 13)), vi_set1(0x3F801000)));
            if (o[k] != 2) fp = vf_sub(fp, vf_set1((float)(2 - o[k])));
            dv[k] = vf_sub(f[k], fp);
            dist2 = k == 0 ? vf_mul(dv[0], dv[0]) : vf_add(dist2, vf_mul(dv[k], dv[k]));
        }
        const VM closer = m_lt(dist2, d1);
        d1 = vf_sel(closer, dist2, d1);
        if (want_grad)
            AKP_UNROLL
            for (int k = 0; k < dims; ++k) near[k] = vf_sel(closer, dv[k], near[k]);
    }
    const VF f1 = vf_sqrt(d1);
    VF v = vf_maskz(valid, f1);
    if (want_grad) {
        const VM pos = m_and(valid, m_gt(f1, vf_zero()));
        AKP_UNROLL
        for (int k = 0; k < dims; ++k) grad[k] = vf_maskz(pos, vf_div(near[k], f1));
    }
    const VF bound = vf_add(one, margin);
    const unsigned far = m_bits(m_and(valid, m_lt(vf_mul(bound, bound), d1)));
    if (far) {
        float pv[3][AKP_W], gv[3][AKP_W], ov[AKP_W];
        vf_store(ov, v);
        AKP_UNROLL
        for (int k = 0; k < dims; ++k) {
            vf_store(pv[k], p[k]);
            if (want_grad) vf_store(gv[k], grad[k]);
        }
        for (int i = 0; i < AKP_W; ++i) {
            if (!(far >> i & 1u)) continue;
            float q[3], g[3];
            for (int k = 0; k < dims; ++k) q[k] = pv[k][i];
            ov[i] = ak_noise_worley(noise, (uint32_t)dims, q, NULL, want_grad ? g : NULL);
            if (want_grad)
                for (int k = 0; k < dims; ++k) gv[k][i] = g[k];
        }
        v = vf_load(ov);
        if (want_grad)
            AKP_UNROLL
            for (int k = 0; k < dims; ++k) grad[k] = vf_load(gv[k]);
    }
    return v;
}

/* ---- the octave loop ----------------------------------------------------------------------- */

KI static inline VF basis_v(int basis, const ak_noise* noise, const PermTab* perm, int dims, const VF* q, VF* g,
                           bool want_grad) {
    if (basis == AK_NOISE_BASIS_SIMPLEX)
        return dims == 2 ? simplex2_v(perm, q, g, want_grad) : simplex3_v(perm, q, g, want_grad);
    if (basis == AK_NOISE_BASIS_VALUE) return value_v(perm, dims, q, g, want_grad);
    if (basis == AK_NOISE_BASIS_WORLEY) return worley_v(noise, dims, q, g, want_grad);
    return perlin_v(perm, dims, q, g, want_grad);
}

KI static inline void fractal_v(const ak_noise* noise, const PermTab* perm, const ak_fractal_desc* d, int basis, int dims, const VF* p,
                                VF* out, VF* gout, bool want_grad) {
    const VF signmask = vf_cast(vi_set1((int)0x80000000u));
    const VF one = vf_set1(1.0f), zero = vf_zero();
    float freq = d->frequency, amp = 1.0f;
    VF sum = zero, weight = one, gs[3] = {zero, zero, zero}, gw[3] = {zero, zero, zero};
    for (uint32_t o = 0; o < d->octaves; ++o) {
        VF q[3], g[3];
        const VF vf = vf_set1(freq), va = vf_set1(amp);
        AKP_UNROLL
        for (int k = 0; k < dims; ++k) q[k] = vf_mul(p[k], vf);
        const VF n = basis_v(basis, noise, perm, dims, q, g, want_grad);
        if (d->type == AK_FRACTAL_FBM) {
            sum = vf_add(sum, vf_mul(va, n));
            if (want_grad) {
                const VF af = vf_set1(amp * freq);
                AKP_UNROLL
                for (int k = 0; k < dims; ++k) gs[k] = vf_add(gs[k], vf_mul(af, g[k]));
            }
        } else if (d->type == AK_FRACTAL_TURBULENCE) {
            const VF sign = vf_and(n, signmask);
            sum = vf_add(sum, vf_mul(va, vf_abs(n)));
            if (want_grad) {
                const VF af = vf_set1(amp * freq);
                AKP_UNROLL
                for (int k = 0; k < dims; ++k) gs[k] = vf_add(gs[k], vf_mul(af, vf_xor(g[k], sign)));
            }
        } else {
            const VF sign = vf_and(n, signmask);
            const VF an = vf_abs(n);
            const VM unclipped = m_lt(an, one);
            const VF s = vf_sub(one, vf_min(an, one));
            const VF s2 = vf_mul(s, s);
            sum = vf_add(sum, vf_mul(va, vf_mul(weight, s2)));
            VF nw = vf_mul(vf_set1(2.0f), s2);
            const VM open = m_and(m_gt(nw, zero), m_lt(nw, one));
            nw = vf_min(vf_max(nw, zero), one);
            if (want_grad) {
                const VF m2s = vf_mul(vf_set1(-2.0f), s);
                AKP_UNROLL
                for (int k = 0; k < dims; ++k) {
                    const VF ds2 = vf_maskz(unclipped, vf_mul(m2s, vf_mul(vf, vf_xor(g[k], sign))));
                    gs[k] = vf_add(gs[k], vf_mul(va, vf_add(vf_mul(weight, ds2), vf_mul(s2, gw[k]))));
                    gw[k] = vf_maskz(open, vf_mul(vf_set1(2.0f), ds2));
                }
            }
            weight = nw;
        }
        freq = freq * d->lacunarity;
        amp = amp * d->gain;
    }
    *out = sum;
    if (want_grad)
        AKP_UNROLL
        for (int k = 0; k < dims; ++k) gout[k] = gs[k];
}

KI static inline void run_dims(const ak_noise* noise, const ak_fractal_desc* d, int basis, int dims,
                               const float* const* xs, size_t count, float* out, float* const* grad) {
    PermTab perm;
    tab_make(noise->perm, &perm);
    for (size_t i = 0; i < count; i += AKP_W) {
        VF p[3], v, g[3];
        AKP_UNROLL
        for (int k = 0; k < dims; ++k) p[k] = vf_load(xs[k] + i);
        if (grad) {
            fractal_v(noise, &perm, d, basis, dims, p, &v, g, true);
            AKP_UNROLL
            for (int k = 0; k < dims; ++k) vf_store(grad[k] + i, g[k]);
        } else {
            fractal_v(noise, &perm, d, basis, dims, p, &v, g, false);
        }
        vf_store(out + i, v);
    }
}

#define AKP_RUNNER(name, basis, dims)                                                                            \
    KERNEL_RUN static void name(const ak_noise* noise, const ak_fractal_desc* d, const float* const* xs,          \
                                size_t count, float* out, float* const* grad) {                                  \
        run_dims(noise, d, basis, dims, xs, count, out, grad);                                                    \
    }
AKP_RUNNER(run_perlin2, AK_NOISE_BASIS_PERLIN, 2)
AKP_RUNNER(run_perlin3, AK_NOISE_BASIS_PERLIN, 3)
AKP_RUNNER(run_simplex2, AK_NOISE_BASIS_SIMPLEX, 2)
AKP_RUNNER(run_simplex3, AK_NOISE_BASIS_SIMPLEX, 3)
AKP_RUNNER(run_value2, AK_NOISE_BASIS_VALUE, 2)
AKP_RUNNER(run_value3, AK_NOISE_BASIS_VALUE, 3)
AKP_RUNNER(run_worley2, AK_NOISE_BASIS_WORLEY, 2)
AKP_RUNNER(run_worley3, AK_NOISE_BASIS_WORLEY, 3)
#undef AKP_RUNNER

void KERNEL_ENTRY(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims, const float* const* xs,
                  size_t count, float* out, float* const* grad) {
    if (d->basis == AK_NOISE_BASIS_SIMPLEX) {
        if (dims == 2) run_simplex2(noise, d, xs, count, out, grad);
        else run_simplex3(noise, d, xs, count, out, grad);
    } else if (d->basis == AK_NOISE_BASIS_VALUE) {
        if (dims == 2) run_value2(noise, d, xs, count, out, grad);
        else run_value3(noise, d, xs, count, out, grad);
    } else if (d->basis == AK_NOISE_BASIS_WORLEY) {
        if (dims == 2) run_worley2(noise, d, xs, count, out, grad);
        else run_worley3(noise, d, xs, count, out, grad);
    } else {
        if (dims == 2) run_perlin2(noise, d, xs, count, out, grad);
        else run_perlin3(noise, d, xs, count, out, grad);
    }
}
