#include "mps_prov.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "mps_host.h"
#include "mps_utf8.h"
#include "mps_version.h"

static char command[4096], hostname[256], host[256], started[32];
static char set_command[4200], set_hostname[300], set_host[300], set_started[64];

/* Appends s to buf (size len, used *at) as one shell word: bare when it
 * needs no quoting, else in single quotes ('\'' for a quote inside). */
static void append_word(char *buf, size_t len, size_t *at, const char *s)
{
    static const char plain[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz"
                                "0123456789_./=:,+-@%";
    int bare = s[0] && strspn(s, plain) == strlen(s);
    if (*at > 0 && *at + 1 < len)
        buf[(*at)++] = ' ';
    if (!bare && *at + 1 < len)
        buf[(*at)++] = '\'';
    for (; *s && *at + 1 < len; s++) {
        if (*s == '\'' && !bare) {
            if (*at + 4 >= len)
                break;
            memcpy(buf + *at, "'\\''", 4);
            *at += 4;
        } else {
            buf[(*at)++] = *s;
        }
    }
    if (!bare && *at + 1 < len)
        buf[(*at)++] = '\'';
    buf[*at] = '\0';
}

void mps_prov_init(int argc, char *const *argv)
{
    size_t at = 0;
    command[0] = '\0';
    for (int i = 0; i < argc; i++)
        append_word(command, sizeof command, &at, argv[i]);
    /* the record goes into the resolved case, which is UTF-8: a byte of
     * anything else (a bad --set, which the case then reports by its key)
     * is recorded as '?' */
    for (unsigned char *p = (unsigned char *)command; *p;) {
        size_t n = mps_utf8_seq(p);
        if (!n)
            *p++ = '?';
        else
            p += n;
    }
    if (gethostname(hostname, sizeof hostname) != 0)
        snprintf(hostname, sizeof hostname, "unknown");
    hostname[sizeof hostname - 1] = '\0';
    mps_host_describe(host, sizeof host);
    time_t now = time(NULL);
    struct tm utc;
    if (!gmtime_r(&now, &utc) || !strftime(started, sizeof started, "%Y-%m-%dT%H:%M:%SZ", &utc))
        snprintf(started, sizeof started, "unknown");
}

const char *mps_prov_command(void)
{
    return command;
}

int mps_prov_sets(const char **sets, int *n, int room)
{
    if (*n + MPS_PROV_NSETS > room)
        return -1;
    snprintf(set_command, sizeof set_command, "run.command=%s", command);
    snprintf(set_hostname, sizeof set_hostname, "run.hostname=%s", hostname);
    snprintf(set_host, sizeof set_host, "run.host=%s", host);
    snprintf(set_started, sizeof set_started, "run.started=%s", started);
    sets[(*n)++] = set_command;
    sets[(*n)++] = set_hostname;
    sets[(*n)++] = set_host;
    sets[(*n)++] = set_started;
    return 0;
}

char *mps_prov_comment(const struct mps_case *c, const char *program)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (!f)
        return NULL;
    fprintf(f, "# program: %s %s (git %s)\n", program, MPS_VERSION, mps_git_rev);
    fprintf(f, "# case: %s\n", mps_case_path(c));
    static const char *const keys[] = {"command", "hostname", "host", "started"};
    for (size_t k = 0; k < sizeof keys / sizeof keys[0]; k++) {
        /* one line each: a newline in a value would end the comment */
        const char *v = mps_case_string(c, "run.%s", keys[k]);
        fprintf(f, "# %s: %.*s\n", keys[k], (int)strcspn(v, "\r\n"), v);
    }
    int bad = ferror(f);
    fclose(f);
    if (bad) {
        free(buf);
        return NULL;
    }
    return buf;
}

void mps_prov_json(const struct mps_case *c, struct mps_json *j)
{
    mps_json_str(j, "command", mps_case_string(c, "run.command"));
    mps_json_str(j, "hostname", mps_case_string(c, "run.hostname"));
    mps_json_str(j, "started", mps_case_string(c, "run.started"));
}
