#include "mps_timer.h"

#include <time.h>

double mps_wall_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void mps_timer_init(struct mps_timer *t, const char *const *names, int nphases)
{
    if (nphases > MPS_TIMER_MAX_PHASES)
        nphases = MPS_TIMER_MAX_PHASES;
    if (nphases < 0)
        nphases = 0;
    t->nphases = nphases;
    for (int k = 0; k < MPS_TIMER_MAX_PHASES; k++) {
        t->names[k] = k < nphases && names ? names[k] : NULL;
        t->seconds[k] = 0.0;
    }
    t->started = -1.0;
    t->open_phase = -1;
}

void mps_timer_switch(struct mps_timer *t, int phase)
{
    double now = mps_wall_seconds();
    if (t->started >= 0.0 && t->open_phase >= 0 && t->open_phase < t->nphases)
        t->seconds[t->open_phase] += now - t->started;
    if (phase >= 0 && phase < t->nphases) {
        t->open_phase = phase;
        t->started = now;
    } else {
        t->open_phase = -1;
        t->started = -1.0;
    }
}

void mps_timer_stop(struct mps_timer *t)
{
    mps_timer_switch(t, -1);
}

double mps_timer_total(const struct mps_timer *t)
{
    double s = 0.0;
    for (int k = 0; k < t->nphases; k++)
        s += t->seconds[k];
    return s;
}
