/*
 * scenegrep.readers._strem: STREM JSON v0.2.0 perception streams to columns, in one pass.
 *
 * parse(buffer, release=False) reads every top-level document of the buffer (documents
 * may follow each other, separated by white space) and returns a dict of columns:
 *   frame_index (int64), frame_time (float64; NaN where a frame has no "timestamp"),
 *   sample_frame, sample_channel, sample_path, sample_width, sample_height (int32),
 *   box_sample, box_class (int32), box_score, box_cx, box_cy, box_w, box_h, box_rotation
 *   (float64), box_oriented (uint8), each as bytes; channels, classes, paths (lists of str,
 *   indexed by the code columns); versions (list of (version, byte offset) per document).
 * Unknown object keys are skipped, as STREM does. With release=True the buffer is taken
 * to be a read-only file mapping whose pages are released (madvise) as they are parsed,
 * so resident memory stays small whatever the file size.
 *
 * Errors raise ValueError(message, byte offset, path) where path names the place, e.g.
 * "frames[3].samples[0].image".
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#define MAX_DEPTH 256
#define RELEASE_STEP (2u << 20)

/* ------------------------------------------------------------------ growable columns */
typedef struct {
    char *data;
    size_t len, cap, item;
} Column;

static int col_grow(Column *c) {
    size_t cap = c->cap ? c->cap * 2 : 1024;
    char *data = realloc(c->data, cap * c->item);
    if (!data) { PyErr_NoMemory(); return -1; }
    c->data = data;
    c->cap = cap;
    return 0;
}

#define PUSH(name, type)                                                  \
    static inline int name(Column *c, type value) {                       \
        if (c->len == c->cap && col_grow(c) < 0) return -1;               \
        ((type *)c->data)[c->len++] = value;                              \
        return 0;                                                         \
    }
PUSH(push_i32, int32_t)
PUSH(push_i64, int64_t)
PUSH(push_f64, double)
PUSH(push_u8, uint8_t)

/* ------------------------------------------------------------------ string interning */
typedef struct {
    char **keys;
    size_t *lens;
    int32_t *codes;
    size_t cap, count;
    char **order;       /* code -> key */
    size_t *order_len;
    size_t order_cap;
} Interner;

static uint64_t fnv(const char *s, size_t n) {
    uint64_t h = 1469598103934665603ull;
    for (size_t i = 0; i < n; i++) { h ^= (unsigned char)s[i]; h *= 1099511628211ull; }
    return h;
}

static int intern_grow(Interner *t) {
    size_t cap = t->cap ? t->cap * 2 : 64;
    char **keys = calloc(cap, sizeof(char *));
    size_t *lens = calloc(cap, sizeof(size_t));
    int32_t *codes = calloc(cap, sizeof(int32_t));
    if (!keys || !lens || !codes) { free(keys); free(lens); free(codes); PyErr_NoMemory(); return -1; }
    for (size_t i = 0; i < t->cap; i++) {
        if (!t->keys[i]) continue;
        size_t j = fnv(t->keys[i], t->lens[i]) & (cap - 1);
        while (keys[j]) j = (j + 1) & (cap - 1);
        keys[j] = t->keys[i]; lens[j] = t->lens[i]; codes[j] = t->codes[i];
    }
    free(t->keys); free(t->lens); free(t->codes);
    t->keys = keys; t->lens = lens; t->codes = codes; t->cap = cap;
    return 0;
}

/* The code of a string (a new code the first time it is seen); -1 on failure. */
static int32_t intern(Interner *t, const char *s, size_t n) {
    if ((t->count + 1) * 2 > t->cap && intern_grow(t) < 0) return -1;
    size_t j = fnv(s, n) & (t->cap - 1);
    while (t->keys[j]) {
        if (t->lens[j] == n && memcmp(t->keys[j], s, n) == 0) return t->codes[j];
        j = (j + 1) & (t->cap - 1);
    }
    char *copy = malloc(n + 1);
    if (!copy) { PyErr_NoMemory(); return -1; }
    memcpy(copy, s, n);
    copy[n] = 0;
    if (t->count == t->order_cap) {
        size_t cap = t->order_cap ? t->order_cap * 2 : 64;
        char **order = realloc(t->order, cap * sizeof(char *));
        if (order) t->order = order;
        size_t *order_len = realloc(t->order_len, cap * sizeof(size_t));
        if (order_len) t->order_len = order_len;
        if (!order || !order_len) { free(copy); PyErr_NoMemory(); return -1; }
        t->order_cap = cap;
    }
    t->keys[j] = copy; t->lens[j] = n; t->codes[j] = (int32_t)t->count;
    t->order[t->count] = copy; t->order_len[t->count] = n;
    return (int32_t)t->count++;
}

static void intern_free(Interner *t) {
    for (size_t i = 0; i < t->count; i++) free(t->order[i]);
    free(t->keys); free(t->lens); free(t->codes); free(t->order); free(t->order_len);
}

static PyObject *intern_list(Interner *t) {
    PyObject *list = PyList_New((Py_ssize_t)t->count);
    if (!list) return NULL;
    for (size_t i = 0; i < t->count; i++) {
        PyObject *s = PyUnicode_DecodeUTF8(t->order[i], (Py_ssize_t)t->order_len[i], "surrogateescape");
        if (!s) { Py_DECREF(list); return NULL; }
        PyList_SET_ITEM(list, (Py_ssize_t)i, s);
    }
    return list;
}

/* ------------------------------------------------------------------ parser state */
enum { C_FRAME_INDEX, C_FRAME_TIME, C_S_FRAME, C_S_CHANNEL, C_S_PATH, C_S_WIDTH, C_S_HEIGHT, C_B_SAMPLE,
       C_B_CLASS, C_B_SCORE, C_B_CX, C_B_CY, C_B_W, C_B_H, C_B_ROT, C_B_OBB, N_COLUMNS };
static const char *COLUMN_NAMES[N_COLUMNS] = {
    "frame_index", "frame_time", "sample_frame", "sample_channel", "sample_path", "sample_width", "sample_height",
    "box_sample", "box_class", "box_score", "box_cx", "box_cy", "box_w", "box_h", "box_rotation", "box_oriented"};
static const size_t COLUMN_SIZES[N_COLUMNS] = {8, 8, 4, 4, 4, 4, 4, 4, 4, 8, 8, 8, 8, 8, 8, 1};

typedef struct {
    const char *buf;
    size_t len, pos;
    int release;
    size_t released;
    Column cols[N_COLUMNS];
    Interner channels, classes, paths;
    char *scratch;           /* decoded string, when it had escapes */
    size_t scratch_len, scratch_cap;
    const char *str;         /* the string just read: into the buffer, or into scratch */
    size_t str_len;
    /* where we are, for messages */
    long frame, sample, annotation;
    const char *where;       /* innermost object or field being read */
    const char *error;
    char message[256];
    size_t error_pos;
    PyObject *versions;
} Parser;

static int fail(Parser *p, const char *message) {
    if (!p->error) {
        snprintf(p->message, sizeof p->message, "%s", message);
        p->error = p->message;
        p->error_pos = p->pos;
    }
    return -1;
}

static void release_pages(Parser *p) {
    if (!p->release || p->pos < p->released + 2 * RELEASE_STEP) return;
    long page = sysconf(_SC_PAGESIZE);
    size_t end = (p->pos - RELEASE_STEP) / (size_t)page * (size_t)page;
    if (end > p->released) {
        madvise((void *)(p->buf + p->released), end - p->released, MADV_DONTNEED);
        p->released = end;
    }
}

static inline void skip_ws(Parser *p) {
    while (p->pos < p->len) {
        char c = p->buf[p->pos];
        if (c != ' ' && c != '\n' && c != '\r' && c != '\t') break;
        p->pos++;
    }
}

static int expect(Parser *p, char c) {
    skip_ws(p);
    if (p->pos >= p->len) return fail(p, "unexpected end of input (truncated JSON?)");
    if (p->buf[p->pos] != c) {
        char message[64];
        snprintf(message, sizeof message, "expected '%c' but found '%c'", c, p->buf[p->pos]);
        return fail(p, message);
    }
    p->pos++;
    return 0;
}

/* After a value inside a container: 1 when another item follows (after ','), 0 at the close. */
static int next_item(Parser *p, char close) {
    skip_ws(p);
    if (p->pos >= p->len) return fail(p, "unexpected end of input (truncated JSON?)");
    if (p->buf[p->pos] == ',') { p->pos++; return 1; }
    if (p->buf[p->pos] == close) { p->pos++; return 0; }
    return fail(p, close == '}' ? "expected ',' or '}'" : "expected ',' or ']'");
}

/* 1 when the container is empty (consumes the close), 0 otherwise. */
static int empty_container(Parser *p, char close) {
    skip_ws(p);
    if (p->pos < p->len && p->buf[p->pos] == close) { p->pos++; return 1; }
    return 0;
}

static int scratch_put(Parser *p, const char *s, size_t n) {
    if (p->scratch_len + n + 1 > p->scratch_cap) {
        size_t cap = (p->scratch_len + n + 1) * 2;
        char *data = realloc(p->scratch, cap);
        if (!data) { PyErr_NoMemory(); return -1; }
        p->scratch = data;
        p->scratch_cap = cap;
    }
    memcpy(p->scratch + p->scratch_len, s, n);
    p->scratch_len += n;
    return 0;
}

static int hex4(const char *s, unsigned *out) {
    unsigned v = 0;
    for (int i = 0; i < 4; i++) {
        char c = s[i];
        v <<= 4;
        if (c >= '0' && c <= '9') v |= (unsigned)(c - '0');
        else if (c >= 'a' && c <= 'f') v |= (unsigned)(c - 'a' + 10);
        else if (c >= 'A' && c <= 'F') v |= (unsigned)(c - 'A' + 10);
        else return -1;
    }
    *out = v;
    return 0;
}

static int put_utf8(Parser *p, unsigned cp) {
    char out[4];
    size_t n;
    if (cp < 0x80) { out[0] = (char)cp; n = 1; }
    else if (cp < 0x800) { out[0] = (char)(0xC0 | (cp >> 6)); out[1] = (char)(0x80 | (cp & 0x3F)); n = 2; }
    else if (cp < 0x10000) {
        out[0] = (char)(0xE0 | (cp >> 12)); out[1] = (char)(0x80 | ((cp >> 6) & 0x3F));
        out[2] = (char)(0x80 | (cp & 0x3F)); n = 3;
    } else {
        out[0] = (char)(0xF0 | (cp >> 18)); out[1] = (char)(0x80 | ((cp >> 12) & 0x3F));
        out[2] = (char)(0x80 | ((cp >> 6) & 0x3F)); out[3] = (char)(0x80 | (cp & 0x3F)); n = 4;
    }
    return scratch_put(p, out, n);
}

/* A JSON string, decoded, in p->str / p->str_len (not NUL-terminated). Strings without
   escapes are not copied: p->str then points into the buffer. */
static int read_string(Parser *p) {
    skip_ws(p);
    if (p->pos >= p->len) return fail(p, "unexpected end of input (truncated JSON?)");
    if (p->buf[p->pos] != '"') return fail(p, "expected a string");
    p->pos++;
    size_t start = p->pos;
    const unsigned char *c = (const unsigned char *)p->buf + start, *stop = (const unsigned char *)p->buf + p->len;
    while (c < stop && *c != '"' && *c != '\\' && *c >= 0x20) c++;
    if (c < stop && *c == '"') {
        p->str = p->buf + start;
        p->str_len = (size_t)((const char *)c - p->str);
        p->pos = (size_t)((const char *)c - p->buf) + 1;
        return 0;
    }
    p->scratch_len = 0;
    size_t run = p->pos;
    while (p->pos < p->len) {
        unsigned char c = (unsigned char)p->buf[p->pos];
        if (c == '"') {
            if (scratch_put(p, p->buf + run, p->pos - run) < 0) return -1;
            p->pos++;
            p->str = p->scratch;
            p->str_len = p->scratch_len;
            return 0;
        }
        if (c < 0x20) return fail(p, "control character in a string");
        if (c != '\\') { p->pos++; continue; }
        if (scratch_put(p, p->buf + run, p->pos - run) < 0) return -1;
        if (p->pos + 1 >= p->len) break;
        char e = p->buf[p->pos + 1];
        const char *plain = strchr("\"\\/bfnrt", e);
        if (e && plain) {
            static const char decoded[] = "\"\\/\b\f\n\r\t";
            if (scratch_put(p, &decoded[plain - "\"\\/bfnrt"], 1) < 0) return -1;
            p->pos += 2;
        } else if (e == 'u') {
            unsigned cp, low;
            if (p->pos + 6 > p->len || hex4(p->buf + p->pos + 2, &cp) < 0) return fail(p, "bad \\u escape");
            p->pos += 6;
            if (cp >= 0xD800 && cp < 0xDC00 && p->pos + 6 <= p->len && p->buf[p->pos] == '\\'
                && p->buf[p->pos + 1] == 'u' && hex4(p->buf + p->pos + 2, &low) == 0 && low >= 0xDC00 && low < 0xE000) {
                cp = 0x10000 + ((cp - 0xD800) << 10) + (low - 0xDC00);
                p->pos += 6;
            }
            if (put_utf8(p, cp) < 0) return -1;
        } else {
            return fail(p, "bad escape in a string");
        }
        run = p->pos;
    }
    return fail(p, "unexpected end of input in a string (truncated JSON?)");
}

/* Compare the string just read with a literal. */
static int key_is(Parser *p, const char *key) {
    size_t n = strlen(key);
    return p->str_len == n && memcmp(p->str, key, n) == 0;
}

/* Clinger's fast path: a decimal with at most 15 significant digits and no exponent is an
   exact integer divided by an exact power of ten, so one correctly rounded division gives
   the same double as strtod. Returns 0 when the text is outside the fast path. */
static int fast_decimal(const char *s, size_t n, double *out) {
    static const double POW10[] = {1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15};
    uint64_t mantissa = 0;
    int digits = 0, fraction = -1, negative = 0;
    size_t i = 0;
    if (i < n && s[i] == '-') { negative = 1; i++; }
    for (; i < n; i++) {
        char c = s[i];
        if (c == '.') { fraction = 0; continue; }
        if (c < '0' || c > '9') return 0;
        if (mantissa || c != '0') digits++;
        if (digits > 15) return 0;
        mantissa = mantissa * 10 + (uint64_t)(c - '0');
        if (fraction >= 0) fraction++;
    }
    double value = (double)mantissa;
    if (fraction > 0) value /= POW10[fraction > 15 ? 15 : fraction];
    if (fraction > 15) return 0;
    *out = negative ? -value : value;
    return 1;
}

/* A JSON number; *integral tells whether it had no fraction or exponent. */
static int read_number(Parser *p, double *out, int *integral) {
    skip_ws(p);
    size_t start = p->pos;
    if (p->pos < p->len && p->buf[p->pos] == '-') p->pos++;
    size_t digits = p->pos;
    while (p->pos < p->len && p->buf[p->pos] >= '0' && p->buf[p->pos] <= '9') p->pos++;
    if (p->pos == digits) { p->pos = start; return fail(p, "expected a number"); }
    if (p->pos - digits > 1 && p->buf[digits] == '0') { p->pos = start; return fail(p, "leading zero in a number"); }
    *integral = 1;
    if (p->pos < p->len && p->buf[p->pos] == '.') {
        *integral = 0;
        p->pos++;
        size_t frac = p->pos;
        while (p->pos < p->len && p->buf[p->pos] >= '0' && p->buf[p->pos] <= '9') p->pos++;
        if (p->pos == frac) return fail(p, "expected digits after '.'");
    }
    if (p->pos < p->len && (p->buf[p->pos] == 'e' || p->buf[p->pos] == 'E')) {
        *integral = 0;
        p->pos++;
        if (p->pos < p->len && (p->buf[p->pos] == '+' || p->buf[p->pos] == '-')) p->pos++;
        size_t exp = p->pos;
        while (p->pos < p->len && p->buf[p->pos] >= '0' && p->buf[p->pos] <= '9') p->pos++;
        if (p->pos == exp) return fail(p, "expected digits in an exponent");
    }
    if (fast_decimal(p->buf + start, p->pos - start, out)) return 0;
    char text[64];
    size_t n = p->pos - start;
    if (n >= sizeof text) return fail(p, "number too long");
    memcpy(text, p->buf + start, n);
    text[n] = 0;
    *out = strtod(text, NULL);
    return 0;
}

static int read_float(Parser *p, double *out) {
    int integral;
    return read_number(p, out, &integral);
}

/* An unsigned integer no larger than max (STREM's usize / u32 fields). */
static int read_unsigned(Parser *p, double max, double *out) {
    int integral;
    size_t start = p->pos;
    if (read_number(p, out, &integral) < 0) return -1;
    if (!integral || *out < 0 || *out > max) {
        char message[96];
        snprintf(message, sizeof message, "expected an unsigned integer, found %.*s",
                 (int)(p->pos - start > 40 ? 40 : p->pos - start), p->buf + start);
        p->pos = start;
        skip_ws(p);
        return fail(p, message);
    }
    return 0;
}

static int skip_value(Parser *p, int depth);

static int skip_literal(Parser *p, const char *word) {
    size_t n = strlen(word);
    if (p->pos + n > p->len || memcmp(p->buf + p->pos, word, n) != 0) return fail(p, "invalid JSON value");
    p->pos += n;
    return 0;
}

static int skip_value(Parser *p, int depth) {
    if (depth > MAX_DEPTH) return fail(p, "nesting too deep");
    skip_ws(p);
    if (p->pos >= p->len) return fail(p, "unexpected end of input (truncated JSON?)");
    char c = p->buf[p->pos];
    if (c == '"') return read_string(p);
    if (c == '{' || c == '[') {
        char close = c == '{' ? '}' : ']';
        p->pos++;
        if (empty_container(p, close)) return 0;
        for (;;) {
            if (c == '{') {
                if (read_string(p) < 0 || expect(p, ':') < 0) return -1;
            }
            if (skip_value(p, depth + 1) < 0) return -1;
            int more = next_item(p, close);
            if (more < 0) return -1;
            if (!more) return 0;
        }
    }
    if (c == 't') return skip_literal(p, "true");
    if (c == 'f') return skip_literal(p, "false");
    if (c == 'n') return skip_literal(p, "null");
    double ignored;
    return read_float(p, &ignored);
}

/* Iterate over an object's keys: calls field(p, ctx) with the key in scratch. */
typedef int (*FieldFn)(Parser *p, void *ctx);

static int read_object(Parser *p, FieldFn field, void *ctx) {
    if (expect(p, '{') < 0) return -1;
    if (empty_container(p, '}')) return 0;
    for (;;) {
        if (read_string(p) < 0 || expect(p, ':') < 0) return -1;
        if (field(p, ctx) < 0) return -1;
        int more = next_item(p, '}');
        if (more < 0) return -1;
        if (!more) return 0;
    }
}

typedef int (*ItemFn)(Parser *p, void *ctx);

static int read_array(Parser *p, ItemFn item, void *ctx) {
    if (expect(p, '[') < 0) return -1;
    if (empty_container(p, ']')) return 0;
    for (;;) {
        if (item(p, ctx) < 0) return -1;
        int more = next_item(p, ']');
        if (more < 0) return -1;
        if (!more) return 0;
    }
}

static int missing(Parser *p, const char *field) {
    char message[96];
    snprintf(message, sizeof message, "missing field `%s`", field);
    return fail(p, message);
}

/* ------------------------------------------------------------------ schema: boxes */
typedef struct {
    double x, y, w, h, rotation;
    int has_center, has_dimensions, has_rotation, has_x, has_y, has_w, has_h;
} Region;

static int point_field(Parser *p, void *ctx) {
    Region *r = ctx;
    if (key_is(p, "x")) { r->has_x = 1; return read_float(p, &r->x); }
    if (key_is(p, "y")) { r->has_y = 1; return read_float(p, &r->y); }
    return skip_value(p, 0);
}

static int size_field(Parser *p, void *ctx) {
    Region *r = ctx;
    if (key_is(p, "w")) { r->has_w = 1; return read_float(p, &r->w); }
    if (key_is(p, "h")) { r->has_h = 1; return read_float(p, &r->h); }
    return skip_value(p, 0);
}

static int region_field(Parser *p, void *ctx) {
    Region *r = ctx;
    if (key_is(p, "center")) {
        p->where = "bbox.region.center";
        r->has_center = 1;
        if (read_object(p, point_field, r) < 0) return -1;
        if (!r->has_x) return missing(p, "x");
        return r->has_y ? 0 : missing(p, "y");
    }
    if (key_is(p, "dimensions")) {
        p->where = "bbox.region.dimensions";
        r->has_dimensions = 1;
        if (read_object(p, size_field, r) < 0) return -1;
        if (!r->has_w) return missing(p, "w");
        return r->has_h ? 0 : missing(p, "h");
    }
    if (key_is(p, "rotation")) { r->has_rotation = 1; return read_float(p, &r->rotation); }
    return skip_value(p, 0);
}

typedef struct {
    Region region;
    int type;                 /* 0 unknown, 1 aabb, 2 obb */
    int has_type, has_region;
} Bbox;

static int bbox_field(Parser *p, void *ctx) {
    Bbox *b = ctx;
    if (key_is(p, "type")) {
        size_t at = p->pos;
        if (read_string(p) < 0) return -1;
        b->has_type = 1;
        if (key_is(p, "@stremf/bbox/aabb")) b->type = 1;
        else if (key_is(p, "@stremf/bbox/obb")) b->type = 2;
        else {
            char message[200];
            snprintf(message, sizeof message, "unknown variant `%.*s`, expected `@stremf/bbox/aabb` or "
                     "`@stremf/bbox/obb`", (int)(p->str_len > 60 ? 60 : p->str_len), p->str);
            p->where = "bbox.type";
            p->pos = at;
            skip_ws(p);
            return fail(p, message);
        }
        return 0;
    }
    if (key_is(p, "region")) {
        p->where = "bbox.region";
        b->has_region = 1;
        size_t at = p->pos;
        if (read_object(p, region_field, &b->region) < 0) return -1;
        Region *r = &b->region;
        if (!r->has_center || !r->has_dimensions) {
            p->pos = at;
            skip_ws(p);
            return missing(p, r->has_center ? "dimensions" : "center");
        }
        return 0;
    }
    return skip_value(p, 0);
}

typedef struct {
    int32_t category;
    double score;
    Bbox bbox;
    int has_class, has_score, has_bbox;
} Annotation;

static int annotation_field(Parser *p, void *ctx) {
    Annotation *a = ctx;
    p->where = NULL;
    if (key_is(p, "class")) {
        p->where = "class";
        if (read_string(p) < 0) return -1;
        a->has_class = 1;
        a->category = intern(&p->classes, p->str, p->str_len);
        return a->category < 0 ? -1 : 0;
    }
    if (key_is(p, "score")) { p->where = "score"; a->has_score = 1; return read_float(p, &a->score); }
    if (key_is(p, "bbox")) {
        p->where = "bbox";
        a->has_bbox = 1;
        size_t at = p->pos;
        if (read_object(p, bbox_field, &a->bbox) < 0) return -1;
        if (!a->bbox.has_type || !a->bbox.has_region) {
            p->pos = at;
            skip_ws(p);
            p->where = "bbox";
            return missing(p, a->bbox.has_type ? "region" : "type");
        }
        if (a->bbox.type == 2 && !a->bbox.region.has_rotation) {
            p->pos = at;
            skip_ws(p);
            p->where = "bbox.region";
            return missing(p, "rotation");
        }
        return 0;
    }
    return skip_value(p, 0);
}

static int annotation_item(Parser *p, void *ctx) {
    int32_t sample = *(int32_t *)ctx;
    Annotation a;
    memset(&a, 0, sizeof a);
    p->where = NULL;
    skip_ws(p);
    size_t at = p->pos;
    if (read_object(p, annotation_field, &a) < 0) return -1;
    if (!a.has_class || !a.has_score || !a.has_bbox) {
        p->pos = at;
        p->where = NULL;
        return missing(p, !a.has_class ? "class" : !a.has_score ? "score" : "bbox");
    }
    int obb = a.bbox.type == 2;
    double rotation = obb ? a.bbox.region.rotation : 0.0;
    uint8_t oriented = (uint8_t)obb;
    Region *r = &a.bbox.region;
    if (push_i32(&p->cols[C_B_SAMPLE], sample) < 0 || push_i32(&p->cols[C_B_CLASS], a.category) < 0
        || push_f64(&p->cols[C_B_SCORE], a.score) < 0 || push_f64(&p->cols[C_B_CX], r->x) < 0
        || push_f64(&p->cols[C_B_CY], r->y) < 0 || push_f64(&p->cols[C_B_W], r->w) < 0
        || push_f64(&p->cols[C_B_H], r->h) < 0 || push_f64(&p->cols[C_B_ROT], rotation) < 0
        || push_u8(&p->cols[C_B_OBB], oriented) < 0)
        return -1;
    p->annotation++;
    return 0;
}

/* ------------------------------------------------------------------ schema: samples, frames */
typedef struct {
    int32_t channel, path, row;
    double width, height;
    int has_type, has_channel, has_image, has_annotations, has_path, has_dimensions, has_width, has_height;
} Sample;

static int image_size_field(Parser *p, void *ctx) {
    Sample *s = ctx;
    if (key_is(p, "width")) { s->has_width = 1; return read_unsigned(p, 4294967295.0, &s->width); }
    if (key_is(p, "height")) { s->has_height = 1; return read_unsigned(p, 4294967295.0, &s->height); }
    return skip_value(p, 0);
}

static int image_field(Parser *p, void *ctx) {
    Sample *s = ctx;
    if (key_is(p, "path")) {
        if (read_string(p) < 0) return -1;
        s->has_path = 1;
        s->path = intern(&p->paths, p->str, p->str_len);
        return s->path < 0 ? -1 : 0;
    }
    if (key_is(p, "dimensions")) {
        p->where = "image.dimensions";
        s->has_dimensions = 1;
        size_t at = p->pos;
        if (read_object(p, image_size_field, s) < 0) return -1;
        if (!s->has_width || !s->has_height) {
            p->pos = at;
            skip_ws(p);
            return missing(p, s->has_width ? "height" : "width");
        }
        return 0;
    }
    return skip_value(p, 0);
}

static int sample_field(Parser *p, void *ctx) {
    Sample *s = ctx;
    p->where = NULL;
    p->annotation = -1;
    if (key_is(p, "type")) {
        size_t at = p->pos;
        p->where = "type";
        if (read_string(p) < 0) return -1;
        if (!key_is(p, "@stremf/sample/detection")) {
            p->pos = at;
            skip_ws(p);
            return fail(p, "unknown variant, expected `@stremf/sample/detection`");
        }
        s->has_type = 1;
        return 0;
    }
    if (key_is(p, "channel")) {
        p->where = "channel";
        if (read_string(p) < 0) return -1;
        s->has_channel = 1;
        s->channel = intern(&p->channels, p->str, p->str_len);
        return s->channel < 0 ? -1 : 0;
    }
    if (key_is(p, "image")) {
        p->where = "image";
        s->has_image = 1;
        size_t at = p->pos;
        if (read_object(p, image_field, s) < 0) return -1;
        if (!s->has_path || !s->has_dimensions) {
            p->pos = at;
            skip_ws(p);
            p->where = "image";
            return missing(p, s->has_path ? "dimensions" : "path");
        }
        return 0;
    }
    if (key_is(p, "annotations")) {
        s->has_annotations = 1;
        p->annotation = 0;
        return read_array(p, annotation_item, &s->row);
    }
    return skip_value(p, 0);
}

static int sample_item(Parser *p, void *ctx) {
    int32_t frame = *(int32_t *)ctx;
    Sample s;
    memset(&s, 0, sizeof s);
    s.row = (int32_t)p->cols[C_S_FRAME].len;
    p->where = NULL;
    skip_ws(p);
    size_t at = p->pos;
    if (read_object(p, sample_field, &s) < 0) return -1;
    p->annotation = -1;
    if (!s.has_type || !s.has_channel || !s.has_image || !s.has_annotations) {
        p->pos = at;
        p->where = NULL;
        return missing(p, !s.has_type ? "type" : !s.has_channel ? "channel" : !s.has_image ? "image" : "annotations");
    }
    int32_t width = (int32_t)(uint32_t)s.width, height = (int32_t)(uint32_t)s.height;
    if (push_i32(&p->cols[C_S_FRAME], frame) < 0 || push_i32(&p->cols[C_S_CHANNEL], s.channel) < 0
        || push_i32(&p->cols[C_S_PATH], s.path) < 0 || push_i32(&p->cols[C_S_WIDTH], width) < 0
        || push_i32(&p->cols[C_S_HEIGHT], height) < 0)
        return -1;
    p->sample++;
    return 0;
}

typedef struct {
    double index, time;
    int32_t position;
    int has_index, has_samples, has_time;
} Frame;

static int frame_field(Parser *p, void *ctx) {
    Frame *f = ctx;
    p->where = NULL;
    p->sample = -1;
    if (key_is(p, "index")) { p->where = "index"; f->has_index = 1; return read_unsigned(p, 9007199254740992.0, &f->index); }
    if (key_is(p, "timestamp")) {
        p->where = "timestamp";
        skip_ws(p);
        if (p->pos < p->len && p->buf[p->pos] == 'n') return skip_literal(p, "null");
        f->has_time = 1;
        return read_float(p, &f->time);
    }
    if (key_is(p, "samples")) {
        f->has_samples = 1;
        p->sample = 0;
        return read_array(p, sample_item, &f->position);
    }
    return skip_value(p, 0);
}

static int frame_item(Parser *p, void *ctx) {
    (void)ctx;
    Frame f;
    memset(&f, 0, sizeof f);
    f.position = (int32_t)p->cols[C_FRAME_INDEX].len;
    p->where = NULL;
    p->sample = -1;
    skip_ws(p);
    size_t at = p->pos;
    if (read_object(p, frame_field, &f) < 0) return -1;
    if (!f.has_index || !f.has_samples) {
        p->pos = at;
        p->where = NULL;
        return missing(p, f.has_index ? "samples" : "index");
    }
    int64_t index = (int64_t)f.index;
    double time = f.has_time ? f.time : NAN;
    if (push_i64(&p->cols[C_FRAME_INDEX], index) < 0 || push_f64(&p->cols[C_FRAME_TIME], time) < 0) return -1;
    p->frame++;
    release_pages(p);
    return 0;
}

typedef struct {
    int has_version, has_frames;
    size_t version_pos;
    PyObject *version;
} Document;

static int document_field(Parser *p, void *ctx) {
    Document *d = ctx;
    p->where = NULL;
    if (key_is(p, "version")) {
        skip_ws(p);
        d->version_pos = p->pos;
        p->where = "version";
        if (read_string(p) < 0) return -1;
        Py_XDECREF(d->version);
        d->version = PyUnicode_DecodeUTF8(p->str, (Py_ssize_t)p->str_len, "surrogateescape");
        d->has_version = 1;
        return d->version ? 0 : -1;
    }
    if (key_is(p, "frames")) {
        d->has_frames = 1;
        p->frame = 0;
        if (read_array(p, frame_item, NULL) < 0) return -1;
        p->frame = -1;
        return 0;
    }
    return skip_value(p, 0);
}

static int read_document(Parser *p) {
    Document d;
    memset(&d, 0, sizeof d);
    p->frame = -1;
    p->where = NULL;
    size_t at = p->pos;
    if (read_object(p, document_field, &d) < 0) { Py_XDECREF(d.version); return -1; }
    if (!d.has_version || !d.has_frames) {
        Py_XDECREF(d.version);
        p->pos = at;
        return missing(p, d.has_version ? "frames" : "version");
    }
    PyObject *entry = Py_BuildValue("(Nn)", d.version, (Py_ssize_t)d.version_pos);
    if (!entry) return -1;
    int result = PyList_Append(p->versions, entry);
    Py_DECREF(entry);
    return result;
}

/* ------------------------------------------------------------------ Python interface */
static PyObject *where_text(Parser *p) {
    char text[300];
    int n = 0;
    if (p->frame >= 0) n += snprintf(text + n, sizeof text - (size_t)n, "frames[%ld]", p->frame);
    if (p->frame >= 0 && p->sample >= 0)
        n += snprintf(text + n, sizeof text - (size_t)n, ".samples[%ld]", p->sample);
    if (p->frame >= 0 && p->sample >= 0 && p->annotation >= 0)
        n += snprintf(text + n, sizeof text - (size_t)n, ".annotations[%ld]", p->annotation);
    if (p->where) n += snprintf(text + n, sizeof text - (size_t)n, "%s%s", n ? "." : "", p->where);
    return PyUnicode_FromStringAndSize(text, n);
}

static void parser_free(Parser *p) {
    for (int i = 0; i < N_COLUMNS; i++) free(p->cols[i].data);
    intern_free(&p->channels);
    intern_free(&p->classes);
    intern_free(&p->paths);
    free(p->scratch);
    Py_XDECREF(p->versions);
}

static PyObject *result_dict(Parser *p) {
    PyObject *out = PyDict_New();
    if (!out) return NULL;
    for (int i = 0; i < N_COLUMNS; i++) {
        PyObject *bytes = PyBytes_FromStringAndSize(p->cols[i].data, (Py_ssize_t)(p->cols[i].len * p->cols[i].item));
        if (!bytes || PyDict_SetItemString(out, COLUMN_NAMES[i], bytes) < 0) { Py_XDECREF(bytes); Py_DECREF(out); return NULL; }
        Py_DECREF(bytes);
        free(p->cols[i].data);
        p->cols[i].data = NULL;
    }
    PyObject *lists[3] = {intern_list(&p->channels), intern_list(&p->classes), intern_list(&p->paths)};
    const char *names[3] = {"channels", "classes", "paths"};
    for (int i = 0; i < 3; i++) {
        if (!lists[i] || PyDict_SetItemString(out, names[i], lists[i]) < 0) {
            for (int j = 0; j < 3; j++) Py_XDECREF(lists[j]);
            Py_DECREF(out);
            return NULL;
        }
    }
    for (int i = 0; i < 3; i++) Py_DECREF(lists[i]);
    if (PyDict_SetItemString(out, "versions", p->versions) < 0) { Py_DECREF(out); return NULL; }
    return out;
}

static PyObject *parse(PyObject *self, PyObject *args, PyObject *kwargs) {
    (void)self;
    static char *keywords[] = {"buffer", "release", NULL};
    Py_buffer view;
    int release = 0;
    if (!PyArg_ParseTupleAndKeywords(args, kwargs, "y*|p", keywords, &view, &release)) return NULL;
    Parser p;
    memset(&p, 0, sizeof p);
    p.buf = view.buf;
    p.len = (size_t)view.len;
    p.release = release;
    p.frame = p.sample = p.annotation = -1;
    for (int i = 0; i < N_COLUMNS; i++) p.cols[i].item = COLUMN_SIZES[i];
    p.versions = PyList_New(0);
    int status = p.versions ? 0 : -1;
    while (status == 0) {
        skip_ws(&p);
        if (p.pos >= p.len) break;
        status = read_document(&p);
    }
    PyObject *result = NULL;
    if (status == 0) {
        result = result_dict(&p);
    } else if (p.error && !PyErr_Occurred()) {
        PyObject *where = where_text(&p);
        /* a message may quote input bytes that are not UTF-8: shown as \xNN escapes */
        PyObject *message = PyUnicode_DecodeUTF8(p.error, (Py_ssize_t)strlen(p.error), "backslashreplace");
        if (where && message)
            PyErr_SetObject(PyExc_ValueError, Py_BuildValue("(NnN)", message, (Py_ssize_t)p.error_pos, where));
        else {
            Py_XDECREF(where);
            Py_XDECREF(message);
        }
    }
    parser_free(&p);
    PyBuffer_Release(&view);
    return result;
}

static PyMethodDef METHODS[] = {
    {"parse", (PyCFunction)(void (*)(void))parse, METH_VARARGS | METH_KEYWORDS,
     "parse(buffer, release=False) -> dict of columns of every STREM JSON document in the buffer."},
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef MODULE = {PyModuleDef_HEAD_INIT, "_strem",
                                    "STREM JSON v0.2.0 streams to columns (see the C source for the contract).", -1,
                                    METHODS, NULL, NULL, NULL, NULL};

PyMODINIT_FUNC PyInit__strem(void) { return PyModule_Create(&MODULE); }
