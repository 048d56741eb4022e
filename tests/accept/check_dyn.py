#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""An independent check of gen_dyn's truth (Python standard library only).

    gen_dyn --case NAME --seed S --out DIR --quiet-noise
    python3 tests/accept/check_dyn.py DIR [SUBSTEPS]

Reads DIR/sim.csv, DIR/real.csv and DIR/truth.json and integrates the real
system again, here, from the files alone plus the rig's parameters written
in truth.json: the input and ambient columns (held or interpolated as the
truth says), the hidden terms evaluated from the conventions of README.md
on the real states, the coefficient converted from the time column's unit
(t_ms: 1e-3 s, t_min: 60 s, else seconds) to seconds, the velocity column
in units per time-column unit, coulomb's scale from the simulation's
velocity column at the recording's rows.  RK4 with
SUBSTEPS (default 16) a simulation step.  Prints the largest difference
between this trajectory and the recording (less the written offset) in
noise sds, and the parting; with --quiet-noise the difference must be far
below 1.  Only for cases with hidden terms or none (not the outside ones).
"""
import csv
import json
import math
import sys


def read(path):
    with open(path) as f:
        r = csv.reader(f)
        head = next(r)
        rows = [[float(x) for x in row] for row in r]
    return head, [list(c) for c in zip(*rows)]


def main():
    d = sys.argv[1]
    sub = int(sys.argv[2]) if len(sys.argv) > 2 else 16
    t = json.load(open(d + "/truth.json"))
    sh, sc = read(d + "/sim.csv")
    rh, rc = read(d + "/real.csv")
    ts, xs, cs2, us = sc           # time, channel, velocity or ambient, input
    tr, yr = rc
    unit = {"t_ms": 1e-3, "t_min": 60.0}.get(sh[0], 1.0)
    K = t["order"]
    p = t["rig_parameters"]
    rig = t["rig"]
    hold = t["input_hold"]
    kelvin = sh[1].endswith("_K")
    # seconds from the first row (the epoch subtracted exactly in both files)
    t0 = ts[0]
    taus = [(x - t0) * unit for x in ts]
    taur = [(x - t0) * unit for x in tr]

    def interp(tt, grid, val):
        # linear interpolation (grid regular or not), by bisection
        lo, hi = 0, len(grid) - 1
        if tt <= grid[0]:
            return val[0]
        if tt >= grid[-1]:
            return val[-1]
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if grid[mid] <= tt:
                lo = mid
            else:
                hi = mid
        lam = (tt - grid[lo]) / (grid[hi] - grid[lo])
        return val[lo] + lam * (val[hi] - val[lo])

    if K == 2:
        vmax = max(abs(interp(x, taus, cs2)) for x in taur)
    terms = [(h["name"], h["coefficient"] / unit ** K) for h in t["truth"]]

    def term(name, x, v, u, ta, tau):
        # x, u, ta as in the columns, v per second, tau seconds from the start
        if name == "bias":
            return 1.0
        if name == "drift":
            return tau / unit
        if name == "viscous_friction":
            return v * unit
        if name == "quadratic_drag":
            return v * unit * abs(v * unit)
        if name == "coulomb_friction":
            return math.tanh(v * unit / (0.002 * vmax))
        if name == "linear_stiffness":
            return x
        if name == "cubic_stiffness":
            return x ** 3
        if name == "thermal_sensitivity":
            return x - xs[0]
        if name == "newton_cooling":
            return x - ta
        if name == "radiative_cooling":
            k = 0.0 if kelvin else 273.15
            return (x + k) ** 4 - (ta + k) ** 4
        if name == "input_gain":
            return u
        raise ValueError(name)

    def f(j, tau, s):
        h = taus[j + 1] - taus[j]
        lam = (tau - taus[j]) / h
        if hold == "zoh":
            u, du = us[j], 0.0
        else:
            du = (us[j + 1] - us[j]) / h
            u = us[j] + lam * (us[j + 1] - us[j])
        if K == 1:
            ta = cs2[j] + lam * (cs2[j + 1] - cs2[j])
            extra = sum(a * term(n, s[0], 0, u, ta, tau) for n, a in terms)
            return [(p["G"] * u - (s[0] - ta)) / p["tau_th"] + extra]
        x, v = s
        extra = sum(a * term(n, x, v, u, 0, tau) for n, a in terms)
        if rig == "cart":
            acc = u * p["inv_m"] - p["c_m"] * v
        elif rig == "msd_force":
            acc = u * p["inv_m"] - p["c_m"] * v - p["k_m"] * x
        elif rig == "msd_shaker":
            acc = -p["c_m"] * (v - du) - p["k_m"] * (x - u)
        else:
            acc = u * p["inv_m"] - p["c_m"] * v - p["w2"] * math.sin(x)
        return [v, acc + extra]

    def rk4(j, tau, s, h):
        k1 = f(j, tau, s)
        k2 = f(j, tau + h / 2, [a + h / 2 * b for a, b in zip(s, k1)])
        k3 = f(j, tau + h / 2, [a + h / 2 * b for a, b in zip(s, k2)])
        k4 = f(j, tau + h, [a + h * b for a, b in zip(s, k3)])
        return [a + h / 6 * (b + 2 * c + 2 * e + g) for a, b, c, e, g in zip(s, k1, k2, k3, k4)]

    s = [p["x0"], p["v0"]] if K == 2 else [p["x0"]]
    out = []
    i = 0   # next recording row
    for j in range(len(taus) - 1):
        # the interval's own stops: its start, the recording rows inside, its end
        stops = [taus[j]]
        while i < len(taur) and taur[i] < taus[j + 1] - 1e-12:
            if taur[i] > taus[j] + 1e-12:
                stops.append(taur[i])
            i += 1
        stops.append(taus[j + 1])
        tau = taus[j]
        for st in stops[1:]:
            h = (st - tau) / sub
            for _ in range(sub):
                s = rk4(j, tau, s, h)
                tau += h
            tau = st
            out.append((st, s[0]))
        if j == 0:
            out.insert(0, (taus[0], p["x0"]))
    worst, part = 0.0, 0.0
    # the trajectory at the recording's rows: every row is a stop
    pos = {round(o[0], 9): o[1] for o in out}
    ot, ox = [o[0] for o in out], [o[1] for o in out]
    for a, y in zip(taur, yr):
        x = pos.get(round(a, 9))
        if x is None:
            x = interp(a, ot, ox)
        worst = max(worst, abs(y - t["offset"] - x))
        part = max(part, abs(x - interp(a, taus, xs)))
    print("%s seed %d (%s, %s, %s): |recording - offset - this integration| <= %.3g sd; "
          "parting here %.4g sd, truth %.4g sd"
          % (t["case"], t["seed"], rig, t["clock"], hold, worst / t["sigma"], part / t["sigma"],
             t["parting"]))


if __name__ == "__main__":
    main()
