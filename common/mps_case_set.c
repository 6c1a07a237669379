/* --set key=value over the keys read from the file (mps_case_priv.h). */
#include "mps_case_priv.h"

#include <stdlib.h>
#include <string.h>

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

enum mps_status case_apply_set(struct mps_case *c, const char *set, struct errs *es)
{
    const char *eq = strchr(set, '=');
    if (!eq) {
        case_add_err(es, "--set %s: expected key=value", set);
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
        case_add_err(es, "--set %s: key too long", set);
        return MPS_EINPUT;
    }
    memcpy(key, k, kn);
    key[kn] = '\0';
    if (!case_key_shape_ok(key)) {
        case_add_err(es, "--set %s: '%s' is not a key name", set, key);
        return MPS_EINPUT;
    }
    char *where = case_xprintf("--set %s", set);
    if (!where)
        return mps_err_set(es->err, MPS_ENOMEM, "--set %s: out of memory", set);
    struct entry *e = case_find_entry(c, key);
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
    const struct entry *o = case_find_conflict(c, key);
    if (o) {
        case_add_err(es, "%s: %s = %.*s: conflicts with %s (%s); a key cannot be both a value and "
                "a section", where, key, (int)vn, v, o->key, o->where);
        free(where);
        return MPS_EINPUT;
    }
    if (case_add_entry(c, key, v, vn, where))
        return mps_err_set(es->err, MPS_ENOMEM, "--set %s: out of memory", set);
    return MPS_OK;
}
