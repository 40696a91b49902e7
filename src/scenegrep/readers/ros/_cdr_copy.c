/*
 * scenegrep.readers.ros._cdr_copy: the per-message loops of the same-layout CDR decoder
 * (cdr_layout.py), in C. Python plans (once per layout) what to check and what to copy; these
 * functions run the plan over every message of a batch, so no Python runs per message or field.
 *
 * locate(payloads, offset, size) -> list of (start, owner)
 *     For each buffer of the sequence `payloads` (bytes, memoryviews), its owner (for a
 *     memoryview the object it views, else itself), its first byte's offset in its owner's
 *     buffer and its length, the last two written into the int64 buffers offset and size (each
 *     as long as payloads). Returns the runs of payloads of one owner: (index of the first, owner).
 *
 * codes16(keys, codes, first) -> k
 *     The n 16-byte keys of `keys` (n * 16 bytes) numbered in order of first appearance: codes[i]
 *     (int64) the number of key i, first[c] (int64) the first row of number c (c < k, the count of
 *     distinct keys, returned). Keys are compared whole.
 *
 * run(base, origins, size, count_at, count_value, copies, outputs, row_bytes, row0) -> int
 *     `base` holds messages whose CDR origins (after the 4-byte encapsulation header) are at
 *     `origins` (int64), each `size` bytes from there. For message i in order: its
 *     encapsulation header must read 00 01 and the uint32 at each origin + count_at[j] (int64)
 *     must equal count_value[j] (uint32), else i is returned (messages before i were copied).
 *     Then every copy (src, out, dst, n) of `copies` (int64, shape (p, 4)) copies n bytes from
 *     origin + src to outputs[out] at byte (row0 + i) * row_bytes[out] + dst. Returns the
 *     number of messages when all match. Every place is bounds-checked before anything is
 *     read or written (ValueError otherwise), so a bad plan cannot touch memory out of range.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define N_OUTPUTS_MAX 256

static int get(PyObject *obj, Py_buffer *view, int writable, Py_ssize_t item, const char *name) {
    if (PyObject_GetBuffer(obj, view, writable ? PyBUF_WRITABLE : PyBUF_SIMPLE) < 0) return -1;
    if (item > 1 && view->len % item) {
        PyErr_Format(PyExc_ValueError, "%s: %zd bytes, not a whole number of %zd-byte items", name, view->len, item);
        PyBuffer_Release(view);
        return -1;
    }
    return 0;
}

static PyObject *locate(PyObject *self, PyObject *args) {
    (void)self;
    PyObject *payloads, *o_obj, *s_obj;
    if (!PyArg_ParseTuple(args, "OOO", &payloads, &o_obj, &s_obj)) return NULL;
    PyObject *seq = PySequence_Fast(payloads, "payloads must be a sequence");
    if (!seq) return NULL;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
    Py_buffer o, s;
    if (get(o_obj, &o, 1, 8, "offset") < 0) { Py_DECREF(seq); return NULL; }
    if (get(s_obj, &s, 1, 8, "size") < 0) { PyBuffer_Release(&o); Py_DECREF(seq); return NULL; }
    PyObject *runs = PyList_New(0), *result = NULL, *owner = NULL;
    const char *start = NULL;
    Py_ssize_t owner_len = 0;
    if (!runs) goto done;
    if (o.len / 8 < n || s.len / 8 < n) {
        PyErr_SetString(PyExc_ValueError, "output buffers shorter than the payloads");
        goto done;
    }
    int64_t *offset = o.buf, *size = s.buf;
    PyObject **items = PySequence_Fast_ITEMS(seq);
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *item = items[i];
        PyObject *base = PyMemoryView_Check(item) ? PyMemoryView_GET_BASE(item) : NULL;
        base = base ? base : item;
        if (base != owner) {
            Py_buffer whole;
            if (PyObject_GetBuffer(base, &whole, PyBUF_SIMPLE) < 0) goto done;
            start = whole.buf;
            owner_len = whole.len;
            PyBuffer_Release(&whole);
            owner = base;
            PyObject *run = Py_BuildValue("(nO)", i, owner);
            if (!run || PyList_Append(runs, run) < 0) { Py_XDECREF(run); goto done; }
            Py_DECREF(run);
        }
        Py_buffer view;
        if (PyObject_GetBuffer(item, &view, PyBUF_SIMPLE) < 0) goto done;
        offset[i] = (int64_t)((const char *)view.buf - start);
        size[i] = (int64_t)view.len;
        PyBuffer_Release(&view);
        if (offset[i] < 0 || offset[i] + size[i] > owner_len) {
            PyErr_SetString(PyExc_ValueError, "a payload outside its owner's buffer");
            goto done;
        }
    }
    result = Py_NewRef(runs);
done:
    Py_XDECREF(runs);
    PyBuffer_Release(&o);
    PyBuffer_Release(&s);
    Py_DECREF(seq);
    return result;
}

static PyObject *run(PyObject *self, PyObject *args) {
    (void)self;
    PyObject *base_obj, *origins_obj, *at_obj, *value_obj, *copies_obj, *outputs, *rows_obj;
    Py_ssize_t size, row0;
    if (!PyArg_ParseTuple(args, "OOnOOOOOn", &base_obj, &origins_obj, &size, &at_obj, &value_obj, &copies_obj,
                          &outputs, &rows_obj, &row0))
        return NULL;
    if (!PyTuple_Check(outputs) || PyTuple_GET_SIZE(outputs) > N_OUTPUTS_MAX) {
        PyErr_SetString(PyExc_ValueError, "outputs must be a tuple of at most 256 buffers");
        return NULL;
    }
    Py_ssize_t n_out = PyTuple_GET_SIZE(outputs);
    Py_buffer base = {0}, origins = {0}, at = {0}, value = {0}, copies = {0}, rows = {0};
    Py_buffer out[N_OUTPUTS_MAX];
    Py_ssize_t got = 0;
    PyObject *result = NULL;
    if (get(base_obj, &base, 0, 1, "base") < 0) return NULL;
    if (get(origins_obj, &origins, 0, 8, "origins") < 0) goto done;
    if (get(at_obj, &at, 0, 8, "count_at") < 0) goto done;
    if (get(value_obj, &value, 0, 4, "count_value") < 0) goto done;
    if (get(copies_obj, &copies, 0, 32, "copies") < 0) goto done;
    if (get(rows_obj, &rows, 0, 8, "row_bytes") < 0) goto done;
    for (; got < n_out; got++)
        if (get(PyTuple_GET_ITEM(outputs, got), &out[got], 1, 1, "output") < 0) goto done;

    Py_ssize_t n = origins.len / 8, m = at.len / 8, p = copies.len / 32;
    const int64_t *origin = origins.buf, *count_at = at.buf, *copy = copies.buf, *row_bytes = rows.buf;
    const uint32_t *count_value = value.buf;
    const unsigned char *data = base.buf;
    if (value.len / 4 != m || rows.len / 8 != n_out || size < 0 || row0 < 0) {
        PyErr_SetString(PyExc_ValueError, "inconsistent plan");
        goto done;
    }
    for (Py_ssize_t i = 0; i < n; i++)
        if (origin[i] < 4 || origin[i] > base.len || size > base.len - origin[i]) {
            PyErr_SetString(PyExc_ValueError, "a message outside its buffer");
            goto done;
        }
    for (Py_ssize_t j = 0; j < m; j++)
        if (count_at[j] < 0 || count_at[j] > size - 4) {
            PyErr_SetString(PyExc_ValueError, "a count outside the message");
            goto done;
        }
    for (Py_ssize_t k = 0; k < p; k++) {
        const int64_t *c = copy + 4 * k;
        if (c[0] < 0 || c[3] < 0 || c[0] > size - c[3] || c[1] < 0 || c[1] >= n_out || c[2] < 0 ||
            c[2] > row_bytes[c[1]] - c[3] || (row0 + n) * row_bytes[c[1]] > out[c[1]].len) {
            PyErr_SetString(PyExc_ValueError, "a copy outside its message or output");
            goto done;
        }
    }
    Py_ssize_t i = 0;
    Py_BEGIN_ALLOW_THREADS
    for (; i < n; i++) {
        const unsigned char *msg = data + origin[i];
        if (msg[-4] != 0 || msg[-3] != 1) break;
        Py_ssize_t j = 0;
        for (; j < m; j++) {
            uint32_t v;
            memcpy(&v, msg + count_at[j], 4);
            if (v != count_value[j]) break;
        }
        if (j < m) break;
        for (Py_ssize_t k = 0; k < p; k++) {
            const int64_t *c = copy + 4 * k;
            char *to = (char *)out[c[1]].buf + (row0 + i) * row_bytes[c[1]] + c[2];
            const unsigned char *from = msg + c[0];
            switch (c[3]) { /* the common sizes as fixed-size copies (inlined) */
            case 1: memcpy(to, from, 1); break;
            case 4: memcpy(to, from, 4); break;
            case 8: memcpy(to, from, 8); break;
            case 16: memcpy(to, from, 16); break;
            case 24: memcpy(to, from, 24); break;
            case 32: memcpy(to, from, 32); break;
            case 56: memcpy(to, from, 56); break;
            default: memcpy(to, from, (size_t)c[3]);
            }
        }
    }
    Py_END_ALLOW_THREADS
    result = PyLong_FromSsize_t(i);
done:
    for (Py_ssize_t k = 0; k < got; k++) PyBuffer_Release(&out[k]);
    if (base.obj) PyBuffer_Release(&base);
    if (origins.obj) PyBuffer_Release(&origins);
    if (at.obj) PyBuffer_Release(&at);
    if (value.obj) PyBuffer_Release(&value);
    if (copies.obj) PyBuffer_Release(&copies);
    if (rows.obj) PyBuffer_Release(&rows);
    return result;
}

/* Codes of 16-byte keys in order of first appearance, by open addressing (a table of a power of
 * two at least twice the rows); every key is compared whole, so equal codes are equal keys. */
static PyObject *codes16(PyObject *self, PyObject *args) {
    (void)self;
    PyObject *raw_obj, *codes_obj, *first_obj;
    if (!PyArg_ParseTuple(args, "OOO", &raw_obj, &codes_obj, &first_obj)) return NULL;
    Py_buffer raw, codes, first;
    if (get(raw_obj, &raw, 0, 16, "keys") < 0) return NULL;
    if (get(codes_obj, &codes, 1, 8, "codes") < 0) { PyBuffer_Release(&raw); return NULL; }
    if (get(first_obj, &first, 1, 8, "first") < 0) {
        PyBuffer_Release(&raw); PyBuffer_Release(&codes); return NULL;
    }
    PyObject *result = NULL;
    Py_ssize_t n = raw.len / 16, size = 16;
    int64_t *table = NULL;
    if (codes.len / 8 < n || first.len / 8 < n) {
        PyErr_SetString(PyExc_ValueError, "codes or first shorter than the keys");
        goto done;
    }
    while (size < 2 * n) size *= 2;
    table = malloc((size_t)size * sizeof(int64_t));
    if (!table) { PyErr_NoMemory(); goto done; }
    memset(table, 0xff, (size_t)size * sizeof(int64_t));
    const unsigned char *key = raw.buf;
    int64_t *code = codes.buf, *row = first.buf, k = 0;
    for (Py_ssize_t i = 0; i < n; i++) {
        uint64_t a, b;
        memcpy(&a, key + 16 * i, 8);
        memcpy(&b, key + 16 * i + 8, 8);
        uint64_t h = (a ^ (b * 0x9E3779B97F4A7C15ULL)) * 0xBF58476D1CE4E5B9ULL;
        Py_ssize_t at = (Py_ssize_t)((h >> 29) & (uint64_t)(size - 1));
        for (;;) {
            int64_t held = table[at];
            if (held < 0) {
                table[at] = k;
                row[k] = i;
                code[i] = k++;
                break;
            }
            if (!memcmp(key + 16 * row[held], key + 16 * i, 16)) {
                code[i] = held;
                break;
            }
            at = (at + 1) & (size - 1);
        }
    }
    result = PyLong_FromLongLong(k);
done:
    free(table);
    PyBuffer_Release(&raw);
    PyBuffer_Release(&codes);
    PyBuffer_Release(&first);
    return result;
}

static PyMethodDef methods[] = {
    {"codes16", codes16, METH_VARARGS, "codes16(keys, codes, first) -> k: see the module comment"},
    {"locate", locate, METH_VARARGS, "locate(payloads, offset, size) -> [(start, owner)]: see the module comment"},
    {"run", run, METH_VARARGS, "run(base, origins, size, count_at, count_value, copies, outputs, row_bytes, row0)"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_cdr_copy", NULL, -1, methods, NULL, NULL, NULL, NULL};

PyMODINIT_FUNC PyInit__cdr_copy(void) { return PyModule_Create(&module); }
