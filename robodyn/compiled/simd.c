/* robodyn.compiled SIMD blocks: one instruction set's variant (see simd.py, which writes
 * this text once per variant with rdsT the vector type of RDS_L doubles and RDS_TARGET its
 * target attribute, after that variant's vector kernels rdsT_tau, rdsT_mass, ...).
 *
 * A block is RDS_L consecutive rows of a batch (row-major, as the runtime's rows): they are
 * transposed into structure-of-arrays vectors (entry j of every row in one vector), run
 * through the vector kernels (the scalar kernels' statements on vectors: the same IEEE
 * operations in the same order, sin/cos the kernels' own on vectors), and transposed back. Each
 * block returns the runtime's row status: 1 a non-finite input, 2 a non-finite output, 3 a
 * singular mass matrix (forward dynamics), the worst of its rows.
 */

/* 1 if an entry of n vectors is not finite (x * 0 is 0 for finite x, NaN otherwise). */
static inline __attribute__((always_inline)) RDS_TARGET int rdsT_bad(const rdsT *x, int n) {
    rdsT zero = x[0] * 0.0;
    for (int j = 1; j < n; ++j) zero += x[j] * 0.0;
    int bad = 0;
    for (int l = 0; l < RDS_L; ++l) bad |= zero[l] != 0.0;
    return bad;
}

/* RDS_L rows of n entries (stride n) -> n vectors. */
static inline __attribute__((always_inline)) RDS_TARGET void rdsT_load(const double *rows, int n, rdsT *out) {
    for (int j = 0; j < n; ++j) out[j] = rdsT_gather(rows + j, n);
}

/* n vectors -> RDS_L rows of n entries (stride n). */
static inline __attribute__((always_inline)) RDS_TARGET void rdsT_store(const rdsT *in, int n, double *rows) {
    for (int j = 0; j < n; ++j) {
        const rdsT x = in[j];
        RDS_SCATTER
    }
}

static RDS_TARGET int rdsT_block_tau(const double *const *in, double *out) {
    rdsT q[RD_NV], v[RD_NV], a[RD_NV], tau[RD_NV];
    rdsT_load(in[0], RD_NV, q);
    rdsT_load(in[1], RD_NV, v);
    rdsT_load(in[2], RD_NV, a);
    if (rdsT_bad(q, RD_NV) || rdsT_bad(v, RD_NV) || rdsT_bad(a, RD_NV)) return 1;
    rdsT_tau(q, v, a, tau);
    if (rdsT_bad(tau, RD_NV)) return 2;
    rdsT_store(tau, RD_NV, out);
    return 0;
}

static RDS_TARGET int rdsT_block_mass(const double *const *in, double *out) {
    rdsT q[RD_NV], M[RD_NV * RD_NV];
    rdsT_load(in[0], RD_NV, q);
    if (rdsT_bad(q, RD_NV)) return 1;
    rdsT_mass(q, M);
    if (rdsT_bad(M, RD_NV * RD_NV)) return 2;
    rdsT_store(M, RD_NV * RD_NV, out);
    return 0;
}

static RDS_TARGET int rdsT_block_nle(const double *const *in, double *out) {
    rdsT q[RD_NV], v[RD_NV], h[RD_NV];
    rdsT_load(in[0], RD_NV, q);
    rdsT_load(in[1], RD_NV, v);
    if (rdsT_bad(q, RD_NV) || rdsT_bad(v, RD_NV)) return 1;
    rdsT_nle(q, v, h);
    if (rdsT_bad(h, RD_NV)) return 2;
    rdsT_store(h, RD_NV, out);
    return 0;
}

static RDS_TARGET int rdsT_block_gravity(const double *const *in, double *out) {
    rdsT q[RD_NV], g[RD_NV];
    rdsT_load(in[0], RD_NV, q);
    if (rdsT_bad(q, RD_NV)) return 1;
    rdsT_gravity(q, g);
    if (rdsT_bad(g, RD_NV)) return 2;
    rdsT_store(g, RD_NV, out);
    return 0;
}

/* rdsT_ldl_solve(M, b), instantiated by simd.py before this text from core.c's RD_LDL_DEFINE:
 * the runtime's rd_ldl_solve on every lane at once (the same operations in the same order; 3
 * if a pivot of any lane is not positive and finite). */

static RDS_TARGET int rdsT_block_fd(const double *const *in, double *out) {
    rdsT q[RD_NV], v[RD_NV], tau[RD_NV], M[RD_NV * RD_NV], a[RD_NV];
    rdsT_load(in[0], RD_NV, q);
    rdsT_load(in[1], RD_NV, v);
    rdsT_load(in[2], RD_NV, tau);
    if (rdsT_bad(q, RD_NV) || rdsT_bad(v, RD_NV) || rdsT_bad(tau, RD_NV)) return 1;
    rdsT_mass_nle(q, v, M, a);
    for (int i = 0; i < RD_NV; ++i) a[i] = tau[i] - a[i];
    if (rdsT_ldl_solve(M, a) || rdsT_bad(a, RD_NV)) return 3;
    rdsT_store(a, RD_NV, out);
    return 0;
}

/* The blocks as the runtime calls them: each clears the vector registers' upper halves on
 * its way out (RDS_VZEROUPPER: vzeroupper for AVX variants; -O1 does not insert it), or the
 * SSE code that runs next (the scalar kernels, numpy, Python) runs ~3 times slower. */
static RDS_TARGET int rdsT_out_tau(const double *const *in, double *out) {
    const int status = rdsT_block_tau(in, out);
    RDS_VZEROUPPER
    return status;
}
static RDS_TARGET int rdsT_out_mass(const double *const *in, double *out) {
    const int status = rdsT_block_mass(in, out);
    RDS_VZEROUPPER
    return status;
}
static RDS_TARGET int rdsT_out_nle(const double *const *in, double *out) {
    const int status = rdsT_block_nle(in, out);
    RDS_VZEROUPPER
    return status;
}
static RDS_TARGET int rdsT_out_gravity(const double *const *in, double *out) {
    const int status = rdsT_block_gravity(in, out);
    RDS_VZEROUPPER
    return status;
}
static RDS_TARGET int rdsT_out_fd(const double *const *in, double *out) {
    const int status = rdsT_block_fd(in, out);
    RDS_VZEROUPPER
    return status;
}

static const rds_blocks rdsT_blocks = {RDS_NAME, RDS_L, rdsT_out_tau, rdsT_out_mass, rdsT_out_nle,
                                       rdsT_out_gravity, rdsT_out_fd};
