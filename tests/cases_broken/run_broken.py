#!/usr/bin/python3
"""Runs every line of MANIFEST (the broken case files of issue 20) through
the programs it names and checks the exit status and the one-line message.

usage: run_broken.py BUILD_BIN_DIR
Prints one line per run; exits 1 if any failed."""
import os
import re
import shlex
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
BIN = os.path.abspath(sys.argv[1])
PROGRAMS = {'all': ['coupler', 'fluid_solver', 'solid_solver'],
            'fluid': ['coupler', 'fluid_solver'], 'solid': ['coupler', 'solid_solver'],
            'coupler': ['coupler']}


def generate(name, tmp):
    """Files not worth committing, made here: a file over the 1 MiB cap, a
    file of 10001 keys, a directory, a good case whose name is not UTF-8."""
    path = os.path.join(tmp, name)
    if name == 'not_utf8_name.yml':  # caf\xe9.yml: Latin-1 bytes, as an old file system has them
        path = os.path.join(tmp, os.fsdecode(b'caf\xe9.yml'))
        with open(path, 'w') as f:
            f.write('dp: 0.01\nend_time: 0.1\nfluid:\n  tank: {width: 0.5, height: 0.4}\n'
                    '  blocks:\n    - {x0: 0.0, y0: 0.0, x1: 0.2, y1: 0.2}\n')
    if name == 'large.yml':
        with open(path, 'w') as f:
            f.write('dp: 0.01\nend_time: 0.1\ndescription: "')
            f.write('x' * (1 << 20))
            f.write('"\n')
    elif name == 'many_keys.yml':
        with open(path, 'w') as f:
            f.write('dp: 0.01\nend_time: 0.1\n')
            for k in range(10001):
                f.write(f'k{k}: {k}\n')
    elif name == 'a_directory.yml':
        os.mkdir(path)
    return path


def raw_bytes(arg):
    """The argument with each \\xNN written as that byte, so a line of the
    manifest (text) can pass bytes that are not UTF-8."""
    return re.sub(rb'\\x([0-9a-fA-F]{2})', lambda m: bytes([int(m.group(1), 16)]),
                  os.fsencode(arg))


def main():
    tmp = tempfile.mkdtemp(prefix='broken_')
    out = os.path.join(tmp, 'out')
    failed, runs, files = [], 0, 0
    for line in open(os.path.join(HERE, 'MANIFEST')):
        if not line.strip() or line.lstrip().startswith('#'):
            continue
        name, progs, code, extra, regex = (x.strip() for x in line.split('|', 4))
        files += 1
        if name.startswith('GEN:'):
            path = generate(name[4:], tmp)
        else:
            path = os.path.relpath(os.path.join(HERE, name))
        pattern = re.compile(regex.replace('@', re.escape(path)))
        for prog in PROGRAMS[progs]:
            runs += 1
            cmd = [os.path.join(BIN, prog), path, '--out', out] + [
                raw_bytes(a) for a in shlex.split(extra)]
            try:
                p = subprocess.run(cmd, capture_output=True, text=True, timeout=30,
                                   errors='replace')
                rc, err = p.returncode, p.stderr
            except subprocess.TimeoutExpired:
                rc, err = None, '(no answer within 30 s)\n'
            lines = err.splitlines()
            why = []
            if rc != int(code):
                why.append(f'exit {rc}, expected {code}')
            if len(lines) != 1:
                why.append(f'{len(lines)} lines on stderr, expected 1')
            if not pattern.search(err):
                why.append(f'no match for /{pattern.pattern}/')
            tag = f'{prog} {name}{" " + extra if extra else ""}'
            print(('ok    ' if not why else 'FAIL  ') + tag + ': ' +
                  (lines[0] if len(lines) == 1 else repr(err[:300])) +
                  ('' if not why else '  <- ' + '; '.join(why)))
            if why:
                failed.append(tag)
    print(f'{files} broken inputs, {runs} runs: {runs - len(failed)} passed, {len(failed)} failed')
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main())
