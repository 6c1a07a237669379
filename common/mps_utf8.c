/* UTF-8: the case files, the resolved case, the protocol's text and the JSON
 * records are all UTF-8, and any byte that is not must be caught at the
 * edge where it comes in, by name. */
#include "mps_utf8.h"

#include <stdio.h>
#include <string.h>

size_t mps_utf8_seq(const unsigned char *p)
{
    int n = *p < 0x80 ? 0 : (*p & 0xe0) == 0xc0 ? 1 : (*p & 0xf0) == 0xe0 ? 2
          : (*p & 0xf8) == 0xf0 ? 3 : -1;
    if (!*p || n < 0 || (n == 1 && *p < 0xc2) || (n == 3 && *p > 0xf4))
        return 0;
    unsigned long cp = *p & (0x7fu >> n);
    for (int k = 1; k <= n; k++) {
        if ((p[k] & 0xc0) != 0x80)
            return 0;
        cp = cp << 6 | (p[k] & 0x3fu);
    }
    if ((n == 2 && (cp < 0x800 || (cp >= 0xd800 && cp <= 0xdfff))) ||
        (n == 3 && (cp < 0x10000 || cp > 0x10ffff)))
        return 0;
    return (size_t)n + 1;
}

int mps_utf8_valid(const char *s)
{
    for (const unsigned char *p = (const unsigned char *)s; *p;) {
        size_t n = mps_utf8_seq(p);
        if (!n)
            return 0;
        p += n;
    }
    return 1;
}

const char *mps_utf8_escaped(const char *s, char *buf, size_t n)
{
    if (n == 0)
        return buf;
    size_t at = 0;
    for (const unsigned char *p = (const unsigned char *)s; *p && at + 5 < n;) {
        size_t k = mps_utf8_seq(p);
        if (!k) {
            at += (size_t)snprintf(buf + at, n - at, "\\x%02x", *p++);
            continue;
        }
        if (at + k + 1 > n)
            break;
        memcpy(buf + at, p, k);
        at += k;
        p += k;
    }
    buf[at] = '\0';
    return buf;
}
