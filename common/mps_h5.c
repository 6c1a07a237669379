#include "mps_h5.h"

#include <errno.h>
#include <hdf5.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mps_cli.h" /* mps_mkdir_p */
#include "mps_version.h"

/* XDMF notes (why the index looks the way it does):
 * - Version 2.0, Polyvertex topology: one vertex cell per particle, with its
 *   connectivity 0 .. n-1 stored in each file (/topology, 4 bytes a
 *   particle). The implicit form (NumberOfElements alone, what SWIFT writes)
 *   gives cells with ParaView's XDMF Reader but none with Xdmf3ReaderS, which
 *   then draws nothing in the Points or Surface representation.
 * - Positions and vector fields have 3 components in the files, z = 0 in 2D
 *   (geometry "XYZ"). XDMF defines a Vector as 3 values: ParaView's XDMF
 *   Reader pads a 2-component one, but Xdmf3ReaderS (what OpenDataFile picks)
 *   keeps 2 components, and WarpByVector then aborts pvpython on an assertion
 *   and a Calculator's mag() finds no vector. The padding costs a third more
 *   disk per vector field; tests/paraview opens every kind of output with both
 *   readers.
 * - File names are relative to the .xmf, so a run directory can be moved.
 * - The text is regular on purpose: one element per line, each snapshot a
 *   block from `<Grid ... GridType="Uniform">` to `</Grid>` with one
 *   `<Time Value="..."/>` line, so mps_h5_write_scene_xdmf (run by another
 *   process) can parse it line by line. */

struct mps_h5_series {
    char *dir, *prefix, *solver, *config;
    char **grids; /* the XDMF <Grid> block of each snapshot */
    int count, cap;
};

/* ---- small helpers ---- */

static char *dup_str(const char *s)
{
    s = s ? s : "";
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

/* A series or scene name becomes a file name: no path separators. */
static enum mps_status check_name(const char *what, const char *name, struct mps_err *err)
{
    if (!name || !name[0] || strchr(name, '/'))
        return mps_err_set(err, MPS_EINPUT, "%s '%s': must be a non-empty name without '/'",
                           what, name ? name : "(null)");
    return MPS_OK;
}

/* Shortest of %.15g and %.17g that reads back exactly: 0.1 stays "0.1". */
static void fmt_time(char buf[32], double v)
{
    snprintf(buf, 32, "%.15g", v);
    if (strtod(buf, NULL) != v)
        snprintf(buf, 32, "%.17g", v);
}

static void xml_escaped(FILE *f, const char *s)
{
    for (; *s; s++) {
        switch (*s) {
        case '&': fputs("&amp;", f); break;
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '"': fputs("&quot;", f); break;
        default: fputc(*s, f);
        }
    }
}

/* Writes text to path through path.tmp and rename(), so a reader never sees
 * a half-written file. */
static enum mps_status atomic_write(const char *path, const char *text, size_t len,
                                    struct mps_err *err)
{
    size_t plen = strlen(path);
    char *tmp = malloc(plen + 5);
    if (!tmp)
        return mps_err_set(err, MPS_ENOMEM, "%s: out of memory", path);
    memcpy(tmp, path, plen);
    memcpy(tmp + plen, ".tmp", 5);
    enum mps_status st = MPS_OK;
    FILE *f = fopen(tmp, "w");
    if (!f) {
        st = mps_err_set(err, MPS_EIO, "cannot write '%s': %s", tmp, strerror(errno));
        goto done;
    }
    size_t w = fwrite(text, 1, len, f);
    int bad = w != len || ferror(f);
    int saved = errno;
    if (fclose(f) != 0 && !bad) {
        bad = 1;
        saved = errno;
    }
    if (bad) {
        st = mps_err_set(err, MPS_EIO, "cannot write '%s': %s", tmp, strerror(saved));
        remove(tmp);
        goto done;
    }
    if (rename(tmp, path) != 0) {
        st = mps_err_set(err, MPS_EIO, "cannot rename '%s' to '%s': %s", tmp, path,
                         strerror(errno));
        remove(tmp);
    }
done:
    free(tmp);
    return st;
}

/* ---- HDF5 ---- */

/* Takes the innermost (most specific) message off HDF5's error stack. */
static herr_t innermost(unsigned n, const H5E_error2_t *e, void *data)
{
    if (n == 0 && e->desc)
        snprintf((char *)data, 256, "%s", e->desc);
    return 0;
}

/* "FILE: CALL failed: why", CALL printf-formatted ("H5Dwrite(/particles/%s)"). */
static enum mps_status h5_fail(struct mps_err *err, const char *path, const char *call, ...)
    __attribute__((format(printf, 3, 4)));

static enum mps_status h5_fail(struct mps_err *err, const char *path, const char *call, ...)
{
    char why[256] = "", what[256];
    H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, innermost, why);
    H5Eclear2(H5E_DEFAULT);
    va_list ap;
    va_start(ap, call);
    vsnprintf(what, sizeof what, call, ap);
    va_end(ap);
    return mps_err_set(err, MPS_ELIB, "%s: %s failed%s%s", path, what, why[0] ? ": " : "", why);
}

/* Fixed-length UTF-8 string type holding s (with its terminator). */
static hid_t string_type(const char *s)
{
    hid_t t = H5Tcopy(H5T_C_S1);
    if (t < 0)
        return t;
    if (H5Tset_size(t, strlen(s) + 1) < 0 || H5Tset_strpad(t, H5T_STR_NULLTERM) < 0 ||
        H5Tset_cset(t, H5T_CSET_UTF8) < 0) {
        H5Tclose(t);
        return -1;
    }
    return t;
}

static enum mps_status attr_str(hid_t obj, const char *name, const char *value, const char *path,
                                struct mps_err *err)
{
    enum mps_status st = MPS_OK;
    value = value ? value : "";
    hid_t t = -1, sp = -1, a = -1;
    if ((t = string_type(value)) < 0) {
        st = h5_fail(err, path, "H5Tcopy/H5Tset_size(string for attribute %s)", name);
        goto done;
    }
    if ((sp = H5Screate(H5S_SCALAR)) < 0) {
        st = h5_fail(err, path, "H5Screate(attribute %s)", name);
        goto done;
    }
    if ((a = H5Acreate2(obj, name, t, sp, H5P_DEFAULT, H5P_DEFAULT)) < 0) {
        st = h5_fail(err, path, "H5Acreate2(attribute %s)", name);
        goto done;
    }
    if (H5Awrite(a, t, value) < 0)
        st = h5_fail(err, path, "H5Awrite(attribute %s)", name);
done:
    if (a >= 0)
        H5Aclose(a);
    if (sp >= 0)
        H5Sclose(sp);
    if (t >= 0)
        H5Tclose(t);
    return st;
}

static enum mps_status attr_num(hid_t obj, const char *name, hid_t ftype, hid_t mtype,
                                const void *value, const char *path, struct mps_err *err)
{
    enum mps_status st = MPS_OK;
    hid_t sp = -1, a = -1;
    if ((sp = H5Screate(H5S_SCALAR)) < 0) {
        st = h5_fail(err, path, "H5Screate(attribute %s)", name);
        goto done;
    }
    if ((a = H5Acreate2(obj, name, ftype, sp, H5P_DEFAULT, H5P_DEFAULT)) < 0) {
        st = h5_fail(err, path, "H5Acreate2(attribute %s)", name);
        goto done;
    }
    if (H5Awrite(a, mtype, value) < 0)
        st = h5_fail(err, path, "H5Awrite(attribute %s)", name);
done:
    if (a >= 0)
        H5Aclose(a);
    if (sp >= 0)
        H5Sclose(sp);
    return st;
}

/* /config: one scalar string dataset. */
static enum mps_status write_config(hid_t file, const char *yaml, const char *path,
                                    struct mps_err *err)
{
    enum mps_status st = MPS_OK;
    yaml = yaml ? yaml : "";
    hid_t t = -1, sp = -1, d = -1;
    if ((t = string_type(yaml)) < 0) {
        st = h5_fail(err, path, "H5Tcopy/H5Tset_size(string for /config)");
        goto done;
    }
    if ((sp = H5Screate(H5S_SCALAR)) < 0) {
        st = h5_fail(err, path, "H5Screate(/config)");
        goto done;
    }
    if ((d = H5Dcreate2(file, "config", t, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)) < 0) {
        st = h5_fail(err, path, "H5Dcreate2(/config)");
        goto done;
    }
    if (H5Dwrite(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, yaml) < 0)
        st = h5_fail(err, path, "H5Dwrite(/config)");
done:
    if (d >= 0)
        H5Dclose(d);
    if (sp >= 0)
        H5Sclose(sp);
    if (t >= 0)
        H5Tclose(t);
    return st;
}

static void h5_types(enum mps_field_type type, hid_t *ftype, hid_t *mtype)
{
    switch (type) {
    case MPS_I32:
        *ftype = H5T_STD_I32LE;
        *mtype = H5T_NATIVE_INT;
        break;
    case MPS_U8:
        *ftype = H5T_STD_U8LE;
        *mtype = H5T_NATIVE_UCHAR;
        break;
    default:
        *ftype = H5T_IEEE_F64LE;
        *mtype = H5T_NATIVE_DOUBLE;
    }
}

static size_t type_bytes(enum mps_field_type type)
{
    return type == MPS_F64 ? sizeof(double) : type == MPS_I32 ? sizeof(int) : 1;
}

/* Components a field has in the files: vectors get MPS_H5_VEC. */
static int file_ncomp(int ncomp)
{
    return ncomp == MPS_DIM ? MPS_H5_VEC : ncomp;
}

/* A copy of n vectors of MPS_DIM components padded with zeros to
 * MPS_H5_VEC; NULL when out of memory. */
static void *pad_vectors(const void *data, size_t n, enum mps_field_type type)
{
    size_t b = type_bytes(type);
    char *out = calloc(n ? n : 1, MPS_H5_VEC * b);
    if (out)
        for (size_t i = 0; i < n; i++)
            memcpy(out + i * MPS_H5_VEC * b, (const char *)data + i * MPS_DIM * b, MPS_DIM * b);
    return out;
}

/* /particles/NAME: n or n x ncomp values (vectors padded to MPS_H5_VEC) with
 * a "units" attribute and, if given, a "legend". */
static enum mps_status write_field(hid_t group, const char *name, int ncomp,
                                   enum mps_field_type type, size_t n, const void *data,
                                   const char *units, const char *legend, const char *path,
                                   struct mps_err *err)
{
    enum mps_status st = MPS_OK;
    void *padded = NULL;
    if (ncomp == MPS_DIM && MPS_DIM != MPS_H5_VEC && n > 0) {
        if (!(padded = pad_vectors(data, n, type)))
            return mps_err_set(err, MPS_ENOMEM, "%s: out of memory writing /particles/%s", path,
                               name);
        data = padded;
    }
    ncomp = file_ncomp(ncomp);
    hsize_t dims[2] = {(hsize_t)n, (hsize_t)ncomp};
    hid_t ftype, mtype, sp = -1, d = -1;
    h5_types(type, &ftype, &mtype);
    if ((sp = H5Screate_simple(ncomp == 1 ? 1 : 2, dims, NULL)) < 0) {
        st = h5_fail(err, path, "H5Screate_simple(/particles/%s)", name);
        goto done;
    }
    if ((d = H5Dcreate2(group, name, ftype, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)) < 0) {
        st = h5_fail(err, path, "H5Dcreate2(/particles/%s)", name);
        goto done;
    }
    /* n = 0: an empty dataset, nothing to write (data may be NULL). */
    if (n > 0 && H5Dwrite(d, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) {
        st = h5_fail(err, path, "H5Dwrite(/particles/%s)", name);
        goto done;
    }
    st = attr_str(d, "units", units, path, err);
    if (st == MPS_OK && legend)
        st = attr_str(d, "legend", legend, path, err);
done:
    if (d >= 0 && H5Dclose(d) < 0 && st == MPS_OK)
        st = h5_fail(err, path, "H5Dclose(/particles/%s)", name);
    if (sp >= 0)
        H5Sclose(sp);
    free(padded);
    return st;
}

/* /topology: 0 .. n-1, the XDMF Polyvertex connectivity (see the notes at
 * the top). */
static enum mps_status write_topology(hid_t file, size_t n, const char *path, struct mps_err *err)
{
    int *idx = malloc((n ? n : 1) * sizeof *idx);
    if (!idx)
        return mps_err_set(err, MPS_ENOMEM, "%s: out of memory writing /topology", path);
    for (size_t i = 0; i < n; i++)
        idx[i] = (int)i;
    hsize_t dims[1] = {(hsize_t)n};
    enum mps_status st = MPS_OK;
    hid_t sp = -1, d = -1;
    if ((sp = H5Screate_simple(1, dims, NULL)) < 0) {
        st = h5_fail(err, path, "H5Screate_simple(/topology)");
        goto done;
    }
    if ((d = H5Dcreate2(file, "topology", H5T_STD_I32LE, sp, H5P_DEFAULT, H5P_DEFAULT,
                        H5P_DEFAULT)) < 0) {
        st = h5_fail(err, path, "H5Dcreate2(/topology)");
        goto done;
    }
    if (n > 0 && H5Dwrite(d, H5T_NATIVE_INT, H5S_ALL, H5S_ALL, H5P_DEFAULT, idx) < 0) {
        st = h5_fail(err, path, "H5Dwrite(/topology)");
        goto done;
    }
    st = attr_str(d, "meaning", "XDMF Polyvertex connectivity: particle i is vertex cell i", path,
                  err);
done:
    if (d >= 0 && H5Dclose(d) < 0 && st == MPS_OK)
        st = h5_fail(err, path, "H5Dclose(/topology)");
    if (sp >= 0)
        H5Sclose(sp);
    free(idx);
    return st;
}

/* ---- XDMF ---- */

static const char *xdmf_number(enum mps_field_type type)
{
    switch (type) {
    case MPS_I32: return "NumberType=\"Int\" Precision=\"4\"";
    case MPS_U8: return "NumberType=\"UChar\" Precision=\"1\"";
    default: return "NumberType=\"Float\" Precision=\"8\"";
    }
}

static void xdmf_dataitem(FILE *f, size_t n, int ncomp, enum mps_field_type type,
                          const char *file, const char *name)
{
    fprintf(f, "     <DataItem Dimensions=\"%zu", n);
    if (ncomp != 1)
        fprintf(f, " %d", file_ncomp(ncomp));
    fprintf(f, "\" %s Format=\"HDF\">", xdmf_number(type));
    xml_escaped(f, file);
    fputs(":/particles/", f);
    xml_escaped(f, name);
    fputs("</DataItem>\n", f);
}

/* The <Grid> block of one snapshot (see the notes at the top). */
static char *xdmf_grid(const char *gridname, const char *file, double time, size_t n,
                       const struct mps_field *fields, int nfields)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (!f)
        return NULL;
    fputs("   <Grid Name=\"", f);
    xml_escaped(f, gridname);
    fputs("\" GridType=\"Uniform\">\n", f);
    char tb[32];
    fmt_time(tb, time);
    fprintf(f, "    <Time Value=\"%s\"/>\n", tb);
    fprintf(f, "    <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"%zu\" "
               "NodesPerElement=\"1\">\n", n);
    fprintf(f, "     <DataItem Dimensions=\"%zu\" %s Format=\"HDF\">", n, xdmf_number(MPS_I32));
    xml_escaped(f, file);
    fputs(":/topology</DataItem>\n", f);
    fputs("    </Topology>\n", f);
    fputs("    <Geometry GeometryType=\"XYZ\">\n", f);
    xdmf_dataitem(f, n, MPS_DIM, MPS_F64, file, "position");
    fputs("    </Geometry>\n", f);
    for (int k = 0; k < nfields; k++) {
        const struct mps_field *fl = &fields[k];
        const char *kind = fl->ncomp == 1 ? "Scalar" : fl->ncomp == MPS_DIM ? "Vector" : "Matrix";
        fputs("    <Attribute Name=\"", f);
        xml_escaped(f, fl->name);
        fprintf(f, "\" AttributeType=\"%s\" Center=\"Node\">\n", kind);
        xdmf_dataitem(f, n, fl->ncomp, fl->type, file, fl->name);
        fputs("    </Attribute>\n", f);
    }
    fputs("   </Grid>\n", f);
    if (ferror(f)) {
        fclose(f);
        free(buf);
        return NULL;
    }
    fclose(f);
    return buf;
}

static const char xdmf_head[] = "<?xml version=\"1.0\" ?>\n"
                                "<Xdmf Version=\"2.0\">\n"
                                " <Domain>\n";
static const char xdmf_tail[] = "  </Grid>\n"
                                " </Domain>\n"
                                "</Xdmf>\n";

static void xdmf_collection(FILE *f, const char *name)
{
    fputs(xdmf_head, f);
    fputs("  <Grid Name=\"", f);
    xml_escaped(f, name);
    fputs("\" GridType=\"Collection\" CollectionType=\"Temporal\">\n", f);
}

static char *join_path(const char *dir, const char *name, const char *ext)
{
    size_t n = strlen(dir) + strlen(name) + strlen(ext) + 2;
    char *p = malloc(n);
    if (p)
        snprintf(p, n, "%s/%s%s", dir, name, ext);
    return p;
}

static enum mps_status write_index(const struct mps_h5_series *s, struct mps_err *err)
{
    char *path = join_path(s->dir, s->prefix, ".xmf");
    char *buf = NULL;
    size_t len = 0;
    FILE *f = path ? open_memstream(&buf, &len) : NULL;
    if (!f) {
        free(path);
        return mps_err_set(err, MPS_ENOMEM, "XDMF index for '%s': out of memory", s->prefix);
    }
    xdmf_collection(f, s->prefix);
    for (int k = 0; k < s->count; k++)
        fputs(s->grids[k], f);
    fputs(xdmf_tail, f);
    int bad = ferror(f);
    fclose(f);
    enum mps_status st = bad ? mps_err_set(err, MPS_ENOMEM, "%s: out of memory", path)
                             : atomic_write(path, buf, len, err);
    free(buf);
    free(path);
    return st;
}

/* ---- series ---- */

enum mps_status mps_h5_open(struct mps_h5_series **out, const char *dir, const char *prefix,
                            const char *solver, const char *config_yaml, struct mps_err *err)
{
    *out = NULL;
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL); /* errors come through our messages */
    enum mps_status st = check_name("snapshot prefix", prefix, err);
    if (st != MPS_OK)
        return st;
    if ((st = mps_mkdir_p(dir, err)) != MPS_OK)
        return st;
    struct mps_h5_series *s = calloc(1, sizeof *s);
    if (!s || !(s->dir = dup_str(dir)) || !(s->prefix = dup_str(prefix)) ||
        !(s->solver = dup_str(solver)) || !(s->config = dup_str(config_yaml))) {
        mps_h5_close(&s);
        return mps_err_set(err, MPS_ENOMEM, "snapshot series '%s': out of memory", prefix);
    }
    /* An empty index right away: the file exists from the start, and an
     * unwritable directory is reported now rather than at the first snapshot. */
    if ((st = write_index(s, err)) != MPS_OK) {
        mps_h5_close(&s);
        return st;
    }
    *out = s;
    return MPS_OK;
}

static enum mps_status check_fields(size_t n, const double (*x)[MPS_DIM],
                                    const struct mps_field *fields, int nfields,
                                    struct mps_err *err)
{
    if (nfields < 0 || (nfields > 0 && !fields))
        return mps_err_set(err, MPS_EINPUT, "snapshot: bad field list (%d fields)", nfields);
    if (n > 0 && !x)
        return mps_err_set(err, MPS_EINPUT, "snapshot: no positions for %zu particles", n);
    for (int k = 0; k < nfields; k++) {
        const struct mps_field *f = &fields[k];
        if (!f->name || !f->name[0] || strchr(f->name, '/') || !strcmp(f->name, "position"))
            return mps_err_set(err, MPS_EINPUT,
                               "snapshot field %d: bad name '%s' (empty, has '/', or "
                               "'position')", k, f->name ? f->name : "(null)");
        if (f->ncomp < 1)
            return mps_err_set(err, MPS_EINPUT, "snapshot field '%s': ncomp = %d: must be >= 1",
                               f->name, f->ncomp);
        if (f->type != MPS_F64 && f->type != MPS_I32 && f->type != MPS_U8)
            return mps_err_set(err, MPS_EINPUT, "snapshot field '%s': unknown type %d", f->name,
                               (int)f->type);
        if (n > 0 && !f->data)
            return mps_err_set(err, MPS_EINPUT, "snapshot field '%s': no data", f->name);
    }
    return MPS_OK;
}

/* Room for one more snapshot in the index. */
static enum mps_status grow_index(struct mps_h5_series *s, struct mps_err *err)
{
    if (s->count < s->cap)
        return MPS_OK;
    int cap = s->cap ? 2 * s->cap : 64;
    char **g = realloc(s->grids, (size_t)cap * sizeof *g);
    if (!g)
        return mps_err_set(err, MPS_ENOMEM, "snapshot series '%s': out of memory", s->prefix);
    s->grids = g;
    s->cap = cap;
    return MPS_OK;
}

enum mps_status mps_h5_write(struct mps_h5_series *s, double time, long step, size_t n,
                             const double (*x)[MPS_DIM], const struct mps_field *fields,
                             int nfields, struct mps_err *err)
{
    if (!isfinite(time))
        return mps_err_set(err, MPS_EINPUT, "snapshot at step %ld: time %g is not finite", step,
                           time);
    enum mps_status st = check_fields(n, x, fields, nfields, err);
    if (st != MPS_OK)
        return st;
    if ((st = grow_index(s, err)))
        return st;
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);

    /* PREFIX_NNNNNN: NNNNNN counts snapshots (not steps), so names sort and
     * ParaView groups them as one series. The file is written as
     * NAME.h5.tmp and renamed once closed: a process killed while writing
     * leaves a .tmp, never a truncated NAME.h5 that a script globbing *.h5
     * would trip on. */
    size_t namelen = strlen(s->prefix) + 24;
    char *name = malloc(namelen), *file = malloc(namelen), *path = NULL, *tmp = NULL;
    if (name && file) {
        snprintf(name, namelen, "%s_%06d", s->prefix, s->count);
        snprintf(file, namelen, "%s.h5", name);
        path = join_path(s->dir, file, "");
        tmp = path ? join_path(s->dir, file, ".tmp") : NULL;
    }
    if (!tmp) {
        free(name);
        free(file);
        free(path);
        return mps_err_set(err, MPS_ENOMEM, "snapshot: out of memory");
    }

    hid_t fid = -1, grp = -1;
    if ((fid = H5Fcreate(tmp, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT)) < 0) {
        st = h5_fail(err, tmp, "H5Fcreate");
        goto done;
    }
    int64_t step64 = step;
    if ((st = attr_num(fid, "time", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &time, tmp, err)) ||
        (st = attr_num(fid, "step", H5T_STD_I64LE, H5T_NATIVE_INT64, &step64, tmp, err)) ||
        (st = attr_str(fid, "code_version", MPS_VERSION, tmp, err)) ||
        (st = attr_str(fid, "git_rev", mps_git_rev, tmp, err)) ||
        (st = attr_str(fid, "solver", s->solver, tmp, err)) ||
        (st = write_config(fid, s->config, tmp, err)))
        goto done;
    if ((st = write_topology(fid, n, tmp, err)))
        goto done;
    if ((grp = H5Gcreate2(fid, "particles", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)) < 0) {
        st = h5_fail(err, tmp, "H5Gcreate2(/particles)");
        goto done;
    }
    if ((st = write_field(grp, "position", MPS_DIM, MPS_F64, n, x, "m", NULL, tmp, err)))
        goto done;
    for (int k = 0; k < nfields; k++) {
        const struct mps_field *f = &fields[k];
        if ((st = write_field(grp, f->name, f->ncomp, f->type, n, f->data, f->units, f->legend,
                              tmp, err)))
            goto done;
    }
done:
    if (grp >= 0 && H5Gclose(grp) < 0 && st == MPS_OK)
        st = h5_fail(err, tmp, "H5Gclose");
    /* The close flushes the data: its failure is a failed write. */
    if (fid >= 0 && H5Fclose(fid) < 0 && st == MPS_OK)
        st = h5_fail(err, tmp, "H5Fclose");
    if (st == MPS_OK && rename(tmp, path) != 0)
        st = mps_err_set(err, MPS_EIO, "cannot rename '%s' to '%s': %s", tmp, path,
                         strerror(errno));
    if (st != MPS_OK && fid >= 0)
        remove(tmp);
    free(tmp);
    free(path);
    /* Only a complete, closed file enters the index. */
    char *grid = st == MPS_OK ? xdmf_grid(name, file, time, n, fields, nfields) : NULL;
    free(name);
    free(file);
    if (st != MPS_OK)
        return st;
    if (!grid)
        return mps_err_set(err, MPS_ENOMEM, "XDMF index for '%s': out of memory", s->prefix);
    s->grids[s->count++] = grid;
    return write_index(s, err);
}

int mps_h5_count(const struct mps_h5_series *s)
{
    return s ? s->count : 0;
}

enum mps_status mps_h5_rewind(struct mps_h5_series *s, int count, struct mps_err *err)
{
    if (!s || count >= s->count)
        return MPS_OK;
    if (count < 0)
        count = 0;
    while (s->count > count)
        free(s->grids[--s->count]);
    return write_index(s, err);
}

enum mps_status mps_h5_put(const struct mps_h5_series *s, struct mps_ckpt *c,
                           struct mps_err *err)
{
    size_t len = 0;
    for (int k = 0; s && k < s->count; k++)
        len += strlen(s->grids[k]) + 1;
    char *all = malloc(len + 1);
    if (!all)
        return mps_err_set(err, MPS_ENOMEM, "checkpoint: no memory for the XDMF index");
    size_t at = 0;
    for (int k = 0; s && k < s->count; k++) {
        size_t l = strlen(s->grids[k]) + 1;
        memcpy(all + at, s->grids[k], l);
        at += l;
    }
    enum mps_status st = mps_ckpt_put(c, "snapshots", all, len, err);
    free(all);
    return st;
}

enum mps_status mps_h5_get(struct mps_h5_series *s, struct mps_ckpt *c, struct mps_err *err)
{
    const void *data;
    size_t len;
    enum mps_status st = mps_ckpt_get_any(c, "snapshots", &data, &len, err);
    if (st || !s)
        return st;
    const char *p = data, *end = p + len;
    if (len && end[-1] != '\0')
        return mps_err_set(err, MPS_EINPUT, "checkpoint: the XDMF index is damaged");
    mps_h5_rewind(s, 0, NULL);
    while (p < end) {
        if ((st = grow_index(s, err)))
            return st;
        if (!(s->grids[s->count] = dup_str(p)))
            return mps_err_set(err, MPS_ENOMEM, "checkpoint: no memory for the XDMF index");
        s->count++;
        p += strlen(p) + 1;
    }
    return write_index(s, err);
}

void mps_h5_close(struct mps_h5_series **s)
{
    if (!s || !*s)
        return;
    struct mps_h5_series *p = *s;
    for (int k = 0; k < p->count; k++)
        free(p->grids[k]);
    free(p->grids);
    free(p->dir);
    free(p->prefix);
    free(p->solver);
    free(p->config);
    free(p);
    *s = NULL;
}

/* ---- scene: several series as one ---- */

struct snap_block {
    double time;
    char *text; /* the grid's lines, without its <Time> line */
};

struct series_blocks {
    struct snap_block *b;
    int n, cap;
};

static void free_blocks(struct series_blocks *sb)
{
    for (int k = 0; k < sb->n; k++)
        free(sb->b[k].text);
    free(sb->b);
    sb->b = NULL;
    sb->n = sb->cap = 0;
}

static const char *skip_blank(const char *s)
{
    while (*s == ' ' || *s == '\t')
        s++;
    return s;
}

/* Reads the snapshot blocks of DIR/PREFIX.xmf as written by write_index. */
static enum mps_status read_index(const char *path, struct series_blocks *sb,
                                  struct mps_err *err)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return mps_err_set(err, MPS_EIO, "cannot read '%s': %s", path, strerror(errno));
    enum mps_status st = MPS_OK;
    char *line = NULL, *text = NULL;
    size_t lcap = 0, tlen = 0;
    FILE *tf = NULL; /* open while inside a block */
    int have_time = 0, lineno = 0, start_line = 0;
    double t = 0.0;
    ssize_t got;
    while ((got = getline(&line, &lcap, f)) >= 0) {
        lineno++;
        const char *s = skip_blank(line);
        if (!tf) {
            if (!strncmp(s, "<Grid ", 6) && strstr(s, "GridType=\"Uniform\"")) {
                tf = open_memstream(&text, &tlen);
                if (!tf) {
                    st = mps_err_set(err, MPS_ENOMEM, "%s: out of memory", path);
                    break;
                }
                fprintf(tf, " %s", line); /* nested one level deeper in the scene */
                have_time = 0;
                start_line = lineno;
            }
            continue;
        }
        if (!strncmp(s, "<Time Value=\"", 13)) {
            char *end;
            t = strtod(s + 13, &end);
            if (end == s + 13 || *end != '"') {
                st = mps_err_set(err, MPS_EINPUT, "%s:%d: cannot read the time in %s", path,
                                 lineno, s);
                break;
            }
            have_time = 1;
            continue;
        }
        fprintf(tf, " %s", line);
        if (!strncmp(s, "</Grid>", 7)) {
            int bad = ferror(tf);
            fclose(tf);
            tf = NULL;
            if (bad) {
                st = mps_err_set(err, MPS_ENOMEM, "%s: out of memory", path);
                break;
            }
            if (!have_time) {
                st = mps_err_set(err, MPS_EINPUT, "%s:%d: snapshot grid without a <Time>", path,
                                 start_line);
                break;
            }
            if (sb->n == sb->cap) {
                int cap = sb->cap ? 2 * sb->cap : 64;
                struct snap_block *b = realloc(sb->b, (size_t)cap * sizeof *b);
                if (!b) {
                    st = mps_err_set(err, MPS_ENOMEM, "%s: out of memory", path);
                    break;
                }
                sb->b = b;
                sb->cap = cap;
            }
            sb->b[sb->n++] = (struct snap_block){t, text};
            text = NULL;
        }
    }
    if (st == MPS_OK && tf)
        st = mps_err_set(err, MPS_EINPUT, "%s:%d: snapshot grid not closed", path, start_line);
    if (st == MPS_OK && ferror(f))
        st = mps_err_set(err, MPS_EIO, "cannot read '%s': %s", path, strerror(errno));
    if (tf)
        fclose(tf);
    free(text);
    free(line);
    fclose(f);
    if (st != MPS_OK)
        free_blocks(sb);
    return st;
}

enum mps_status mps_h5_write_scene_xdmf(const char *dir, const char *name,
                                        const char *const *series_prefixes, int n,
                                        struct mps_err *err)
{
    enum mps_status st = check_name("scene name", name, err);
    if (st != MPS_OK)
        return st;
    if (n < 1 || !series_prefixes)
        return mps_err_set(err, MPS_EINPUT, "scene '%s': no series given", name);
    struct series_blocks *sb = calloc((size_t)n, sizeof *sb);
    char *buf = NULL, *path = join_path(dir, name, ".xmf");
    size_t len = 0;
    if (!sb || !path) {
        st = mps_err_set(err, MPS_ENOMEM, "scene '%s': out of memory", name);
        goto done;
    }
    for (int k = 0; k < n; k++) {
        if ((st = check_name("series prefix", series_prefixes[k], err)) != MPS_OK)
            goto done;
        char *idx = join_path(dir, series_prefixes[k], ".xmf");
        if (!idx) {
            st = mps_err_set(err, MPS_ENOMEM, "scene '%s': out of memory", name);
            goto done;
        }
        st = read_index(idx, &sb[k], err);
        free(idx);
        if (st != MPS_OK)
            goto done;
    }
    FILE *f = open_memstream(&buf, &len);
    if (!f) {
        st = mps_err_set(err, MPS_ENOMEM, "scene '%s': out of memory", name);
        goto done;
    }
    xdmf_collection(f, name);
    for (int i = 0; i < sb[0].n; i++) {
        double t = sb[0].b[i].time;
        fputs("   <Grid Name=\"", f);
        xml_escaped(f, name);
        fprintf(f, "_%06d\" GridType=\"Collection\" CollectionType=\"Spatial\">\n", i);
        /* One time for the whole collection: the members keep no <Time> of
         * their own, so a reader sees no spurious time steps. */
        char tb[32];
        fmt_time(tb, t);
        fprintf(f, "    <Time Value=\"%s\"/>\n", tb);
        for (int k = 0; k < n; k++) {
            int best = -1;
            double dbest = 0.0;
            for (int m = 0; m < sb[k].n; m++) {
                double dt = sb[k].b[m].time - t;
                dt = dt < 0 ? -dt : dt;
                if (best < 0 || dt < dbest) {
                    best = m;
                    dbest = dt;
                }
            }
            if (best >= 0)
                fputs(sb[k].b[best].text, f);
        }
        fputs("   </Grid>\n", f);
    }
    fputs(xdmf_tail, f);
    int bad = ferror(f);
    fclose(f);
    st = bad ? mps_err_set(err, MPS_ENOMEM, "scene '%s': out of memory", name)
             : atomic_write(path, buf, len, err);
done:
    if (sb)
        for (int k = 0; k < n; k++)
            free_blocks(&sb[k]);
    free(sb);
    free(buf);
    free(path);
    return st;
}
