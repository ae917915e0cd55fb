/* robodyn contact step, previous modes kept (robodyn/compiled/contact.py): after the
 * includes and core.c. One METH_FASTCALL entry point,
 *
 *   kept(inverse, joints, centres, offsets, mask, v, tau, bias, guess, axes, settings, q)
 *       -> (v_next (nv,), impulses (k, 3), forces (k, 3), slip (k,), gaps (k,), dq = dt v_next,
 *           the floating base's new origin (3,) or None) or None
 *
 * with M⁻¹ (nv, nv, its upper triangle read), the joints' world Jacobians (6, nv,
 * column-major: Pinocchio's data.J), the points' anchors in world axes (k, 3) and their
 * offsets (radius · n, k x 3: a point is its anchor minus its offset), which columns each
 * point sees (k, nv: 0 or 1), the previous step's impulses (3k,), the axes (3, 3) as rows
 * (t1, t2, n), settings = (dt, baumgarte, friction, the plane's level n · c) and q (a
 * floating base's configuration, its quaternion (x, y, z, w) at q[3:7]) or None. It is robodyn.sim.contact_solver's polish of the previous impulses with
 * cone=True (every closed contact sticking, its impulse inside its cone) on a regular
 * system: the same modes, an LU solve of the sticking rows (partial pivoting), the same
 * bound and the same complementarity check. None means "not this case" (a contact on its
 * cone, more rows than nv, a singular or too large answer, a failed check, or an argument
 * that is not a C-contiguous float64 array of the expected size): the caller then takes
 * the Python path, which solves the same problem.
 */

#define RDC_TOLERANCE 1e-9 /* contact_solver.POLISH_TOLERANCE */

static const double *rdc_array(PyObject *object, npy_intp size) {
    if (!PyArray_CheckExact(object)) return NULL;
    PyArrayObject *array = (PyArrayObject *)object;
    if (PyArray_TYPE(array) != NPY_DOUBLE || !PyArray_ISCARRAY_RO(array) || !PyArray_ISNOTSWAPPED(array)) return NULL;
    if (PyArray_SIZE(array) != size) return NULL;
    return (const double *)PyArray_DATA(array);
}

/* A Fortran-ordered (column-major) one: Eigen's, as Pinocchio's data.J. */
static const double *rdc_columns(PyObject *object, npy_intp size) {
    if (!PyArray_CheckExact(object)) return NULL;
    PyArrayObject *array = (PyArrayObject *)object;
    if (PyArray_TYPE(array) != NPY_DOUBLE || !PyArray_ISFARRAY_RO(array) || !PyArray_ISNOTSWAPPED(array)) return NULL;
    if (PyArray_NDIM(array) != 2 || PyArray_SIZE(array) != size) return NULL;
    return (const double *)PyArray_DATA(array);
}

static double rdc_largest(const double *x, int n) {
    double largest = 0.0;
    for (int i = 0; i < n; ++i)
        if (fabs(x[i]) > largest || isnan(x[i])) largest = isnan(x[i]) ? NAN : fabs(x[i]);
    return largest;
}

/* Solves a x = b in place (a: m x m row-major, overwritten; b becomes x). 0 on a zero pivot. */
static int rdc_lu_solve(double *a, double *b, int m) {
    for (int k = 0; k < m; ++k) {
        int pivot = k;
        double best = fabs(a[k * m + k]);
        for (int i = k + 1; i < m; ++i)
            if (fabs(a[i * m + k]) > best) best = fabs(a[i * m + k]), pivot = i;
        if (!(best > 0.0)) return 0;
        if (pivot != k) {
            for (int j = 0; j < m; ++j) {
                double t = a[k * m + j];
                a[k * m + j] = a[pivot * m + j];
                a[pivot * m + j] = t;
            }
            double t = b[k];
            b[k] = b[pivot];
            b[pivot] = t;
        }
        for (int i = k + 1; i < m; ++i) {
            double factor = a[i * m + k] / a[k * m + k];
            for (int j = k + 1; j < m; ++j) a[i * m + j] -= factor * a[k * m + j];
            b[i] -= factor * b[k];
        }
    }
    for (int i = m - 1; i >= 0; --i) {
        double sum = b[i];
        for (int j = i + 1; j < m; ++j) sum -= a[i * m + j] * b[j];
        b[i] = sum / a[i * m + i];
    }
    return 1;
}

/* The impulses of the sticking contacts `stuck` (count), others open, into p; 0: not this case. */
static int rdc_stick(const double *A, const double *c, const int *stuck, int count, int r, double scale_p, double *work,
                     double *p) {
    const int m = 3 * count;
    double *sub = work, *x = work + m * m;
    for (int a = 0; a < m; ++a) {
        const int row = 3 * stuck[a / 3] + a % 3;
        x[a] = -c[row];
        for (int b = 0; b < m; ++b) sub[a * m + b] = A[row * r + 3 * stuck[b / 3] + b % 3];
    }
    const double bound = 1e3 * scale_p; /* contact_solver._bound: the impulses' scale, never the target's */
    if (!rdc_lu_solve(sub, x, m) || !(rdc_largest(x, m) <= bound)) return 0;
    for (int i = 0; i < r; ++i) p[i] = 0.0;
    for (int a = 0; a < m; ++a) p[3 * stuck[a / 3] + a % 3] = x[a];
    return 1;
}

/* contact_solver._solves: every impulse in its cone, no contact penetrating or pushing apart,
 * no slip turned against the modes' (before). */
static int rdc_solves(const double *A, const double *c, const double *p, const double *before, double friction, int r,
                      double *u) {
    for (int a = 0; a < r; ++a) {
        double sum = c[a];
        for (int b = 0; b < r; ++b) sum += A[a * r + b] * p[b];
        u[a] = sum;
    }
    const double size_p = RDC_TOLERANCE * fmax(rdc_largest(p, r), 1e-12);
    const double size_u = RDC_TOLERANCE * fmax(rdc_largest(c, r), 1e-12);
    const double pushing = size_u * size_p / RDC_TOLERANCE;
    for (int i = 0; i < r; i += 3) {
        const double normal = p[i + 2], speed = u[i + 2];
        if (!(normal >= -size_p) || hypot(p[i], p[i + 1]) > friction * normal + size_p) return 0;
        if (!(speed >= -size_u) || fabs(speed) * fabs(normal) > pushing) return 0;
        const int turned = u[i] * before[i] + u[i + 1] * before[i + 1] <= 0;
        if (turned && normal > size_p && hypot(u[i], u[i + 1]) > size_u) return 0;
    }
    return 1;
}

/* free = v + dt M⁻¹ (tau − bias), R = M⁻¹ Jᵀ stored transposed (r x nv), A = J R (symmetric:
 * its upper triangle mirrored), c = J free + the gaps' bias. M⁻¹ is read from its upper
 * triangle (Pinocchio's computeMinverse fills that one) into `full` (nv x nv). */
static void rdc_terms(const double *inverse, const double *J, const double *v, const double *tau, const double *bias,
                      const double *gaps, const double *settings, int nv, int r, double *full, double *free, double *R,
                      double *A, double *c) {
    const double dt = settings[0], beta = settings[1];
    for (int i = 0; i < nv; ++i)
        for (int j = i; j < nv; ++j) full[i * nv + j] = full[j * nv + i] = inverse[i * nv + j];
    for (int i = 0; i < nv; ++i) {
        double sum = 0.0;
        for (int j = 0; j < nv; ++j) sum += full[i * nv + j] * (tau[j] - bias[j]);
        free[i] = v[i] + dt * sum;
    }
    for (int a = 0; a < r; ++a)
        for (int i = 0; i < nv; ++i) {
            double s = 0.0;
            for (int j = 0; j < nv; ++j) s += full[i * nv + j] * J[a * nv + j];
            R[a * nv + i] = s;
        }
    for (int a = 0; a < r; ++a) {
        double s = 0.0;
        for (int i = 0; i < nv; ++i) s += J[a * nv + i] * free[i];
        c[a] = s;
        for (int b = a; b < r; ++b) {
            double t = 0.0;
            for (int i = 0; i < nv; ++i) t += J[a * nv + i] * R[b * nv + i];
            A[a * r + b] = A[b * r + a] = t;
        }
    }
    for (int a = 2; a < r; a += 3) {
        const double gap = gaps[a / 3];
        c[a] += gap >= 0.0 ? gap / dt : beta * gap / dt;
    }
}

/* The polish of the previous impulses (contact_solver's polish with cone=True): every closed
 * contact sticks, its impulse inside its cone; 0: not this case. */
static int rdc_kept(const double *A, const double *c, const double *guess, double friction, int r, int nv, double *work,
                    double *p) {
    double *u_before = work, *u = work + r;
    int *stuck = (int *)(work + 2 * r), count = 0;
    for (int a = 0; a < r; ++a) {
        double sum = c[a];
        for (int b = 0; b < r; ++b) sum += A[a * r + b] * guess[b];
        u_before[a] = sum;
    }
    const double scale_p = fmax(rdc_largest(guess, r), 1e-300), scale_u = fmax(rdc_largest(c, r), 1e-300);
    if (isnan(scale_p) || isnan(scale_u)) return 0;
    for (int i = 0; i < r; i += 3) {
        const double normal = guess[i + 2];
        if (!(normal > 1e-6 * scale_p)) continue; /* open */
        if (!(hypot(guess[i], guess[i + 1]) < (1 - 1e-6) * friction * normal)) return 0; /* on its cone: slipped */
        stuck[count++] = i / 3;
    }
    if (3 * count > nv) return 0; /* redundant rows: least-norm, in Python */
    if (count == 0)
        for (int i = 0; i < r; ++i) p[i] = 0.0;
    else if (!rdc_stick(A, c, stuck, count, r, scale_p, work + 3 * r, p))
        return 0;
    return rdc_solves(A, c, p, u_before, friction, r, u);
}

/* The floating base's new origin q[:3] + R(q) dq[:3] (robodyn.sim.contact.integrate; R as
 * Eigen's Quaternion::toRotationMatrix of q[3:7] = (x, y, z, w)). */
static void rdc_base(const double *q, const double *dq, double *base) {
    const double x = q[3], y = q[4], z = q[5], w = q[6];
    const double tx = 2 * x, ty = 2 * y, tz = 2 * z;
    const double twx = tx * w, twy = ty * w, twz = tz * w, txx = tx * x, txy = ty * x, txz = tz * x;
    const double tyy = ty * y, tyz = tz * y, tzz = tz * z;
    const double R[9] = {1 - (tyy + tzz), txy - twz, txz + twy, txy + twz, 1 - (txx + tzz),
                         tyz - twx,       txz - twy, tyz + twx, 1 - (txx + tyy)};
    for (int i = 0; i < 3; ++i) base[i] = q[i] + (R[3 * i] * dq[0] + R[3 * i + 1] * dq[1] + R[3 * i + 2] * dq[2]);
}

static PyObject *rdc_result(const double *free, const double *R, const double *J, const double *p, const double *gaps,
                            const double *axes, const double *q, double dt, int nv, int r) {
    const npy_intp k = r / 3, vector[1] = {nv}, matrix[2] = {k, 3}, slips[1] = {k};
    PyObject *v_next = PyArray_SimpleNew(1, vector, NPY_DOUBLE), *impulses = PyArray_SimpleNew(2, matrix, NPY_DOUBLE);
    PyObject *forces = PyArray_SimpleNew(2, matrix, NPY_DOUBLE), *slip = PyArray_SimpleNew(1, slips, NPY_DOUBLE);
    const npy_intp three[1] = {3};
    PyObject *heights = PyArray_SimpleNew(1, slips, NPY_DOUBLE), *step = PyArray_SimpleNew(1, vector, NPY_DOUBLE);
    PyObject *base = q ? PyArray_SimpleNew(1, three, NPY_DOUBLE) : Py_NewRef(Py_None);
    if (!v_next || !impulses || !forces || !slip || !heights || !step || !base) {
        Py_XDECREF(v_next), Py_XDECREF(impulses), Py_XDECREF(forces), Py_XDECREF(slip), Py_XDECREF(heights);
        Py_XDECREF(step), Py_XDECREF(base);
        return NULL;
    }
    double *vn = PyArray_DATA((PyArrayObject *)v_next), *pi = PyArray_DATA((PyArrayObject *)impulses);
    double *f = PyArray_DATA((PyArrayObject *)forces), *s = PyArray_DATA((PyArrayObject *)slip);
    memcpy(PyArray_DATA((PyArrayObject *)heights), gaps, (size_t)k * sizeof(double));
    for (int i = 0; i < nv; ++i) {
        double sum = 0.0;
        for (int a = 0; a < r; ++a) sum += R[a * nv + i] * p[a];
        vn[i] = free[i] + sum;
    }
    for (int a = 0; a < r; ++a) pi[a] = p[a];
    for (int i = 0; i < k; ++i) {
        for (int j = 0; j < 3; ++j)
            f[3 * i + j] = (p[3 * i] * axes[j] + p[3 * i + 1] * axes[3 + j] + p[3 * i + 2] * axes[6 + j]) / dt;
        double tangent[2];
        for (int t = 0; t < 2; ++t) {
            double sum = 0.0;
            for (int j = 0; j < nv; ++j) sum += J[(3 * i + t) * nv + j] * vn[j];
            tangent[t] = sum;
        }
        s[i] = hypot(tangent[0], tangent[1]);
    }
    double *dq = PyArray_DATA((PyArrayObject *)step);
    for (int i = 0; i < nv; ++i) dq[i] = dt * vn[i];
    if (q) rdc_base(q, dq, PyArray_DATA((PyArrayObject *)base));
    return Py_BuildValue("(NNNNNNN)", v_next, impulses, forces, slip, heights, step, base);
}

/* The points' Jacobian J (3k x nv) in the contact axes: row t of point i is
 * a_t · (J_v − [p_i]× J_ω) over the columns it sees (robodyn.sim.contact.ContactStepper.jacobian). */
static void rdc_jacobian(const double *joints, const double *points, const double *mask, const double *axes, int k, int nv,
                         double *J) {
    for (int i = 0; i < k; ++i) {
        const double *p = points + 3 * i;
        for (int j = 0; j < nv; ++j) {
            const double m = mask[i * nv + j], *column = joints + 6 * j; /* column-major (6, nv) */
            const double vx = column[0] * m, vy = column[1] * m, vz = column[2] * m;
            const double wx = column[3] * m, wy = column[4] * m, wz = column[5] * m;
            const double lx = vx - (-p[2] * wy + p[1] * wz), ly = vy - (p[2] * wx - p[0] * wz), lz = vz - (-p[1] * wx + p[0] * wy);
            for (int t = 0; t < 3; ++t) J[(3 * i + t) * nv + j] = axes[3 * t] * lx + axes[3 * t + 1] * ly + axes[3 * t + 2] * lz;
        }
    }
}

static PyObject *rdc_kept_step(PyObject *module, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 12 || !PyArray_CheckExact(args[5]) || !PyArray_CheckExact(args[8])) Py_RETURN_NONE;
    const int nv = (int)PyArray_SIZE((PyArrayObject *)args[5]), r = (int)PyArray_SIZE((PyArrayObject *)args[8]), k = r / 3;
    const double *inverse = rdc_array(args[0], (npy_intp)nv * nv), *joints = rdc_columns(args[1], 6 * (npy_intp)nv);
    const double *centres = rdc_array(args[2], r), *offsets = rdc_array(args[3], r);
    const double *mask = rdc_array(args[4], (npy_intp)k * nv), *v = rdc_array(args[5], nv);
    const double *tau = rdc_array(args[6], nv), *bias = rdc_array(args[7], nv), *guess = rdc_array(args[8], r);
    const double *axes = rdc_array(args[9], 9), *settings = rdc_array(args[10], 4);
    const npy_intp nq = PyArray_CheckExact(args[11]) ? PyArray_SIZE((PyArrayObject *)args[11]) : 0;
    const double *q = nq >= 7 ? rdc_array(args[11], nq) : NULL; /* a floating base's q */
    if (!inverse || !joints || !centres || !offsets || !mask || !v || !tau || !bias || !guess || !axes || !settings ||
        (args[11] != Py_None && !q) || k == 0 || r % 3)
        Py_RETURN_NONE;
    const size_t size = (size_t)nv * (nv + 1) + 3 * (size_t)nv * r + 2 * (size_t)r * r + 8 * (size_t)r + 2;
    double *buffer = malloc(size * sizeof(double));
    if (!buffer) return PyErr_NoMemory();
    double *free_velocity = buffer, *R = free_velocity + nv, *A = R + nv * r, *c = A + r * r, *p = c + r;
    double *J = p + r, *full = J + (size_t)r * nv, *points = full + (size_t)nv * nv, *gaps = points + r;
    double *work = gaps + k; /* u_before, u, stuck, the system */
    for (int i = 0; i < k; ++i) {
        for (int j = 0; j < 3; ++j) points[3 * i + j] = centres[3 * i + j] - offsets[3 * i + j];
        gaps[i] = (points[3 * i] * axes[6] + points[3 * i + 1] * axes[7] + points[3 * i + 2] * axes[8]) - settings[3];
    }
    rdc_jacobian(joints, points, mask, axes, k, nv, J);
    rdc_terms(inverse, J, v, tau, bias, gaps, settings, nv, r, full, free_velocity, R, A, c);
    PyObject *result = NULL;
    if (rdc_kept(A, c, guess, settings[2], r, nv, work, p))
        result = rdc_result(free_velocity, R, J, p, gaps, axes, q, settings[0], nv, r);
    else
        result = Py_NewRef(Py_None);
    free(buffer);
    return result;
}

static PyMethodDef rdc_methods[] = {
    {"kept", (PyCFunction)(void (*)(void))rdc_kept_step, METH_FASTCALL,
     "kept(inverse, joints, centres, offsets, mask, v, tau, bias, guess, axes, settings, q)"},
    {NULL, NULL, 0, NULL},
};

static PyObject *rdc_module(const char *name) {
    import_array1(NULL);
    static struct PyModuleDef definition = {PyModuleDef_HEAD_INIT, NULL, "robodyn compiled contact step", -1, rdc_methods};
    definition.m_name = name;
    return PyModule_Create(&definition);
}
