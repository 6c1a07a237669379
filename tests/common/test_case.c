/* Case files: flattening, getters, defaults, --set, every load error, ignored
 * prefixes, resolved-YAML round trip, and the getters' aborts on misuse. */
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "../test_util.h"
#include "mps_case.h"

static const struct mps_key_spec test_keys[] = {
    {"fluid.rho", MPS_KEY_DOUBLE, "1000", 0, 0, MPS_KEY_LO_OPEN | MPS_KEY_NO_HI, NULL, "kg/m^3",
     "fluid density"},
    {"fluid.c0", MPS_KEY_DOUBLE, NULL, 0, 0, MPS_KEY_LO_OPEN | MPS_KEY_NO_HI, NULL, "m/s",
     "speed of sound"},
    {"fluid.alpha", MPS_KEY_DOUBLE, "0.1", 0, 0.5, MPS_KEY_HI_OPEN, NULL, "", "damping"},
    {"fluid.nsteps", MPS_KEY_INT, "10", 1, 1000, 0, NULL, "", "steps"},
    {"fluid.verbose", MPS_KEY_BOOL, "no", 0, 0, 0, NULL, "", "chatty"},
    {"fluid.gradient", MPS_KEY_ENUM, "corrected", 0, 0, 0, "corrected|plain", "",
     "pressure gradient"},
    {"fluid.blocks.*.x0", MPS_KEY_DOUBLE, NULL, 0, 0,
     MPS_KEY_REQUIRED | MPS_KEY_NO_LO | MPS_KEY_NO_HI, NULL, "m", "block left edge"},
    {"fluid.blocks.*.x1", MPS_KEY_DOUBLE, NULL, 0, 0,
     MPS_KEY_REQUIRED | MPS_KEY_NO_LO | MPS_KEY_NO_HI, NULL, "m", "block right edge"},
    {"fluid.blocks.*.kind", MPS_KEY_ENUM, "water", 0, 0, 0, "water|oil", "", "liquid"},
    {"probes.*", MPS_KEY_STRING, NULL, 0, 0, 0, NULL, "", "probe name"},
    {"fluid.table", MPS_KEY_STRING, "", 0, 0, MPS_KEY_PATH, NULL, "", "a file"},
    {.name = NULL},
};

static const struct mps_key_spec *const tables[] = {mps_case_common_keys, test_keys};
static const char *const ignore[] = {"solid.", NULL};

static const char good_yaml[] =
    "# a comment\n"
    "description: \"dam break\"\n"
    "dp: 0.01\n"
    "end_time: 1.5\n"
    "gravity:\n"
    "  y: -9.8\n"
    "fluid:\n"
    "  rho: 998.2\n"
    "  nsteps: 20\n"
    "  verbose: yes\n"
    "  gradient: plain\n"
    "  blocks:\n"
    "    - x0: 0\n"
    "      x1: 0.5\n"
    "    - {x0: 1, x1: 2, kind: oil}\n"
    "probes: [p0, p1, p2]\n"
    "empty_map: {}\n"
    "solid:\n"
    "  anything: goes\n"
    "  deeper: [1, {a: b}]\n"
    "  none: {}\n";

static char tmp_paths[64][64];
static int ntmp;

/* Writes text to a new temporary file; returns its path. */
static const char *write_tmp(const char *text)
{
    if (ntmp == 64)
        abort(); /* raise tmp_paths */
    char *p = tmp_paths[ntmp++];
    snprintf(p, sizeof tmp_paths[0], "/tmp/test_case_XXXXXX");
    int fd = mkstemp(p);
    if (fd < 0) {
        perror("mkstemp");
        exit(1);
    }
    FILE *f = fdopen(fd, "w");
    fputs(text, f);
    fclose(f);
    return p;
}

static struct mps_case *load(const char *path, const char *const *sets, int nsets,
                             struct mps_err *err)
{
    struct mps_case *c = (struct mps_case *)1;
    mps_err_clear(err);
    enum mps_status st = mps_case_load(&c, path, sets, nsets, tables, 2, ignore, err);
    CHECK((st == MPS_OK) == (c != NULL));
    if (st != MPS_OK)
        CHECK(c == NULL && err->code == st);
    return c;
}

/* Loads text (+ sets) expecting failure, and checks that the message contains
 * every one of the given fragments. "@" in a fragment stands for the path. */
static void expect_error(const char *text, const char *const *sets, int nsets,
                         const char *f1, const char *f2, const char *f3)
{
    struct mps_err err;
    const char *path = write_tmp(text);
    struct mps_case *c = load(path, sets, nsets, &err);
    CHECK(c == NULL);
    mps_case_destroy(&c);
    const char *frags[] = {f1, f2, f3};
    for (int i = 0; i < 3; i++) {
        if (!frags[i])
            continue;
        char want[512];
        const char *at = strchr(frags[i], '@');
        if (at)
            snprintf(want, sizeof want, "%.*s%s%s", (int)(at - frags[i]), frags[i], path,
                     at + 1);
        else
            snprintf(want, sizeof want, "%s", frags[i]);
        if (!strstr(err.msg, want)) {
            test_failures++;
            fprintf(stderr, "expected \"%s\" in error:\n%s\n", want, err.msg);
        }
        test_checks++;
    }
}

static void test_good(void)
{
    struct mps_err err;
    const char *path = write_tmp(good_yaml);
    struct mps_case *c = load(path, NULL, 0, &err);
    CHECK(c != NULL);
    if (!c) {
        fprintf(stderr, "%s\n", err.msg);
        return;
    }
    CHECK_NEAR(mps_case_double(c, "dp"), 0.01, 0);
    CHECK_NEAR(mps_case_double(c, "end_time"), 1.5, 0);
    CHECK_NEAR(mps_case_double(c, "gravity.y"), -9.8, 0);
    CHECK_NEAR(mps_case_double(c, "gravity.x"), 0, 0);             /* default */
    CHECK_NEAR(mps_case_double(c, "output.interval"), 0.05, 0);    /* default */
    CHECK_NEAR(mps_case_double(c, "fluid.rho"), 998.2, 0);
    CHECK_NEAR(mps_case_double(c, "fluid.alpha"), 0.1, 0);         /* default */
    CHECK(mps_case_int(c, "fluid.nsteps") == 20);
    CHECK_NEAR(mps_case_double(c, "fluid.nsteps"), 20, 0);         /* int as double */
    CHECK(mps_case_bool(c, "fluid.verbose") == 1);
    CHECK(strcmp(mps_case_string(c, "fluid.gradient"), "plain") == 0);
    CHECK(strcmp(mps_case_string(c, "description"), "dam break") == 0);
    CHECK(mps_case_count(c, "fluid.blocks") == 2);
    CHECK(mps_case_count(c, "probes") == 3);
    CHECK(mps_case_count(c, "solid.deeper") == 2);
    CHECK(mps_case_count(c, "nothing.here") == 0);
    CHECK(mps_case_count(c, "empty_map") == 0);
    for (int i = 0; i < 2; i++)
        CHECK_NEAR(mps_case_double(c, "fluid.blocks.%d.x1", i), i ? 2 : 0.5, 0);
    CHECK(strcmp(mps_case_string(c, "fluid.blocks.%d.kind", 0), "water") == 0); /* default */
    CHECK(strcmp(mps_case_string(c, "fluid.blocks.%d.kind", 1), "oil") == 0);
    CHECK(strcmp(mps_case_string(c, "probes.%d", 2), "p2") == 0);
    CHECK(mps_case_has(c, "fluid.c0") == 0);
    CHECK(mps_case_has(c, "fluid.rho") == 1);
    CHECK(mps_case_has(c, "fluid.blocks.7.kind") == 1); /* spec default */
    CHECK(mps_case_has(c, "fluid.blocks.7.x0") == 0);
    CHECK(mps_case_has(c, "solid.anything") == 1);
    CHECK(mps_case_has(c, "solid.deeper.1.a") == 1);
    CHECK(mps_case_has(c, "solid.missing") == 0);

    char want[128];
    snprintf(want, sizeof want, "%s:3", path);
    CHECK(strcmp(mps_case_where(c, "dp"), want) == 0);
    snprintf(want, sizeof want, "%s:15", path);
    CHECK(strcmp(mps_case_where(c, "fluid.blocks.1.x0"), want) == 0);
    CHECK(strcmp(mps_case_where(c, "gravity.x"), "default") == 0);
    CHECK(strcmp(mps_case_path(c), path) == 0);
    CHECK(strcmp(mps_case_dir(c), "/tmp") == 0);

    CHECK(mps_case_fail(c, &err, "fluid.rho", "must exceed %d", 1000) == MPS_EINPUT);
    snprintf(want, sizeof want, "%s:8: fluid.rho = 998.2: must exceed 1000", path);
    CHECK(strcmp(err.msg, want) == 0);

    /* a section points at its first key */
    CHECK(mps_case_fail(c, &err, "fluid.blocks", "%d blocks: too many", 2) == MPS_EINPUT);
    snprintf(want, sizeof want, "%s:13: fluid.blocks: 2 blocks: too many", path);
    CHECK(strcmp(err.msg, want) == 0);
    snprintf(want, sizeof want, "%s:13", path);
    CHECK(strcmp(mps_case_where(c, "fluid.blocks"), want) == 0);
    CHECK(strcmp(mps_case_where(c, "nowhere"), path) == 0);

    char *y = mps_case_resolved_yaml(c);
    CHECK(y != NULL);
    if (y) {
        CHECK(strstr(y, "anything: goes") != NULL); /* ignored keys kept */
        CHECK(strstr(y, "probe_interval: 0.001") != NULL); /* defaults included */
        CHECK(strstr(y, "dp: 0.01") != NULL);
        /* sorted: description < dp < end_time < fluid < gravity */
        CHECK(strstr(y, "description") < strstr(y, "dp:"));
        CHECK(strstr(y, "fluid:") < strstr(y, "gravity:"));
    }
    free(y);
    mps_case_destroy(&c);
    CHECK(c == NULL);
    mps_case_destroy(&c); /* NULL is fine */
}

static void test_set(void)
{
    struct mps_err err;
    const char *path = write_tmp(good_yaml);
    const char *sets[] = {"dp=0.02", "fluid.blocks.3.x0=3", " fluid.blocks.3.x1 = 4 ",
                          "description='hello world'", "gravity.x=1.5", "solid.new.key=x"};
    struct mps_case *c = load(path, sets, 6, &err);
    CHECK(c != NULL);
    if (!c) {
        fprintf(stderr, "%s\n", err.msg);
        return;
    }
    CHECK_NEAR(mps_case_double(c, "dp"), 0.02, 0);
    CHECK(strcmp(mps_case_where(c, "dp"), "--set dp=0.02") == 0);
    CHECK(mps_case_count(c, "fluid.blocks") == 4);
    CHECK_NEAR(mps_case_double(c, "fluid.blocks.3.x1"), 4, 0);
    CHECK(strcmp(mps_case_string(c, "fluid.blocks.3.kind"), "water") == 0); /* item default */
    CHECK(strcmp(mps_case_string(c, "description"), "hello world") == 0);
    CHECK_NEAR(mps_case_double(c, "gravity.x"), 1.5, 0);
    CHECK(strcmp(mps_case_where(c, "gravity.x"), "--set gravity.x=1.5") == 0);
    CHECK(mps_case_has(c, "solid.new.key") == 1);
    /* item 2 does not exist: no default filled in for it */
    CHECK(strcmp(mps_case_where(c, "fluid.blocks.2.kind"), "default") == 0);

    CHECK(mps_case_fail(c, &err, "dp", "too coarse") == MPS_EINPUT);
    CHECK(strcmp(err.msg, "--set dp=0.02: dp = 0.02: too coarse") == 0);
    mps_case_destroy(&c);
}

static void test_errors(void)
{
    const char *base = "dp: 0.01\nend_time: 1\n";
    char text[512];

    snprintf(text, sizeof text, "%sfluid:\n  rhoo: 1000\n", base);
    expect_error(text, NULL, 0, "@:4: fluid.rhoo = 1000: unknown key", "did you mean fluid.rho?",
                 NULL);
    /* the suggestion keeps the item's index (an empty first item, so that
     * the one-line message starts with item 1) */
    snprintf(text, sizeof text, "%sfluid:\n  blcks:\n    - {}\n    - {x0: 0}\n", base);
    expect_error(text, NULL, 0, "@:6: fluid.blcks.1.x0 = 0: unknown key",
                 "did you mean fluid.blocks.1.x0?", NULL);
    /* one line however many problems: the first, the count, the next */
    expect_error("dp: -1\nend_time: 0\ngravity: {x: a}\n", NULL, 0, "@:1: dp = -1: must be > 0",
                 "(and 2 more problems; the next: @:2: end_time = 0: must be in (0, 10000])", NULL);
    expect_error("dp: 0.01\nend_tmie: 1\n", NULL, 0, "@:2: end_tmie = 1: unknown key",
                 "did you mean end_time?", "@: missing required key 'end_time'");
    expect_error("dp: 0.01\nend_time: 1\nzzz: 1\n", NULL, 0, "@:3: zzz = 1: unknown key", NULL,
                 NULL);

    expect_error("dp: abc\nend_time: 1\n", NULL, 0, "@:1: dp = abc: must be a number", NULL,
                 NULL);
    expect_error("dp: 0.01\nend_time: inf\n", NULL, 0, "@:2: end_time = inf: must be a finite",
                 NULL, NULL);
    snprintf(text, sizeof text, "%sfluid: {nsteps: 2.5}\n", base);
    expect_error(text, NULL, 0, "@:3: fluid.nsteps = 2.5: must be an integer", NULL, NULL);
    snprintf(text, sizeof text, "%sfluid: {verbose: maybe}\n", base);
    expect_error(text, NULL, 0, "@:3: fluid.verbose = maybe: must be true or false", NULL, NULL);

    /* bounds: open lower, closed range, half-open range */
    expect_error("\ndp: -0.003\nend_time: 1\n", NULL, 0, "@:2: dp = -0.003: must be > 0", NULL,
                 NULL);
    expect_error("dp: 0\nend_time: 1\n", NULL, 0, "@:1: dp = 0: must be > 0", NULL, NULL);
    snprintf(text, sizeof text, "%sfluid: {nsteps: 0}\n", base);
    expect_error(text, NULL, 0, "@:3: fluid.nsteps = 0: must be in [1, 1000]", NULL, NULL);
    snprintf(text, sizeof text, "%sfluid: {alpha: 0.5}\n", base);
    expect_error(text, NULL, 0, "@:3: fluid.alpha = 0.5: must be in [0, 0.5)", NULL, NULL);
    snprintf(text, sizeof text, "%soutput: {interval: -1}\n", base);
    expect_error(text, NULL, 0, "@:3: output.interval = -1: must be >= 0", NULL, NULL);

    snprintf(text, sizeof text, "%sfluid: {gradient: fancy}\n", base);
    expect_error(text, NULL, 0,
                 "@:3: fluid.gradient = fancy: must be one of corrected, plain", NULL, NULL);

    expect_error("end_time: 1\n", NULL, 0,
                 "@: missing required key 'dp' (initial particle spacing, m)", NULL, NULL);
    snprintf(text, sizeof text, "%sfluid:\n  blocks:\n    - {x0: 0, x1: 1}\n    - {x0: 2}\n",
             base);
    expect_error(text, NULL, 0,
                 "@: missing required key 'fluid.blocks.1.x1' (block right edge, m)", NULL, NULL);

    /* several problems are reported together */
    expect_error("dp: -1\nend_time: 0\n", NULL, 0, "@:1: dp = -1: must be > 0",
                 "@:2: end_time = 0: must be in (0, 10000]", NULL);

    expect_error("dp: [1, 2\nend_time: 1\n", NULL, 0, "YAML syntax error", "@:", NULL);
    expect_error("dp: 1\n  end_time: 1\n", NULL, 0, "@:2: YAML syntax error:", NULL, NULL);
    expect_error("dp: 1\nend_time: 1\ndp: 2\n", NULL, 0,
                 "@:3: duplicate key 'dp' (first given at line 1)", NULL, NULL);
    expect_error("dp: 1\nend_time: 1\ngravity: {x: 0}\ngravity:\n  y: 0\n", NULL, 0,
                 "@:4: duplicate key 'gravity'", NULL, NULL);
    expect_error("dp: 1\nend_time: 1\ngravity.x: 0\ngravity: {x: 1}\n", NULL, 0,
                 "@:4: duplicate key 'gravity.x'", NULL, NULL);
    expect_error("- 1\n- 2\n", NULL, 0, "@:1: the top level must be a mapping", NULL, NULL);
    expect_error("a: &x 1\nb: *x\n", NULL, 0, "@:2: YAML aliases are not supported", NULL, NULL);

    const char *s1[] = {"dp"};
    expect_error(base, s1, 1, "--set dp: expected key=value", NULL, NULL);
    const char *s2[] = {"dp=-1"};
    expect_error(base, s2, 1, "--set dp=-1: dp = -1: must be > 0", NULL, NULL);
    const char *s3[] = {"fluid.rhoo=1"};
    expect_error(base, s3, 1, "--set fluid.rhoo=1: fluid.rhoo = 1: unknown key",
                 "did you mean fluid.rho?", NULL);
    const char *s4[] = {"gravity=1", "gravity.x=2"};
    expect_error(base, s4, 2, "--set gravity.x=2: gravity.x = 2: conflicts with gravity", NULL,
                 NULL);
    const char *s5[] = {"=1"};
    expect_error(base, s5, 1, "--set =1: '' is not a key name", NULL, NULL);

    struct mps_err err;
    struct mps_case *c = (struct mps_case *)1;
    CHECK(mps_case_load(&c, "cases/no_such_case/case.yml", NULL, 0, tables, 2, NULL, &err) ==
          MPS_EIO);
    CHECK(c == NULL);
    CHECK(strcmp(err.msg, "cases/no_such_case/case.yml: cannot open: No such file or directory") ==
          0);
}

/* Without the ignore prefix, solid.* keys are unknown. */
static void test_ignore(void)
{
    struct mps_err err;
    const char *path = write_tmp("dp: 1\nend_time: 1\nsolid: {E: 1e6}\n");
    struct mps_case *c = NULL;
    CHECK(mps_case_load(&c, path, NULL, 0, tables, 2, NULL, &err) == MPS_EINPUT);
    CHECK(strstr(err.msg, "solid.E = 1e6: unknown key") != NULL);
    c = load(path, NULL, 0, &err);
    CHECK(c != NULL);
    CHECK(c && strcmp(mps_case_where(c, "solid.E"), "") != 0);
    mps_case_destroy(&c);
}

/* The UTF-8 check every key and value passes (the resolved case is YAML):
 * each kind of malformed sequence, and the longest well-formed ones. */
static void test_utf8(void)
{
    static const struct {
        const char *s;
        size_t n;
    } seqs[] = {
        {"a", 1},
        {"\xc3\xa9", 2},         /* U+00E9 */
        {"\xe2\x82\xac", 3},     /* U+20AC */
        {"\xf0\x9f\x98\x80", 4}, /* U+1F600 */
        {"\xf4\x8f\xbf\xbf", 4}, /* U+10FFFF, the last code point */
        {"\xff", 0},             /* never a lead byte */
        {"\x80", 0},             /* a continuation byte first */
        {"\xc3", 0},             /* cut short */
        {"\xc3\x41", 0},         /* not a continuation */
        {"\xc0\x80", 0},         /* overlong NUL */
        {"\xe0\x80\xaf", 0},     /* overlong '/' */
        {"\xed\xa0\x80", 0},     /* a surrogate, U+D800 */
        {"\xf4\x90\x80\x80", 0}, /* past U+10FFFF */
        {"", 0},
    };
    for (size_t i = 0; i < sizeof seqs / sizeof seqs[0]; i++)
        CHECK(mps_utf8_seq((const unsigned char *)seqs[i].s) == seqs[i].n);

    /* by key, in a declared string, an undeclared key under an ignored
     * prefix, and a key itself; the bytes shown as \xNN */
    const char *base = "dp: 1\nend_time: 1\n";
    const char *s1[] = {"probes.0=a\xff"};
    expect_error(base, s1, 1, "probes.0 = a\\xff: must be UTF-8 text", NULL, NULL);
    const char *s2[] = {"solid.note=caf\xe9"};
    expect_error(base, s2, 1, "solid.note = caf\\xe9: must be UTF-8 text", NULL, NULL);
    const char *s3[] = {"solid.\xc0\x80=1"};
    expect_error(base, s3, 1, "solid.\\xc0\\x80 = 1: must be UTF-8 text", NULL, NULL);
    const char *s4[] = {"description=caf\xc3\xa9 \xe2\x82\xac"}; /* well formed */
    struct mps_err err;
    struct mps_case *c = load(write_tmp(base), s4, 1, &err);
    CHECK(c != NULL);
    char *y = c ? mps_case_resolved_yaml(c) : NULL;
    CHECK(y && strstr(y, "caf\xc3\xa9 \xe2\x82\xac"));
    free(y);
    mps_case_destroy(&c);

    /* a case file's path that is not UTF-8 (it goes into the records) */
    char dir[] = "/tmp/test_case_XXXXXX", bad_dir[64], bad_path[96], cwd[4096];
    CHECK(mkdtemp(dir) != NULL);
    snprintf(bad_dir, sizeof bad_dir, "%s/d\xe9", dir);
    CHECK(mkdir(bad_dir, 0700) == 0);
    snprintf(bad_path, sizeof bad_path, "%s/case.yml", bad_dir);
    FILE *f = fopen(bad_path, "w");
    CHECK(f && fputs("dp: 1\nend_time: 1\nfluid: {table: t.csv}\n", f) >= 0 && fclose(f) == 0);
    c = (struct mps_case *)1;
    CHECK(mps_case_load(&c, bad_path, NULL, 0, tables, 2, ignore, &err) == MPS_EINPUT && !c);
    CHECK(strstr(err.msg, "/d\\xe9/case.yml: the case file's path must be UTF-8 text"));
    /* loaded by a relative path from inside that directory, the path key's
     * absolute form is not UTF-8: refused by key when the resolved case is
     * written, not written half */
    CHECK(getcwd(cwd, sizeof cwd) && chdir(bad_dir) == 0);
    c = load("case.yml", NULL, 0, &err);
    char out[96];
    snprintf(out, sizeof out, "%s/resolved.yml", dir);
    CHECK(c && mps_case_write_resolved(c, out, NULL, &err) == MPS_EINPUT);
    CHECK(strstr(err.msg, "case.yml:3: fluid.table = t.csv: its absolute path ") &&
          strstr(err.msg, "/d\\xe9/t.csv must be UTF-8 text"));
    CHECK(access(out, F_OK) != 0);
    mps_case_destroy(&c);
    CHECK(chdir(cwd) == 0);
    remove(bad_path);
    rmdir(bad_dir);
    rmdir(dir);
}

static void test_round_trip(void)
{
    struct mps_err err;
    const char *path = write_tmp(good_yaml);
    /* strings that need quoting, a hole in a sequence, a multi-line value */
    const char *sets[] = {"description=line one\nline two: with colon",
                          "fluid.blocks.3.x0=7",
                          "fluid.blocks.3.x1=8",
                          "probes.1=- not a list",
                          "probes.2=#hash",
                          "probes.4=",
                          "solid.odd='yes'",
                          "solid.deeper.5.k=  spaced  "};
    struct mps_case *c = load(path, sets, 8, &err);
    CHECK(c != NULL);
    if (!c) {
        fprintf(stderr, "%s\n", err.msg);
        return;
    }
    char *out = tmp_paths[ntmp++];
    snprintf(out, sizeof tmp_paths[0], "/tmp/test_case_XXXXXX");
    int fd = mkstemp(out);
    CHECK(fd >= 0);
    close(fd);
    CHECK(mps_case_write_resolved(c, out, "# note: kept\n", &err) == MPS_OK);
    struct mps_case *r = load(out, NULL, 0, &err);
    CHECK(r != NULL);
    if (!r) {
        fprintf(stderr, "%s\n", err.msg);
        mps_case_destroy(&c);
        return;
    }
    char *y1 = mps_case_resolved_yaml(c), *y2 = mps_case_resolved_yaml(r);
    CHECK(y1 && y2 && strcmp(y1, y2) == 0);
    if (y1 && y2 && strcmp(y1, y2) != 0)
        fprintf(stderr, "--- first\n%s--- reloaded\n%s", y1, y2);
    free(y1);
    free(y2);
    CHECK(strcmp(mps_case_string(r, "description"), "line one\nline two: with colon") == 0);
    CHECK(strcmp(mps_case_string(r, "probes.1"), "- not a list") == 0);
    CHECK(strcmp(mps_case_string(r, "probes.4"), "") == 0);
    CHECK(mps_case_has(r, "probes.3") == 0);
    CHECK(mps_case_count(r, "probes") == 5);
    CHECK(mps_case_count(r, "fluid.blocks") == 4);
    CHECK_NEAR(mps_case_double(r, "fluid.blocks.3.x1"), 8, 0);
    CHECK(mps_case_has(r, "solid.odd") && mps_case_has(r, "solid.none") == 0);
    /* Each key keeps where the user gave it (the file's line, --set, the
     * default), so a solver that finds a problem in the copy names the
     * user's file: fluid.rho is line 8 of good_yaml, solid.anything line 19. */
    char want[300];
    snprintf(want, sizeof want, "%s:8", path);
    CHECK(strcmp(mps_case_where(r, "fluid.rho"), want) == 0);
    CHECK(strcmp(mps_case_where(r, "fluid.blocks.3.x0"), "--set fluid.blocks.3.x0=7") == 0);
    CHECK(strcmp(mps_case_where(r, "gravity.x"), "default") == 0);
    /* a --set holding a line break cannot be one comment line: the copy's line */
    CHECK(strncmp(mps_case_where(r, "description"), out, strlen(out)) == 0);
    mps_err_clear(&err);
    CHECK(mps_case_fail(r, &err, "fluid.rho", "too dense") == MPS_EINPUT);
    snprintf(want, sizeof want, "%s:8: fluid.rho = 998.2: too dense", path);
    CHECK(strcmp(err.msg, want) == 0);
    /* a program that does not ignore solid.* names the user's line too */
    struct mps_case *strict = (struct mps_case *)1;
    CHECK(mps_case_load(&strict, out, NULL, 0, tables, 2, NULL, &err) == MPS_EINPUT);
    snprintf(want, sizeof want, "%s:19: solid.anything = goes: unknown key", path);
    CHECK(strict == NULL && strncmp(err.msg, want, strlen(want)) == 0);
    if (strncmp(err.msg, want, strlen(want)) != 0)
        fprintf(stderr, "  got:  %s\n  want: %s\n", err.msg, want);
    mps_case_destroy(&c);
    mps_case_destroy(&r);
    /* a value edited in the copy is the copy's: its line is named */
    FILE *f = fopen(out, "r+");
    char text[8192];
    size_t n = f ? fread(text, 1, sizeof text - 1, f) : 0;
    text[n] = '\0';
    char *rho = strstr(text, "rho: 998.2\n");
    CHECK(f && rho);
    if (f && rho) {
        memcpy(rho, "rho: 998.3", 10);
        rewind(f);
        fputs(text, f);
    }
    CHECK(f && fclose(f) == 0);
    r = load(out, NULL, 0, &err);
    CHECK(r && strncmp(mps_case_where(r, "fluid.rho"), out, strlen(out)) == 0);
    snprintf(want, sizeof want, "%s:9", path); /* fluid.nsteps: unchanged */
    CHECK(r && strcmp(mps_case_where(r, "fluid.nsteps"), want) == 0);
    mps_case_destroy(&r);
    /* origin lines count only in a resolved file (its first line says so) */
    const char *plain = write_tmp("dp: 0.01\nend_time: 1\n#@ dp\tspoof.yml:1\n");
    struct mps_case *p = load(plain, NULL, 0, &err);
    snprintf(want, sizeof want, "%s:1", plain);
    CHECK(p && strcmp(mps_case_where(p, "dp"), want) == 0);
    mps_case_destroy(&p);
}

/* Programmer errors abort: run each in a child and expect SIGABRT. */
static void expect_abort(const struct mps_case *c, int which)
{
    fflush(NULL);
    pid_t pid = fork();
    if (pid == 0) {
        if (!freopen("/dev/null", "w", stderr))
            _exit(3);
        switch (which) {
        case 0: mps_case_double(c, "fluid.nope"); break;         /* undeclared */
        case 1: mps_case_int(c, "dp"); break;                    /* wrong type */
        case 2: mps_case_double(c, "fluid.c0"); break;           /* absent, no default */
        case 3: mps_case_string(c, "solid.anything"); break;     /* ignored, not declared */
        case 4: mps_case_bool(c, "fluid.gradient"); break;       /* wrong type */
        case 5: mps_case_has(c, "fluid.typo"); break;            /* undeclared */
        }
        _exit(0);
    }
    int status = 0;
    waitpid(pid, &status, 0);
    CHECK(WIFSIGNALED(status) && WTERMSIG(status) == SIGABRT);
}

/* --keys: every key of every table, once, with its type, default, bounds and
 * help, under its table's title */
static void test_print_keys(void)
{
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    CHECK(f != NULL);
    const char *const titles[] = {"Common", "Test"};
    mps_case_print_keys(f, tables, titles, 2);
    CHECK(fclose(f) == 0);
    const char *want[] = {
        "## Common\n\n- `dp` (number, m, required, > 0): initial particle spacing\n",
        "\n\n## Test\n\n- `fluid.rho` (number, kg/m^3, default 1000, > 0): fluid density\n",
        "- `fluid.c0` (number, m/s, no default: off when absent, > 0): speed of sound\n",
        "- `fluid.alpha` (number, default 0.1, in [0, 0.5)): damping\n",
        "- `fluid.nsteps` (integer, default 10, in [1, 1000]): steps\n",
        "- `fluid.verbose` (true/false, default no): chatty\n",
        "- `fluid.gradient` (one of `corrected`, `plain`, default corrected): pressure gradient\n",
        "- `fluid.blocks.*.x0` (number, m, required): block left edge\n",
        "- `probes.*` (text, no default: off when absent): probe name\n",
        "- `fluid.table` (file path): a file\n",
    };
    for (size_t k = 0; k < sizeof want / sizeof *want; k++) {
        if (!strstr(text, want[k]))
            fprintf(stderr, "test_print_keys: missing %s", want[k]);
        CHECK(strstr(text, want[k]) != NULL);
    }
    int lines = 0;
    for (const char *c = text; *c; c++)
        lines += (*c == '\n' && c[1] == '-');
    int nspecs = 0;
    for (int t = 0; t < 2; t++)
        for (const struct mps_key_spec *sp = tables[t]; sp->name; sp++)
            nspecs++;
    CHECK(lines == nspecs);
    free(text);
}

static void test_aborts(void)
{
    struct mps_err err;
    struct mps_case *c = load(write_tmp(good_yaml), NULL, 0, &err);
    CHECK(c != NULL);
    if (!c)
        return;
    for (int k = 0; k < 6; k++)
        expect_abort(c, k);
    mps_case_destroy(&c);
}

int main(void)
{
    test_good();
    test_set();
    test_errors();
    test_ignore();
    test_utf8();
    test_round_trip();
    test_print_keys();
    test_aborts();
    for (int i = 0; i < ntmp; i++)
        remove(tmp_paths[i]);
    return test_summary("test_case");
}
