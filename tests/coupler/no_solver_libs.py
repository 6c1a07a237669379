#!/usr/bin/python3
"""The coupler links neither solver library (issue 22).

usage: no_solver_libs.py COUPLER LINK_LIBRARIES_FILE LIBFLUIDCORE.a LIBSOLIDCORE.a

Fails if the coupler's link libraries (as CMake records them) name fluidcore
or solidcore, or if the coupler binary defines any global symbol one of those
libraries defines (nm). Positive controls keep it from passing on empty nm
output: the libraries must define their readers (fluid_params_read,
solid_scene_read) and the coupler must define mps_case_load (mpscommon)."""
import subprocess
import sys


def defined(path):
    """Global symbols path defines (code and data), from nm."""
    out = subprocess.run(['nm', '--defined-only', '-g', path], capture_output=True, text=True,
                         check=True).stdout
    return {f[2] for f in (line.split() for line in out.splitlines())
            if len(f) == 3 and f[1] in 'TDRBVW'}


def main():
    coupler, link_file, fluid, solid = sys.argv[1:5]
    bad = []
    libs = open(link_file).read().replace(';', ' ').split()
    named = [lib for lib in libs if lib in ('fluidcore', 'solidcore')]
    if named:
        bad.append(f'the coupler links {", ".join(named)} ({" ".join(libs)})')
    mine = defined(coupler)
    for lib, control in ((fluid, 'fluid_params_read'), (solid, 'solid_scene_read')):
        theirs = defined(lib)
        if control not in theirs:
            bad.append(f'{lib}: nm shows no {control}: cannot check')
        common = sorted(mine & theirs)
        if common:
            bad.append(f'the coupler holds {len(common)} symbols of {lib}: {", ".join(common[:8])}')
    if 'mps_case_load' not in mine:
        bad.append(f'{coupler}: nm shows no mps_case_load: cannot check')
    if bad:
        print('FAIL: ' + '; '.join(bad), file=sys.stderr)
        return 1
    print(f'ok: the coupler ({len(mine)} symbols) links neither solver library ({" ".join(libs)})')
    return 0


if __name__ == '__main__':
    sys.exit(main())
