/* The key reference a program prints for --keys: its spec tables as
 * Markdown, one section per table, so that a user can see every key the
 * program reads, its type, default, bounds and meaning, without reading C.
 * docs/keys.md is the three programs' lists (tests/docs/keys_doc.py keeps it
 * equal to them). */
#include "mps_case_priv.h"

#include <stdio.h>
#include <string.h>

static const char *type_text(const struct mps_key_spec *s)
{
    switch (s->type) {
    case MPS_KEY_DOUBLE:
        return "number";
    case MPS_KEY_INT:
        return "integer";
    case MPS_KEY_BOOL:
        return "true/false";
    case MPS_KEY_ENUM:
        return "one of";
    case MPS_KEY_STRING:
        break;
    }
    return (s->flags & MPS_KEY_PATH) ? "file path" : "text";
}

static void print_key(FILE *f, const struct mps_key_spec *s)
{
    fprintf(f, "- `%s` (%s", s->name, type_text(s));
    if (s->type == MPS_KEY_ENUM && s->choices) {
        /* "a|b|c" as `a`, `b`, `c` */
        const char *c = s->choices;
        for (int first = 1; *c; first = 0) {
            size_t n = strcspn(c, "|");
            fprintf(f, "%s`%.*s`", first ? " " : ", ", (int)n, c);
            c += n + (c[n] == '|');
        }
    }
    if (s->units && s->units[0])
        fprintf(f, ", %s", s->units);
    if (s->flags & MPS_KEY_REQUIRED)
        fprintf(f, ", required");
    else if (s->def && s->def[0])
        fprintf(f, ", default %s", s->def);
    else if (!s->def)
        fprintf(f, ", no default: off when absent");
    if ((s->type == MPS_KEY_DOUBLE || s->type == MPS_KEY_INT) &&
        (s->flags & (MPS_KEY_NO_LO | MPS_KEY_NO_HI)) != (MPS_KEY_NO_LO | MPS_KEY_NO_HI)) {
        char b[96];
        case_bounds_text(s, b, sizeof b);
        const char *pre = "must be ";
        fprintf(f, ", %s", strncmp(b, pre, strlen(pre)) ? b : b + strlen(pre));
    }
    fprintf(f, ")");
    if (s->help && s->help[0])
        fprintf(f, ": %s", s->help);
    fprintf(f, "\n");
}

void mps_case_print_keys(FILE *f, const struct mps_key_spec *const *tables,
                         const char *const *titles, int ntables)
{
    for (int t = 0; t < ntables; t++) {
        fprintf(f, "%s## %s\n\n", t ? "\n" : "", titles[t]);
        for (const struct mps_key_spec *s = tables[t]; s && s->name; s++)
            print_key(f, s);
    }
}
