/* robodyn.compiled runtime: appended to a robot's generated kernels (see codegen.py).
 *
 * Python entry points (METH_FASTCALL; one state 1-D, a batch 2-D with one state a row):
 *   tau(q, v, a, threads), mass(q, threads), nle(q, v, threads), gravity(q, threads),
 *   fd(q, v, tau, threads)
 * Each returns a new float64 array, or None when an argument is not a C-contiguous native
 * float64 array of the right shape (the caller then checks and converts it), or an int
 * status: 1 a non-finite input, 2 a non-finite output, 3 a singular mass matrix.
 * Batches run across rows on `threads` POSIX threads with the GIL released; where the
 * module has SIMD variants (robodyn/compiled/simd.py, RD_SIMD), several rows at a time:
 *   simd([name]) -> the instruction set batches run ("scalar", "sse2", "avx2", "avx512"),
 *   after choosing `name`; info() names it ("instruction_set", "lanes", "instruction_sets").
 *
 *   simulate(q0, v0, dt, steps, t0, rk4, kind, hold, params, controller, out_q, out_v,
 *            out_a, out_tau[, frame]) -> -1, or the step after which the state stopped being finite
 * integrates in C (RK4 or semi-implicit Euler); kind 0 holds params[0:n] as the torque,
 * the others are the controllers' compiled twins (robodyn/compiled/controllers.py declares
 * each one's kind RD_KIND_<LAW> and parameter layout RD_<LAW>_<FIELD>(n), generated as C
 * macros prepended to this file), on the controller's model (a capsule of another compiled
 * robot's kernels, `_kernels`) and, for the frame laws, a frame's kernels (the capsule
 * `_frame` of a frame module, robodyn/compiled/kinematics.py). */

#ifndef RD_NQ
#define RD_NQ RD_NV /* a floating base's q has one entry more than v (its quaternion) */
#endif
#define RD_CAPSULE "robodyn.compiled.kernels"

typedef struct {
    int nv;
    void (*tau)(const double *, const double *, const double *, double *);
    void (*mass)(const double *, double *);
    void (*nle)(const double *, const double *, double *);
    void (*gravity)(const double *, double *);
    void (*mass_nle)(const double *, const double *, double *, double *);
} rd_kernels;

static const rd_kernels rd_self = {RD_NV, rd_tau, rd_mass, rd_nle, rd_gravity, rd_mass_nle};

static int rd_finite(const double *x, int n) {
    for (int i = 0; i < n; ++i)
        if (!isfinite(x[i])) return 0;
    return 1;
}

/* A finite q; a floating base's quaternion unit within RD_QUATERNION_TOLERANCE (as
 * robodyn.dynamics.handle's validate: anything else goes back to the checked path, its error). */
static int rd_q_ok(const double *q) {
    if (!rd_finite(q, RD_NQ)) return 0;
#if RD_NQ != RD_NV
    const double norm = sqrt(q[3] * q[3] + q[4] * q[4] + q[5] * q[5] + q[6] * q[6]);
    if (!(fabs(norm - 1.0) < RD_QUATERNION_TOLERANCE)) return 0;
#endif
    return 1;
}

/* The tree LDLᵀ on doubles (core.c's RD_LDL_DEFINE): rd_ldl_factor, rd_ldl_apply,
 * rd_ldl_apply_columns, rd_ldl_solve. */
static inline int rd_pivot_bad(double d) { return !(d > 0.0) || !isfinite(d); }
RD_LDL_DEFINE(__attribute__((unused)) static, rd_, double)

/* Forward dynamics of one state, no checks: 0, or 3 for a singular mass matrix. */
static int rd_fd_raw(const double *q, const double *v, const double *tau, double *a) {
    double M[RD_NV * RD_NV], h[RD_NV];
    rd_mass_nle(q, v, M, h);
    for (int i = 0; i < RD_NV; ++i) a[i] = tau[i] - h[i];
    return rd_ldl_solve(M, a);
}

/* ---- one row of a batch: checks inputs, computes, checks outputs ---------------------- */
typedef int (*rd_row)(const double *const *in, double *out);

static int row_tau(const double *const *in, double *out) {
    if (!rd_q_ok(in[0]) || !rd_finite(in[1], RD_NV) || !rd_finite(in[2], RD_NV)) return 1;
    rd_tau(in[0], in[1], in[2], out);
    return rd_finite(out, RD_NV) ? 0 : 2;
}
static int row_mass(const double *const *in, double *out) {
    if (!rd_q_ok(in[0])) return 1;
    rd_mass(in[0], out);
    return rd_finite(out, RD_NV * RD_NV) ? 0 : 2;
}
static int row_nle(const double *const *in, double *out) {
    if (!rd_q_ok(in[0]) || !rd_finite(in[1], RD_NV)) return 1;
    rd_nle(in[0], in[1], out);
    return rd_finite(out, RD_NV) ? 0 : 2;
}
static int row_gravity(const double *const *in, double *out) {
    if (!rd_q_ok(in[0])) return 1;
    rd_gravity(in[0], out);
    return rd_finite(out, RD_NV) ? 0 : 2;
}
static int row_fd(const double *const *in, double *out) {
    if (!rd_q_ok(in[0]) || !rd_finite(in[1], RD_NV) || !rd_finite(in[2], RD_NV)) return 1;
    if (rd_fd_raw(in[0], in[1], in[2], out)) return 3;
    return rd_finite(out, RD_NV) ? 0 : 3;
}

typedef struct {
    rd_row row;
    int nin, out_size;
    const double *in[3];
    double *out;
    rd_row block; /* SIMD: `lanes` rows at once (robodyn.compiled.simd), or NULL */
    int lanes;
} rd_job;

/* Rows [begin, end) of a batch (core.c's rd_range, run by its thread pool rd_parallel). */
static int rd_rows(const void *work, Py_ssize_t begin, Py_ssize_t end) {
    const rd_job *job = (const rd_job *)work;
    int worst = 0;
    const double *in[3] = {0, 0, 0};
    Py_ssize_t r = begin;
    if (job->block) /* blocks of `lanes` rows; a failing block's rows again one by one (their exact statuses) */
        for (; r + job->lanes <= end; r += job->lanes) {
            for (int k = 0; k < job->nin; ++k) in[k] = job->in[k] + r * (k ? RD_NV : RD_NQ);
            if (!job->block(in, job->out + r * job->out_size)) continue;
            for (Py_ssize_t s = r; s < r + job->lanes; ++s) {
                for (int k = 0; k < job->nin; ++k) in[k] = job->in[k] + s * (k ? RD_NV : RD_NQ);
                const int status = job->row(in, job->out + s * job->out_size);
                if (status > worst) worst = status;
            }
        }
    for (; r < end; ++r) {
        for (int k = 0; k < job->nin; ++k) in[k] = job->in[k] + r * (k ? RD_NV : RD_NQ);
        const int status = job->row(in, job->out + r * job->out_size);
        if (status > worst) worst = status;
    }
    return worst;
}

/* A C-contiguous, aligned, native float64 array of shape (width,) or (rows, width). */
static int rd_accept_width(PyObject *object, int *ndim, npy_intp *rows, npy_intp width) {
    if (!PyArray_CheckExact(object)) return 0;
    PyArrayObject *array = (PyArrayObject *)object;
    if (PyArray_TYPE(array) != NPY_DOUBLE || !PyArray_ISCARRAY_RO(array) || !PyArray_ISNOTSWAPPED(array)) return 0;
    const int nd = PyArray_NDIM(array);
    const npy_intp *dims = PyArray_DIMS(array);
    if (nd == 1 && dims[0] == width) {
        if (*ndim == 2) return 0;
        *ndim = 1;
        return 1;
    }
    if (nd == 2 && dims[1] == width) {
        if (*ndim == 1 || (*ndim == 2 && *rows != dims[0])) return 0;
        *ndim = 2;
        *rows = dims[0];
        return 1;
    }
    return 0;
}

/* The same of width RD_NV (a velocity-sized argument; the derivative kernels' entry points). */
static inline int rd_accept(PyObject *object, int *ndim, npy_intp *rows) { return rd_accept_width(object, ndim, rows, RD_NV); }

/* The job's SIMD block for its row kernel, in the instruction set chosen (none: scalar rows). */
static void rd_simd_block(rd_job *job) {
    job->block = NULL;
    job->lanes = 1;
#ifdef RD_SIMD
    const rds_blocks *b = rds_current();
    if (!b) return;
    job->lanes = b->lanes;
    if (job->row == row_tau) job->block = b->tau;
    if (job->row == row_mass) job->block = b->mass;
    if (job->row == row_nle) job->block = b->nle;
    if (job->row == row_gravity) job->block = b->gravity;
    if (job->row == row_fd) job->block = b->fd;
#endif
}

static PyObject *rd_entry(PyObject *const *args, Py_ssize_t nargs, int nin, rd_row row, int matrix) {
    if (nargs != nin + 1) {
        PyErr_SetString(PyExc_TypeError, "wrong number of arguments");
        return NULL;
    }
    const long threads = PyLong_AsLong(args[nin]);
    if (threads == -1 && PyErr_Occurred()) return NULL;
    int ndim = 0;
    npy_intp rows = 1;
    for (int k = 0; k < nin; ++k)
        if (!rd_accept_width(args[k], &ndim, &rows, k ? RD_NV : RD_NQ)) Py_RETURN_NONE;
    npy_intp dims[3];
    int out_nd = 0;
    if (ndim == 2) dims[out_nd++] = rows;
    dims[out_nd++] = RD_NV;
    if (matrix) dims[out_nd++] = RD_NV;
    PyObject *out = PyArray_SimpleNew(out_nd, dims, NPY_DOUBLE);
    if (!out) return NULL;
    rd_job job = {row, nin, matrix ? RD_NV * RD_NV : RD_NV, {0, 0, 0}, (double *)PyArray_DATA((PyArrayObject *)out), NULL, 1};
    for (int k = 0; k < nin; ++k) job.in[k] = (const double *)PyArray_DATA((PyArrayObject *)args[k]);
    rd_simd_block(&job);
    int status;
    if (ndim == 1) {
        status = row(job.in, job.out);
    } else {
        Py_BEGIN_ALLOW_THREADS
        status = rd_parallel(rd_rows, &job, rows, job.block ? job.lanes : 1, threads);
        Py_END_ALLOW_THREADS
    }
    if (status) {
        Py_DECREF(out);
        return PyLong_FromLong(status);
    }
    return out;
}

static PyObject *py_tau(PyObject *m, PyObject *const *a, Py_ssize_t n) { return rd_entry(a, n, 3, row_tau, 0); }
static PyObject *py_mass(PyObject *m, PyObject *const *a, Py_ssize_t n) { return rd_entry(a, n, 1, row_mass, 1); }
static PyObject *py_nle(PyObject *m, PyObject *const *a, Py_ssize_t n) { return rd_entry(a, n, 2, row_nle, 0); }
static PyObject *py_gravity(PyObject *m, PyObject *const *a, Py_ssize_t n) { return rd_entry(a, n, 1, row_gravity, 0); }
static PyObject *py_fd(PyObject *m, PyObject *const *a, Py_ssize_t n) { return rd_entry(a, n, 3, row_fd, 0); }

/* ---- simulation ------------------------------------------------------------------------ */
typedef struct {
    int kind, hold;
    const double *params;
    const rd_kernels *model;
    const void *frame; /* the frame laws: the controlled frame's rd_frame_kernels */
    const double *damping; /* the plant's joint damping b (the torque − b v at every stage), or NULL */
} rd_controller;

/* ---- compiled frame controllers (task space, operational space, impedance) -------------
 * Each is the Python controller of robodyn.sim (control.py, operational_space.py), formula
 * for formula, on the controller's model (rd_kernels) and one frame's kinematics
 * (rd_frame_kernels, the capsule `_frame` of a frame module, see kinematics.py). */

#define RD_FRAME_CAPSULE "robodyn.compiled.frame"

typedef struct {
    int nv;
    void (*pose)(const double *, double *, double *);
    void (*jacobian)(const double *, double *);
    void (*all)(const double *, const double *, double *, double *, double *, double *);
} rd_frame_kernels;

/* Solve A X = B in place (A m×m destroyed, B m×k, both row-major): Gaussian elimination with
 * partial pivoting (numpy.linalg.solve's LU). */
static void rdc_solve(double *A, double *B, int m, int k) {
    for (int c = 0; c < m; ++c) {
        int pivot = c;
        for (int r = c + 1; r < m; ++r)
            if (fabs(A[r * m + c]) > fabs(A[pivot * m + c])) pivot = r;
        if (pivot != c) {
            for (int j = 0; j < m; ++j) { const double x = A[c * m + j]; A[c * m + j] = A[pivot * m + j]; A[pivot * m + j] = x; }
            for (int j = 0; j < k; ++j) { const double x = B[c * k + j]; B[c * k + j] = B[pivot * k + j]; B[pivot * k + j] = x; }
        }
        for (int r = c + 1; r < m; ++r) {
            const double f = A[r * m + c] / A[c * m + c];
            for (int j = c; j < m; ++j) A[r * m + j] -= f * A[c * m + j];
            for (int j = 0; j < k; ++j) B[r * k + j] -= f * B[c * k + j];
        }
    }
    for (int c = m - 1; c >= 0; --c)
        for (int j = 0; j < k; ++j) {
            double x = B[c * k + j];
            for (int r = c + 1; r < m; ++r) x -= A[c * m + r] * B[r * k + j];
            B[c * k + j] = x / A[c * m + c];
        }
}

/* rd_ldl_apply on k right-hand sides at once, B n×k row-major (B[j k + c] is b_c[j]): each
 * column gets rd_ldl_apply's operations in its order (the same bits), the tree walked once. */
static void rdc_ldl_apply_block(const double *M, double *B, int k) {
    const int n = RD_NV;
    for (int i = n - 1; i >= 0; --i)
        for (int j = rd_parent[i]; j >= 0; j = rd_parent[j]) {
            const double x = M[i * n + j];
            for (int c = 0; c < k; ++c) B[j * k + c] -= x * B[i * k + c];
        }
    for (int i = 0; i < n; ++i) {
        const double d = M[i * n + i];
        for (int c = 0; c < k; ++c) B[i * k + c] /= d;
    }
    for (int i = 0; i < n; ++i)
        for (int j = rd_parent[i]; j >= 0; j = rd_parent[j]) {
            const double x = M[i * n + j];
            for (int c = 0; c < k; ++c) B[i * k + c] -= x * B[j * k + c];
        }
}

/* Eigen-decomposition of a symmetric m×m matrix (its lower triangle, as numpy's eigh): Householder
 * tridiagonalisation + implicit QL (EISPACK tred2/tql2, as in Numerical Recipes). */
static void rdc_tred2(double *a, int n, double *d, double *e) {
    for (int i = n - 1; i > 0; --i) {
        const int l = i - 1;
        double h = 0.0, scale = 0.0;
        if (l > 0) {
            for (int k = 0; k <= l; ++k) scale += fabs(a[i * n + k]);
            if (scale == 0.0) {
                e[i] = a[i * n + l];
            } else {
                for (int k = 0; k <= l; ++k) {
                    a[i * n + k] /= scale;
                    h += a[i * n + k] * a[i * n + k];
                }
                double f = a[i * n + l];
                double g = f >= 0.0 ? -sqrt(h) : sqrt(h);
                e[i] = scale * g;
                h -= f * g;
                a[i * n + l] = f - g;
                f = 0.0;
                for (int j = 0; j <= l; ++j) {
                    a[j * n + i] = a[i * n + j] / h;
                    g = 0.0;
                    for (int k = 0; k <= j; ++k) g += a[j * n + k] * a[i * n + k];
                    for (int k = j + 1; k <= l; ++k) g += a[k * n + j] * a[i * n + k];
                    e[j] = g / h;
                    f += e[j] * a[i * n + j];
                }
                const double hh = f / (h + h);
                for (int j = 0; j <= l; ++j) {
                    f = a[i * n + j];
                    e[j] = g = e[j] - hh * f;
                    for (int k = 0; k <= j; ++k) a[j * n + k] -= f * e[k] + g * a[i * n + k];
                }
            }
        } else {
            e[i] = a[i * n + l];
        }
        d[i] = h;
    }
    d[0] = 0.0;
    e[0] = 0.0;
    for (int i = 0; i < n; ++i) {
        const int l = i - 1;
        if (d[i] != 0.0) {
            for (int j = 0; j <= l; ++j) {
                double g = 0.0;
                for (int k = 0; k <= l; ++k) g += a[i * n + k] * a[k * n + j];
                for (int k = 0; k <= l; ++k) a[k * n + j] -= g * a[k * n + i];
            }
        }
        d[i] = a[i * n + i];
        a[i * n + i] = 1.0;
        for (int j = 0; j <= l; ++j) a[j * n + i] = a[i * n + j] = 0.0;
    }
}

/* sqrt(a² + b²) without overflow or underflow: directly when the squares are normal numbers
 * (the QL sweeps' usual case), else scaled (Numerical Recipes' pythag). libm's hypot is
 * correctly rounded and several times slower; the sweeps do not need its last bit. */
static double rdc_pythag(double a, double b) {
    const double x = fabs(a), y = fabs(b);
    if (x < 1e150 && y < 1e150 && (x > 1e-150 || y > 1e-150)) return sqrt(x * x + y * y);
    if (x > y) {
        const double r = y / x;
        return x * sqrt(1.0 + r * r);
    }
    if (y == 0.0) return 0.0;
    const double r = x / y;
    return y * sqrt(1.0 + r * r);
}

static void rdc_tqli(double *d, double *e, int n, double *z) {
    for (int i = 1; i < n; ++i) e[i - 1] = e[i];
    e[n - 1] = 0.0;
    for (int l = 0; l < n; ++l) {
        int iter = 0, m;
        do {
            for (m = l; m < n - 1; ++m) {
                const double dd = fabs(d[m]) + fabs(d[m + 1]);
                if (fabs(e[m]) <= 2.220446049250313e-16 * dd) break;
            }
            if (m != l) {
                if (iter++ == 60) break;
                double g = (d[l + 1] - d[l]) / (2.0 * e[l]);
                double r = rdc_pythag(g, 1.0);
                g = d[m] - d[l] + e[l] / (g + (g >= 0.0 ? fabs(r) : -fabs(r)));
                double s = 1.0, c = 1.0, p = 0.0;
                int i;
                for (i = m - 1; i >= l; --i) {
                    double f = s * e[i], b = c * e[i];
                    e[i + 1] = (r = rdc_pythag(f, g));
                    if (r == 0.0) {
                        d[i + 1] -= p;
                        e[m] = 0.0;
                        break;
                    }
                    s = f / r;
                    c = g / r;
                    g = d[i + 1] - p;
                    r = (d[i] - g) * s + 2.0 * c * b;
                    d[i + 1] = g + (p = s * r);
                    g = c * r - b;
                    for (int k = 0; k < n; ++k) {
                        f = z[k * n + i + 1];
                        z[k * n + i + 1] = s * z[k * n + i] + c * f;
                        z[k * n + i] = c * z[k * n + i] - s * f;
                    }
                }
                if (r == 0.0 && i >= l) continue;
                d[l] -= p;
                e[l] = g;
                e[m] = 0.0;
            }
        } while (m != l);
    }
}

/* Λ from Λ⁻¹ = A (m×m, symmetric), damped as operational_space.damped_task_inertia. */
static void rdc_task_inertia(double *A, double damping, int m, double *L) {
    double V[36], s[6], d[6], e[6], top = 0.0;
    memcpy(V, A, sizeof(double) * m * m); /* eigenvectors as the columns of V, values in d */
    rdc_tred2(V, m, d, e);
    rdc_tqli(d, e, m, V);
    for (int i = 0; i < m; ++i) {
        s[i] = d[i] > 0.0 ? d[i] : 0.0;
        if (s[i] > top) top = s[i];
    }
    const double floor = (damping * top) * (damping * top);
    for (int i = 0; i < m; ++i) s[i] = floor == 0.0 ? 1.0 / s[i] : s[i] / (s[i] * s[i] + floor);
    for (int i = 0; i < m; ++i)
        for (int j = 0; j < m; ++j) {
            double x = 0.0;
            for (int k = 0; k < m; ++k) x += V[i * m + k] * s[k] * V[j * m + k];
            L[i * m + j] = x;
        }
}

/* λ_v of sim.task_damping: λ_max √(1 − (σ/ε)²) below ε, else 0, with σ = σ_r(S J) / ℓ from the
 * eigenvalues of (S J)(S J)ᵀ / ℓ² (J: m rows of n columns, the rotation rows scaled by ℓ). */
static double rdc_variable_damping(const double *J, int n, int m, double length, int rank, double threshold, double maximum) {
    if (maximum == 0.0 || rank < 1) return rank < 1 ? maximum : 0.0;
    double G[36], d[6], e[6];
    for (int i = 0; i < m; ++i)
        for (int k = 0; k <= i; ++k) {
            const double scale = (i >= 3 ? length : 1.0) * (k >= 3 ? length : 1.0) / (length * length);
            double s = 0.0;
            for (int j = 0; j < n; ++j) s += J[i * n + j] * J[k * n + j];
            G[i * m + k] = G[k * m + i] = s * scale;
        }
    rdc_tred2(G, m, d, e);
    rdc_tqli(d, e, m, G);
    for (int i = 1; i < m; ++i) /* descending */
        for (int k = i; k > 0 && d[k] > d[k - 1]; --k) {
            const double t = d[k];
            d[k] = d[k - 1];
            d[k - 1] = t;
        }
    const double sigma = sqrt(d[rank - 1] > 0.0 ? d[rank - 1] : 0.0);
    return sigma >= threshold ? 0.0 : maximum * sqrt(1.0 - (sigma / threshold) * (sigma / threshold));
}

/* pin.log3 (Pinocchio's formulas: renormalised matrix, series near 0, axis near π). */
static void rdc_log3_axis(int i0, const double *R, double val, double *angle, double *axis) {
    const double eps = 2.220446049250313e-16;
    const int i1 = (i0 + 1) % 3, i2 = (i0 + 2) % 3;
    const double s = sqrt(val + eps + eps * eps) * (R[i2 * 3 + i1] >= R[i1 * 3 + i2] ? 1.0 : -1.0);
    axis[i0] = s / 2.0;
    axis[i1] = 1.0 / (2.0 * s) * (R[i1 * 3 + i0] + R[i0 * 3 + i1]);
    axis[i2] = 1.0 / (2.0 * s) * (R[i2 * 3 + i0] + R[i0 * 3 + i2]);
    const double w = 1.0 / (2.0 * s) * (R[i2 * 3 + i1] - R[i1 * 3 + i2]);
    const double norm = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    *angle = 2.0 * atan2(norm, w);
    for (int k = 0; k < 3; ++k) axis[k] /= norm;
}
static void rdc_log3(const double *R0, double *out) {
    const double eps = 2.220446049250313e-16, prec = cbrt(eps), pi = 3.14159265358979323846;
    double R[9], c0[3], c1[3];
    const double n0 = sqrt(R0[0] * R0[0] + R0[3] * R0[3] + R0[6] * R0[6]), n1 = sqrt(R0[1] * R0[1] + R0[4] * R0[4] + R0[7] * R0[7]);
    for (int k = 0; k < 3; ++k) c0[k] = R0[k * 3] / n0, c1[k] = R0[k * 3 + 1] / n1;
    const double c2[3] = {c0[1] * c1[2] - c0[2] * c1[1], c0[2] * c1[0] - c0[0] * c1[2], c0[0] * c1[1] - c0[1] * c1[0]};
    const double d0[3] = {c1[1] * c2[2] - c1[2] * c2[1], c1[2] * c2[0] - c1[0] * c2[2], c1[0] * c2[1] - c1[1] * c2[0]};
    for (int k = 0; k < 3; ++k) R[k * 3] = d0[k], R[k * 3 + 1] = c1[k], R[k * 3 + 2] = c2[k];
    const double tr = R[0] + R[4] + R[8], cos_value = (tr - 1.0) / 2.0;
    if (cos_value < -1.0 + prec) { /* near π: Pinocchio's axis from the largest diagonal entry */
        double val[3], angle, axis[3];
        for (int k = 0; k < 3; ++k) val[k] = 2.0 * R[k * 4] - tr + 1.0;
        const int i0 = val[0] >= val[1] ? (val[0] >= val[2] ? 0 : 2) : (val[1] >= val[2] ? 1 : 2);
        rdc_log3_axis(i0, R, val[i0], &angle, axis);
        for (int k = 0; k < 3; ++k) out[k] = angle * axis[k];
        return;
    }
    const double expansion = sqrt(2.0 * (1.0 - cos_value) + eps * eps);
    const double theta = tr <= 3.0 - prec ? (tr >= -1.0 + prec ? acos(cos_value) : pi - expansion) : expansion;
    const double a[3] = {(R[7] - R[5]) / 2.0, (R[2] - R[6]) / 2.0, (R[3] - R[1]) / 2.0};
    const double a2 = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
    const double t = theta >= prec ? theta / sin(theta) : 1.0 + a2 / 6.0 + a2 * a2 * 3.0 / 40.0;
    for (int k = 0; k < 3; ++k) out[k] = t * a[k];
}

/* y = Rᵀ x (transpose) or R x, R row-major 3×3 */
static void rdc_rot(const double *R, const double *x, double *y, int transpose) {
    for (int i = 0; i < 3; ++i)
        y[i] = transpose ? R[i] * x[0] + R[3 + i] * x[1] + R[6 + i] * x[2] : R[3 * i] * x[0] + R[3 * i + 1] * x[1] + R[3 * i + 2] * x[2];
}
static void rdc_skew(const double *w, double *S) {
    S[0] = 0, S[1] = -w[2], S[2] = w[1], S[3] = w[2], S[4] = 0, S[5] = -w[0], S[6] = -w[1], S[7] = w[0], S[8] = 0;
}
static void rdc_mat3(const double *A, const double *B, double *C) {
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) C[i * 3 + j] = A[i * 3] * B[j] + A[i * 3 + 1] * B[3 + j] + A[i * 3 + 2] * B[6 + j];
}

/* so3_log.log_coefficients: c(θ) and c'(θ)/θ */
static void rdc_log_coefficients(double theta, double *c, double *cp) {
    if (theta < 0.05) {
        *c = 1.0 / 12 + theta * theta / 720 + pow(theta, 4) / 30240;
        *cp = 1.0 / 360 + theta * theta / 7560;
        return;
    }
    const double cot = 1.0 / tan(theta / 2);
    *c = 1.0 / (theta * theta) - cot / (2 * theta);
    const double sh = sin(theta / 2);
    *cp = (-2.0 / pow(theta, 3) + cot / (2 * theta * theta) + 1.0 / (4 * theta * (sh * sh))) / theta;
}

/* The angular part of OperationalSpace._error: the world angular acceleration command. */
static void rdc_orientation_command(const double *R, const double *Rd, const double *omega, double kp, double kd, double *angular) {
    double RtRd[9], e[3], phi[3], body[3], S[9], S2[9], Jinv[9], rate[3], pd[3], Sd[9], A[9], B[9], T[9], x[3];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) RtRd[i * 3 + j] = R[i] * Rd[j] + R[3 + i] * Rd[3 + j] + R[6 + i] * Rd[6 + j];
    rdc_log3(RtRd, e);
    for (int k = 0; k < 3; ++k) phi[k] = -e[k];
    rdc_rot(R, omega, body, 1);
    const double theta = sqrt(phi[0] * phi[0] + phi[1] * phi[1] + phi[2] * phi[2]);
    double c, cp;
    rdc_log_coefficients(theta, &c, &cp);
    rdc_skew(phi, S);
    rdc_mat3(S, S, S2);
    for (int k = 0; k < 9; ++k) Jinv[k] = (k % 4 == 0) + 0.5 * S[k] + c * S2[k];
    rdc_rot(Jinv, body, rate, 0);
    for (int k = 0; k < 3; ++k) rate[k] = -rate[k], pd[k] = -rate[k]; /* angle_rate, and φ̇ = −angle_rate */
    rdc_skew(pd, Sd);
    rdc_mat3(Sd, S, A);
    rdc_mat3(S, Sd, B);
    const double dot = phi[0] * pd[0] + phi[1] * pd[1] + phi[2] * pd[2];
    for (int k = 0; k < 9; ++k) T[k] = 0.5 * Sd[k] + c * (A[k] + B[k]) + cp * dot * S2[k];
    double rate_term[3];
    rdc_rot(T, body, rate_term, 0);
    for (int k = 0; k < 3; ++k) x[k] = -(-kd * rate[k] - kp * e[k]) - rate_term[k];
    rdc_solve(Jinv, x, 3, 1);
    rdc_rot(R, x, angular, 0);
}

/* params: RD_TS_* (robodyn.compiled.controllers.CompiledTaskSpace's layout; robodyn.sim.control.TaskSpace) */
static void rdc_task_space(const rd_kernels *model, const rd_frame_kernels *frame, const double *p, const double *q,
                           const double *v, double *tau) {
    const int n = RD_NV;
    double x[3], R[9], J[6 * RD_NV], bias[6], desired[3], gram[9], pinv[3 * RD_NV], command[RD_NV], jv[RD_NV], Nv[RD_NV];
    frame->all(q, v, x, R, J, bias);
    for (int i = 0; i < 3; ++i) {
        double velocity = 0.0;
        for (int j = 0; j < n; ++j) velocity += J[i * n + j] * v[j];
        desired[i] = p[RD_TS_KP(n)] * (p[RD_TS_TARGET(n) + i] - x[i]) - p[RD_TS_KD(n)] * velocity - bias[i];
        for (int k = 0; k < 3; ++k) {
            double g = 0.0;
            for (int j = 0; j < n; ++j) g += J[i * n + j] * J[k * n + j];
            gram[i * 3 + k] = g + (i == k) * p[RD_TS_DAMPING(n)];
        }
    }
    memcpy(pinv, J, sizeof(double) * 3 * n); /* gram⁻¹ J, then pinv = (gram⁻¹ J)ᵀ = Jᵀ gram⁻¹ */
    rdc_solve(gram, pinv, 3, n);
    for (int j = 0; j < n; ++j) jv[j] = p[RD_TS_JOINT_DAMPING(n)] * v[j];
    for (int i = 0; i < n; ++i) { /* N = I - pinv J; command = pinv desired - N jv */
        double Nrow = 0.0, pd = 0.0;
        for (int j = 0; j < n; ++j) {
            double pj = 0.0;
            for (int k = 0; k < 3; ++k) pj += pinv[k * n + i] * J[k * n + j];
            Nrow += ((i == j) - pj) * jv[j];
        }
        for (int k = 0; k < 3; ++k) pd += pinv[k * n + i] * desired[k];
        Nv[i] = Nrow;
        command[i] = pd - Nv[i];
    }
    model->tau(q, v, command, tau);
    for (int j = 0; j < n; ++j) tau[j] += p[RD_TS_VISCOUS(n) + j] * v[j]; /* + b ∘ v (zeros: the rigid law) */
}

/* params: RD_OSC_* (CompiledOperationalSpace's layout; robodyn.sim.operational_space.OperationalSpace,
 * fixed target) */
static void rdc_operational_space(const rd_kernels *model, const rd_frame_kernels *frame, const double *p, const double *q,
                                  const double *v, double *tau, double *a) {
    const int n = RD_NV, m = (int)p[RD_OSC_ROWS(n)];
    double x[3], R[9], J[6 * RD_NV], bias[6], command[6], M[RD_NV * RD_NV], L[RD_NV * RD_NV], h[RD_NV];
    double MiJt[6 * RD_NV], A[36], Lam[36], f[6], posture[RD_NV], y[6];
    frame->all(q, v, x, R, J, bias);
    double velocity[6];
    for (int i = 0; i < 6; ++i) {
        velocity[i] = 0.0;
        for (int j = 0; j < n; ++j) velocity[i] += J[i * n + j] * v[j];
    }
    for (int i = 0; i < 3; ++i)
        command[i] = 0.0 + p[RD_OSC_KD(n)] * (0.0 - velocity[i]) + p[RD_OSC_KP(n)] * (p[RD_OSC_POSITION(n) + i] - x[i]);
    if (m == 6) rdc_orientation_command(R, p + RD_OSC_ROTATION(n), velocity + 3, p[RD_OSC_KP(n)], p[RD_OSC_KD(n)], command + 3);
    model->mass_nle(q, v, M, h);
    memcpy(L, M, sizeof M);
    if (rd_ldl_factor(L)) {
        for (int i = 0; i < n; ++i) tau[i] = NAN;
        if (a)
            for (int i = 0; i < n; ++i) a[i] = NAN;
        return;
    }
    double block[6 * RD_NV]; /* M⁻¹ Jᵀ (n×m), solved for its m columns at once */
    for (int j = 0; j < n; ++j)
        for (int k = 0; k < m; ++k) block[j * m + k] = J[k * n + j];
    rdc_ldl_apply_block(L, block, m);
    for (int k = 0; k < m; ++k) /* column k of M⁻¹ Jᵀ, stored as row k */
        for (int j = 0; j < n; ++j) MiJt[k * n + j] = block[j * m + k];
    for (int i = 0; i < m; ++i) /* J M⁻¹ Jᵀ: its lower triangle, all the eigen-decomposition reads */
        for (int k = 0; k <= i; ++k) {
            double s = 0.0;
            for (int j = 0; j < n; ++j) s += J[i * n + j] * MiJt[k * n + j];
            A[i * m + k] = A[k * m + i] = s;
        }
    const double extra = rdc_variable_damping(J, n, m, p[RD_OSC_LENGTH(n)], (int)p[RD_OSC_RANK(n)], p[RD_OSC_SINGULAR_THRESHOLD(n)],
                                              p[RD_OSC_SINGULAR_DAMPING(n)]);
    const double floor_damping = p[RD_OSC_DAMPING(n)];
    rdc_task_inertia(A, extra == 0.0 ? floor_damping : hypot(floor_damping, extra), m, Lam);
    for (int i = 0; i < m; ++i) y[i] = command[i] - bias[i];
    for (int i = 0; i < m; ++i) {
        f[i] = 0.0;
        for (int k = 0; k < m; ++k) f[i] += Lam[i * m + k] * y[k];
    }
    double rate[RD_NV];
    for (int j = 0; j < n; ++j)
        rate[j] = p[RD_OSC_POSTURE_KP(n)] * (p[RD_OSC_HAS_POSTURE(n)] ? p[RD_OSC_POSTURE(n) + j] - q[j] : 0.0) - p[RD_OSC_POSTURE_KD(n)] * v[j];
    for (int i = 0; i < n; ++i) { /* posture = M (kp0 (q0 - q) - kd0 v) */
        double s = 0.0;
        for (int j = 0; j < n; ++j) s += M[i * n + j] * rate[j];
        posture[i] = s;
    }
    double JP[6] = {0}; /* Nᵀ posture = posture - Jᵀ Λ (M⁻¹Jᵀ)ᵀ posture */
    for (int k = 0; k < m; ++k)
        for (int j = 0; j < n; ++j) JP[k] += MiJt[k * n + j] * posture[j];
    double LJP[6];
    for (int i = 0; i < m; ++i) {
        LJP[i] = 0.0;
        for (int k = 0; k < m; ++k) LJP[i] += Lam[k * m + i] * JP[k];
    }
    for (int j = 0; j < n; ++j) {
        double task = 0.0, back = 0.0;
        for (int i = 0; i < m; ++i) task += J[i * n + j] * f[i], back += J[i * n + j] * LJP[i];
        tau[j] = task + h[j] + (posture[j] - back) + p[RD_OSC_VISCOUS(n) + j] * v[j]; /* + b ∘ v */
    }
    if (a) { /* the plant's accelerations when it is this model: rd_fd_raw's arithmetic on M, h */
        for (int i = 0; i < n; ++i) a[i] = tau[i] - h[i];
        rd_ldl_apply(L, a);
    }
}

/* params: RD_IMP_* (CompiledImpedance's layout; robodyn.sim.operational_space.Impedance) */
static void rdc_impedance(const rd_kernels *model, const rd_frame_kernels *frame, const double *p, const double *q,
                          const double *v, double *tau) {
    const int n = RD_NV, m = (int)p[RD_IMP_ROWS(n)];
    const double *Rd = p + RD_IMP_ROTATION(n);
    double x[3], R[9], J[6 * RD_NV], bias[6], error[6], wrench[6], gram[36], GJ[6 * RD_NV], g[RD_NV], dv[RD_NV];
    frame->all(q, v, x, R, J, bias);
    for (int i = 0; i < 3; ++i) error[i] = p[RD_IMP_POSITION(n) + i] - x[i];
    if (m == 6) {
        double RtRd[9], e[3];
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) RtRd[i * 3 + j] = R[i] * Rd[j] + R[3 + i] * Rd[3 + j] + R[6 + i] * Rd[6 + j];
        rdc_log3(RtRd, e);
        rdc_rot(R, e, error + 3, 0);
    }
    for (int i = 0; i < m; ++i) {
        double velocity = 0.0;
        for (int j = 0; j < n; ++j) velocity += J[i * n + j] * v[j];
        wrench[i] = p[RD_IMP_STIFFNESS(n) + i] * error[i] - p[RD_IMP_DAMPING(n) + i] * velocity;
        for (int k = 0; k < m; ++k) {
            double s = 0.0;
            for (int j = 0; j < n; ++j) s += J[i * n + j] * J[k * n + j];
            gram[i * m + k] = s + (i == k) * 1e-8;
        }
    }
    memcpy(GJ, J, sizeof(double) * m * n);
    rdc_solve(gram, GJ, m, n); /* gram⁻¹ J; N = I - Jᵀ gram⁻¹ J */
    for (int j = 0; j < n; ++j) dv[j] = p[RD_IMP_NULL_DAMPING(n)] * v[j];
    model->gravity(q, g);
    for (int j = 0; j < n; ++j) { /* Nᵀ dv = dv - (gram⁻¹ J)ᵀ J dv: N is symmetric up to rounding; use Nᵀ */
        double Jw = 0.0, Ntdv = dv[j];
        for (int i = 0; i < m; ++i) Jw += J[i * n + j] * wrench[i];
        for (int k = 0; k < n; ++k) {
            double JtGJ = 0.0;
            for (int i = 0; i < m; ++i) JtGJ += J[i * n + k] * GJ[i * n + j];
            Ntdv -= JtGJ * dv[k];
        }
        tau[j] = g[j] + Jw - Ntdv + p[RD_IMP_VISCOUS(n) + j] * v[j]; /* + b ∘ v */
    }
}

static void rd_control_frame(const rd_controller *c, const double *q, const double *v, double *tau) {
    const rd_frame_kernels *frame = (const rd_frame_kernels *)c->frame;
    if (c->kind == RD_KIND_TS) rdc_task_space(c->model, frame, c->params, q, v, tau);
    if (c->kind == RD_KIND_OSC) rdc_operational_space(c->model, frame, c->params, q, v, tau, NULL);
    if (c->kind == RD_KIND_IMP) rdc_impedance(c->model, frame, c->params, q, v, tau);
}


/* params: RD_LQR_*: S u_eq (n), S K (n × 2n, row-major), x_eq = (q_eq, v_eq) (2n)
 * (robodyn.sim.control.LQR: tau = S (u_eq − K (x − x_eq)), S selecting the actuated joints) */
static void rdc_lqr(const double *p, const double *q, const double *v, double *tau) {
    const int n = RD_NV;
    const double *u = p + RD_LQR_U(n), *K = p + RD_LQR_K(n), *x_eq = p + RD_LQR_X_EQ(n);
    double e[2 * RD_NV];
    for (int j = 0; j < n; ++j) e[j] = q[j] - x_eq[j], e[n + j] = v[j] - x_eq[n + j];
    for (int i = 0; i < n; ++i) {
        double s = 0.0;
        for (int j = 0; j < 2 * n; ++j) s += K[i * 2 * n + j] * e[j];
        tau[i] = u[i] - s;
    }
}

/* The quintic rest-to-rest profile at time t of a motion lasting duration (the one C copy of
 * robodyn.sim.control.QuinticReference, same operations in the same order): the share of the
 * way covered, its rate [1/s] and its second derivative [1/s²]; at rest outside (0, duration). */
static void rd_quintic(double t, double duration, double *position, double *speed, double *acceleration) {
    double s = t / duration;
    s = s < 0.0 ? 0.0 : (s > 1.0 ? 1.0 : s);
    const int moving = 0 < t && t < duration;
    *position = 10 * pow(s, 3) - 15 * pow(s, 4) + 6 * pow(s, 5);
    *speed = moving ? (30 * pow(s, 2) - 60 * pow(s, 3) + 30 * pow(s, 4)) / duration : 0.0;
    *acceleration = moving ? (60 * s - 180 * pow(s, 2) + 120 * pow(s, 3)) / pow(duration, 2) : 0.0;
}

#if RD_NQ != RD_NV
/* Joint torques giving the joints the accelerations a[6:] with no torque on the free base
 * (robodyn.sim.control.free_base_torques): a[0:6] = -M_bb⁻¹ (M_bj a_j + h_b), tau = ID(q, v, a), tau[0:6] = 0. */
static void rd_free_base_torques(const rd_kernels *model, const double *q, const double *v, double *a, double *tau) {
    const int n = RD_NV;
    double M[RD_NV * RD_NV], h[RD_NV], A[36], b[6];
    model->mass_nle(q, v, M, h);
    for (int i = 0; i < 6; ++i) {
        double s = 0.0;
        for (int j = 6; j < n; ++j) s += M[i * n + j] * a[j];
        b[i] = -(s + h[i]);
        for (int k = 0; k < 6; ++k) A[i * 6 + k] = M[i * n + k];
    }
    rdc_solve(A, b, 6, 1);
    memcpy(a, b, sizeof b);
    model->tau(q, v, a, tau);
    for (int i = 0; i < 6; ++i) tau[i] = 0.0;
}

/* PD + gravity (RD_KIND_PD) and computed torque along a quintic (RD_KIND_CT) on a floating robot's
 * joints, its base free (robodyn.sim.control: _floating_pd, ComputedTorque): params as for a
 * fixed base, of the joints only. */
static void rd_control_free_base(const rd_controller *c, double t, const double *q, const double *v, double *tau) {
    const int m = RD_NV - 6;
    const double *p = c->params;
    double a[RD_NV] = {0}, zero[RD_NV] = {0};
    if (c->kind == RD_KIND_PD) {
        double holding[RD_NV];
        rd_free_base_torques(c->model, q, zero, a, holding);
        for (int i = 0; i < 6; ++i) tau[i] = 0.0;
        for (int i = 0; i < m; ++i)
            tau[6 + i] = p[RD_PD_KP(m) + i] * (p[RD_PD_TARGET(m) + i] - q[7 + i]) - p[RD_PD_KD(m) + i] * v[6 + i] + holding[6 + i];
        return;
    }
    double position, speed, acceleration;
    rd_quintic(t, p[RD_CT_DURATION(m)], &position, &speed, &acceleration);
    for (int i = 0; i < m; ++i) {
        const double delta = p[RD_CT_Q_END(m) + i] - p[RD_CT_Q_START(m) + i];
        const double q_d = p[RD_CT_Q_START(m) + i] + position * delta, v_d = speed * delta, a_d = acceleration * delta;
        a[6 + i] = a_d + p[RD_CT_KD(m) + i] * (v_d - v[6 + i]) + p[RD_CT_KP(m) + i] * (q_d - q[7 + i]);
    }
    rd_free_base_torques(c->model, q, v, a, tau);
    for (int i = 0; i < m; ++i) tau[6 + i] += p[RD_CT_VISCOUS(m) + i] * v[6 + i]; /* + b ∘ v on the joints */
}
#endif

static void rd_control(const rd_controller *c, double t, const double *q, const double *v, double *tau) {
    const int n = RD_NV;
    const double *p = c->params;
#if RD_NQ != RD_NV
    if (c->kind == RD_KIND_PD || c->kind == RD_KIND_CT) { /* the joints' laws with the base free */
        rd_control_free_base(c, t, q, v, tau);
        return;
    }
#endif
    if (c->kind == 0) {
        for (int i = 0; i < n; ++i) tau[i] = p[i];
    } else if (c->kind == RD_KIND_PD) {
        double g[RD_NV];
        c->model->gravity(q, g);
        for (int i = 0; i < n; ++i) tau[i] = p[RD_PD_KP(n) + i] * (p[RD_PD_TARGET(n) + i] - q[i]) - p[RD_PD_KD(n) + i] * v[i] + g[i];
    } else if (c->kind == RD_KIND_LQR) {
        rdc_lqr(p, q, v, tau);
    } else if (c->kind != RD_KIND_CT) { /* task space, operational space, impedance */
        rd_control_frame(c, q, v, tau);
    } else { /* computed torque along a quintic */
        double position, speed, acceleration;
        rd_quintic(t, p[RD_CT_DURATION(n)], &position, &speed, &acceleration);
        double command[RD_NV];
        for (int i = 0; i < n; ++i) {
            const double delta = p[RD_CT_Q_END(n) + i] - p[RD_CT_Q_START(n) + i];
            const double q_d = p[RD_CT_Q_START(n) + i] + position * delta, v_d = speed * delta, a_d = acceleration * delta;
            command[i] = a_d + p[RD_CT_KD(n) + i] * (v_d - v[i]) + p[RD_CT_KP(n) + i] * (q_d - q[i]);
        }
        c->model->tau(q, v, command, tau);
        for (int i = 0; i < n; ++i) tau[i] += p[RD_CT_VISCOUS(n) + i] * v[i]; /* + b ∘ v (zeros: the rigid law) */
    }
}

/* tau(t, q, v) and the plant's a = FD(q, v, tau) in one pass, when the controller's model is
 * the plant's (this module's kernels) and it computes M and C v + G anyway (operational space):
 * 1 when done (a NaN for a singular M), 0 when the caller is to call rd_control and rd_fd_raw.
 * Bit-identical to those two: the same M, h and the same LDLᵀ arithmetic. */
static int rd_control_fd(const rd_controller *c, const double *q, const double *v, double *tau, double *a) {
    if (c->kind != RD_KIND_OSC || c->model != &rd_self || c->damping) return 0;
    rdc_operational_space(c->model, (const rd_frame_kernels *)c->frame, c->params, q, v, tau, a);
    return 1;
}

/* The plant's forward dynamics under the torque tau and its joints' damping: FD(q, v, tau − b v)
 * (robodyn.sim.joint_friction's order of operations), FD(q, v, tau) without damping. */
static int rd_fd_damped(const rd_controller *c, const double *q, const double *v, const double *tau, double *a) {
    if (!c->damping) return rd_fd_raw(q, v, tau, a);
    double total[RD_NV];
    for (int i = 0; i < RD_NV; ++i) total[i] = tau[i] - c->damping[i] * v[i];
    return rd_fd_raw(q, v, total, a);
}

/* out = q ⊕ h w (Pinocchio's integrate): joints by addition; a floating base on SE(3),
 * M0 exp6(h w) in the base frame, its quaternion (x, y, z, w) on the side of q's and
 * renormalised to first order, as pinocchio::integrate of a free flyer. */
static void rd_qplus(const double *q, const double *w, double h, double *out) {
#if RD_NQ != RD_NV
    double u[6];
    for (int i = 0; i < 6; ++i) u[i] = h * w[i];
    const double th2 = u[3] * u[3] + u[4] * u[4] + u[5] * u[5], th = sqrt(th2);
    double a, b, c, s; /* V = 1 + a [ω]× + b [ω]×²; the half-angle quaternion (s ω, c) */
    if (th < 1e-3) {
        a = 0.5 - th2 / 24.0 + th2 * th2 / 720.0;
        b = 1.0 / 6.0 - th2 / 120.0 + th2 * th2 / 5040.0;
        s = 0.5 - th2 / 48.0 + th2 * th2 / 3840.0;
    } else {
        a = (1.0 - cos(th)) / th2;
        b = (th - sin(th)) / (th2 * th);
        s = sin(0.5 * th) / th;
    }
    c = cos(0.5 * th);
    const double *o = u + 3, *l = u;
    const double ol[3] = {o[1] * l[2] - o[2] * l[1], o[2] * l[0] - o[0] * l[2], o[0] * l[1] - o[1] * l[0]};
    const double ool[3] = {o[1] * ol[2] - o[2] * ol[1], o[2] * ol[0] - o[0] * ol[2], o[0] * ol[1] - o[1] * ol[0]};
    double p[3];
    for (int i = 0; i < 3; ++i) p[i] = l[i] + a * ol[i] + b * ool[i];
    const double x = q[3], y = q[4], z = q[5], qw = q[6];
    const double R[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - z * qw), 2 * (x * z + y * qw),
                         2 * (x * y + z * qw), 1 - 2 * (x * x + z * z), 2 * (y * z - x * qw),
                         2 * (x * z - y * qw), 2 * (y * z + x * qw), 1 - 2 * (x * x + y * y)};
    for (int i = 0; i < 3; ++i) out[i] = q[i] + R[3 * i] * p[0] + R[3 * i + 1] * p[1] + R[3 * i + 2] * p[2];
    const double ex = s * o[0], ey = s * o[1], ez = s * o[2], ew = c; /* q ⊗ exp(ω/2) */
    double r[4] = {qw * ex + x * ew + y * ez - z * ey, qw * ey - x * ez + y * ew + z * ex,
                   qw * ez + x * ey - y * ex + z * ew, qw * ew - x * ex - y * ey - z * ez};
    const double dot = r[0] * x + r[1] * y + r[2] * z + r[3] * qw;
    const double n2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3];
    const double scale = (dot < 0.0 ? -1.0 : 1.0) * (3.0 - n2) / 2.0;
    for (int i = 0; i < 4; ++i) out[3 + i] = scale * r[i];
    for (int i = 6; i < RD_NV; ++i) out[i + 1] = q[i + 1] + h * w[i];
#else
    for (int i = 0; i < RD_NV; ++i) out[i] = q[i] + h * w[i];
#endif
}

/* a = FD(q, v, tau(t, q, v)); the stage's torque is the held one when c->hold. */
static void rd_stage(const rd_controller *c, double t, const double *q, const double *v, const double *held, double *a) {
    double tau[RD_NV];
    if (c->hold || c->kind == 0)
        memcpy(tau, held, sizeof tau);
    else if (rd_control_fd(c, q, v, tau, a))
        return;
    else
        rd_control(c, t, q, v, tau);
    if (rd_fd_damped(c, q, v, tau, a))
        for (int i = 0; i < RD_NV; ++i) a[i] = NAN;
}

static Py_ssize_t rd_integrate(const rd_controller *c, double *q, double *v, double dt, Py_ssize_t steps, double t0, int rk4,
                               double *oq, double *ov, double *oa, double *otau) {
    const int n = RD_NV, nq = RD_NQ;
    const double half = 0.5 * dt, sixth = dt / 6.0;
    double tau[RD_NV], a[RD_NV], q2[RD_NQ], v2[RD_NV], a2[RD_NV], v3[RD_NV], a3[RD_NV], v4[RD_NV], a4[RD_NV], w[RD_NV];
    for (Py_ssize_t k = 0; k < steps; ++k) {
        const double t = t0 + k * dt;
        memcpy(oq + k * nq, q, nq * sizeof(double));
        memcpy(ov + k * n, v, n * sizeof(double));
        const int fused = rd_control_fd(c, q, v, tau, a);
        if (!fused) rd_control(c, t, q, v, tau);
        memcpy(otau + k * n, tau, n * sizeof(double));
        if (!fused && rd_fd_damped(c, q, v, tau, a))
            for (int i = 0; i < n; ++i) a[i] = NAN;
        memcpy(oa + k * n, a, n * sizeof(double));
        if (rk4) {
            for (int i = 0; i < n; ++i) v2[i] = v[i] + half * a[i];
            rd_qplus(q, v, half, q2);
            rd_stage(c, t + half, q2, v2, tau, a2);
            for (int i = 0; i < n; ++i) v3[i] = v[i] + half * a2[i];
            rd_qplus(q, v2, half, q2);
            rd_stage(c, t + half, q2, v3, tau, a3);
            for (int i = 0; i < n; ++i) v4[i] = v[i] + dt * a3[i];
            rd_qplus(q, v3, dt, q2);
            rd_stage(c, t + dt, q2, v4, tau, a4);
            for (int i = 0; i < n; ++i) {
                w[i] = v[i] + v4[i] + 2.0 * (v2[i] + v3[i]);
                v[i] = v[i] + sixth * (a[i] + a4[i] + 2.0 * (a2[i] + a3[i]));
            }
            rd_qplus(q, w, sixth, q2);
        } else {
            for (int i = 0; i < n; ++i) v[i] = v[i] + dt * a[i];
            rd_qplus(q, v, dt, q2);
        }
        memcpy(q, q2, nq * sizeof(double));
        if (!rd_finite(q, nq) || !rd_finite(v, n)) {
            memcpy(oq + (k + 1) * nq, q, nq * sizeof(double));
            memcpy(ov + (k + 1) * n, v, n * sizeof(double));
            return k;
        }
    }
    memcpy(oq + steps * nq, q, nq * sizeof(double));
    memcpy(ov + steps * n, v, n * sizeof(double));
    if (steps > 0) {
        memcpy(otau + steps * n, otau + (steps - 1) * n, n * sizeof(double));
        memcpy(oa + steps * n, oa + (steps - 1) * n, n * sizeof(double));
    } else {
        double zero[RD_NV] = {0};
        memcpy(otau, zero, sizeof zero);
        if (rd_fd_damped(c, q, v, zero, a))
            for (int i = 0; i < n; ++i) a[i] = NAN;
        memcpy(oa, a, n * sizeof(double));
    }
    return -1;
}

static double *rd_array(PyObject *object, npy_intp size, int writable) {
    if (!PyArray_CheckExact(object)) return NULL;
    PyArrayObject *array = (PyArrayObject *)object;
    if (PyArray_TYPE(array) != NPY_DOUBLE || !PyArray_ISCARRAY_RO(array) || !PyArray_ISNOTSWAPPED(array) ||
        PyArray_SIZE(array) != size || (writable && !PyArray_ISWRITEABLE(array)))
        return NULL;
    return (double *)PyArray_DATA(array);
}

static PyObject *py_simulate(PyObject *m, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs < 14 || nargs > 16) {
        PyErr_SetString(PyExc_TypeError, "simulate takes 14 to 16 arguments");
        return NULL;
    }
    const double dt = PyFloat_AsDouble(args[2]);
    const Py_ssize_t steps = PyLong_AsSsize_t(args[3]);
    const double t0 = PyFloat_AsDouble(args[4]);
    const long rk4 = PyLong_AsLong(args[5]), kind = PyLong_AsLong(args[6]), hold = PyLong_AsLong(args[7]);
    if (PyErr_Occurred()) return NULL;
    const int n = RD_NV, nj = RD_NV - 6 * (RD_NQ - RD_NV); /* a floating base's PD and CT params: its joints' */
    if (kind < 0 || kind >= RD_KINDS || steps < 0) {
        PyErr_SetString(PyExc_ValueError, "bad controller kind or step count");
        return NULL;
    }
    const double *q0 = rd_array(args[0], RD_NQ, 0), *v0 = rd_array(args[1], n, 0), *params = rd_array(args[8], RD_PARAM_SIZE(kind, n, nj), 0);
    double *oq = rd_array(args[10], (steps + 1) * RD_NQ, 1), *ov = rd_array(args[11], (steps + 1) * n, 1);
    double *oa = rd_array(args[12], (steps + 1) * n, 1), *otau = rd_array(args[13], (steps + 1) * n, 1);
    const rd_kernels *model = &rd_self;
    if (args[9] != Py_None) {
        model = (const rd_kernels *)PyCapsule_GetPointer(args[9], RD_CAPSULE);
        if (!model) return NULL;
    }
    if (!q0 || !v0 || !params || !oq || !ov || !oa || !otau || model->nv != n) {
        PyErr_SetString(PyExc_ValueError, "simulate: arrays of the wrong type or size");
        return NULL;
    }
    const rd_frame_kernels *frame = NULL; /* the 15th argument: the frame capsule of the frame laws */
    if (nargs >= 15 && args[14] != Py_None) {
        frame = (const rd_frame_kernels *)PyCapsule_GetPointer(args[14], RD_FRAME_CAPSULE);
        if (!frame) return NULL;
    }
    if ((kind == RD_KIND_TS || kind == RD_KIND_OSC || kind == RD_KIND_IMP) && (!frame || frame->nv != n)) {
        PyErr_SetString(PyExc_ValueError, "simulate: a frame controller needs its frame's kernels");
        return NULL;
    }
    const double *damping = NULL; /* the 16th argument: the joints' damping (nv), or None */
    if (nargs == 16 && args[15] != Py_None && !(damping = rd_array(args[15], n, 0))) {
        PyErr_SetString(PyExc_ValueError, "simulate: damping of the wrong type or size");
        return NULL;
    }
    rd_controller controller = {(int)kind, (int)hold, params, model, frame, damping};
    double q[RD_NQ], v[RD_NV];
    memcpy(q, q0, sizeof q);
    memcpy(v, v0, sizeof v);
    Py_ssize_t failed;
    Py_BEGIN_ALLOW_THREADS
    failed = rd_integrate(&controller, q, v, dt, steps, t0, (int)rk4, oq, ov, oa, otau);
    Py_END_ALLOW_THREADS
    return PyLong_FromSsize_t(failed);
}

static PyObject *py_info(PyObject *m, PyObject *unused) {
    PyObject *parents = PyTuple_New(RD_NV);
    if (!parents) return NULL;
    for (int i = 0; i < RD_NV; ++i) PyTuple_SET_ITEM(parents, i, PyLong_FromLong(rd_parent[i]));
#ifdef RD_SIMD
    const rds_blocks *b = rds_current();
    PyObject *sets = PyList_New(0);
    for (int level = 0; sets && level < RDS_COUNT; ++level) {
        PyObject *name = rds_supported(level) ? PyUnicode_FromString(rds_names[level]) : NULL;
        if (name && PyList_Append(sets, name) < 0) Py_CLEAR(sets);
        Py_XDECREF(name);
    }
    if (!sets) {
        Py_DECREF(parents);
        return NULL;
    }
    return Py_BuildValue("{s:i,s:N,s:s,s:i,s:N}", "nv", RD_NV, "parents", parents, "instruction_set", rds_names[rds_level], "lanes",
                         b ? b->lanes : 1, "instruction_sets", sets);
#else
    return Py_BuildValue("{s:i,s:N,s:s,s:i}", "nv", RD_NV, "parents", parents, "instruction_set", "scalar", "lanes", 1);
#endif
}

#ifdef RD_SIMD
/* simd() -> the instruction set the batches run; simd(name) chooses one this CPU runs
 * ("scalar", "sse2", "avx2", "avx512"), for every batch of this module, and returns it. */
static PyObject *py_simd(PyObject *m, PyObject *const *args, Py_ssize_t nargs) {
    rds_current();
    if (nargs > 1) {
        PyErr_SetString(PyExc_TypeError, "simd takes at most one argument");
        return NULL;
    }
    if (nargs == 1) {
        const char *wanted = PyUnicode_AsUTF8(args[0]);
        if (!wanted) return NULL;
        int level = 0;
        while (level < RDS_COUNT && strcmp(rds_names[level], wanted) != 0) ++level;
        if (level == RDS_COUNT || !rds_supported(level)) {
            PyErr_Format(PyExc_ValueError, "instruction set %s is not one this module runs on this CPU", wanted);
            return NULL;
        }
        rds_level = level;
    }
    return PyUnicode_FromString(rds_names[rds_level]);
}
#endif

static PyMethodDef rd_methods[] = {
    {"tau", (PyCFunction)(void (*)(void))py_tau, METH_FASTCALL, "tau(q, v, a, threads)"},
    {"mass", (PyCFunction)(void (*)(void))py_mass, METH_FASTCALL, "mass(q, threads)"},
    {"nle", (PyCFunction)(void (*)(void))py_nle, METH_FASTCALL, "nle(q, v, threads)"},
    {"gravity", (PyCFunction)(void (*)(void))py_gravity, METH_FASTCALL, "gravity(q, threads)"},
    {"fd", (PyCFunction)(void (*)(void))py_fd, METH_FASTCALL, "fd(q, v, tau, threads)"},
    {"simulate", (PyCFunction)(void (*)(void))py_simulate, METH_FASTCALL, "simulate(...)"},
    {"info", py_info, METH_NOARGS, "info()"},
#ifdef RD_SIMD
    {"simd", (PyCFunction)(void (*)(void))py_simd, METH_FASTCALL, "simd([name])"},
#endif
    {NULL, NULL, 0, NULL},
};

static int rd_exec(PyObject *module) {
    PyObject *capsule = PyCapsule_New((void *)&rd_self, RD_CAPSULE, NULL);
    if (!capsule || PyModule_AddObject(module, "_kernels", capsule) < 0) {
        Py_XDECREF(capsule);
        return -1;
    }
    return 0;
}

static PyObject *rd_module(const char *name) {
    import_array1(NULL);
    static struct PyModuleDef definition = {PyModuleDef_HEAD_INIT, NULL, "robodyn compiled dynamics", -1, rd_methods};
    definition.m_name = name;
    PyObject *module = PyModule_Create(&definition);
    if (module && rd_exec(module) < 0) {
        Py_DECREF(module);
        return NULL;
    }
    return module;
}
