/* Codec of the coupling protocol (proto/PROTOCOL.md). The header is written
 * byte by byte, so it is little-endian on any host; arrays are memcpy'd on
 * little-endian hosts and byte-swapped element by element elsewhere. */
#include "proto_msg.h"

#include <inttypes.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(PROTO_TEST_SWAP)
/* Test build: pretend to be big-endian so the swap path runs on any host. */
#define HOST_LE 0
#elif defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
#define HOST_LE 1
#elif defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
#define HOST_LE 0
#else
#error "proto_msg.c: cannot tell the host byte order"
#endif

_Static_assert(sizeof(int) == 4, "ids travel as i32");
_Static_assert(sizeof(double) == 8, "floats travel as IEEE-754 binary64");
_Static_assert(PROTO_HEADER_LEN == 80, "PROTOCOL.md section 3");

/* ---- header bytes ---- */

static void put_u16(unsigned char *p, uint16_t v) { p[0] = v & 0xff; p[1] = v >> 8; }
static void put_u32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (v >> (8 * i)) & 0xff;
}
static void put_u64(unsigned char *p, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        p[i] = (v >> (8 * i)) & 0xff;
}
static void put_f64(unsigned char *p, double d)
{
    uint64_t v;
    memcpy(&v, &d, 8);
    put_u64(p, v);
}
static uint16_t get_u16(const unsigned char *p) { return (uint16_t)(p[0] | (p[1] << 8)); }
static uint32_t get_u32(const unsigned char *p)
{
    uint32_t v = 0;
    for (int i = 0; i < 4; i++)
        v |= (uint32_t)p[i] << (8 * i);
    return v;
}
static uint64_t get_u64(const unsigned char *p)
{
    uint64_t v = 0;
    for (int i = 0; i < 8; i++)
        v |= (uint64_t)p[i] << (8 * i);
    return v;
}
static double get_f64(const unsigned char *p)
{
    uint64_t v = get_u64(p);
    double d;
    memcpy(&d, &v, 8);
    return d;
}

/* Copies n elements of size elem, converting host <-> little-endian. */
static void le_copy(void *dst, const void *src, size_t n, size_t elem)
{
    if (n == 0)
        return;
    if (HOST_LE || elem == 1) {
        memcpy(dst, src, n * elem);
        return;
    }
    unsigned char *d = dst;
    const unsigned char *s = src;
    for (size_t i = 0; i < n; i++, d += elem, s += elem)
        for (size_t b = 0; b < elem; b++)
            d[b] = s[elem - 1 - b];
}

/* ---- names and tables ---- */

static const char *const type_names[] = {"?", "HELLO", "REJECT", "CONFIG", "READY", "ADVANCE",
                                         "RESULT", "STOP", "BYE", "ERROR", "ABORT"};

const char *proto_type_name(int type)
{
    return type >= PROTO_HELLO && type <= PROTO_ABORT ? type_names[type] : "?";
}

const char *proto_payload_name(int payload)
{
    switch (payload) {
    case PROTO_NONE: return "NONE";
    case PROTO_STATE: return "STATE";
    case PROTO_LOADS: return "LOADS";
    }
    return "?";
}

/* One array frame of a payload (PROTOCOL.md section 5). */
struct arr_desc {
    const char *name;
    size_t elem;      /* bytes per value */
    int vector;       /* 1: MPS_DIM components per particle */
    const char *tname;
};

static const struct arr_desc state_arrays[] = {
    {"id", 4, 0, "i32"}, {"x", 8, 1, "f64"}, {"v", 8, 1, "f64"},
    {"surface", 1, 0, "u8"}, {"fixed", 1, 0, "u8"}};
static const struct arr_desc loads_arrays[] = {
    {"id", 4, 0, "i32"}, {"pressure", 8, 0, "f64"}, {"force", 8, 1, "f64"}};

static int payload_narrays(enum proto_payload p, const struct arr_desc **d)
{
    switch (p) {
    case PROTO_STATE: *d = state_arrays; return 5;
    case PROTO_LOADS: *d = loads_arrays; return 3;
    default: *d = NULL; return 0;
    }
}

static const void *arr_get(const struct proto_msg *m, int k)
{
    if (m->payload == PROTO_STATE) {
        switch (k) {
        case 0: return m->id;
        case 1: return m->x;
        case 2: return m->v;
        case 3: return m->surface;
        case 4: return m->fixed;
        }
    } else if (m->payload == PROTO_LOADS) {
        switch (k) {
        case 0: return m->id;
        case 1: return m->pressure;
        case 2: return m->force;
        }
    }
    return NULL;
}

static void arr_set(struct proto_msg *m, int k, const void *p)
{
    if (m->payload == PROTO_STATE) {
        switch (k) {
        case 0: m->id = p; break;
        case 1: m->x = p; break;
        case 2: m->v = p; break;
        case 3: m->surface = p; break;
        case 4: m->fixed = p; break;
        }
    } else if (m->payload == PROTO_LOADS) {
        switch (k) {
        case 0: m->id = p; break;
        case 1: m->pressure = p; break;
        case 2: m->force = p; break;
        }
    }
}

static int has_probe_frame(const struct proto_msg *m)
{
    return m->type == PROTO_RESULT && (m->flags & PROTO_F_PROBES);
}

/* ---- text ---- */

/* Offset of the first invalid UTF-8 sequence (overlong forms, surrogates and
 * code points above U+10FFFF are invalid), or -1 if s[0..n) is valid. */
static long utf8_invalid_at(const unsigned char *s, size_t n)
{
    size_t i = 0;
    while (i < n) {
        unsigned c = s[i];
        if (c < 0x80) {
            i++;
            continue;
        }
        size_t len;
        uint32_t cp, min;
        if ((c & 0xe0) == 0xc0) {
            len = 2, cp = c & 0x1f, min = 0x80;
        } else if ((c & 0xf0) == 0xe0) {
            len = 3, cp = c & 0x0f, min = 0x800;
        } else if ((c & 0xf8) == 0xf0) {
            len = 4, cp = c & 0x07, min = 0x10000;
        } else {
            return (long)i;
        }
        if (i + len > n)
            return (long)i;
        for (size_t k = 1; k < len; k++) {
            if ((s[i + k] & 0xc0) != 0x80)
                return (long)i;
            cp = (cp << 6) | (s[i + k] & 0x3f);
        }
        if (cp < min || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff))
            return (long)i;
        i += len;
    }
    return -1;
}

int proto_text_get(const char *text, char sep, const char *key, char *buf, size_t n)
{
    if (!text || !key)
        return 0;
    size_t klen = strlen(key);
    const char *p = text;
    while (*p) {
        const char *end = strchr(p, sep);
        if (!end)
            end = p + strlen(p);
        if ((size_t)(end - p) > klen && strncmp(p, key, klen) == 0 && p[klen] == '=') {
            const char *val = p + klen + 1;
            size_t vlen = (size_t)(end - val);
            if (!buf || vlen + 1 > n)
                return -1;
            memcpy(buf, val, vlen);
            buf[vlen] = '\0';
            return 1;
        }
        p = *end ? end + 1 : end;
    }
    return 0;
}

/* 1 and the code if text starts with "STATUS: " for a known status name. */
static int status_prefix(const char *text, enum mps_status *code, const char **rest)
{
    for (int c = MPS_EINPUT; c <= MPS_EINTR; c++) {
        const char *name = mps_status_name((enum mps_status)c);
        size_t len = strlen(name);
        if (strncmp(text, name, len) == 0 && text[len] == ':' && text[len + 1] == ' ') {
            *code = (enum mps_status)c;
            if (rest)
                *rest = text + len + 2;
            return 1;
        }
    }
    return 0;
}

enum mps_status proto_error_status(const char *text, const char **message)
{
    enum mps_status code = MPS_EPEER;
    const char *rest = text;
    if (!text || !status_prefix(text, &code, &rest)) {
        code = MPS_EPEER;
        rest = text;
    }
    if (message)
        *message = rest;
    return code;
}

int proto_case_error(const char *text, const char **line)
{
    const char *rest = NULL;
    if (proto_error_status(text, &rest) != MPS_EINPUT || !rest ||
        strncmp(rest, PROTO_CASE_ERROR, strlen(PROTO_CASE_ERROR)) != 0)
        return 0;
    if (line)
        *line = rest + strlen(PROTO_CASE_ERROR);
    return 1;
}

/* ---- semantic checks shared by encode and decode ---- */

__attribute__((format(printf, 3, 4)))
static enum mps_status bad(struct mps_err *err, const struct proto_msg *m, const char *fmt, ...)
{
    char what[768];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    return mps_err_set(err, MPS_EPROTO, "%s: %s", proto_type_name(m->type), what);
}

static enum mps_status check_hello(const struct proto_msg *m, struct mps_err *err)
{
    char role[16], model[64], pid[32];
    if (proto_text_get(m->text, ' ', "role", role, sizeof role) != 1 ||
        (strcmp(role, "fluid") != 0 && strcmp(role, "solid") != 0))
        return bad(err, m, "text '%.200s': needs role=fluid or role=solid", m->text);
    int r = proto_text_get(m->text, ' ', "model", model, sizeof model); /* -1: long name */
    if (r == 0 || (r == 1 && !model[0]))
        return bad(err, m, "text '%.200s': needs model=NAME", m->text);
    int ok = proto_text_get(m->text, ' ', "pid", pid, sizeof pid) == 1 && pid[0];
    for (const char *c = pid; ok && *c; c++)
        ok = *c >= '0' && *c <= '9';
    if (!ok)
        return bad(err, m, "text '%.200s': needs pid=N (decimal)", m->text);
    return MPS_OK;
}

static enum mps_status check_config(const struct proto_msg *m, struct mps_err *err)
{
    static const char *const required[] = {"case", "out", "prefix"};
    for (const char *p = m->text; *p;) {
        const char *end = strchr(p, '\n');
        if (!end)
            end = p + strlen(p);
        const char *eq = memchr(p, '=', (size_t)(end - p));
        if (end > p && (!eq || eq == p))
            return bad(err, m, "line '%.*s': expected key=value",
                       (int)(end - p < 100 ? end - p : 100), p);
        p = *end ? end + 1 : end;
    }
    for (size_t k = 0; k < sizeof required / sizeof *required; k++) {
        char val[8];
        if (proto_text_get(m->text, '\n', required[k], val, sizeof val) == 0)
            return bad(err, m, "key '%s' missing (needs case, out, prefix)", required[k]);
    }
    return MPS_OK;
}

/* Probe names: comma-separated, non-empty, no whitespace or control bytes. */
static enum mps_status check_probe_names(const struct proto_msg *m, struct mps_err *err)
{
    const char *t = m->text ? m->text : "";
    long names = 0;
    if (*t) {
        names = 1;
        const char *start = t;
        for (const char *c = t;; c++) {
            if (*c == ',' || *c == '\0') {
                if (c == start)
                    return bad(err, m, "probe names '%.200s': empty name", t);
                if (*c == '\0')
                    break;
                names++;
                start = c + 1;
            } else if ((unsigned char)*c <= ' ' || *c == 0x7f) {
                return bad(err, m, "probe names '%.200s': whitespace or control character", t);
            }
        }
    }
    if (names != m->nprobes)
        return bad(err, m, "%ld probe names, nprobes = %d", names, m->nprobes);
    return MPS_OK;
}

static enum mps_status check_arrays(const struct proto_msg *m, struct mps_err *err)
{
    const struct arr_desc *d;
    int na = payload_narrays(m->payload, &d);
    if (m->count == 0)
        return MPS_OK;
    for (int k = 0; k < na; k++) {
        if (!arr_get(m, k))
            return bad(err, m, "array %s is NULL with count = %zu", d[k].name, m->count);
    }
    for (size_t i = 0; i < m->count; i++) {
        if (m->id[i] < 0)
            return bad(err, m, "id[%zu] = %d: ids must be >= 0", i, m->id[i]);
    }
    const double *f[2] = {NULL, NULL};
    const char *fname[2] = {NULL, NULL};
    int comps[2] = {1, 1};
    if (m->payload == PROTO_STATE) {
        for (size_t i = 0; i < m->count; i++) {
            if (m->surface[i] > 1 || m->fixed[i] > 1)
                return bad(err, m, "surface[%zu] = %u, fixed[%zu] = %u: must be 0 or 1", i,
                           m->surface[i], i, m->fixed[i]);
        }
        f[0] = &m->x[0][0], fname[0] = "x", comps[0] = MPS_DIM;
        f[1] = &m->v[0][0], fname[1] = "v", comps[1] = MPS_DIM;
    } else if (m->payload == PROTO_LOADS) {
        f[0] = m->pressure, fname[0] = "pressure";
        f[1] = &m->force[0][0], fname[1] = "force", comps[1] = MPS_DIM;
    }
    for (int a = 0; a < 2 && f[a]; a++) {
        for (size_t i = 0; i < m->count * (size_t)comps[a]; i++) {
            if (isfinite(f[a][i]))
                continue;
            if (comps[a] == 1)
                return bad(err, m, "%s[%zu] = %g (id %d): must be finite", fname[a], i, f[a][i],
                           m->id[i]);
            return bad(err, m, "%s[%zu][%zu] = %g (id %d): must be finite", fname[a],
                       i / (size_t)comps[a], i % (size_t)comps[a], f[a][i],
                       m->id[i / (size_t)comps[a]]);
        }
    }
    return MPS_OK;
}

static enum mps_status check_msg(const struct proto_msg *m, struct mps_err *err)
{
    enum proto_type t = m->type;
    if (t < PROTO_HELLO || t > PROTO_ABORT)
        return mps_err_set(err, MPS_EPROTO, "unknown message type %d (known: 1..10)", (int)t);
    if (m->payload != PROTO_NONE && m->payload != PROTO_STATE && m->payload != PROTO_LOADS)
        return bad(err, m, "unknown payload kind %d (known: 0..2)", (int)m->payload);
    /* Which payloads, flags and text each type takes (PROTOCOL.md section 4). */
    int payload_ok;
    switch (t) {
    case PROTO_READY: payload_ok = m->payload != PROTO_LOADS; break;
    case PROTO_ADVANCE: payload_ok = 1; break;
    case PROTO_RESULT: payload_ok = m->payload != PROTO_NONE; break;
    default: payload_ok = m->payload == PROTO_NONE; break;
    }
    if (!payload_ok)
        return bad(err, m, "payload %s not allowed", proto_payload_name(m->payload));
    uint32_t known = PROTO_F_TEXT | PROTO_F_SNAPSHOT | PROTO_F_PROBES | PROTO_F_CHECKPOINT;
    if (m->flags & ~known)
        return bad(err, m, "flags 0x%" PRIx32 " have unknown bits 0x%" PRIx32, m->flags,
                   m->flags & ~known);
    if ((m->flags & PROTO_F_SNAPSHOT) && t != PROTO_ADVANCE)
        return bad(err, m, "flag SNAPSHOT is for ADVANCE only");
    if ((m->flags & PROTO_F_CHECKPOINT) && t != PROTO_ADVANCE)
        return bad(err, m, "flag CHECKPOINT is for ADVANCE only");
    if ((m->flags & PROTO_F_PROBES) && t != PROTO_ADVANCE && t != PROTO_RESULT)
        return bad(err, m, "flag PROBES is for ADVANCE and RESULT only");
    int text_rule; /* 1 required, 0 forbidden, -1 optional */
    switch (t) {
    case PROTO_READY: text_rule = -1; break;
    case PROTO_ADVANCE:
    case PROTO_RESULT:
    case PROTO_STOP: text_rule = 0; break;
    default: text_rule = 1; break;
    }
    if (((m->flags & PROTO_F_TEXT) != 0) != (m->text != NULL))
        return bad(err, m, "flag TEXT does not match the presence of a text");
    if (text_rule == 1 && !m->text)
        return bad(err, m, "text frame missing (required)");
    if (text_rule == 0 && m->text)
        return bad(err, m, "unexpected text frame");
    if (m->text) {
        size_t len = strlen(m->text);
        if (len > PROTO_MAX_TEXT)
            return bad(err, m, "text is %zu bytes, at most %u", len, PROTO_MAX_TEXT);
        long at = utf8_invalid_at((const unsigned char *)m->text, len);
        if (at >= 0)
            return bad(err, m, "text is not valid UTF-8 at byte %ld", at);
    }
    /* Scalars. */
    if (m->step < 0)
        return bad(err, m, "step = %" PRId64 ": must be >= 0", m->step);
    if (m->iteration < 0)
        return bad(err, m, "iteration = %" PRId32 ": must be >= 0", m->iteration);
    if (m->n_sub < 0 || (t == PROTO_ADVANCE && m->n_sub < 1) || (t != PROTO_ADVANCE && m->n_sub))
        return bad(err, m, "n_sub = %" PRId32 ": must be %s", m->n_sub,
                   t == PROTO_ADVANCE ? ">= 1" : "0 (ADVANCE only)");
    if (!isfinite(m->time))
        return bad(err, m, "time = %g: must be finite", m->time);
    int dt_positive = t == PROTO_ADVANCE || t == PROTO_READY || t == PROTO_RESULT;
    if (!isfinite(m->dt) || m->dt < 0 || (dt_positive && !(m->dt > 0)))
        return bad(err, m, "dt = %g: must be finite and %s", m->dt, dt_positive ? "> 0" : ">= 0");
    /* Payload and probes. */
    if (m->count > PROTO_MAX_COUNT)
        return bad(err, m, "count = %zu exceeds %llu", m->count, PROTO_MAX_COUNT);
    if (m->payload == PROTO_NONE && m->count)
        return bad(err, m, "count = %zu with payload NONE: must be 0", m->count);
    int probes_allowed = t == PROTO_READY || has_probe_frame(m);
    if (m->nprobes < 0 || m->nprobes > PROTO_MAX_PROBES || (!probes_allowed && m->nprobes))
        return bad(err, m, "nprobes = %d: must be %s", m->nprobes,
                   probes_allowed ? "in 0..65536" : "0 here");
    if (has_probe_frame(m) && m->nprobes > 0 && !m->probes)
        return bad(err, m, "probes is NULL with nprobes = %d", m->nprobes);
    enum mps_status st;
    if (t == PROTO_READY && (st = check_probe_names(m, err)))
        return st;
    if (t == PROTO_HELLO && (st = check_hello(m, err)))
        return st;
    if (t == PROTO_CONFIG && (st = check_config(m, err)))
        return st;
    enum mps_status code;
    if (t == PROTO_ERROR && !status_prefix(m->text, &code, NULL))
        return bad(err, m, "text '%.40s' must start with 'STATUS: ' (input, io, memory, library, "
                           "solver, diverged, protocol, timeout, peer, interrupted)", m->text);
    return check_arrays(m, err);
}

/* ---- encode ---- */

struct proto_msg proto_msg_make(enum proto_type type)
{
    struct proto_msg m = {0};
    m.type = type;
    return m;
}

enum mps_status proto_msg_encode(const struct proto_msg *m, struct proto_frames *out,
                                 struct mps_err *err)
{
    memset(out, 0, sizeof *out);
    struct proto_msg c = *m;
    c.flags = (m->flags & ~PROTO_F_TEXT) | (m->text ? PROTO_F_TEXT : 0);
    enum mps_status st = check_msg(&c, err);
    if (st)
        return st;

    const struct arr_desc *d;
    int na = payload_narrays(c.payload, &d);
    int probes = has_probe_frame(&c);
    size_t comps = MPS_DIM;

    unsigned char *h = out->header;
    memcpy(h, "MPSC", 4);
    put_u16(h + 4, PROTO_VERSION);
    put_u16(h + 6, (uint16_t)c.type);
    put_u32(h + 8, c.flags);
    put_u16(h + 12, MPS_DIM);
    put_u16(h + 14, (uint16_t)c.payload);
    put_u64(h + 16, (uint64_t)c.step);
    put_u32(h + 24, (uint32_t)c.iteration);
    put_u32(h + 28, (uint32_t)c.n_sub);
    put_f64(h + 32, c.time);
    put_f64(h + 40, c.dt);
    put_u64(h + 48, (uint64_t)c.count);
    put_u32(h + 56, (uint32_t)(na + probes));
    put_u32(h + 60, (uint32_t)c.nprobes);
    /* bytes 64..79 reserved: zero from the memset */
    out->f[out->n++] = (struct proto_frame){h, PROTO_HEADER_LEN};

    size_t len[PROTO_MAX_FRAMES], elem[PROTO_MAX_FRAMES], total = 0;
    const void *src[PROTO_MAX_FRAMES];
    int nf = 0;
    for (int k = 0; k < na; k++, nf++) {
        elem[nf] = d[k].elem;
        len[nf] = c.count * (d[k].vector ? comps : 1) * d[k].elem;
        src[nf] = arr_get(&c, k);
    }
    if (probes) {
        elem[nf] = 8;
        len[nf] = (size_t)c.nprobes * 8;
        src[nf++] = c.probes;
    }
    if (!HOST_LE) {
        for (int k = 0; k < nf; k++)
            total += (len[k] + 7) & ~(size_t)7;
        if (total && !(out->swap_ = malloc(total))) {
            out->n = 0;
            return mps_err_set(err, MPS_ENOMEM, "%s: cannot allocate %zu bytes to encode",
                               proto_type_name(c.type), total);
        }
    }
    unsigned char *swap = out->swap_;
    for (int k = 0; k < nf; k++) {
        const void *data = len[k] ? src[k] : NULL;
        if (!HOST_LE && len[k]) {
            le_copy(swap, src[k], len[k] / elem[k], elem[k]);
            data = swap;
            swap += (len[k] + 7) & ~(size_t)7;
        }
        out->f[out->n++] = (struct proto_frame){data, len[k]};
    }
    if (c.text)
        out->f[out->n++] = (struct proto_frame){c.text, strlen(c.text)};
    return MPS_OK;
}

void proto_frames_clear(struct proto_frames *fr)
{
    if (!fr)
        return;
    free(fr->swap_);
    memset(fr, 0, sizeof *fr);
}

/* ---- decode ---- */

void proto_msg_clear(struct proto_msg *m)
{
    if (!m)
        return;
    free(m->own_);
    memset(m, 0, sizeof *m);
}

/* Printable form of 4 magic bytes, for the error message. */
static void magic_str(const unsigned char *p, char out[20])
{
    char *o = out;
    for (int i = 0; i < 4; i++) {
        if (p[i] >= 0x20 && p[i] < 0x7f && p[i] != '\\')
            *o++ = (char)p[i];
        else
            o += sprintf(o, "\\x%02x", p[i]);
    }
    *o = '\0';
}

static enum mps_status decode(struct proto_msg *m, const struct proto_frame *fr, int nframes,
                              struct mps_err *err)
{
    if (!fr || nframes < 1)
        return mps_err_set(err, MPS_EPROTO, "empty message: at least the header frame needed");
    const unsigned char *h = fr[0].data;
    size_t hl = fr[0].len;
    if (hl < 8)
        return mps_err_set(err, MPS_EPROTO, "header frame is %zu bytes, expected %d", hl,
                           PROTO_HEADER_LEN);
    if (memcmp(h, "MPSC", 4) != 0) {
        char s[20];
        magic_str(h, s);
        return mps_err_set(err, MPS_EPROTO,
                           "bad magic \"%s\", expected \"MPSC\": not a coupling-protocol message",
                           s);
    }
    unsigned version = get_u16(h + 4);
    if (version != PROTO_VERSION) {
        char why[256] = "";
        /* A REJECT's reason is readable whatever its version (PROTOCOL.md 3). */
        if (get_u16(h + 6) == PROTO_REJECT && nframes >= 2) {
            const struct proto_frame *t = &fr[nframes - 1];
            size_t n = t->len < 160 ? t->len : 160, k = 0;
            char txt[161];
            for (size_t i = 0; i < n; i++) {
                unsigned char c = ((const unsigned char *)t->data)[i];
                txt[k++] = c >= 0x20 && c != 0x7f ? (char)c : '?';
            }
            txt[k] = '\0';
            snprintf(why, sizeof why, " (the peer's REJECT says: %s)", txt);
        }
        return mps_err_set(err, MPS_EPROTO,
                           "protocol version %u received, this build speaks version %d%s",
                           version, PROTO_VERSION, why);
    }
    if (hl != PROTO_HEADER_LEN)
        return mps_err_set(err, MPS_EPROTO, "header frame is %zu bytes, expected %d", hl,
                           PROTO_HEADER_LEN);

    unsigned type = get_u16(h + 6);
    const char *tn = proto_type_name((int)type);
    if (type < PROTO_HELLO || type > PROTO_ABORT)
        return mps_err_set(err, MPS_EPROTO, "unknown message type %u (known: 1..10)", type);
    m->type = (enum proto_type)type;
    m->flags = get_u32(h + 8);
    unsigned dim = get_u16(h + 12);
    unsigned payload = get_u16(h + 14);
    m->step = (int64_t)get_u64(h + 16);
    m->iteration = (int32_t)get_u32(h + 24);
    m->n_sub = (int32_t)get_u32(h + 28);
    m->time = get_f64(h + 32);
    m->dt = get_f64(h + 40);
    uint64_t count = get_u64(h + 48);
    uint32_t narrays = get_u32(h + 56);
    uint32_t nprobes = get_u32(h + 60);

    if (dim != MPS_DIM)
        return mps_err_set(err, MPS_EPROTO, "%s: dim = %u, this build is %dD", tn, dim, MPS_DIM);
    if (payload > PROTO_LOADS)
        return mps_err_set(err, MPS_EPROTO, "%s: unknown payload kind %u (known: 0..2)", tn,
                           payload);
    m->payload = (enum proto_payload)payload;
    if (count > PROTO_MAX_COUNT)
        return mps_err_set(err, MPS_EPROTO, "%s: count = %" PRIu64 " exceeds %llu", tn, count,
                           PROTO_MAX_COUNT);
    if (payload == PROTO_NONE && count)
        return mps_err_set(err, MPS_EPROTO, "%s: count = %" PRIu64 " with payload NONE", tn,
                           count);
    if (nprobes > PROTO_MAX_PROBES)
        return mps_err_set(err, MPS_EPROTO, "%s: nprobes = %" PRIu32 " exceeds %d", tn, nprobes,
                           PROTO_MAX_PROBES);
    m->count = (size_t)count;
    m->nprobes = (int)nprobes;

    const struct arr_desc *d;
    uint32_t na = (uint32_t)payload_narrays(m->payload, &d);
    int probes = has_probe_frame(m);
    if (narrays != na + (uint32_t)probes)
        return mps_err_set(err, MPS_EPROTO,
                           "%s: narrays = %" PRIu32 ", expected %u for payload %s%s", tn,
                           narrays, na + probes, proto_payload_name(m->payload),
                           probes ? " plus the probe frame" : "");
    int text = (m->flags & PROTO_F_TEXT) != 0;
    int want = 1 + (int)narrays + text;
    if (nframes != want)
        return mps_err_set(err, MPS_EPROTO, "%s: %d frames, expected %d (header + %" PRIu32
                           " arrays%s)", tn, nframes, want, narrays, text ? " + text" : "");

    /* Frame lengths; count <= 2^31 keeps every product below 2^36. */
    size_t total = 0;
    for (uint32_t k = 0; k < narrays; k++) {
        const struct proto_frame *f = &fr[1 + k];
        uint64_t expect;
        if (k < na) {
            uint64_t comps = d[k].vector ? MPS_DIM : 1;
            expect = count * comps * d[k].elem;
            if (f->len != expect)
                return mps_err_set(err, MPS_EPROTO,
                                   "%s frame %u (%s): %zu bytes, expected %" PRIu64
                                   " (count %" PRIu64 " x %" PRIu64 " x %s)",
                                   tn, k + 1, d[k].name, f->len, expect, count, comps, d[k].tname);
        } else {
            expect = (uint64_t)nprobes * 8;
            if (f->len != expect)
                return mps_err_set(err, MPS_EPROTO,
                                   "%s frame %u (probes): %zu bytes, expected %" PRIu64
                                   " (nprobes %" PRIu32 " x f64)",
                                   tn, k + 1, f->len, expect, nprobes);
        }
        if (f->len && !f->data)
            return mps_err_set(err, MPS_EPROTO, "%s frame %u: no data", tn, k + 1);
        total += (f->len + 7) & ~(size_t)7;
    }
    size_t tlen = 0;
    const unsigned char *tdata = NULL;
    if (text) {
        tlen = fr[nframes - 1].len;
        tdata = fr[nframes - 1].data;
        if (tlen > PROTO_MAX_TEXT)
            return mps_err_set(err, MPS_EPROTO, "%s: text frame is %zu bytes, at most %u", tn,
                               tlen, PROTO_MAX_TEXT);
        if (tlen && !tdata)
            return mps_err_set(err, MPS_EPROTO, "%s: text frame has no data", tn);
        const unsigned char *nul = tlen ? memchr(tdata, 0, tlen) : NULL;
        if (nul)
            return mps_err_set(err, MPS_EPROTO, "%s: text frame has a NUL byte at offset %td",
                               tn, nul - tdata);
        /* UTF-8 is checked with the rest by check_msg below, as for a
         * message about to be sent */
        total += tlen + 1;
    }

    /* Copy into one owned block, each array 8-byte aligned. */
    unsigned char *block = malloc(total ? total : 1);
    if (!block)
        return mps_err_set(err, MPS_ENOMEM, "%s: cannot allocate %zu bytes to decode", tn, total);
    m->own_ = block;
    for (uint32_t k = 0; k < narrays; k++) {
        const struct proto_frame *f = &fr[1 + k];
        size_t elem = k < na ? d[k].elem : 8;
        le_copy(block, f->data, f->len / elem, elem);
        if (k < na)
            arr_set(m, (int)k, block);
        else
            m->probes = (const double *)block;
        block += (f->len + 7) & ~(size_t)7;
    }
    if (text) {
        if (tlen)
            memcpy(block, tdata, tlen);
        block[tlen] = '\0';
        m->text = (const char *)block;
    }
    return check_msg(m, err);
}

enum mps_status proto_msg_decode(struct proto_msg *m, const struct proto_frame *fr, int nframes,
                                 struct mps_err *err)
{
    memset(m, 0, sizeof *m);
    enum mps_status st = decode(m, fr, nframes, err);
    if (st)
        proto_msg_clear(m);
    return st;
}
