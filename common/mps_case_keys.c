/* Case keys against their specs: values (type, bounds, choices), unknown
 * keys, required keys, defaults (mps_case_priv.h). */
#include "mps_case_priv.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* ---- values ---- */

const char *case_shown(const char *v)
{
    return *v ? v : "(empty)";
}

void case_bounds_text(const struct mps_key_spec *s, char *buf, size_t n)
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
int case_check_value(const struct mps_key_spec *s, const char *text, struct value *v,
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
            case_bounds_text(s, prob, np);
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
            case_bounds_text(s, prob, np);
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

int case_copy_specs(struct mps_case *c, const struct mps_key_spec *const *tables, int ntables,
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
        if (case_is_index(k + plen, qn))
            idx[ni++] = strtol(k + plen, NULL, 10);
    }
    qsort(idx, (size_t)ni, sizeof *idx, cmp_long);
    int rc = 0;
    for (int i = 0; i < ni && !rc; i++) {
        if (i > 0 && idx[i] == idx[i - 1])
            continue;
        char *sub = case_xprintf("%.*s%ld%s", (int)plen, pat, idx[i], star + 1);
        rc = sub ? expand(c, s, sub, fn, es) : -1;
        free(sub);
    }
    free(idx);
    return rc;
}

static int check_required(struct mps_case *c, const struct mps_key_spec *s, const char *key,
                          struct errs *es)
{
    if (case_find_entry(c, key))
        return 0;
    const char *help = s->help ? s->help : "", *units = s->units ? s->units : "";
    const char *file = mps_case_origin(c);
    if (*help && *units)
        case_add_err(es, "%s: missing required key '%s' (%s, %s)", file, key, help, units);
    else if (*help || *units)
        case_add_err(es, "%s: missing required key '%s' (%s)", file, key, *help ? help : units);
    else
        case_add_err(es, "%s: missing required key '%s'", file, key);
    return 0;
}

static int fill_default(struct mps_case *c, const struct mps_key_spec *s, const char *key,
                        struct errs *es)
{
    if (case_find_entry(c, key))
        return 0;
    char prob[256];
    if (case_add_entry(c, key, s->def, strlen(s->def), strdup("default")))
        return -1;
    struct entry *e = &c->e[c->n - 1];
    e->spec = s;
    case_check_value(s, s->def, &e->v, prob, sizeof prob); /* checked in case_validate() */
    return 0;
}

static void check_keys(struct mps_case *c, struct errs *es)
{
    char prob[256];
    struct value v;
    for (int i = 0; i < c->nspecs; i++) { /* programmer errors, reported like input */
        const struct mps_key_spec *s = &c->specs[i];
        if (s->def && case_check_value(s, s->def, &v, prob, sizeof prob))
            case_add_err(es, "default: %s = %s: %s", s->name, case_shown(s->def), prob);
    }
    for (int i = 0; i < c->n; i++) {
        struct entry *e = &c->e[i];
        /* The resolved case handed to the solvers is YAML, which is UTF-8:
         * a key or value that is not could be read but not written back,
         * and this holds under an ignored prefix too (another program's
         * section, copied through) */
        if (!mps_utf8_valid(e->key) || !mps_utf8_valid(e->val)) {
            char where[KEY_MAX + 64], key[KEY_MAX * 4], val[256];
            case_add_err(es, "%s: %s = %s: must be UTF-8 text",
                         mps_utf8_escaped(e->where, where, sizeof where),
                         mps_utf8_escaped(e->key, key, sizeof key),
                         mps_utf8_escaped(case_shown(e->val), val, sizeof val));
            continue;
        }
        /* A declared key is validated even under an ignored prefix. */
        e->spec = case_find_spec(c, e->key);
        if (!e->spec) {
            if (case_is_ignored(c, e->key))
                continue;
            char hint[KEY_MAX + 32] = "";
            if (es->n < 2) /* only the first two problems are shown */
                case_suggest(c, e->key, hint, sizeof hint);
            case_add_err(es, "%s: %s = %s: unknown key%s", e->where, e->key, case_shown(e->val), hint);
        } else if (case_check_value(e->spec, e->val, &e->v, prob, sizeof prob)) {
            case_add_err(es, "%s: %s = %s: %s", e->where, e->key, case_shown(e->val), prob);
        }
    }
}

/* The keys against the specs, then the required keys, then (if all is well)
 * the defaults. MPS_ENOMEM, or MPS_OK with the problems in es. */
enum mps_status case_validate(struct mps_case *c, struct errs *es)
{
    check_keys(c, es);
    for (int i = 0; i < c->nspecs; i++)
        if ((c->specs[i].flags & MPS_KEY_REQUIRED) &&
            expand(c, &c->specs[i], c->specs[i].name, check_required, es))
            return MPS_ENOMEM;
    if (es->n == 0)
        for (int i = 0; i < c->nspecs; i++)
            if (c->specs[i].def && expand(c, &c->specs[i], c->specs[i].name, fill_default, es))
                return MPS_ENOMEM;
    return MPS_OK;
}
