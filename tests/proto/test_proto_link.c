/* The ZeroMQ link over ipc:// in a temporary directory: a whole conversation
 * with a fake solid in a thread, receive deadlines and signals, a
 * wrong-version HELLO answered by a REJECT, and malformed multipart input. */
#include <pthread.h>
#include <signal.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include <zmq.h>

#include "proto_link.h"
#include "proto_samples.h"
#include "test_util.h"

static void *ctx;
static char dir[64];

static void endpoint(char *buf, size_t n, const char *name)
{
    snprintf(buf, n, "ipc://%s/%s.sock", dir, name);
}

static long long now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (long long)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
}

static void *open_sock(enum proto_link_mode mode, const char *ep)
{
    void *s = NULL;
    struct mps_err e = {0};
    enum mps_status st = proto_link_open(ctx, mode, ep, &s, &e);
    CHECK(st == MPS_OK);
    if (st)
        fprintf(stderr, "open %s: %s\n", ep, e.msg);
    return s;
}

/* ---- a fake solid solver, in a thread: HELLO, READY, RESULT, BYE ---- */

static int solver_failures;
static char solver_ep[128];

#define SOLVER_CHECK(cond)                                                        \
    do {                                                                          \
        if (!(cond)) {                                                            \
            solver_failures++;                                                    \
            fprintf(stderr, "%s:%d: solver: failed: %s (%s)\n", __FILE__, __LINE__, #cond, \
                    e.msg);                                                       \
        }                                                                         \
    } while (0)

static void *fake_solid(void *arg)
{
    (void)arg;
    struct mps_err e = {0};
    void *s = NULL;
    SOLVER_CHECK(proto_link_open(ctx, PROTO_LINK_CONNECT, solver_ep, &s, &e) == MPS_OK);
    struct proto_msg m = proto_msg_make(PROTO_HELLO), in, want;
    char hello[96];
    snprintf(hello, sizeof hello, "role=solid model=fake pid=%ld", (long)getpid());
    m.text = hello;
    SOLVER_CHECK(proto_link_send(s, &m, &e) == MPS_OK);

    SOLVER_CHECK(proto_link_recv(s, &in, 5000, &e) == MPS_OK);
    char prefix[16];
    SOLVER_CHECK(in.type == PROTO_CONFIG);
    SOLVER_CHECK(proto_text_get(in.text, '\n', "prefix", prefix, sizeof prefix) == 1);
    proto_msg_clear(&in);

    proto_sample_build(proto_sample_find("ready_solid"), &m);
    SOLVER_CHECK(proto_link_send(s, &m, &e) == MPS_OK);

    char why[128] = "";
    SOLVER_CHECK(proto_link_recv(s, &in, 5000, &e) == MPS_OK);
    proto_sample_build(proto_sample_find("advance_solid"), &want);
    SOLVER_CHECK(proto_msg_same(&want, &in, why, sizeof why));
    proto_msg_clear(&in);

    proto_sample_build(proto_sample_find("result_solid"), &m);
    SOLVER_CHECK(proto_link_send(s, &m, &e) == MPS_OK);

    SOLVER_CHECK(proto_link_recv(s, &in, 5000, &e) == MPS_OK);
    SOLVER_CHECK(in.type == PROTO_STOP);
    proto_msg_clear(&in);
    proto_sample_build(proto_sample_find("bye"), &m);
    SOLVER_CHECK(proto_link_send(s, &m, &e) == MPS_OK);
    proto_link_close(&s);
    return NULL;
}

/* Coupler side, in the main thread; strict request/reply, so the two threads
 * never build samples (shared static storage) at the same time. */
static void test_conversation(void)
{
    endpoint(solver_ep, sizeof solver_ep, "solid");
    void *s = open_sock(PROTO_LINK_BIND, solver_ep);
    pthread_t th;
    CHECK(pthread_create(&th, NULL, fake_solid, NULL) == 0);

    struct mps_err e = {0};
    struct proto_msg in, m, want;
    char role[16], why[128] = "";
    CHECK(proto_link_recv(s, &in, 5000, &e) == MPS_OK);
    CHECK(in.type == PROTO_HELLO);
    CHECK(proto_text_get(in.text, ' ', "role", role, sizeof role) == 1 && !strcmp(role, "solid"));
    proto_msg_clear(&in);

    proto_sample_build(proto_sample_find("config"), &m);
    CHECK(proto_link_send(s, &m, &e) == MPS_OK);
    CHECK(proto_link_recv(s, &in, 5000, &e) == MPS_OK);
    proto_sample_build(proto_sample_find("ready_solid"), &want);
    CHECK(proto_msg_same(&want, &in, why, sizeof why));
    proto_msg_clear(&in);

    proto_sample_build(proto_sample_find("advance_solid"), &m);
    CHECK(proto_link_send(s, &m, &e) == MPS_OK);
    CHECK(proto_link_recv(s, &in, 5000, &e) == MPS_OK);
    proto_sample_build(proto_sample_find("result_solid"), &want);
    CHECK(proto_msg_same(&want, &in, why, sizeof why));
    proto_msg_clear(&in);

    proto_sample_build(proto_sample_find("stop"), &m);
    CHECK(proto_link_send(s, &m, &e) == MPS_OK);
    CHECK(proto_link_recv(s, &in, 5000, &e) == MPS_OK);
    CHECK(in.type == PROTO_BYE && in.text && in.text[0] == '{');
    proto_msg_clear(&in);
    if (why[0])
        fprintf(stderr, "conversation: %s\n", why);

    CHECK(pthread_join(th, NULL) == 0);
    CHECK(solver_failures == 0);
    proto_link_close(&s);
    CHECK(s == NULL);
    proto_link_close(&s);
}

static void test_timeout(void)
{
    char ep[128];
    endpoint(ep, sizeof ep, "quiet");
    void *s = open_sock(PROTO_LINK_BIND, ep);
    struct proto_msg in;
    struct mps_err e = {0};
    long long t0 = now_ms();
    enum mps_status st = proto_link_recv(s, &in, 200, &e);
    long long dt = now_ms() - t0;
    CHECK(st == MPS_ETIMEOUT);
    CHECK(dt >= 190 && dt < 1500);
    CHECK(strstr(e.msg, "no message within 200 ms") != NULL);
    CHECK(in.own_ == NULL && in.type == 0);
    printf("  timeout after %lld ms: %s\n", dt, e.msg);
    proto_link_close(&s);
}

/* ---- a signal during the wait ends it with MPS_EINTR ---- */

static volatile sig_atomic_t got_signal;
static void on_signal(int sig) { got_signal = sig; }

static void *poke(void *arg)
{
    struct timespec ts = {0, 100 * 1000000L};
    nanosleep(&ts, NULL);
    pthread_kill(*(pthread_t *)arg, SIGUSR1);
    return NULL;
}

static void test_interrupt(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal; /* no SA_RESTART, as the programs install it */
    sigemptyset(&sa.sa_mask);
    CHECK(sigaction(SIGUSR1, &sa, NULL) == 0);

    char ep[128];
    endpoint(ep, sizeof ep, "intr");
    void *s = open_sock(PROTO_LINK_BIND, ep);
    pthread_t self = pthread_self(), th;
    CHECK(pthread_create(&th, NULL, poke, &self) == 0);
    struct proto_msg in;
    struct mps_err e = {0};
    long long t0 = now_ms();
    enum mps_status st = proto_link_recv(s, &in, 5000, &e);
    long long dt = now_ms() - t0;
    CHECK(st == MPS_EINTR);
    CHECK(got_signal == SIGUSR1);
    CHECK(dt < 3000);
    printf("  interrupted after %lld ms: %s\n", dt, e.msg);
    pthread_join(th, NULL);
    proto_link_close(&s);
    signal(SIGUSR1, SIG_DFL);
}

/* Sends raw frames, as a foreign or broken peer would. */
static void send_raw(void *s, const struct proto_frame *f, int n)
{
    for (int k = 0; k < n; k++)
        CHECK(zmq_send(s, f[k].data, f[k].len, k + 1 < n ? ZMQ_SNDMORE : 0) == (int)f[k].len);
}

static void test_wrong_version_hello(void)
{
    char ep[128];
    endpoint(ep, sizeof ep, "fluid");
    void *coupler = open_sock(PROTO_LINK_BIND, ep);
    void *solver = open_sock(PROTO_LINK_CONNECT, ep);

    struct proto_msg m, in;
    struct proto_frames fr;
    struct mps_err e = {0};
    proto_sample_build(proto_sample_find("hello"), &m);
    CHECK(proto_msg_encode(&m, &fr, &e) == MPS_OK);
    unsigned char h2[PROTO_HEADER_LEN];
    memcpy(h2, fr.f[0].data, sizeof h2);
    h2[4] = 1; /* a version-1 solver (before implicit coupling) */
    fr.f[0].data = h2;
    send_raw(solver, fr.f, fr.n);
    proto_frames_clear(&fr);

    CHECK(proto_link_recv(coupler, &in, 5000, &e) == MPS_EPROTO);
    CHECK(strstr(e.msg, "protocol version 1 received, this build speaks version 2") != NULL);
    printf("  wrong-version HELLO: %s\n", e.msg);

    /* the coupler turns it away with the reason; the solver reads it */
    char reason[sizeof e.msg];
    memcpy(reason, e.msg, sizeof reason);
    struct proto_msg rej = proto_msg_make(PROTO_REJECT);
    rej.text = reason;
    CHECK(proto_link_send(coupler, &rej, &e) == MPS_OK);
    CHECK(proto_link_recv(solver, &in, 5000, &e) == MPS_OK);
    CHECK(in.type == PROTO_REJECT && in.text && strstr(in.text, "version 1 received"));
    proto_msg_clear(&in);

    /* a message of too many frames is dropped whole; the next one is fine */
    struct proto_frame junk[9];
    for (int k = 0; k < 9; k++)
        junk[k] = (struct proto_frame){"", 0};
    send_raw(solver, junk, 9);
    CHECK(proto_link_recv(coupler, &in, 5000, &e) == MPS_EPROTO);
    CHECK(strstr(e.msg, "message of 9 frames, at most 8") != NULL);
    proto_sample_build(proto_sample_find("error"), &m);
    CHECK(proto_link_send(solver, &m, &e) == MPS_OK);
    CHECK(proto_link_recv(coupler, &in, 5000, &e) == MPS_OK);
    CHECK(in.type == PROTO_ERROR && proto_error_status(in.text, NULL) == MPS_EDIVERGED);
    proto_msg_clear(&in);

    /* a message breaking a rule is refused before anything is sent */
    proto_sample_build(proto_sample_find("advance_solid"), &m);
    m.dt = -1.0;
    CHECK(proto_link_send(coupler, &m, &e) == MPS_EPROTO && strstr(e.msg, "dt = -1"));
    CHECK(proto_link_recv(solver, &in, 100, &e) == MPS_ETIMEOUT);

    proto_link_close(&solver);
    proto_link_close(&coupler);
}

static void test_poll_two(void)
{
    char ep_a[128], ep_b[128];
    endpoint(ep_a, sizeof ep_a, "a");
    endpoint(ep_b, sizeof ep_b, "b");
    void *a = open_sock(PROTO_LINK_BIND, ep_a), *b = open_sock(PROTO_LINK_BIND, ep_b);
    void *pb = open_sock(PROTO_LINK_CONNECT, ep_b);
    struct proto_msg m, in;
    struct mps_err e = {0};
    proto_sample_build(proto_sample_find("error"), &m);
    CHECK(proto_link_send(pb, &m, &e) == MPS_OK);
    void *both[2] = {a, b};
    int which = -1;
    CHECK(proto_link_poll(both, 2, 5000, &which, &e) == MPS_OK && which == 1);
    CHECK(proto_link_recv(b, &in, 0, &e) == MPS_OK && in.type == PROTO_ERROR);
    proto_msg_clear(&in);
    CHECK(proto_link_poll(both, 2, 50, &which, &e) == MPS_ETIMEOUT);
    proto_link_close(&pb);
    proto_link_close(&a);
    proto_link_close(&b);
}

static void test_bad_endpoints(void)
{
    char ep[256] = "ipc://";
    memset(ep + 6, 'a', 120);
    ep[126] = '\0';
    void *s = (void *)1;
    struct mps_err e = {0};
    CHECK(proto_link_open(ctx, PROTO_LINK_BIND, ep, &s, &e) == MPS_EINPUT && s == NULL);
    CHECK(strstr(e.msg, "ipc path is 120 bytes, the system allows 107") != NULL);
    CHECK(proto_link_open(ctx, PROTO_LINK_BIND, "ipc:///nonexistent-dir-mps/x.sock", &s, &e) ==
          MPS_ELIB);
    CHECK(strstr(e.msg, "cannot bind ipc:///nonexistent-dir-mps/x.sock") != NULL);
    printf("  bad endpoint: %s\n", e.msg);
}

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/mpsproto-XXXXXX");
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    ctx = zmq_ctx_new();
    test_conversation();
    test_timeout();
    test_interrupt();
    test_wrong_version_hello();
    test_poll_two();
    test_bad_endpoints();
    zmq_ctx_term(ctx);
    /* the bound sockets remove their files on close; remove leftovers anyway */
    static const char *const names[] = {"solid", "quiet", "intr", "fluid", "a", "b"};
    for (size_t k = 0; k < sizeof names / sizeof *names; k++) {
        char p[128];
        snprintf(p, sizeof p, "%s/%s.sock", dir, names[k]);
        unlink(p);
    }
    CHECK(rmdir(dir) == 0);
    return test_summary("proto_link");
}
