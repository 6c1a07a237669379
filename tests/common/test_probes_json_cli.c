/* Small output helpers and the command line: probes CSV, JSON writer, CLI
 * parsing (happy path and each error), mkdir -p, timer. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "../test_util.h"
#include "mps_cli.h"
#include "mps_json.h"
#include "mps_json_read.h"
#include "mps_probes.h"
#include "mps_progress.h"
#include "mps_timer.h"

static char dir[] = "/tmp/mps_test_pjc_XXXXXX";

static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    char *b = calloc(1 << 16, 1);
    size_t n = fread(b, 1, (1 << 16) - 1, f);
    b[n] = '\0';
    fclose(f);
    return b;
}

#define CHECK_STR(got, want)                                                      \
    do {                                                                          \
        const char *g_ = (got), *w_ = (want);                                     \
        CHECK(g_ && !strcmp(g_, w_));                                             \
        if (!(g_ && !strcmp(g_, w_)))                                             \
            fprintf(stderr, "  got:  [%s]\n  want: [%s]\n", g_ ? g_ : "(null)", w_); \
    } while (0)

static void test_probes(void)
{
    char path[256];
    snprintf(path, sizeof path, "%s/probes.csv", dir);
    struct mps_err err = {0};
    struct mps_probes *p = NULL;
    const char *names[] = {"p_gauge1", "h,left", "say \"hi\""};
    CHECK(mps_probes_open(&p, path, "# case: a.yml\n", names, 3, &err) == MPS_OK);
    double v1[] = {1.0 / 3.0, -2.5e-20, 101325.0};
    double v2[] = {0.0, 1e300, 12345678901.0};
    CHECK(mps_probes_write(p, 0.0, v1, &err) == MPS_OK);
    /* flushed per row: complete before close */
    char *t = slurp(path);
    CHECK_STR(t, "# case: a.yml\ntime,p_gauge1,\"h,left\",\"say \"\"hi\"\"\"\n"
                 "0,0.333333333,-2.5e-20,101325\n");
    free(t);
    CHECK(mps_probes_write(p, 0.125, v2, &err) == MPS_OK);
    mps_probes_close(&p);
    CHECK(p == NULL);
    mps_probes_close(&p);
    t = slurp(path);
    CHECK_STR(t, "# case: a.yml\ntime,p_gauge1,\"h,left\",\"say \"\"hi\"\"\"\n"
                 "0,0.333333333,-2.5e-20,101325\n"
                 "0.125,0,1e+300,1.23456789e+10\n");
    free(t);

    snprintf(path, sizeof path, "%s/no/such/dir/probes.csv", dir);
    CHECK(mps_probes_open(&p, path, NULL, names, 3, &err) == MPS_EIO);
    CHECK(strstr(err.msg, path) != NULL);
    CHECK(p == NULL);
}

static void test_json(void)
{
    char path[256];
    snprintf(path, sizeof path, "%s/summary.json", dir);
    FILE *f = fopen(path, "w");
    struct mps_json j;
    mps_json_begin(&j, f);
    mps_json_str(&j, "name", "quote\" back\\ nl\n tab\t ctl\x01 utf8 \xc3\xa9");
    /* JSON is UTF-8: a stray byte (a path, a peer's text) becomes U+FFFD,
     * a cut sequence too, and what follows is kept */
    mps_json_str(&j, "stray", "caf\xe9.yml \xe2\x82 \xf0\x9f\x98\x80");
    mps_json_num(&j, "dt", 0.1);
    mps_json_num(&j, "third", 1.0 / 3.0);
    mps_json_num(&j, "nan", 0.0 / 0.0);
    mps_json_num(&j, "inf", -1.0 / 0.0);
    mps_json_int(&j, "steps", 123456789012LL);
    mps_json_bool(&j, "ok", 1);
    mps_json_object(&j, "timing");
    mps_json_num(&j, "total", 2.5);
    mps_json_array(&j, "phases");
    mps_json_str(&j, NULL, "nbr");
    mps_json_object(&j, NULL);
    mps_json_bool(&j, "x", 0);
    mps_json_close(&j);
    mps_json_array(&j, NULL);
    mps_json_close(&j);
    mps_json_close(&j);
    mps_json_close(&j);
    mps_json_object(&j, "empty");
    mps_json_close(&j);
    mps_json_str(&j, "null_str", NULL);
    mps_json_end(&j);
    fclose(f);
    char *t = slurp(path);
    CHECK_STR(t, "{\n"
                 "  \"name\": \"quote\\\" back\\\\ nl\\n tab\\t ctl\\u0001 utf8 \xc3\xa9\",\n"
                 "  \"stray\": \"caf\\ufffd.yml \\ufffd\\ufffd \xf0\x9f\x98\x80\",\n"
                 "  \"dt\": 0.1,\n"
                 "  \"third\": 0.33333333333333331,\n"
                 "  \"nan\": null,\n"
                 "  \"inf\": null,\n"
                 "  \"steps\": 123456789012,\n"
                 "  \"ok\": true,\n"
                 "  \"timing\": {\n"
                 "    \"total\": 2.5,\n"
                 "    \"phases\": [\n"
                 "      \"nbr\",\n"
                 "      {\n"
                 "        \"x\": false\n"
                 "      },\n"
                 "      []\n"
                 "    ]\n"
                 "  },\n"
                 "  \"empty\": {},\n"
                 "  \"null_str\": null\n"
                 "}\n");
    free(t);
    /* an independent parser agrees, when one is at hand */
    if (system("command -v python3 >/dev/null 2>&1") == 0) {
        char cmd[512];
        snprintf(cmd, sizeof cmd,
                 "python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); "
                 "assert d[\"timing\"][\"phases\"][1][\"x\"] is False' '%s'", path);
        CHECK(system(cmd) == 0);
    }
    /* empty root */
    snprintf(path, sizeof path, "%s/empty.json", dir);
    f = fopen(path, "w");
    mps_json_begin(&j, f);
    mps_json_end(&j);
    fclose(f);
    t = slurp(path);
    CHECK_STR(t, "{}\n");
    free(t);
}

/* Runs the parser on a NULL-terminated argument list. */
static enum mps_status parse(struct mps_cli *cli, struct mps_cli_extra *ex, int nex,
                             struct mps_err *err, const char **args)
{
    char *argv[64];
    int argc = 0;
    argv[argc++] = "prog";
    for (; *args; args++)
        argv[argc++] = (char *)*args;
    argv[argc] = NULL;
    return mps_cli_parse(cli, argc, argv, ex, nex, "usage: prog CASE.yml --out DIR", err);
}

/* The coupler reads the solvers' summaries (BYE) with mps_json_top_number:
 * only a top-level member counts, not the same key nested in an object or an
 * array or quoted in a string (what a strstr reading took for the member). */
static void test_json_read(void)
{
    double v = -1.0;
    const char *bye = "{\"program\": \"solid\", \"note\": \"\\\"compute_seconds\\\": 9\", "
                      "\"phases\": {\"compute_seconds\": 7, \"x\": [1, {\"a\": \"]\"}]}, "
                      "\"list\": [\"compute_seconds\", 8],\n \"compute_seconds\" : -2.5e-1, "
                      "\"lost\": null}";
    CHECK(mps_json_top_number(bye, "compute_seconds", &v) == 1);
    CHECK_NEAR(v, -0.25, 0.0);
    CHECK(mps_json_top_number(bye, "lost", &v) == 0);      /* null is no number */
    CHECK(mps_json_top_number(bye, "program", &v) == 0);   /* nor a string */
    CHECK(mps_json_top_number(bye, "a", &v) == 0);         /* nested only */
    CHECK(mps_json_top_number(bye, "compute", &v) == 0);   /* a prefix is not the key */
    CHECK(mps_json_top_number("{}", "x", &v) == 0);
    CHECK(mps_json_top_number(" {\"x\":3}", "x", &v) == 1 && v == 3.0);
    /* not JSON objects, or cut short before the member */
    CHECK(mps_json_top_number("", "x", &v) == -1);
    CHECK(mps_json_top_number("[1]", "x", &v) == -1);
    CHECK(mps_json_top_number("{\"y\": [1, 2}, \"x\": 1}", "x", &v) == -1);
    CHECK(mps_json_top_number("{\"y\": \"open, \"x\": 1", "x", &v) == -1);
    CHECK(mps_json_top_number("{\"x\": 12abc}", "x", &v) == -1);
    CHECK(mps_json_top_number("{\"y\" 1, \"x\": 1}", "x", &v) == -1);
    /* what the writer writes, the reader reads back */
    char path[300];
    snprintf(path, sizeof path, "%s/read.json", dir);
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    if (!f)
        return;
    struct mps_json j;
    mps_json_begin(&j, f);
    mps_json_object(&j, "inner");
    mps_json_num(&j, "lost_particles", 5);
    mps_json_close(&j);
    mps_json_str(&j, "text", "\"lost_particles\": 6");
    mps_json_int(&j, "lost_particles", 12);
    mps_json_end(&j);
    CHECK(fclose(f) == 0);
    char *text = slurp(path);
    CHECK(text && mps_json_top_number(text, "lost_particles", &v) == 1 && v == 12.0);
    free(text);
}

static void test_cli(void)
{
    struct mps_cli cli;
    struct mps_err err = {0};
    struct mps_cli_extra ex[3] = {
        {"--model", 1, "solid model (mps|tlsph)", NULL},
        {"--dry-run", 0, "check the case and stop", NULL},
        {"--port", 1, "coupler port", NULL},
    };

    const char *ok1[] = {"case.yml", "--out", "run1", "--set", "fluid.rho=998",
                         "--set=dp=0.002", "--quiet", "--model", "tlsph", "--dry-run", NULL};
    CHECK(parse(&cli, ex, 3, &err, ok1) == MPS_OK);
    CHECK_STR(cli.case_path, "case.yml");
    CHECK_STR(cli.out_dir, "run1");
    CHECK(cli.nsets == 2);
    CHECK_STR(cli.sets[0], "fluid.rho=998");
    CHECK_STR(cli.sets[1], "dp=0.002");
    CHECK(cli.quiet == 1);
    CHECK_STR(ex[0].value, "tlsph");
    CHECK_STR(ex[1].value, "1");
    CHECK(ex[2].value == NULL);

    const char *ok2[] = {"--out=run2", "--model=mps", "cases/dam.yml", NULL};
    CHECK(parse(&cli, ex, 3, &err, ok2) == MPS_OK);
    CHECK_STR(cli.case_path, "cases/dam.yml");
    CHECK_STR(cli.out_dir, "run2");
    CHECK(cli.nsets == 0 && cli.quiet == 0);
    CHECK_STR(ex[0].value, "mps");
    CHECK(ex[1].value == NULL); /* reset by each parse */

    const char *ok3[] = {"c.yml", NULL}; /* --out is optional here; extras may be NULL */
    CHECK(parse(&cli, NULL, 0, &err, ok3) == MPS_OK);
    CHECK(cli.out_dir == NULL);

    struct {
        const char *args[6];
        const char *msg;
    } bad[] = {
        {{"case.yml", "--foo", NULL}, "unknown option '--foo' (see --help)"},
        {{"case.yml", "-x", NULL}, "unknown option '-x' (see --help)"},
        {{"case.yml", "--set", "dp", NULL}, "--set needs key=value, got 'dp'"},
        {{"case.yml", "--set=dp", NULL}, "--set needs key=value, got 'dp'"},
        {{"case.yml", "--set", "=1", NULL}, "--set needs key=value, got '=1'"},
        {{"case.yml", "--set", NULL}, "--set needs key=value"},
        {{"case.yml", "--set", "--quiet", NULL}, "--set needs key=value"},
        {{"--out", "run", NULL}, "missing case file (see --help)"},
        {{"case.yml", "--out", NULL}, "--out needs a directory"},
        {{"case.yml", "--out=", NULL}, "--out needs a directory"},
        {{"a.yml", "b.yml", NULL},
         "unexpected argument 'b.yml': the case file is already 'a.yml' (only one is accepted)"},
        {{"case.yml", "--model", NULL}, "--model needs a value"},
        {{"case.yml", "--dry-run=yes", NULL}, "--dry-run takes no value, got '--dry-run=yes'"},
        {{"case.yml", "--modelx", "1", NULL}, "unknown option '--modelx' (see --help)"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
        mps_err_clear(&err);
        CHECK(parse(&cli, ex, 3, &err, bad[k].args) == MPS_EINPUT);
        CHECK(err.code == MPS_EINPUT);
        CHECK_STR(err.msg, bad[k].msg);
    }

    const char *help[] = {"--foo", "--help", NULL};
    fflush(stdout);
    CHECK(parse(&cli, ex, 3, &err, help) == MPS_EINTR);

    /* --keys wins as --help does (no case file needed) and says so for main
     * to print its tables */
    const char *keys[] = {"--out", "--keys", NULL};
    mps_err_clear(&err);
    CHECK(parse(&cli, ex, 3, &err, keys) == MPS_EINTR);
    CHECK(cli.keys == 1);
    CHECK(parse(&cli, ex, 3, &err, ok3) == MPS_OK && cli.keys == 0);

    const char *dashdash[] = {"--quiet", "--", "--odd-name.yml", NULL};
    CHECK(parse(&cli, ex, 3, &err, dashdash) == MPS_OK);
    CHECK_STR(cli.case_path, "--odd-name.yml");
}

static void test_mkdir(void)
{
    struct mps_err err = {0};
    char path[256];
    snprintf(path, sizeof path, "%s/a/b//c/", dir);
    CHECK(mps_mkdir_p(path, &err) == MPS_OK);
    struct stat st;
    snprintf(path, sizeof path, "%s/a/b/c", dir);
    CHECK(stat(path, &st) == 0 && S_ISDIR(st.st_mode));
    CHECK(mps_mkdir_p(path, &err) == MPS_OK); /* exists: fine */
    snprintf(path, sizeof path, "%s/file", dir);
    FILE *f = fopen(path, "w");
    fclose(f);
    snprintf(path, sizeof path, "%s/file/sub", dir);
    CHECK(mps_mkdir_p(path, &err) == MPS_EIO);
    CHECK(strstr(err.msg, path) != NULL);
    printf("expected error: %s\n", err.msg);
    CHECK(mps_mkdir_p("", &err) == MPS_EINPUT);
}

static void test_timer_progress(void)
{
    const char *names[] = {"a", "b"};
    struct mps_timer t;
    mps_timer_init(&t, names, 2);
    double w0 = mps_wall_seconds();
    mps_timer_switch(&t, 0);
    struct timespec ts = {0, 20 * 1000 * 1000};
    nanosleep(&ts, NULL);
    mps_timer_switch(&t, 1);
    mps_timer_stop(&t);
    double w1 = mps_wall_seconds();
    CHECK(t.seconds[0] >= 0.015 && t.seconds[0] <= w1 - w0);
    CHECK(t.seconds[1] >= 0.0 && t.open_phase < 0);
    CHECK_NEAR(mps_timer_total(&t), t.seconds[0] + t.seconds[1], 1e-15);

    struct mps_progress p;
    mps_progress_init(&p, "fluid", 1.0, 1);
    mps_progress_update(&p, 0.5, 10);
    mps_progress_finish(&p, 1.0, 20);
    CHECK(p.printed == 0);

    /* the ETA of a restart: resumed at 9.9 s of a run to 10 s, halfway after
     * 10 s of wall time the rest takes 10 s more (the first update is the
     * baseline and prints nothing) */
    struct mps_progress r;
    mps_progress_init(&r, "coupled", 10.0, 0);
    CHECK(mps_progress_eta(&r, 9.9, mps_wall_seconds()) < 0.0); /* no update yet */
    mps_progress_update(&r, 9.9, 24157);
    CHECK(r.printed == 0);
    CHECK(mps_progress_eta(&r, 9.9, r.wall_base + 1.0) < 0.0); /* no progress yet */
    CHECK_NEAR(mps_progress_eta(&r, 9.95, r.wall_base + 10.0), 10.0, 1e-9);
}

int main(void)
{
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    test_probes();
    test_json();
    test_json_read();
    test_cli();
    test_mkdir();
    test_timer_progress();
    int rc = test_summary("test_probes_json_cli");
    if (rc == 0) {
        char cmd[256];
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
        if (system(cmd) != 0)
            fprintf(stderr, "could not remove %s\n", dir);
    } else {
        fprintf(stderr, "output kept in %s\n", dir);
    }
    return rc;
}
