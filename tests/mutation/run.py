#!/usr/bin/python3
"""The mutation check (issue 22): does the test suite catch a deliberate fault
in each equation the code implements, the protocol's rejections and the
coupler's failure handling? The faults are in tests/mutation/faults.py.

    nice -n 10 /usr/bin/python3 tests/mutation/run.py [--work DIR] [--only ID,ID]
        [--redo] [--baseline] [--all-tests] [--hints-only] [--table FILE] [--check]

It copies the repository (a clone of HEAD with the working tree's files laid
over it: uncommitted changes count) to a scratch directory (default
/tmp/mpsfsi-mutation), configures one Release build there as CI does
(-DMPS_WERROR=ON) and runs the baseline: the fast CI suite, that is ctest
without the labels paraview, docs and fuzz (ParaView's reading of the
outputs, the README commands and the fuzzers: about 10 minutes more per
fault, and none of them tests an equation). Then, one fault at a time: apply
the patch, rebuild (incremental: one source file and the links), run the
fault's hinted tests; if none fails, the rest of the fast suite until the
first failure (--all-tests: every fast test, to list all that catch it);
restore the file. A fault caught by the compiler (CI builds with warnings
as errors) counts as caught by 'build'. Tests that fail on the baseline are
left out of every run (listed in the report).

Results go to WORK/results.json as they come, each with the revision of the
tree it ran on. A rerun lays the working tree over the scratch copy again
and skips the faults done, unless --redo (with --only: those faults);
--baseline runs the baseline again (after a change to the tests). --table
FILE writes the markdown table for docs/testing.md.
--hints-only skips the suite's baseline and runs only each fault's hinted
tests, on the unmodified tree first (a test failing there is left out; each
test once per sweep) and then with the fault: minutes instead of the suite's
ten, for checking new faults or sweeping all of them; a fault none of its
hints catches is reported as survived, not run against the rest of the
suite. Such results are marked, and a later run without --hints-only runs
those faults again on the whole suite.
--check only verifies that every fault's text occurs once in its file.
Exit status: 0 if every fault was caught, 1 otherwise."""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
from faults import FAULTS  # noqa: E402

FAST = ['-LE', 'paraview|docs|fuzz']
RESULT_RE = re.compile(r'^\s*\d+/\d+ Test\s+#\d+: (\S+) \.*\s*(\*\*\*)?(\S+(?: \S+)?)')


def sh(cmd, cwd=None, log=None, timeout=None):
    """Runs cmd, output to the file log (appended); returns the exit status."""
    with open(log or os.devnull, 'a') as f:
        f.write(f'\n$ {" ".join(cmd)}\n')
        f.flush()
        try:
            return subprocess.run(cmd, cwd=cwd, stdout=f, stderr=subprocess.STDOUT,
                                  timeout=timeout).returncode
        except subprocess.TimeoutExpired:
            f.write('(timed out)\n')
            return 124


def check_faults(src):
    bad = []
    ids = set()
    for f in FAULTS:
        if f['id'] in ids:
            bad.append(f"{f['id']}: id used twice")
        ids.add(f['id'])
        path = os.path.join(src, f['file'])
        n = open(path).read().count(f['old']) if os.path.exists(path) else -1
        if n != 1:
            bad.append(f"{f['id']}: {f['file']}: the text occurs {n} times (must be once)")
    return bad


def tree_files():
    """The working tree's files (bytes, relative): git's tracked and untracked
    ones not ignored; outside a git repository every file but build*/ and out/."""
    git = subprocess.run(['git', 'ls-files', '-co', '--exclude-standard', '-z'], cwd=ROOT,
                         capture_output=True)
    if git.returncode == 0:
        return git.stdout.split(b'\0')
    names = []
    for d, dirs, files in os.walk(ROOT):
        dirs[:] = [x for x in dirs if not x.startswith(('build', '.git', 'out', 'runs'))]
        names += [os.path.relpath(os.path.join(d, f), ROOT).encode() for f in files]
    return names


def prepare(work, log):
    src, build = os.path.join(work, 'src'), os.path.join(work, 'build')
    if not os.path.isdir(src):
        # a clone, so the copy has a git revision (test version_git_rev);
        # outside a repository a plain copy (that test then fails in the
        # baseline and is left out)
        if subprocess.run(['git', 'clone', '-q', '--no-hardlinks', ROOT, src],
                          capture_output=True).returncode != 0:
            shutil.rmtree(src, ignore_errors=True)
            os.makedirs(src)
    files = tree_files()
    for name in files:
        if not name:
            continue
        a, b = os.path.join(ROOT.encode(), name), os.path.join(src.encode(), name)
        if not os.path.isfile(a):
            continue
        os.makedirs(os.path.dirname(b), exist_ok=True)
        data = open(a, 'rb').read()
        if not os.path.exists(b) or open(b, 'rb').read() != data:
            with open(b, 'wb') as f:
                f.write(data)
            shutil.copymode(a, b)
    if not os.path.exists(os.path.join(build, 'CMakeCache.txt')):
        if sh(['cmake', '-S', src, '-B', build, '-DCMAKE_BUILD_TYPE=Release', '-DMPS_WERROR=ON'],
              log=log):
            sys.exit(f'mutation: configure failed, see {log}')
    return src, build


def revision():
    """HEAD of the tree the faults are applied to, '+' if it has changes."""
    head = subprocess.run(['git', 'rev-parse', '--short', 'HEAD'], cwd=ROOT, capture_output=True,
                          text=True).stdout.strip() or 'no-git'
    dirty = subprocess.run(['git', 'status', '--porcelain', '--untracked-files=no'], cwd=ROOT,
                           capture_output=True, text=True).stdout.strip()
    return head + ('+' if dirty else '')


def build_tree(build, log):
    return sh(['cmake', '--build', build, '-j2'], log=log) == 0


def ctest(build, log, args):
    """Runs ctest with args; returns {test: status} (Passed, Failed, Timeout, ...)."""
    out = subprocess.run(['ctest', '--test-dir', build] + args, capture_output=True, text=True)
    with open(log, 'a') as f:
        f.write(f'\n$ ctest {" ".join(args)}\n{out.stdout}{out.stderr}')
    got = {}
    for line in out.stdout.splitlines():
        m = RESULT_RE.match(line)
        if m:
            got[m.group(1)] = m.group(3).strip()
    return got


def failed(results):
    return sorted(t for t, s in results.items() if s not in ('Passed', 'Skipped', 'Not Run'))


def fast_tests(build):
    out = subprocess.run(['ctest', '--test-dir', build, '-N'] + FAST, capture_output=True,
                         text=True).stdout
    return [m.group(1) for m in re.finditer(r'Test\s+#\d+: (\S+)', out)]


def alternation(names):
    return '^(' + '|'.join(re.escape(n) for n in names) + ')$'


def run_fault(f, src, build, log, baseline_bad, all_tests, hints_only=False, clean=None):
    """clean (hints_only): {test: status} on the unmodified tree, filled as
    tests run there, so that a test hinted by several faults runs once
    unmodified in a sweep (the tree and its build are the same between faults)."""
    path = os.path.join(src, f['file'])
    text = open(path).read()
    if text.count(f['old']) != 1:
        return {'status': 'not applied', 'caught_by': []}
    if hints_only:  # the hinted tests' own baseline, on the unmodified tree
        clean = {} if clean is None else clean
        hinted = [t for t in fast_tests(build) if re.search(f.get('hint', '$^'), t)]
        if not hinted:
            return {'status': 'not applied', 'caught_by': [], 'why': 'no hinted test'}
        new = [t for t in hinted if t not in clean]
        if new:  # the last fault's file is restored, its build not yet
            build_tree(build, log)
            clean.update(ctest(build, log, ['-R', alternation(new)]))
        baseline_bad = set(failed({t: clean.get(t, 'Not Run') for t in hinted}))
    t0 = time.time()
    try:
        with open(path, 'w') as fp:
            fp.write(text.replace(f['old'], f['new']))
        if not build_tree(build, log):
            return {'status': 'caught', 'caught_by': ['build'], 'seconds': time.time() - t0}
        every = [t for t in fast_tests(build) if t not in baseline_bad]
        hinted = [t for t in every if re.search(f.get('hint', '$^'), t)]
        caught = []
        ran = set()
        if hinted and not all_tests:
            r = ctest(build, log, ['-R', alternation(hinted)])
            ran.update(r)
            caught = failed(r)
        if not caught and not hints_only:
            rest = [t for t in every if t not in ran]
            if rest:
                extra = [] if all_tests else ['--stop-on-failure']
                r = ctest(build, log, ['-R', alternation(rest)] + extra)
                ran.update(r)
                caught = failed(r)
        return {'status': 'caught' if caught else 'survived', 'caught_by': caught,
                'tests_run': len(ran), 'seconds': round(time.time() - t0, 1)}
    finally:
        # restored; the next build (its fault's, or a baseline's) rebuilds it
        with open(path, 'w') as fp:
            fp.write(text)


def table(results):
    rows = ['| # | fault | breaks | how | caught by |', '|---|---|---|---|---|']
    for k, f in enumerate(FAULTS, 1):
        r = results.get(f['id'])
        by = ('**not caught**' if r and r['status'] == 'survived' else
              ', '.join(f'`{t}`' for t in r['caught_by']) if r else '(not run)')
        rows.append(f"| {k} | `{f['id']}` ({f['file']}) | {f['eq']} | {f['what']} | {by} |")
    done = [r for r in results.values() if r['status'] in ('caught', 'survived')]
    caught = sum(r['status'] == 'caught' for r in done)
    return caught, len(done), '\n'.join(rows)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('--work', default='/tmp/mpsfsi-mutation')
    ap.add_argument('--only', help='comma-separated fault ids')
    ap.add_argument('--all-tests', action='store_true', help='every fast test for every fault')
    ap.add_argument('--redo', action='store_true', help='run faults already in results.json')
    ap.add_argument('--baseline', action='store_true', help='run the baseline again')
    ap.add_argument('--hints-only', action='store_true',
                    help="only each fault's hinted tests, with their own baseline")
    ap.add_argument('--table', help='write the markdown table to this file')
    ap.add_argument('--check', action='store_true', help='only check that the faults apply')
    a = ap.parse_args()
    bad = check_faults(ROOT)
    if bad or a.check:
        print('\n'.join(bad) or f'{len(FAULTS)} faults, each applies once')
        sys.exit(1 if bad else 0)
    os.makedirs(a.work, exist_ok=True)
    log = os.path.join(a.work, 'log.txt')
    res_path = os.path.join(a.work, 'results.json')
    src, build = prepare(a.work, log)
    if not build_tree(build, log):
        sys.exit(f'mutation: the unmodified tree does not build, see {log}')
    state = json.load(open(res_path)) if os.path.exists(res_path) else {'faults': {}}
    rev = revision()
    if a.hints_only:
        # each fault runs its hints' own baseline; the suite's is neither run nor stored
        base = {'failed': []}
        print("baseline: each fault's hinted tests on the unmodified tree (--hints-only)",
              flush=True)
    else:
        if 'baseline' not in state or a.baseline:
            print(f'baseline: the fast suite on the unmodified tree ({rev}) ...', flush=True)
            t0 = time.time()
            r = ctest(build, log, FAST)
            state['baseline'] = {'failed': failed(r), 'tests': len(r), 'revision': rev,
                                 'seconds': round(time.time() - t0)}
            json.dump(state, open(res_path, 'w'), indent=1)
        base = state['baseline']
        print(f"baseline: {base['tests']} fast tests in {base['seconds']} s; failing (left out): "
              f"{base['failed'] or 'none'}", flush=True)
    only = set(a.only.split(',')) if a.only else None
    clean = {}   # --hints-only: each test's status on the unmodified tree, run once
    for f in FAULTS:
        if only and f['id'] not in only:
            continue
        done = state['faults'].get(f['id'])
        # a fault done counts, unless only its hints ran and the suite is asked for now
        if done and not a.redo and (a.hints_only or not done.get('hints_only')):
            continue
        r = run_fault(f, src, build, log, set(base['failed']), a.all_tests, a.hints_only, clean)
        r['revision'] = rev
        r['hints_only'] = a.hints_only
        state['faults'][f['id']] = r
        json.dump(state, open(res_path, 'w'), indent=1)
        print(f"{f['id']:32s} {r['status']:9s} {', '.join(r['caught_by'])} "
              f"({r.get('seconds', 0):.0f} s)", flush=True)
    build_tree(build, log)  # the scratch build back to the unmodified tree
    state['faults'] = {k: v for k, v in state['faults'].items()
                       if any(f['id'] == k for f in FAULTS)}  # faults since removed
    caught, done, md = table(state['faults'])
    print(f'\nscore: {caught} of {done} faults caught')
    if a.table:
        with open(a.table, 'w') as fp:
            fp.write(f'Score: {caught} of {done} faults caught.\n\n{md}\n')
    sys.exit(0 if caught == done == len(FAULTS) else 1)


if __name__ == '__main__':
    main()
