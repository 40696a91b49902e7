/*
 * scenegrep.scene._reach: the inverted walk's exact reach test (scene/follow_inverse.py) in one C
 * pass per backward step, so no array is made per operation (the step's many small numpy calls
 * cost more than their arithmetic).
 *
 * narrow(p, r, a, z, radius, unit, before, after, constants, nearest, low, high)
 *     Row i of m: the point p[i] + t r[i] (t in [0, 1]) and the centreline segment a[i]-z[i]
 *     (p, r, a, z, unit, before, after: (m, 2) float64; radius: (m,) float64). Writes into low[i],
 *     high[i] ((m,) float64) the hull [t_lo, t_hi] (t_lo > t_hi: empty) of the t at which the
 *     point lies within radius[i] of the segment (the band along it and the discs at its ends),
 *     then, when `nearest`, that hull narrowed past the t at which the point lies FOOT_SLACK or
 *     more before a along the segment (unit[i]: its direction) and along the segment before it
 *     (before[i]; NaN: none), and likewise past z along it and the segment after (after[i]).
 *     constants = (DEGENERATE_M ** 2, FOOT_SLACK_M). The formulas, their order of operations and
 *     numpy's NaN rules (np.minimum and np.maximum propagate NaN) are those of the numpy code this
 *     replaced (kept in follow_inverse.py's docstrings), so the results are the same bit for bit
 *     (but for the sign of a zero). Shapes and dtypes are checked (ValueError otherwise).
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>

typedef struct {
    Py_buffer view;
} Array;

/* A C-contiguous float64 buffer of `rows` rows of `columns` entries (columns 0: 1-d). */
static int get(PyObject *obj, Array *a, const char *name, Py_ssize_t rows, Py_ssize_t columns, int writable) {
    int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (writable ? PyBUF_WRITABLE : 0);
    if (PyObject_GetBuffer(obj, &a->view, flags) < 0) {
        a->view.obj = NULL;
        return -1;
    }
    const char *format = a->view.format ? a->view.format : "";
    if (format[0] == '<' || format[0] == '=' || format[0] == '@') format++;
    int ndim = columns ? 2 : 1;
    int ok = format[0] == 'd' && format[1] == 0 && a->view.ndim == ndim && a->view.shape[0] == rows &&
             (columns == 0 || a->view.shape[1] == columns);
    if (!ok) {
        PyErr_Format(PyExc_ValueError, "%s: expected a C-contiguous float64 array of %zd rows%s", name, rows,
                     columns ? " of 2 columns" : "");
        PyBuffer_Release(&a->view);
        a->view.obj = NULL;
        return -1;
    }
    return 0;
}

/* np.minimum and np.maximum: NaN if either is. */
static inline double np_min(double x, double y) {
    if (isnan(x) || isnan(y)) return NAN;
    return x <= y ? x : y;
}

static inline double np_max(double x, double y) {
    if (isnan(x) || isnan(y)) return NAN;
    return x >= y ? x : y;
}

/* follow_inverse._linear_bounds: the t with bottom <= f0 + f1 t <= top. */
static inline void linear_bounds(double f0, double f1, double bottom, double top, double *low, double *high) {
    double u = (bottom - f0) / f1, v = (top - f0) / f1;
    if (fabs(f1) <= 1e-300) {
        int inside = f0 >= bottom && f0 <= top;
        *low = inside ? -INFINITY : INFINITY;
        *high = inside ? INFINITY : -INFINITY;
    } else {
        *low = np_min(u, v);
        *high = np_max(u, v);
    }
}

/* follow_inverse._quadratic_below: the t in [0, 1] with |d + t r| <= radius. */
static inline void quadratic_below(double rx, double ry, double dx, double dy, double radius, double still,
                                   double *low, double *high) {
    double rr = rx * rx + ry * ry;
    double dr = dx * rx + dy * ry;
    double c = (dx * dx + dy * dy) - radius * radius;
    double lo, hi;
    if (rr > still) {
        double disc = dr * dr - rr * c;
        double root = sqrt(disc >= 0 ? disc : NAN);
        lo = (-dr - root) / rr;
        hi = (-dr + root) / rr;
    } else {
        lo = c <= 0 ? 0.0 : INFINITY;
        hi = c <= 0 ? 1.0 : -INFINITY;
    }
    if (isnan(lo) || isnan(hi)) {
        *low = INFINITY;
        *high = -INFINITY;
    } else {
        *low = np_max(lo, 0.0);
        *high = np_min(hi, 1.0);
    }
}

/* follow_inverse._stadium: the hull of the band along a-b and the discs at its ends. */
static inline void stadium(double px, double py, double rx, double ry, double ax, double ay, double zx, double zy,
                           double radius, double still, double *low, double *high) {
    double wx = zx - ax, wy = zy - ay;
    double ww = wx * wx + wy * wy;
    double length = sqrt(ww);
    double pax = px - ax, pay = py - ay;
    double lows[3], highs[3], l0, h0, l1, h1;
    linear_bounds((pax * wx + pay * wy) / ww, (rx * wx + ry * wy) / ww, 0.0, 1.0, &l0, &h0);
    linear_bounds((wx * pay - wy * pax) / length, (wx * ry - wy * rx) / length, -radius, radius, &l1, &h1);
    quadratic_below(rx, ry, pax, pay, radius, still, &lows[0], &highs[0]);
    quadratic_below(rx, ry, px - zx, py - zy, radius, still, &lows[1], &highs[1]);
    lows[2] = ww > 0 ? np_max(np_max(0.0, l0), l1) : INFINITY;
    highs[2] = ww > 0 ? np_min(np_min(1.0, h0), h1) : -INFINITY;
    double t_lo = INFINITY, t_hi = -INFINITY;
    for (int k = 0; k < 3; k++) {
        int empty = lows[k] > highs[k];
        t_lo = k ? np_min(t_lo, empty ? INFINITY : lows[k]) : (empty ? INFINITY : lows[k]);
        t_hi = k ? np_max(t_hi, empty ? -INFINITY : highs[k]) : (empty ? -INFINITY : highs[k]);
    }
    *low = t_lo;
    *high = t_hi;
}

/* follow_inverse._nearest_on: [low, high] narrowed past the t forbidden at either end. */
static inline void nearest_on(double px, double py, double rx, double ry, const double *vertex[2],
                              const double *direction[4], double slack, double *low, double *high) {
    double f_lo[2], f_hi[2];
    for (int j = 0; j < 2; j++) {
        double sign = j ? 1.0 : -1.0, l[2], h[2];
        for (int k = 0; k < 2; k++) {
            const double *d = direction[2 * j + k];
            double along = sign * ((px - vertex[j][0]) * d[0] + (py - vertex[j][1]) * d[1]);
            double rate = sign * (rx * d[0] + ry * d[1]);
            linear_bounds(along, rate, slack, INFINITY, &l[k], &h[k]);
        }
        f_lo[j] = np_max(np_max(0.0, l[0]), l[1]);
        f_hi[j] = np_min(np_min(1.0, h[0]), h[1]);
        if (isnan(f_lo[j]) || isnan(f_hi[j]) || isnan(direction[2 * j + 1][0])) {
            f_lo[j] = INFINITY;
            f_hi[j] = -INFINITY;
        }
    }
    double lo = *low, hi = *high;
    for (int round = 0; round < 2; round++) {
        for (int j = 0; j < 2; j++) {
            if (lo >= f_lo[j] && lo <= f_hi[j]) lo = f_hi[j];
            if (hi >= f_lo[j] && hi <= f_hi[j]) hi = f_lo[j];
        }
    }
    *low = lo;
    *high = hi;
}

static PyObject *narrow(PyObject *self, PyObject *args) {
    (void)self;
    PyObject *objs[10];
    double still, slack;
    int nearest;
    if (!PyArg_ParseTuple(args, "OOOOOOOO(dd)pOO", &objs[0], &objs[1], &objs[2], &objs[3], &objs[4], &objs[5],
                          &objs[6], &objs[7], &still, &slack, &nearest, &objs[8], &objs[9])) {
        return NULL;
    }
    static const char *names[10] = {"p", "r", "a", "z", "radius", "unit", "before", "after", "low", "high"};
    Array arrays[10];
    int got = 0, failed = 0;
    Py_buffer first;
    if (PyObject_GetBuffer(objs[0], &first, PyBUF_ND) < 0) return NULL;
    Py_ssize_t m = first.ndim >= 1 ? first.shape[0] : -1;
    PyBuffer_Release(&first);
    for (; got < 10; got++) {
        Py_ssize_t columns = (got == 4 || got >= 8) ? 0 : 2;
        if (get(objs[got], &arrays[got], names[got], m, columns, got >= 8) < 0) {
            failed = 1;
            break;
        }
    }
    if (!failed) {
        const double *p = arrays[0].view.buf, *r = arrays[1].view.buf, *a = arrays[2].view.buf;
        const double *z = arrays[3].view.buf, *radius = arrays[4].view.buf, *unit = arrays[5].view.buf;
        const double *before = arrays[6].view.buf, *after = arrays[7].view.buf;
        double *low = arrays[8].view.buf, *high = arrays[9].view.buf;
        for (Py_ssize_t i = 0; i < m; i++) {
            stadium(p[2 * i], p[2 * i + 1], r[2 * i], r[2 * i + 1], a[2 * i], a[2 * i + 1], z[2 * i], z[2 * i + 1],
                    radius[i], still, &low[i], &high[i]);
            if (nearest) {
                const double *vertex[2] = {a + 2 * i, z + 2 * i};
                const double *direction[4] = {unit + 2 * i, before + 2 * i, unit + 2 * i, after + 2 * i};
                nearest_on(p[2 * i], p[2 * i + 1], r[2 * i], r[2 * i + 1], vertex, direction, slack, &low[i], &high[i]);
            }
        }
    }
    for (int k = 0; k < got; k++) PyBuffer_Release(&arrays[k].view);
    if (failed) return NULL;
    Py_RETURN_NONE;
}

static PyMethodDef methods[] = {
    {"narrow", narrow, METH_VARARGS,
     "narrow(p, r, a, z, radius, unit, before, after, constants, nearest, low, high): the reach test"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_reach", NULL, -1, methods, NULL, NULL, NULL, NULL};

PyMODINIT_FUNC PyInit__reach(void) { return PyModule_Create(&module); }
