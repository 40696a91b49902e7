/*
 * scenegrep.readers.ros._cdr_walk: CDR messages walked in C along a program compiled from their
 * type (cdr_walk.py), one message after the other, wanted fields appended to columns.
 *
 * walk(base, origins, sizes, program, columns, strings, parents, ranks, counts, reached, first) -> int
 *   base: the buffer holding the messages; message i's CDR origin (after its 4-byte encapsulation
 *   header, which must read 00 01) is at origins[i] (int64), sizes[i] (int64) bytes from there.
 *   program: int64 rows of 6 (op, a, b, c, d, e):
 *     PRIM 1 (size, count, column): align to size, `count` values; appended to bytearray
 *            columns[column] unless column < 0.
 *     SKIP 2 (size, align): a plain struct not wanted.
 *     STRING 3 (column): a uint32 length (aligned to 4) and that many bytes; when column >= 0 the
 *            bytes go to the bytearray `strings` and (offset in it, length) as two int64 to
 *            columns[column].
 *     SEQ_SKIP 4 (size, align, fixed): `fixed` elements (a sequence's uint32 count when fixed < 0)
 *            of `size` bytes each, aligned to `align` when there are any; not wanted.
 *     SEQ 5 (level, body, least, fixed): the elements (count as above), each an item of `level`:
 *            its parent item and rank appended (int64) to parents[level] and ranks[level], then
 *            the next `body` rows walked for it; those rows are skipped after the last element.
 *   A count (or a fixed array's size) must leave room for its elements (`least` bytes each, at
 *   least 1; for a fixed array this is stricter than the generic walk, which then decodes it). counts[level]
 *   (int64, in and out) numbers each level's items; reached[level] (int64) is set to 1 when its
 *   SEQ row is walked. Message i is item first + i of the top level.
 *   Returns -1 when every message was walked, else the index of the first that could not be
 *   (a bad header, a read past its end, a count too large): what it appended stays.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define MAX_LEVELS 64
#define MAX_COLUMNS 256
#define MAX_DEPTH 64

enum { PRIM = 1, SKIP = 2, STRING = 3, SEQ_SKIP = 4, SEQ = 5 };

typedef struct {
    char *data;
    size_t len, cap;
} Buf;

typedef struct {
    const unsigned char *msg;
    int64_t end;
    const int64_t *ops;
    PyObject **columns, **parents, **ranks, *strings;
    Buf *bufs; /* one per column, then per level parents, per level ranks, then the strings */
    int64_t *counts, *reached, heap;
    Py_ssize_t n_columns, n_levels;
} Walk;

static int grow(Buf *b, size_t n);

/* Append n bytes (the common sizes copied inline). */
static inline int put(Buf *b, const void *data, size_t n) {
    if (b->len + n > b->cap && grow(b, n) < 0) return -1;
    char *to = b->data + b->len;
    switch (n) {
    case 1: *to = *(const char *)data; break;
    case 4: memcpy(to, data, 4); break;
    case 8: memcpy(to, data, 8); break;
    case 16: memcpy(to, data, 16); break;
    default: memcpy(to, data, n);
    }
    b->len += n;
    return 0;
}

static int grow(Buf *b, size_t n) {
    {
        size_t cap = b->cap ? b->cap : 4096;
        while (cap < b->len + n) cap *= 2;
        char *grown = realloc(b->data, cap);
        if (!grown) {
            PyErr_NoMemory();
            return -1;
        }
        b->data = grown;
        b->cap = cap;
    }
    return 0;
}

#define COLUMN(w, c) (&(w)->bufs[c])
#define PARENTS(w, l) (&(w)->bufs[(w)->n_columns + (l)])
#define RANKS(w, l) (&(w)->bufs[(w)->n_columns + (w)->n_levels + (l)])
#define HEAP(w) (&(w)->bufs[(w)->n_columns + 2 * (w)->n_levels])

static int64_t align(int64_t pos, int64_t size) { return (pos + size - 1) & -size; }

/* The position after rows [k, stop) walked from `pos` for `item`; -1 when the message is bad,
 * -2 on a Python error (memory). */
static int64_t walk_rows(Walk *w, Py_ssize_t k, Py_ssize_t stop, int64_t pos, int64_t item, int depth) {
    if (depth > MAX_DEPTH) return -1;
    while (k < stop) {
        const int64_t *r = w->ops + 6 * k;
        switch (r[0]) {
        case PRIM: {
            pos = align(pos, r[1]);
            int64_t n = r[1] * r[2];
            if (pos + n > w->end) return -1;
            if (r[3] >= 0 && put(COLUMN(w, r[3]), w->msg + pos, (size_t)n) < 0) return -2;
            pos += n;
            k++;
            break;
        }
        case SKIP:
            pos = align(pos, r[2]);
            if (pos + r[1] > w->end) return -1;
            pos += r[1];
            k++;
            break;
        case STRING: {
            pos = align(pos, 4);
            if (pos + 4 > w->end) return -1;
            uint32_t n;
            memcpy(&n, w->msg + pos, 4);
            pos += 4;
            if (pos + (int64_t)n > w->end) return -1;
            if (r[1] >= 0) {
                int64_t place[2] = {w->heap + (int64_t)HEAP(w)->len, n};
                if (put(HEAP(w), w->msg + pos, n) < 0 || put(COLUMN(w, r[1]), place, 16) < 0) return -2;
            }
            pos += n;
            k++;
            break;
        }
        case SEQ_SKIP:
        case SEQ: {
            int64_t n = r[0] == SEQ ? r[4] : r[3], least = r[0] == SEQ ? r[3] : r[1];
            if (n < 0) {
                pos = align(pos, 4);
                if (pos + 4 > w->end) return -1;
                uint32_t count;
                memcpy(&count, w->msg + pos, 4);
                pos += 4;
                n = count;
            }
            /* (a fixed array too: its items are bounded by the bytes left, whatever the schema says) */
            if (pos + n * (least > 1 ? least : 1) > w->end) return -1;
            if (r[0] == SEQ_SKIP) {
                if (n > 0) pos = align(pos, r[2]);
                pos += n * r[1];
                if (pos > w->end) return -1;
                k++;
                break;
            }
            int64_t level = r[1];
            w->reached[level] = 1;
            for (int64_t j = 0; j < n; j++) {
                int64_t id = w->counts[level]++;
                if (put(PARENTS(w, level), &item, 8) < 0 || put(RANKS(w, level), &j, 8) < 0) return -2;
                pos = walk_rows(w, k + 1, k + 1 + r[2], pos, id, depth + 1);
                if (pos < 0) return pos;
            }
            k += 1 + r[2];
            break;
        }
        default:
            return -1;
        }
    }
    return pos;
}

static int bytearrays(PyObject *list, PyObject ***out, Py_ssize_t *n, Py_ssize_t most) {
    if (!PyList_Check(list) || PyList_GET_SIZE(list) > most) {
        PyErr_SetString(PyExc_ValueError, "expected a list of bytearrays");
        return -1;
    }
    *n = PyList_GET_SIZE(list);
    *out = PySequence_Fast_ITEMS(list);
    for (Py_ssize_t k = 0; k < *n; k++)
        if (!PyByteArray_Check((*out)[k])) {
            PyErr_SetString(PyExc_ValueError, "expected a list of bytearrays");
            return -1;
        }
    return 0;
}

static PyObject *walk(PyObject *self, PyObject *args) {
    (void)self;
    PyObject *base_obj, *origins_obj, *sizes_obj, *program_obj, *columns, *strings, *parents, *ranks, *counts_obj,
        *reached_obj;
    Py_ssize_t first;
    if (!PyArg_ParseTuple(args, "OOOOO!O!O!O!OOn", &base_obj, &origins_obj, &sizes_obj, &program_obj, &PyList_Type,
                          &columns, &PyByteArray_Type, &strings, &PyList_Type, &parents, &PyList_Type, &ranks,
                          &counts_obj, &reached_obj, &first))
        return NULL;
    Py_buffer base = {0}, origins = {0}, sizes = {0}, program = {0}, counts = {0}, reached = {0};
    PyObject *result = NULL;
    Walk w;
    Py_ssize_t n_ranks;
    if (PyObject_GetBuffer(base_obj, &base, PyBUF_SIMPLE) < 0) return NULL;
    if (PyObject_GetBuffer(origins_obj, &origins, PyBUF_SIMPLE) < 0) goto done;
    if (PyObject_GetBuffer(sizes_obj, &sizes, PyBUF_SIMPLE) < 0) goto done;
    if (PyObject_GetBuffer(program_obj, &program, PyBUF_SIMPLE) < 0) goto done;
    if (PyObject_GetBuffer(counts_obj, &counts, PyBUF_WRITABLE) < 0) goto done;
    if (PyObject_GetBuffer(reached_obj, &reached, PyBUF_WRITABLE) < 0) goto done;
    if (bytearrays(columns, &w.columns, &w.n_columns, MAX_COLUMNS) < 0) goto done;
    if (bytearrays(parents, &w.parents, &w.n_levels, MAX_LEVELS) < 0) goto done;
    if (bytearrays(ranks, &w.ranks, &n_ranks, MAX_LEVELS) < 0) goto done;
    Py_ssize_t n = origins.len / 8, n_ops = program.len / 48;
    const int64_t *origin = origins.buf, *size = sizes.buf, *ops = program.buf;
    if (sizes.len != origins.len || program.len % 48 || n_ranks != w.n_levels || counts.len != 8 * w.n_levels ||
        reached.len != 8 * w.n_levels || first < 0) {
        PyErr_SetString(PyExc_ValueError, "inconsistent arguments");
        goto done;
    }
    /* the program is checked once: every column and level it names exists, every body is inside it */
    for (Py_ssize_t k = 0; k < n_ops; k++) {
        const int64_t *r = ops + 6 * k;
        int ok = (r[0] == PRIM && r[1] > 0 && (r[1] & (r[1] - 1)) == 0 && r[2] >= 0 && r[3] < w.n_columns) ||
                 (r[0] == SKIP && r[1] >= 0 && r[2] > 0 && (r[2] & (r[2] - 1)) == 0) ||
                 (r[0] == STRING && r[1] < w.n_columns) ||
                 (r[0] == SEQ_SKIP && r[1] >= 0 && r[2] > 0 && (r[2] & (r[2] - 1)) == 0) ||
                 (r[0] == SEQ && r[1] >= 0 && r[1] < w.n_levels && r[2] >= 0 && r[2] < n_ops - k && r[3] >= 0);
        if (!ok) {
            PyErr_Format(PyExc_ValueError, "bad program row %zd", k);
            goto done;
        }
    }
    for (Py_ssize_t i = 0; i < n; i++)
        if (origin[i] < 4 || size[i] < 0 || origin[i] > base.len || size[i] > base.len - origin[i]) {
            PyErr_SetString(PyExc_ValueError, "a message outside its buffer");
            goto done;
        }
    w.ops = ops;
    w.strings = strings;
    w.counts = counts.buf;
    w.reached = reached.buf;
    w.heap = PyByteArray_GET_SIZE(strings);
    Py_ssize_t n_bufs = w.n_columns + 2 * w.n_levels + 1, i = 0;
    w.bufs = calloc((size_t)n_bufs, sizeof(Buf));
    if (!w.bufs) {
        PyErr_NoMemory();
        goto done;
    }
    for (; i < n; i++) {
        w.msg = (const unsigned char *)base.buf + origin[i];
        w.end = size[i];
        if (w.msg[-4] != 0 || w.msg[-3] != 1) break;
        int64_t end = walk_rows(&w, 0, n_ops, 0, first + i, 0);
        if (end == -2) break;
        if (end < 0) break;
    }
    int failed = PyErr_Occurred() != NULL;
    for (Py_ssize_t b = 0; b < n_bufs; b++) {
        PyObject *out = b < w.n_columns                    ? w.columns[b]
                        : b < w.n_columns + w.n_levels     ? w.parents[b - w.n_columns]
                        : b < w.n_columns + 2 * w.n_levels ? w.ranks[b - w.n_columns - w.n_levels]
                                                           : strings;
        Py_ssize_t at = PyByteArray_GET_SIZE(out);
        if (!failed && w.bufs[b].len) {
            if (PyByteArray_Resize(out, at + (Py_ssize_t)w.bufs[b].len) < 0)
                failed = 1;
            else
                memcpy(PyByteArray_AS_STRING(out) + at, w.bufs[b].data, w.bufs[b].len);
        }
        free(w.bufs[b].data);
    }
    free(w.bufs);
    if (!failed) result = PyLong_FromSsize_t(i < n ? i : -1);
done:
    PyBuffer_Release(&base);
    if (origins.obj) PyBuffer_Release(&origins);
    if (sizes.obj) PyBuffer_Release(&sizes);
    if (program.obj) PyBuffer_Release(&program);
    if (counts.obj) PyBuffer_Release(&counts);
    if (reached.obj) PyBuffer_Release(&reached);
    return result;
}

static PyMethodDef methods[] = {
    {"walk", walk, METH_VARARGS, "walk(base, origins, sizes, program, columns, strings, parents, ranks, counts, "
                                 "reached, first) -> -1 or the first bad message"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_cdr_walk", NULL, -1, methods, NULL, NULL, NULL, NULL};

PyMODINIT_FUNC PyInit__cdr_walk(void) { return PyModule_Create(&module); }
