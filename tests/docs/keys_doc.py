#!/usr/bin/python3
"""docs/keys.md is the programs' own key lists (`PROGRAM --keys`), so the
reference a user reads cannot drift from what the programs accept.

Runs `coupler --keys`, `fluid_solver --keys` and `solid_solver --keys`, keeps
each section once (the common keys and the tank's motion, which all three
print, must read the same in each), and compares the page with them; --write
writes the page instead.

usage: keys_doc.py BUILD_DIR [--write]   (from the repository root)
"""
import os
import subprocess
import sys

PAGE = 'docs/keys.md'
PROGRAMS = ['coupler', 'fluid_solver', 'solid_solver']
INTRO = """# Case keys

Every key a case file may hold, with its type, units, default, the values a
program accepts and what it does. Each program prints its own list:
`build/bin/coupler --keys`, `build/bin/fluid_solver --keys`,
`build/bin/solid_solver --keys`; this page is the three lists with their
shared sections once (`tests/docs/keys_doc.py build --write` writes it, the
ctest `doc_keys` fails when it differs from what the programs print).

A case file is YAML; nested mappings are the dotted keys below (`fluid:` then
`rho:` is `fluid.rho`), and `*` stands for the index of a list item
(`fluid.blocks.0.x0` is the first block's x0). `--set KEY=VALUE` on the
command line overrides a key. A key that is not listed, a value of the wrong
type or out of its range is refused before anything runs, naming the file,
line and key (docs/security.md, "Broken case files"). The coupler checks its
own sections and hands `fluid.*` and `solid.*` to the solvers, which check
theirs (docs/coupling.md, "Who checks which keys"); `OUT/case_resolved.yml`
of a run holds every key as it ran.

"""


def sections(text, program):
    """[(title, body)] of one program's --keys output."""
    out = []
    for part in text.split('\n## ')[0:]:
        part = part[3:] if part.startswith('## ') else part
        title, _, body = part.partition('\n')
        if not title:
            sys.exit(f'keys_doc: {program} --keys: a section without a title')
        out.append((title, body.strip('\n') + '\n'))
    return out


def page(build):
    seen, order = {}, []
    for prog in PROGRAMS:
        exe = os.path.join(build, 'bin', prog)
        p = subprocess.run([exe, '--keys'], capture_output=True, text=True, timeout=60)
        if p.returncode != 0 or not p.stdout.startswith('## '):
            sys.exit(f'keys_doc: {exe} --keys: exit {p.returncode}, output {p.stdout[:80]!r} '
                     f'{p.stderr[:200]!r}')
        for title, body in sections(p.stdout, prog):
            if title in seen:
                if seen[title] != body:
                    sys.exit(f'keys_doc: section "{title}" differs between the programs '
                             f'(each prints its own copy of a shared table)')
                continue
            seen[title] = body
            order.append(title)
    # the shared sections first and last, the programs' own between
    shared = [t for t in order if t.startswith('Every program')]
    order = shared[:1] + [t for t in order if t not in shared] + shared[1:]
    return INTRO + '\n'.join(f'## {t}\n\n{seen[t]}' for t in order)


def main():
    if len(sys.argv) not in (2, 3) or (len(sys.argv) == 3 and sys.argv[2] != '--write'):
        sys.exit(__doc__.strip().split('\n')[-1])
    text = page(sys.argv[1])
    if len(sys.argv) == 3:
        with open(PAGE, 'w') as f:
            f.write(text)
        print(f'keys_doc: wrote {PAGE}')
        return
    with open(PAGE) as f:
        old = f.read()
    if old != text:
        a, b = old.split('\n'), text.split('\n')
        n = next((i for i in range(min(len(a), len(b))) if a[i] != b[i]), min(len(a), len(b)))
        sys.exit(f'keys_doc: {PAGE} differs from the programs\' --keys from line {n + 1}:\n'
                 f'  page:     {a[n] if n < len(a) else "(end)"}\n'
                 f'  programs: {b[n] if n < len(b) else "(end)"}\n'
                 f'a key was added or changed: run tests/docs/keys_doc.py build --write')
    print(f'keys_doc: {PAGE} matches the programs ({text.count(chr(10) + "- ")} keys)')


if __name__ == '__main__':
    main()
