/* Case files: YAML -> flat table of dotted keys -> validated against specs.
 * See mps_case.h for the contract. Storage is a plain array with linear
 * lookup: case files have a few hundred keys at most and are read once. */
/* realpath() is XSI */
#define _XOPEN_SOURCE 700
#include "mps_case.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include <yaml.h>

#define KEY_MAX 512        /* longest key a getter formats */
/* Bounds that keep a hostile or mistaken file from costing more than a real
 * case ever needs (ours are a few kB and under 300 keys; lookups are linear,
 * so the key count bounds the quadratic work of loading). */
#define CASE_MAX_BYTES (1L << 20)
#define CASE_MAX_KEYS 10000
#define CASE_MAX_DEPTH 32
#define INDEX_MAX_DIGITS 9 /* a sequence index fits an int */

struct value {
    double d;
    long i;
    int b;
};

struct entry {
    char *key;   /* "fluid.blocks.0.x0" */
    char *val;   /* the scalar as text */
    char *where; /* "case.yml:14", "--set dp=1", "default" */
    const struct mps_key_spec *spec; /* into mps_case.specs; NULL: ignored key */
    struct value v;                  /* parsed value when spec != NULL */
};

struct mps_case {
    char *path, *dir;
    struct entry *e;
    int n, cap;
    /* Copies of the spec tables and ignore prefixes (strings in pool), so the
     * caller's tables need not outlive the case. */
    struct mps_key_spec *specs;
    int nspecs;
    const char **ignore;
    int nignore;
    char *pool;
};

/* ---- small string helpers ---- */

struct sbuf {
    char *s;
    size_t n, cap;
};

static int sb_add(struct sbuf *b, const void *p, size_t n)
{
    if (b->n + n + 1 > b->cap) {
        size_t cap = b->cap ? b->cap : 256;
        while (cap < b->n + n + 1)
            cap *= 2;
        char *s = realloc(b->s, cap);
        if (!s)
            return -1;
        b->s = s;
        b->cap = cap;
    }
    memcpy(b->s + b->n, p, n);
    b->n += n;
    b->s[b->n] = '\0';
    return 0;
}

static void sb_cut(struct sbuf *b, size_t n)
{
    b->n = n;
    if (b->s)
        b->s[n] = '\0';
}

static char *xprintf(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static char *xprintf(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    char *s = n >= 0 ? malloc((size_t)n + 1) : NULL;
    if (s) {
        va_start(ap, fmt);
        vsnprintf(s, (size_t)n + 1, fmt, ap);
        va_end(ap);
    }
    return s;
}

/* A sequence index component: digits, no leading zero, fits an int. */
static int is_index(const char *s, size_t n)
{
    if (n == 0 || n > INDEX_MAX_DIGITS || (n > 1 && s[0] == '0'))
        return 0;
    for (size_t i = 0; i < n; i++)
        if (s[i] < '0' || s[i] > '9')
            return 0;
    return 1;
}

/* Spec name pat ("fluid.blocks.*.x0") against key ("fluid.blocks.3.x0"). */
static int name_matches(const char *pat, const char *key)
{
    for (;;) {
        size_t pn = strcspn(pat, "."), kn = strcspn(key, ".");
        if (pn == 1 && pat[0] == '*') {
            if (!is_index(key, kn))
                return 0;
        } else if (pn != kn || memcmp(pat, key, pn) != 0) {
            return 0;
        }
        pat += pn;
        key += kn;
        if (!*pat || !*key)
            return !*pat && !*key;
        pat++;
        key++;
    }
}

/* No empty components: rejects "", ".a", "a.", "a..b". */
static int key_shape_ok(const char *key)
{
    size_t n = strlen(key);
    return n > 0 && key[0] != '.' && key[n - 1] != '.' && !strstr(key, "..");
}

/* ---- lookup ---- */

static struct entry *find_entry(const struct mps_case *c, const char *key)
{
    for (int i = 0; i < c->n; i++)
        if (strcmp(c->e[i].key, key) == 0)
            return &c->e[i];
    return NULL;
}

static const struct mps_key_spec *find_spec(const struct mps_case *c, const char *key)
{
    for (int i = 0; i < c->nspecs; i++)
        if (name_matches(c->specs[i].name, key))
            return &c->specs[i];
    return NULL;
}

static int is_ignored(const struct mps_case *c, const char *key)
{
    for (int i = 0; i < c->nignore; i++)
        if (strncmp(key, c->ignore[i], strlen(c->ignore[i])) == 0)
            return 1;
    return 0;
}

/* An existing key that cannot coexist with key: one is a section of the other
 * ("gravity" and "gravity.x"). */
static const struct entry *find_conflict(const struct mps_case *c, const char *key)
{
    size_t kn = strlen(key);
    for (int i = 0; i < c->n; i++) {
        const char *o = c->e[i].key;
        size_t on = strlen(o);
        if ((on > kn && strncmp(o, key, kn) == 0 && o[kn] == '.') ||
            (kn > on && strncmp(key, o, on) == 0 && key[on] == '.'))
            return &c->e[i];
    }
    return NULL;
}

/* Takes ownership of where. */
static int add_entry(struct mps_case *c, const char *key, const char *val, size_t vlen,
                     char *where)
{
    if (!where)
        return -1;
    if (c->n == c->cap) {
        int cap = c->cap ? 2 * c->cap : 64;
        struct entry *e = realloc(c->e, (size_t)cap * sizeof *e);
        if (!e) {
            free(where);
            return -1;
        }
        c->e = e;
        c->cap = cap;
    }
    struct entry *e = &c->e[c->n];
    memset(e, 0, sizeof *e);
    e->key = strdup(key);
    e->val = malloc(vlen + 1);
    e->where = where;
    if (!e->key || !e->val) {
        free(e->key);
        free(e->val);
        free(where);
        return -1;
    }
    memcpy(e->val, val, vlen);
    e->val[vlen] = '\0';
    c->n++;
    return 0;
}

/* ---- error list: one line (house rule), the first problem in full and
 * how many more there are, with the next one ---- */

struct errs {
    struct mps_err *err;
    int n;
    char next[200]; /* the second problem */
};

static void add_err(struct errs *es, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void add_err(struct errs *es, const char *fmt, ...)
{
    char line[sizeof es->err->msg];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    if (es->n++ == 0)
        mps_err_set(es->err, MPS_EINPUT, "%s", line);
    else if (es->n == 2)
        snprintf(es->next, sizeof es->next, "%.*s", (int)sizeof es->next - 1, line);
}

/* An error is one line on a terminal: a key or value from the file with a
 * newline or another control byte in it (quoted YAML allows any) shows '?'
 * there instead. */
static void one_line(char *msg)
{
    for (unsigned char *p = (unsigned char *)msg; *p; p++)
        if (*p < 0x20 || *p == 0x7f)
            *p = '?';
}

/* Appends "(and N more problems; the next: ...)" to the first one. */
static void finish_errs(struct errs *es)
{
    if (es->n < 2 || !es->err)
        return;
    char *msg = es->err->msg;
    size_t used = strlen(msg);
    snprintf(msg + used, sizeof es->err->msg - used, " (and %d more problem%s; the next: %s)",
             es->n - 1, es->n > 2 ? "s" : "", es->next);
}

/* ---- values ---- */

static const char *shown(const char *v)
{
    return *v ? v : "(empty)";
}

static void bounds_text(const struct mps_key_spec *s, char *buf, size_t n)
{
    int lo = !(s->flags & MPS_KEY_NO_LO), hi = !(s->flags & MPS_KEY_NO_HI);
    int lo_open = !!(s->flags & MPS_KEY_LO_OPEN), hi_open = !!(s->flags & MPS_KEY_HI_OPEN);
    if (lo && hi)
        snprintf(buf, n, "must be in %c%g, %g%c", lo_open ? '(' : '[', s->lo, s->hi,
                 hi_open ? ')' : ']');
    else if (lo)
        snprintf(buf, n, "must be %s %g", lo_open ? ">" : ">=", s->lo);
    else if (hi)
        snprintf(buf, n, "must be %s %g", hi_open ? "<" : "<=", s->hi);
    else
        snprintf(buf, n, "out of range");
}

static int in_bounds(const struct mps_key_spec *s, double x)
{
    if (!(s->flags & MPS_KEY_NO_LO) && ((s->flags & MPS_KEY_LO_OPEN) ? !(x > s->lo) : !(x >= s->lo)))
        return 0;
    if (!(s->flags & MPS_KEY_NO_HI) && ((s->flags & MPS_KEY_HI_OPEN) ? !(x < s->hi) : !(x <= s->hi)))
        return 0;
    return 1;
}

/* Parses text as the spec's type and checks its bounds. Returns 0, or -1 with
 * the problem ("must be > 0") in prob. */
static int check_value(const struct mps_key_spec *s, const char *text, struct value *v,
                       char *prob, size_t np)
{
    char *end;
    memset(v, 0, sizeof *v);
    switch (s->type) {
    case MPS_KEY_DOUBLE:
        errno = 0;
        v->d = strtod(text, &end);
        if (end == text || *end) {
            snprintf(prob, np, "must be a number");
            return -1;
        }
        if (!isfinite(v->d)) {
            snprintf(prob, np, "must be a finite number");
            return -1;
        }
        if (!in_bounds(s, v->d)) {
            bounds_text(s, prob, np);
            return -1;
        }
        return 0;
    case MPS_KEY_INT:
        errno = 0;
        v->i = strtol(text, &end, 10);
        if (end == text || *end) {
            snprintf(prob, np, "must be an integer");
            return -1;
        }
        if (errno == ERANGE) {
            snprintf(prob, np, "integer too large");
            return -1;
        }
        v->d = (double)v->i;
        if (!in_bounds(s, v->d)) {
            bounds_text(s, prob, np);
            return -1;
        }
        return 0;
    case MPS_KEY_BOOL: {
        static const char *const yes[] = {"true", "yes", "on", "1"};
        static const char *const no[] = {"false", "no", "off", "0"};
        for (int k = 0; k < 4; k++) {
            if (strcasecmp(text, yes[k]) == 0) {
                v->b = 1;
                return 0;
            }
            if (strcasecmp(text, no[k]) == 0) {
                v->b = 0;
                return 0;
            }
        }
        snprintf(prob, np, "must be true or false (or yes/no, on/off, 1/0)");
        return -1;
    }
    case MPS_KEY_STRING:
        return 0;
    case MPS_KEY_ENUM: {
        const char *p = s->choices ? s->choices : "";
        size_t tn = strlen(text);
        for (;;) {
            size_t cn = strcspn(p, "|");
            if (cn == tn && memcmp(p, text, tn) == 0)
                return 0;
            if (!p[cn])
                break;
            p += cn + 1;
        }
        size_t k = (size_t)snprintf(prob, np, "must be one of ");
        for (p = s->choices ? s->choices : ""; *p && k + 3 < np; p++) {
            if (*p == '|') {
                prob[k++] = ',';
                prob[k++] = ' ';
            } else {
                prob[k++] = *p;
            }
        }
        prob[k < np ? k : np - 1] = '\0';
        return -1;
    }
    }
    snprintf(prob, np, "unknown key type");
    return -1;
}

/* ---- "did you mean": optimal string alignment distance over spec names ---- */

static int edit_distance(const char *a, const char *b)
{
    enum { N = 128 };
    size_t m = strlen(a), n = strlen(b);
    if (m >= N || n >= N)
        return 1 << 20;
    int d[3][N]; /* rows i-2, i-1, i (mod 3) */
    for (size_t j = 0; j <= n; j++)
        d[0][j] = (int)j;
    for (size_t i = 1; i <= m; i++) {
        int *cur = d[i % 3], *p1 = d[(i - 1) % 3], *p2 = d[(i + 1) % 3];
        cur[0] = (int)i;
        for (size_t j = 1; j <= n; j++) {
            int cost = a[i - 1] != b[j - 1];
            int x = p1[j] + 1, y = cur[j - 1] + 1, z = p1[j - 1] + cost;
            int best = x < y ? x : y;
            best = best < z ? best : z;
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] &&
                p2[j - 2] + 1 < best)
                best = p2[j - 2] + 1;
            cur[j] = best;
        }
    }
    return d[m % 3][n];
}

/* Writes "; did you mean fluid.blocks.0.x0?" (with key's own indices) or "". */
static void suggest(const struct mps_case *c, const char *key, char *out, size_t n)
{
    char wild[KEY_MAX], idx[KEY_MAX];
    size_t w = 0, ni = 0;
    out[0] = '\0';
    /* wild: key with indices replaced by "*"; idx: the indices, '.'-separated */
    for (const char *p = key; *p;) {
        size_t cn = strcspn(p, ".");
        int isx = is_index(p, cn);
        const char *src = isx ? "*" : p;
        size_t sn = isx ? 1 : cn;
        if (w + sn + 2 >= sizeof wild || ni + cn + 2 >= sizeof idx)
            return;
        memcpy(wild + w, src, sn);
        w += sn;
        if (isx) {
            memcpy(idx + ni, p, cn);
            ni += cn;
            idx[ni++] = '.';
        }
        p += cn;
        if (*p) {
            wild[w++] = '.';
            p++;
        }
    }
    wild[w] = '\0';
    idx[ni] = '\0';

    const char *best = NULL;
    int bd = 0;
    int wl = (int)strlen(wild);
    for (int i = 0; i < c->nspecs; i++) {
        /* the distance is at least the difference in length: a name too
         * long or too short to be accepted below is not worth aligning */
        int sl = (int)strlen(c->specs[i].name), room = sl / 4 > 1 ? sl / 4 : 1;
        if (wl - sl > room || sl - wl > room)
            continue;
        int d = edit_distance(wild, c->specs[i].name);
        if (!best || d < bd) {
            best = c->specs[i].name;
            bd = d;
        }
    }
    /* Near enough: a typo or two, more for long names. */
    int limit = best ? (int)strlen(best) / 4 : 0;
    if (!best || bd > (limit > 1 ? limit : 1))
        return;

    /* Show the spec back with the key's indices in place of its "*"s. */
    char shown_name[KEY_MAX];
    size_t k = 0;
    const char *ip = idx;
    for (const char *p = best; *p && k + 12 < sizeof shown_name;) {
        size_t cn = strcspn(p, ".");
        if (cn == 1 && *p == '*' && *ip) {
            size_t in = strcspn(ip, ".");
            memcpy(shown_name + k, ip, in);
            k += in;
            ip += in + 1;
        } else {
            size_t take = cn < sizeof shown_name - k - 12 ? cn : sizeof shown_name - k - 12;
            memcpy(shown_name + k, p, take);
            k += take;
        }
        p += cn;
        if (*p) {
            shown_name[k++] = '.';
            p++;
        }
    }
    shown_name[k] = '\0';
    snprintf(out, n, "; did you mean %s?", shown_name);
}

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
    sb_cut(&r->path, f->base);
    if (f->base > 0 && sb_add(&r->path, ".", 1))
        return -1;
    return sb_add(&r->path, s, n);
}

static int path_index(struct reader *r, const struct frame *f)
{
    char num[32];
    int n = snprintf(num, sizeof num, "%ld", f->idx);
    return path_child(r, f, num, (size_t)n);
}

/* Reader errors are fatal: returns the status after setting err. */
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
            if (r->depth) {
                top = &r->st[r->depth - 1];
                sb_cut(&r->path, top->base);
                if (top->seq)
                    top->idx++;
                else
                    top->want_key = 1;
            }
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
            if (!key_shape_ok(key))
                FAIL(MPS_EINPUT, "%s:%d: '%s': empty key name", file, line, key);
            if (find_entry(c, key))
                FAIL(MPS_EINPUT, "%s:%d: duplicate key '%s'", file, line, key);
            const struct entry *o = find_conflict(c, key);
            if (o)
                FAIL(MPS_EINPUT, "%s:%d: %s = %s: conflicts with %s (%s); a key cannot be both "
                     "a value and a section", file, line, key, shown(s), o->key, o->where);
            if (c->n >= CASE_MAX_KEYS)
                FAIL(MPS_EINPUT, "%s:%d: more than %d keys: not a case file", file, line,
                     CASE_MAX_KEYS);
            if (add_entry(c, key, s, sn, xprintf("%s:%d", file, line)))
                NOMEM();
            sb_cut(&r->path, top->base);
            if (top->seq)
                top->idx++;
            else
                top->want_key = 1;
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

static enum mps_status read_file(struct mps_case *c, struct mps_err *err)
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

/* ---- --set ---- */

static void trim(const char **s, size_t *n)
{
    while (*n && (**s == ' ' || **s == '\t')) {
        (*s)++;
        (*n)--;
    }
    while (*n && ((*s)[*n - 1] == ' ' || (*s)[*n - 1] == '\t'))
        (*n)--;
}

static enum mps_status apply_set(struct mps_case *c, const char *set, struct errs *es)
{
    const char *eq = strchr(set, '=');
    if (!eq) {
        add_err(es, "--set %s: expected key=value", set);
        return MPS_EINPUT;
    }
    const char *k = set, *v = eq + 1;
    size_t kn = (size_t)(eq - set), vn = strlen(v);
    trim(&k, &kn);
    trim(&v, &vn);
    /* A value may be quoted as in YAML; no escapes are interpreted. */
    if (vn >= 2 && (v[0] == '"' || v[0] == '\'') && v[vn - 1] == v[0]) {
        v++;
        vn -= 2;
    }
    char key[KEY_MAX];
    if (kn >= sizeof key) {
        add_err(es, "--set %s: key too long", set);
        return MPS_EINPUT;
    }
    memcpy(key, k, kn);
    key[kn] = '\0';
    if (!key_shape_ok(key)) {
        add_err(es, "--set %s: '%s' is not a key name", set, key);
        return MPS_EINPUT;
    }
    char *where = xprintf("--set %s", set);
    if (!where)
        return mps_err_set(es->err, MPS_ENOMEM, "--set %s: out of memory", set);
    struct entry *e = find_entry(c, key);
    if (e) {
        char *val = strndup(v, vn);
        if (!val) {
            free(where);
            return mps_err_set(es->err, MPS_ENOMEM, "--set %s: out of memory", set);
        }
        free(e->val);
        free(e->where);
        e->val = val;
        e->where = where;
        return MPS_OK;
    }
    const struct entry *o = find_conflict(c, key);
    if (o) {
        add_err(es, "%s: %s = %.*s: conflicts with %s (%s); a key cannot be both a value and "
                "a section", where, key, (int)vn, v, o->key, o->where);
        free(where);
        return MPS_EINPUT;
    }
    if (add_entry(c, key, v, vn, where))
        return mps_err_set(es->err, MPS_ENOMEM, "--set %s: out of memory", set);
    return MPS_OK;
}

/* ---- specs: copy, expand "*" over existing items ---- */

static char *pool_put(char **p, const char *s)
{
    if (!s)
        return NULL;
    size_t n = strlen(s) + 1;
    char *d = memcpy(*p, s, n);
    *p += n;
    return d;
}

static int copy_specs(struct mps_case *c, const struct mps_key_spec *const *tables, int ntables,
                      const char *const *ignore)
{
    size_t bytes = 1;
    int ns = 0, ni = 0;
    for (int t = 0; t < ntables; t++)
        for (const struct mps_key_spec *s = tables[t]; s && s->name; s++, ns++) {
            const char *str[] = {s->name, s->def, s->choices, s->units, s->help};
            for (int k = 0; k < 5; k++)
                bytes += str[k] ? strlen(str[k]) + 1 : 0;
        }
    for (; ignore && ignore[ni]; ni++)
        bytes += strlen(ignore[ni]) + 1;
    c->specs = calloc((size_t)ns + 1, sizeof *c->specs);
    c->ignore = calloc((size_t)ni + 1, sizeof *c->ignore);
    c->pool = malloc(bytes);
    if (!c->specs || !c->ignore || !c->pool)
        return -1;
    char *p = c->pool;
    for (int t = 0; t < ntables; t++)
        for (const struct mps_key_spec *s = tables[t]; s && s->name; s++) {
            struct mps_key_spec *d = &c->specs[c->nspecs++];
            *d = *s;
            d->name = pool_put(&p, s->name);
            d->def = pool_put(&p, s->def);
            d->choices = pool_put(&p, s->choices);
            d->units = pool_put(&p, s->units);
            d->help = pool_put(&p, s->help);
        }
    for (int i = 0; i < ni; i++)
        c->ignore[c->nignore++] = pool_put(&p, ignore[i]);
    return 0;
}

typedef int (*key_fn)(struct mps_case *c, const struct mps_key_spec *s, const char *key,
                      struct errs *es);

static int cmp_long(const void *a, const void *b)
{
    long x = *(const long *)a, y = *(const long *)b;
    return (x > y) - (x < y);
}

/* Calls fn for every concrete key of pattern pat: each "*" takes the indices
 * of the items that exist (have any key) at that place. */
static int expand(struct mps_case *c, const struct mps_key_spec *s, const char *pat, key_fn fn,
                  struct errs *es)
{
    const char *star = NULL;
    for (const char *p = pat; *p;) {
        size_t cn = strcspn(p, ".");
        if (cn == 1 && *p == '*') {
            star = p;
            break;
        }
        p += cn + (p[cn] == '.');
    }
    if (!star)
        return fn(c, s, pat, es);

    size_t plen = (size_t)(star - pat); /* prefix incl. its trailing '.' */
    long *idx = malloc(((size_t)c->n + 1) * sizeof *idx);
    if (!idx)
        return -1;
    int ni = 0;
    for (int i = 0; i < c->n; i++) {
        const char *k = c->e[i].key;
        if (strncmp(k, pat, plen) != 0)
            continue;
        size_t qn = strcspn(k + plen, ".");
        if (is_index(k + plen, qn))
            idx[ni++] = strtol(k + plen, NULL, 10);
    }
    qsort(idx, (size_t)ni, sizeof *idx, cmp_long);
    int rc = 0;
    for (int i = 0; i < ni && !rc; i++) {
        if (i > 0 && idx[i] == idx[i - 1])
            continue;
        char *sub = xprintf("%.*s%ld%s", (int)plen, pat, idx[i], star + 1);
        rc = sub ? expand(c, s, sub, fn, es) : -1;
        free(sub);
    }
    free(idx);
    return rc;
}

static int check_required(struct mps_case *c, const struct mps_key_spec *s, const char *key,
                          struct errs *es)
{
    if (find_entry(c, key))
        return 0;
    const char *help = s->help ? s->help : "", *units = s->units ? s->units : "";
    if (*help && *units)
        add_err(es, "%s: missing required key '%s' (%s, %s)", c->path, key, help, units);
    else if (*help || *units)
        add_err(es, "%s: missing required key '%s' (%s)", c->path, key, *help ? help : units);
    else
        add_err(es, "%s: missing required key '%s'", c->path, key);
    return 0;
}

static int fill_default(struct mps_case *c, const struct mps_key_spec *s, const char *key,
                        struct errs *es)
{
    if (find_entry(c, key))
        return 0;
    char prob[256];
    if (add_entry(c, key, s->def, strlen(s->def), strdup("default")))
        return -1;
    struct entry *e = &c->e[c->n - 1];
    e->spec = s;
    check_value(s, s->def, &e->v, prob, sizeof prob); /* checked in validate() */
    return 0;
}

/* ---- load ---- */

static void validate(struct mps_case *c, struct errs *es)
{
    char prob[256];
    struct value v;
    for (int i = 0; i < c->nspecs; i++) { /* programmer errors, reported like input */
        const struct mps_key_spec *s = &c->specs[i];
        if (s->def && check_value(s, s->def, &v, prob, sizeof prob))
            add_err(es, "default: %s = %s: %s", s->name, shown(s->def), prob);
    }
    for (int i = 0; i < c->n; i++) {
        struct entry *e = &c->e[i];
        /* A declared key is validated even under an ignored prefix. */
        e->spec = find_spec(c, e->key);
        if (!e->spec) {
            if (is_ignored(c, e->key))
                continue;
            char hint[KEY_MAX + 32] = "";
            if (es->n < 2) /* only the first two problems are shown */
                suggest(c, e->key, hint, sizeof hint);
            add_err(es, "%s: %s = %s: unknown key%s", e->where, e->key, shown(e->val), hint);
        } else if (check_value(e->spec, e->val, &e->v, prob, sizeof prob)) {
            add_err(es, "%s: %s = %s: %s", e->where, e->key, shown(e->val), prob);
        }
    }
}

enum mps_status mps_case_load(struct mps_case **out, const char *path,
                              const char *const *sets, int nsets,
                              const struct mps_key_spec *const *spec_tables, int ntables,
                              const char *const *ignore_prefixes, struct mps_err *err)
{
    *out = NULL;
    struct mps_case *c = calloc(1, sizeof *c);
    if (!c)
        return mps_err_set(err, MPS_ENOMEM, "%s: out of memory", path);
    const char *slash = strrchr(path, '/');
    c->path = strdup(path);
    c->dir = !slash ? strdup(".") : slash == path ? strdup("/")
                                                  : strndup(path, (size_t)(slash - path));
    if (!c->path || !c->dir || copy_specs(c, spec_tables, ntables, ignore_prefixes)) {
        mps_case_destroy(&c);
        return mps_err_set(err, MPS_ENOMEM, "%s: out of memory", path);
    }

    enum mps_status st = read_file(c, err);
    struct errs es = {err, 0, ""};
    for (int i = 0; i < nsets && st == MPS_OK; i++)
        if (apply_set(c, sets[i], &es) == MPS_ENOMEM)
            st = MPS_ENOMEM;
    if (st == MPS_OK) {
        validate(c, &es);
        for (int i = 0; i < c->nspecs && st == MPS_OK; i++)
            if ((c->specs[i].flags & MPS_KEY_REQUIRED) &&
                expand(c, &c->specs[i], c->specs[i].name, check_required, &es))
                st = MPS_ENOMEM;
        if (es.n == 0)
            for (int i = 0; i < c->nspecs && st == MPS_OK; i++)
                if (c->specs[i].def &&
                    expand(c, &c->specs[i], c->specs[i].name, fill_default, &es))
                    st = MPS_ENOMEM;
        if (st == MPS_ENOMEM)
            mps_err_set(err, st, "%s: out of memory", path);
    }
    if (st == MPS_OK && es.n > 0) {
        st = MPS_EINPUT;
        finish_errs(&es);
    }
    if (st != MPS_OK && err)
        one_line(err->msg);
    if (st != MPS_OK) {
        mps_case_destroy(&c);
        return st;
    }
    *out = c;
    return MPS_OK;
}

void mps_case_destroy(struct mps_case **cp)
{
    if (!cp || !*cp)
        return;
    struct mps_case *c = *cp;
    for (int i = 0; i < c->n; i++) {
        free(c->e[i].key);
        free(c->e[i].val);
        free(c->e[i].where);
    }
    free(c->e);
    free(c->specs);
    free(c->ignore);
    free(c->pool);
    free(c->path);
    free(c->dir);
    free(c);
    *cp = NULL;
}

/* ---- getters ---- */

static const char *type_name(enum mps_key_type t)
{
    switch (t) {
    case MPS_KEY_DOUBLE: return "double";
    case MPS_KEY_INT: return "int";
    case MPS_KEY_BOOL: return "bool";
    case MPS_KEY_STRING: return "string";
    case MPS_KEY_ENUM: return "enum";
    }
    return "?";
}

static void format_key(char *key, const char *fn, const char *fmt, va_list ap)
{
    int n = vsnprintf(key, KEY_MAX, fmt, ap);
    if (n < 0 || n >= KEY_MAX) {
        fprintf(stderr, "%s: key '%s...' is too long\n", fn, key);
        abort();
    }
}

/* The value of key for a getter that accepts the types in mask (bits
 * 1 << type); aborts on programmer errors. Returns the text, fills v. */
static const char *get(const struct mps_case *c, const char *fn, const char *key, unsigned mask,
                       struct value *v)
{
    const struct mps_key_spec *s = find_spec(c, key);
    if (!s) {
        fprintf(stderr, "%s: key '%s' is not declared in any spec table\n", fn, key);
        abort();
    }
    if (!(mask & (1u << s->type))) {
        fprintf(stderr, "%s: key '%s' is declared as %s\n", fn, key, type_name(s->type));
        abort();
    }
    const struct entry *e = find_entry(c, key);
    if (e) {
        *v = e->v;
        return e->val;
    }
    if (!s->def) {
        fprintf(stderr, "%s: key '%s' is absent and has no default (check mps_case_has)\n", fn,
                key);
        abort();
    }
    char prob[256];
    check_value(s, s->def, v, prob, sizeof prob); /* validated at load */
    return s->def;
}

#define FORMAT_KEY(fn)                  \
    char key[KEY_MAX];                  \
    va_list ap;                         \
    va_start(ap, fmt);                  \
    format_key(key, fn, fmt, ap);       \
    va_end(ap)

double mps_case_double(const struct mps_case *c, const char *fmt, ...)
{
    FORMAT_KEY("mps_case_double");
    struct value v;
    get(c, "mps_case_double", key, 1u << MPS_KEY_DOUBLE | 1u << MPS_KEY_INT, &v);
    return v.d;
}

long mps_case_int(const struct mps_case *c, const char *fmt, ...)
{
    FORMAT_KEY("mps_case_int");
    struct value v;
    get(c, "mps_case_int", key, 1u << MPS_KEY_INT, &v);
    return v.i;
}

int mps_case_bool(const struct mps_case *c, const char *fmt, ...)
{
    FORMAT_KEY("mps_case_bool");
    struct value v;
    get(c, "mps_case_bool", key, 1u << MPS_KEY_BOOL, &v);
    return v.b;
}

const char *mps_case_string(const struct mps_case *c, const char *fmt, ...)
{
    FORMAT_KEY("mps_case_string");
    struct value v;
    return get(c, "mps_case_string", key, 1u << MPS_KEY_STRING | 1u << MPS_KEY_ENUM, &v);
}

int mps_case_has(const struct mps_case *c, const char *fmt, ...)
{
    FORMAT_KEY("mps_case_has");
    if (find_entry(c, key))
        return 1;
    const struct mps_key_spec *s = find_spec(c, key);
    if (s)
        return s->def != NULL;
    if (is_ignored(c, key))
        return 0;
    /* A typo here would silently read as "absent". */
    fprintf(stderr, "mps_case_has: key '%s' is neither declared nor under an ignored prefix\n",
            key);
    abort();
}

const char *mps_case_text(const struct mps_case *c, const char *fmt, ...)
{
    FORMAT_KEY("mps_case_text");
    const struct entry *e = find_entry(c, key);
    return e ? e->val : NULL;
}

int mps_case_count(const struct mps_case *c, const char *fmt, ...)
{
    FORMAT_KEY("mps_case_count");
    size_t pn = strlen(key);
    long max = -1;
    for (int i = 0; i < c->n; i++) {
        const char *k = c->e[i].key;
        if (strncmp(k, key, pn) != 0 || k[pn] != '.')
            continue;
        size_t qn = strcspn(k + pn + 1, ".");
        if (is_index(k + pn + 1, qn)) {
            long x = strtol(k + pn + 1, NULL, 10);
            if (x > max)
                max = x;
        }
    }
    return (int)(max + 1);
}

/* For a section ("solid.bodies"), its first key in the file. */
static const struct entry *find_section(const struct mps_case *c, const char *key)
{
    size_t kn = strlen(key);
    for (int i = 0; i < c->n; i++)
        if (strncmp(c->e[i].key, key, kn) == 0 && c->e[i].key[kn] == '.')
            return &c->e[i];
    return NULL;
}

const char *mps_case_where(const struct mps_case *c, const char *key)
{
    const struct entry *e = find_entry(c, key);
    if (e)
        return e->where;
    const struct mps_key_spec *s = find_spec(c, key);
    if (s && s->def)
        return "default";
    e = find_section(c, key);
    return e ? e->where : c->path;
}

enum mps_status mps_case_fail(const struct mps_case *c, struct mps_err *err, const char *key,
                              const char *fmt, ...)
{
    char prob[sizeof err->msg];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(prob, sizeof prob, fmt, ap);
    va_end(ap);
    const struct entry *e = find_entry(c, key);
    const struct mps_key_spec *s = e ? NULL : find_spec(c, key);
    if (e)
        mps_err_set(err, MPS_EINPUT, "%s: %s = %s: %s", e->where, key, shown(e->val), prob);
    else if (s && s->def)
        mps_err_set(err, MPS_EINPUT, "default: %s = %s: %s", key, shown(s->def), prob);
    else
        mps_err_set(err, MPS_EINPUT, "%s: %s: %s", mps_case_where(c, key), key, prob);
    if (err)
        one_line(err->msg);
    return MPS_EINPUT;
}

const char *mps_case_path(const struct mps_case *c)
{
    return c->path;
}

const char *mps_case_dir(const struct mps_case *c)
{
    return c->dir;
}

/* ---- resolved YAML: sort the flat keys and nest them again ---- */

/* Component by component; indices compare as numbers so items stay in order. */
static int cmp_keys(const void *pa, const void *pb)
{
    const char *x = (*(const struct entry *const *)pa)->key;
    const char *y = (*(const struct entry *const *)pb)->key;
    for (;;) {
        size_t xn = strcspn(x, "."), yn = strcspn(y, ".");
        int r;
        if (is_index(x, xn) && is_index(y, yn) && xn != yn) {
            r = xn < yn ? -1 : 1;
        } else {
            r = memcmp(x, y, xn < yn ? xn : yn);
            if (!r)
                r = (xn > yn) - (xn < yn);
        }
        if (r)
            return r;
        x += xn;
        y += yn;
        if (!*x || !*y)
            return (*x != 0) - (*y != 0);
        x++;
        y++;
    }
}

static int emit_scalar(yaml_emitter_t *em, const char *s, size_t n)
{
    yaml_event_t ev;
    return yaml_scalar_event_initialize(&ev, NULL, NULL, (yaml_char_t *)s, (int)n, 1, 1,
                                        YAML_ANY_SCALAR_STYLE) &&
           yaml_emitter_emit(em, &ev);
}

static int emit_container(yaml_emitter_t *em, int seq, int start, int flow)
{
    yaml_event_t ev;
    int ok;
    if (seq)
        ok = start ? yaml_sequence_start_event_initialize(&ev, NULL, NULL, 1,
                                                          YAML_BLOCK_SEQUENCE_STYLE)
                   : yaml_sequence_end_event_initialize(&ev);
    else
        ok = start ? yaml_mapping_start_event_initialize(
                         &ev, NULL, NULL, 1,
                         flow ? YAML_FLOW_MAPPING_STYLE : YAML_BLOCK_MAPPING_STYLE)
                   : yaml_mapping_end_event_initialize(&ev);
    return ok && yaml_emitter_emit(em, &ev);
}

/* Emits the node at path v[0]->key[0..plen) holding entries v[0..n). */
static int emit_node(yaml_emitter_t *em, struct entry **v, int n, size_t plen, int root)
{
    if (!root && n == 1 && strlen(v[0]->key) == plen)
        return emit_scalar(em, v[0]->val, strlen(v[0]->val));
    size_t off = root ? 0 : plen + 1;
    int seq = !root; /* the root is always a mapping */
    for (int i = 0; i < n && seq; i++)
        seq = is_index(v[i]->key + off, strcspn(v[i]->key + off, "."));
    if (!emit_container(em, seq, 1, 0))
        return 0;
    long next = 0;
    for (int i = 0; i < n;) {
        const char *comp = v[i]->key + off;
        size_t cn = strcspn(comp, ".");
        int j = i + 1;
        while (j < n && strncmp(v[j]->key + off, comp, cn) == 0 &&
               (v[j]->key[off + cn] == '.' || v[j]->key[off + cn] == '\0'))
            j++;
        if (seq) {
            /* Missing items become {} so later items keep their index. */
            for (long k = strtol(comp, NULL, 10); next < k; next++)
                if (!emit_container(em, 0, 1, 1) || !emit_container(em, 0, 0, 1))
                    return 0;
            next++;
        } else if (!emit_scalar(em, comp, cn)) {
            return 0;
        }
        if (!emit_node(em, v + i, j - i, off + cn, 0))
            return 0;
        i = j;
    }
    return emit_container(em, seq, 0, 0);
}

static int write_sbuf(void *data, unsigned char *buf, size_t size)
{
    return sb_add(data, buf, size) == 0;
}

/* A relative path value (MPS_KEY_PATH) made absolute against the case's
 * directory, malloc'd; NULL when it needs no change or memory ran out. */
static char *absolute_path(const struct mps_case *c, const struct entry *e)
{
    if (!e->spec || !(e->spec->flags & MPS_KEY_PATH) || !e->val[0] || e->val[0] == '/')
        return NULL;
    char *dir = realpath(c->dir, NULL);
    char *abs = xprintf("%s/%s", dir ? dir : c->dir, e->val);
    free(dir);
    return abs;
}

char *mps_case_resolved_yaml(const struct mps_case *c)
{
    struct entry **v = malloc(((size_t)c->n + 1) * sizeof *v);
    /* copies of the entries, so path values can be made absolute: the
     * resolved file is read from elsewhere (the coupler's OUT) */
    struct entry *copy = malloc(((size_t)c->n + 1) * sizeof *copy);
    char **abs_val = calloc((size_t)c->n + 1, sizeof *abs_val);
    if (!v || !copy || !abs_val) {
        free(v);
        free(copy);
        free(abs_val);
        return NULL;
    }
    for (int i = 0; i < c->n; i++) {
        copy[i] = c->e[i];
        if ((abs_val[i] = absolute_path(c, &c->e[i])))
            copy[i].val = abs_val[i];
        v[i] = &copy[i];
    }
    qsort(v, (size_t)c->n, sizeof *v, cmp_keys);

    struct sbuf out = {0};
    yaml_emitter_t em;
    yaml_event_t ev;
    int ok = yaml_emitter_initialize(&em);
    if (ok) {
        yaml_emitter_set_output(&em, write_sbuf, &out);
        yaml_emitter_set_width(&em, -1); /* never fold long strings */
        yaml_emitter_set_unicode(&em, 1);
        ok = yaml_stream_start_event_initialize(&ev, YAML_UTF8_ENCODING) &&
             yaml_emitter_emit(&em, &ev) &&
             yaml_document_start_event_initialize(&ev, NULL, NULL, NULL, 1) &&
             yaml_emitter_emit(&em, &ev) && emit_node(&em, v, c->n, 0, 1) &&
             yaml_document_end_event_initialize(&ev, 1) && yaml_emitter_emit(&em, &ev) &&
             yaml_stream_end_event_initialize(&ev) && yaml_emitter_emit(&em, &ev) &&
             yaml_emitter_flush(&em);
        yaml_emitter_delete(&em);
    }
    for (int i = 0; i < c->n; i++)
        free(abs_val[i]);
    free(abs_val);
    free(copy);
    free(v);
    if (!ok || !out.s) {
        free(out.s);
        return NULL;
    }
    return out.s;
}

enum mps_status mps_case_write_resolved(const struct mps_case *c, const char *path,
                                        const char *comment, struct mps_err *err)
{
    char *y = mps_case_resolved_yaml(c);
    char *tmp = xprintf("%s.tmp", path);
    if (!y || !tmp) {
        free(y);
        free(tmp);
        return mps_err_set(err, MPS_ENOMEM, "%s: cannot build the resolved configuration",
                           path);
    }
    enum mps_status st = MPS_OK;
    FILE *f = fopen(tmp, "w");
    if (!f) {
        st = mps_err_set(err, MPS_EIO, "%s: cannot open for writing: %s", tmp, strerror(errno));
        goto done;
    }
    int bad = fprintf(f, "# Resolved from %s (defaults filled in, --set applied)\n%s%s", c->path,
                      comment ? comment : "", y) < 0;
    bad |= fclose(f) != 0;
    if (bad) {
        st = mps_err_set(err, MPS_EIO, "%s: cannot write: %s", tmp, strerror(errno));
        remove(tmp);
    } else if (rename(tmp, path) != 0) {
        st = mps_err_set(err, MPS_EIO, "cannot rename '%s' to '%s': %s", tmp, path,
                         strerror(errno));
        remove(tmp);
    }
done:
    free(tmp);
    free(y);
    return st;
}
