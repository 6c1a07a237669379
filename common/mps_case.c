/* Case files: the table of dotted keys, loading, the getters. See mps_case.h
 * for the contract, mps_case_priv.h for the modules. Storage is a plain
 * array with linear lookup: case files have a few hundred keys at most and
 * are read once. */
#include "mps_case_priv.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- small string helpers ---- */

int case_sb_add(struct sbuf *b, const void *p, size_t n)
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

void case_sb_cut(struct sbuf *b, size_t n)
{
    b->n = n;
    if (b->s)
        b->s[n] = '\0';
}

char *case_xprintf(const char *fmt, ...)
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
int case_is_index(const char *s, size_t n)
{
    if (n == 0 || n > INDEX_MAX_DIGITS || (n > 1 && s[0] == '0'))
        return 0;
    for (size_t i = 0; i < n; i++)
        if (s[i] < '0' || s[i] > '9')
            return 0;
    return 1;
}

/* Spec name pat ("fluid.blocks.*.x0") against key ("fluid.blocks.3.x0"). */
int case_name_matches(const char *pat, const char *key)
{
    for (;;) {
        size_t pn = strcspn(pat, "."), kn = strcspn(key, ".");
        if (pn == 1 && pat[0] == '*') {
            if (!case_is_index(key, kn))
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
int case_key_shape_ok(const char *key)
{
    size_t n = strlen(key);
    return n > 0 && key[0] != '.' && key[n - 1] != '.' && !strstr(key, "..");
}

/* ---- lookup ---- */

struct entry *case_find_entry(const struct mps_case *c, const char *key)
{
    for (int i = 0; i < c->n; i++)
        if (strcmp(c->e[i].key, key) == 0)
            return &c->e[i];
    return NULL;
}

const struct mps_key_spec *case_find_spec(const struct mps_case *c, const char *key)
{
    for (int i = 0; i < c->nspecs; i++)
        if (case_name_matches(c->specs[i].name, key))
            return &c->specs[i];
    return NULL;
}

int case_is_ignored(const struct mps_case *c, const char *key)
{
    for (int i = 0; i < c->nignore; i++)
        if (strncmp(key, c->ignore[i], strlen(c->ignore[i])) == 0)
            return 1;
    return 0;
}

/* An existing key that cannot coexist with key: one is a section of the other
 * ("gravity" and "gravity.x"). */
const struct entry *case_find_conflict(const struct mps_case *c, const char *key)
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
int case_add_entry(struct mps_case *c, const char *key, const char *val, size_t vlen,
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

void case_add_err(struct errs *es, const char *fmt, ...)
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
void case_one_line(char *msg)
{
    for (unsigned char *p = (unsigned char *)msg; *p; p++)
        if (*p < 0x20 || *p == 0x7f)
            *p = '?';
}

/* Appends "(and N more problems; the next: ...)" to the first one. */
void case_finish_errs(struct errs *es)
{
    if (es->n < 2 || !es->err)
        return;
    char *msg = es->err->msg;
    size_t used = strlen(msg);
    snprintf(msg + used, sizeof es->err->msg - used, " (and %d more problem%s; the next: %s)",
             es->n - 1, es->n > 2 ? "s" : "", es->next);
}

/* ---- load ---- */

/* Every program lands on each snapshot, probe and checkpoint time in turn.
 * An interval so short that end_time holds more than MPS_CASE_MAX_EVENTS of
 * them is refused: at 1e-300 s the loops stepped by nothing (t + 1e-300 ==
 * t) and the solid, or the coupler of a solid alone, never finished. 1e8 is
 * far past any output a run can write (probes.csv at 1e8 rows is ~10 GB) and
 * keeps every interval above 1e-8 end_time, far above a double's rounding. */
#define MPS_CASE_MAX_EVENTS 1e8

static enum mps_status case_check_events(const struct mps_case *c, struct mps_err *err)
{
    static const struct {
        const char *key, *what, *hint;
    } events[] = {{"output.interval", "snapshots", ", or 0 for none"},
                  {"output.probe_interval", "probes.csv rows", ""},
                  {"output.checkpoint_interval", "checkpoints", ", or 0 for none"}};
    if (!case_find_spec(c, "end_time"))
        return MPS_OK; /* a table without the common keys (tests) */
    const double end = mps_case_double(c, "end_time");
    for (size_t k = 0; k < sizeof events / sizeof events[0]; k++) {
        if (!case_find_spec(c, events[k].key))
            continue;
        double dt = mps_case_double(c, "%s", events[k].key);
        if (dt > 0.0 && end / dt > MPS_CASE_MAX_EVENTS)
            return mps_case_fail(c, err, events[k].key,
                                 "%.3g %s to end_time = %g s, more than %.0e: give a "
                                 "longer interval%s",
                                 end / dt, events[k].what, end, MPS_CASE_MAX_EVENTS,
                                 events[k].hint);
    }
    return MPS_OK;
}

enum mps_status mps_case_load(struct mps_case **out, const char *path,
                              const char *const *sets, int nsets,
                              const struct mps_key_spec *const *spec_tables, int ntables,
                              const char *const *ignore_prefixes, struct mps_err *err)
{
    *out = NULL;
    if (!mps_utf8_valid(path)) { /* it is written into the run's YAML and JSON records */
        char shown[1024];
        return mps_err_set(err, MPS_EINPUT, "%s: the case file's path must be UTF-8 text "
                           "(it is recorded in the run's YAML and JSON files)",
                           mps_utf8_escaped(path, shown, sizeof shown));
    }
    struct mps_case *c = calloc(1, sizeof *c);
    if (!c)
        return mps_err_set(err, MPS_ENOMEM, "%s: out of memory", path);
    const char *slash = strrchr(path, '/');
    c->path = strdup(path);
    c->dir = !slash ? strdup(".") : slash == path ? strdup("/")
                                                  : strndup(path, (size_t)(slash - path));
    if (!c->path || !c->dir || case_copy_specs(c, spec_tables, ntables, ignore_prefixes)) {
        mps_case_destroy(&c);
        return mps_err_set(err, MPS_ENOMEM, "%s: out of memory", path);
    }

    enum mps_status st = case_read_file(c, err);
    if (st == MPS_OK)
        st = case_read_origins(c, err);
    struct errs es = {err, 0, ""};
    for (int i = 0; i < nsets && st == MPS_OK; i++)
        if (case_apply_set(c, sets[i], &es) == MPS_ENOMEM)
            st = MPS_ENOMEM;
    if (st == MPS_OK && (st = case_validate(c, &es)) == MPS_ENOMEM)
        mps_err_set(err, st, "%s: out of memory", path);
    if (st == MPS_OK && es.n > 0) {
        st = MPS_EINPUT;
        case_finish_errs(&es);
    }
    if (st == MPS_OK)
        st = case_check_events(c, err);
    if (st != MPS_OK && err)
        case_one_line(err->msg);
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
    free(c->origin);
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
    const struct mps_key_spec *s = case_find_spec(c, key);
    if (!s) {
        fprintf(stderr, "%s: key '%s' is not declared in any spec table\n", fn, key);
        abort();
    }
    if (!(mask & (1u << s->type))) {
        fprintf(stderr, "%s: key '%s' is declared as %s\n", fn, key, type_name(s->type));
        abort();
    }
    const struct entry *e = case_find_entry(c, key);
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
    case_check_value(s, s->def, v, prob, sizeof prob); /* validated at load */
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
    if (case_find_entry(c, key))
        return 1;
    const struct mps_key_spec *s = case_find_spec(c, key);
    if (s)
        return s->def != NULL;
    if (case_is_ignored(c, key))
        return 0;
    /* A typo here would silently read as "absent". */
    fprintf(stderr, "mps_case_has: key '%s' is neither declared nor under an ignored prefix\n",
            key);
    abort();
}

const char *mps_case_text(const struct mps_case *c, const char *fmt, ...)
{
    FORMAT_KEY("mps_case_text");
    const struct entry *e = case_find_entry(c, key);
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
        if (case_is_index(k + pn + 1, qn)) {
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
    const struct entry *e = case_find_entry(c, key);
    if (e)
        return e->where;
    const struct mps_key_spec *s = case_find_spec(c, key);
    if (s && s->def)
        return "default";
    e = find_section(c, key);
    return e ? e->where : mps_case_origin(c);
}

enum mps_status mps_case_fail(const struct mps_case *c, struct mps_err *err, const char *key,
                              const char *fmt, ...)
{
    char prob[sizeof err->msg];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(prob, sizeof prob, fmt, ap);
    va_end(ap);
    const struct entry *e = case_find_entry(c, key);
    const struct mps_key_spec *s = e ? NULL : case_find_spec(c, key);
    if (e)
        mps_err_set(err, MPS_EINPUT, "%s: %s = %s: %s", e->where, key, case_shown(e->val), prob);
    else if (s && s->def)
        mps_err_set(err, MPS_EINPUT, "default: %s = %s: %s", key, case_shown(s->def), prob);
    else
        mps_err_set(err, MPS_EINPUT, "%s: %s: %s", mps_case_where(c, key), key, prob);
    if (err)
        case_one_line(err->msg);
    return MPS_EINPUT;
}

const char *mps_case_origin(const struct mps_case *c)
{
    return c->origin ? c->origin : c->path;
}

const char *mps_case_path(const struct mps_case *c)
{
    return c->path;
}

const char *mps_case_dir(const struct mps_case *c)
{
    return c->dir;
}
