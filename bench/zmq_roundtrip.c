/* The floor under the coupler's messaging: the round trip of one small
 * message between two processes over ZeroMQ on this machine, with nothing
 * else to do. A coupled step makes two such round trips (coupler-fluid,
 * coupler-solid), so twice this is the least messaging a step can cost.
 *
 *   cc -O2 bench/zmq_roundtrip.c -o /tmp/zmq_roundtrip -lzmq
 *   /tmp/zmq_roundtrip [ROUND_TRIPS] [BYTES] [ENDPOINT] [FRAMES] [curve]
 *
 * defaults: 5000 round trips of 2000 bytes over ipc:///tmp/zmq_roundtrip.sock,
 * one frame per message (FRAMES > 1 splits each message into that many
 * parts, as the coupling protocol's messages are). "curve" secures the
 * link with CURVE as the coupler does on tcp (PROTOCOL.md section 10; the
 * ZAP check runs once per connection, so it is left out here).
 * The receiver blocks in zmq_poll as the solvers do. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include <zmq.h>

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Waits up to 5 s for one message, all its parts; returns 0 on success. */
static int recv_one(void *s, char *buf, size_t size)
{
    zmq_pollitem_t item = {s, 0, ZMQ_POLLIN, 0};
    if (zmq_poll(&item, 1, 5000) != 1)
        return -1;
    int more = 1;
    while (more) {
        size_t len = sizeof more;
        if (zmq_recv(s, buf, size, 0) < 0 || zmq_getsockopt(s, ZMQ_RCVMORE, &more, &len) != 0)
            return -1;
    }
    return 0;
}

/* Sends size bytes as frames parts; returns 0 on success. */
static int send_one(void *s, const char *buf, size_t size, int frames)
{
    for (int k = 0; k < frames; k++)
        if (zmq_send(s, buf, size / (size_t)frames, k + 1 < frames ? ZMQ_SNDMORE : 0) < 0)
            return -1;
    return 0;
}

int main(int argc, char **argv)
{
    int n = argc > 1 ? atoi(argv[1]) : 5000;
    size_t size = argc > 2 ? (size_t)atol(argv[2]) : 2000;
    const char *endpoint = argc > 3 ? argv[3] : "ipc:///tmp/zmq_roundtrip.sock";
    int frames = argc > 4 ? atoi(argv[4]) : 1;
    int curve = argc > 5 && strcmp(argv[5], "curve") == 0;
    char spub[41], ssec[41], cpub[41], csec[41];
    if (curve && (zmq_curve_keypair(spub, ssec) || zmq_curve_keypair(cpub, csec))) {
        fprintf(stderr, "no CURVE in this libzmq\n");
        return 1;
    }
    if (n < 2 || size == 0 || frames < 1 || (size_t)frames > size) {
        fprintf(stderr, "usage: %s [ROUND_TRIPS >= 2] [BYTES > 0] [ENDPOINT] [FRAMES, 1..BYTES]\n",
                argv[0]);
        return 2;
    }
    char *buf = calloc(size, 1);
    if (!buf)
        return 1;
    pid_t pid = fork();
    if (pid < 0) {
        perror("fork");
        return 1;
    }
    void *ctx = zmq_ctx_new();
    void *s = zmq_socket(ctx, ZMQ_PAIR);
    int linger = 0;
    zmq_setsockopt(s, ZMQ_LINGER, &linger, sizeof linger);
    if (curve && pid == 0) {
        zmq_setsockopt(s, ZMQ_CURVE_SERVERKEY, spub, 40);
        zmq_setsockopt(s, ZMQ_CURVE_PUBLICKEY, cpub, 40);
        zmq_setsockopt(s, ZMQ_CURVE_SECRETKEY, csec, 40);
    } else if (curve) {
        int on = 1;
        zmq_setsockopt(s, ZMQ_CURVE_SERVER, &on, sizeof on);
        zmq_setsockopt(s, ZMQ_CURVE_SECRETKEY, ssec, 40);
    }
    if (pid == 0) { /* echo */
        if (zmq_connect(s, endpoint) != 0)
            return 1;
        for (int i = 0; i < n; i++)
            if (recv_one(s, buf, size) || send_one(s, buf, size, frames))
                return 1;
    } else {
        if (zmq_bind(s, endpoint) != 0) {
            fprintf(stderr, "cannot bind %s: %s\n", endpoint, zmq_strerror(zmq_errno()));
            return 1;
        }
        double t0 = 0.0;
        for (int i = 0; i < n; i++) {
            if (i == 1)
                t0 = now(); /* the first trip includes the connection */
            if (send_one(s, buf, size, frames) || recv_one(s, buf, size)) {
                fprintf(stderr, "round trip %d failed\n", i);
                return 1;
            }
        }
        printf("%d round trips of %zu bytes in %d frame(s) over %s%s: %.1f us each\n", n - 1,
               size, frames, endpoint, curve ? " with CURVE" : "",
               1e6 * (now() - t0) / (n - 1));
        int status = 0;
        waitpid(pid, &status, 0);
    }
    zmq_close(s);
    zmq_ctx_term(ctx);
    free(buf);
    return 0;
}
