/* proto_dump: the C side of the C <-> Python codec cross-check, and a small
 * tool to look at recorded messages. Frame files: PROTOCOL.md appendix A.
 *
 *   proto_dump --write DIR      one NAME.mpsf per sample (proto_samples.c)
 *   proto_dump --check FILE...  decode each file, compare with the sample
 *                               named by its basename, re-encode and compare
 *                               the bytes
 *   proto_dump --reject FILE... each file must fail to decode; prints why
 *   proto_dump --print FILE...  decode and print the fields
 * Exit status 0 when every file passes. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "proto_msg.h"
#include "proto_samples.h"

struct ffile {
    int n;
    struct proto_frame f[16];
    unsigned char *buf;
};

static void put_le(unsigned char *p, uint64_t v, int bytes)
{
    for (int i = 0; i < bytes; i++)
        p[i] = (v >> (8 * i)) & 0xff;
}

static uint64_t get_le(const unsigned char *p, int bytes)
{
    uint64_t v = 0;
    for (int i = 0; i < bytes; i++)
        v |= (uint64_t)p[i] << (8 * i);
    return v;
}

static int write_frames(const char *path, const struct proto_frames *fr)
{
    FILE *f = fopen(path, "wb");
    if (!f) {
        perror(path);
        return 0;
    }
    unsigned char head[8];
    memcpy(head, "MPSF", 4);
    put_le(head + 4, (uint64_t)fr->n, 4);
    int ok = fwrite(head, 1, 8, f) == 8;
    for (int k = 0; ok && k < fr->n; k++) {
        unsigned char len[8];
        put_le(len, fr->f[k].len, 8);
        ok = fwrite(len, 1, 8, f) == 8 &&
             (fr->f[k].len == 0 || fwrite(fr->f[k].data, 1, fr->f[k].len, f) == fr->f[k].len);
    }
    ok = (fclose(f) == 0) && ok;
    if (!ok)
        fprintf(stderr, "%s: write failed\n", path);
    return ok;
}

/* Reads a frame file; frames point into ff->buf. */
static int read_frames(const char *path, struct ffile *ff)
{
    memset(ff, 0, sizeof *ff);
    FILE *f = fopen(path, "rb");
    if (!f) {
        perror(path);
        return 0;
    }
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fseek(f, 0, SEEK_SET);
    ff->buf = malloc(size > 0 ? (size_t)size : 1);
    int ok = ff->buf && size >= 8 && fread(ff->buf, 1, (size_t)size, f) == (size_t)size;
    fclose(f);
    if (!ok || memcmp(ff->buf, "MPSF", 4) != 0) {
        fprintf(stderr, "%s: not a frame file\n", path);
        return 0;
    }
    uint64_t n = get_le(ff->buf + 4, 4), pos = 8;
    if (n > 16) {
        fprintf(stderr, "%s: %llu frames, at most 16\n", path, (unsigned long long)n);
        return 0;
    }
    for (uint64_t k = 0; k < n; k++) {
        if (pos + 8 > (uint64_t)size) {
            fprintf(stderr, "%s: truncated\n", path);
            return 0;
        }
        uint64_t len = get_le(ff->buf + pos, 8);
        pos += 8;
        if (len > (uint64_t)size - pos) {
            fprintf(stderr, "%s: truncated\n", path);
            return 0;
        }
        ff->f[k] = (struct proto_frame){ff->buf + pos, (size_t)len};
        pos += len;
    }
    ff->n = (int)n;
    return 1;
}

static int cmd_write(const char *dir)
{
    int ok = 1;
    for (int k = 0; k < proto_sample_count(); k++) {
        struct proto_msg m;
        struct proto_frames fr;
        struct mps_err e = {0};
        proto_sample_build(k, &m);
        if (proto_msg_encode(&m, &fr, &e)) {
            fprintf(stderr, "sample %s: %s\n", proto_sample_name(k), e.msg);
            ok = 0;
            continue;
        }
        char path[4096];
        snprintf(path, sizeof path, "%s/%s.mpsf", dir, proto_sample_name(k));
        ok &= write_frames(path, &fr);
        proto_frames_clear(&fr);
    }
    return ok;
}

static void sample_name_of(const char *path, char *name, size_t n)
{
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    snprintf(name, n, "%s", base);
    char *dot = strrchr(name, '.');
    if (dot)
        *dot = '\0';
}

static int check_file(const char *path)
{
    struct ffile ff;
    struct proto_msg m, want;
    struct proto_frames fr;
    struct mps_err e = {0};
    char name[256], why[128];
    int ok = 0;
    sample_name_of(path, name, sizeof name);
    int k = proto_sample_find(name);
    if (k < 0) {
        fprintf(stderr, "%s: no sample named '%s'\n", path, name);
        return 0;
    }
    if (!read_frames(path, &ff))
        goto out;
    if (proto_msg_decode(&m, ff.f, ff.n, &e)) {
        fprintf(stderr, "%s: %s\n", path, e.msg);
        goto out;
    }
    proto_sample_build(k, &want);
    if (!proto_msg_same(&want, &m, why, sizeof why)) {
        fprintf(stderr, "%s: decoded %s, but %s\n", path, proto_type_name(m.type), why);
    } else if (proto_msg_encode(&m, &fr, &e)) {
        fprintf(stderr, "%s: re-encoding: %s\n", path, e.msg);
    } else {
        ok = fr.n == ff.n;
        for (int i = 0; ok && i < fr.n; i++)
            ok = fr.f[i].len == ff.f[i].len &&
                 (fr.f[i].len == 0 || memcmp(fr.f[i].data, ff.f[i].data, fr.f[i].len) == 0);
        if (!ok)
            fprintf(stderr, "%s: re-encoded bytes differ from the file\n", path);
        proto_frames_clear(&fr);
    }
    proto_msg_clear(&m);
    if (ok)
        printf("ok %s (%s, %d frames)\n", name, proto_type_name(want.type), ff.n);
out:
    free(ff.buf);
    return ok;
}

static int reject_file(const char *path)
{
    struct ffile ff;
    struct proto_msg m;
    struct mps_err e = {0};
    int ok = 0;
    if (read_frames(path, &ff)) {
        enum mps_status st = proto_msg_decode(&m, ff.f, ff.n, &e);
        if (st == MPS_EPROTO) {
            printf("%s: %s\n", path, e.msg);
            ok = 1;
        } else {
            fprintf(stderr, "%s: decoded (%s), expected a rejection\n", path,
                    mps_status_name(st));
            proto_msg_clear(&m);
        }
    }
    free(ff.buf);
    return ok;
}

static int print_file(const char *path)
{
    struct ffile ff;
    struct proto_msg m;
    struct mps_err e = {0};
    int ok = read_frames(path, &ff) && proto_msg_decode(&m, ff.f, ff.n, &e) == MPS_OK;
    if (!ok) {
        fprintf(stderr, "%s: %s\n", path, e.msg);
    } else {
        printf("%s: %s payload %s flags 0x%x step %lld iteration %d n_sub %d time %.17g dt "
               "%.17g count %zu nprobes %d\n",
               path, proto_type_name(m.type), proto_payload_name(m.payload), (unsigned)m.flags,
               (long long)m.step, (int)m.iteration, (int)m.n_sub, m.time, m.dt, m.count,
               m.nprobes);
        if (m.text)
            printf("  text: %s\n", m.text);
        proto_msg_clear(&m);
    }
    free(ff.buf);
    return ok;
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: %s --write DIR | --check FILE... | --reject FILE... | "
                        "--print FILE...\n", argv[0]);
        return 2;
    }
    int ok = 1;
    if (strcmp(argv[1], "--write") == 0) {
        ok = cmd_write(argv[2]);
    } else {
        int (*fn)(const char *) = strcmp(argv[1], "--check") == 0    ? check_file
                                  : strcmp(argv[1], "--reject") == 0 ? reject_file
                                  : strcmp(argv[1], "--print") == 0  ? print_file
                                                                     : NULL;
        if (!fn) {
            fprintf(stderr, "%s: unknown option %s\n", argv[0], argv[1]);
            return 2;
        }
        for (int i = 2; i < argc; i++)
            ok &= fn(argv[i]);
    }
    return ok ? 0 : 1;
}
