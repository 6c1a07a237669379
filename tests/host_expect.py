"""The "host" a summary.json must name (common/mps_host.h), read here from
/proc/cpuinfo on its own: the first processor's model name, family and
model, and the CPUs online. Imported by the tests that read summaries."""
import os


def expected_host():
    info = {}
    try:
        with open('/proc/cpuinfo') as f:
            for line in f:
                if not line.strip():
                    break   # the first processor only
                key, _, value = line.partition(':')
                info.setdefault(key.strip(), value.strip())
    except OSError:
        pass
    n = os.sysconf('SC_NPROCESSORS_ONLN')
    if 'model name' not in info:
        return f'unknown CPU, {n} CPUs'
    if 'cpu family' in info and 'model' in info:
        return f"{info['model name']} (family {info['cpu family']} model {info['model']}), {n} CPUs"
    return f"{info['model name']}, {n} CPUs"
