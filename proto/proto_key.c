/* CURVE key files (proto_key.h, PROTOCOL.md section 10). */
#include "proto_key.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zmq.h>

int proto_key_curve_available(void)
{
    return zmq_has("curve") == 1;
}

enum mps_status proto_key_pair(char pub[PROTO_KEY_Z85 + 1], char sec[PROTO_KEY_Z85 + 1],
                               struct mps_err *err)
{
    if (!proto_key_curve_available())
        return mps_err_set(err, MPS_ELIB, "this libzmq has no CURVE security (built without "
                                          "libsodium): tcp transport is not available");
    if (zmq_curve_keypair(pub, sec) != 0)
        return mps_err_set(err, MPS_ELIB, "zmq_curve_keypair: %s", zmq_strerror(zmq_errno()));
    return MPS_OK;
}

enum mps_status proto_key_write(const char *path, const struct proto_curve *k,
                                struct mps_err *err)
{
    int fd = open(path, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (fd < 0)
        return mps_err_set(err, MPS_EIO, "%s: cannot create the key file: %s", path,
                           strerror(errno));
    char buf[512];
    int n = snprintf(buf, sizeof buf,
                     "# mpsfsi coupling key for one solver of one run (PROTOCOL.md section 10).\n"
                     "# Private: whoever holds it can join the run as this solver.\n"
                     "server_public=%s\nclient_public=%s\nclient_secret=%s\n",
                     k->server_public, k->client_public, k->client_secret);
    ssize_t w = n > 0 && (size_t)n < sizeof buf ? write(fd, buf, (size_t)n) : -1;
    int e = errno;
    if (close(fd) != 0 && w == n)
        w = -1, e = errno;
    if (w != n) {
        unlink(path);
        return mps_err_set(err, MPS_EIO, "%s: cannot write the key file: %s", path, strerror(e));
    }
    return MPS_OK;
}

/* 1 if s is exactly 40 characters that decode as Z85. */
static int z85_ok(const char *s)
{
    uint8_t bin[32];
    return strlen(s) == PROTO_KEY_Z85 && zmq_z85_decode(bin, s) != NULL;
}

enum mps_status proto_key_read(const char *path, struct proto_curve *k, struct mps_err *err)
{
    memset(k, 0, sizeof *k);
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return mps_err_set(err, MPS_EIO, "%s: cannot open the key file: %s", path,
                           strerror(errno));
    struct stat sb;
    if (fstat(fd, &sb) != 0) {
        int e = errno;
        close(fd);
        return mps_err_set(err, MPS_EIO, "%s: %s", path, strerror(e));
    }
    if (!S_ISREG(sb.st_mode)) {
        close(fd);
        return mps_err_set(err, MPS_EINPUT, "%s: the key file is not a regular file", path);
    }
    /* as ssh does with its keys: a secret others can read is no secret */
    if (sb.st_mode & 077) {
        close(fd);
        return mps_err_set(err, MPS_EINPUT,
                           "%s: the key file has mode %04o, others may read it: chmod 600 %s",
                           path, (unsigned)(sb.st_mode & 07777), path);
    }
    char buf[4096];
    ssize_t n = read(fd, buf, sizeof buf);
    char extra;
    int more = n == (ssize_t)sizeof buf && read(fd, &extra, 1) > 0;
    int e = errno;
    close(fd);
    if (n < 0)
        return mps_err_set(err, MPS_EIO, "%s: cannot read the key file: %s", path, strerror(e));
    if (more)
        return mps_err_set(err, MPS_EINPUT, "%s: not a key file (over %zu bytes)", path,
                           sizeof buf);
    if (memchr(buf, '\0', (size_t)n))
        return mps_err_set(err, MPS_EINPUT, "%s: not a key file (binary data)", path);
    struct {
        const char *name;
        char *dst;
    } fields[] = {{"server_public", k->server_public},
                  {"client_public", k->client_public},
                  {"client_secret", k->client_secret}};
    enum { NF = sizeof fields / sizeof fields[0] };
    int line = 0;
    for (char *p = buf, *end = buf + n; p < end;) {
        char *nl = memchr(p, '\n', (size_t)(end - p));
        char *stop = nl ? nl : end;
        line++;
        size_t len = (size_t)(stop - p);
        if (len && p[len - 1] == '\r')
            len--;
        if (len && p[0] != '#') {
            char *eq = memchr(p, '=', len);
            int f = -1;
            for (int q = 0; eq && q < NF; q++)
                if ((size_t)(eq - p) == strlen(fields[q].name) &&
                    memcmp(p, fields[q].name, (size_t)(eq - p)) == 0)
                    f = q;
            if (f < 0)
                return mps_err_set(err, MPS_EINPUT,
                                   "%s:%d: expected server_public=, client_public= or "
                                   "client_secret=, got '%.*s'",
                                   path, line, (int)(len < 40 ? len : 40), p);
            if (fields[f].dst[0])
                return mps_err_set(err, MPS_EINPUT, "%s:%d: %s given twice", path, line,
                                   fields[f].name);
            size_t vlen = len - (size_t)(eq + 1 - p);
            if (vlen != PROTO_KEY_Z85)
                return mps_err_set(err, MPS_EINPUT,
                                   "%s:%d: %s is %zu characters, a Z85 key has %d", path, line,
                                   fields[f].name, vlen, PROTO_KEY_Z85);
            memcpy(fields[f].dst, eq + 1, vlen);
            fields[f].dst[vlen] = '\0';
            if (!z85_ok(fields[f].dst))
                return mps_err_set(err, MPS_EINPUT, "%s:%d: %s is not a Z85 key", path, line,
                                   fields[f].name);
        }
        p = nl ? nl + 1 : end;
    }
    for (int q = 0; q < NF; q++)
        if (!fields[q].dst[0])
            return mps_err_set(err, MPS_EINPUT, "%s: %s missing", path, fields[q].name);
    char derived[PROTO_KEY_Z85 + 1];
    if (zmq_curve_public(derived, k->client_secret) != 0)
        return mps_err_set(err, MPS_ELIB, "%s: zmq_curve_public: %s", path,
                           zmq_strerror(zmq_errno()));
    if (strcmp(derived, k->client_public) != 0)
        return mps_err_set(err, MPS_EINPUT,
                           "%s: client_public does not belong to client_secret", path);
    return MPS_OK;
}
