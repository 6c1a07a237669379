/* Wall-clock accounting of the phases of a step, for the run summary and the
 * speed reports. Phases are small integers the solver defines. */
#ifndef MPS_TIMER_H
#define MPS_TIMER_H

#define MPS_TIMER_MAX_PHASES 16

struct mps_timer {
    int nphases;
    const char *names[MPS_TIMER_MAX_PHASES];
    double seconds[MPS_TIMER_MAX_PHASES];
    double started;   /* wall time of the open phase, or < 0 */
    int open_phase;
};

/* Monotonic wall clock in seconds. */
double mps_wall_seconds(void);

/* names: nphases phase names, borrowed (string literals). */
void mps_timer_init(struct mps_timer *t, const char *const *names, int nphases);
/* Closes the open phase (if any) and opens phase. */
void mps_timer_switch(struct mps_timer *t, int phase);
/* Closes the open phase. */
void mps_timer_stop(struct mps_timer *t);
double mps_timer_total(const struct mps_timer *t);

#endif
