#include "mps_json_read.h"

#include <stdlib.h>
#include <string.h>

static const char *skip_ws(const char *s)
{
    while (*s == ' ' || *s == '\t' || *s == '\n' || *s == '\r')
        s++;
    return s;
}

/* s at an opening quote; returns the character after the closing one, or
 * NULL for an unterminated string or a raw control character (RFC 8259 7). */
static const char *skip_string(const char *s)
{
    for (s++; *s; s++) {
        if (*s == '\\') {
            if (!*++s)
                return NULL;
        } else if (*s == '"') {
            return s + 1;
        } else if ((unsigned char)*s < 0x20) {
            return NULL;
        }
    }
    return NULL;
}

/* One value (after white space): a string, a balanced object or array (its
 * strings skipped as such, so a quoted bracket does not count), or a bare
 * scalar (number, true, false, null). Returns the character after it, or
 * NULL if there is none or it is cut short. */
static const char *skip_value(const char *s)
{
    s = skip_ws(s);
    if (*s == '"')
        return skip_string(s);
    if (*s == '{' || *s == '[') {
        char stack[64]; /* the closers expected, innermost last */
        int depth = 0;
        do {
            if (*s == '"') {
                if (!(s = skip_string(s)))
                    return NULL;
                continue;
            }
            if (*s == '{' || *s == '[') {
                if (depth == (int)sizeof stack)
                    return NULL; /* deeper than any summary: not ours */
                stack[depth++] = *s == '{' ? '}' : ']';
            } else if (*s == '}' || *s == ']') {
                if (*s != stack[--depth])
                    return NULL;
            } else if (!*s) {
                return NULL;
            }
            s++;
        } while (depth > 0);
        return s;
    }
    const char *e = s;
    while (*e && !strchr(",}] \t\r\n", *e))
        e++;
    return e > s ? e : NULL;
}

int mps_json_top_number(const char *json, const char *key, double *v)
{
    const char *s = skip_ws(json);
    size_t klen = strlen(key);
    if (*s++ != '{')
        return -1;
    s = skip_ws(s);
    if (*s == '}')
        return 0;
    for (;;) {
        if (*s != '"')
            return -1;
        const char *name = s + 1, *end = skip_string(s);
        if (!end)
            return -1;
        /* the raw text between the quotes: our keys need no escapes */
        int match = (size_t)(end - 1 - name) == klen && memcmp(name, key, klen) == 0;
        s = skip_ws(end);
        if (*s++ != ':')
            return -1;
        const char *val = skip_ws(s);
        if (!(s = skip_value(val)))
            return -1;
        if (match) {
            if (*val != '-' && (*val < '0' || *val > '9'))
                return 0;
            char *num_end;
            double x = strtod(val, &num_end);
            if (num_end != s)
                return -1; /* "12abc": not a JSON number */
            *v = x;
            return 1;
        }
        s = skip_ws(s);
        if (*s == '}')
            return 0;
        if (*s++ != ',')
            return -1;
        s = skip_ws(s);
    }
}
