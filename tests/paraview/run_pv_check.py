#!/usr/bin/python3
"""ctest paraview_reads_outputs: writes one output of every kind the project
writes (the fluid alone, the solid alone, a coupled run with the MPS solid and
its scene.xmf, a coupled run with the Python solid and its scene.xmf), then
opens them all in ParaView (tests/paraview/pv_check.py under pvbatch, on a
private Xvfb display). Exit 77 (ctest: SKIPPED) where pvbatch or Xvfb is
missing: Debian's paraview, python3-paraview and xvfb provide them (.ci/run
installs them).

usage: run_pv_check.py BUILD_DIR OUT_DIR   (from the repository root)
"""
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

SKIP = 77
HERE = os.path.dirname(os.path.abspath(__file__))


def run(cmd, timeout=300):
    print('+ ' + ' '.join(cmd), flush=True)
    r = subprocess.run(cmd, timeout=timeout)
    if r.returncode != 0:
        sys.exit(f'run_pv_check: {cmd[0]} exited with {r.returncode}')


def outputs(bin_dir, out):
    """Writes the outputs into out; returns the .xmf files to open."""
    shutil.rmtree(out, ignore_errors=True)
    quick = ['--quiet', '--set', 'output.interval=0.02']
    run([f'{bin_dir}/fluid_solver', 'cases/dambreak/case.yml', '--out', f'{out}/fluid', *quick,
         '--set', 'dp=0.02', '--set', 'end_time=0.04'])
    run([f'{bin_dir}/solid_solver', 'cases/cantilever_beam/case.yml', '--out', f'{out}/solid',
         *quick, '--set', 'end_time=0.04'])
    plate = ['cases/dambreak_elastic_plate/case.yml', *quick, '--set', 'dp=0.006',
             '--set', 'end_time=0.04']
    run([f'{bin_dir}/coupler', plate[0], '--out', f'{out}/coupled', *plate[1:]])
    run([f'{bin_dir}/coupler', plate[0], '--out', f'{out}/python', *plate[1:],
         '--solid', '/usr/bin/python3 solid_solver/python/modal_beam_solid.py'])
    return [f'{out}/fluid/fluid.xmf', f'{out}/solid/solid.xmf', f'{out}/coupled/fluid.xmf',
            f'{out}/coupled/solid.xmf', f'{out}/coupled/scene.xmf', f'{out}/python/solid.xmf',
            f'{out}/python/scene.xmf']


def start_xvfb():
    """A private X server; returns (process, DISPLAY). -noreset: by default
    Xvfb resets when its last client leaves, and pvbatch, which connects once
    to probe OpenGL and again to render, then finds no server (1 run in 6)."""
    fd_r, fd_w = os.pipe()
    xvfb = subprocess.Popen(['Xvfb', '-displayfd', str(fd_w), '-screen', '0', '1024x768x24',
                             '-nolisten', 'tcp', '-noreset'], pass_fds=(fd_w,),
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)
    os.close(fd_w)
    number = b''
    deadline = time.time() + 30
    os.set_blocking(fd_r, False)
    while not number.endswith(b'\n') and time.time() < deadline and xvfb.poll() is None:
        try:
            number += os.read(fd_r, 16)
        except BlockingIOError:
            time.sleep(0.05)
    os.close(fd_r)
    if not number.strip().isdigit():
        stop(xvfb)
        sys.exit('run_pv_check: Xvfb did not start')
    return xvfb, ':' + number.decode().strip()


def stop(proc):
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGTERM)
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    build, out = sys.argv[1], os.path.abspath(sys.argv[2])
    missing = [p for p in ('pvbatch', 'Xvfb') if not shutil.which(p)]
    if missing:
        print(f'SKIPPED: {" and ".join(missing)} not found (Debian: apt-get install paraview '
              'python3-paraview xvfb)')
        return SKIP
    files = outputs(os.path.join(build, 'bin'), out)
    xvfb, display = start_xvfb()
    try:
        env = dict(os.environ, DISPLAY=display)
        with tempfile.TemporaryDirectory() as home:  # no ParaView settings of the user's
            env['HOME'] = home
            cmd = ['pvbatch', os.path.join(HERE, 'pv_check.py'), f'{out}/png', *files]
            print('+ ' + ' '.join(cmd), flush=True)
            rc = subprocess.run(cmd, env=env, timeout=600).returncode
    finally:
        stop(xvfb)
    if rc != 0:
        print(f'run_pv_check: pvbatch exited with {rc}')
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main())
