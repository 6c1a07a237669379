#!/usr/bin/python3
"""What CURVE costs (issue 20): the bare round trip over tcp with and without
CURVE (bench/zmq_roundtrip.c, both processes on CPU 0 as the coupler places
them), and the messaging per coupling step of the coupled 6 mm plate over ipc
(no security: the 0700 run directory) and over tcp (CURVE, always on).
Runs alternate (A B A B ...) so a drift of the machine hits both alike.

usage: bench/curve_cost.py [--pairs N] [--build build] [--end 0.6]
Prints a markdown table; the numbers in docs/coupling.md come from it."""
import argparse
import json
import os
import re
import statistics
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def roundtrip(curve, port):
    exe = os.path.join(tempfile.gettempdir(), 'zmq_roundtrip')
    if not os.path.exists(exe):
        subprocess.run(['cc', '-O2', os.path.join(ROOT, 'bench', 'zmq_roundtrip.c'), '-o', exe,
                        '-lzmq'], check=True)
    out = subprocess.run(['taskset', '-c', '0', exe, '5000', '2000', f'tcp://127.0.0.1:{port}',
                          '6'] + (['curve'] if curve else []), capture_output=True, text=True,
                         check=True).stdout
    return float(re.search(r'([0-9.]+) us each', out).group(1))


def coupled(build, transport, end, port):
    out = tempfile.mkdtemp(prefix=f'curve_{transport}_')
    subprocess.run([os.path.join(build, 'bin', 'coupler'),
                    os.path.join(ROOT, 'cases', 'dambreak_elastic_plate', 'case.yml'),
                    '--out', out, '--quiet', '--set', 'dp=0.006', '--set', f'end_time={end}',
                    '--set', 'output.interval=0', '--set', f'coupling.transport={transport}',
                    '--set', f'coupling.tcp_port={port}'], check=True)
    s = json.load(open(os.path.join(out, 'summary.json')))
    steps = s['coupling_steps']
    return (1e6 * s['time_split_seconds']['messaging'] / steps, s['wall_seconds'], steps,
            open(os.path.join(out, 'probes.csv')).read())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--pairs', type=int, default=5)
    ap.add_argument('--build', default=os.path.join(ROOT, 'build'))
    ap.add_argument('--end', type=float, default=0.6)
    ap.add_argument('--port', type=int, default=5790)
    a = ap.parse_args()
    rt = {False: [], True: []}
    for _ in range(a.pairs):
        for curve in (False, True):
            rt[curve].append(roundtrip(curve, a.port))
    cp = {'ipc': [], 'tcp': []}
    probes = set()
    for _ in range(a.pairs):
        for t in ('ipc', 'tcp'):
            msg, wall, steps, csv = coupled(a.build, t, a.end, a.port)
            cp[t].append((msg, wall))
            probes.add(csv)
    print(f'load average: {os.getloadavg()}')
    print('| what | without CURVE | with CURVE | difference |')
    print('|---|---|---|---|')
    m0, m1 = statistics.median(rt[False]), statistics.median(rt[True])
    print(f'| round trip, 2 kB in 6 frames, tcp, CPU 0 (us; median of {a.pairs}, '
          f'range) | {m0:.1f} ({min(rt[False]):.1f}-{max(rt[False]):.1f}) | '
          f'{m1:.1f} ({min(rt[True]):.1f}-{max(rt[True]):.1f}) | {m1 - m0:+.1f} |')
    i0 = statistics.median(x[0] for x in cp['ipc'])
    i1 = statistics.median(x[0] for x in cp['tcp'])
    w0 = statistics.median(x[1] for x in cp['ipc'])
    w1 = statistics.median(x[1] for x in cp['tcp'])
    print(f'| 6 mm plate to {a.end} s ({steps} coupling steps): messaging per coupling step '
          f'(us; ipc / tcp+CURVE) | {i0:.0f} ({min(x[0] for x in cp["ipc"]):.0f}-'
          f'{max(x[0] for x in cp["ipc"]):.0f}) | {i1:.0f} ({min(x[0] for x in cp["tcp"]):.0f}-'
          f'{max(x[0] for x in cp["tcp"]):.0f}) | {i1 - i0:+.0f} |')
    print(f'| same, wall time (s) | {w0:.2f} | {w1:.2f} | {w1 - w0:+.2f} |')
    print(f'probes.csv identical across all {2 * a.pairs} runs: {len(probes) == 1}')


if __name__ == '__main__':
    main()
