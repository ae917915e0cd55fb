/* robodyn.compiled derivatives: appended after runtime.c in a robot's derivative module
 * (see derivatives.py; the kernel rdd_tau_derivatives and the robot's kernels precede it).
 *
 * Python entry points (METH_FASTCALL; one state 1-D, a batch 2-D with one state a row):
 *   tau_derivatives(q, v, a, threads) -> (dtau_dq, dtau_dv, M)
 *   fd_derivatives(q, v, tau, threads) -> (dqdd_dq, dqdd_dv, Minv)
 * Each returns a tuple of three new float64 arrays (nv, nv) or (rows, nv, nv), or None when
 * an argument is not a C-contiguous native float64 array of the right shape (the caller then
 * checks and converts it), or an int status as the runtime's: 1 a non-finite input, 2 a
 * non-finite output, 3 a singular mass matrix. Batches run on `threads` POSIX threads with
 * the GIL released.
 */

/* The LDLᵀ is the runtime's (core.c's RD_LDL_DEFINE on doubles): rd_ldl_factor, rd_ldl_apply,
 * rd_ldl_apply_columns; the thread pool too (core.c's rd_parallel). */

typedef int (*rdd_row)(const double *const *in, double *const *out);

static int rdd_row_tau(const double *const *in, double *const *out) {
    if (!rd_finite(in[0], RD_NV) || !rd_finite(in[1], RD_NV) || !rd_finite(in[2], RD_NV)) return 1;
    rdd_tau_derivatives(in[0], in[1], in[2], out[0], out[1]);
    rd_mass(in[0], out[2]);
    for (int k = 0; k < 3; ++k)
        if (!rd_finite(out[k], RD_NV * RD_NV)) return 2;
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
    for (int k = 0; k < 3; ++k) rd_ldl_apply_columns(M, out[k], n);
    for (int i = 0; i < n * n; ++i) {
        out[0][i] = -out[0][i];
        out[1][i] = -out[1][i];
    }
    for (int k = 0; k < 3; ++k)
        if (!rd_finite(out[k], n * n)) return 3;
    return 0;
}

/* q̈ = M⁻¹ (τ − h); ∂q̈/∂x = −M⁻¹ ∂τ/∂x at a = q̈; ∂q̈/∂τ = M⁻¹ (one factorisation). */
static int rdd_row_fd(const double *const *in, double *const *out) {
    double M[RD_NV * RD_NV], a[RD_NV];
    const int status = rdd_fd_start(in, M, a);
    if (status) return status;
    rdd_tau_derivatives(in[0], in[1], a, out[0], out[1]);
    return rdd_fd_finish(M, out);
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

typedef struct {
    rdd_row row;
    rdd_pair pair; /* NULL: one row at a time */
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
        if (job->pair && r + 1 < end) {
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
    rdd_job job = {row, pair, {0, 0, 0}, {0, 0, 0}};
    for (int k = 0; k < 3; ++k) {
        PyObject *out = PyArray_SimpleNew(ndim + 1, ndim == 2 ? dims : dims + 1, NPY_DOUBLE);
        if (!out) {
            Py_DECREF(result);
            return NULL;
        }
        PyTuple_SET_ITEM(result, k, out);
        job.in[k] = (const double *)PyArray_DATA((PyArrayObject *)args[k]);
        job.out[k] = (double *)PyArray_DATA((PyArrayObject *)out);
    }
    int status;
    if (ndim == 1) {
        status = row(job.in, job.out);
    } else {
        Py_BEGIN_ALLOW_THREADS
        status = rd_parallel(rdd_rows, &job, rows, 1, threads);
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

static PyObject *py_derivative_info(PyObject *m, PyObject *unused) { return Py_BuildValue("{s:i}", "nv", RD_NV); }

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
