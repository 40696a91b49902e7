/*
 * scenegrep.readers.ros._place: the per-box math of framing (framing.py) in one C pass, so no
 * array is made per operation and each box is read and written once.
 *
 * place(xyz, quat, size, velocity, each, shift, turn, dest, out, cosine)
 *     For box i of n: position xyz[i] (n, 3), rotation quat[i] (n, 4; x, y, z, w), size[i]
 *     (n, 3) and velocity velocity[i] (n, 3), all float64 with any strides. each[i] (int64) is
 *     the row of its transform into the map frame in shift (m, 3) and turn (m, 4; a unit
 *     quaternion), or -1 when the box is in the map frame already. dest[i] (int64) is the row
 *     the box is written to in out and cosine, or -1 when it is not written. out is a sequence
 *     of 9 float64 arrays and cosine one more (1-d, any stride, all of one length); with
 *     (x, y, z, w) = turn * quat, they get at row dest[i]: x, y, z (turn applied to xyz, then
 *     shift added), 2 (w z + x y) in out[3] and 1 - 2 (y y + z z) in cosine (the yaw is their
 *     atan2: the caller takes it with numpy's vectorised atan2, several times faster than a
 *     call per box, and makes it the heading), length, width, height (size as is), vx, vy
 *     (velocity turned by turn * quat). The formulas and their order of operations are those
 *     of transforms.py (product, rotated, yaw), so the results are theirs bit for bit (built
 *     with -ffp-contract=off: no fused multiply-adds where the target has them). Shapes,
 *     dtypes and every index of `each` and `dest` are checked before anything is written
 *     (ValueError otherwise).
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdint.h>

typedef struct {
    Py_buffer view;
    const char *name;
} Array;

/* A float64 (or int64 when `integer`) buffer of `ndim` dimensions, the last of `columns` entries
 * (0: any), writable when asked. */
static int get(PyObject *obj, Array *a, const char *name, int ndim, Py_ssize_t columns, int writable, int integer) {
    a->name = name;
    int flags = PyBUF_RECORDS_RO | (writable ? PyBUF_WRITABLE : 0);
    if (PyObject_GetBuffer(obj, &a->view, flags) < 0) {
        a->view.obj = NULL;
        return -1;
    }
    const char *format = a->view.format ? a->view.format : "";
    if (format[0] == '<' || format[0] == '=' || format[0] == '@') format++; /* (x86-64 and arm64: little-endian) */
    int ok = a->view.ndim == ndim && a->view.itemsize == 8 &&
             (integer ? (format[0] == 'l' || format[0] == 'q') && format[1] == 0
                      : format[0] == 'd' && format[1] == 0) &&
             (columns == 0 || a->view.shape[ndim - 1] == columns);
    if (!ok) {
        PyErr_Format(PyExc_ValueError, "%s: expected %d-d %s array%s", name, ndim, integer ? "int64" : "float64",
                     columns == 3 ? " of 3 columns" : (columns == 4 ? " of 4 columns" : ""));
        PyBuffer_Release(&a->view);
        a->view.obj = NULL;
        return -1;
    }
    return 0;
}

static inline double at(const Array *a, Py_ssize_t i, Py_ssize_t j) {
    return *(const double *)((const char *)a->view.buf + i * a->view.strides[0] + j * a->view.strides[1]);
}

/* v rotated by the unit quaternion (ux, uy, uz, w): v + w t + u x t with t = 2 (u x v). */
static inline void rotate(const double q[4], const double v[3], double r[3]) {
    double ux = q[0], uy = q[1], uz = q[2], w = q[3];
    double tx = (uy * v[2] - uz * v[1]) * 2.0;
    double ty = (uz * v[0] - ux * v[2]) * 2.0;
    double tz = (ux * v[1] - uy * v[0]) * 2.0;
    r[0] = (w * tx + v[0]) + (uy * tz - uz * ty);
    r[1] = (w * ty + v[1]) + (uz * tx - ux * tz);
    r[2] = (w * tz + v[2]) + (ux * ty - uy * tx);
}

/* The Hamilton product a * b. */
static inline void product(const double a[4], const double b[4], double r[4]) {
    double ax = a[0], ay = a[1], az = a[2], aw = a[3], bx = b[0], by = b[1], bz = b[2], bw = b[3];
    r[0] = aw * bx + ax * bw + ay * bz - az * by;
    r[1] = aw * by - ax * bz + ay * bw + az * bx;
    r[2] = aw * bz + ax * by - ay * bx + az * bw;
    r[3] = aw * bw - ax * bx - ay * by - az * bz;
}

static PyObject *place(PyObject *self, PyObject *args) {
    (void)self;
    PyObject *objs[10];
    if (!PyArg_ParseTuple(args, "OOOOOOOOOO", &objs[0], &objs[1], &objs[2], &objs[3], &objs[4], &objs[5], &objs[6],
                          &objs[7], &objs[8], &objs[9]))
        return NULL;
    Array xyz, quat, size, velocity, each, shift, turn, dest, out[10];
    Array *all[18] = {&xyz, &quat, &size, &velocity, &each, &shift, &turn, &dest};
    for (int k = 0; k < 10; k++) all[8 + k] = &out[k];
    for (int k = 0; k < 18; k++) all[k]->view.obj = NULL;
    PyObject *result = NULL, *columns = NULL;
    static const char *names[10] = {"out x",     "out y",      "out z",  "out heading", "out length",
                                    "out width", "out height", "out vx", "out vy",      "cosine"};
    if (get(objs[0], &xyz, "xyz", 2, 3, 0, 0) < 0 || get(objs[1], &quat, "quat", 2, 4, 0, 0) < 0 ||
        get(objs[2], &size, "size", 2, 3, 0, 0) < 0 || get(objs[3], &velocity, "velocity", 2, 3, 0, 0) < 0 ||
        get(objs[4], &each, "each", 1, 0, 0, 1) < 0 || get(objs[5], &shift, "shift", 2, 3, 0, 0) < 0 ||
        get(objs[6], &turn, "turn", 2, 4, 0, 0) < 0 || get(objs[7], &dest, "dest", 1, 0, 0, 1) < 0)
        goto done;
    columns = PySequence_Fast(objs[8], "out must be a sequence of 9 arrays");
    if (!columns) goto done;
    if (PySequence_Fast_GET_SIZE(columns) != 9) {
        PyErr_SetString(PyExc_ValueError, "out must be a sequence of 9 arrays");
        goto done;
    }
    for (int k = 0; k < 9; k++)
        if (get(PySequence_Fast_GET_ITEM(columns, k), &out[k], names[k], 1, 0, 1, 0) < 0) goto done;
    if (get(objs[9], &out[9], names[9], 1, 0, 1, 0) < 0) goto done;
    Py_ssize_t n = xyz.view.shape[0], m = shift.view.shape[0], rows = out[0].view.shape[0];
    int same = 1;
    for (int k = 1; k < 10; k++) same &= out[k].view.shape[0] == rows;
    if (quat.view.shape[0] != n || size.view.shape[0] != n || velocity.view.shape[0] != n ||
        each.view.shape[0] != n || dest.view.shape[0] != n || turn.view.shape[0] != m || !same) {
        PyErr_SetString(PyExc_ValueError, "place: arrays of different lengths");
        goto done;
    }
    const char *each_buf = each.view.buf, *dest_buf = dest.view.buf;
    Py_ssize_t each_stride = each.view.strides[0], dest_stride = dest.view.strides[0];
    for (Py_ssize_t i = 0; i < n; i++) {
        int64_t e = *(const int64_t *)(each_buf + i * each_stride), d = *(const int64_t *)(dest_buf + i * dest_stride);
        if (e < -1 || e >= m) {
            PyErr_Format(PyExc_ValueError, "place: each[%zd] = %lld is not a transform row", i, (long long)e);
            goto done;
        }
        if (d < -1 || d >= rows) {
            PyErr_Format(PyExc_ValueError, "place: dest[%zd] = %lld is not a row of out", i, (long long)d);
            goto done;
        }
    }
    char *o[10];
    Py_ssize_t os[10];
    for (int k = 0; k < 10; k++) {
        o[k] = out[k].view.buf;
        os[k] = out[k].view.strides[0];
    }
    Py_BEGIN_ALLOW_THREADS
    for (Py_ssize_t i = 0; i < n; i++) {
        int64_t e = *(const int64_t *)(each_buf + i * each_stride), d = *(const int64_t *)(dest_buf + i * dest_stride);
        if (d < 0) continue;
        double p[3] = {at(&xyz, i, 0), at(&xyz, i, 1), at(&xyz, i, 2)};
        double q[4] = {at(&quat, i, 0), at(&quat, i, 1), at(&quat, i, 2), at(&quat, i, 3)};
        double v[3] = {at(&velocity, i, 0), at(&velocity, i, 1), at(&velocity, i, 2)};
        double position[3], rotation[4], moved[3];
        if (e >= 0) {
            double t[4] = {at(&turn, e, 0), at(&turn, e, 1), at(&turn, e, 2), at(&turn, e, 3)};
            rotate(t, p, position);
            for (int k = 0; k < 3; k++) position[k] += at(&shift, e, k);
            product(t, q, rotation);
        } else {
            for (int k = 0; k < 3; k++) position[k] = p[k];
            for (int k = 0; k < 4; k++) rotation[k] = q[k];
        }
        double x = rotation[0], y = rotation[1], z = rotation[2], w = rotation[3];
        double sine = (w * z + x * y) * 2.0, cosine = (y * y + z * z) * 2.0;
        rotate(rotation, v, moved);
        double values[10] = {position[0],     position[1],     position[2], sine,     at(&size, i, 0),
                             at(&size, i, 1), at(&size, i, 2), moved[0],    moved[1], 1.0 - cosine};
        for (int k = 0; k < 10; k++) *(double *)(o[k] + d * os[k]) = values[k];
    }
    Py_END_ALLOW_THREADS
    result = Py_NewRef(Py_None);
done:
    for (int k = 0; k < 17; k++)
        if (all[k]->view.obj) PyBuffer_Release(&all[k]->view);
    Py_XDECREF(columns);
    return result;
}

static PyMethodDef methods[] = {
    {"place", place, METH_VARARGS, "place(xyz, quat, size, velocity, each, shift, turn, dest, out, cosine): see the module comment"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_place", NULL, -1, methods, NULL, NULL, NULL, NULL};

PyMODINIT_FUNC PyInit__place(void) { return PyModule_Create(&module); }
