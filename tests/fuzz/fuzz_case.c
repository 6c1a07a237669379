/* libFuzzer target: the case-file reader (YAML, declared keys, --set) and
 * the checks across keys that the coupler runs before it launches anything
 * (fluid_params_read, solid_scene_read: blocks in the tank, bodies, the
 * memory estimate; mps_motion_read: the tank's motion and its table). Input layout: the YAML file, then optionally a NUL byte
 * and --set items, one a line. The file is an in-memory file (memfd), read
 * through its /proc path as the programs read theirs. On success the
 * resolved YAML is written and must load again. */
#define _GNU_SOURCE /* memfd_create */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "coupler_keys.h"
#include "fluid_params.h"
#include "mps_case.h"
#include "mps_motion.h"
#include "solid_scene.h"

#define MAX_SETS 16

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int write_file(int fd, const void *p, size_t n)
{
    if (ftruncate(fd, 0) != 0 || lseek(fd, 0, SEEK_SET) != 0)
        return -1;
    return write(fd, p, n) == (ssize_t)n ? 0 : -1;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static int fd = -1;
    static char path[64];
    if (fd < 0) {
        fd = memfd_create("case", 0);
        if (fd < 0)
            abort();
        snprintf(path, sizeof path, "/proc/self/fd/%d", fd);
    }
    const uint8_t *nul = memchr(data, 0, size);
    size_t ylen = nul ? (size_t)(nul - data) : size;
    if (write_file(fd, data, ylen) != 0)
        abort();
    /* --set items: copies, one a line */
    char *setbuf = NULL;
    const char *sets[MAX_SETS];
    int nsets = 0;
    if (nul) {
        size_t sl = size - ylen - 1;
        setbuf = malloc(sl + 1);
        memcpy(setbuf, nul + 1, sl);
        setbuf[sl] = '\0';
        for (char *p = setbuf; *p && nsets < MAX_SETS;) {
            char *nl = strchr(p, '\n');
            if (nl)
                *nl = '\0';
            if (strchr(p, '='))
                sets[nsets++] = p;
            if (!nl)
                break;
            p = nl + 1;
        }
    }
    const struct mps_key_spec *const tables[] = {mps_case_common_keys, fluid_case_keys,
                                                 solid_case_keys, coupler_case_keys,
                                                 mps_motion_keys};
    struct mps_case *c = NULL;
    struct mps_err err;
    if (mps_case_load(&c, path, sets, nsets, tables, 5, NULL, &err) == MPS_OK) {
        struct fluid_params fp;
        struct solid_scene *sc = malloc(sizeof *sc);
        if (mps_case_has(c, "fluid.tank.width"))
            fluid_params_read(&fp, c, &err);
        if (mps_case_count(c, "solid.bodies") > 0)
            solid_scene_read(sc, c, &err);
        free(sc);
        struct mps_motion *m = NULL;
        if (mps_motion_read(&m, c, &err) == MPS_OK) {
            struct mps_motion_frame f = mps_motion_at(m, 0.5 * mps_case_double(c, "end_time"));
            (void)f;
        }
        mps_motion_destroy(&m);
        char *y = mps_case_resolved_yaml(c);
        if (!y)
            abort();
        /* what the coupler hands to the solvers must read back */
        struct mps_case *again = NULL;
        if (write_file(fd, y, strlen(y)) != 0)
            abort();
        if (mps_case_load(&again, path, NULL, 0, tables, 5, NULL, &err) != MPS_OK) {
            fprintf(stderr, "resolved case does not load again: %s\n%s\n", err.msg, y);
            abort();
        }
        mps_case_destroy(&again);
        free(y);
        mps_case_destroy(&c);
    }
    free(setbuf);
    return 0;
}
