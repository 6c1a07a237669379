/* The checkpoint image and files (common/mps_ckpt.h, mps_restart.h,
 * mps_probes_resume): blocks read back in order with names and sizes
 * checked, a damaged or truncated file refused, a kill while writing (a
 * stale .tmp) leaving the checkpoints readable, the last two kept, the
 * nearest to --from chosen, probes.csv cut where a checkpoint left it. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../test_util.h"
#include "mps_ckpt.h"
#include "mps_probes.h"

static void image(void)
{
    struct mps_ckpt c = {0};
    struct mps_err err = {0};
    double a[3] = {1.0, -2.5, 1e-300};
    int b = 7;
    CHECK(mps_ckpt_put(&c, "a", a, sizeof a, &err) == MPS_OK);
    CHECK(mps_ckpt_put(&c, "bee", &b, sizeof b, &err) == MPS_OK);
    CHECK(mps_ckpt_put(&c, "empty", NULL, 0, &err) == MPS_OK);
    double ra[3] = {0};
    int rb = 0;
    const void *p = NULL;
    size_t n = 1;
    CHECK(mps_ckpt_get(&c, "a", ra, sizeof ra, &err) == MPS_OK);
    CHECK(memcmp(a, ra, sizeof a) == 0);
    CHECK(mps_ckpt_get(&c, "bee", &rb, sizeof rb, &err) == MPS_OK && rb == 7);
    CHECK(mps_ckpt_get_any(&c, "empty", &p, &n, &err) == MPS_OK && n == 0);
    CHECK(mps_ckpt_get(&c, "more", &rb, sizeof rb, &err) == MPS_EINPUT); /* past the end */
    mps_ckpt_rewind(&c);
    CHECK(mps_ckpt_get(&c, "bee", &rb, sizeof rb, &err) == MPS_EINPUT); /* out of order */
    CHECK(strstr(err.msg, "'a' where 'bee'") != NULL);
    mps_ckpt_rewind(&c);
    CHECK(mps_ckpt_get(&c, "a", ra, 2 * sizeof(double), &err) == MPS_EINPUT); /* size */
    /* data in place is aligned for any type */
    mps_ckpt_rewind(&c);
    CHECK(mps_ckpt_get_any(&c, "a", &p, &n, &err) == MPS_OK && ((size_t)p & 7) == 0);
    /* a section asked for before it is read (a newer version's), wherever
     * the read position is */
    CHECK(mps_ckpt_has(&c, "a") && mps_ckpt_has(&c, "bee") && mps_ckpt_has(&c, "empty"));
    CHECK(!mps_ckpt_has(&c, "be") && !mps_ckpt_has(&c, "beee") && !mps_ckpt_has(&c, "more"));
    CHECK(mps_ckpt_get(&c, "bee", &rb, sizeof rb, &err) == MPS_OK); /* pos did not move */
    /* and where it is, read in place (the restart's record of its arithmetic) */
    const void *q = NULL;
    size_t qn = 0;
    CHECK(mps_ckpt_peek(&c, "bee", &q, &qn) && qn == sizeof rb && *(const int *)q == 7);
    CHECK(mps_ckpt_peek(&c, "empty", &q, &qn) && qn == 0);
    CHECK(!mps_ckpt_peek(&c, "more", &q, &qn) && qn == 0);
    CHECK(mps_ckpt_get_any(&c, "empty", &p, &n, &err) == MPS_OK); /* pos did not move */
    mps_ckpt_free(&c);
}

static long file_size(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fclose(f);
    return n;
}

static void files(const char *dir)
{
    struct mps_ckpt c = {0}, r = {0};
    struct mps_err err = {0};
    char path[4400], found[4400];
    for (long k = 1; k <= 4; k++) {
        mps_ckpt_clear(&c);
        double t = 0.1 * (double)k + 1e-4; /* a step past each multiple */
        CHECK(mps_ckpt_put(&c, "t", &t, sizeof t, &err) == MPS_OK);
        CHECK(mps_ckpt_write_file(&c, dir, "p", k, t, path, sizeof path, &err) == MPS_OK);
    }
    /* the last two kept */
    mps_ckpt_path(path, sizeof path, dir, "p", 2);
    CHECK(access(path, F_OK) != 0);
    mps_ckpt_path(path, sizeof path, dir, "p", 3);
    CHECK(access(path, F_OK) == 0);
    /* latest, nearest to --from */
    CHECK(mps_ckpt_find(dir, "p", -1.0, found, sizeof found, &err) == MPS_OK);
    CHECK(strstr(found, "p_000004.ckpt") != NULL);
    CHECK(mps_ckpt_find(dir, "p", 0.3, found, sizeof found, &err) == MPS_OK);
    CHECK(strstr(found, "p_000003.ckpt") != NULL);
    CHECK(mps_ckpt_find(dir, "q", -1.0, found, sizeof found, &err) == MPS_EINPUT);
    /* a kill while writing checkpoint 5 leaves its .tmp: the others stand */
    mps_ckpt_path(path, sizeof path, dir, "p", 5);
    strcat(path, ".tmp");
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    if (f) {
        fputs("MPSCKPT1 half", f);
        fclose(f);
    }
    CHECK(mps_ckpt_find(dir, "p", -1.0, found, sizeof found, &err) == MPS_OK);
    CHECK(strstr(found, "p_000004.ckpt") != NULL);
    CHECK(mps_ckpt_read_file(&r, found, &err) == MPS_OK && r.number == 4);
    double t = 0;
    CHECK(mps_ckpt_get(&r, "t", &t, sizeof t, &err) == MPS_OK && t == r.time);
    /* a flipped byte or a cut file is refused */
    long n = file_size(found);
    f = fopen(found, "r+b");
    CHECK(f != NULL);
    if (f) {
        fseek(f, n - 12, SEEK_SET);
        int ch = fgetc(f);
        fseek(f, n - 12, SEEK_SET);
        fputc(ch ^ 1, f);
        fclose(f);
    }
    CHECK(mps_ckpt_read_file(&r, found, &err) == MPS_EINPUT && strstr(err.msg, "damaged"));
    CHECK(truncate(found, n - 20) == 0);
    CHECK(mps_ckpt_read_file(&r, found, &err) == MPS_EINPUT && strstr(err.msg, "truncated"));
    mps_ckpt_path(path, sizeof path, dir, "p", 9);
    CHECK(mps_ckpt_read_file(&r, path, &err) == MPS_EINPUT); /* none of that number */
    mps_ckpt_free(&c);
    mps_ckpt_free(&r);
}

static void probes(const char *dir)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/probes.csv", dir);
    struct mps_probes *p = NULL;
    struct mps_err err = {0};
    const char *names[1] = {"h"};
    double v = 1.0;
    CHECK(mps_probes_open(&p, path, "# made by test_ckpt\n", names, 1, &err) == MPS_OK);
    CHECK(mps_probes_write(p, 0.1, &v, &err) == MPS_OK);
    long at = mps_probes_bytes(p); /* a checkpoint here */
    v = 2.0;
    CHECK(mps_probes_write(p, 0.2, &v, &err) == MPS_OK); /* the killed run went on */
    mps_probes_close(&p);
    CHECK(mps_probes_resume(&p, path, at, 1, &err) == MPS_OK);
    CHECK(mps_probes_bytes(p) == at);
    v = 3.0;
    CHECK(mps_probes_write(p, 0.2, &v, &err) == MPS_OK);
    mps_probes_close(&p);
    char buf[512] = "";
    FILE *f = fopen(path, "r");
    size_t n = f ? fread(buf, 1, sizeof buf - 1, f) : 0;
    if (f)
        fclose(f);
    buf[n] = '\0';
    CHECK(strcmp(buf, "# made by test_ckpt\ntime,h\n0.1,1\n0.2,3\n") == 0);
    CHECK(mps_probes_resume(&p, path, 4096, 1, &err) == MPS_EINPUT); /* not that file */
}

int main(void)
{
    char dir[] = "/tmp/test_ckpt_XXXXXX";
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    image();
    files(dir);
    probes(dir);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "test_ckpt: could not remove %s\n", dir);
    return test_summary("test_ckpt");
}
