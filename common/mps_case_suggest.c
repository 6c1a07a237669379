/* "did you mean": the spec name nearest an unknown key (mps_case_priv.h). */
#include "mps_case_priv.h"

#include <stdio.h>
#include <string.h>

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

/* A key whose first component is a typo for a section another program owns
 * (an ignored prefix: "fluidd.rho" in the coupler, which leaves "fluid." to
 * the fluid solver): "; did you mean fluid.rho?", the key in that section.
 * Whether the rest is a key there is that program's to say. */
static void suggest_section(const struct mps_case *c, const char *key, char *out, size_t n)
{
    size_t kn = strcspn(key, ".");
    if (!key[kn] || kn >= KEY_MAX)
        return;
    char first[KEY_MAX], sect[KEY_MAX];
    memcpy(first, key, kn);
    first[kn] = '\0';
    for (int i = 0; i < c->nignore; i++) {
        size_t sn = strlen(c->ignore[i]);
        if (sn < 2 || sn > KEY_MAX || c->ignore[i][sn - 1] != '.')
            continue;
        memcpy(sect, c->ignore[i], sn - 1);
        sect[sn - 1] = '\0';
        int limit = (int)(sn - 1) / 4 > 1 ? (int)(sn - 1) / 4 : 1;
        if (strcmp(first, sect) != 0 && edit_distance(first, sect) <= limit) {
            snprintf(out, n, "; did you mean %s%s?", sect, key + kn);
            return;
        }
    }
}

/* Writes "; did you mean fluid.blocks.0.x0?" (with key's own indices) or "". */
void case_suggest(const struct mps_case *c, const char *key, char *out, size_t n)
{
    char wild[KEY_MAX], idx[KEY_MAX];
    size_t w = 0, ni = 0;
    out[0] = '\0';
    /* wild: key with indices replaced by "*"; idx: the indices, '.'-separated */
    for (const char *p = key; *p;) {
        size_t cn = strcspn(p, ".");
        int isx = case_is_index(p, cn);
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
    if (!best || bd > (limit > 1 ? limit : 1)) {
        suggest_section(c, key, out, n);
        return;
    }

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
