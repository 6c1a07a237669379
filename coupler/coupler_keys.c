#include "coupler_keys.h"

#include "mps_motion.h"

/* The deadlines are at most 1e6 s (11 days: no deadline at all in practice)
 * because the solvers get them in milliseconds on CONFIG, where 1e300 s was
 * a 304-digit number that overflowed their counts. */
const struct mps_key_spec coupler_case_keys[] = {
    {"coupling.hello_timeout", MPS_KEY_DOUBLE, "60", 0, 1e6, MPS_KEY_LO_OPEN, NULL,
     "s", "deadline for a launched solver to connect"},
    {"coupling.ready_timeout", MPS_KEY_DOUBLE, "600", 0, 1e6, MPS_KEY_LO_OPEN,
     NULL, "s", "deadline for a solver to build its scene"},
    {"coupling.step_timeout", MPS_KEY_DOUBLE, "600", 0, 1e6, MPS_KEY_LO_OPEN,
     NULL, "s", "deadline for a solver to answer one ADVANCE"},
    {"coupling.transport", MPS_KEY_ENUM, "ipc", 0, 0, 0, "ipc|tcp", "",
     "ipc:// in a private run directory, or tcp:// (solvers on other hosts)"},
    {"coupling.tcp_port", MPS_KEY_INT, "5600", 1024, 65534, 0, NULL, "",
     "first port for tcp transport (fluid: port, solid: port + 1)"},
    {"coupling.tcp_host", MPS_KEY_STRING, "127.0.0.1", 0, 0, 0, NULL, "",
     "address the solvers connect to with tcp transport"},
    {"coupling.tcp_bind", MPS_KEY_STRING, "127.0.0.1", 0, 0, 0, NULL, "",
     "address the coupler listens on with tcp transport (an interface's address, or * for "
     "every interface); connections are authenticated with CURVE either way"},
    {"coupling.pin_cpus", MPS_KEY_ENUM, "auto", 0, 0, 0, "auto|off", "",
     "auto: the coupler and the solvers' main threads share one CPU (cheaper messages), "
     "OpenMP workers take the others; off: the OS places them"},
    /* implicit coupling: docs/coupling.md, "Implicit coupling" */
    {"coupling.scheme", MPS_KEY_ENUM, "explicit", 0, 0, 0, "explicit|implicit", "",
     "explicit: the paper's weak coupling, one fluid and one solid solve per step; implicit: "
     "each step repeated from its start until the interface converges"},
    {"coupling.implicit.acceleration", MPS_KEY_ENUM, "aitken", 0, 0, 0,
     "aitken|iqn_ils|constant", "",
     "how the next iterate of the interface is chosen (coupler/coupling_accel.h)"},
    {"coupling.implicit.predictor", MPS_KEY_ENUM, "solid", 0, 0, 0, "solid|extrapolate", "",
     "the first iterate of a step: solid, the extrapolated interface moved towards where the "
     "solid gets alone under the last step's loads, by a weight fitted to past steps; "
     "extrapolate, the interface's last step repeated"},
    {"coupling.implicit.relaxation", MPS_KEY_DOUBLE, "0.5", 0, 1, MPS_KEY_LO_OPEN, NULL, "",
     "initial relaxation factor of each step (aitken, iqn_ils without columns); the factor "
     "of constant"},
    {"coupling.implicit.tolerance", MPS_KEY_DOUBLE, "0.1", 0, 1, MPS_KEY_LO_OPEN, NULL, "",
     "converged when the rms change of the interface positions is at most this times their "
     "rms displacement over the step (the mean velocity the fluid saw is within this "
     "fraction of the solid's), plus abs_tolerance times the step"},
    {"coupling.implicit.abs_tolerance", MPS_KEY_DOUBLE, "1e-4", 0, 0, MPS_KEY_NO_HI, NULL, "m/s",
     "absolute part of the convergence test, as a velocity (an interface at rest has no "
     "displacement)"},
    {"coupling.implicit.max_iterations", MPS_KEY_INT, "20", 1, 1000, 0, NULL, "",
     "iterations (fluid and solid solves) per step at most"},
    {"coupling.implicit.on_max", MPS_KEY_ENUM, "accept", 0, 0, 0, "accept|error", "",
     "at max_iterations: accept the last iterate (warned and counted in summary.json) or stop "
     "with an error"},
    {"coupling.implicit.reuse", MPS_KEY_INT, "2", 0, 100, 0, NULL, "",
     "iqn_ils: past steps whose columns are kept"},
    {"coupling.implicit.filter", MPS_KEY_DOUBLE, "0.1", 0, 1, MPS_KEY_HI_OPEN, NULL, "",
     "iqn_ils: a column whose part orthogonal to the newer ones is shorter than this "
     "fraction of it is dropped"},
    {"coupling.implicit.log", MPS_KEY_BOOL, "false", 0, 0, 0, NULL, "",
     "write OUT/iterations.csv: every iteration's interface change, displacement and "
     "relaxation factor"},
    {NULL, 0, NULL, 0, 0, 0, NULL, NULL, NULL},
};

const struct mps_key_spec *const coupler_case_tables[COUPLER_NTABLES] = {
    mps_case_common_keys, coupler_case_keys, mps_motion_keys};

const char *const coupler_solver_sections[] = {"fluid.", "solid.", NULL};
