#!/bin/sh
# SPDX-License-Identifier: MIT
# make demo: the main job.  foldest finds what a simulation left out:
#   1. a synthetic experiment whose recording hides quadratic drag (at most
#      0.3 noise standard deviations per sample, coloured noise), generated
#      here, and a negative control with nothing hidden; then a cart whose
#      simulation lacks a viscous friction that changes its motion (--order 2);
#   2. the phone free-fall recordings (../shared/data/freefall-drag, or
#      $FOLDEST_DATA), each drop against a vacuum free-fall simulation of it;
#   3. magnetometer recordings against the best sphere through them;
# each with a report (Markdown and plots) under $OUT.
set -e
B=${1:-build}
FOLDEST=$B/bin/foldest
OUT=${FOLDEST_OUT:-$B/out}/demo
mkdir -p "$OUT"
say() { printf '\n\033[1m== %s\033[0m\n' "$*"; }

say "1. A synthetic experiment with a concealed effect (the truth is known)"
"$FOLDEST" synth --effect quadratic_drag --seed 7 --real "$OUT/drag_real.csv" --sim "$OUT/drag_sim.csv"
"$FOLDEST" discover --real "$OUT/drag_real.csv" --sim "$OUT/drag_sim.csv" --channel acceleration \
  --role position=position --role velocity=velocity --role input=input \
  --base bias,gain --holdout 0.3 --report "$OUT/synthetic"

say "1b. The negative control: the same rig with nothing hidden"
"$FOLDEST" synth --effect none --seed 7 --real "$OUT/null_real.csv" --sim "$OUT/null_sim.csv" 2>/dev/null
"$FOLDEST" discover --real "$OUT/null_real.csv" --sim "$OUT/null_sim.csv" --channel acceleration \
  --role position=position --role velocity=velocity --role input=input \
  --base bias,gain --holdout 0.3 | tail -n 4

say "1c. When the missing physics changes the motion: a driven cart missing a viscous friction"
"$FOLDEST" synth --effect viscous_friction --order 2 --seed 3 --rows 6000 \
  --real "$OUT/cart_real.csv" --sim "$OUT/cart_sim.csv"
echo "adding terms to the position (the first mode) misses it:"
"$FOLDEST" discover --real "$OUT/cart_real.csv" --sim "$OUT/cart_sim.csv" --channel position \
  --role velocity=velocity --role input=input --holdout 0.3 | sed -n '/^verdict/,$p'
echo "the effect in the cart's acceleration (--order 2):"
"$FOLDEST" discover --real "$OUT/cart_real.csv" --sim "$OUT/cart_sim.csv" --channel position \
  --role velocity=velocity --role input=input --order 2 --holdout 0.3 --report "$OUT/dynamics" |
  sed -n '/^order/p;/^what was left out/,/^$/p;/^held out/p;/^verdict/,$p'

say "2. Real recordings: a phone in free fall against a vacuum simulation, drop by drop"
DATA=${FOLDEST_DATA:-../shared/data}
if [ -f "$DATA/freefall-drag/csv/fall_1.csv" ]; then
  FOLDEST_OUT=$OUT "$B/examples/freefall_sim" "$DATA/freefall-drag/csv" "$OUT/freefall_sim" > "$OUT/freefall_sim.txt"
  head -n 3 "$OUT/freefall_sim.txt"
  echo "..."
  common="--channel Absolute --time Time --role velocity=velocity --base bias --holdout 0"
  for k in 1 2 3 4 5 6 7 8 9 10 11 12; do
    sim="$OUT/freefall_sim/fall_${k}_sim.csv"
    [ -f "$sim" ] || continue
    # shellcheck disable=SC2086
    found=$("$FOLDEST" discover --real "$DATA/freefall-drag/csv/fall_$k.csv" --sim "$sim" $common |
            sed -n 's/^  [0-9]*\. \([a-z_]*\) .*coefficient \([^ ]*\) +\/- \([^ ]*\) .*/\1 \2 +\/- \3/p' | tr '\n' ';')
    printf '  fall_%-2s %s\n' "$k" "${found:-nothing named}"
  done
  echo "the first drop in full:"
  # shellcheck disable=SC2086
  "$FOLDEST" discover --real "$DATA/freefall-drag/csv/fall_1.csv" --sim "$OUT/freefall_sim/fall_1_sim.csv" \
    $common --report "$OUT/freefall"
else
  echo "no recordings at $DATA (set FOLDEST_DATA): skipped"
fi

say "3. Magnetometers: the best sphere as the simulation"
if [ -f "$DATA/qmc5883l_tomisuarez/filtered_raw_data.csv" ]; then
  "$FOLDEST" discover --sphere "$DATA/qmc5883l_tomisuarez/filtered_raw_data.csv" | sed -n '/left out/,$p'
  echo
  "$FOLDEST" discover --sphere "$DATA/ck_explorer_accmag/acc_mag_log.csv" --columns mx,my,mz | sed -n '/left out/,$p'
  echo
  echo "one hemisphere only (x-IMU3): refused, not explained:"
  "$FOLDEST" discover --sphere "$DATA/ximu3_fusion/sensor_data.csv" \
    --columns "Magnetometer X","Magnetometer Y","Magnetometer Z" || true
else
  echo "no recordings at $DATA (set FOLDEST_DATA): skipped"
fi

say "Reports"
for r in "$OUT"/*/report.md; do echo "  $r"; done
echo "(other examples: make run-examples)"
