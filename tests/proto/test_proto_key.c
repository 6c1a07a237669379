/* CURVE key files (proto_key.h, PROTOCOL.md section 10): what is accepted,
 * what is refused and why, and that a CURVE link only carries messages
 * between holders of matching keys. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zmq.h>

#include "proto_key.h"
#include "proto_link.h"
#include "test_util.h"

static char dir[64];

static const char *write_file(const char *name, const char *text, mode_t mode)
{
    static char path[128];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    unlink(path);
    FILE *f = fopen(path, "w");
    if (!f)
        return path;
    fputs(text, f);
    fclose(f);
    chmod(path, mode);
    return path;
}

/* The load fails with a message holding want. */
static void refused(const char *name, const char *text, mode_t mode, const char *want)
{
    struct proto_curve k;
    struct mps_err err = {0};
    const char *path = write_file(name, text, mode);
    enum mps_status st = proto_key_read(path, &k, &err);
    CHECK(st == MPS_EINPUT);
    if (!strstr(err.msg, want)) {
        test_failures++;
        fprintf(stderr, "%s: expected \"%s\" in: %s\n", name, want, err.msg);
    }
    test_checks++;
}

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/test_key_XXXXXX");
    if (!mkdtemp(dir))
        return 1;
    CHECK(proto_key_curve_available());
    struct proto_curve k = {0}, r;
    struct mps_err err = {0};
    CHECK(proto_key_pair(k.server_public, k.server_secret, &err) == MPS_OK);
    CHECK(proto_key_pair(k.client_public, k.client_secret, &err) == MPS_OK);

    /* written 0600, read back the same; never over an existing file */
    char path[128];
    snprintf(path, sizeof path, "%s/solid.key", dir);
    CHECK(proto_key_write(path, &k, &err) == MPS_OK);
    struct stat sb;
    CHECK(stat(path, &sb) == 0 && (sb.st_mode & 0777) == 0600);
    CHECK(proto_key_read(path, &r, &err) == MPS_OK);
    CHECK(strcmp(r.server_public, k.server_public) == 0 &&
          strcmp(r.client_public, k.client_public) == 0 &&
          strcmp(r.client_secret, k.client_secret) == 0 && r.server_secret[0] == '\0');
    CHECK(proto_key_write(path, &k, &err) == MPS_EIO);

    char good[512], text[600];
    snprintf(good, sizeof good, "server_public=%s\nclient_public=%s\nclient_secret=%s\n",
             k.server_public, k.client_public, k.client_secret);
    refused("mode", good, 0644, "mode 0644, others may read it");
    refused("empty", "", 0600, "server_public missing");
    snprintf(text, sizeof text, "%sclient_public=%s\n", good, k.client_public);
    refused("twice", text, 0600, ":4: client_public given twice");
    snprintf(text, sizeof text, "# comment\nserver_key=%s\n", k.server_public);
    refused("unknown", text, 0600, ":2: expected server_public=");
    refused("short", "server_public=abc\n", 0600, ":1: server_public is 3 characters");
    snprintf(text, sizeof text, "server_public=%.39s~\n", k.server_public); /* ~ not Z85 */
    refused("not_z85", text, 0600, ":1: server_public is not a Z85 key");
    /* the public key of another pair */
    snprintf(text, sizeof text, "server_public=%s\nclient_public=%s\nclient_secret=%s\n",
             k.server_public, k.server_public, k.client_secret);
    refused("mismatch", text, 0600, "client_public does not belong to client_secret");
    {
        const char *bin = write_file("binary", "", 0600);
        FILE *f = fopen(bin, "wb");
        if (f) {
            fwrite("server_public=\0\x01", 1, 16, f);
            fclose(f);
        }
        CHECK(proto_key_read(bin, &r, &err) == MPS_EINPUT && strstr(err.msg, "binary data"));
    }
    snprintf(path, sizeof path, "%s/nope.key", dir);
    CHECK(proto_key_read(path, &r, &err) == MPS_EIO);

    /* a link: the server's key must match, else nothing arrives */
    void *ctx = zmq_ctx_new();
    struct proto_curve other = k;
    CHECK(proto_key_pair(other.server_public, other.server_secret, &err) == MPS_OK);
    for (int wrong = 0; wrong < 2; wrong++) {
        void *srv = NULL, *cli = NULL;
        char ep[64];
        size_t len = sizeof ep;
        /* a free port, chosen by the system */
        CHECK(proto_link_open_secure(ctx, PROTO_LINK_BIND, "tcp://127.0.0.1:*", &k, "solid",
                                     &srv, &err) == MPS_OK);
        if (!srv || zmq_getsockopt(srv, ZMQ_LAST_ENDPOINT, ep, &len) != 0)
            return test_summary("test_proto_key");
        CHECK(proto_link_open_secure(ctx, PROTO_LINK_CONNECT, ep, wrong ? &other : &k, NULL,
                                     &cli, &err) == MPS_OK);
        struct proto_msg m = proto_msg_make(PROTO_HELLO), got;
        m.text = "role=solid model=test pid=1";
        int sndtimeo = 200;
        zmq_setsockopt(cli, ZMQ_SNDTIMEO, &sndtimeo, sizeof sndtimeo);
        proto_link_send(cli, &m, &err);
        enum mps_status st = proto_link_recv(srv, &got, 1500, &err);
        if (wrong)
            CHECK(st == MPS_ETIMEOUT); /* handshake failed: nothing got through */
        else
            CHECK(st == MPS_OK && got.type == PROTO_HELLO);
        proto_msg_clear(&got);
        int linger = 0;
        zmq_setsockopt(cli, ZMQ_LINGER, &linger, sizeof linger);
        zmq_setsockopt(srv, ZMQ_LINGER, &linger, sizeof linger);
        proto_link_close(&cli);
        proto_link_close(&srv);
    }
    zmq_ctx_term(ctx);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
    return test_summary("test_proto_key");
}
