#define _GNU_SOURCE /* sched_setaffinity, CPU_SET */
#include "launch.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <sched.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "proto_key.h"

#define MAX_WORDS 64

/* Splits on blanks; single or double quotes group words (no escapes). */
static int split_words(char *s, char **words, int max)
{
    int n = 0;
    while (*s) {
        while (*s == ' ' || *s == '\t')
            s++;
        if (!*s)
            break;
        if (n == max - 1)
            return -1;
        char q = (*s == '"' || *s == '\'') ? *s++ : 0;
        words[n++] = s;
        while (*s && (q ? *s != q : (*s != ' ' && *s != '\t')))
            s++;
        if (q && !*s)
            return -2;
        if (*s)
            *s++ = '\0';
    }
    words[n] = NULL;
    return n;
}

/* A bare name is looked up beside the coupler first, so a build tree works
 * without PATH changes. */
static void resolve(const char *word, char *out, size_t len)
{
    snprintf(out, len, "%s", word);
    if (strchr(word, '/'))
        return;
    char self[PATH_MAX];
    ssize_t k = readlink("/proc/self/exe", self, sizeof self - 1);
    if (k <= 0)
        return;
    self[k] = '\0';
    char *slash = strrchr(self, '/');
    if (!slash)
        return;
    *slash = '\0';
    char cand[PATH_MAX + 256];
    snprintf(cand, sizeof cand, "%s/%s", self, word);
    if (access(cand, X_OK) == 0 && strlen(cand) < len)
        memcpy(out, cand, strlen(cand) + 1);
}

/* Set by launch_share_cpu: the mask the solvers get back, and their places. */
static struct {
    int on;
    cpu_set_t allowed;
    char places[8192];
} shared;

/* Claims CPU `cpu` for this coupler's life: an exclusive flock on a file
 * named after it, which the kernel drops when the coupler exits however it
 * ends. Every coupler on the machine uses the same names, whoever runs it
 * (the file is made readable by all; a lock needs only a read descriptor).
 * Returns 1 if claimed. The descriptor is kept open on purpose. */
static int claim_cpu(int cpu)
{
    char path[64];
    snprintf(path, sizeof path, "/tmp/mpsfsi-cpu%d.lock", cpu);
    /* O_NOFOLLOW: a symlink planted in /tmp under this name is refused,
     * not followed to another file */
    int fd = open(path, O_RDONLY | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (fd < 0)
        return 0;
    /* a umask of 077 would leave the file unreadable to other users, whose
     * couplers would then take the CPU as held for as long as it exists */
    struct stat st;
    if (fstat(fd, &st) == 0 && st.st_uid == geteuid() && (st.st_mode & 0444) != 0444)
        (void)fchmod(fd, 0644);
    if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
        close(fd);
        return 0;
    }
    return 1;
}

int launch_share_cpu(int want, char *note, size_t len)
{
    if (!want) {
        snprintf(note, len, "off (coupling.pin_cpus)");
        return 0;
    }
    if (getenv("OMP_PLACES") || getenv("OMP_PROC_BIND")) {
        snprintf(note, len, "off: OMP_PLACES or OMP_PROC_BIND set by the user");
        return 0;
    }
    cpu_set_t a;
    CPU_ZERO(&a);
    if (sched_getaffinity(0, sizeof a, &a) != 0) {
        snprintf(note, len, "off: sched_getaffinity: %s", strerror(errno));
        return 0;
    }
    if (CPU_COUNT(&a) < 2) {
        snprintf(note, len, "off: one CPU");
        return 0;
    }
    /* Two couplers that both took their first allowed CPU would stack
     * their main threads on it, each at half speed, with the other CPUs
     * idle: measured, two 1-thread sloshing runs started together shared
     * CPU 0 at 44% each. So each takes the first CPU no other coupler has
     * claimed, and with none left is placed by the OS. */
    int mine = -1;
    for (int cpu = 0; cpu < CPU_SETSIZE && mine < 0; cpu++)
        if (CPU_ISSET(cpu, &a) && claim_cpu(cpu))
            mine = cpu;
    if (mine < 0) {
        snprintf(note, len, "off: every allowed CPU is claimed by other couplers");
        return 0;
    }
    int w = snprintf(shared.places, sizeof shared.places, "{%d}", mine);
    size_t used = (size_t)w;
    for (int cpu = 0; cpu < CPU_SETSIZE; cpu++) {
        if (!CPU_ISSET(cpu, &a) || cpu == mine)
            continue;
        w = snprintf(shared.places + used, sizeof shared.places - used, ",{%d}", cpu);
        if (w < 0 || (size_t)w >= sizeof shared.places - used) {
            snprintf(note, len, "off: too many CPUs to list in OMP_PLACES");
            return 0;
        }
        used += (size_t)w;
    }
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(mine, &one);
    if (sched_setaffinity(0, sizeof one, &one) != 0) {
        snprintf(note, len, "off: sched_setaffinity: %s", strerror(errno));
        return 0;
    }
    shared.on = 1;
    shared.allowed = a;
    snprintf(note, len, "CPU %d shared by the coupler and the solvers' main threads", mine);
    return 1;
}

enum mps_status launch_start(struct child *c, const char *name, const char *command,
                             const char *endpoint, const char *key_file, struct mps_err *err)
{
    memset(c, 0, sizeof *c);
    c->name = name;
    snprintf(c->command, sizeof c->command, "%s", command);
    char buf[4096];
    snprintf(buf, sizeof buf, "%s", command);
    char *words[MAX_WORDS + 3];
    int n = split_words(buf, words, MAX_WORDS);
    if (n <= 0)
        return mps_err_set(err, MPS_EINPUT, "%s solver command '%s': %s", name, command,
                           n == 0 ? "empty" : n == -1 ? "too many words" : "unbalanced quote");
    char prog[PATH_MAX];
    resolve(words[0], prog, sizeof prog);
    words[0] = prog;
    words[n++] = "--connect";
    words[n++] = (char *)endpoint;
    words[n] = NULL;

    pid_t parent = getpid();
    pid_t pid = fork();
    if (pid < 0)
        return mps_err_set(err, MPS_EIO, "cannot fork the %s solver: %s", name, strerror(errno));
    if (pid == 0) {
        /* child: die with the coupler; keep our own process group out of the
         * terminal's Ctrl-C so the coupler decides how solvers stop */
        prctl(PR_SET_PDEATHSIG, SIGTERM);
        if (getppid() != parent)
            _exit(126);
        setpgid(0, 0);
        /* The solvers take turns on the same cores: OpenMP threads that spin
         * on while the other solver runs cost it up to 20x
         * (docs/ppe_solvers.md). Passive threads, which sleep at once, cost
         * a wake-up per parallel region instead, and a fluid step has ~80 of
         * them: the 3 mm plate to 0.3 s took 20.6 s, against 11.8 s with a
         * short spin (about 20k polls, tens of microseconds) before sleeping,
         * which bridges the regions of one step but not the other solver's
         * turn. GNU and LLVM runtimes; a user's own setting wins. */
        if (!getenv("OMP_WAIT_POLICY")) {
            setenv("GOMP_SPINCOUNT", "20000", 0);
            setenv("KMP_BLOCKTIME", "1", 0);
        }
        if (shared.on) {
            /* back to every CPU; OpenMP puts the main thread on the shared
             * one (the first place) and the workers on the others */
            sched_setaffinity(0, sizeof shared.allowed, &shared.allowed);
            setenv("OMP_PLACES", shared.places, 0);
            setenv("OMP_PROC_BIND", "close", 0);
        }
        /* the run's key (PROTOCOL.md section 10); an inherited one is not
         * this run's */
        if (key_file)
            setenv(PROTO_KEY_ENV, key_file, 1);
        else
            unsetenv(PROTO_KEY_ENV);
        execvp(words[0], words);
        fprintf(stderr, "coupler: cannot start the %s solver '%s': %s\n", name, words[0],
                strerror(errno));
        _exit(127);
    }
    c->pid = pid;
    return MPS_OK;
}

int launch_poll(struct child *c)
{
    if (c->exited)
        return 1;
    if (c->pid <= 0)
        return 0;
    int status;
    pid_t r = waitpid(c->pid, &status, WNOHANG);
    if (r == c->pid) {
        c->exited = 1;
        c->status = status;
        return 1;
    }
    return 0;
}

void launch_describe(const struct child *c, char *buf, size_t len)
{
    if (!c->exited)
        snprintf(buf, len, "is still running");
    else if (WIFEXITED(c->status) && WEXITSTATUS(c->status) == 127)
        snprintf(buf, len, "could not be started ('%s')", c->command);
    else if (WIFEXITED(c->status))
        snprintf(buf, len, "exited with status %d", WEXITSTATUS(c->status));
    else if (WIFSIGNALED(c->status))
        snprintf(buf, len, "was killed by signal %d (%s)", WTERMSIG(c->status),
                 strsignal(WTERMSIG(c->status)));
    else
        snprintf(buf, len, "ended (status 0x%x)", c->status);
}

static void sleep_ms(int ms)
{
    struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

#define REAP_TICK_MS 50
#define REAP_KILL_TICKS 40 /* SIGTERM to SIGKILL: 2 s */

void launch_reap_all(struct child *const *kids, const double *grace_s, int n)
{
    long termed[8] = {0}; /* tick + 1 at which child k got SIGTERM */
    if (n > 8)
        n = 8;
    for (long tick = 0;; tick++) {
        int running = 0;
        for (int k = 0; k < n; k++) {
            struct child *c = kids[k];
            if (c->pid <= 0 || launch_poll(c))
                continue;
            if (!termed[k] && tick >= (long)(grace_s[k] * (1000 / REAP_TICK_MS))) {
                kill(c->pid, SIGTERM);
                termed[k] = tick + 1;
            } else if (termed[k] && tick + 1 - termed[k] >= REAP_KILL_TICKS) {
                kill(c->pid, SIGKILL);
                int status;
                if (waitpid(c->pid, &status, 0) == c->pid) {
                    c->exited = 1;
                    c->status = status;
                }
                continue;
            }
            running++;
        }
        if (!running)
            return;
        sleep_ms(REAP_TICK_MS);
    }
}
