#include "mps_host.h"

#include <stdio.h>
#include <string.h>
#include <unistd.h>

/* The value of "key<spaces>: value" with its newline removed, or NULL. */
static const char *cpuinfo_value(char *line, const char *key)
{
    size_t n = strlen(key);
    if (strncmp(line, key, n) != 0 || (line[n] != ' ' && line[n] != '\t' && line[n] != ':'))
        return NULL;
    char *colon = strchr(line + n, ':');
    if (!colon)
        return NULL;
    char *v = colon + 1 + (colon[1] == ' ');
    v[strcspn(v, "\n")] = '\0';
    return v;
}

void mps_host_describe(char *buf, size_t size)
{
    char model[160] = "", family[16] = "", cpu_model[16] = "", line[512];
    FILE *f = fopen("/proc/cpuinfo", "r");
    if (f) {
        const char *v;
        /* the first processor's block only: a blank line ends it */
        while (fgets(line, sizeof line, f) && line[0] != '\n') {
            if ((v = cpuinfo_value(line, "model name")))
                snprintf(model, sizeof model, "%s", v);
            else if ((v = cpuinfo_value(line, "cpu family")))
                snprintf(family, sizeof family, "%s", v);
            else if ((v = cpuinfo_value(line, "model")))
                snprintf(cpu_model, sizeof cpu_model, "%s", v);
        }
        fclose(f);
    }
    /* online CPUs, not this process's mask: the coupler pins itself to one */
    long ncpu = sysconf(_SC_NPROCESSORS_ONLN);
    if (!model[0])
        snprintf(buf, size, "unknown CPU, %ld CPUs", ncpu);
    else if (family[0] && cpu_model[0]) /* a model name can cover generations */
        snprintf(buf, size, "%s (family %s model %s), %ld CPUs", model, family, cpu_model, ncpu);
    else
        snprintf(buf, size, "%s, %ld CPUs", model, ncpu);
}
