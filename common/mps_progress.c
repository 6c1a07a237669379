#include "mps_progress.h"

#include <stdio.h>
#include <unistd.h>

#include "mps_timer.h"

/* On a terminal the line is redrawn in place ('\r') at most once a second; in
 * a log file (not a TTY) a full line is written at most every 10 s. */
#define TTY_PERIOD 1.0
#define LOG_PERIOD 10.0

static int is_tty(void)
{
    return isatty(fileno(stderr));
}

static void format_eta(char *buf, size_t n, double s)
{
    if (!(s >= 0.0) || s > 1e8)
        snprintf(buf, n, "ETA ?");
    else if (s < 120.0)
        snprintf(buf, n, "ETA %.0f s", s);
    else if (s < 7200.0)
        snprintf(buf, n, "ETA %.0f min", s / 60.0);
    else
        snprintf(buf, n, "ETA %.1f h", s / 3600.0);
}

void mps_progress_init(struct mps_progress *p, const char *label, double end_time, int quiet)
{
    p->quiet = quiet;
    p->label = label ? label : "";
    p->wall_start = p->wall_last = mps_wall_seconds();
    p->end_time = end_time;
    p->steps_at_last = -1; /* no step seen yet */
    p->time_base = p->wall_base = 0.0;
    p->printed = 0;
}

void mps_progress_update(struct mps_progress *p, double time, long step)
{
    if (p->quiet)
        return;
    double now = mps_wall_seconds();
    if (p->steps_at_last < 0) {
        /* First call: the baseline for steps/s and the ETA (a restart need
         * not start at 0). */
        p->steps_at_last = step;
        p->wall_last = p->wall_base = now;
        p->time_base = time;
        return;
    }
    int tty = is_tty();
    double since = now - p->wall_last;
    if (since < (tty ? TTY_PERIOD : LOG_PERIOD))
        return;
    double rate = (double)(step - p->steps_at_last) / since;
    double eta = mps_progress_eta(p, time, now);
    char etab[32], line[256];
    format_eta(etab, sizeof etab, eta);
    snprintf(line, sizeof line, "%s t=%.3f/%.3f s  step %ld  %.0f steps/s  %s", p->label, time,
             p->end_time, step, rate, etab);
    if (tty)
        fprintf(stderr, "\r%-78s", line); /* padding wipes a longer previous line */
    else
        fprintf(stderr, "%s\n", line);
    fflush(stderr);
    p->printed = 1;
    p->wall_last = now;
    p->steps_at_last = step;
}

double mps_progress_eta(const struct mps_progress *p, double time, double now)
{
    /* From the first update, not from t = 0: measured from t = 0, a restart
     * counted the simulated time before its checkpoint as done in its own
     * wall time (resumed at 9.9 s to 10 s, it read about a two-hundredth of
     * the true ETA halfway), and the set-up before the first step as
     * stepping. */
    const double done = time - p->time_base;
    if (p->steps_at_last < 0 || !(done > 0.0))
        return -1.0;
    return (p->end_time - time) * (now - p->wall_base) / done;
}

void mps_progress_finish(struct mps_progress *p, double time, long step)
{
    if (p->quiet || !p->printed)
        return;
    double wall = mps_wall_seconds() - p->wall_start;
    char line[256];
    snprintf(line, sizeof line, "%s t=%.3f/%.3f s  step %ld  done in %.1f s", p->label, time,
             p->end_time, step, wall);
    fprintf(stderr, is_tty() ? "\r%-78s\n" : "%s\n", line);
    fflush(stderr);
}
