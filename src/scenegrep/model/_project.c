/*
 * scenegrep.model._project: shapely's line_locate_point (GEOS LengthIndexOfPoint::indexOf) for
 * the polylines of model/polylines.py, on their flat segment arrays, without making a shapely
 * point or going through GEOS's geometry per call (a call costs ~0.6 us per point in GEOS).
 *
 * locate(start, end, first, count, line, x, y, out)
 *     start, end: (s, 2) float64, the segments; first, count: (k,) int64, polyline j's segments
 *     are first[j] .. first[j] + count[j] - 1; line: (n,) int64; x, y: (n,) float64; out: (n,)
 *     float64, written. out[i]: the arc length along polyline line[i] of its point nearest to
 *     (x[i], y[i]), as GEOS computes it: over the segments in order, the first at the least
 *     distance (Distance::pointToSegment; a distance not below DBL_MAX, e.g. NaN, never counts),
 *     the point's projection factor on it (LineSegment::projectionFactor) clamped to [0, 1] times
 *     its length plus the lengths of the segments before it summed from 0 in order; -1 when no
 *     segment counts (where shapely raises). The same operations in the same order, built with
 *     -ffp-contract=off, so the same doubles. Shapes, dtypes and indices are checked (ValueError).
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <float.h>
#include <math.h>

/* A C-contiguous 1-d (columns 0) or (rows, columns) buffer of 8-byte floats (kind 'd') or
 * integers (kind 'q': 'q' or 'l'); rows < 0: any number of rows. */
static int get(PyObject *obj, Py_buffer *view, const char *name, char kind, Py_ssize_t rows, Py_ssize_t columns,
               int writable) {
    int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (writable ? PyBUF_WRITABLE : 0);
    if (PyObject_GetBuffer(obj, view, flags) < 0) {
        view->obj = NULL;
        return -1;
    }
    const char *format = view->format ? view->format : "";
    if (format[0] == '<' || format[0] == '=' || format[0] == '@') format++;
    int typed = format[1] == 0 && view->itemsize == 8 &&
                (kind == 'd' ? format[0] == 'd' : (format[0] == 'q' || format[0] == 'l'));
    int ndim = columns ? 2 : 1;
    int ok = typed && view->ndim == ndim && (rows < 0 || view->shape[0] == rows) &&
             (columns == 0 || view->shape[1] == columns);
    if (!ok) {
        PyErr_Format(PyExc_ValueError, "%s: expected a C-contiguous %s array%s", name,
                     kind == 'd' ? "float64" : "int64", columns ? " of 2 columns" : "");
        PyBuffer_Release(view);
        view->obj = NULL;
        return -1;
    }
    return 0;
}

/* Distance::pointToSegment (A != B: the polylines have no repeated vertices, and a zero squared
 * length gives NaN as in GEOS's division). */
static inline double point_to_segment(double px, double py, double ax, double ay, double bx, double by, double *r) {
    double dx = bx - ax, dy = by - ay;
    double squared = dx * dx + dy * dy;
    *r = ((px - ax) * dx + (py - ay) * dy) / squared;
    if (*r <= 0.0) return sqrt((px - ax) * (px - ax) + (py - ay) * (py - ay));
    if (*r >= 1.0) return sqrt((px - bx) * (px - bx) + (py - by) * (py - by));
    double s = ((ay - py) * dx - (ax - px) * dy) / squared;
    return fabs(s) * sqrt(squared);
}

static PyObject *locate(PyObject *self, PyObject *args) {
    (void)self;
    PyObject *objects[8];
    if (!PyArg_ParseTuple(args, "OOOOOOOO", &objects[0], &objects[1], &objects[2], &objects[3], &objects[4],
                          &objects[5], &objects[6], &objects[7]))
        return NULL;
    Py_buffer v[8];
    for (int k = 0; k < 8; k++) v[k].obj = NULL;
    PyObject *result = NULL;
    if (get(objects[0], &v[0], "start", 'd', -1, 2, 0) < 0) goto done;
    Py_ssize_t s = v[0].shape[0];
    if (get(objects[1], &v[1], "end", 'd', s, 2, 0) < 0) goto done;
    if (get(objects[2], &v[2], "first", 'q', -1, 0, 0) < 0) goto done;
    Py_ssize_t k = v[2].shape[0];
    if (get(objects[3], &v[3], "count", 'q', k, 0, 0) < 0) goto done;
    if (get(objects[4], &v[4], "line", 'q', -1, 0, 0) < 0) goto done;
    Py_ssize_t n = v[4].shape[0];
    if (get(objects[5], &v[5], "x", 'd', n, 0, 0) < 0) goto done;
    if (get(objects[6], &v[6], "y", 'd', n, 0, 0) < 0) goto done;
    if (get(objects[7], &v[7], "out", 'd', n, 0, 1) < 0) goto done;
    const double *start = v[0].buf, *end = v[1].buf, *x = v[5].buf, *y = v[6].buf;
    const long long *first = v[2].buf, *count = v[3].buf, *line = v[4].buf;
    double *out = v[7].buf;
    for (Py_ssize_t j = 0; j < k; j++) {
        if (first[j] < 0 || count[j] < 0 || first[j] > s || count[j] > s - first[j]) {
            PyErr_Format(PyExc_ValueError, "polyline %zd: segments out of range", j);
            goto done;
        }
    }
    for (Py_ssize_t i = 0; i < n; i++) {
        if (line[i] < 0 || line[i] >= k) {
            PyErr_Format(PyExc_ValueError, "line[%zd] = %lld: no such polyline", i, line[i]);
            goto done;
        }
    }
    for (Py_ssize_t i = 0; i < n; i++) {
        double least = DBL_MAX, measure = -1.0, before = 0.0;
        const double px = x[i], py = y[i];
        for (long long g = first[line[i]], stop = first[line[i]] + count[line[i]]; g < stop; g++) {
            double ax = start[2 * g], ay = start[2 * g + 1], bx = end[2 * g], by = end[2 * g + 1];
            double r;
            double distance = point_to_segment(px, py, ax, ay, bx, by, &r);
            double length = sqrt((ax - bx) * (ax - bx) + (ay - by) * (ay - by));
            if (distance < least) {
                least = distance;
                /* LineSegment::projectionFactor: 0 at a, 1 at b, else r (the same expression) */
                double factor = (px == ax && py == ay) ? 0.0 : (px == bx && py == by) ? 1.0 : r;
                measure = factor <= 0.0 ? before : factor <= 1.0 ? before + factor * length : before + length;
            }
            before += length;
        }
        out[i] = measure;
    }
    Py_INCREF(Py_None);
    result = Py_None;
done:
    for (int j = 0; j < 8; j++)
        if (v[j].obj) PyBuffer_Release(&v[j]);
    return result;
}

static PyMethodDef methods[] = {
    {"locate", locate, METH_VARARGS, "GEOS's line_locate_point on flat polyline segments (see the module comment)."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_project", NULL, -1, methods, NULL, NULL, NULL, NULL};

PyMODINIT_FUNC PyInit__project(void) { return PyModule_Create(&module); }
