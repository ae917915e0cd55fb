/* robodyn.compiled runtime: appended to a robot's generated kernels (see codegen.py).
 *
 * Python entry points (METH_FASTCALL; one state 1-D, a batch 2-D with one state a row):
 *   tau(q, v, a, threads), mass(q, threads), nle(q, v, threads), gravity(q, threads),
 *   fd(q, v, tau, threads)
 * Each returns a new float64 array, or None when an argument is not a C-contiguous native
 * float64 array of the right shape (the caller then checks and converts it), or an int
 * status: 1 a non-finite input, 2 a non-finite output, 3 a singular mass matrix.
 * Batches run across rows on `threads` POSIX threads with the GIL released.
 *
 *   simulate(q0, v0, dt, steps, t0, rk4, kind, hold, params, controller, out_q, out_v,
 *            out_a, out_tau) -> -1, or the step after which the state stopped being finite
 * integrates in C (RK4 or semi-implicit Euler); kind 0 holds params[0:n] as the torque,
 * 1 is PD + gravity, 2 computed torque along a quintic, both on the controller's model
 * (a capsule of another compiled robot's kernels, `_kernels`).
 */

#define RD_CAPSULE "robodyn.compiled.kernels"
#define RD_MIN_ROWS_PER_THREAD 64

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

/* Solve M x = b in place (b -> x), M destroyed: M = Lᵀ D L with L following the tree
 * (Featherstone's LTDL: no fill-in when parents precede children). 3 if not positive definite. */
static int rd_ldl_solve(double *M, double *b) {
    const int n = RD_NV;
    for (int k = n - 1; k >= 0; --k) {
        const double d = M[k * n + k];
        if (!(d > 0.0) || !isfinite(d)) return 3;
        for (int i = rd_parent[k]; i >= 0; i = rd_parent[i]) {
            const double x = M[k * n + i] / d;
            for (int j = i; j >= 0; j = rd_parent[j]) M[i * n + j] -= M[k * n + j] * x;
            M[k * n + i] = x;
        }
    }
    for (int i = n - 1; i >= 0; --i)
        for (int j = rd_parent[i]; j >= 0; j = rd_parent[j]) b[j] -= M[i * n + j] * b[i];
    for (int i = 0; i < n; ++i) b[i] /= M[i * n + i];
    for (int i = 0; i < n; ++i)
        for (int j = rd_parent[i]; j >= 0; j = rd_parent[j]) b[i] -= M[i * n + j] * b[j];
    return 0;
}

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
    if (!rd_finite(in[0], RD_NV) || !rd_finite(in[1], RD_NV) || !rd_finite(in[2], RD_NV)) return 1;
    rd_tau(in[0], in[1], in[2], out);
    return rd_finite(out, RD_NV) ? 0 : 2;
}
static int row_mass(const double *const *in, double *out) {
    if (!rd_finite(in[0], RD_NV)) return 1;
    rd_mass(in[0], out);
    return rd_finite(out, RD_NV * RD_NV) ? 0 : 2;
}
static int row_nle(const double *const *in, double *out) {
    if (!rd_finite(in[0], RD_NV) || !rd_finite(in[1], RD_NV)) return 1;
    rd_nle(in[0], in[1], out);
    return rd_finite(out, RD_NV) ? 0 : 2;
}
static int row_gravity(const double *const *in, double *out) {
    if (!rd_finite(in[0], RD_NV)) return 1;
    rd_gravity(in[0], out);
    return rd_finite(out, RD_NV) ? 0 : 2;
}
static int row_fd(const double *const *in, double *out) {
    if (!rd_finite(in[0], RD_NV) || !rd_finite(in[1], RD_NV) || !rd_finite(in[2], RD_NV)) return 1;
    if (rd_fd_raw(in[0], in[1], in[2], out)) return 3;
    return rd_finite(out, RD_NV) ? 0 : 3;
}

typedef struct {
    rd_row row;
    int nin, out_size;
    const double *in[3];
    double *out;
    Py_ssize_t begin, end;
    int status;
} rd_job;

static void *rd_run(void *arg) {
    rd_job *job = (rd_job *)arg;
    int worst = 0;
    const double *in[3] = {0, 0, 0};
    for (Py_ssize_t r = job->begin; r < job->end; ++r) {
        for (int k = 0; k < job->nin; ++k) in[k] = job->in[k] + r * RD_NV;
        const int status = job->row(in, job->out + r * job->out_size);
        if (status > worst) worst = status;
    }
    job->status = worst;
    return NULL;
}

#define RD_MAX_THREADS 256

static int rd_parallel(rd_job *base, Py_ssize_t rows, long threads) {
    if (threads > RD_MAX_THREADS) threads = RD_MAX_THREADS;
    if (threads > rows / RD_MIN_ROWS_PER_THREAD) threads = (long)(rows / RD_MIN_ROWS_PER_THREAD);
    if (threads < 1) threads = 1;
    rd_job jobs[RD_MAX_THREADS];
    pthread_t ids[RD_MAX_THREADS];
    int started[RD_MAX_THREADS];
    for (long k = 0; k < threads; ++k) {
        jobs[k] = *base;
        jobs[k].begin = rows * k / threads;
        jobs[k].end = rows * (k + 1) / threads;
        started[k] = 0;
    }
    for (long k = 1; k < threads; ++k) started[k] = pthread_create(&ids[k], NULL, rd_run, &jobs[k]) == 0;
    rd_run(&jobs[0]);
    int worst = jobs[0].status;
    for (long k = 1; k < threads; ++k) {
        if (started[k])
            pthread_join(ids[k], NULL);
        else
            rd_run(&jobs[k]); /* could not start a thread: do its rows here */
        if (jobs[k].status > worst) worst = jobs[k].status;
    }
    return worst;
}

/* A C-contiguous, aligned, native float64 array of shape (RD_NV,) or (rows, RD_NV). */
static int rd_accept(PyObject *object, int *ndim, npy_intp *rows) {
    if (!PyArray_CheckExact(object)) return 0;
    PyArrayObject *array = (PyArrayObject *)object;
    if (PyArray_TYPE(array) != NPY_DOUBLE || !PyArray_ISCARRAY_RO(array) || !PyArray_ISNOTSWAPPED(array)) return 0;
    const int nd = PyArray_NDIM(array);
    const npy_intp *dims = PyArray_DIMS(array);
    if (nd == 1 && dims[0] == RD_NV) {
        if (*ndim == 2) return 0;
        *ndim = 1;
        return 1;
    }
    if (nd == 2 && dims[1] == RD_NV) {
        if (*ndim == 1 || (*ndim == 2 && *rows != dims[0])) return 0;
        *ndim = 2;
        *rows = dims[0];
        return 1;
    }
    return 0;
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
        if (!rd_accept(args[k], &ndim, &rows)) Py_RETURN_NONE;
    npy_intp dims[3];
    int out_nd = 0;
    if (ndim == 2) dims[out_nd++] = rows;
    dims[out_nd++] = RD_NV;
    if (matrix) dims[out_nd++] = RD_NV;
    PyObject *out = PyArray_SimpleNew(out_nd, dims, NPY_DOUBLE);
    if (!out) return NULL;
    rd_job job = {row, nin, matrix ? RD_NV * RD_NV : RD_NV, {0, 0, 0}, (double *)PyArray_DATA((PyArrayObject *)out), 0, rows, 0};
    for (int k = 0; k < nin; ++k) job.in[k] = (const double *)PyArray_DATA((PyArrayObject *)args[k]);
    int status;
    if (ndim == 1) {
        status = row(job.in, job.out);
    } else {
        Py_BEGIN_ALLOW_THREADS
        status = rd_parallel(&job, rows, threads);
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
} rd_controller;

static void rd_control(const rd_controller *c, double t, const double *q, const double *v, double *tau) {
    const int n = RD_NV;
    const double *p = c->params;
    if (c->kind == 0) {
        for (int i = 0; i < n; ++i) tau[i] = p[i];
    } else if (c->kind == 1) { /* params: target, kp, kd */
        double g[RD_NV];
        c->model->gravity(q, g);
        for (int i = 0; i < n; ++i) tau[i] = p[n + i] * (p[i] - q[i]) - p[2 * n + i] * v[i] + g[i];
    } else { /* params: q_start, q_end, kp, kd, duration */
        const double duration = p[4 * n];
        double s = t / duration;
        s = s < 0.0 ? 0.0 : (s > 1.0 ? 1.0 : s);
        const int moving = 0 < t && t < duration;
        const double position = 10 * pow(s, 3) - 15 * pow(s, 4) + 6 * pow(s, 5);
        const double speed = moving ? (30 * pow(s, 2) - 60 * pow(s, 3) + 30 * pow(s, 4)) / duration : 0.0;
        const double acceleration = moving ? (60 * s - 180 * pow(s, 2) + 120 * pow(s, 3)) / pow(duration, 2) : 0.0;
        double command[RD_NV];
        for (int i = 0; i < n; ++i) {
            const double delta = p[n + i] - p[i];
            const double q_d = p[i] + position * delta, v_d = speed * delta, a_d = acceleration * delta;
            command[i] = a_d + p[3 * n + i] * (v_d - v[i]) + p[2 * n + i] * (q_d - q[i]);
        }
        c->model->tau(q, v, command, tau);
    }
}

/* a = FD(q, v, tau(t, q, v)); the stage's torque is the held one when c->hold. */
static void rd_stage(const rd_controller *c, double t, const double *q, const double *v, const double *held, double *a) {
    double tau[RD_NV];
    if (c->hold || c->kind == 0)
        memcpy(tau, held, sizeof tau);
    else
        rd_control(c, t, q, v, tau);
    if (rd_fd_raw(q, v, tau, a))
        for (int i = 0; i < RD_NV; ++i) a[i] = NAN;
}

static Py_ssize_t rd_integrate(const rd_controller *c, double *q, double *v, double dt, Py_ssize_t steps, double t0, int rk4,
                               double *oq, double *ov, double *oa, double *otau) {
    const int n = RD_NV;
    const double half = 0.5 * dt, sixth = dt / 6.0;
    double tau[RD_NV], a[RD_NV], q2[RD_NV], v2[RD_NV], a2[RD_NV], v3[RD_NV], a3[RD_NV], v4[RD_NV], a4[RD_NV];
    for (Py_ssize_t k = 0; k < steps; ++k) {
        const double t = t0 + k * dt;
        memcpy(oq + k * n, q, n * sizeof(double));
        memcpy(ov + k * n, v, n * sizeof(double));
        rd_control(c, t, q, v, tau);
        memcpy(otau + k * n, tau, n * sizeof(double));
        if (rd_fd_raw(q, v, tau, a))
            for (int i = 0; i < n; ++i) a[i] = NAN;
        memcpy(oa + k * n, a, n * sizeof(double));
        if (rk4) {
            for (int i = 0; i < n; ++i) v2[i] = v[i] + half * a[i], q2[i] = q[i] + half * v[i];
            rd_stage(c, t + half, q2, v2, tau, a2);
            for (int i = 0; i < n; ++i) v3[i] = v[i] + half * a2[i], q2[i] = q[i] + half * v2[i];
            rd_stage(c, t + half, q2, v3, tau, a3);
            for (int i = 0; i < n; ++i) v4[i] = v[i] + dt * a3[i], q2[i] = q[i] + dt * v3[i];
            rd_stage(c, t + dt, q2, v4, tau, a4);
            for (int i = 0; i < n; ++i) {
                q[i] = q[i] + sixth * (v[i] + v4[i] + 2.0 * (v2[i] + v3[i]));
                v[i] = v[i] + sixth * (a[i] + a4[i] + 2.0 * (a2[i] + a3[i]));
            }
        } else {
            for (int i = 0; i < n; ++i) {
                v[i] = v[i] + dt * a[i];
                q[i] = q[i] + dt * v[i];
            }
        }
        if (!rd_finite(q, n) || !rd_finite(v, n)) {
            memcpy(oq + (k + 1) * n, q, n * sizeof(double));
            memcpy(ov + (k + 1) * n, v, n * sizeof(double));
            return k;
        }
    }
    memcpy(oq + steps * n, q, n * sizeof(double));
    memcpy(ov + steps * n, v, n * sizeof(double));
    if (steps > 0) {
        memcpy(otau + steps * n, otau + (steps - 1) * n, n * sizeof(double));
        memcpy(oa + steps * n, oa + (steps - 1) * n, n * sizeof(double));
    } else {
        double zero[RD_NV] = {0};
        memcpy(otau, zero, sizeof zero);
        if (rd_fd_raw(q, v, zero, a))
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
    if (nargs != 14) {
        PyErr_SetString(PyExc_TypeError, "simulate takes 14 arguments");
        return NULL;
    }
    const double dt = PyFloat_AsDouble(args[2]);
    const Py_ssize_t steps = PyLong_AsSsize_t(args[3]);
    const double t0 = PyFloat_AsDouble(args[4]);
    const long rk4 = PyLong_AsLong(args[5]), kind = PyLong_AsLong(args[6]), hold = PyLong_AsLong(args[7]);
    if (PyErr_Occurred()) return NULL;
    const int n = RD_NV;
    const npy_intp sizes[4] = {n, 3 * n, 4 * n + 1};
    if (kind < 0 || kind > 2 || steps < 0) {
        PyErr_SetString(PyExc_ValueError, "bad controller kind or step count");
        return NULL;
    }
    const double *q0 = rd_array(args[0], n, 0), *v0 = rd_array(args[1], n, 0), *params = rd_array(args[8], sizes[kind], 0);
    double *oq = rd_array(args[10], (steps + 1) * n, 1), *ov = rd_array(args[11], (steps + 1) * n, 1);
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
    rd_controller controller = {(int)kind, (int)hold, params, model};
    double q[RD_NV], v[RD_NV];
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
    return Py_BuildValue("{s:i,s:N}", "nv", RD_NV, "parents", parents);
}

static PyMethodDef rd_methods[] = {
    {"tau", (PyCFunction)(void (*)(void))py_tau, METH_FASTCALL, "tau(q, v, a, threads)"},
    {"mass", (PyCFunction)(void (*)(void))py_mass, METH_FASTCALL, "mass(q, threads)"},
    {"nle", (PyCFunction)(void (*)(void))py_nle, METH_FASTCALL, "nle(q, v, threads)"},
    {"gravity", (PyCFunction)(void (*)(void))py_gravity, METH_FASTCALL, "gravity(q, threads)"},
    {"fd", (PyCFunction)(void (*)(void))py_fd, METH_FASTCALL, "fd(q, v, tau, threads)"},
    {"simulate", (PyCFunction)(void (*)(void))py_simulate, METH_FASTCALL, "simulate(...)"},
    {"info", py_info, METH_NOARGS, "info()"},
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
