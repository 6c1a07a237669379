#include "coupler_keys.h"

const struct mps_key_spec coupler_case_keys[] = {
    {"coupling.hello_timeout", MPS_KEY_DOUBLE, "60", 0, 0, MPS_KEY_LO_OPEN | MPS_KEY_NO_HI, NULL,
     "s", "deadline for a launched solver to connect"},
    {"coupling.ready_timeout", MPS_KEY_DOUBLE, "600", 0, 0, MPS_KEY_LO_OPEN | MPS_KEY_NO_HI,
     NULL, "s", "deadline for a solver to build its scene"},
    {"coupling.step_timeout", MPS_KEY_DOUBLE, "600", 0, 0, MPS_KEY_LO_OPEN | MPS_KEY_NO_HI,
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
    {NULL, 0, NULL, 0, 0, 0, NULL, NULL, NULL},
};
