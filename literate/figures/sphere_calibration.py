#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The sphere chapter's figures: magnetometer samples before and after
`foldest calibrate --model ellipsoid`, raw against calibrated.

Used as: python3 literate/figures/sphere_calibration.py OUTDIR
  (make doc runs it; FOLDEST names the command, default build/bin/foldest;
   FOLDEST_DATA the real recordings, default ../shared/data)

Two cases, one figure each:

- sphere-synthetic: a magnetometer this script makes up (seed 4): 20000
  field directions uniform on the sphere, a field of 1100 counts, soft iron
  S (a symmetric matrix with axes about 0.66, 1.0 and 1.45, cross terms up
  to 0.04), hard iron b = (6000, 250, 3500) counts and normal noise of 3
  counts on each axis: x = b + 1100 S u + noise.
- sphere-qmc5883l: the QMC5883L recording of ../shared/data
  (qmc5883l_tomisuarez/filtered_raw_data.csv), when it is there; when it is
  not, the figure says so (and this script too) instead of a plot.

For each, `foldest calibrate --model ellipsoid --json --apply CAL.csv` fits
the offset b and the matrix M and writes the calibrated samples R M (x - b)
(R the fitted field); `foldest calibrate --model sphere --json` gives the
best sphere's RMS error for comparison.  The figure shows two thin slices
of the samples, those within 0.08 of the calibrated plane z = 0 (drawn in
x-y) and of y = 0 (drawn in x-z): raw, about the fitted centre and divided
by the fitted field, (x - b) / R, and calibrated, M (x - b), both in units
of the field, with the unit circle.  Raw samples lie on a tilted ellipse,
calibrated ones on the circle.

Writes OUTDIR/NAME.dat, NAME.gp (gnuplot NAME.gp in OUTDIR redraws) and
NAME.svg.  Standard library only; the fit is foldest's, this script draws.
"""
import csv
import json
import math
import os
import random
import shutil
import subprocess
import sys
import tempfile
import time

FOLDEST = os.environ.get("FOLDEST", "build/bin/foldest")
DATA = os.environ.get("FOLDEST_DATA", "../shared/data")
SLAB = 0.08          # half-thickness of a slice, in units of the field
MAX_POINTS = 700     # per slice and state, so that the SVG stays small


def synthesise(path, n=20000, seed=4):
    """Write n samples of the made-up magnetometer to path (mx,my,mz)."""
    g = random.Random(seed)
    S = [[0.66, 0.02, 0.01], [0.02, 1.0, 0.04], [0.01, 0.04, 1.45]]
    b = [6000.0, 250.0, 3500.0]
    with open(path, "w") as f:
        f.write("mx,my,mz\n")
        for _ in range(n):
            u = [g.gauss(0, 1) for _ in range(3)]
            norm = math.sqrt(sum(v * v for v in u))
            u = [v / norm for v in u]
            x = [b[r] + 1100.0 * sum(S[r][c] * u[c] for c in range(3)) + 3.0 * g.gauss(0, 1)
                 for r in range(3)]
            f.write("%.3f,%.3f,%.3f\n" % tuple(x))


def calibrate(model, path, extra=()):
    r = subprocess.run([FOLDEST, "calibrate", "--model", model, "--json"] + list(extra) + [path],
                       capture_output=True, text=True, check=False)
    if r.returncode != 0:
        raise RuntimeError("foldest calibrate --model %s %s: exit %d\n%s%s"
                           % (model, path, r.returncode, r.stdout, r.stderr))
    return json.loads(r.stdout)


def read_table(path):
    """Rows of three numbers after the header line (the first line whose
    first field is not a number and has three fields)."""
    rows = []
    with open(path) as f:
        header = False
        for rec in csv.reader(f):
            if not header:
                header = len(rec) == 3
                continue
            rows.append([float(v) for v in rec])
    return rows


GNUPLOT = r"""# Made by literate/figures/sphere_calibration.py; redraw with: gnuplot %(name)s.gp
# Columns of %(name)s.dat: slice (0: |z| < %(slab)g, drawn x-y; 1: |y| < %(slab)g, drawn x-z),
# raw (x - b)/R (three columns), calibrated M (x - b) (three columns).
set terminal svg size 960,600 fixed font 'sans,16' background '#ffffff'
set output '%(name)s.svg'
set multiplot layout 1,2 title "%(title)s" font 'sans,17'
set bmargin 6
set size ratio -1
set xrange [-1.6:1.6]
set yrange [-1.6:1.6]
set xtics 0.5
set ytics 0.5
set grid lc rgb '#e4e4e4'
set key at screen 0.5,0.02 center bottom horizontal maxrows 1 box width 1 font 'sans,14' samplen 1.5
set parametric
set trange [0:2*pi]
set samples 200
set title "slice |z| < %(slab)g, the x-y plane"
set xlabel 'x / field'
set ylabel 'y / field'
plot '%(name)s.dat' u ($1==0?$2:NaN):3 w p pt 7 ps 0.3 lc rgb '#c0392b' notitle, \
     '' u ($1==0?$5:NaN):6 w p pt 7 ps 0.3 lc rgb '#1f5fa8' notitle, \
     cos(t), sin(t) w l lc rgb '#222222' lw 1 dt 2 t 'unit circle', \
     NaN, NaN w p pt 7 ps 1 lc rgb '#c0392b' t 'raw (x - b) / R', \
     NaN, NaN w p pt 7 ps 1 lc rgb '#1f5fa8' t 'calibrated M (x - b)'
set title "slice |y| < %(slab)g, the x-z plane"
unset key
set xlabel 'x / field'
set ylabel 'z / field'
plot '%(name)s.dat' u ($1==1?$2:NaN):4 w p pt 7 ps 0.3 lc rgb '#c0392b' notitle, \
     '' u ($1==1?$5:NaN):7 w p pt 7 ps 0.3 lc rgb '#1f5fa8' notitle, \
     cos(t), sin(t) w l lc rgb '#222222' lw 1 dt 2 t 'unit circle', \
     NaN, NaN w p pt 7 ps 1 lc rgb '#c0392b' t 'raw (x - b) / R', \
     NaN, NaN w p pt 7 ps 1 lc rgb '#1f5fa8' t 'calibrated M (x - b)'
unset multiplot
"""

ABSENT = r"""# Made by literate/figures/sphere_calibration.py: the recording was absent.
set terminal svg size 960,160 fixed font 'sans,14' background '#ffffff'
set output '%(name)s.svg'
unset border
unset tics
unset key
set xrange [0:1]
set yrange [0:1]
set label 1 "%(message)s" at 0.5,0.5 center noenhanced
plot NaN
"""


def gnuplot(outdir, name, script):
    with open(os.path.join(outdir, name + ".gp"), "w") as f:
        f.write(script)
    r = subprocess.run(["gnuplot", name + ".gp"], cwd=outdir, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError("gnuplot %s.gp: %s" % (name, r.stderr))


def figure(outdir, name, raw_path, what, tmp):
    """Calibrate raw_path, write NAME.dat and NAME.svg; what names the data."""
    cal_path = os.path.join(tmp, name + "-cal.csv")
    sphere = calibrate("sphere", raw_path)
    ell = calibrate("ellipsoid", raw_path, ["--apply", cal_path])
    b, R = ell["offset"], ell["radius"]
    raw, cal = read_table(raw_path), read_table(cal_path)
    assert len(raw) == len(cal) == ell["n"], (len(raw), len(cal), ell["n"])
    slices = [[], []]
    for x, y in zip(raw, cal):
        y = [v / R for v in y]          # R M (x - b) / R: on the unit sphere
        for s, axis in ((0, 2), (1, 1)):
            if abs(y[axis]) < SLAB:
                slices[s].append([(x[i] - b[i]) / R for i in range(3)] + y)
    with open(os.path.join(outdir, name + ".dat"), "w") as f:
        for s, rows in enumerate(slices):
            step = max(1, math.ceil(len(rows) / MAX_POINTS))
            for r in rows[::step]:
                f.write("%d %s\n" % (s, " ".join("%.5f" % v for v in r)))
    title = ("%s, %d samples\\nRMS error: best sphere %.1f %% of the field, "
             "ellipsoid %.2f %%" % (what, ell["n"], sphere["rms_percent"], ell["rms_percent"]))
    gnuplot(outdir, name, GNUPLOT % {"name": name, "slab": SLAB, "title": title})
    print("%s: %d samples, sphere %.2f %%, ellipsoid %.3f %%, offset (%.1f, %.1f, %.1f), field %.1f "
          "-> %s" % (name, ell["n"], sphere["rms_percent"], ell["rms_percent"], b[0], b[1], b[2], R,
                     os.path.join(outdir, name + ".svg")))


def main(argv):
    if len(argv) != 2:
        sys.stderr.write("usage: sphere_calibration.py OUTDIR\n")
        return 2
    outdir = argv[1]
    os.makedirs(outdir, exist_ok=True)
    start = time.time()
    tmp = tempfile.mkdtemp(prefix="foldest-figure-")
    try:
        raw = os.path.join(tmp, "synthetic.csv")
        synthesise(raw)
        figure(outdir, "sphere-synthetic", raw, "Synthetic magnetometer (seed 4)", tmp)
        qmc = os.path.join(DATA, "qmc5883l_tomisuarez", "filtered_raw_data.csv")
        if os.path.exists(qmc):
            figure(outdir, "sphere-qmc5883l", qmc, "QMC5883L recording", tmp)
        else:
            message = ("Skipped: the QMC5883L recording is not on the machine that wove this page\\n"
                       "(looked for %s; set FOLDEST_DATA)" % qmc)
            gnuplot(outdir, "sphere-qmc5883l", ABSENT % {"name": "sphere-qmc5883l", "message": message})
            print("sphere-qmc5883l: skipped, %s is absent (a figure saying so is drawn)" % qmc)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print("sphere figures: %.1f s" % (time.time() - start))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
