#include "proto_samples.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define SAMPLE_MAX 8

struct sample {
    const char *name;
    enum proto_type type;
    enum proto_payload payload;
    unsigned flags;
    long long step;
    int n_sub;
    double time, dt;
    size_t count;
    int nprobes;
    const char *text;
};

/* Keep in step with SAMPLES in test_python_codec.py. */
static const struct sample samples[] = {
    {"hello", PROTO_HELLO, PROTO_NONE, 0, 0, 0, 0, 0, 0, 0, "role=fluid model=mps pid=4242"},
    {"reject", PROTO_REJECT, PROTO_NONE, 0, 0, 0, 0, 0, 0, 0,
     "protocol version 1 received, this build speaks version 2"},
    {"config", PROTO_CONFIG, PROTO_NONE, 0, 0, 0, 0, 0, 0, 0,
     "case=/tmp/run/case.resolved.yml\nout=/tmp/run/out dir\nprefix=fluid\ntimeout_ms=1260000\n"},
    {"ready_fluid", PROTO_READY, PROTO_NONE, 0, 0, 0, 0, 0x1p-13, 0, 2, "p_gauge,h_front"},
    {"ready_solid", PROTO_READY, PROTO_STATE, 0, 0, 0, 0, 0x1p-18, 5, 1, "tip_dx"},
    {"advance_fluid", PROTO_ADVANCE, PROTO_STATE, PROTO_F_SNAPSHOT | PROTO_F_PROBES, 41, 1,
     0.015625, 0x1p-13, 7, 0, NULL},
    {"advance_solid", PROTO_ADVANCE, PROTO_LOADS, 0, 41, 40, 0.015625, 0x1p-13, 4, 0, NULL},
    {"advance_none", PROTO_ADVANCE, PROTO_NONE, 0, 0, 1, 0, 0x1p-10, 0, 0, NULL},
    {"result_fluid", PROTO_RESULT, PROTO_LOADS, PROTO_F_PROBES, 41, 0, 0.015625 + 0x1p-13,
     0x1p-12, 4, 2, NULL},
    {"result_solid", PROTO_RESULT, PROTO_STATE, 0, 41, 0, 0.015625 + 0x1p-13, 0x1p-19, 6, 0,
     NULL},
    {"result_empty", PROTO_RESULT, PROTO_LOADS, PROTO_F_PROBES, 3, 0, 0.5, 0.25, 0, 0, NULL},
    {"stop", PROTO_STOP, PROTO_NONE, 0, 1000, 0, 0.5, 0, 0, 0, NULL},
    {"bye", PROTO_BYE, PROTO_NONE, 0, 1000, 0, 0.5, 0, 0, 0,
     "{\"solver\":\"fluid\",\"steps\":1000,\"wall_s\":12.5,\"note\":\"\xce\x94t ok\"}"},
    {"error", PROTO_ERROR, PROTO_NONE, 0, 41, 0, 0.015625, 0, 0, 0,
     "diverged: particle 17 x = nan at t = 0.015625 s"},
    {"abort", PROTO_ABORT, PROTO_NONE, 0, 41, 0, 0.015625, 0, 0, 0,
     "fluid: diverged: particle 17 x = nan at t = 0.015625 s"},
};

enum { NSAMPLES = sizeof samples / sizeof *samples };

int proto_sample_count(void) { return NSAMPLES; }

const char *proto_sample_name(int k) { return k >= 0 && k < NSAMPLES ? samples[k].name : NULL; }

int proto_sample_find(const char *name)
{
    for (int k = 0; k < NSAMPLES; k++)
        if (strcmp(samples[k].name, name) == 0)
            return k;
    return -1;
}

static int id_[SAMPLE_MAX];
static double x_[SAMPLE_MAX][MPS_DIM], v_[SAMPLE_MAX][MPS_DIM], f_[SAMPLE_MAX][MPS_DIM];
static double p_[SAMPLE_MAX], probes_[2];
static unsigned char surface_[SAMPLE_MAX], fixed_[SAMPLE_MAX];

void proto_sample_build(int k, struct proto_msg *m)
{
    const struct sample *s = &samples[k];
    *m = proto_msg_make(s->type);
    m->payload = s->payload;
    m->flags = s->flags;
    m->step = s->step;
    m->n_sub = s->n_sub;
    m->time = s->time;
    m->dt = s->dt;
    m->count = s->count;
    m->nprobes = s->nprobes;
    m->text = s->text;
    for (size_t i = 0; i < s->count; i++) {
        id_[i] = 1000 * k + 3 * (int)i + 1;
        for (int d = 0; d < MPS_DIM; d++) {
            x_[i][d] = 0.125 * (double)(i + 1) + 0.5 * d - 0.25 * k;
            v_[i][d] = -0.0625 * (double)(i + 1) + 2.0 * d;
            f_[i][d] = (d ? -0.75 : 0.75) * (double)(i + 1) + k;
        }
        p_[i] = 1000.5 * (double)(i + 1);
        surface_[i] = i % 2;
        fixed_[i] = i % 3 == 0;
    }
    if (s->payload != PROTO_NONE)
        m->id = id_;
    if (s->payload == PROTO_STATE) {
        m->x = (const double (*)[MPS_DIM])x_;
        m->v = (const double (*)[MPS_DIM])v_;
        m->surface = surface_;
        m->fixed = fixed_;
    } else if (s->payload == PROTO_LOADS) {
        m->pressure = p_;
        m->force = (const double (*)[MPS_DIM])f_;
    }
    if (s->type == PROTO_RESULT && (s->flags & PROTO_F_PROBES)) {
        probes_[0] = 101325.5;
        probes_[1] = NAN; /* "no value" */
        m->probes = probes_;
    }
}

/* Bit for bit, except that any two NaNs match (probe "no value"). */
static int same_bits(const double *a, const double *b, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!(isnan(a[i]) && isnan(b[i])) && memcmp(&a[i], &b[i], sizeof *a) != 0)
            return 0;
    return 1;
}

int proto_msg_same(const struct proto_msg *a, const struct proto_msg *b, char *why, size_t n)
{
#define DIFF(cond, what)                       \
    do {                                       \
        if (cond) {                            \
            snprintf(why, n, "%s differs", what); \
            return 0;                          \
        }                                      \
    } while (0)
    DIFF(a->type != b->type, "type");
    DIFF(a->payload != b->payload, "payload");
    DIFF((a->flags & ~PROTO_F_TEXT) != (b->flags & ~PROTO_F_TEXT), "flags");
    DIFF(a->step != b->step, "step");
    DIFF(a->iteration != b->iteration, "iteration");
    DIFF(a->n_sub != b->n_sub, "n_sub");
    DIFF(memcmp(&a->time, &b->time, 8) != 0, "time");
    DIFF(memcmp(&a->dt, &b->dt, 8) != 0, "dt");
    DIFF(a->count != b->count, "count");
    DIFF(a->nprobes != b->nprobes, "nprobes");
    DIFF(!a->text != !b->text, "text presence");
    DIFF(a->text && strcmp(a->text, b->text) != 0, "text");
    size_t c = a->count, cd = a->count * MPS_DIM;
    if (a->payload != PROTO_NONE && c)
        DIFF(memcmp(a->id, b->id, c * sizeof *a->id) != 0, "id");
    if (a->payload == PROTO_STATE && c) {
        DIFF(!same_bits(&a->x[0][0], &b->x[0][0], cd), "x");
        DIFF(!same_bits(&a->v[0][0], &b->v[0][0], cd), "v");
        DIFF(memcmp(a->surface, b->surface, c) != 0, "surface");
        DIFF(memcmp(a->fixed, b->fixed, c) != 0, "fixed");
    }
    if (a->payload == PROTO_LOADS && c) {
        DIFF(!same_bits(a->pressure, b->pressure, c), "pressure");
        DIFF(!same_bits(&a->force[0][0], &b->force[0][0], cd), "force");
    }
    if (a->type == PROTO_RESULT && (a->flags & PROTO_F_PROBES))
        DIFF(!same_bits(a->probes, b->probes, (size_t)a->nprobes), "probes");
#undef DIFF
    return 1;
}
