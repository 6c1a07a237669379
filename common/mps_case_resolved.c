/* The resolved case: every key, defaults included, nested back into YAML
 * (mps_case_resolved_yaml, mps_case_write_resolved in mps_case.h). */
#include "mps_case_priv.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

char *mps_case_resolved_yaml(const struct mps_case *c)
{
    struct entry **v = malloc(((size_t)c->n + 1) * sizeof *v);
    if (!v)
        return NULL;
    for (int i = 0; i < c->n; i++)
        v[i] = &c->e[i];
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
