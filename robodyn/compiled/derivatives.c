/* robodyn.compiled derivatives: appended after runtime.c in a robot's derivative module
 * (see derivatives.py; the kernel rdd_tau_derivatives and the robot's kernels precede it).
 *
 * Python entry points (METH_FASTCALL; one state 1-D, a batch 2-D with one state a row):
 *   tau_derivatives(q, v, a, threads) -> (dtau_dq, dtau_dv, M)
 *   fd_derivatives(q, v, tau, threads) -> (dqdd_dq, dqdd_dv, Minv)
 *   info() -> {"nv", "instruction_set" (of batches: "scalar", "sse2", "avx2", "avx512"), "lanes"}
 * Each returns a tuple of three new float64 arrays (nv, nv) or (rows, nv, nv) (a batch's three: views
 * of one buffer, the allocation the next call reuses), or None when
 * an argument is not a C-contiguous native float64 array of the right shape (the caller then
 * checks and converts it), or an int status as the runtime's: 1 a non-finite input, 2 a
 * non-finite output, 3 a singular mass matrix. Batches run on `threads` POSIX threads with
 * the GIL released.
 */

/* The LDLᵀ is the runtime's (core.c's RD_LDL_DEFINE on doubles): rd_ldl_factor, rd_ldl_apply,
 * rd_ldl_apply_columns (the derivatives' own rdd_columns below: a reciprocal a row); the thread pool
 * too (core.c's rd_parallel). */

typedef int (*rdd_row)(const double *const *in, double *const *out);

/* P##columns(M, B, k): B -> M⁻¹ B for k columns at once (B n×k row-major), M factored by
 * rd_ldl_factor: core.c's ldl_apply_columns with the diagonal applied as one reciprocal a row
 * times each entry (a division an entry cost a block of 8 states 147 vector divisions, 20 % of
 * its time). The single call (tangent_single.py's rdd_apply) does the same operations, column c
 * in lane c, so the bits are the same everywhere. Q the qualifiers, T the type. */
#define RDD_COLUMNS_DEFINE(Q, P, T)                                                           \
    Q void P##columns(const T *M, T *B, int k) {                                              \
        const int n = RD_NV;                                                                  \
        for (int i = n - 1; i >= 0; --i)                                                      \
            for (int a = 0; a < rd_depth[i]; ++a) {                                           \
                const int j = rd_ancestor[i][a];                                              \
                const T x = M[i * n + j];                                                     \
                for (int c = 0; c < k; ++c) B[j * k + c] -= x * B[i * k + c];                 \
            }                                                                                 \
        for (int i = 0; i < n; ++i) {                                                         \
            const T r = 1.0 / M[i * n + i];                                                   \
            for (int c = 0; c < k; ++c) B[i * k + c] *= r;                                    \
        }                                                                                     \
        for (int i = 0; i < n; ++i)                                                           \
            for (int a = 0; a < rd_depth[i]; ++a) {                                           \
                const int j = rd_ancestor[i][a];                                              \
                const T x = M[i * n + j];                                                     \
                for (int c = 0; c < k; ++c) B[i * k + c] -= x * B[j * k + c];                 \
            }                                                                                 \
    }
RDD_COLUMNS_DEFINE(static inline __attribute__((always_inline)), rdd_, double)

/* rd_finite's answer on outputs (a row's, a block's), without a branch an entry: x * 0 is ±0 for a
 * finite x and NaN otherwise (four sums: no one chain of dependent additions). */
static inline int rdd_finite(const double *x, int n) {
    double z0 = 0.0, z1 = 0.0, z2 = 0.0, z3 = 0.0;
    int i = 0;
    for (; i + 4 <= n; i += 4) {
        z0 += x[i] * 0.0;
        z1 += x[i + 1] * 0.0;
        z2 += x[i + 2] * 0.0;
        z3 += x[i + 3] * 0.0;
    }
    for (; i < n; ++i) z0 += x[i] * 0.0;
    return (z0 + z1) + (z2 + z3) == 0.0;
}

static int rdd_row_tau(const double *const *in, double *const *out) {
    if (!rd_finite(in[0], RD_NV) || !rd_finite(in[1], RD_NV) || !rd_finite(in[2], RD_NV)) return 1;
    rdd_tau_derivatives(in[0], in[1], in[2], out[0], out[1]);
    rdd_single_mass(in[0], out[2]); /* rd_mass (tangent_single.py: for the single call's instruction set) */
    for (int k = 0; k < 3; ++k)
        if (!rdd_finite(out[k], RD_NV * RD_NV)) return 2;
    return 0;
}

/* The forward dynamics' part before the derivatives: M factored, a = q̈ (status 1 or 3). */
static int rdd_fd_start(const double *const *in, double *M, double *a) {
    const int n = RD_NV;
    if (!rd_finite(in[0], n) || !rd_finite(in[1], n) || !rd_finite(in[2], n)) return 1;
    rd_mass_nle(in[0], in[1], M, a);
    for (int i = 0; i < n; ++i) a[i] = in[2][i] - a[i];
    if (rd_ldl_factor(M)) return 3;
    rd_ldl_apply(M, a);
    return 0;
}

/* ... and after them: out = (−M⁻¹ ∂τ/∂q, −M⁻¹ ∂τ/∂v, M⁻¹), checked (status 3 if not finite). */
static int rdd_fd_finish(const double *M, double *const *out) {
    const int n = RD_NV;
    for (int i = 0; i < n * n; ++i) out[2][i] = (i % (n + 1)) == 0 ? 1.0 : 0.0;
    for (int k = 0; k < 3; ++k) rdd_columns(M, out[k], n);
    for (int i = 0; i < n * n; ++i) {
        out[0][i] = -out[0][i];
        out[1][i] = -out[1][i];
    }
    for (int k = 0; k < 3; ++k)
        if (!rd_finite(out[k], n * n)) return 3;
    return 0;
}

/* q̈ = M⁻¹ (τ − h); ∂q̈/∂x = −M⁻¹ ∂τ/∂x at a = q̈; ∂q̈/∂τ = M⁻¹ (one factorisation): the
 * generated rdd_fd_derivatives solves on the directions in SIMD lanes, rdd_fd_finish's
 * operations on each column (the same bits as the pairs' and blocks' column by column). */
static int rdd_row_fd(const double *const *in, double *const *out) {
    double M[RD_NV * RD_NV], a[RD_NV];
    const int status = rdd_single_start(in, M, a); /* rdd_fd_start, as rdd_single_mass */
    if (status) return status;
    rdd_fd_derivatives(in[0], in[1], a, M, out[0], out[1], out[2]);
    for (int k = 0; k < 3; ++k)
        if (!rdd_finite(out[k], RD_NV * RD_NV)) return 3;
    return 0;
}

/* Two rows at once (a batch): the derivative kernel on two states in SIMD lanes. */
typedef int (*rdd_pair)(const double *const *in0, const double *const *in1, double *const *out0, double *const *out1);

#if RDD_PAIRS
static int rdd_pair_tau(const double *const *in0, const double *const *in1, double *const *out0, double *const *out1) {
    for (int k = 0; k < 3; ++k)
        if (!rd_finite(in0[k], RD_NV) || !rd_finite(in1[k], RD_NV)) return 1;
    rdd_tau_derivatives2(in0[0], in0[1], in0[2], in1[0], in1[1], in1[2], out0[0], out0[1], out1[0], out1[1]);
    rd_mass(in0[0], out0[2]);
    rd_mass(in1[0], out1[2]);
    for (int k = 0; k < 3; ++k)
        if (!rd_finite(out0[k], RD_NV * RD_NV) || !rd_finite(out1[k], RD_NV * RD_NV)) return 2;
    return 0;
}

static int rdd_pair_fd(const double *const *in0, const double *const *in1, double *const *out0, double *const *out1) {
    double M0[RD_NV * RD_NV], a0[RD_NV], M1[RD_NV * RD_NV], a1[RD_NV];
    const int s0 = rdd_fd_start(in0, M0, a0), s1 = rdd_fd_start(in1, M1, a1);
    if (s0 || s1) return s0 > s1 ? s0 : s1;
    rdd_tau_derivatives2(in0[0], in0[1], a0, in1[0], in1[1], a1, out0[0], out0[1], out1[0], out1[1]);
    const int f0 = rdd_fd_finish(M0, out0), f1 = rdd_fd_finish(M1, out1);
    return f0 > f1 ? f0 : f1;
}
#endif

/* L rows at once (a batch): derivatives.py's rdd<L>_tau_derivatives, one per instruction set
 * built (RDD_BLOCKS(X) lists them as X(type, L, name, GCC target, target attribute)), the rest
 * of each row (its checks, M, the forward dynamics' factorisation and solves) as the single
 * call does it. A block's status is the worst of its rows'; a failing block's rows are done
 * again one by one (their exact statuses). RDD_BLOCKS's entries: X(type, L, name, GCC target,
 * target attribute, the SIMD dynamics' vector prefix, the exit's vzeroupper). */
typedef int (*rdd_block)(const double *const *in, double *const *out);

typedef struct {
    const char *name;
    int lanes;
    rdd_block tau, fd;
} rdd_variant;

/* count vectors of L lanes (x as doubles: entry e of lane l at x[e L + l]) -> L rows of count
 * entries (stride count): each row written in order. */
static inline __attribute__((always_inline)) void rdd_to_rows(const double *x, int count, int L, double *rows) {
    for (int l = 0; l < L; ++l)
        for (int e = 0; e < count; ++e) rows[l * count + e] = x[e * L + l];
}

/* The forward dynamics' part of a block around the derivatives: with the robot's SIMD
 * dynamics in the module (RD_SIMD: simd.py's rds<L>_mass_nle and tree LDLᵀ on vectors, the
 * same operations as the scalar ones in the same order), on L lanes at once; else row by row. */
#ifdef RD_SIMD
/* M of L rows (q: L rows of RD_NV, M: L rows of RD_NV²) by the SIMD dynamics' mass kernel. */
#define RDD_MASS(L, S, rows_q, rows_M)                                                                    \
    do {                                                                                                 \
        S q_[RD_NV], M_[RD_NV * RD_NV];                                                                  \
        S##_load(rows_q, RD_NV, q_);                                                                     \
        S##_mass(q_, M_);                                                                                \
        S##_store(M_, RD_NV * RD_NV, rows_M);                                                            \
    } while (0)
#define RDD_FD_BLOCK(T, L, S, ATTR)                                                                       \
    RDD_COLUMNS_DEFINE(static inline __attribute__((always_inline)) ATTR, T##_, T)                       \
    static ATTR int T##_fd_inner(const double *const *in, double *const *out) {                          \
        const Py_ssize_t n = RD_NV;                                                                      \
        S q[RD_NV], v[RD_NV], tau[RD_NV], M[RD_NV * RD_NV], h[RD_NV], X[3][RD_NV * RD_NV];                \
        double acc[L * RD_NV];                                                                           \
        S##_load(in[0], RD_NV, q);                                                                       \
        S##_load(in[1], RD_NV, v);                                                                       \
        S##_load(in[2], RD_NV, tau);                                                                     \
        if (S##_bad(q, RD_NV) || S##_bad(v, RD_NV) || S##_bad(tau, RD_NV)) return 1;                    \
        S##_mass_nle(q, v, M, h);                                                                        \
        for (int i = 0; i < RD_NV; ++i) h[i] = tau[i] - h[i];                                            \
        if (S##_ldl_factor(M)) return 3;                                                                 \
        S##_ldl_apply(M, h);                                                                             \
        S##_store(h, RD_NV, acc);                                                                        \
        const double *qs[L], *vs[L], *as[L];                                                             \
        for (int l = 0; l < L; ++l) qs[l] = in[0] + l * n, vs[l] = in[1] + l * n, as[l] = acc + l * n;   \
        T##_tau_derivatives(qs, vs, as, X[0], X[1]);                                                     \
        for (int i = 0; i < RD_NV * RD_NV; ++i) X[2][i] = S##_splat((i % (RD_NV + 1)) == 0 ? 1.0 : 0.0); \
        for (int k = 0; k < 3; ++k) {                                                                    \
            T##_columns(M, X[k], RD_NV);                                                                 \
            if (k < 2)                                                                                   \
                for (int i = 0; i < RD_NV * RD_NV; ++i) X[k][i] = -X[k][i];                              \
            if (S##_bad(X[k], RD_NV * RD_NV)) return 3;                                                  \
        }                                                                                                \
        for (int k = 0; k < 3; ++k) rdd_to_rows((const double *)X[k], RD_NV * RD_NV, L, out[k]);           \
        return 0;                                                                                        \
    }
#else
#define RDD_MASS(L, S, rows_q, rows_M)                                                                    \
    for (int l = 0; l < L; ++l) rd_mass((rows_q) + l * RD_NV, (rows_M) + l * RD_NV * RD_NV)
#define RDD_FD_BLOCK(T, L, S, ATTR)                                                                       \
    static ATTR int T##_fd_inner(const double *const *in, double *const *out) {                          \
        const Py_ssize_t n = RD_NV, size = RD_NV * RD_NV;                                                \
        double M[L][RD_NV * RD_NV], acc[L][RD_NV];                                                       \
        const double *q[L], *v[L], *a[L];                                                                \
        T dq[RD_NV * RD_NV], dv[RD_NV * RD_NV];                                                          \
        for (int l = 0; l < L; ++l) {                                                                    \
            const double *row[3] = {in[0] + l * n, in[1] + l * n, in[2] + l * n};                        \
            const int status = rdd_fd_start(row, M[l], acc[l]);                                          \
            if (status) return status;                                                                   \
            q[l] = row[0], v[l] = row[1], a[l] = acc[l];                                                 \
        }                                                                                                \
        T##_tau_derivatives(q, v, a, dq, dv);                                                            \
        rdd_to_rows((const double *)dq, RD_NV * RD_NV, L, out[0]);                                          \
        rdd_to_rows((const double *)dv, RD_NV * RD_NV, L, out[1]);                                          \
        int worst = 0;                                                                                   \
        for (int l = 0; l < L; ++l) {                                                                    \
            double *const row[3] = {out[0] + l * size, out[1] + l * size, out[2] + l * size};            \
            const int status = rdd_fd_finish(M[l], row);                                                 \
            if (status > worst) worst = status;                                                          \
        }                                                                                                \
        return worst;                                                                                    \
    }
#endif

#define RDD_BLOCK_DEFINE(T, L, NAME, TARGET, ATTR, S, VZEROUPPER)                                         \
    static ATTR int T##_tau_inner(const double *const *in, double *const *out) {                         \
        const Py_ssize_t n = RD_NV, size = RD_NV * RD_NV;                                                \
        const double *q[L], *v[L], *a[L];                                                                \
        T dq[RD_NV * RD_NV], dv[RD_NV * RD_NV];                                                          \
        for (int l = 0; l < L; ++l) {                                                                    \
            q[l] = in[0] + l * n, v[l] = in[1] + l * n, a[l] = in[2] + l * n;                            \
            if (!rd_finite(q[l], RD_NV) || !rd_finite(v[l], RD_NV) || !rd_finite(a[l], RD_NV)) return 1; \
        }                                                                                                \
        T##_tau_derivatives(q, v, a, dq, dv);                                                            \
        rdd_to_rows((const double *)dq, RD_NV * RD_NV, L, out[0]);                                          \
        rdd_to_rows((const double *)dv, RD_NV * RD_NV, L, out[1]);                                          \
        RDD_MASS(L, S, in[0], out[2]);                                                                   \
        for (int l = 0; l < L; ++l)                                                                      \
            for (int k = 0; k < 3; ++k)                                                                  \
                if (!rdd_finite(out[k] + l * size, RD_NV * RD_NV)) return 2;                             \
        return 0;                                                                                        \
    }                                                                                                    \
    RDD_FD_BLOCK(T, L, S, ATTR)                                                                          \
    /* each clears the vector registers' upper halves on its way out (see simd.c) */                     \
    static ATTR int T##_block_tau(const double *const *in, double *const *out) {                         \
        const int status = T##_tau_inner(in, out);                                                       \
        VZEROUPPER                                                                                       \
        return status;                                                                                   \
    }                                                                                                    \
    static ATTR int T##_block_fd(const double *const *in, double *const *out) {                          \
        const int status = T##_fd_inner(in, out);                                                        \
        VZEROUPPER                                                                                       \
        return status;                                                                                   \
    }                                                                                                    \
    static const rdd_variant T##_variant = {NAME, L, T##_block_tau, T##_block_fd};

#define RDD_CHOOSE(T, L, NAME, TARGET, ATTR, S, VZEROUPPER) \
    if (!chosen && __builtin_cpu_supports(TARGET)) chosen = &T##_variant;

RDD_BLOCKS(RDD_BLOCK_DEFINE)

/* The widest variant built that this CPU runs (chosen once), or NULL: rows and pairs. */
static const rdd_variant *rdd_current(void) {
    static int chosen_yet = 0;
    static const rdd_variant *current = NULL;
    if (!chosen_yet) {
        const rdd_variant *chosen = NULL;
#if defined(__x86_64__) && defined(__GNUC__)
        __builtin_cpu_init();
        RDD_BLOCKS(RDD_CHOOSE)
#endif
        current = chosen;
        chosen_yet = 1;
    }
    return current;
}

typedef struct {
    rdd_row row;
    rdd_pair pair; /* NULL: one row at a time */
    rdd_block block; /* NULL: no blocks of lanes rows */
    int lanes;
    const double *in[3];
    double *out[3];
} rdd_job;

/* Rows [begin, end) of a batch, two at a time where the kernel has pairs (core.c's rd_range). */
static int rdd_rows(const void *work, Py_ssize_t begin, Py_ssize_t end) {
    const rdd_job *job = (const rdd_job *)work;
    int worst = 0;
    const Py_ssize_t size = RD_NV * RD_NV;
    for (Py_ssize_t r = begin; r < end;) {
        const double *in[3] = {job->in[0] + r * RD_NV, job->in[1] + r * RD_NV, job->in[2] + r * RD_NV};
        double *out[3] = {job->out[0] + r * size, job->out[1] + r * size, job->out[2] + r * size};
        int status;
        if (job->block && r + job->lanes <= end) {
            status = job->block(in, out);
            if (status) { /* its rows again one by one: their exact statuses */
                status = 0;
                for (int l = 0; l < job->lanes; ++l) {
                    const double *row_in[3] = {in[0] + l * RD_NV, in[1] + l * RD_NV, in[2] + l * RD_NV};
                    double *row_out[3] = {out[0] + l * size, out[1] + l * size, out[2] + l * size};
                    const int row_status = job->row(row_in, row_out);
                    if (row_status > status) status = row_status;
                }
            }
            r += job->lanes;
        } else if (job->pair && r + 1 < end) {
            const double *in1[3] = {in[0] + RD_NV, in[1] + RD_NV, in[2] + RD_NV};
            double *out1[3] = {out[0] + size, out[1] + size, out[2] + size};
            status = job->pair(in, in1, out, out1);
            r += 2;
        } else {
            status = job->row(in, out);
            r += 1;
        }
        if (status > worst) worst = status;
    }
    return worst;
}

static PyObject *rdd_entry(PyObject *const *args, Py_ssize_t nargs, rdd_row row, rdd_pair pair) {
    if (nargs != 4) {
        PyErr_SetString(PyExc_TypeError, "wrong number of arguments");
        return NULL;
    }
    const long threads = PyLong_AsLong(args[3]);
    if (threads == -1 && PyErr_Occurred()) return NULL;
    int ndim = 0;
    npy_intp rows = 1;
    for (int k = 0; k < 3; ++k)
        if (!rd_accept(args[k], &ndim, &rows)) Py_RETURN_NONE;
    npy_intp dims[3] = {rows, RD_NV, RD_NV};
    PyObject *result = PyTuple_New(3);
    if (!result) return NULL;
    const rdd_variant *variant = ndim == 2 ? rdd_current() : NULL;
    rdd_job job = {row, pair, NULL, 1, {0, 0, 0}, {0, 0, 0}};
    if (variant) {
        job.block = row == rdd_row_tau ? variant->tau : variant->fd;
        job.lanes = variant->lanes;
    }
    /* A batch's three results share one buffer (one allocation: the allocator keeps it for the
     * next call, where three would be returned to the system and their pages faulted in again). */
    npy_intp whole[4] = {3, rows, RD_NV, RD_NV};
    PyObject *base = ndim == 2 ? PyArray_SimpleNew(4, whole, NPY_DOUBLE) : NULL;
    if (ndim == 2 && !base) {
        Py_DECREF(result);
        return NULL;
    }
    for (int k = 0; k < 3; ++k) {
        PyObject *out;
        if (base) {
            double *data = (double *)PyArray_DATA((PyArrayObject *)base) + k * rows * RD_NV * RD_NV;
            out = PyArray_NewFromDescr(&PyArray_Type, PyArray_DescrFromType(NPY_DOUBLE), 3, dims, NULL, data,
                                       NPY_ARRAY_CARRAY, NULL);
            Py_INCREF(base); /* the view's reference, which PyArray_SetBaseObject steals */
            if (out && PyArray_SetBaseObject((PyArrayObject *)out, base) < 0) Py_CLEAR(out);
        } else {
            out = PyArray_SimpleNew(1 + 1, dims + 1, NPY_DOUBLE);
        }
        if (!out) {
            Py_XDECREF(base);
            Py_DECREF(result);
            return NULL;
        }
        PyTuple_SET_ITEM(result, k, out);
        job.in[k] = (const double *)PyArray_DATA((PyArrayObject *)args[k]);
        job.out[k] = (double *)PyArray_DATA((PyArrayObject *)out);
    }
    Py_XDECREF(base);
    int status;
    if (ndim == 1) {
        status = row(job.in, job.out);
    } else {
        Py_BEGIN_ALLOW_THREADS
        status = rd_parallel(rdd_rows, &job, rows, job.lanes, threads);
        Py_END_ALLOW_THREADS
    }
    if (status) {
        Py_DECREF(result);
        return PyLong_FromLong(status);
    }
    return result;
}

#if RDD_PAIRS
#define RDD_PAIR_TAU rdd_pair_tau
#define RDD_PAIR_FD rdd_pair_fd
#else
#define RDD_PAIR_TAU NULL
#define RDD_PAIR_FD NULL
#endif
static PyObject *py_tau_derivatives(PyObject *m, PyObject *const *a, Py_ssize_t n) { return rdd_entry(a, n, rdd_row_tau, RDD_PAIR_TAU); }
static PyObject *py_fd_derivatives(PyObject *m, PyObject *const *a, Py_ssize_t n) { return rdd_entry(a, n, rdd_row_fd, RDD_PAIR_FD); }

static PyObject *py_derivative_info(PyObject *m, PyObject *unused) {
    const rdd_variant *variant = rdd_current();
    return Py_BuildValue("{s:i,s:s,s:i}", "nv", RD_NV, "instruction_set", variant ? variant->name : "scalar", "lanes",
                         variant ? variant->lanes : (RDD_PAIRS ? 2 : 1));
}

static PyMethodDef rdd_methods[] = {
    {"tau_derivatives", (PyCFunction)(void (*)(void))py_tau_derivatives, METH_FASTCALL, "tau_derivatives(q, v, a, threads)"},
    {"fd_derivatives", (PyCFunction)(void (*)(void))py_fd_derivatives, METH_FASTCALL, "fd_derivatives(q, v, tau, threads)"},
    {"info", py_derivative_info, METH_NOARGS, "info()"},
    {NULL, NULL, 0, NULL},
};

static PyObject *rdd_module(const char *name) {
    import_array1(NULL);
    static struct PyModuleDef definition = {PyModuleDef_HEAD_INIT, NULL, "robodyn compiled derivatives", -1, rdd_methods};
    definition.m_name = name;
    return PyModule_Create(&definition);
}
