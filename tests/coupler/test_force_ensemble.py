#!/usr/bin/python3
"""bench/plate_force_ensemble.py's split of the force deviation on
realisations whose two parts are known.

Each synthetic run is the same force history (a 25 ms impact ramp to 140 N/m,
a decay, a 20 ms swing of -60 N/m: the shapes of the 6 mm plate's mean force,
docs/pressure.md) plus its own white noise of 4 N/m per 2 ms row, over 8 s. The split
over the means of 2-64 runs must give:
- shared: the deviation of the noise-free history from its own 20 ms mean,
  within 10% (over twelve noise seeds the fit's relative error has a
  standard deviation of 3%: 3.5 of them);
- independent: the noise's deviation from its 10-row centred mean,
  4 sqrt(1 - 1/10) N/m, within 4% (standard deviation over the seeds 0.9%:
  a 10% error in either of the fit's squared terms moves it by 5%).
failing_intervals must place the noise-free history's rows outside 15% in
the swing and nowhere else (the ramp is linear, its own centred mean). Exit 0 if all hold."""
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, '..', '..', 'bench'))
sys.path.insert(0, HERE)
from plate_force_ensemble import failing_intervals, split_deviation  # noqa: E402
from check_plate_flicker import force_series_smoothness  # noqa: E402


def history(t):
    ramp = np.clip((t - 0.13) / 0.025, 0.0, 1.0)
    decay = np.where(t > 0.155, np.exp(-(t - 0.155) / 0.3), 1.0)
    swing = -60.0 * np.exp(-0.5 * ((t - 0.6) / 0.01) ** 2)
    return 140.0 * ramp * decay + swing


def main():
    t = np.arange(0.0, 8.0, 0.002)
    clean = history(t)
    rng = np.random.default_rng(11)
    sigma = 4.0
    runs = clean + sigma * rng.standard_normal((64, t.size))
    sizes = [2, 4, 8, 16, 32, 64]
    devs = [force_series_smoothness(t, runs[:n].mean(axis=0))['rms_dev'] for n in sizes]
    shared, independent = split_deviation(sizes, devs)
    want_shared = force_series_smoothness(t, clean)['rms_dev']
    want_indep = sigma * np.sqrt(1.0 - 1.0 / 10.0)
    fails = []
    print('shared %.3f N/m (the noise-free history: %.3f), independent %.3f N/m (want %.3f)'
          % (shared, want_shared, independent, want_indep))
    if abs(shared - want_shared) > 0.1 * want_shared:
        fails.append('shared part off by more than 10%')
    if abs(independent - want_indep) > 0.04 * want_indep:
        fails.append('independent part off by more than 4%')
    iv = failing_intervals(t, clean)
    print('the noise-free history\'s rows outside 15%%: %s' % iv)
    # a linear ramp is its own centred mean; only the swing's curvature fails
    if not iv or any(x0 < 0.57 or x1 > 0.63 for x0, x1 in iv):
        fails.append('the failing rows are not all in the swing (0.57-0.63 s)')
    for f in fails:
        print('FAIL: ' + f)
    return 1 if fails else 0


if __name__ == '__main__':
    sys.exit(main())
