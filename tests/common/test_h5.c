/* mps_h5: snapshots read back through the HDF5 C API, the XDMF index, the
 * scene file built from two series, n = 0, and errors naming file and call. */
#include <hdf5.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../test_util.h"
#include "mps_h5.h"
#include "mps_version.h"

#define N 7

static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *b = malloc((size_t)n + 1);
    size_t got = fread(b, 1, (size_t)n, f);
    b[got] = '\0';
    fclose(f);
    return b;
}

static int count(const char *hay, const char *needle)
{
    int c = 0;
    for (const char *p = strstr(hay, needle); p; p = strstr(p + 1, needle))
        c++;
    return c;
}

/* Balanced tags: every "<Tag " / "<Tag>" opened without "/>" is closed. */
static void check_balanced(const char *text, const char *tag)
{
    char open1[64], open2[64], close[64];
    snprintf(open1, sizeof open1, "<%s ", tag);
    snprintf(open2, sizeof open2, "<%s>", tag);
    snprintf(close, sizeof close, "</%s>", tag);
    int opens = 0, selfclosed = 0;
    for (const char *p = text; (p = strchr(p, '<')); p++) {
        if (!strncmp(p, open1, strlen(open1)) || !strncmp(p, open2, strlen(open2))) {
            opens++;
            const char *gt = strchr(p, '>');
            if (gt && gt[-1] == '/')
                selfclosed++;
        }
    }
    int closes = count(text, close);
    if (opens - selfclosed != closes)
        fprintf(stderr, "tag %s: %d opened, %d self-closed, %d closed\n", tag, opens, selfclosed,
                closes);
    CHECK(opens - selfclosed == closes);
}

static void check_xml(const char *path)
{
    char *t = slurp(path);
    CHECK(t != NULL);
    if (!t)
        return;
    const char *tags[] = {"Xdmf", "Domain", "Grid", "Topology", "Geometry", "DataItem",
                          "Attribute", "Time"};
    for (size_t k = 0; k < sizeof tags / sizeof *tags; k++)
        check_balanced(t, tags[k]);
    free(t);
    if (system("command -v xmllint >/dev/null 2>&1") == 0) {
        char cmd[512];
        snprintf(cmd, sizeof cmd, "xmllint --noout '%s'", path);
        CHECK(system(cmd) == 0);
    }
}

static char *read_str_attr(hid_t obj, const char *name)
{
    hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
    if (a < 0)
        return NULL;
    hid_t t = H5Aget_type(a);
    size_t sz = H5Tget_size(t);
    char *buf = calloc(sz + 1, 1);
    CHECK(H5Tget_class(t) == H5T_STRING);
    CHECK(H5Aread(a, t, buf) >= 0);
    H5Tclose(t);
    H5Aclose(a);
    return buf;
}

static int str_attr_is(hid_t obj, const char *name, const char *want)
{
    char *s = read_str_attr(obj, name);
    int ok = s && !strcmp(s, want);
    if (!ok)
        fprintf(stderr, "attribute %s = '%s', want '%s'\n", name, s ? s : "(missing)", want);
    free(s);
    return ok;
}

/* Reads /particles/NAME: checks rank, dims, units, and returns the values. */
static int read_field(hid_t f, const char *name, hid_t mtype, size_t n, int ncomp,
                      const char *units, void *buf)
{
    char path[128];
    snprintf(path, sizeof path, "/particles/%s", name);
    hid_t d = H5Dopen2(f, path, H5P_DEFAULT);
    CHECK(d >= 0);
    if (d < 0)
        return 0;
    hid_t sp = H5Dget_space(d);
    hsize_t dims[2] = {0, 0};
    int rank = H5Sget_simple_extent_dims(sp, dims, NULL);
    CHECK(rank == (ncomp == 1 ? 1 : 2));
    CHECK(dims[0] == n);
    if (ncomp != 1)
        CHECK(dims[1] == (hsize_t)ncomp);
    CHECK(str_attr_is(d, "units", units));
    int ok = n == 0 || H5Dread(d, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) >= 0;
    CHECK(ok);
    H5Sclose(sp);
    H5Dclose(d);
    return ok;
}

static const char *yaml = "# case\nfluid:\n  rho: 1000.0\n  name: \"w\\u00e4sser\"\n";

/* Data of snapshot s, particle i: distinct for every value. */
static double xval(int s, int i, int d) { return 0.01 * i + 0.001 * d + 10.0 * s; }
static double vval(int s, int i, int d) { return -1.0 * i + 0.5 * d + 100.0 * s; }
static double pval(int s, int i) { return 1000.0 * s + i * 1.25; }
static int ival(int s, int i) { return -3 * i + 100 * s; }
static uint8_t uval(int s, int i) { return (uint8_t)(250 - i - s); }

static void write_fluid(const char *dir)
{
    struct mps_err err = {0};
    struct mps_h5_series *s = NULL;
    CHECK(mps_h5_open(&s, dir, "fluid", "fluid_solver", yaml, &err) == MPS_OK);
    if (!s) {
        fprintf(stderr, "%s\n", err.msg);
        return;
    }
    CHECK(mps_h5_count(s) == 0);
    for (int sn = 0; sn < 3; sn++) {
        double x[N][MPS_DIM], v[N][MPS_DIM], p[N];
        int id[N];
        uint8_t u[N];
        for (int i = 0; i < N; i++) {
            for (int d = 0; d < MPS_DIM; d++) {
                x[i][d] = xval(sn, i, d);
                v[i][d] = vval(sn, i, d);
            }
            p[i] = pval(sn, i);
            id[i] = ival(sn, i);
            u[i] = uval(sn, i);
        }
        struct mps_field fields[] = {
            {"velocity", MPS_DIM, MPS_F64, v, "m/s", NULL},
            {"pressure", 1, MPS_F64, p, "Pa", NULL},
            {"id", 1, MPS_I32, id, "", NULL},
            {"type", 1, MPS_U8, u, NULL, "250 this, 249 that"},
        };
        enum mps_status st = mps_h5_write(s, 0.1 * sn, 10L * sn + 1234567890123L, N,
                                          (const double(*)[MPS_DIM])x, fields, 4, &err);
        CHECK(st == MPS_OK);
        if (st != MPS_OK)
            fprintf(stderr, "%s\n", err.msg);
        CHECK(mps_h5_count(s) == sn + 1);
    }
    mps_h5_close(&s);
    CHECK(s == NULL);
    mps_h5_close(&s); /* accepts NULL */
}

static void check_fluid(const char *dir)
{
    for (int sn = 0; sn < 3; sn++) {
        char path[512];
        snprintf(path, sizeof path, "%s/fluid_%06d.h5.tmp", dir, sn);
        CHECK(access(path, F_OK) != 0); /* renamed once complete */
        snprintf(path, sizeof path, "%s/fluid_%06d.h5", dir, sn);
        hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
        CHECK(f >= 0);
        if (f < 0)
            continue;
        double t = -1.0;
        int64_t step = -1;
        hid_t a = H5Aopen(f, "time", H5P_DEFAULT);
        CHECK(a >= 0 && H5Aread(a, H5T_NATIVE_DOUBLE, &t) >= 0);
        H5Aclose(a);
        a = H5Aopen(f, "step", H5P_DEFAULT);
        hid_t at = H5Aget_type(a);
        CHECK(H5Tget_class(at) == H5T_INTEGER && H5Tget_size(at) == 8);
        H5Tclose(at);
        CHECK(a >= 0 && H5Aread(a, H5T_NATIVE_INT64, &step) >= 0);
        H5Aclose(a);
        CHECK(t == 0.1 * sn);
        CHECK(step == 10L * sn + 1234567890123L);
        CHECK(str_attr_is(f, "code_version", MPS_VERSION));
        CHECK(str_attr_is(f, "git_rev", mps_git_rev));
        CHECK(str_attr_is(f, "solver", "fluid_solver"));

        hid_t d = H5Dopen2(f, "/config", H5P_DEFAULT);
        CHECK(d >= 0);
        hid_t dt = H5Dget_type(d);
        char *cfg = calloc(H5Tget_size(dt) + 1, 1);
        CHECK(H5Dread(d, dt, H5S_ALL, H5S_ALL, H5P_DEFAULT, cfg) >= 0);
        CHECK(!strcmp(cfg, yaml));
        free(cfg);
        H5Tclose(dt);
        H5Dclose(d);

        /* vectors have 3 components in the file whatever MPS_DIM is, z = 0 in 2D */
        double x[N][MPS_H5_VEC], v[N][MPS_H5_VEC], p[N];
        int id[N];
        uint8_t u[N];
        read_field(f, "position", H5T_NATIVE_DOUBLE, N, MPS_H5_VEC, "m", x);
        read_field(f, "velocity", H5T_NATIVE_DOUBLE, N, MPS_H5_VEC, "m/s", v);
        read_field(f, "pressure", H5T_NATIVE_DOUBLE, N, 1, "Pa", p);
        read_field(f, "id", H5T_NATIVE_INT, N, 1, "", id);
        read_field(f, "type", H5T_NATIVE_UINT8, N, 1, "", u);
        int bad = 0;
        for (int i = 0; i < N; i++) {
            for (int dd = 0; dd < MPS_DIM; dd++)
                bad += x[i][dd] != xval(sn, i, dd) || v[i][dd] != vval(sn, i, dd);
            for (int dd = MPS_DIM; dd < MPS_H5_VEC; dd++)
                bad += x[i][dd] != 0.0 || v[i][dd] != 0.0;
            bad += p[i] != pval(sn, i) || id[i] != ival(sn, i) || u[i] != uval(sn, i);
        }
        CHECK(bad == 0);
        /* the Polyvertex connectivity, 0 .. n-1 */
        int topo[N];
        d = H5Dopen2(f, "/topology", H5P_DEFAULT);
        CHECK(d >= 0 && H5Dread(d, H5T_NATIVE_INT, H5S_ALL, H5S_ALL, H5P_DEFAULT, topo) >= 0);
        H5Dclose(d);
        for (int i = 0; i < N; i++)
            bad += topo[i] != i;
        CHECK(bad == 0);
        /* a coded field says what its codes mean; the others have no legend */
        d = H5Dopen2(f, "/particles/type", H5P_DEFAULT);
        CHECK(str_attr_is(d, "legend", "250 this, 249 that"));
        H5Dclose(d);
        d = H5Dopen2(f, "/particles/id", H5P_DEFAULT);
        CHECK(H5Aexists(d, "legend") == 0);
        H5Dclose(d);
        /* on-disk types: float64, int32, uint8 */
        d = H5Dopen2(f, "/particles/type", H5P_DEFAULT);
        dt = H5Dget_type(d);
        CHECK(H5Tget_size(dt) == 1 && H5Tget_sign(dt) == H5T_SGN_NONE);
        H5Tclose(dt);
        H5Dclose(d);
        d = H5Dopen2(f, "/particles/id", H5P_DEFAULT);
        dt = H5Dget_type(d);
        CHECK(H5Tget_size(dt) == 4 && H5Tget_sign(dt) == H5T_SGN_2);
        H5Tclose(dt);
        H5Dclose(d);
        CHECK(H5Fclose(f) >= 0);
    }

    char path[512];
    snprintf(path, sizeof path, "%s/fluid.xmf", dir);
    char *t = slurp(path);
    CHECK(t != NULL);
    if (!t)
        return;
    CHECK(strstr(t, "CollectionType=\"Temporal\"") != NULL);
    CHECK(count(t, "GridType=\"Uniform\"") == 3);
    CHECK(count(t, "TopologyType=\"Polyvertex\" NumberOfElements=\"7\"") == 3);
    for (int sn = 0; sn < 3; sn++) {
        char want[128];
        snprintf(want, sizeof want, "Precision=\"4\" Format=\"HDF\">fluid_%06d.h5:/topology<", sn);
        CHECK(count(t, want) == 1);
    }
    CHECK(count(t, "GeometryType=\"XYZ\"") == 3);
    for (int sn = 0; sn < 3; sn++) {
        char want[128];
        snprintf(want, sizeof want, ">fluid_%06d.h5:/particles/position<", sn);
        CHECK(count(t, want) == 1);
        snprintf(want, sizeof want, ">fluid_%06d.h5:/particles/velocity<", sn);
        CHECK(count(t, want) == 1);
        snprintf(want, sizeof want, "<Time Value=\"%.15g\"/>", 0.1 * sn);
        CHECK(count(t, want) == 1);
    }
    CHECK(strstr(t, dir) == NULL); /* relative names only */
    CHECK(count(t, "<Attribute Name=\"velocity\" AttributeType=\"Vector\"") == 3);
    CHECK(count(t, "<Attribute Name=\"pressure\" AttributeType=\"Scalar\"") == 3);
    char want[128];
    snprintf(want, sizeof want, "Dimensions=\"7 %d\" NumberType=\"Float\" Precision=\"8\"",
             MPS_H5_VEC);
    CHECK(count(t, want) == 6); /* position and velocity, 3 snapshots */
    CHECK(count(t, "Dimensions=\"7\" NumberType=\"Float\" Precision=\"8\"") == 3);
    CHECK(count(t, "Dimensions=\"7\" NumberType=\"Int\" Precision=\"4\"") == 6); /* id, topology */
    CHECK(count(t, "Dimensions=\"7\" NumberType=\"UChar\" Precision=\"1\"") == 3);
    free(t);
    check_xml(path);
    snprintf(path, sizeof path, "%s/fluid.xmf.tmp", dir);
    CHECK(access(path, F_OK) != 0);
}

/* A second series: its first snapshot is empty (n = 0), times 0, 0.045, ... */
static void write_solid(const char *dir)
{
    struct mps_err err = {0};
    struct mps_h5_series *s = NULL;
    CHECK(mps_h5_open(&s, dir, "solid", "solid_solver", NULL, &err) == MPS_OK);
    if (!s)
        return;
    double x[2][MPS_DIM] = {{0}};
    double pr[2] = {1, 2};
    for (int sn = 0; sn < 6; sn++) {
        size_t n = sn == 0 ? 0 : 2;
        struct mps_field fields[] = {{"stress", 1, MPS_F64, n ? pr : NULL, "Pa", NULL}};
        enum mps_status st = mps_h5_write(s, 0.045 * sn, sn, n,
                                          n ? (const double(*)[MPS_DIM])x : NULL, fields, 1, &err);
        CHECK(st == MPS_OK);
        if (st != MPS_OK)
            fprintf(stderr, "%s\n", err.msg);
    }
    mps_h5_close(&s);

    char path[512];
    snprintf(path, sizeof path, "%s/solid_000000.h5", dir);
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    CHECK(f >= 0);
    double dummy;
    read_field(f, "position", H5T_NATIVE_DOUBLE, 0, MPS_H5_VEC, "m", &dummy);
    read_field(f, "stress", H5T_NATIVE_DOUBLE, 0, 1, "Pa", &dummy);
    CHECK(str_attr_is(f, "solver", "solid_solver"));
    H5Fclose(f);
    snprintf(path, sizeof path, "%s/solid.xmf", dir);
    check_xml(path);
}

static void check_scene(const char *dir)
{
    struct mps_err err = {0};
    const char *series[] = {"fluid", "solid"};
    enum mps_status st = mps_h5_write_scene_xdmf(dir, "scene", series, 2, &err);
    CHECK(st == MPS_OK);
    if (st != MPS_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return;
    }
    char path[512];
    snprintf(path, sizeof path, "%s/scene.xmf", dir);
    check_xml(path);
    char *t = slurp(path);
    if (!t)
        return;
    CHECK(count(t, "CollectionType=\"Spatial\"") == 3);
    CHECK(count(t, "GridType=\"Uniform\"") == 6);
    CHECK(count(t, "<Time ") == 3); /* only on the spatial collections */
    /* fluid t = 0, 0.1, 0.2 -> solid snapshots at 0, 0.09 and 0.18 (0.045 k) */
    const int want_solid[3] = {0, 2, 4};
    const char *p = t;
    for (int k = 0; k < 3; k++) {
        const char *c = strstr(p, "CollectionType=\"Spatial\"");
        CHECK(c != NULL);
        if (!c)
            break;
        const char *next = strstr(c + 1, "CollectionType=\"Spatial\"");
        size_t len = next ? (size_t)(next - c) : strlen(c);
        char *chunk = strndup(c, len);
        char want[128];
        snprintf(want, sizeof want, "<Time Value=\"%.15g\"/>", 0.1 * k);
        CHECK(strstr(chunk, want) != NULL);
        snprintf(want, sizeof want, ">fluid_%06d.h5:/particles/pressure<", k);
        CHECK(strstr(chunk, want) != NULL);
        snprintf(want, sizeof want, ">solid_%06d.h5:/particles/stress<", want_solid[k]);
        CHECK(strstr(chunk, want) != NULL);
        CHECK(count(chunk, "solid_0") == 4); /* name, topology, position, stress of one snapshot */
        free(chunk);
        p = c + 1;
    }
    free(t);

    /* a missing series is an I/O error naming its index file */
    const char *bad[] = {"fluid", "nosuch"};
    st = mps_h5_write_scene_xdmf(dir, "scene2", bad, 2, &err);
    CHECK(st == MPS_EIO);
    CHECK(strstr(err.msg, "nosuch.xmf") != NULL);
}

static void check_errors(const char *dir)
{
    struct mps_err err = {0};
    struct mps_h5_series *s = NULL;
    CHECK(mps_h5_open(&s, dir, "a/b", "x", "", &err) == MPS_EINPUT);
    CHECK(s == NULL);

    /* A snapshot is written as NAME.h5.tmp, then renamed. A directory where
     * the .tmp should go makes H5Fcreate fail. */
    char path[512], tmp[520];
    snprintf(path, sizeof path, "%s/err_000000.h5", dir);
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    CHECK(mkdir(tmp, 0777) == 0);
    CHECK(mps_h5_open(&s, dir, "err", "x", "", &err) == MPS_OK);
    double x[1][MPS_DIM] = {{0}};
    enum mps_status st = mps_h5_write(s, 0.0, 0, 1, (const double(*)[MPS_DIM])x, NULL, 0, &err);
    CHECK(st == MPS_ELIB);
    CHECK(strstr(err.msg, "err_000000.h5.tmp") != NULL);
    CHECK(strstr(err.msg, "H5Fcreate") != NULL);
    printf("expected error: %s\n", err.msg);
    CHECK(mps_h5_count(s) == 0);
    CHECK(access(path, F_OK) != 0);
    CHECK(rmdir(tmp) == 0);

    /* A directory at the final name makes the rename fail: the complete
     * .tmp is removed, nothing enters the index. */
    CHECK(mkdir(path, 0777) == 0);
    st = mps_h5_write(s, 0.0, 0, 1, (const double(*)[MPS_DIM])x, NULL, 0, &err);
    CHECK(st == MPS_EIO);
    CHECK(strstr(err.msg, "cannot rename") != NULL);
    CHECK(strstr(err.msg, "err_000000.h5'") != NULL);
    printf("expected error: %s\n", err.msg);
    CHECK(mps_h5_count(s) == 0);
    CHECK(access(tmp, F_OK) != 0);

    /* a field without data, a non-finite time */
    struct mps_field f = {"p", 1, MPS_F64, NULL, "Pa", NULL};
    CHECK(mps_h5_write(s, 0.0, 0, 1, (const double(*)[MPS_DIM])x, &f, 1, &err) == MPS_EINPUT);
    CHECK(mps_h5_write(s, 0.0 / 0.0, 0, 1, (const double(*)[MPS_DIM])x, NULL, 0, &err) ==
          MPS_EINPUT);
    mps_h5_close(&s);

    /* open creates missing parents */
    snprintf(path, sizeof path, "%s/deep/er/run", dir);
    CHECK(mps_h5_open(&s, path, "fluid", "x", "", &err) == MPS_OK);
    mps_h5_close(&s);
    snprintf(path, sizeof path, "%s/deep/er/run/fluid.xmf", dir);
    CHECK(access(path, F_OK) == 0);
}

int main(void)
{
    char dir[] = "/tmp/mps_test_h5_XXXXXX";
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    write_fluid(dir);
    check_fluid(dir);
    write_solid(dir);
    check_scene(dir);
    check_errors(dir);
    int rc = test_summary("test_h5");
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
