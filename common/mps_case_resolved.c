/* The resolved case: every key, defaults included, nested back into YAML
 * (mps_case_resolved_yaml, mps_case_write_resolved in mps_case.h), with
 * where each key came from, which mps_case_load reads back
 * (case_read_origins). */
/* realpath() is XSI */
#define _XOPEN_SOURCE 700
#include "mps_case_priv.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>

#include <yaml.h>

/* ---- resolved YAML: sort the flat keys and nest them again ---- */

/* Component by component; indices compare as numbers so items stay in order. */
static int cmp_keys(const void *pa, const void *pb)
{
    const char *x = (*(const struct entry *const *)pa)->key;
    const char *y = (*(const struct entry *const *)pb)->key;
    for (;;) {
        size_t xn = strcspn(x, "."), yn = strcspn(y, ".");
        int r;
        if (case_is_index(x, xn) && case_is_index(y, yn) && xn != yn) {
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
        seq = case_is_index(v[i]->key + off, strcspn(v[i]->key + off, "."));
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
    return case_sb_add(data, buf, size) == 0;
}

/* A relative path value (MPS_KEY_PATH) made absolute against the case's
 * directory, malloc'd; NULL when it needs no change or memory ran out. */
static char *absolute_path(const struct mps_case *c, const struct entry *e)
{
    if (!e->spec || !(e->spec->flags & MPS_KEY_PATH) || !e->val[0] || e->val[0] == '/')
        return NULL;
    char *dir = realpath(c->dir, NULL);
    char *abs = case_xprintf("%s/%s", dir ? dir : c->dir, e->val);
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

/* The comment lines that carry each key's origin: "#@ KEY<TAB>WHERE<TAB>
 * VALUE". The value is there so an origin is used only while the copy holds
 * the value given there (someone may edit the copy and run it again). A
 * key, origin or value holding a line break (a --set value can), or a key
 * or origin holding a tab, is left out: the reader then names the resolved
 * file's line for it. */
static int write_origins(FILE *f, const struct mps_case *c)
{
    int bad = fputs(ORIGIN_INTRO, f) < 0;
    for (int i = 0; i < c->n && !bad; i++)
        if (!strpbrk(c->e[i].key, "\t\r\n") && !strpbrk(c->e[i].where, "\t\r\n") &&
            !strpbrk(c->e[i].val, "\r\n"))
            bad = fprintf(f, "%s%s\t%s\t%s\n", ORIGIN_MARK, c->e[i].key, c->e[i].where,
                          c->e[i].val) < 0;
    return bad;
}

/* The user's case named in the resolved file's first line, line (RESOLVED_INTRO
 * PATH RESOLVED_TAIL), into c->origin; a line of another shape leaves it. */
static enum mps_status read_origin_path(struct mps_case *c, const char *line)
{
    const char *p = line + strlen(RESOLVED_INTRO);
    size_t n = strcspn(p, "\r\n"), tn = strlen(RESOLVED_TAIL);
    if (n <= tn || strncmp(p + n - tn, RESOLVED_TAIL, tn) != 0)
        return MPS_OK;
    free(c->origin);
    c->origin = strndup(p, n - tn);
    return c->origin ? MPS_OK : MPS_ENOMEM;
}

enum mps_status case_read_origins(struct mps_case *c, struct mps_err *err)
{
    FILE *f = fopen(c->path, "r");
    if (!f) /* it was read a moment ago: gone now */
        return mps_err_set(err, MPS_EIO, "%s: cannot read: %s", c->path, strerror(errno));
    char *line = NULL;
    size_t cap = 0;
    ssize_t n;
    int first = 1, marks = 0;
    enum mps_status st = MPS_OK;
    while ((n = getline(&line, &cap, f)) > 0) {
        if (first && strncmp(line, RESOLVED_INTRO, strlen(RESOLVED_INTRO)) != 0)
            break; /* not a resolved case: its keys are where the file has them */
        if (first && (st = read_origin_path(c, line))) {
            mps_err_set(err, st, "%s: out of memory", c->path);
            break;
        }
        first = 0;
        if (strncmp(line, ORIGIN_MARK, strlen(ORIGIN_MARK)) != 0)
            continue;
        if (++marks > c->n)
            break; /* more origins than keys: not ours, and no quadratic work */
        line[strcspn(line, "\r\n")] = '\0';
        char *key = line + strlen(ORIGIN_MARK), *at = strchr(key, '\t');
        char *val = at ? strchr(at + 1, '\t') : NULL;
        if (!val)
            continue;
        *at++ = '\0';
        *val++ = '\0';
        struct entry *e = case_find_entry(c, key);
        if (e && strcmp(e->val, val) != 0)
            e = NULL; /* edited since: the copy's line is where it was given */
        char *where = e ? strdup(at) : NULL;
        if (e && !where) {
            st = mps_err_set(err, MPS_ENOMEM, "%s: out of memory", c->path);
            break;
        }
        if (e) {
            free(e->where);
            e->where = where;
        }
    }
    free(line);
    fclose(f); /* read only: nothing to lose */
    return st;
}

/* A path key's value is written absolute (absolute_path), and YAML is UTF-8:
 * a case in a directory whose name is not would give a resolved case that
 * cannot be written, so that is an input error naming the key. */
static enum mps_status check_absolute_paths(const struct mps_case *c, struct mps_err *err)
{
    for (int i = 0; i < c->n; i++) {
        char *abs = absolute_path(c, &c->e[i]);
        if (abs && !mps_utf8_valid(abs)) {
            char shown[1024];
            mps_err_set(err, MPS_EINPUT, "%s: %s = %s: its absolute path %s must be UTF-8 "
                        "text (the resolved case is YAML)", c->e[i].where, c->e[i].key,
                        c->e[i].val, mps_utf8_escaped(abs, shown, sizeof shown));
            free(abs);
            return MPS_EINPUT;
        }
        free(abs);
    }
    return MPS_OK;
}

enum mps_status mps_case_write_resolved(const struct mps_case *c, const char *path,
                                        const char *comment, struct mps_err *err)
{
    enum mps_status pst = check_absolute_paths(c, err);
    if (pst)
        return pst;
    char *y = mps_case_resolved_yaml(c);
    char *tmp = case_xprintf("%s.tmp", path);
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
    int bad = fprintf(f, RESOLVED_INTRO "%s" RESOLVED_TAIL "\n%s%s", c->path,
                      comment ? comment : "", y) < 0;
    bad |= write_origins(f, c);
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
