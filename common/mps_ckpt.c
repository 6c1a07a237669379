#include "mps_ckpt.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "mps_cli.h"

#define MAGIC "MPSCKPT1"
#define VERSION 1u

void mps_ckpt_clear(struct mps_ckpt *c)
{
    c->len = c->pos = 0;
}

void mps_ckpt_rewind(struct mps_ckpt *c)
{
    c->pos = 0;
}

void mps_ckpt_free(struct mps_ckpt *c)
{
    free(c->buf);
    memset(c, 0, sizeof *c);
}

static enum mps_status reserve(struct mps_ckpt *c, size_t more, struct mps_err *err)
{
    if (c->len + more <= c->cap)
        return MPS_OK;
    size_t cap = c->cap ? c->cap : 4096;
    while (cap < c->len + more)
        cap *= 2;
    unsigned char *b = realloc(c->buf, cap);
    if (!b)
        return mps_err_set(err, MPS_ENOMEM, "checkpoint: no memory for %zu bytes", cap);
    c->buf = b;
    c->cap = cap;
    return MPS_OK;
}

/* Blocks start, and their data starts, at multiples of 8 bytes of the image
 * (a malloc'd buffer), so the data can be read in place as any type. */
static size_t pad8(size_t n)
{
    return (n + 7) & ~(size_t)7;
}

enum mps_status mps_ckpt_put(struct mps_ckpt *c, const char *name, const void *data,
                             size_t bytes, struct mps_err *err)
{
    size_t nl = strlen(name);
    uint16_t n16 = (uint16_t)nl;
    uint64_t b64 = bytes;
    size_t head = pad8(sizeof n16 + nl), total = head + sizeof b64 + pad8(bytes);
    enum mps_status st = reserve(c, total, err);
    if (st)
        return st;
    unsigned char *p = c->buf + c->len;
    memset(p, 0, total); /* the padding too: a file's bytes depend only on the state */
    memcpy(p, &n16, sizeof n16);
    memcpy(p + sizeof n16, name, nl);
    memcpy(p + head, &b64, sizeof b64);
    if (bytes)
        memcpy(p + head + sizeof b64, data, bytes);
    c->len += total;
    return MPS_OK;
}

/* The block at pos: its name (*got, *nl), where its data start (*at) and
 * their length (*bytes). 0, or -1 where the header is cut short, -2 where the
 * data run past the end. The one reading of the layout mps_ckpt_put writes. */
static int block_at(const struct mps_ckpt *c, size_t pos, const char **got, size_t *nl,
                    size_t *at, size_t *bytes)
{
    uint16_t n16;
    uint64_t b64;
    if (pos + sizeof n16 > c->len)
        return -1;
    memcpy(&n16, c->buf + pos, sizeof n16);
    *got = (const char *)c->buf + pos + sizeof n16;
    *nl = n16;
    size_t head = pad8(sizeof n16 + n16);
    if (pos + head + sizeof b64 > c->len)
        return -1;
    memcpy(&b64, c->buf + pos + head, sizeof b64);
    *at = pos + head + sizeof b64;
    if (b64 > c->len - *at || pad8((size_t)b64) > c->len - *at)
        return -2;
    *bytes = (size_t)b64;
    return 0;
}

enum mps_status mps_ckpt_get_any(struct mps_ckpt *c, const char *name, const void **data,
                                 size_t *bytes, struct mps_err *err)
{
    const char *got = "";
    size_t gl = 0, at = 0, n = 0, nl = strlen(name);
    if (c->pos + sizeof(uint16_t) > c->len)
        return mps_err_set(err, MPS_EINPUT, "checkpoint: ends where block '%s' should be", name);
    int r = block_at(c, c->pos, &got, &gl, &at, &n);
    if (r == -1)
        return mps_err_set(err, MPS_EINPUT, "checkpoint: truncated at block '%s'", name);
    if (gl != nl || memcmp(got, name, nl) != 0)
        return mps_err_set(err, MPS_EINPUT,
                           "checkpoint: block '%.*s' where '%s' should be (written by another "
                           "version or another case?)",
                           (int)gl, got, name);
    if (r == -2)
        return mps_err_set(err, MPS_EINPUT, "checkpoint: block '%s' runs past the end", name);
    *data = c->buf + at;
    *bytes = n;
    c->pos = at + pad8(n);
    return MPS_OK;
}

int mps_ckpt_peek(const struct mps_ckpt *c, const char *name, const void **data,
                  size_t *bytes)
{
    const size_t nl = strlen(name);
    const char *got;
    size_t gl, at, n;
    /* a damaged image has no such block here: reading it will say why */
    for (size_t pos = 0; block_at(c, pos, &got, &gl, &at, &n) == 0; pos = at + pad8(n))
        if (gl == nl && memcmp(got, name, nl) == 0) {
            if (data)
                *data = c->buf + at;
            if (bytes)
                *bytes = n;
            return 1;
        }
    return 0;
}

int mps_ckpt_has(const struct mps_ckpt *c, const char *name)
{
    return mps_ckpt_peek(c, name, NULL, NULL);
}

enum mps_status mps_ckpt_get(struct mps_ckpt *c, const char *name, void *data, size_t bytes,
                             struct mps_err *err)
{
    const void *p = NULL;
    size_t got = 0;
    enum mps_status st = mps_ckpt_get_any(c, name, &p, &got, err);
    if (st)
        return st;
    if (got != bytes)
        return mps_err_set(err, MPS_EINPUT,
                           "checkpoint: block '%s' holds %zu bytes, %zu expected (another "
                           "case or build?)",
                           name, got, bytes);
    if (bytes)
        memcpy(data, p, bytes);
    return MPS_OK;
}

static uint64_t fnv1a(const unsigned char *p, size_t n)
{
    uint64_t h = 14695981039346656037ull;
    for (size_t i = 0; i < n; i++) {
        h ^= p[i];
        h *= 1099511628211ull;
    }
    return h;
}

struct header {
    char magic[8];
    uint32_t version, zero;
    double time;
    int64_t number;
    uint64_t bytes;
};

void mps_ckpt_path(char *path, size_t len, const char *dir, const char *prefix, long number)
{
    snprintf(path, len, "%s/" MPS_CKPT_DIR "/%s_%06ld.ckpt", dir, prefix, number);
}

/* The number of a file called PREFIX_NNNNNN.ckpt, or -1. */
static long number_of(const char *name, const char *prefix)
{
    size_t pl = strlen(prefix), nl = strlen(name);
    if (nl != pl + 1 + 6 + 5 || strncmp(name, prefix, pl) != 0 || name[pl] != '_' ||
        strcmp(name + nl - 5, ".ckpt") != 0)
        return -1;
    long k = 0;
    for (size_t i = pl + 1; i < pl + 7; i++) {
        if (name[i] < '0' || name[i] > '9')
            return -1;
        k = 10 * k + (name[i] - '0');
    }
    return k;
}

static enum mps_status write_all(int fd, const void *p, size_t n, const char *path,
                                 struct mps_err *err)
{
    const unsigned char *b = p;
    while (n) {
        ssize_t w = write(fd, b, n);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            return mps_err_set(err, MPS_EIO, "cannot write '%s': %s", path, strerror(errno));
        b += w;
        n -= (size_t)w;
    }
    return MPS_OK;
}

enum mps_status mps_ckpt_write_file(const struct mps_ckpt *c, const char *dir,
                                    const char *prefix, long number, double time, char *path,
                                    size_t len, struct mps_err *err)
{
    char cdir[4200], final[4400], tmp[4410];
    snprintf(cdir, sizeof cdir, "%s/" MPS_CKPT_DIR, dir);
    enum mps_status st = mps_mkdir_p(cdir, err);
    if (st)
        return st;
    mps_ckpt_path(final, sizeof final, dir, prefix, number);
    snprintf(tmp, sizeof tmp, "%s.tmp", final);
    int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    if (fd < 0)
        return mps_err_set(err, MPS_EIO, "cannot create '%s': %s", tmp, strerror(errno));
    struct header h = {.version = VERSION, .time = time, .number = number, .bytes = c->len};
    memcpy(h.magic, MAGIC, 8);
    uint64_t hash = fnv1a(c->buf, c->len);
    if ((st = write_all(fd, &h, sizeof h, tmp, err)) ||
        (st = write_all(fd, c->buf, c->len, tmp, err)) ||
        (st = write_all(fd, &hash, sizeof hash, tmp, err))) {
        close(fd);
        unlink(tmp);
        return st;
    }
    /* on disk before the rename makes it the checkpoint */
    if (fsync(fd) != 0) {
        st = mps_err_set(err, MPS_EIO, "cannot flush '%s': %s", tmp, strerror(errno));
        close(fd);
        unlink(tmp);
        return st;
    }
    if (close(fd) != 0 || rename(tmp, final) != 0) {
        st = mps_err_set(err, MPS_EIO, "cannot write '%s': %s", final, strerror(errno));
        unlink(tmp);
        return st;
    }
    int dfd = open(cdir, O_RDONLY | O_DIRECTORY);
    if (dfd >= 0) { /* the rename itself on disk; a failure here loses nothing yet */
        (void)fsync(dfd);
        close(dfd);
    }
    if (path)
        snprintf(path, len, "%s", final);
    /* keep the last MPS_CKPT_KEEP up to this one */
    DIR *d = opendir(cdir);
    if (!d)
        return MPS_OK;
    struct dirent *e;
    while ((e = readdir(d))) {
        long k = number_of(e->d_name, prefix);
        if (k >= 0 && (k <= number - MPS_CKPT_KEEP || k > number)) {
            char old[4400];
            mps_ckpt_path(old, sizeof old, dir, prefix, k);
            unlink(old);
        }
    }
    closedir(d);
    return MPS_OK;
}

static enum mps_status read_header(FILE *f, const char *path, struct header *h,
                                   struct mps_err *err)
{
    if (fread(h, sizeof *h, 1, f) != 1 || memcmp(h->magic, MAGIC, 8) != 0)
        return mps_err_set(err, MPS_EINPUT, "%s: not a checkpoint file", path);
    if (h->version != VERSION)
        return mps_err_set(err, MPS_EINPUT, "%s: checkpoint version %u, this build reads %u",
                           path, (unsigned)h->version, VERSION);
    return MPS_OK;
}

enum mps_status mps_ckpt_read_file(struct mps_ckpt *c, const char *path, struct mps_err *err)
{
    FILE *f = fopen(path, "rb");
    if (!f) /* a checkpoint named that is not there: the request is wrong */
        return mps_err_set(err, errno == ENOENT ? MPS_EINPUT : MPS_EIO,
                           "cannot open checkpoint '%s': %s", path, strerror(errno));
    struct header h;
    uint64_t hash = 0;
    mps_ckpt_clear(c);
    enum mps_status st = read_header(f, path, &h, err);
    if (!st && !(st = reserve(c, (size_t)h.bytes, err))) {
        if (fread(c->buf, 1, (size_t)h.bytes, f) != (size_t)h.bytes ||
            fread(&hash, sizeof hash, 1, f) != 1)
            st = mps_err_set(err, MPS_EINPUT, "%s: truncated checkpoint", path);
        else if (hash != fnv1a(c->buf, (size_t)h.bytes))
            st = mps_err_set(err, MPS_EINPUT, "%s: checkpoint damaged (hash mismatch)", path);
    }
    fclose(f);
    if (st)
        return st;
    c->len = (size_t)h.bytes;
    c->pos = 0;
    c->time = h.time;
    c->number = (long)h.number;
    return MPS_OK;
}

enum mps_status mps_ckpt_find(const char *dir, const char *prefix, double from, char *path,
                              size_t len, struct mps_err *err)
{
    char cdir[4200];
    snprintf(cdir, sizeof cdir, "%s/" MPS_CKPT_DIR, dir);
    DIR *d = opendir(cdir);
    if (!d)
        return mps_err_set(err, MPS_EINPUT, "%s: no checkpoints (%s)", cdir, strerror(errno));
    long best = -1;
    double best_t = -INFINITY;
    struct dirent *e;
    while ((e = readdir(d))) {
        long k = number_of(e->d_name, prefix);
        if (k < 0)
            continue;
        char p[4400];
        mps_ckpt_path(p, sizeof p, dir, prefix, k);
        FILE *f = fopen(p, "rb");
        struct header h;
        if (!f)
            continue;
        int ok = fread(&h, sizeof h, 1, f) == 1 && memcmp(h.magic, MAGIC, 8) == 0;
        fclose(f);
        if (!ok)
            continue;
        /* --from: the nearest (a checkpoint is taken at the end of the
         * first step reaching its time, a little after it) */
        double score = from >= 0.0 ? -fabs(h.time - from) : h.time;
        if (best < 0 || score > best_t) {
            best_t = score;
            best = k;
        }
    }
    closedir(d);
    if (best < 0) {
        return mps_err_set(err, MPS_EINPUT, "%s: no %s checkpoint", cdir, prefix);
    }
    mps_ckpt_path(path, len, dir, prefix, best);
    return MPS_OK;
}
