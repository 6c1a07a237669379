#!/usr/bin/python3
"""Every command in README.md and docs/*.md runs as written from the
repository root, after the first README command (./setup.sh: dependencies
installed, build/ built).

What counts as a command (docs/output.md and the README follow it):
  - every fenced block marked ```sh: one script per block, run by `sh -e` as
    written (continuation lines, loops, comments);
  - every inline code span that starts a program: after VAR=value words, a
    path into build/, bench/, tests/, ./ or /tmp/, or /usr/bin/python3,
    cmake, ctest, cc or taskset; with at least one argument and no
    placeholder (an upper-case word such as CASE, DIR, OUT, or '[').
Other fences (```text, ```c, plain ```) are synopses and examples, not run.

The commands run in order, one file after another, in a copy of the
repository whose build/ is the real build directory, so a command may use
what an earlier one wrote (bench/plate_compare.py out/plate after the run
that made it) and nothing lands in the source tree.

Never run, in any mode (reason printed): the `./setup.sh && ` prefix of the
README's commands is the first README command itself (done: dropped);
configuring or building (cmake -S/-B, cmake --build: the build is the first
README command's, and a second configure of it from the copy is refused by
CMake); ./setup.sh --debug (the sanitizer build, which .ci/run builds with the
same command); ctest (the suite itself).

MPS_DOC_TEST_SHORT=1 (ctest sets it): the long ones are shortened by the
table SHORT (end_time/dp overrides, or skipped with a reason). Every entry
must match some command, so the table cannot outlive the docs. Without it
every command runs as written: the docs' benches take hours.

usage: doc_commands.py BUILD_DIR [--list] [FILE.md...]   (from the repository root;
       FILE.md: only these files' commands, e.g. docs/fracture.md)
"""
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..'))
PROGRAM = re.compile(r'^(build/|bench/|tests/|\./|/tmp/|/usr/bin/python3\b|cmake\b|ctest\b|cc\b|'
                     r'taskset\b)')
PLACEHOLDER = re.compile(r'\[|\.\.\.|(?<![\w$])[A-Z][A-Z0-9_]+\b(?!=)')
NEVER = [
    (re.compile(r'^\./setup\.sh && ', re.M), '',
     './setup.sh is the first README command, done before this test'),
    (re.compile(r'^cmake -S .*$', re.M), 'true',
     'configures and builds build/: the first README command did'),
    (re.compile(r'^(ctest|cd build && ctest)\b.*$', re.M), 'true', 'runs the test suite itself'),
    # 1.5 min each from scratch in the copy, and the same command as .ci/run's
    (re.compile(r'^(MPS_WERROR=ON )?\./setup\.sh --debug$', re.M), 'true',
     'builds the sanitizer build (build-debug/): .ci/run runs MPS_WERROR=ON ./setup.sh --debug '
     'itself'),
    (re.compile(r'^.*\bbuild-debug/bin\b.*$', re.M), 'true',
     'runs the sanitizer build, which this test does not build (.ci/run builds it)'),
]

# (file, pattern, Python module, reason): run only where the module imports
REQUIRES = [
    ('docs/fluid_speed.md', r'^bench/pysph_dambreak\.py .*$', 'pysph',
     "PySPH's dam break: needs Debian's python3-pysph, not a dependency of this project"),
]

# (file, pattern, replacement, reason): MPS_DOC_TEST_SHORT only. Runs keep
# their case and lose time or resolution (a later --set wins); the checks that
# follow them are given the shorter end where they ask for one.
SET_PLATE = r'\g<0> --set dp=0.006 --set end_time=0.6'
SHORT = [
    ('docs/dambreak_plate.md', r'^build/bin/coupler .* --out runs/g(6|3|15) .*--quiet$', SET_PLATE,
     'the 6, 3 and 1.5 mm plates (5 s, 27 s and 4 min on a quiet machine; README.md runs the '
     'first in full) at 6 mm to 0.6 s'),
    ('docs/elastic_gate.md', r'build/bin/coupler cases/elastic_gate/case\.yml --out runs/\S+',
     r'\g<0> --set dp=0.0016 --set end_time=0.05',
     'the gates (72-100 s each) at 1.6 mm (3 particles thick: the quadratic TLSPH needs 3) '
     'to 0.05 s'),
    ('docs/fluid.md', r'^(MPS_SIMD=sse2 bench/dambreak_speed_error\.py --dps )0\.004,0\.002$',
     r'\g<1>0.008', 'the speed-error bench at 8 mm only'),
    ('docs/fluid.md', r'^build/bin/fluid_solver cases/hydrostatic/case\.yml .*$',
     r'\g<0> --set end_time=0.2', 'still water to 0.2 s, not 2'),
    ('docs/fluid.md', r'for dp in 0\.008 0\.004 0\.002', 'for dp in 0.008 0.004',
     'the dam break at 8 and 4 mm (2 mm: 8-15 s)'),
    ('docs/fluid.md', r'^(build/bin/fluid_solver .* --out out/db2s --quiet)(.*)$',
     r'\g<1> --set end_time=0.3\g<2>', 'the 2 s dam break to 0.3 s'),
    ('docs/fluid.md', r'(check_stable\.py out/db2s --t-end )2$', r'\g<1>0.3', 'to 0.3 s'),
    ('docs/fluid.md', r'^bench/fluid_variants\.sh build$', 'true',
     'twelve runs of every fluid variant, several minutes'),
    ('docs/fluid_speed.md', r'(OMP_NUM_THREADS=2 build/bin/fluid_solver .*--set end_time=)1\.0',
     r'\g<1>0.02', 'the 3 mm dam break to 0.02 s, not 1 (12 s each)'),
    ('docs/restart.md', r'^(build/bin/(?:fluid_solver|coupler) cases/\S+ --out runs/ck_\w+ --quiet '
     r'(?:--set \S+ )*--set end_time=)0\.5$', r'\g<1>0.15',
     'the checkpoint cost runs (20 s each under load) to 0.15 s: one checkpoint each'),
    ('docs/fracture.md', r'^(build/bin/solid_solver cases/fracture_collision/case\.yml '
     r'--out out/fc(_nc)?)( .*)?$', r'\g<1> --set dp=0.05 --set end_time=0.2\g<3>',
     'the collision at dp 0.05 to 0.2 s (dp 0.0125 to 2 s: about a minute each)'),
    ('docs/fracture.md', r'(bench/fracture_pictures\.py --bin build/bin/solid_solver )--dp 0\.0125',
     r'\g<1>--dp 0.05', 'the pictures at dp 0.05 (two runs of a minute at 0.0125)'),
    ('docs/fracture.md', r'(bench/fracture_pictures\.py )--dp 0\.0125( --out out/fracture '
     r'--table-only)', r'\g<1>--dp 0.05\g<2>', 'the table of those runs'),
    ('docs/fracture.md', r'--dp 0\.0125 --end 0\.5 --threads 1 --repeat 3',
     '--dp 0.05 --end 0.05 --threads 1 --repeat 1', 'the timing at dp 0.05 to 0.05 s, once'),
    ('docs/fracture.md', r'^bench/fracture_pictures\.py --timing$',
     r'\g<0> --dp 0.05 --end 0.05 --repeat 1', 'the timing at dp 0.05 to 0.05 s, once'),
    ('docs/sloshing.md', r'^build/bin/coupler cases/sloshing_high/case\.yml .*$',
     r'\g<0> --set dp=0.002 --set fluid.dt_max=1e-3 --set end_time=0.02',
     'the 1 mm sloshing runs (hours) at 2 mm to 0.02 s'),
    ('docs/sloshing.md', r'^for dtm in 1e-3 2e-4 1\.5e-4 1e-4 7e-5 5e-5', 'for dtm in 5e-5',
     'the coupling-step scan at one step only'),
    ('docs/sloshing.md', r'--set end_time=0\.05 (--set output\.interval=0 --set motion\.kind=none)',
     r'--set end_time=0.0005 \1', 'the coupling-step scan (4-7 min a run) to 0.0005 s'),
    ('docs/sloshing.md', r'^(bench/sloshing_runs\.py --runs) .* (--table docs/sloshing_table\.md .*)$',
     r'\1 high_2_mps low_2_mps high_2_mps_table --set end_time=0.02 \2',
     'the 2 mm sloshing runs (10-25 min each) to 0.02 s, three of them'),
    ('docs/sloshing.md', r'(bench/sloshing_runs\.py --runs high_1_mps --set end_time=)0\.01',
     r'\g<1>0.001', 'the 1 mm timing run (200 steps, minutes) to 0.001 s'),
    ('docs/sloshing.md', r'(bench/sloshing_pictures\.py runs/sloshing/\w+ --times)( [0-9.]+)+',
     r'\1 0.01 0.02', 'the pictures at 0.01 and 0.02 s (the short runs)'),
    ('docs/sloshing.md', r'(bench/sloshing_plate_alone\.py) --dp 0\.002 0\.001 --models mps tlsph',
     r'\1 --dp 0.002 --models mps', 'the plates alone at 2 mm, MPS only (1 mm: minutes)'),
    ('docs/solid_cantilever.md', r'^bench/solid_cantilever\.py --bin build/bin/solid_solver.*$',
     'true', 'the cantilever table: 10 runs of up to 40 particles across, minutes'),
    ('docs/solid_cantilever.md', r'^bench/solid_elastica_ref\.py', r'\g<0> 10 20',
     'the elastica reference at N = 10, 20 (40, 80, 160: minutes)'),
    ('docs/pressure.md', r'^/usr/bin/python3 bench/pressure_quality\.py .*$',
     '/usr/bin/python3 bench/pressure_quality.py --only impact --dps 0.008 --out /tmp/pq_short',
     'the impact section at 8 mm only (the whole page: 40 minutes and a second build)'),
    ('docs/pressure.md', r'^bench/flicker_ensemble\.py --runs 8 --plate$',
     'bench/flicker_ensemble.py --runs 2 --plate --set end_time=0.3',
     'two plate realisations to 0.3 s, not eight to 2 s (a minute)'),
    ('docs/coupling.md', r'(bench/curve_cost\.py --pairs )5\b', r'\g<1>1',
     'one pair of the CURVE timing, not five'),
    ('docs/pressure.md', r'^bench/pressure_quality\.py --only still$', 'true',
     'the still-water variants: eleven 10 s runs, about 10 minutes'),
    ('docs/security.md', r'^(build/fuzz/fuzz_\w+) -runs=\d+ ', r'test ! -x \g<1> || \g<1> -runs=5000 ',
     'each fuzzer for 5000 inputs (millions: 15 minutes); skipped where the build has no '
     'fuzzers (MPS_FUZZ=1 and clang)'),
    ('docs/hard_cases.md', r'^/usr/bin/python3 bench/hard_cases\.py$', r'\g<0> --quick --report-only',
     'the report from the runs there are (none in the copy: rows "not run"); the runs take '
     'hours'),
    ('docs/hard_cases.md', r'^for i in 1 2 3 4 5 6; do for s in implicit explicit', 'for i in 1; do for s in implicit explicit',
     'one pair of the paired timing, not six'),
    ('docs/hard_cases.md', r'^OMP_NUM_THREADS=1 build/bin/coupler .*std_explicit_1thread_60 .*$',
     r'\g<0> --set end_time=0.3', 'the one-thread plate to 0.3 s, not 2'),
    ('docs/solid_models.md', r'^\s*bench/solid_cantilever\.py --bin build/bin/solid_solver.*\\\n.*$',
     'true', 'the cantilever table of each model: minutes'),
    ('docs/testing.md', r'^nice -n 10 /usr/bin/python3 tests/mutation/run\.py .*$',
     '/usr/bin/python3 tests/mutation/run.py --check',
     'the mutation check (hours: a build and tests per fault): only that every fault applies'),
]


def fences(text):
    """(line, script) of every ```sh block."""
    out, lines, i = [], text.split('\n'), 0
    while i < len(lines):
        m = re.match(r'^```(\S*)\s*$', lines[i])
        if m:
            j = i + 1
            while j < len(lines) and not lines[j].startswith('```'):
                j += 1
            if m.group(1) == 'sh':
                out.append((i + 1, '\n'.join(lines[i + 1:j]) + '\n'))
            i = j + 1
            continue
        i += 1
    return out


def inline(text):
    """(line, command) of the inline spans that are commands (outside fences)."""
    out, in_fence = [], False
    for n, line in enumerate(text.split('\n'), 1):
        if line.startswith('```'):
            in_fence = not in_fence
            continue
        if in_fence:
            continue
        for span in re.findall(r'`([^`]+)`', line):
            words = span.split()
            k = 0
            while k < len(words) and re.match(r'^[A-Z_][A-Z0-9_]*=\S*$', words[k]):
                k += 1
            rest = ' '.join(words[k:])
            if len(words) - k < 2 or not PROGRAM.match(rest):
                continue
            if PLACEHOLDER.search(' '.join(words[k + 1:])):
                continue
            out.append((n, span.replace('\\|', '|') + '\n'))
    return out


def commands():
    files = ['README.md'] + sorted(os.path.join('docs', f) for f in os.listdir(os.path.join(ROOT, 'docs'))
                                   if f.endswith('.md'))
    out = []
    for f in files:
        with open(os.path.join(ROOT, f)) as fh:
            text = fh.read()
        found = fences(text) + inline(text)
        out += [(f, n, s) for n, s in sorted(found)]
    return out


def have_module(name):
    return subprocess.run(['/usr/bin/python3', '-c', f'import {name}'],
                          stderr=subprocess.DEVNULL).returncode == 0


def rewrite(f, script, short, used):
    notes = []
    for k, (pat, rep, why) in enumerate(NEVER):
        script, n = pat.subn(rep, script)
        if n:
            notes.append(why)
    for file, pat, module, why in REQUIRES:
        if file == f and re.search(pat, script, flags=re.M) and not have_module(module):
            script = re.sub(pat, 'true', script, flags=re.M)
            notes.append(why)
    if short:
        for k, (file, pat, rep, why) in enumerate(SHORT):
            if file != f:
                continue
            script, n = re.subn(pat, rep, script, flags=re.M)
            if n:
                used.add(k)
                notes.append('short: ' + why)
    return script, notes


def sandbox(build):
    """A copy of the repository (sources, cases, docs; no build, no runs)
    whose build/ is the real build directory."""
    root = tempfile.mkdtemp(prefix='mps_doc_commands_')
    for name in os.listdir(ROOT):
        if name.startswith(('build', '.git', 'out', 'runs')) or name == '__pycache__':
            continue
        src = os.path.join(ROOT, name)
        if os.path.isdir(src):
            shutil.copytree(src, os.path.join(root, name),
                            ignore=shutil.ignore_patterns('__pycache__'))
        else:
            shutil.copy2(src, os.path.join(root, name))
    os.symlink(os.path.abspath(build), os.path.join(root, 'build'))
    return root


def run(script, root, env, timeout):
    """Runs script by sh -e in root; a run over timeout (s) is killed with
    everything it started (its process group)."""
    p = subprocess.Popen(['sh', '-ec', script], cwd=root, env=env, stdin=subprocess.DEVNULL,
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, start_new_session=True)
    try:
        out, _ = p.communicate(timeout=timeout)
        return subprocess.CompletedProcess(p.args, p.returncode, out)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        out, _ = p.communicate()
        return subprocess.CompletedProcess(p.args, f'timeout ({timeout} s)', out)


def main():
    args = sys.argv[1:]
    if not args:
        sys.exit(__doc__)
    build, listing = args[0], '--list' in args
    only = [a for a in args[1:] if a != '--list']
    short = os.environ.get('MPS_DOC_TEST_SHORT', '') not in ('', '0')
    cmds = [c for c in commands() if not only or c[0] in only]
    used = set()
    plan = []
    for f, n, s in cmds:
        script, notes = rewrite(f, s, short, used)
        plan.append((f, n, s, script, notes))
    stale = [SHORT[k] for k in range(len(SHORT))
             if k not in used and (not only or SHORT[k][0] in only)]
    if listing:
        for f, n, s, script, notes in plan:
            print(f'{f}:{n}: {s.strip()}' + (f'\n    -> {script.strip()}' if script != s else '')
                  + ''.join(f'\n    [{x}]' for x in notes))
        return 0
    root = sandbox(build)
    failed = []
    env = dict(os.environ, OMP_NUM_THREADS=os.environ.get('OMP_NUM_THREADS', '2'))
    try:
        for f, n, s, script, notes in plan:
            where = f'{f}:{n}'
            if script.strip() in ('', 'true'):
                print(f'SKIP {where}: {s.strip()}  [{"; ".join(notes)}]', flush=True)
                continue
            t0 = time.time()
            r = run(script, root, env, 600 if short else None)
            took = time.time() - t0
            shown = script.strip().replace('\n', '\n     ')
            if r.returncode != 0:
                msg = (f'FAIL {where} ({took:.1f} s, exit {r.returncode}): {shown}\n'
                       + r.stdout.decode(errors='replace')[-3000:])
                failed.append((where, msg))
                print(msg, flush=True)
            else:
                print(f'ok   {where} ({took:.1f} s): {shown}'
                      + (f'  [{"; ".join(notes)}]' if notes else ''), flush=True)
    finally:
        shutil.rmtree(root, ignore_errors=True)
    # the failures again at the end: a log cut to its head and tail (CI's
    # excerpt) loses the middle, where they were printed
    for where, msg in failed:
        print(f'\n(again) {msg}')
    for e in stale:
        print(f'FAIL stale SHORT entry (matches no command of {e[0]}): {e[1]}')
    print(f'doc_commands: {len(plan)} commands, {len(failed)} failed'
          + (f': {", ".join(w for w, _ in failed)}' if failed else ''))
    return 1 if failed or stale else 0


if __name__ == '__main__':
    sys.exit(main())
