/* Terminal progress for long runs: simulated time, steps/s and ETA on one
 * line of stderr, refreshed at most once a second; silent when quiet. */
#ifndef MPS_PROGRESS_H
#define MPS_PROGRESS_H

struct mps_progress {
    int quiet;
    const char *label;
    double wall_start, wall_last;
    double end_time;
    /* the first update's simulated time and wall clock: the ETA's baseline
     * (a restart starts at its checkpoint's time, not at 0) */
    double time_base, wall_base;
    long steps_at_last;
    int printed;
};

void mps_progress_init(struct mps_progress *p, const char *label, double end_time, int quiet);
void mps_progress_update(struct mps_progress *p, double time, long step);
/* Seconds of wall time to end_time at the mean rate (simulated seconds per
 * wall second) since the first update; negative while unknown. */
double mps_progress_eta(const struct mps_progress *p, double time, double now);
/* Prints the final line (with newline) if anything was printed. */
void mps_progress_finish(struct mps_progress *p, double time, long step);

#endif
