#include "mps_json.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>

#include "mps_utf8.h"

#define MAX_DEPTH ((int)(sizeof ((struct mps_json *)0)->first / sizeof(int)) - 1)

/* Newline and two spaces per level. */
static void indent(struct mps_json *j, int level)
{
    fputc('\n', j->f);
    for (int d = 0; d < level; d++)
        fputs("  ", j->f);
}

static void string(FILE *f, const char *s)
{
    fputc('"', f);
    for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
        size_t k = mps_utf8_seq(p);
        if (k > 1) { /* UTF-8 passes through */
            fwrite(p, 1, k, f);
            p += k - 1;
            continue;
        }
        if (k == 0) { /* JSON is UTF-8: a stray byte (a path, a peer's text) becomes U+FFFD */
            fputs("\\ufffd", f);
            continue;
        }
        switch (*p) {
        case '"': fputs("\\\"", f); break;
        case '\\': fputs("\\\\", f); break;
        case '\b': fputs("\\b", f); break;
        case '\f': fputs("\\f", f); break;
        case '\n': fputs("\\n", f); break;
        case '\r': fputs("\\r", f); break;
        case '\t': fputs("\\t", f); break;
        default:
            if (*p < 0x20)
                fprintf(f, "\\u%04x", *p);
            else
                fputc(*p, f);
        }
    }
    fputc('"', f);
}

/* Comma, newline and indentation before a member; then "key": in objects.
 * depth is the innermost open level (the root is 0); its members are
 * indented depth + 1 steps. */
static void member(struct mps_json *j, const char *key)
{
    if (!j->first[j->depth])
        fputc(',', j->f);
    j->first[j->depth] = 0;
    indent(j, j->depth + 1);
    if (!j->array[j->depth]) {
        assert(key && "members of an object need a key");
        string(j->f, key ? key : "");
        fputs(": ", j->f);
    }
}

static void open_level(struct mps_json *j, const char *key, int is_array)
{
    assert(j->depth < MAX_DEPTH && "JSON nesting too deep");
    member(j, key);
    fputc(is_array ? '[' : '{', j->f);
    if (j->depth < MAX_DEPTH)
        j->depth++;
    j->first[j->depth] = 1;
    j->array[j->depth] = (char)is_array;
}

void mps_json_begin(struct mps_json *j, FILE *f)
{
    j->f = f;
    j->depth = 0;
    fputc('{', f);
    j->first[0] = 1;
    j->array[0] = 0;
}

void mps_json_close(struct mps_json *j)
{
    if (j->depth <= 0)
        return; /* the root is closed by mps_json_end */
    int empty = j->first[j->depth];
    int is_array = j->array[j->depth];
    j->depth--;
    if (!empty)
        indent(j, j->depth + 1);
    fputc(is_array ? ']' : '}', j->f);
}

void mps_json_end(struct mps_json *j)
{
    while (j->depth > 0)
        mps_json_close(j);
    if (!j->first[0])
        fputc('\n', j->f);
    fputs("}\n", j->f);
}

void mps_json_object(struct mps_json *j, const char *key)
{
    open_level(j, key, 0);
}

void mps_json_array(struct mps_json *j, const char *key)
{
    open_level(j, key, 1);
}

void mps_json_num(struct mps_json *j, const char *key, double v)
{
    member(j, key);
    if (!isfinite(v)) {
        fputs("null", j->f);
        return;
    }
    /* Shortest of %.15g and %.17g that reads back exactly: 0.1 stays "0.1". */
    char buf[32];
    snprintf(buf, sizeof buf, "%.15g", v);
    if (strtod(buf, NULL) != v)
        snprintf(buf, sizeof buf, "%.17g", v);
    fputs(buf, j->f);
}

void mps_json_int(struct mps_json *j, const char *key, long long v)
{
    member(j, key);
    fprintf(j->f, "%lld", v);
}

void mps_json_str(struct mps_json *j, const char *key, const char *v)
{
    member(j, key);
    if (v)
        string(j->f, v);
    else
        fputs("null", j->f);
}

void mps_json_bool(struct mps_json *j, const char *key, int v)
{
    member(j, key);
    fputs(v ? "true" : "false", j->f);
}
