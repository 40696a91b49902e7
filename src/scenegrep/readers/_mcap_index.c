/*
 * scenegrep.readers._mcap_index: the messages of a decompressed MCAP chunk, made in one C loop.
 *
 * messages(records, at, channels, message_type, views) -> (list, at, opcode)
 *     `records` is a memoryview of MCAP records (opcode u8, length u64 little-endian, body).
 *     From byte `at`, every Message record (channel u16, sequence u32, log time u64, publish
 *     time u64, data) on a channel of the dict `channels` (channel id -> the 5-tuple topic,
 *     schema name, schema encoding, schema data, message encoding) becomes
 *     message_type(*channel, log_time, data): a tuple subclass of 7 items, data a slice of
 *     `records` when `views` is true, else bytes. Records of other opcodes are skipped. The loop
 *     stops at the first record Python must read itself (a Schema or Channel record, or a
 *     Message record shorter than its header or on a channel not in `channels`) and returns
 *     the messages made, that record's byte offset and its opcode; at the end, len(records)
 *     and -1. A record whose header or body runs past the end raises
 *     ValueError("a record inside runs past the end of its chunk", its byte offset).
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <stdint.h>
#include <string.h>

#define SCHEMA 0x03
#define CHANNEL 0x04
#define MESSAGE 0x05
#define MESSAGE_HEADER 22

static uint64_t u64(const unsigned char *p) {
    uint64_t v = 0;
    for (int k = 7; k >= 0; k--) v = (v << 8) | p[k];
    return v;
}

static PyObject *message(PyTypeObject *type, PyObject *channel, PyObject *records, const unsigned char *base,
                         Py_ssize_t start, Py_ssize_t end, uint64_t log_time, int views) {
    PyObject *data;
    if (views) {
        PyObject *first = PyLong_FromSsize_t(start), *last = PyLong_FromSsize_t(end);
        PyObject *slice = first && last ? PySlice_New(first, last, NULL) : NULL;
        Py_XDECREF(first);
        Py_XDECREF(last);
        if (!slice) return NULL;
        data = PyObject_GetItem(records, slice);
        Py_DECREF(slice);
    } else {
        data = PyBytes_FromStringAndSize((const char *)base + start, end - start);
    }
    PyObject *time = PyLong_FromUnsignedLongLong(log_time);
    PyObject *item = type->tp_alloc(type, 7);
    if (!data || !time || !item) {
        Py_XDECREF(data);
        Py_XDECREF(time);
        Py_XDECREF(item);
        return NULL;
    }
    for (Py_ssize_t k = 0; k < 5; k++) PyTuple_SET_ITEM(item, k, Py_NewRef(PyTuple_GET_ITEM(channel, k)));
    PyTuple_SET_ITEM(item, 5, time);
    PyTuple_SET_ITEM(item, 6, data);
    return item;
}

static PyObject *messages(PyObject *self, PyObject *args) {
    (void)self;
    PyObject *records, *channels, *type_obj;
    Py_ssize_t at;
    int views;
    if (!PyArg_ParseTuple(args, "OnO!O!p", &records, &at, &PyDict_Type, &channels, &PyType_Type, &type_obj, &views))
        return NULL;
    PyTypeObject *type = (PyTypeObject *)type_obj;
    if (!PyType_IsSubtype(type, &PyTuple_Type)) {
        PyErr_SetString(PyExc_TypeError, "message_type must be a tuple subclass");
        return NULL;
    }
    Py_buffer view;
    if (PyObject_GetBuffer(records, &view, PyBUF_SIMPLE) < 0) return NULL;
    const unsigned char *data = view.buf;
    Py_ssize_t end = view.len;
    int opcode = -1;
    PyObject *out = PyList_New(0), *result = NULL;
    if (!out || at < 0) goto done;
    while (at < end) {
        if (end - at < 9 || u64(data + at + 1) > (uint64_t)(end - at - 9)) {
            PyObject *error = Py_BuildValue("(sn)", "a record inside runs past the end of its chunk", at);
            if (error) PyErr_SetObject(PyExc_ValueError, error);
            Py_XDECREF(error);
            goto done;
        }
        Py_ssize_t length = (Py_ssize_t)u64(data + at + 1), body = at + 9;
        int op = data[at];
        if (op == SCHEMA || op == CHANNEL) {
            opcode = op;
            break;
        }
        if (op == MESSAGE) {
            if (length < MESSAGE_HEADER) {
                opcode = op;
                break;
            }
            PyObject *key = PyLong_FromLong(data[body] | (data[body + 1] << 8));
            if (!key) goto done;
            PyObject *channel = PyDict_GetItemWithError(channels, key);
            Py_DECREF(key);
            if (!channel) {
                if (PyErr_Occurred()) goto done;
                opcode = op;
                break;
            }
            if (!PyTuple_Check(channel) || PyTuple_GET_SIZE(channel) != 5) {
                PyErr_SetString(PyExc_TypeError, "a channel must be a 5-tuple");
                goto done;
            }
            PyObject *item =
                message(type, channel, records, data, body + MESSAGE_HEADER, body + length, u64(data + body + 6), views);
            if (!item || PyList_Append(out, item) < 0) {
                Py_XDECREF(item);
                goto done;
            }
            Py_DECREF(item);
        }
        at = body + length;
    }
    result = Py_BuildValue("(Oni)", out, at < end ? at : end, opcode);
done:
    Py_XDECREF(out);
    PyBuffer_Release(&view);
    return result;
}

static PyMethodDef methods[] = {
    {"messages", messages, METH_VARARGS, "messages(records, at, channels, message_type, views) -> (list, at, opcode)"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_mcap_index", NULL, -1, methods, NULL, NULL, NULL, NULL};

PyMODINIT_FUNC PyInit__mcap_index(void) { return PyModule_Create(&module); }
