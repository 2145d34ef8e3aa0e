/* The XPBD/PBD constraint solves, written once over an abstract lane type and included by
 * step.c (scalar: one constraint per call), cloth_avx2.c (8 lanes) and cloth_avx512.c (16
 * lanes). Every variant performs the same IEEE operations (add, sub, mul, div, sqrt, compare,
 * select, sign flips) in the same order, with no fused multiply-add (C11 mode: GCC does not
 * contract; clang is told not to below), so one constraint gives the same bits whichever width
 * solves it, and the step's result does not depend on the CPU's SIMD level or thread count.
 *
 * A block solves the constraints [k, k + KW) of one colour: no two of them share a particle, so
 * each lane gathers its particles (displacement and inverse mass: one 16-byte akp_px each),
 * computes, and scatters them back without conflict. Vectors between particles are their value
 * at the start of the step (per-constraint arrays, contiguous loads) plus the difference of the
 * displacements since (KN(rel)). Early outs of the scalar solve (a
 * degenerate constraint, no free particle) become lane masks: a masked lane writes its
 * particles back unchanged and keeps its multiplier.
 *
 * The including file defines, before including this header:
 *   KW                      lanes per block
 *   KV, KM                  lane vector type, lane mask type
 *   KFN                     attributes of the functions (static inline + target)
 *   K_SET1(f) K_LOAD(p) K_STORE(p, v)        (unaligned float loads and stores)
 *   K_ADD K_SUB K_MUL K_DIV K_SQRT K_ABS K_NEG
 *   K_LT K_GT K_NE K_EQ K_NLT (ordered <, >, unordered !=, ordered ==, !(a < b))
 *   K_MAND(m, n) K_SEL(m, a, b) (m ? a : b)
 *   K_GATHER(x, idx, out_kv3, out_w)  K_SCATTER(x, idx, kv3, w)
 *   KN(name)                the name of a function in this variant */
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#endif

typedef struct kv3 {
    KV x, y, z;
} kv3;

KFN kv3 kv3_add(kv3 a, kv3 b) { return (kv3){K_ADD(a.x, b.x), K_ADD(a.y, b.y), K_ADD(a.z, b.z)}; }
KFN kv3 kv3_sub(kv3 a, kv3 b) { return (kv3){K_SUB(a.x, b.x), K_SUB(a.y, b.y), K_SUB(a.z, b.z)}; }
KFN kv3 kv3_scale(kv3 a, KV s) { return (kv3){K_MUL(a.x, s), K_MUL(a.y, s), K_MUL(a.z, s)}; }
KFN KV kv3_dot(kv3 a, kv3 b) { return K_ADD(K_ADD(K_MUL(a.x, b.x), K_MUL(a.y, b.y)), K_MUL(a.z, b.z)); }
KFN kv3 kv3_cross(kv3 a, kv3 b) {
    return (kv3){K_SUB(K_MUL(a.y, b.z), K_MUL(a.z, b.y)), K_SUB(K_MUL(a.z, b.x), K_MUL(a.x, b.z)),
                 K_SUB(K_MUL(a.x, b.y), K_MUL(a.y, b.x))};
}
KFN kv3 kv3_sel(KM m, kv3 a, kv3 b) { return (kv3){K_SEL(m, a.x, b.x), K_SEL(m, a.y, b.y), K_SEL(m, a.z, b.z)}; }

/* atan2 to about 1e-5 rad: odd minimax polynomial of atan on [0, 1] after folding the octant
 * (libm's atan2f was a quarter of the step). 0 when x = y = 0. */
KFN KV KN(atan2)(KV y, KV x) {
    const KV ax = K_ABS(x), ay = K_ABS(y);
    const KM xbig = K_GT(ax, ay);
    const KV mx = K_SEL(xbig, ax, ay), mn = K_SEL(xbig, ay, ax);
    const KV z = K_DIV(mn, mx), z2 = K_MUL(z, z);
    KV p = K_MUL(z2, K_SET1(-0.01172120f));
    p = K_MUL(z2, K_ADD(K_SET1(0.05265332f), p));
    p = K_MUL(z2, K_ADD(K_SET1(-0.11643287f), p));
    p = K_MUL(z2, K_ADD(K_SET1(0.19354346f), p));
    p = K_MUL(z2, K_ADD(K_SET1(-0.33262347f), p));
    KV r = K_MUL(z, K_ADD(K_SET1(0.99997726f), p));
    r = K_SEL(K_GT(ay, ax), K_SUB(K_SET1(1.57079633f), r), r);
    r = K_SEL(K_LT(x, K_SET1(0.0f)), K_SUB(K_SET1(3.14159265f), r), r);
    r = K_SEL(K_LT(y, K_SET1(0.0f)), K_NEG(r), r);
    return K_SEL(K_EQ(mx, K_SET1(0.0f)), K_SET1(0.0f), r);
}

/* Dihedral angle of an element (wings x0, x1, edge x2 -> x3; Bridson, Marino, Fedkiw 2003) from
 * its edge vectors e = x3 - x2, a = x0 - x2, b = x1 - x2, and its gradient g: the signed angle
 * between the triangle normals n1 = e x a and n2 = b x e about e, from the unnormalised normals
 * (atan2 ignores a common positive scale). *out_ok is false where a triangle or the edge is
 * degenerate (|n|^2 or |e|^2 below 1e-24); those lanes' angle and gradient are meaningless. */
KFN KV KN(dihedral)(kv3 e, kv3 a, kv3 b, kv3 g[4], KM* out_ok) {
    const kv3 n1 = kv3_cross(e, a), n2 = kv3_cross(b, e);
    const KV l1 = kv3_dot(n1, n1), l2 = kv3_dot(n2, n2), le2 = kv3_dot(e, e);
    const KV tiny = K_SET1(1e-24f);
    *out_ok = K_MAND(K_MAND(K_NLT(l1, tiny), K_NLT(l2, tiny)), K_NLT(le2, tiny));
    const KV le = K_SQRT(le2), inv = K_DIV(K_SET1(1.0f), le);
    const KV theta = KN(atan2)(K_MUL(kv3_dot(kv3_cross(n1, n2), e), inv), kv3_dot(n1, n2));
    const kv3 u1 = kv3_scale(n1, K_DIV(K_SET1(1.0f), l1)), u2 = kv3_scale(n2, K_DIV(K_SET1(1.0f), l2));
    const KV nle = K_NEG(le);
    g[0] = kv3_scale(u1, nle);
    g[1] = kv3_scale(u2, nle);
    /* (x_i - x3) . e = (x_i - x2) . e - |e|^2 */
    const KV b0 = K_MUL(kv3_dot(a, e), inv), b1 = K_MUL(kv3_dot(b, e), inv);
    const KV a0 = K_SUB(b0, le), a1 = K_SUB(b1, le);
    g[2] = kv3_sub(kv3_scale(u1, K_NEG(a0)), kv3_scale(u2, a1));
    g[3] = kv3_add(kv3_scale(u1, b0), kv3_scale(u2, b1));
    return theta;
}

/* The vector from particle j to particle i of a constraint: its value at the start of the
 * step (off[0..2] + k, computed once per step from the caller's positions) plus the difference
 * of the two displacements since then, so that it keeps float's relative precision wherever
 * the cloth is and however small the substep's motion. */
KFN kv3 KN(rel)(float* const off[3], size_t k, kv3 di, kv3 dj) {
    const kv3 o = {K_LOAD(off[0] + k), K_LOAD(off[1] + k), K_LOAD(off[2] + k)};
    return kv3_add(o, kv3_sub(di, dj));
}

/* dlambda of one XPBD (or PBD) update: C the constraint, wsum = sum_i w_i |grad_i C|^2, alpha the
 * compliance, lam the multiplier so far, vdot = sum_i grad_i C . (x_i - prev_i) (read only when
 * damped). */
KFN KV KN(dlambda)(const akp_solve* s, KV C, KV wsum, KV alpha, KV lam, KV vdot) {
    if (s->pbd) return K_DIV(K_MUL(K_SET1(-s->pbd_stiffness), C), wsum);
    const KV at = K_DIV(alpha, K_SET1(s->h2));
    KV num = K_SUB(K_NEG(C), K_MUL(at, lam));
    if (!s->damped) return K_DIV(num, K_ADD(wsum, at));
    /* eq. 26: gamma = alpha~ beta~ / h with beta~ = h^2 beta */
    const KV gamma = K_DIV(K_MUL(alpha, K_SET1(s->beta)), K_SET1(s->h));
    num = K_SUB(num, K_MUL(gamma, vdot));
    return K_DIV(num, K_ADD(K_MUL(K_ADD(K_SET1(1.0f), gamma), wsum), at));
}

/* Distance constraints [k, k + KW): C = |x_i - x_j| - rest. */
KFN void KN(dist)(const akp_solve* s, size_t k, bool first) {
    const ak_cloth* cl = s->cl;
    kv3 xi, xj;
    KV wi, wj;
    K_GATHER(s->x, cl->dist_i + k, xi, wi);
    K_GATHER(s->x, cl->dist_j + k, xj, wj);
    const KV w = K_ADD(wi, wj);
    const kv3 e = KN(rel)(s->dist_off, k, xi, xj);
    const KV len = K_SQRT(kv3_dot(e, e));
    const KM on = K_MAND(K_NE(w, K_SET1(0.0f)), K_NLT(len, K_SET1(1e-12f)));
    const kv3 g = kv3_scale(e, K_DIV(K_SET1(1.0f), len)); /* grad_i C; grad_j C = -g */
    const KV C = K_SUB(len, K_LOAD(cl->dist_rest + k));
    const KV lam = first || s->pbd ? K_SET1(0.0f) : K_LOAD(s->lambda + k);
    KV vdot = K_SET1(0.0f);
    if (s->damped && !s->pbd) {
        kv3 pi, pj;
        KV unused_i, unused_j;
        K_GATHER(s->prev, cl->dist_i + k, pi, unused_i);
        K_GATHER(s->prev, cl->dist_j + k, pj, unused_j);
        (void)unused_i, (void)unused_j;
        vdot = kv3_dot(g, kv3_sub(kv3_sub(xi, pi), kv3_sub(xj, pj)));
    }
    const KV dl = KN(dlambda)(s, C, w, K_LOAD(cl->dist_alpha + k), lam, vdot);
    if (!s->pbd) K_STORE(s->lambda + k, K_SEL(on, K_ADD(lam, dl), lam));
    xi = kv3_sel(on, kv3_add(xi, kv3_scale(g, K_MUL(wi, dl))), xi);
    xj = kv3_sel(on, kv3_sub(xj, kv3_scale(g, K_MUL(wj, dl))), xj);
    K_SCATTER(s->x, cl->dist_i + k, xi, wi);
    K_SCATTER(s->x, cl->dist_j + k, xj, wj);
}

/* Bending constraints [k, k + KW): dihedral (C = angle - rest angle, wrapped to [-pi, pi],
 * compliance 1 / dihedral_stiffness) or isometric (C = |sum_q K_q x_q| - rest, per-constraint
 * compliance). */
KFN void KN(bend)(const akp_solve* s, size_t k, bool first) {
    const ak_cloth* cl = s->cl;
    kv3 x[4], g[4];
    KV w[4];
    for (int q = 0; q < 4; ++q) K_GATHER(s->x, cl->bend_p[q] + k, x[q], w[q]);
    KV C, alpha, wsum = K_SET1(0.0f);
    KM on;
    if (s->iso) {
        /* C = |b| - |b_rest|, grad_q C = K_q b / |b| */
        KV Kq[4];
        for (int q = 0; q < 4; ++q) Kq[q] = K_LOAD(cl->bend_K[q] + k);
        /* b = sum_q K_q x_q = sum_{q != 2} K_q (x_q - x_2) (the weights sum to zero): its value at
         * the start of the step plus the displacements' share */
        kv3 bv = {K_LOAD(s->bend_off[0] + k), K_LOAD(s->bend_off[1] + k), K_LOAD(s->bend_off[2] + k)};
        bv = kv3_add(bv, kv3_scale(kv3_sub(x[0], x[2]), Kq[0]));
        bv = kv3_add(bv, kv3_scale(kv3_sub(x[1], x[2]), Kq[1]));
        bv = kv3_add(bv, kv3_scale(kv3_sub(x[3], x[2]), Kq[3]));
        const KV l = K_SQRT(kv3_dot(bv, bv));
        on = K_NLT(l, K_SET1(1e-12f));
        const kv3 n = kv3_scale(bv, K_DIV(K_SET1(1.0f), l));
        for (int q = 0; q < 4; ++q) {
            g[q] = kv3_scale(n, Kq[q]);
            wsum = K_ADD(wsum, K_MUL(K_MUL(w[q], Kq[q]), Kq[q]));
        }
        C = K_SUB(l, K_LOAD(cl->bend_rest + k));
        alpha = K_LOAD(cl->bend_alpha + k);
    } else {
        const kv3 e = KN(rel)(s->bend_off, k, x[3], x[2]);
        const kv3 a = KN(rel)(s->bend_off + 3, k, x[0], x[2]);
        const kv3 b = KN(rel)(s->bend_off + 6, k, x[1], x[2]);
        C = K_SUB(KN(dihedral)(e, a, b, g, &on), K_LOAD(cl->bend_rest + k));
        const KV pi = K_SET1(AK_PI), two_pi = K_SET1(2.0f * AK_PI);
        C = K_SEL(K_GT(C, pi), K_SUB(C, two_pi), C);
        C = K_SEL(K_LT(C, K_NEG(pi)), K_ADD(C, two_pi), C);
        for (int q = 0; q < 4; ++q) wsum = K_ADD(wsum, K_MUL(w[q], kv3_dot(g[q], g[q])));
        alpha = K_SET1(s->bend_alpha);
    }
    on = K_MAND(on, K_NLT(wsum, K_SET1(1e-20f)));
    float* lam_slot = s->lambda + cl->dist_count + k;
    const KV lam = first || s->pbd ? K_SET1(0.0f) : K_LOAD(lam_slot);
    KV vdot = K_SET1(0.0f);
    if (s->damped && !s->pbd) {
        for (int q = 0; q < 4; ++q) {
            kv3 p;
            KV unused;
            K_GATHER(s->prev, cl->bend_p[q] + k, p, unused);
            (void)unused;
            vdot = K_ADD(vdot, kv3_dot(g[q], kv3_sub(x[q], p)));
        }
    }
    const KV dl = KN(dlambda)(s, C, wsum, alpha, lam, vdot);
    if (!s->pbd) K_STORE(lam_slot, K_SEL(on, K_ADD(lam, dl), lam));
    for (int q = 0; q < 4; ++q) {
        const KM m = K_MAND(on, K_GT(w[q], K_SET1(0.0f)));
        x[q] = kv3_sel(m, kv3_add(x[q], kv3_scale(g[q], K_MUL(w[q], dl))), x[q]);
        K_SCATTER(s->x, cl->bend_p[q] + k, x[q], w[q]);
    }
}
