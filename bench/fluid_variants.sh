#!/bin/bash
# Fluid method variants on the two validation cases (docs/fluid.md, table
# "Variants"). For each variant:
#   hydrostatic  cases/hydrostatic at dp = 10 mm for 2 s: max speed over the
#                run, bottom pressure error vs rho g h at the end;
#   dam break    cases/dambreak at dp = 4 mm to T = 3 (t = 0.27 s): front error
#                vs Martin & Moyce (max and mean |.| over the table points),
#                height error (max |.|);
#   stability    cases/dambreak at dp = 8 mm for 2 s: finished, no particle
#                out of the tank (else the time it failed).
# usage: bench/fluid_variants.sh [BUILD_DIR] [NAME...]   (default build/, all)
# Needs a Release build of fluid_solver; OMP_NUM_THREADS=1 per run, two runs
# at a time. About 1-2 minutes per variant on a quiet 2-core machine.
set -u
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD=${1:-$ROOT/build}
[ $# -gt 0 ] && shift
BIN=$BUILD/bin/fluid_solver
OUT=${FLUID_VARIANTS_OUT:-/tmp/fluid_variants}
[ -x "$BIN" ] || { echo "no $BIN: build fluid_solver first" >&2; exit 2; }
mkdir -p "$OUT"

# name | --set options (empty: the defaults)
VARIANTS=(
  "default|"
  "paper|fluid.wall_bc=ppe fluid.ppe_source=density fluid.initial_pressure=zero fluid.surface_scan=0 fluid.collision_distance=0 fluid.shifting=0"
  "paper_plain_grad|fluid.wall_bc=ppe fluid.ppe_source=density fluid.gradient=plain fluid.initial_pressure=zero fluid.surface_scan=0 fluid.collision_distance=0 fluid.shifting=0"
  "previous_default|fluid.wall_bc=ppe fluid.gradient_min=true fluid.initial_pressure=zero fluid.surface_scan=0 fluid.collision_distance=0.5 fluid.shifting=0"
  "ppe_walls|fluid.wall_bc=ppe"
  "density_source|fluid.ppe_source=density"
  "plain_gradient|fluid.gradient=plain"
  "gradient_min|fluid.gradient_min=true"
  "truncated_surface|fluid.surface_laplacian=truncated"
  "no_surface_scan|fluid.surface_scan=0"
  "no_shifting|fluid.shifting=0"
  "collision_0.5|fluid.collision_distance=0.5"
  "no_collision|fluid.collision_distance=0"
  "initial_p_zero|fluid.initial_pressure=zero"
  "kappa_0.05|fluid.kappa=0.05"
  "alpha_1e-6|fluid.alpha=1e-6"
  "courant_0.1|fluid.courant=0.1"
)

sets() { for s in $1; do printf -- '--set %s ' "$s"; done; }

one() {
  local name=$1 opts=$2 d=$OUT/$1
  mkdir -p "$d"
  export OMP_NUM_THREADS=1
  # shellcheck disable=SC2046
  "$BIN" "$ROOT/cases/hydrostatic/case.yml" --out "$d/hs" --quiet --set output.interval=0 \
    $(sets "$opts") 2>"$d/hs.err"
  # shellcheck disable=SC2046
  "$BIN" "$ROOT/cases/dambreak/case.yml" --out "$d/db4" --quiet --set end_time=0.27 \
    --set output.interval=0 $(sets "$opts") 2>"$d/db4.err"
  # shellcheck disable=SC2046
  "$BIN" "$ROOT/cases/dambreak/case.yml" --out "$d/db8" --quiet --set dp=0.008 \
    --set output.interval=0 $(sets "$opts") 2>"$d/db8.err"
  /usr/bin/python3 - "$d" "$name" "$opts" "$ROOT" > "$d/row.md" <<'PY'
import csv, json, math, os, sys
d, name, opts, root = sys.argv[1:5]
sys.path.insert(0, os.path.join(root, 'bench'))
import dambreak_compare as dc

def probes(run):
    try:
        with open(os.path.join(run, 'probes.csv')) as f:
            return list(csv.DictReader(l for l in f if not l.startswith('#')))
    except OSError:
        return []

def status(run):
    try:
        with open(os.path.join(run, 'summary.json')) as f:
            s = json.load(f)
        return s['status'], s.get('simulated_time', 0.0)
    except (OSError, ValueError):
        return 'missing', 0.0

hs = probes(os.path.join(d, 'hs'))
st, t = status(os.path.join(d, 'hs'))
if hs:
    vmax = max(float(r['max_speed']) for r in hs)
    bp = 100 * (float(hs[-1]['bottom_pressure']) / (1000 * 9.81 * 0.3) - 1)
    hcell = f"{vmax:.4f} | {bp:+.2f}%" + ('' if st == 'ok' else f" (failed at {t:.2f} s)")
else:
    hcell = 'failed | -'
st4, t4 = status(os.path.join(d, 'db4'))
try:
    r = dc.compare(os.path.join(d, 'db4'))
    dcell = (f"{100 * r['front_max_rel_err']:.1f}% / {100 * r['front_mean_rel_err']:.1f}% | "
             f"{100 * r['height_max_rel_err']:.1f}%")
    if st4 != 'ok':
        dcell += f" (failed at {t4:.3f} s)"
except Exception:
    dcell = f'failed at {t4:.3f} s | -'
st8, t8 = status(os.path.join(d, 'db8'))
esc = max((float(x.get('escaped', 0)) for x in probes(os.path.join(d, 'db8'))), default=0)
scell = 'yes' if st8 == 'ok' and t8 >= 2.0 - 1e-9 and esc == 0 else f'no ({t8:.2f} s)'
o = ' '.join('`' + s + '`' for s in opts.split()) if opts else '(defaults)'
print(f"| {name} | {o} | {hcell} | {dcell} | {scell} |")
PY
  cat "$d/row.md"
}

echo "| variant | options | hydrostatic max speed (m/s) | bottom pressure error | dam-break front max / mean error | height max error | stable to 2 s (8 mm) |"
echo "|---|---|---|---|---|---|---|"
running=0
for v in "${VARIANTS[@]}"; do
  name=${v%%|*}; opts=${v#*|}
  if [ $# -gt 0 ]; then
    case " $* " in *" $name "*) ;; *) continue ;; esac
  fi
  rm -f "$OUT/$name.row"
  one "$name" "$opts" > "$OUT/$name.row" &
  running=$((running + 1))
  if [ $running -ge 2 ]; then wait -n; running=$((running - 1)); fi
done
wait
for v in "${VARIANTS[@]}"; do
  name=${v%%|*}
  if [ $# -gt 0 ]; then
    case " $* " in *" $name "*) ;; *) continue ;; esac
  fi
  cat "$OUT/$name.row"
done
