/* 3x3 decompositions: signed SVD by one-sided Jacobi rotations, and the polar decomposition
 * M = R D by the averaging scheme R_{i+1} = (R_i + R_i^-T)/2 with an SVD fallback.
 * Everything runs in double precision and is rounded to float once at the end, so float
 * inputs come out with float-rounding accuracy even when badly conditioned. */
#include <animkit/math.h>

typedef struct dm3 {
    double m[3][3]; /* [row][column] */
} dm3;

static dm3 dm3_from(ak_mat3 a) {
    dm3 r;
    for (int c = 0; c < 3; ++c)
        for (int row = 0; row < 3; ++row) r.m[row][c] = a.m[c * 3 + row];
    return r;
}

static ak_mat3 dm3_to(const dm3* a) {
    ak_mat3 r;
    for (int c = 0; c < 3; ++c)
        for (int row = 0; row < 3; ++row) r.m[c * 3 + row] = (float)a->m[row][c];
    return r;
}

static double dm3_det(const dm3* a) {
    const double(*m)[3] = a->m;
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

static double dm3_frob(const dm3* a) {
    double s = 0.0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) s += a->m[i][j] * a->m[i][j];
    return sqrt(s);
}

/* Transpose of the inverse (cofactor matrix / det); det must be non-zero. */
static dm3 dm3_inverse_transpose(const dm3* a, double det) {
    const double(*m)[3] = a->m;
    dm3 r;
    for (int i = 0; i < 3; ++i) {
        int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
        for (int j = 0; j < 3; ++j) {
            int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
            r.m[i][j] = (m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1]) / det;
        }
    }
    return r;
}

/* r = V diag(s) V^T (symmetric by construction). */
static dm3 dm3_sym_from_eigen(const dm3* v, const double s[3]) {
    dm3 r;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            r.m[i][j] = v->m[i][0] * s[0] * v->m[j][0] + v->m[i][1] * s[1] * v->m[j][1] + v->m[i][2] * s[2] * v->m[j][2];
    return r;
}

static void cross3(const double a[3], const double b[3], double out[3]) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static bool dm3_finite(const dm3* a) {
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            if (!(a->m[i][j] - a->m[i][j] == 0.0)) return false;
    return true;
}

/* Signed SVD a = U diag(s) V^T with U, V rotations; false for the zero matrix. */
static bool svd3(const dm3* a, dm3* u, double s[3], dm3* v) {
    double scale = 0.0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) scale = fmax(scale, fabs(a->m[i][j]));
    *u = *v = (dm3){{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
    s[0] = s[1] = s[2] = 0.0;
    if (!(scale > 0.0)) return false;
    /* Work on a / max|a_ij| so that no square below over- or underflows. */
    dm3 b;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) b.m[i][j] = a->m[i][j] / scale;
    dm3 vv = *v;
    /* One-sided Jacobi: rotate column pairs of B (and V alongside, so A V = B) until every
     * pair is orthogonal to 1e-15 relative; 3x3 needs about 5 sweeps. */
    for (int sweep = 0; sweep < 40; ++sweep) {
        bool rotated = false;
        for (int p = 0; p < 2; ++p)
            for (int q = p + 1; q < 3; ++q) {
                double al = 0, be = 0, ga = 0;
                for (int r = 0; r < 3; ++r) {
                    al += b.m[r][p] * b.m[r][p];
                    be += b.m[r][q] * b.m[r][q];
                    ga += b.m[r][p] * b.m[r][q];
                }
                if (al == 0.0 || be == 0.0 || fabs(ga) <= 1e-15 * sqrt(al) * sqrt(be)) continue;
                rotated = true;
                double zeta = (be - al) / (2.0 * ga);
                double t = (zeta >= 0.0 ? 1.0 : -1.0) / (fabs(zeta) + sqrt(1.0 + zeta * zeta));
                double c = 1.0 / sqrt(1.0 + t * t), sn = c * t;
                for (int r = 0; r < 3; ++r) {
                    double bp = b.m[r][p], bq = b.m[r][q];
                    b.m[r][p] = c * bp - sn * bq, b.m[r][q] = sn * bp + c * bq;
                    double vp = vv.m[r][p], vq = vv.m[r][q];
                    vv.m[r][p] = c * vp - sn * vq, vv.m[r][q] = sn * vp + c * vq;
                }
            }
        if (!rotated) break;
    }
    /* Order columns by decreasing norm. */
    double nrm[3];
    int o[3] = {0, 1, 2};
    for (int j = 0; j < 3; ++j) nrm[j] = sqrt(b.m[0][j] * b.m[0][j] + b.m[1][j] * b.m[1][j] + b.m[2][j] * b.m[2][j]);
    for (int x = 0; x < 3; ++x)
        for (int y = x + 1; y < 3; ++y)
            if (nrm[o[y]] > nrm[o[x]]) {
                int tmp = o[x];
                o[x] = o[y], o[y] = tmp;
            }
    double col[3][3], uc[3][3];
    for (int j = 0; j < 3; ++j)
        for (int r = 0; r < 3; ++r) col[j][r] = b.m[r][o[j]];
    /* U = [u1, u2, u1 x u2] is a rotation by construction; Gram-Schmidt keeps it orthonormal
     * and a vanishing column is replaced by a perpendicular direction. */
    for (int r = 0; r < 3; ++r) uc[0][r] = col[0][r] / nrm[o[0]];
    double d = uc[0][0] * col[1][0] + uc[0][1] * col[1][1] + uc[0][2] * col[1][2];
    double w[3] = {col[1][0] - d * uc[0][0], col[1][1] - d * uc[0][1], col[1][2] - d * uc[0][2]};
    double wn = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    if (!(wn > 1e-300)) {
        /* Any unit vector perpendicular to u1. */
        double e[3] = {0, 0, 0};
        int small = fabs(uc[0][0]) < fabs(uc[0][1]) ? (fabs(uc[0][0]) < fabs(uc[0][2]) ? 0 : 2)
                                                     : (fabs(uc[0][1]) < fabs(uc[0][2]) ? 1 : 2);
        e[small] = 1.0;
        cross3(uc[0], e, w);
        wn = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    }
    for (int r = 0; r < 3; ++r) uc[1][r] = w[r] / wn;
    cross3(uc[0], uc[1], uc[2]);
    s[0] = nrm[o[0]];
    s[1] = uc[1][0] * col[1][0] + uc[1][1] * col[1][1] + uc[1][2] * col[1][2];
    s[2] = uc[2][0] * col[2][0] + uc[2][1] * col[2][1] + uc[2][2] * col[2][2];
    for (int j = 0; j < 3; ++j)
        for (int r = 0; r < 3; ++r) {
            u->m[r][j] = uc[j][r];
            v->m[r][j] = vv.m[r][o[j]];
        }
    if (dm3_det(v) < 0.0) {
        /* A (-v3) = -s3 u3: flipping v3 keeps A = U S V^T and makes V a rotation. */
        for (int r = 0; r < 3; ++r) v->m[r][2] = -v->m[r][2];
        s[2] = -s[2];
    }
    for (int j = 0; j < 3; ++j) s[j] *= scale;
    return true;
}

ak_svd3 ak_mat3_svd(ak_mat3 m) {
    ak_svd3 out = {ak_mat3_identity(), {0.0f, 0.0f, 0.0f}, ak_mat3_identity()};
    dm3 a = dm3_from(m), u, v;
    double s[3];
    if (!dm3_finite(&a) || !svd3(&a, &u, s, &v)) return out;
    out.u = dm3_to(&u);
    out.v = dm3_to(&v);
    out.sigma = ak_vec3_make((float)s[0], (float)s[1], (float)s[2]);
    return out;
}

ak_polar ak_mat3_polar(ak_mat3 m) {
    ak_polar out = {ak_mat3_identity(), ak_mat3_identity(), 0, false};
    dm3 a = dm3_from(m);
    if (!dm3_finite(&a)) return out;
    double norm = dm3_frob(&a);
    if (norm == 0.0) {
        out.stretch = ak_mat3_scale(ak_mat3_identity(), 0.0f);
        return out;
    }
    double det = dm3_det(&a);
    dm3 x = a;
    bool converged = false;
    /* The Frobenius condition number |A| |A^-1| >= sigma_max / sigma_min; above 1e5 (or for
     * det <= 0, where the scheme would converge to a reflection) the SVD is used. */
    if (det > 0.0) {
        dm3 it = dm3_inverse_transpose(&a, det);
        if (norm * dm3_frob(&it) <= 1e5) {
            for (int i = 1; i <= 40 && !converged; ++i) {
                double dx = dm3_det(&x);
                if (!(dx > 0.0)) break;
                dm3 xit = dm3_inverse_transpose(&x, dx);
                double nx = dm3_frob(&x), ni = dm3_frob(&xit);
                /* Higham's scaling g = sqrt(|X^-1| / |X|) balances the singular values while
                 * they are far from 1; near convergence g -> 1 and plain averaging (quadratic
                 * convergence) takes over. */
                double g = sqrt(ni / nx);
                if (fabs(g - 1.0) < 1e-3) g = 1.0;
                dm3 y;
                double change = 0.0;
                for (int r = 0; r < 3; ++r)
                    for (int c = 0; c < 3; ++c) {
                        y.m[r][c] = 0.5 * (g * x.m[r][c] + xit.m[r][c] / g);
                        double dd = y.m[r][c] - x.m[r][c];
                        change += dd * dd;
                    }
                x = y;
                out.iterations = i;
                converged = sqrt(change) <= 1e-12 * dm3_frob(&x);
            }
        }
    }
    dm3 d;
    if (converged) {
        /* D = R^T A, symmetrised (it is symmetric up to rounding). */
        dm3 rt;
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
                rt.m[r][c] = x.m[0][r] * a.m[0][c] + x.m[1][r] * a.m[1][c] + x.m[2][r] * a.m[2][c];
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) d.m[r][c] = 0.5 * (rt.m[r][c] + rt.m[c][r]);
    } else {
        dm3 u, v;
        double s[3];
        svd3(&a, &u, s, &v);
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
                x.m[r][c] = u.m[r][0] * v.m[c][0] + u.m[r][1] * v.m[c][1] + u.m[r][2] * v.m[c][2];
        d = dm3_sym_from_eigen(&v, s);
        out.iterations = 0;
        out.used_svd = true;
    }
    out.rotation = dm3_to(&x);
    out.stretch = dm3_to(&d);
    return out;
}
