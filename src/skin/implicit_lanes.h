/* The body of implicit skinning's lane kernels (implicit_avx2.c, implicit_avx512.c): the field
 * of implicit.c's field_eval (broad-phase bones, trilinear grid interpolation, compact support,
 * gradient to posed space, the two strongest fields, the contact bulge) at LANES points at
 * once. The including file defines the vector types and operations:
 *   LANES, LANES_PACKED (1: pack the lanes inside each bone's grid with compress stores, so that
 *   the gathers run on full vectors), VF (floats), VI (int32), VM (lane mask), KFUNC (function attributes),
 *   F_SET1 F_LOAD F_STORE F_ADD F_SUB F_MUL F_DIV F_SQRT F_ZERO, F_SEL(m, a, b) (m ? a : b),
 *   M_LT M_LE M_GT M_GE M_EQ (ordered: false on NaN), M_AND, M_OR, M_ANDNOT(a, b) (a and not
 *   b), M_ANY, M_FROM_BITS, M_BITS, F_ABS, I_STORE, I_SET1 I_ADD I_MUL I_MIN I_TRUNC (float to int, toward 0) I_TO_F,
 *   GATHER4(m, base, index, out) (out[k]: float base[index + k], k < 4; lanes off m give 0),
 *   I_LOAD, I_SUB, COMPRESS_F / COMPRESS_I(dst, m, v) (the lanes of v on m to dst[0], dst[1], ...
 *   in lane order), EXPAND_F(src, m) (src[0], src[1], ... into the lanes on m, 0 elsewhere).
 * Every lane does the scalar code's operations in the same order (lerp in x, then y, then z;
 * sums left to right; no fused multiply-add), so the results are bitwise field_eval's. */

/* Bone b's grid for the lanes of L that it holds (their mask bits for b): each lane's posed
 * point in grid coordinates (grid_locate), *in set for the lanes inside the grid's box and the
 * capsule bound, and the cell (clamped to the last one) and its first node (cell_at). False
 * when no lane is inside: the bone is skipped. */
typedef struct lane_cell {
    const float* F; /* the bone's frame record (fd->bf) */
    int nx, ny;     /* the grid's nodes along x and y */
    VF px, py, pz;  /* grid coordinates */
    VI ix, iy, iz;  /* the cell */
    VI node;        /* its first node's index */
} lane_cell;

KFUNC static inline bool lanes_locate(const akp_implicit_field* fd, const akp_implicit_lanes* L, unsigned b, VF X,
                                      VF Y, VF Z, VM* in_out, lane_cell* c) {
    const VF zero = F_ZERO(), one = F_SET1(1.0f);
    unsigned bits = 0;
    for (unsigned l = 0; l < LANES; ++l) bits |= (unsigned)((L->mask[l] >> b) & 1u) << l;
    const float* F = fd->bf + (size_t)b * fd->bf_floats;
    const VF px = F_ADD(F_ADD(F_ADD(F_MUL(F_SET1(F[0]), X), F_MUL(F_SET1(F[3]), Y)), F_MUL(F_SET1(F[6]), Z)), F_SET1(F[9]));
    const VF py = F_ADD(F_ADD(F_ADD(F_MUL(F_SET1(F[1]), X), F_MUL(F_SET1(F[4]), Y)), F_MUL(F_SET1(F[7]), Z)), F_SET1(F[10]));
    const VF pz = F_ADD(F_ADD(F_ADD(F_MUL(F_SET1(F[2]), X), F_MUL(F_SET1(F[5]), Y)), F_MUL(F_SET1(F[8]), Z)), F_SET1(F[11]));
    VM in = M_AND(M_FROM_BITS(bits), M_AND(M_AND(M_GE(px, zero), M_GE(py, zero)), M_GE(pz, zero)));
    in = M_AND(in, M_AND(M_AND(M_LE(px, F_SET1(F[20])), M_LE(py, F_SET1(F[21]))), M_LE(pz, F_SET1(F[22]))));
    if (!M_ANY(in)) return false;
    if (F[19] > 0.0f) {
        const VF ax = F_SUB(px, F_SET1(F[12])), ay = F_SUB(py, F_SET1(F[13])), az = F_SUB(pz, F_SET1(F[14]));
        const VF c0 = F_SET1(F[15]), c1 = F_SET1(F[16]), c2 = F_SET1(F[17]);
        const VF t0 = F_MUL(F_ADD(F_ADD(F_MUL(ax, c0), F_MUL(ay, c1)), F_MUL(az, c2)), F_SET1(F[18]));
        const VF t = F_SEL(M_GT(t0, zero), F_SEL(M_LT(t0, one), t0, one), zero);
        const VF wx = F_SUB(ax, F_MUL(c0, t)), wy = F_SUB(ay, F_MUL(c1, t)), wz = F_SUB(az, F_MUL(c2, t));
        const VF w2 = F_ADD(F_ADD(F_MUL(wx, wx), F_MUL(wy, wy)), F_MUL(wz, wz));
        in = M_ANDNOT(in, M_GE(w2, F_SET1(F[19])));
        if (!M_ANY(in)) return false;
    }
    const uint32_t* I = fd->grid_info + (size_t)b * 4;
    const int nx = (int)I[0], ny = (int)I[1], nz = (int)I[2];
    c->F = F, c->nx = nx, c->ny = ny, c->px = px, c->py = py, c->pz = pz;
    c->ix = I_MIN(I_TRUNC(px), I_SET1(nx - 2)), c->iy = I_MIN(I_TRUNC(py), I_SET1(ny - 2));
    c->iz = I_MIN(I_TRUNC(pz), I_SET1(nz - 2));
    c->node = I_ADD(I_ADD(I_ADD(I_SET1((int)I[3]), c->ix), I_MUL(c->iy, I_SET1(nx))), I_MUL(c->iz, I_SET1(nx * ny)));
    *in_out = in;
    return true;
}

/* grid_interp and compact for the lanes in `in`: the 4 values (distance, gradient x y z) of
 * the cell's 8 nodes (first indices i000, i010, i001, i011; fractions tx, ty, tz), lerp in x
 * per (y, z) corner, then in y, then in z; then the compact-support map t(u), u = distance x
 * inv_r: 1 (gradient 0) deep inside, nothing beyond. *keep: the lanes with a field; g: the
 * gradient in the bone's grid frame, +0 deep inside as the scalar code's (not the product's
 * possibly signed zero). */
KFUNC static inline void lanes_interp(const akp_implicit_field* fd, VM in, VI i000, VI i010, VI i001, VI i011, VF tx,
                                      VF ty, VF tz, VF inv_r, VF* t_out, VM* keep_out, VF g[3]) {
    const VF zero = F_ZERO(), one = F_SET1(1.0f);
    VF a[4], bq[4], cq[4], dq[4], n0[4], n1[4];
    GATHER4(in, fd->grid, i000, n0), GATHER4(in, fd->grid + 4, i000, n1);
    for (int k = 0; k < 4; ++k) a[k] = F_ADD(n0[k], F_MUL(tx, F_SUB(n1[k], n0[k])));
    GATHER4(in, fd->grid, i010, n0), GATHER4(in, fd->grid + 4, i010, n1);
    for (int k = 0; k < 4; ++k) bq[k] = F_ADD(n0[k], F_MUL(tx, F_SUB(n1[k], n0[k])));
    GATHER4(in, fd->grid, i001, n0), GATHER4(in, fd->grid + 4, i001, n1);
    for (int k = 0; k < 4; ++k) cq[k] = F_ADD(n0[k], F_MUL(tx, F_SUB(n1[k], n0[k])));
    GATHER4(in, fd->grid, i011, n0), GATHER4(in, fd->grid + 4, i011, n1);
    for (int k = 0; k < 4; ++k) dq[k] = F_ADD(n0[k], F_MUL(tx, F_SUB(n1[k], n0[k])));
    VF r[4];
    for (int k = 0; k < 4; ++k) {
        const VF e = F_ADD(a[k], F_MUL(ty, F_SUB(bq[k], a[k]))), f = F_ADD(cq[k], F_MUL(ty, F_SUB(dq[k], cq[k])));
        r[k] = F_ADD(e, F_MUL(tz, F_SUB(f, e)));
    }
    /* compact: t(u) inside the support, 1 (gradient 0) deep inside, nothing beyond */
    const VF u = F_MUL(r[0], inv_r), u2 = F_MUL(u, u);
    const VF poly = F_ADD(F_SUB(u, F_MUL(F_MUL(u2, u), F_SET1(2.0f / 3.0f))), F_MUL(F_MUL(F_MUL(u2, u2), u), F_SET1(0.2f)));
    const VM deep = M_LE(u, F_SET1(-1.0f));
    const VF t = F_SEL(deep, one, F_SUB(F_SET1(0.5f), F_MUL(F_SET1(0.9375f), poly)));
    const VF w = F_SUB(one, u2);
    const VF dt = F_MUL(F_MUL(F_MUL(F_SET1(-0.9375f), w), w), inv_r);
    const VM keep = M_AND(M_AND(in, M_LT(u, one)), M_GT(t, zero));
    *t_out = t, *keep_out = keep;
    for (int k = 0; k < 3; ++k) g[k] = F_SEL(deep, zero, F_MUL(r[k + 1], dt));
}

/* keep_strongest over the lanes: the two strongest fields so far and their gradients in posed
 * space. */
typedef struct lane_best {
    VF f1, f2, g1x, g1y, g1z, g2x, g2y, g2z;
} lane_best;

/* One bone's field t (where keep) with its grid-frame gradient gy, turned to posed space by
 * (M^-1)^T (m: the bone's fd->inv record), into the two strongest of B. */
KFUNC static inline void lanes_keep_strongest(lane_best* B, const float* m, VM keep, VF t, VF gyx, VF gyy, VF gyz) {
    const VF gx = F_ADD(F_ADD(F_MUL(F_SET1(m[0]), gyx), F_MUL(F_SET1(m[1]), gyy)), F_MUL(F_SET1(m[2]), gyz));
    const VF gy = F_ADD(F_ADD(F_MUL(F_SET1(m[3]), gyx), F_MUL(F_SET1(m[4]), gyy)), F_MUL(F_SET1(m[5]), gyz));
    const VF gz = F_ADD(F_ADD(F_MUL(F_SET1(m[6]), gyx), F_MUL(F_SET1(m[7]), gyy)), F_MUL(F_SET1(m[8]), gyz));
    const VM over1 = M_AND(keep, M_GT(t, B->f1));
    const VM over2 = M_ANDNOT(M_AND(keep, M_GT(t, B->f2)), over1);
    B->f2 = F_SEL(over1, B->f1, F_SEL(over2, t, B->f2));
    B->g2x = F_SEL(over1, B->g1x, F_SEL(over2, gx, B->g2x));
    B->g2y = F_SEL(over1, B->g1y, F_SEL(over2, gy, B->g2y));
    B->g2z = F_SEL(over1, B->g1z, F_SEL(over2, gz, B->g2z));
    B->f1 = F_SEL(over1, t, B->f1);
    B->g1x = F_SEL(over1, gx, B->g1x), B->g1y = F_SEL(over1, gy, B->g1y), B->g1z = F_SEL(over1, gz, B->g1z);
}

#if LANES_PACKED
/* The (lane, bone) pairs of one call whose point lies in the bone's grid (phase 1 of
 * lanes_field), packed: the cell's first node and the nodes one step up in y and in z (float
 * index), the fractions, 1 / the support radius; then (phase 2) the field and its bind-space
 * gradient (f 0: no field). At most 64 bones (one broad-phase mask word) times 16 lanes, plus a
 * vector's padding. */
typedef struct lane_pairs {
    _Alignas(64) int32_t i000[64 * 16 + 16];
    _Alignas(64) int32_t i010[64 * 16 + 16];
    _Alignas(64) int32_t i001[64 * 16 + 16];
    _Alignas(64) float tx[64 * 16 + 16];
    _Alignas(64) float ty[64 * 16 + 16];
    _Alignas(64) float tz[64 * 16 + 16];
    _Alignas(64) float inv_r[64 * 16 + 16];
    _Alignas(64) float f[64 * 16 + 16];
    _Alignas(64) float gx[64 * 16 + 16];
    _Alignas(64) float gy[64 * 16 + 16];
    _Alignas(64) float gz[64 * 16 + 16];
    uint32_t bone[64], start[64], lanes[64]; /* per located bone: its pairs and lanes */
} lane_pairs;

/* field_eval at the lanes of L. Three phases so that the gathers run on full vectors: (1) per
 * bone of the lanes' cells, in bone order, the grid coordinates, box and capsule bound of every
 * lane (the lanes inside are packed as pairs); (2) the pairs, a vector at a time: the trilinear
 * interpolation of the 8 nodes (gathers) and the compact-support map; (3) per bone again, in
 * bone order, its pairs' results back in their lanes: the gradient to posed space and the two
 * strongest fields, as keep_strongest. Then the contact bulge. */
KFUNC static void lanes_field(const akp_implicit_field* fd, akp_implicit_lanes* L) {
    lane_pairs P; /* 45 KiB of stack */
    uint64_t all = 0;
    for (unsigned l = 0; l < LANES; ++l) all |= L->mask[l];
    const VF zero = F_ZERO();
    const VF X = F_LOAD(L->x), Y = F_LOAD(L->y), Z = F_LOAD(L->z);
    unsigned n = 0, nb = 0;
    for (; all; all &= all - 1) {
        const unsigned b = (unsigned)__builtin_ctzll(all);
        lane_cell C;
        VM in;
        if (!lanes_locate(fd, L, b, X, Y, Z, &in, &C)) continue;
        const float* F = C.F;
        const int nx = C.nx, ny = C.ny;
        const VF px = C.px, py = C.py, pz = C.pz;
        const VI ix = C.ix, iy = C.iy, iz = C.iz, node = C.node;
        const VI i000 = I_MUL(node, I_SET1(4));
        COMPRESS_I(P.i000 + n, in, i000);
        COMPRESS_I(P.i010 + n, in, I_ADD(i000, I_SET1(4 * nx)));
        COMPRESS_I(P.i001 + n, in, I_ADD(i000, I_SET1(4 * nx * ny)));
        COMPRESS_F(P.tx + n, in, F_SUB(px, I_TO_F(ix)));
        COMPRESS_F(P.ty + n, in, F_SUB(py, I_TO_F(iy)));
        COMPRESS_F(P.tz + n, in, F_SUB(pz, I_TO_F(iz)));
        COMPRESS_F(P.inv_r + n, in, F_SET1(F[23]));
        P.bone[nb] = b, P.start[nb] = n, P.lanes[nb] = M_BITS(in);
        ++nb, n += (unsigned)__builtin_popcount(M_BITS(in));
    }
    for (unsigned q = 0; q < n; q += LANES) {
        /* grid_interp: the 4 values (distance, gradient x y z) of the cell's 8 nodes, lerp in x
         * per (y, z) corner, then in y, then in z; then compact */
        const VM in = M_FROM_BITS(n - q >= LANES ? (1u << LANES) - 1u : (1u << (n - q)) - 1u);
        const VI i000 = I_LOAD(P.i000 + q), i010 = I_LOAD(P.i010 + q), i001 = I_LOAD(P.i001 + q);
        const VI i011 = I_ADD(i001, I_SUB(i010, i000));
        const VF tx = F_LOAD(P.tx + q), ty = F_LOAD(P.ty + q), tz = F_LOAD(P.tz + q);
        VF t, g[3];
        VM keep;
        lanes_interp(fd, in, i000, i010, i001, i011, tx, ty, tz, F_LOAD(P.inv_r + q), &t, &keep, g);
        /* f 0 where there is no field */
        F_STORE(P.f + q, F_SEL(keep, t, zero));
        F_STORE(P.gx + q, g[0]), F_STORE(P.gy + q, g[1]), F_STORE(P.gz + q, g[2]);
    }
    lane_best B = {zero, zero, zero, zero, zero, zero, zero, zero};
    for (unsigned k = 0; k < nb; ++k) {
        const VM in = M_FROM_BITS(P.lanes[k]);
        const unsigned q = P.start[k];
        const VF t = EXPAND_F(P.f + q, in);
        const VM keep = M_GT(t, zero);
        if (!M_ANY(keep)) continue;
        const VF gyx = EXPAND_F(P.gx + q, in), gyy = EXPAND_F(P.gy + q, in), gyz = EXPAND_F(P.gz + q, in);
        lanes_keep_strongest(&B, fd->inv + 12 * (size_t)P.bone[k], keep, t, gyx, gyy, gyz);
    }
#else
/* field_eval at the lanes of L, bone by bone in bone order (the AVX2 kernel, which has no
 * compress store): each bone's grid coordinates, box and capsule bound for every lane, then the
 * trilinear interpolation (gathers) of the lanes inside, the compact-support map, the gradient to
 * posed space and the two strongest fields, as keep_strongest. Then the contact bulge. */
KFUNC static void lanes_field(const akp_implicit_field* fd, akp_implicit_lanes* L) {
    uint64_t all = 0;
    for (unsigned l = 0; l < LANES; ++l) all |= L->mask[l];
    const VF zero = F_ZERO();
    const VF X = F_LOAD(L->x), Y = F_LOAD(L->y), Z = F_LOAD(L->z);
    lane_best B = {zero, zero, zero, zero, zero, zero, zero, zero};
    for (; all; all &= all - 1) {
        const unsigned b = (unsigned)__builtin_ctzll(all);
        lane_cell C;
        VM in;
        if (!lanes_locate(fd, L, b, X, Y, Z, &in, &C)) continue;
        const float* F = C.F;
        const int nx = C.nx, ny = C.ny;
        const VF px = C.px, py = C.py, pz = C.pz;
        const VI ix = C.ix, iy = C.iy, iz = C.iz, node = C.node;
        const VF tx = F_SUB(px, I_TO_F(ix)), ty = F_SUB(py, I_TO_F(iy)), tz = F_SUB(pz, I_TO_F(iz));
        const VI i000 = I_MUL(node, I_SET1(4)), i010 = I_ADD(i000, I_SET1(4 * nx));
        const VI i001 = I_ADD(i000, I_SET1(4 * nx * ny)), i011 = I_ADD(i001, I_SET1(4 * nx));
        /* grid_interp: the 4 values (distance, gradient x y z) of the cell's 8 nodes, lerp in x
         * per (y, z) corner, then in y, then in z */
        VF t, g[3];
        VM keep;
        lanes_interp(fd, in, i000, i010, i001, i011, tx, ty, tz, F_SET1(F[23]), &t, &keep, g);
        if (!M_ANY(keep)) continue;
        lanes_keep_strongest(&B, fd->inv + 12 * (size_t)b, keep, t, g[0], g[1], g[2]);
    }
#endif
    const VF f1 = B.f1, f2 = B.f2, g1x = B.g1x, g1y = B.g1y, g1z = B.g1z, g2x = B.g2x, g2y = B.g2y, g2z = B.g2z;
    VF Fo = f1, Gx = g1x, Gy = g1y, Gz = g1z;
    if (fd->bulge > 0.0f) {
        const VF l1 = F_SQRT(F_ADD(F_ADD(F_MUL(g1x, g1x), F_MUL(g1y, g1y)), F_MUL(g1z, g1z)));
        const VF l2 = F_SQRT(F_ADD(F_ADD(F_MUL(g2x, g2x), F_MUL(g2y, g2y)), F_MUL(g2z, g2z)));
        const VF dot = F_ADD(F_ADD(F_MUL(g1x, g2x), F_MUL(g1y, g2y)), F_MUL(g1z, g2z));
        const VF w = F_DIV(F_SUB(zero, dot), F_MUL(l1, l2));
        const VM c = M_AND(M_AND(M_GT(f2, zero), M_AND(M_GT(l1, zero), M_GT(l2, zero))), M_GT(w, zero));
        if (M_ANY(c)) {
            const VF k = F_MUL(F_MUL(F_SET1(2.0f * fd->bulge), w), f2);
            Fo = F_SEL(c, F_ADD(f1, F_MUL(F_MUL(F_MUL(F_SET1(fd->bulge), w), f2), f2)), f1);
            Gx = F_SEL(c, F_ADD(g1x, F_MUL(g2x, k)), g1x);
            Gy = F_SEL(c, F_ADD(g1y, F_MUL(g2y, k)), g1y);
            Gz = F_SEL(c, F_ADD(g1z, F_MUL(g2z, k)), g1z);
        }
    }
    F_STORE(L->f, Fo), F_STORE(L->gx, Gx), F_STORE(L->gy, Gy), F_STORE(L->gz, Gz);
}

/* project's march_step for the live lanes: the broad-phase cell of each point, the field there,
 * then one Newton step, each lane as the scalar code; returns the lanes whose march ended. */
KFUNC static unsigned lanes_march(const akp_implicit_field* fd, akp_implicit_lanes* L, unsigned live) {
    const VF zero = F_ZERO();
    const VM on = M_FROM_BITS(live);
    {
        /* field_eval's broad-phase cell (-1 outside: the field is 0) */
        const VF top = F_SET1((float)fd->bp_cells);
        const VF p0 = F_MUL(F_SUB(F_LOAD(L->x), F_SET1(fd->bp_lo[0])), F_SET1(fd->bp_inv_cell[0]));
        const VF p1 = F_MUL(F_SUB(F_LOAD(L->y), F_SET1(fd->bp_lo[1])), F_SET1(fd->bp_inv_cell[1]));
        const VF p2 = F_MUL(F_SUB(F_LOAD(L->z), F_SET1(fd->bp_lo[2])), F_SET1(fd->bp_inv_cell[2]));
        const VM in = M_AND(M_AND(M_AND(M_GE(p0, zero), M_GE(p1, zero)), M_AND(M_GE(p2, zero), M_LT(p0, top))),
                            M_AND(M_AND(M_LT(p1, top), M_LT(p2, top)), on));
        const VI n = I_SET1((int)fd->bp_cells);
        const VI cell = I_ADD(I_TRUNC(F_SEL(in, p0, zero)),
                              I_MUL(n, I_ADD(I_TRUNC(F_SEL(in, p1, zero)), I_MUL(n, I_TRUNC(F_SEL(in, p2, zero))))));
        I_STORE(L->cell, cell);
        const unsigned inside = fd->bp_mask ? M_BITS(in) : 0u;
        for (unsigned l = 0; l < LANES; ++l) L->mask[l] = inside >> l & 1u ? fd->bp_mask[L->cell[l]] : 0u;
    }
    lanes_field(fd, L);
    const VF F = F_LOAD(L->f), gx = F_LOAD(L->gx), gy = F_LOAD(L->gy), gz = F_LOAD(L->gz);
    const VF px = F_LOAD(L->px), py = F_LOAD(L->py), pz = F_LOAD(L->pz), it = F_LOAD(L->it), st = F_LOAD(L->st);
    /* march_step: the end tests, then the step (capped) */
    const VF e = F_SUB(F_LOAD(L->iso), F);
    const VF ae = F_ABS(e);
    const VF gl2 = F_ADD(F_ADD(F_MUL(gx, gx), F_MUL(gy, gy)), F_MUL(gz, gz));
    VM done = M_OR(M_OR(M_LT(ae, F_SET1(fd->iso_eps)), M_EQ(it, F_SET1(fd->iterations))), M_ANDNOT(on, M_GT(gl2, F_SET1(1e-20f))));
    const VF dot = F_ADD(F_ADD(F_MUL(gx, px), F_MUL(gy, py)), F_MUL(gz, pz));
    const VF pl2 = F_ADD(F_ADD(F_MUL(px, px), F_MUL(py, py)), F_MUL(pz, pz));
    const VM turn = M_ANDNOT(M_AND(M_GT(it, zero), M_LT(dot, F_MUL(F_SET1(fd->stop_cos), F_SQRT(F_MUL(gl2, pl2))))), done);
    done = M_OR(done, turn);
    VF state = F_SEL(turn, F_SET1(2.0f), st); /* ST_STOPPED */
    const VM go = M_ANDNOT(on, done);
    const VF q = F_DIV(e, gl2);
    VF sx = F_MUL(gx, q), sy = F_MUL(gy, q), sz = F_MUL(gz, q);
    const VF sl = F_SQRT(F_ADD(F_ADD(F_MUL(sx, sx), F_MUL(sy, sy)), F_MUL(sz, sz)));
    const VF cap = F_SET1(fd->step_cap);
    const VM long_step = M_GT(sl, cap);
    const VF k = F_DIV(cap, sl);
    sx = F_SEL(long_step, F_MUL(sx, k), sx), sy = F_SEL(long_step, F_MUL(sy, k), sy), sz = F_SEL(long_step, F_MUL(sz, k), sz);
    F_STORE(L->x, F_SEL(go, F_ADD(F_LOAD(L->x), sx), F_LOAD(L->x)));
    F_STORE(L->y, F_SEL(go, F_ADD(F_LOAD(L->y), sy), F_LOAD(L->y)));
    F_STORE(L->z, F_SEL(go, F_ADD(F_LOAD(L->z), sz), F_LOAD(L->z)));
    F_STORE(L->px, F_SEL(go, gx, px)), F_STORE(L->py, F_SEL(go, gy, py)), F_STORE(L->pz, F_SEL(go, gz, pz));
    state = F_SEL(M_AND(go, M_EQ(state, zero)), F_SET1(1.0f), state); /* ST_KEEP -> ST_MOVED */
    F_STORE(L->st, state);
    const VM last = M_AND(go, M_LT(ae, F_SET1(fd->unchecked_below)));
    done = M_OR(done, last);
    F_STORE(L->it, F_SEL(M_ANDNOT(go, last), F_ADD(it, F_SET1(1.0f)), it));
    return M_BITS(done) & live;
}
