/* realpath() is XSI */
#define _XOPEN_SOURCE 700
#include "mps_cli.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "mps_simd.h"
#include "mps_version.h"

static void print_help(const char *usage, const struct mps_cli_extra *extra, int nextra)
{
    if (usage && usage[0])
        printf("%s%s", usage, usage[strlen(usage) - 1] == '\n' ? "" : "\n");
    printf("\nOptions:\n"
           "  --out DIR            output directory (required; created if missing)\n"
           "  --set KEY=VALUE      override a case-file key; repeatable\n"
           "  --quiet              no progress output\n"
           "  --restart DIR        continue the run in DIR from its latest checkpoint\n"
           "  --from TIME          with --restart: from the checkpoint nearest to TIME\n"
           "  --stop-at TIME       stop at the first checkpoint at or after TIME (s)\n"
           "  --version            show the version and git revision it was built from\n"
           "  --keys               list every case key this program reads, with its type,\n"
           "                       default, bounds and meaning (Markdown; docs/keys.md)\n"
           "  --help               show this help\n");
    for (int k = 0; k < nextra; k++) {
        char head[128];
        snprintf(head, sizeof head, "%s%s", extra[k].name, extra[k].takes_value ? " VALUE" : "");
        printf("  %-20s %s\n", head, extra[k].help ? extra[k].help : "");
    }
}

/* If arg is "NAME" or "NAME=VALUE", returns 1 and sets *inline_value to the
 * text after '=' (NULL for the plain form). */
static int match(const char *arg, const char *name, const char **inline_value)
{
    size_t n = strlen(name);
    if (strncmp(arg, name, n) != 0)
        return 0;
    if (arg[n] == '\0') {
        *inline_value = NULL;
        return 1;
    }
    if (arg[n] == '=') {
        *inline_value = arg + n + 1;
        return 1;
    }
    return 0;
}

/* The value of an option: inline ("--out=DIR") or the next argument, which
 * must exist and not be another option. NULL if missing. */
static const char *option_value(const char *inline_value, int argc, char **argv, int *i)
{
    if (inline_value)
        return inline_value[0] ? inline_value : NULL;
    if (*i + 1 < argc && strncmp(argv[*i + 1], "--", 2) != 0)
        return argv[++*i];
    return NULL;
}

enum mps_status mps_cli_parse(struct mps_cli *cli, int argc, char **argv,
                              struct mps_cli_extra *extra, int nextra, const char *usage,
                              struct mps_err *err)
{
    memset(cli, 0, sizeof *cli);
    cli->restart_from = -1.0;
    cli->stop_at = INFINITY;
    if (!extra)
        nextra = 0;
    for (int k = 0; k < nextra; k++)
        extra[k].value = NULL;

    /* --help and --version win over everything else, even errors, so they
     * always work. */
    for (int i = 1; i < argc && strcmp(argv[i], "--") != 0; i++) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            print_help(usage, extra, nextra);
            return mps_err_set(err, MPS_EINTR, "help shown");
        }
        if (!strcmp(argv[i], "--keys")) {
            cli->keys = 1;
            return mps_err_set(err, MPS_EINTR, "keys asked");
        }
        if (!strcmp(argv[i], "--version")) {
            const char *slash = strrchr(argv[0], '/');
            printf("%s %s (git %s)\n", slash ? slash + 1 : argv[0], MPS_VERSION, mps_git_rev);
            return mps_err_set(err, MPS_EINTR, "version shown");
        }
    }

    int options_done = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = NULL;
        if (options_done || a[0] != '-' || !strcmp(a, "-")) {
            if (cli->case_path)
                return mps_err_set(err, MPS_EINPUT,
                                   "unexpected argument '%s': the case file is already '%s' "
                                   "(only one is accepted)", a, cli->case_path);
            cli->case_path = a;
            continue;
        }
        if (!strcmp(a, "--")) {
            options_done = 1;
            continue;
        }
        if (match(a, "--out", &v)) {
            const char *dir = option_value(v, argc, argv, &i);
            if (!dir)
                return mps_err_set(err, MPS_EINPUT, "--out needs a directory");
            cli->out_dir = dir;
            continue;
        }
        if (match(a, "--set", &v)) {
            const char *kv = option_value(v, argc, argv, &i);
            if (!kv)
                return mps_err_set(err, MPS_EINPUT, "--set needs key=value");
            const char *eq = strchr(kv, '=');
            if (!eq || eq == kv)
                return mps_err_set(err, MPS_EINPUT, "--set needs key=value, got '%s'", kv);
            if (cli->nsets >= MPS_CLI_MAX_SETS)
                return mps_err_set(err, MPS_EINPUT, "too many --set options (at most %d)",
                                   MPS_CLI_MAX_SETS);
            cli->sets[cli->nsets++] = kv;
            continue;
        }
        if (!strcmp(a, "--quiet")) {
            cli->quiet = 1;
            continue;
        }
        if (match(a, "--restart", &v)) {
            if (!(cli->restart_dir = option_value(v, argc, argv, &i)))
                return mps_err_set(err, MPS_EINPUT, "--restart needs the run's directory");
            continue;
        }
        if (match(a, "--from", &v) || match(a, "--stop-at", &v)) {
            const char *t = option_value(v, argc, argv, &i);
            char *end = NULL;
            double val = t ? strtod(t, &end) : NAN;
            if (!t || end == t || *end || !(val >= 0.0) || !isfinite(val))
                return mps_err_set(err, MPS_EINPUT, "%s needs a time >= 0 in seconds, got '%s'",
                                   a[2] == 'f' ? "--from" : "--stop-at", t ? t : "");
            *(a[2] == 'f' ? &cli->restart_from : &cli->stop_at) = val;
            continue;
        }
        int k;
        for (k = 0; k < nextra; k++)
            if (match(a, extra[k].name, &v))
                break;
        if (k == nextra)
            return mps_err_set(err, MPS_EINPUT, "unknown option '%s' (see --help)", a);
        if (!extra[k].takes_value) {
            if (v)
                return mps_err_set(err, MPS_EINPUT, "%s takes no value, got '%s'",
                                   extra[k].name, a);
            extra[k].value = "1";
            continue;
        }
        const char *val = option_value(v, argc, argv, &i);
        if (!val)
            return mps_err_set(err, MPS_EINPUT, "%s needs a value", extra[k].name);
        extra[k].value = val;
    }
    if (cli->restart_dir) {
        if (cli->case_path)
            return mps_err_set(err, MPS_EINPUT, "--restart %s takes no case file ('%s'): the "
                               "run continues with the case its checkpoint holds",
                               cli->restart_dir, cli->case_path);
        if (cli->out_dir)
            return mps_err_set(err, MPS_EINPUT, "--restart %s writes into that directory: "
                               "no --out", cli->restart_dir);
        for (int k = 0; k < cli->nsets; k++)
            if (strncmp(cli->sets[k], "end_time=", 9) != 0)
                return mps_err_set(err, MPS_EINPUT, "--set %s: a restart takes only "
                                   "--set end_time=T (the rest is the checkpoint's case)",
                                   cli->sets[k]);
        cli->out_dir = cli->restart_dir;
        return mps_simd_check_env(err);
    }
    if (cli->restart_from >= 0.0)
        return mps_err_set(err, MPS_EINPUT, "--from needs --restart DIR");
    if (!cli->case_path)
        return mps_err_set(err, MPS_EINPUT, "missing case file (see --help)");
    return mps_simd_check_env(err);
}

/* mkdir that accepts an existing directory. */
static int mkdir_one(const char *p)
{
    if (mkdir(p, 0777) == 0)
        return 0;
    int e = errno;
    struct stat st;
    if (e == EEXIST && stat(p, &st) == 0 && S_ISDIR(st.st_mode))
        return 0;
    if (e == EEXIST)
        e = ENOTDIR;
    errno = e;
    return -1;
}

enum mps_status mps_mkdir_p(const char *path, struct mps_err *err)
{
    if (!path || !path[0])
        return mps_err_set(err, MPS_EINPUT, "empty directory name");
    size_t n = strlen(path);
    char *p = malloc(n + 1);
    if (!p)
        return mps_err_set(err, MPS_ENOMEM, "out of memory creating '%s'", path);
    memcpy(p, path, n + 1);
    enum mps_status st = MPS_OK;
    /* Each parent in turn: cut the string at every '/' after the first char. */
    for (size_t i = 1; i <= n; i++) {
        if (p[i] != '/' && p[i] != '\0')
            continue;
        if (p[i - 1] == '/') /* "a//b" */
            continue;
        char c = p[i];
        p[i] = '\0';
        if (mkdir_one(p) != 0) {
            st = mps_err_set(err, MPS_EIO, "cannot create directory '%s'%s%s%s: %s", path,
                             strcmp(p, path) ? " (at '" : "", strcmp(p, path) ? p : "",
                             strcmp(p, path) ? "')" : "", strerror(errno));
            break;
        }
        p[i] = c;
    }
    free(p);
    return st;
}

char *mps_realpath(const char *path, char *buf, size_t len)
{
    char *r = realpath(path, NULL);
    if (!r)
        return NULL;
    if (strlen(r) >= len) {
        free(r);
        errno = ENAMETOOLONG;
        return NULL;
    }
    memcpy(buf, r, strlen(r) + 1);
    free(r);
    return buf;
}
