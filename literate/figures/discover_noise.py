#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The discovery chapter's figure: how often `foldest discover` names a
concealed drift (power), and how often its 95 % interval holds the true
coefficient (coverage), as the noise's colour changes, with the noise model
(the default) and with batch means (--noise batch).

Used as: python3 literate/figures/discover_noise.py OUTDIR
  (make doc runs it; FOLDEST names the command, default build/bin/foldest;
   SEEDS the seeds per colour, default 20; ROWS the rows, default 20000)

For each lag-one correlation rho of the list below and each seed 1..SEEDS,
`foldest synth --effect drift --rho RHO --seed S --rows ROWS` writes a
recording/simulation pair whose recording holds a drift the simulation
lacks (at most 0.3 noise standard deviations at any sample; the noise an
AR(1) with lag-one correlation rho, rho = 0 white), and prints the true
coefficient and the command that analyses the pair.  That command is run
twice with --json, as printed and with --noise batch.  A run counts as
naming the drift when "drift" is among its discovered terms; its interval
covers when the true coefficient lies in that term's interval95.  The same
seeds serve every colour, so the rigs and the noise's normal draws are the
same and only the colour differs.

Writes OUTDIR/discover-noise.dat (one row per colour and method: counts),
OUTDIR/discover-noise.gp (the gnuplot script; `gnuplot discover-noise.gp`
in OUTDIR redraws) and OUTDIR/discover-noise.svg.  Two workers at most.
Standard library only; the statistics are foldest's, this script counts.
"""
import json
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor

FOLDEST = os.environ.get("FOLDEST", "build/bin/foldest")
SEEDS = int(os.environ.get("SEEDS", "20"))
ROWS = int(os.environ.get("ROWS", "20000"))
EFFECT = "drift"
RHOS = [0.0, 0.3, 0.6, 0.9]
METHODS = [("ar", [], "noise model (default)"), ("batch", ["--noise", "batch"], "batch means (--noise batch)")]


def run(args):
    r = subprocess.run(args, capture_output=True, text=True, check=False)
    if r.returncode != 0:
        raise RuntimeError("%s: exit %d\n%s" % (" ".join(args), r.returncode, r.stderr))
    return r


def one_case(tmp, rho, seed):
    """Write one pair and analyse it both ways: {method: (named, covers)}."""
    d = os.path.join(tmp, "rho%g-seed%d" % (rho, seed))
    os.makedirs(d)
    real, sim = os.path.join(d, "real.csv"), os.path.join(d, "sim.csv")
    r = run([FOLDEST, "synth", "--effect", EFFECT, "--seed", str(seed), "--rows", str(ROWS),
             "--rho", repr(rho), "--real", real, "--sim", sim])
    truth = float(re.search(r"hidden effect %s, coefficient (\S+);" % EFFECT, r.stderr).group(1))
    command = shlex.split(r.stderr.split("analyse with:\n", 1)[1].strip())
    assert command[:2] == ["foldest", "discover"], command
    out = {}
    for method, extra, _ in METHODS:
        js = json.loads(run([FOLDEST] + command[1:] + ["--json"] + extra).stdout)
        found = next((t for t in js["discovered"] if t["name"] == EFFECT), None)
        covers = found is not None and found["interval95"][0] <= truth <= found["interval95"][1]
        others = sum(1 for t in js["discovered"] if t["name"] != EFFECT)
        out[method] = (found is not None, covers, others)
    shutil.rmtree(d)
    return rho, out


GNUPLOT = r"""# The discovery chapter's figure; made by literate/figures/discover_noise.py.
# Columns of discover-noise.dat: rho, method (0 noise model, 1 batch means),
# runs, named, covered, other terms named, power, coverage (NaN: none named).
set terminal svg size 960,460 fixed font 'sans,16' background '#ffffff'
set output 'discover-noise.svg'
set datafile missing 'NaN'
set multiplot layout 1,2 title "A drift concealed in %(seeds)d synthetic records of %(rows)d rows per colour, found by foldest discover" font 'sans,17'
set xlabel "lag-one correlation {/:Italic ρ} of the AR(1) noise (0: white)"
set xrange [-0.1:1.0]
set xtics (%(xtics)s)
set ytics 0.2
set grid ytics lc rgb '#dddddd'
set style line 1 lc rgb '#1f5fa8' lw 2.5 pt 7 ps 1.2
set style line 2 lc rgb '#c0392b' lw 2.5 pt 5 ps 1.2 dt 2
set yrange [-0.06:1.14]
set title 'Power: the drift is named'
set ylabel 'fraction of the records'
set key top right box opaque font 'sans,14' samplen 2
plot 'discover-noise.dat' u 1:($2==0?$7:NaN) w lp ls 1 t 'noise model', \
     '' u 1:($2==1?$7:NaN) w lp ls 2 t 'batch means', \
     '' u 1:($2==0?$7:NaN):(sprintf('%%d/%%d',$4,$3)) w labels offset -1.2,0.9 tc rgb '#1f5fa8' font 'sans,12' notitle, \
     '' u 1:($2==1?$7:NaN):(sprintf('%%d/%%d',$4,$3)) w labels offset 1.2,-0.9 tc rgb '#c0392b' font 'sans,12' notitle
set title 'Coverage: the 95 %% interval holds the truth'
set ylabel 'fraction of the intervals given'
set key bottom left
plot 0.95 w l lc rgb '#555555' dt 3 lw 1.5 t 'nominal 0.95', \
     'discover-noise.dat' u 1:($2==0?$8:NaN) w lp ls 1 notitle, \
     '' u 1:($2==1?$8:NaN) w lp ls 2 notitle, \
     '' u 1:($2==0?$8:NaN):(sprintf('%%d/%%d',$5,$4)) w labels offset -1.2,0.9 tc rgb '#1f5fa8' font 'sans,12' notitle, \
     '' u 1:($2==1?$8:NaN):(sprintf('%%d/%%d',$5,$4)) w labels offset 1.2,-0.9 tc rgb '#c0392b' font 'sans,12' notitle
unset multiplot
"""


def main(argv):
    if len(argv) != 2:
        sys.stderr.write("usage: discover_noise.py OUTDIR\n")
        return 2
    outdir = argv[1]
    os.makedirs(outdir, exist_ok=True)
    start = time.time()
    tmp = tempfile.mkdtemp(prefix="foldest-figure-")
    try:
        with ThreadPoolExecutor(max_workers=2) as pool:
            results = list(pool.map(lambda a: one_case(tmp, *a),
                                    [(rho, s) for rho in RHOS for s in range(1, SEEDS + 1)]))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    lines = ["# rho method runs named covered others power coverage"
             "  (method 0: noise model, 1: batch means; %s, %d rows, seeds 1..%d)" % (EFFECT, ROWS, SEEDS)]
    for rho in RHOS:
        for m, (method, _, label) in enumerate(METHODS):
            rs = [out[method] for r, out in results if r == rho]
            n, named = len(rs), sum(x[0] for x in rs)
            covered, others = sum(x[1] for x in rs), sum(x[2] for x in rs)
            power = named / n
            coverage = covered / named if named else float("nan")
            lines.append("%g %d %d %d %d %d %.4f %s" % (rho, m, n, named, covered, others, power,
                                                          "NaN" if named == 0 else "%.4f" % coverage))
            print("discover-noise: rho %-4g %-28s named %2d/%d, covered %2d/%d, other terms %d"
                  % (rho, label, named, n, covered, named, others))
    with open(os.path.join(outdir, "discover-noise.dat"), "w") as f:
        f.write("\n".join(lines) + "\n")
    with open(os.path.join(outdir, "discover-noise.gp"), "w") as f:
        f.write(GNUPLOT % {"seeds": SEEDS, "rows": ROWS,
                           "xtics": ", ".join("'%g' %g" % (r, r) for r in RHOS)})
    run_gp = subprocess.run(["gnuplot", "discover-noise.gp"], cwd=outdir, capture_output=True, text=True)
    if run_gp.returncode != 0:
        sys.stderr.write(run_gp.stderr)
        return 1
    print("discover-noise: %d pairs, %d analyses in %.1f s -> %s" % (
        len(results), 2 * len(results), time.time() - start, os.path.join(outdir, "discover-noise.svg")))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
