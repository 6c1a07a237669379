/* Reading a case file: bounded, then YAML events into the flat key table
 * with the file:line of each key (mps_case_priv.h). */
#include "mps_case_priv.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <yaml.h>

/* ---- YAML reading ---- */

struct frame {
    int seq;      /* sequence, else mapping */
    int want_key; /* mapping: the next scalar is a key */
    long idx;     /* sequence: index of the next item */
    size_t base;  /* path length of this container */
};

struct seen {
    char *path;
    int line;
};

struct reader {
    struct mps_case *c;
    struct sbuf path;
    struct frame *st;
    int depth, cap;
    struct seen *seen; /* every mapping key, for duplicates */
    int nseen, capseen;
};

static int push_frame(struct reader *r, int seq)
{
    if (r->depth >= CASE_MAX_DEPTH)
        return 1;
    if (r->depth == r->cap) {
        int cap = r->cap ? 2 * r->cap : 16;
        struct frame *st = realloc(r->st, (size_t)cap * sizeof *st);
        if (!st)
            return -1;
        r->st = st;
        r->cap = cap;
    }
    r->st[r->depth++] = (struct frame){seq, 1, 0, r->path.n};
    return 0;
}

/* Appends component s (n chars) to the path of container f. */
static int path_child(struct reader *r, const struct frame *f, const char *s, size_t n)
{
    case_sb_cut(&r->path, f->base);
    if (f->base > 0 && case_sb_add(&r->path, ".", 1))
        return -1;
    return case_sb_add(&r->path, s, n);
}

static int path_index(struct reader *r, const struct frame *f)
{
    char num[32];
    int n = snprintf(num, sizeof num, "%ld", f->idx);
    return path_child(r, f, num, (size_t)n);
}

/* Reader errors are fatal: returns the status after setting err. */
/* A value of the frame f is complete: back to f's path, on to its next
 * item (a sequence's next index, a mapping's next key). */
static void next_item(struct reader *r, struct frame *f)
{
    case_sb_cut(&r->path, f->base);
    if (f->seq)
        f->idx++;
    else
        f->want_key = 1;
}

static enum mps_status read_yaml(struct reader *r, yaml_parser_t *p, struct mps_err *err)
{
    struct mps_case *c = r->c;
    const char *file = c->path;
    int ndocs = 0, done = 0;
    enum mps_status st = MPS_OK;
#define FAIL(code, ...)                          \
    do {                                         \
        st = mps_err_set(err, code, __VA_ARGS__); \
        goto out;                                \
    } while (0)
#define NOMEM() FAIL(MPS_ENOMEM, "%s: out of memory", file)

    while (!done) {
        yaml_event_t ev;
        if (!yaml_parser_parse(p, &ev)) {
            /* The context says where an unclosed construct began. */
            char ctx[128] = "";
            if (p->context)
                snprintf(ctx, sizeof ctx, " (%s at line %lu)", p->context,
                         (unsigned long)p->context_mark.line + 1);
            unsigned long at = (unsigned long)p->problem_mark.line + 1;
            if (p->error == YAML_READER_ERROR) {
                /* the reader (bad UTF-8, a control byte) gives a byte offset,
                 * not a line: count the lines up to it */
                const unsigned char *in = p->input.string.start;
                size_t off = p->problem_offset, n = (size_t)(p->input.string.end - in);
                at = 1;
                for (size_t k = 0; in && k < off && k < n; k++)
                    at += in[k] == '\n';
            }
            return mps_err_set(err, MPS_EINPUT, "%s:%lu: YAML syntax error: %s%s", file, at,
                               p->problem ? p->problem : "unknown", ctx);
        }
        int line = (int)ev.start_mark.line + 1;
        struct frame *top = r->depth ? &r->st[r->depth - 1] : NULL;
        switch (ev.type) {
        case YAML_STREAM_END_EVENT:
            done = 1;
            break;
        case YAML_DOCUMENT_START_EVENT:
            if (++ndocs > 1)
                FAIL(MPS_EINPUT, "%s:%d: only one YAML document is allowed", file, line);
            break;
        case YAML_ALIAS_EVENT:
            FAIL(MPS_EINPUT, "%s:%d: YAML aliases are not supported", file, line);
        case YAML_MAPPING_START_EVENT:
        case YAML_SEQUENCE_START_EVENT: {
            int seq = ev.type == YAML_SEQUENCE_START_EVENT;
            if (!top) {
                if (seq)
                    FAIL(MPS_EINPUT, "%s:%d: the top level must be a mapping of keys", file,
                         line);
            } else if (top->seq) {
                if (path_index(r, top))
                    NOMEM();
            } else if (top->want_key) {
                FAIL(MPS_EINPUT, "%s:%d: complex mapping keys are not supported", file, line);
            }
            int pf = push_frame(r, seq);
            if (pf == 1)
                FAIL(MPS_EINPUT, "%s:%d: nested deeper than %d levels: not a case file", file,
                     line, CASE_MAX_DEPTH);
            if (pf)
                NOMEM();
            break;
        }
        case YAML_MAPPING_END_EVENT:
        case YAML_SEQUENCE_END_EVENT:
            r->depth--;
            if (r->depth)
                next_item(r, &r->st[r->depth - 1]);
            break;
        case YAML_SCALAR_EVENT: {
            const char *s = (const char *)ev.data.scalar.value;
            size_t sn = ev.data.scalar.length;
            if (!top) { /* an empty document is a null scalar */
                if (sn)
                    FAIL(MPS_EINPUT, "%s:%d: the top level must be a mapping of keys", file,
                         line);
                break;
            }
            if (!top->seq && top->want_key) {
                if (path_child(r, top, s, sn))
                    NOMEM();
                for (int i = 0; i < r->nseen; i++)
                    if (strcmp(r->seen[i].path, r->path.s) == 0)
                        FAIL(MPS_EINPUT, "%s:%d: duplicate key '%s' (first given at line %d)",
                             file, line, r->path.s, r->seen[i].line);
                if (r->nseen >= CASE_MAX_KEYS)
                    FAIL(MPS_EINPUT, "%s:%d: more than %d keys: not a case file", file, line,
                         CASE_MAX_KEYS);
                if (r->nseen == r->capseen) {
                    int cap = r->capseen ? 2 * r->capseen : 64;
                    struct seen *sv = realloc(r->seen, (size_t)cap * sizeof *sv);
                    if (!sv)
                        NOMEM();
                    r->seen = sv;
                    r->capseen = cap;
                }
                if (!(r->seen[r->nseen].path = strdup(r->path.s)))
                    NOMEM();
                r->seen[r->nseen++].line = line;
                top->want_key = 0;
                break;
            }
            if (top->seq && path_index(r, top))
                NOMEM();
            const char *key = r->path.s;
            if (!case_key_shape_ok(key))
                FAIL(MPS_EINPUT, "%s:%d: '%s': empty key name", file, line, key);
            if (case_find_entry(c, key))
                FAIL(MPS_EINPUT, "%s:%d: duplicate key '%s'", file, line, key);
            const struct entry *o = case_find_conflict(c, key);
            if (o)
                FAIL(MPS_EINPUT, "%s:%d: %s = %s: conflicts with %s (%s); a key cannot be both "
                     "a value and a section", file, line, key, case_shown(s), o->key, o->where);
            if (c->n >= CASE_MAX_KEYS)
                FAIL(MPS_EINPUT, "%s:%d: more than %d keys: not a case file", file, line,
                     CASE_MAX_KEYS);
            if (case_add_entry(c, key, s, sn, case_xprintf("%s:%d", file, line)))
                NOMEM();
            next_item(r, top);
            break;
        }
        default:
            break;
        }
    out:
        yaml_event_delete(&ev);
        if (st != MPS_OK)
            return st;
    }
    return MPS_OK;
#undef NOMEM
#undef FAIL
}

/* The whole file, read at most CASE_MAX_BYTES + 1 bytes (a pipe or a device
 * works too, and never runs on). *len = bytes read. */
static enum mps_status slurp(const char *path, unsigned char **out, size_t *len,
                             struct mps_err *err)
{
    *out = NULL;
    *len = 0;
    FILE *f = fopen(path, "rb");
    if (!f)
        return mps_err_set(err, MPS_EIO, "%s: cannot open: %s", path, strerror(errno));
    struct stat sb;
    if (fstat(fileno(f), &sb) == 0 && S_ISDIR(sb.st_mode)) {
        fclose(f);
        return mps_err_set(err, MPS_EIO, "%s: cannot read: it is a directory, not a case file",
                           path);
    }
    /* grown as it fills: a case is a few kB, the cap is far above */
    size_t n = 0, cap = 0;
    unsigned char *buf = NULL;
    int bad = 0, e = 0;
    for (;;) {
        if (n == cap) {
            size_t ncap = cap ? 2 * cap : 16384;
            if (ncap > (size_t)CASE_MAX_BYTES + 1)
                ncap = (size_t)CASE_MAX_BYTES + 1;
            if (ncap == cap)
                break; /* the cap is full: too large */
            unsigned char *nb = realloc(buf, ncap);
            if (!nb) {
                free(buf);
                fclose(f);
                return mps_err_set(err, MPS_ENOMEM, "%s: out of memory", path);
            }
            buf = nb;
            cap = ncap;
        }
        size_t got = fread(buf + n, 1, cap - n, f);
        n += got;
        if (got == 0) {
            bad = ferror(f);
            e = errno;
            break;
        }
    }
    fclose(f);
    if (bad) {
        free(buf);
        return mps_err_set(err, MPS_EIO, "%s: cannot read: %s", path, strerror(e));
    }
    if (n > (size_t)CASE_MAX_BYTES) {
        free(buf);
        return mps_err_set(err, MPS_EINPUT, "%s: over %ld bytes: not a case file (ours are a "
                           "few kB)", path, CASE_MAX_BYTES);
    }
    *out = buf;
    *len = n;
    return MPS_OK;
}

enum mps_status case_read_file(struct mps_case *c, struct mps_err *err)
{
    unsigned char *text;
    size_t len;
    enum mps_status st = slurp(c->path, &text, &len, err);
    if (st)
        return st;
    yaml_parser_t p;
    if (!yaml_parser_initialize(&p)) {
        free(text);
        return mps_err_set(err, MPS_ENOMEM, "%s: cannot start the YAML parser", c->path);
    }
    yaml_parser_set_input_string(&p, text, len);
    struct reader r = {.c = c};
    st = read_yaml(&r, &p, err);
    if (st == MPS_OK && c->n == 0)
        st = mps_err_set(err, MPS_EINPUT, "%s: no keys: the case file is empty (a case needs "
                         "at least dp and end_time)", c->path);
    yaml_parser_delete(&p);
    free(text);
    free(r.path.s);
    free(r.st);
    for (int i = 0; i < r.nseen; i++)
        free(r.seen[i].path);
    free(r.seen);
    return st;
}
