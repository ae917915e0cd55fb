/* robodyn.compiled frame runtime: appended to one frame's generated kernels (see kinematics.py).
 *
 * Python entry points (METH_FASTCALL; one state 1-D, a stack of states 2-D, one a row):
 *   position(q) -> (3,), rotation(q) -> (3, 3), jacobian(q) -> (6, nv), bias(q, v) -> (6,)
 * Each returns a new float64 array, None when an argument is not a C-contiguous native
 * float64 array of the right shape (the caller checks and converts), or 1 for a non-finite input.
 * The capsule `_frame` (an rd_frame_kernels) hands the kernels to the compiled controllers.
 */

#define RD_FRAME_CAPSULE "robodyn.compiled.frame"

typedef struct {
    int nv;
    void (*pose)(const double *, double *, double *);
    void (*jacobian)(const double *, double *);
    void (*all)(const double *, const double *, double *, double *, double *, double *);
} rd_frame_kernels;

static const rd_frame_kernels rd_frame_self = {RD_NV, rd_frame_pose, rd_frame_jacobian, rd_frame_all};

static int rdf_finite(const double *x, int n) {
    for (int i = 0; i < n; ++i)
        if (!isfinite(x[i])) return 0;
    return 1;
}

/* 0 unusable, else rows (1-D: ndim 1). */
static npy_intp rdf_accept(PyObject *object, int *ndim, npy_intp rows) {
    if (!PyArray_CheckExact(object)) return 0;
    PyArrayObject *array = (PyArrayObject *)object;
    if (PyArray_TYPE(array) != NPY_DOUBLE || !PyArray_ISCARRAY_RO(array) || !PyArray_ISNOTSWAPPED(array)) return 0;
    const int nd = PyArray_NDIM(array);
    const npy_intp *dims = PyArray_DIMS(array);
    if (nd == 1 && dims[0] == RD_NV && (*ndim == 0 || *ndim == 1)) {
        *ndim = 1;
        return 1;
    }
    if (nd == 2 && dims[1] == RD_NV && (*ndim == 0 || (*ndim == 2 && rows == dims[0]))) {
        *ndim = 2;
        return dims[0];
    }
    return 0;
}

/* what: 0 position, 1 rotation, 2 jacobian, 3 bias */
static PyObject *rdf_entry(PyObject *const *args, Py_ssize_t nargs, int what) {
    const int nin = what == 3 ? 2 : 1;
    if (nargs != nin) {
        PyErr_SetString(PyExc_TypeError, "wrong number of arguments");
        return NULL;
    }
    int ndim = 0;
    npy_intp rows = 0;
    for (int k = 0; k < nin; ++k) {
        rows = rdf_accept(args[k], &ndim, rows);
        if (!rows) Py_RETURN_NONE;
    }
    npy_intp dims[3];
    int nd = 0;
    if (ndim == 2) dims[nd++] = rows;
    const int size = what == 0 ? 3 : (what == 1 ? 9 : (what == 2 ? 6 * RD_NV : 6));
    if (what == 0 || what == 3) dims[nd++] = size;
    if (what == 1) dims[nd++] = 3, dims[nd++] = 3;
    if (what == 2) dims[nd++] = 6, dims[nd++] = RD_NV;
    const double *q = (const double *)PyArray_DATA((PyArrayObject *)args[0]);
    const double *v = nin == 2 ? (const double *)PyArray_DATA((PyArrayObject *)args[1]) : NULL;
    if (!rdf_finite(q, (int)(rows * RD_NV)) || (v && !rdf_finite(v, (int)(rows * RD_NV)))) return PyLong_FromLong(1);
    PyObject *out = PyArray_SimpleNew(nd, dims, NPY_DOUBLE);
    if (!out) return NULL;
    double *o = (double *)PyArray_DATA((PyArrayObject *)out);
    double p[3], R[9], J[6 * RD_NV], b[6];
    for (npy_intp r = 0; r < rows; ++r) {
        const double *qr = q + r * RD_NV;
        double *target = o + r * size;
        if (what == 0) rd_frame_pose(qr, target, R);
        if (what == 1) rd_frame_pose(qr, p, target);
        if (what == 2) rd_frame_jacobian(qr, target);
        if (what == 3) rd_frame_all(qr, v + r * RD_NV, p, R, J, target);
    }
    return out;
}

static PyObject *pyf_position(PyObject *m, PyObject *const *a, Py_ssize_t n) { return rdf_entry(a, n, 0); }
static PyObject *pyf_rotation(PyObject *m, PyObject *const *a, Py_ssize_t n) { return rdf_entry(a, n, 1); }
static PyObject *pyf_jacobian(PyObject *m, PyObject *const *a, Py_ssize_t n) { return rdf_entry(a, n, 2); }
static PyObject *pyf_bias(PyObject *m, PyObject *const *a, Py_ssize_t n) { return rdf_entry(a, n, 3); }
static PyObject *pyf_info(PyObject *m, PyObject *unused) { return Py_BuildValue("{s:i}", "nv", RD_NV); }

static PyMethodDef rdf_methods[] = {
    {"position", (PyCFunction)(void (*)(void))pyf_position, METH_FASTCALL, "position(q)"},
    {"rotation", (PyCFunction)(void (*)(void))pyf_rotation, METH_FASTCALL, "rotation(q)"},
    {"jacobian", (PyCFunction)(void (*)(void))pyf_jacobian, METH_FASTCALL, "jacobian(q)"},
    {"bias", (PyCFunction)(void (*)(void))pyf_bias, METH_FASTCALL, "bias(q, v)"},
    {"info", pyf_info, METH_NOARGS, "info()"},
    {NULL, NULL, 0, NULL},
};

static PyObject *rd_frame_module(const char *name) {
    import_array1(NULL);
    static struct PyModuleDef definition = {PyModuleDef_HEAD_INIT, NULL, "robodyn compiled frame kinematics", -1, rdf_methods};
    definition.m_name = name;
    PyObject *module = PyModule_Create(&definition);
    if (!module) return NULL;
    PyObject *capsule = PyCapsule_New((void *)&rd_frame_self, RD_FRAME_CAPSULE, NULL);
    if (!capsule || PyModule_AddObject(module, "_frame", capsule) < 0) {
        Py_XDECREF(capsule);
        Py_DECREF(module);
        return NULL;
    }
    return module;
}
