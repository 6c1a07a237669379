/* Case keys every program shares (see mps_case.h). */
#include "mps_case.h"

const struct mps_key_spec mps_case_common_keys[] = {
    {"dp", MPS_KEY_DOUBLE, NULL, 0, 0, MPS_KEY_REQUIRED | MPS_KEY_LO_OPEN | MPS_KEY_NO_HI, NULL,
     "m", "initial particle spacing"},
    /* every program lands on its event times within 1e-9 end_time, which
     * must stay far below a step: at 1e4 s it is 1e-5 s (1% of the default
     * dt_max), and 1e4 s is 1e7 of the longest steps, beyond any run here.
     * Unbounded, end_time = 1e300 made that tolerance 1e291 s and the
     * coupler spun for ever moving its next probe time past it. */
    {"end_time", MPS_KEY_DOUBLE, NULL, 0, 1e4, MPS_KEY_REQUIRED | MPS_KEY_LO_OPEN, NULL, "s",
     "simulated time to run"},
    {"gravity.x", MPS_KEY_DOUBLE, "0", 0, 0, MPS_KEY_NO_LO | MPS_KEY_NO_HI, NULL, "m/s^2",
     "gravity, x component"},
    {"gravity.y", MPS_KEY_DOUBLE, "-9.81", 0, 0, MPS_KEY_NO_LO | MPS_KEY_NO_HI, NULL, "m/s^2",
     "gravity, y component"},
    {"output.interval", MPS_KEY_DOUBLE, "0.05", 0, 0, MPS_KEY_NO_HI, NULL, "s",
     "time between HDF5 snapshots (0: no snapshots)"},
    {"output.probe_interval", MPS_KEY_DOUBLE, "0.001", 0, 0, MPS_KEY_LO_OPEN | MPS_KEY_NO_HI,
     NULL, "s", "time between probes.csv rows"},
    /* simulated time, not wall time: a run then checkpoints at the same
     * steps whatever the machine's load (docs/restart.md: the default, its
     * cost and the wall time it bounds) */
    {"output.checkpoint_interval", MPS_KEY_DOUBLE, "0.1", 0, 0, MPS_KEY_NO_HI, NULL, "s",
     "time between checkpoints, from which a run restarts (0: none; docs/restart.md)"},
    {"description", MPS_KEY_STRING, "", 0, 0, 0, NULL, "", "free text"},
    /* read by the coupler only, declared here so every program accepts them */
    {"solid_solver", MPS_KEY_STRING, "solid_solver", 0, 0, 0, NULL, "",
     "command of the solid program (a bare name is looked up beside the coupler first)"},
    {"fluid_solver", MPS_KEY_STRING, "fluid_solver", 0, 0, 0, NULL, "",
     "command of the fluid program"},
    /* provenance (mps_prov.h): set by the program the user started, kept by
     * the solvers the coupler launches; a value in a case file is replaced */
    {"run.command", MPS_KEY_STRING, "", 0, 0, 0, NULL, "",
     "the command line that started the run (written by the program)"},
    {"run.hostname", MPS_KEY_STRING, "", 0, 0, 0, NULL, "",
     "name of the machine the run started on (written by the program)"},
    {"run.host", MPS_KEY_STRING, "", 0, 0, 0, NULL, "",
     "its CPU and CPU count (written by the program)"},
    {"run.started", MPS_KEY_STRING, "", 0, 0, 0, NULL, "",
     "when the run started, UTC, ISO 8601 (written by the program)"},
    {.name = NULL},
};
