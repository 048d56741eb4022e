#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The acceptance suite of `foldest discover` (make accept).

Every case of tests/accept/gen.c (an independent generator) over SEEDS seeds,
analysed by `foldest discover ... --json`, once with the default noise model
and once with `--noise batch` when the command has that option; then the
real recordings (free-fall drops, magnetometer spheres); then the dynamics
section: every case of tests/accept/gen_dyn.c (output error, the hidden
effect inside the K-th derivative) over SEEDS seeds, with its `--order K`
and without it (today's additive mode).  Python 3 standard library only.
See tests/accept/README.md.

    run.py              everything (make accept)
    run.py --dynamics   the dynamics section only (make accept-dynamics)
    run.py --static     everything but the dynamics section

Environment: SEEDS (default 20), SEED0 (the first seed, default 0), QUICK=1 (3 seeds), JOBS (at most 2),
ACCEPT_MODES (the noise modes of the static section to run, e.g. default),
FOLDEST (build/bin/foldest), GEN (build/accept/gen), GEN_DYN
(build/accept/gen_dyn), ACCEPT_OUT (build/accept/runs), FOLDEST_DATA
(../shared/data), KEEP=1 keeps the files.  Results: ACCEPT_OUT/results.json,
{"static": [...], "dynamics": [...]} (a run of one section keeps the other's).
"""
import json
import os
import shlex
import shutil
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor

from pairs import generate

FOLDEST = os.environ.get("FOLDEST", "build/bin/foldest")
GEN = os.environ.get("GEN", "build/accept/gen")
GEN_DYN = os.environ.get("GEN_DYN", "build/accept/gen_dyn")
OUT = os.environ.get("ACCEPT_OUT", "build/accept/runs")
DATA = os.environ.get("FOLDEST_DATA", "../shared/data")
QUICK = os.environ.get("QUICK", "") not in ("", "0")
SEEDS = int(os.environ.get("SEEDS", "3" if QUICK else "20"))
SEED0 = int(os.environ.get("SEED0", "0"))   # the first seed: SEED0 .. SEED0 + SEEDS - 1
JOBS = max(1, min(2, int(os.environ.get("JOBS", "2"))))
KEEP = os.environ.get("KEEP", "") not in ("", "0")

TARGETS = {"first": (">=", 0.97), "fd": ("<=", 0.05), "cover": (">=", 0.93),
           "heldout": (">=", 0.97), "honest": (">=", 0.8)}
DYN_TARGETS = {"first": (">=", 0.95), "fd": ("<=", 0.05), "cover": (">=", 0.90),
               "heldout": (">=", 0.95), "honest": (">=", 0.8)}


def discover_help():
    r = subprocess.run([FOLDEST, "discover", "--help"], capture_output=True, text=True)
    return r.stdout + r.stderr


MODES = [("default", [])]
if "--noise" in discover_help():
    MODES.append(("batch", ["--noise", "batch"]))
if os.environ.get("ACCEPT_MODES"):      # e.g. ACCEPT_MODES=default: one column only
    MODES = [m for m in MODES if m[0] in os.environ["ACCEPT_MODES"].split(",")]


def discover(args):
    """Run foldest with args + --json; return (exit status, parsed JSON or None, seconds)."""
    t0 = time.time()
    r = subprocess.run([FOLDEST] + args + ["--json"], capture_output=True, text=True)
    try:
        js = json.loads(r.stdout) if r.stdout.strip() else None
    except json.JSONDecodeError:
        js = None
    return r.returncode, js, time.time() - t0


def score(truth, js, rc):
    """The metrics of one run, from the truth and discover's JSON."""
    s = {"rc": rc}
    if js is None or rc != 0:
        js = {"verdict": "error (exit %d)" % rc, "discovered": [],
              "baseline": {"heldout_rms": 0}, "final": {"heldout_rms": 0}}
    found = js.get("discovered", [])
    names = [d["name"] for d in found]
    s["verdict"] = js.get("verdict")
    s["named"] = names
    s["heldout_rms"] = [js["baseline"].get("heldout_rms"), js["final"].get("heldout_rms")]
    fam = truth["family"]
    if truth["truth"]:
        tnames = [t["name"] for t in truth["truth"]]
        s["first"] = bool(names) and names[0] in tnames
        s["all"] = all(n in names for n in tnames)
        cov = []
        for t in truth["truth"]:
            d = next((d for d in found if d["name"] == t["name"]), None)
            lo, hi = (d["interval95"] if d else (1, 0))
            cov.append(lo <= t["coefficient"] <= hi)
        s["cover"] = cov
        b, f = js["baseline"].get("heldout_rms"), js["final"].get("heldout_rms")
        s["heldout"] = b is not None and f is not None and f < b
    if fam == "null":
        s["fd"] = bool(names)
    if fam == "outside":
        s["honest"] = js.get("verdict") != "mismatch explained"
    return s


def one_case(case, seed):
    d = os.path.join(OUT, "%s.%d" % (case, seed))
    args, truth, _ = generate(GEN, case, seed, d)
    res = {}
    for mode, extra in MODES:
        rc, js, sec = discover(args + extra)
        res[mode] = score(truth, js, rc)
        res[mode]["seconds"] = sec
    if not KEEP:
        shutil.rmtree(d, ignore_errors=True)
    return {"truth": truth, "args": args, "res": res}


# ---------------------------------------------------------------- tables

def frac(vals):
    vals = [bool(v) for v in vals]
    return (sum(vals), len(vals))


def cell(k, n):
    return "%4.2f %4s" % (k / n, "%d/%d" % (k, n)) if n else "   -     "


def metrics(runs, mode):
    """first, all, coverage, held-out gain, false discovery, honest: (k, n) each."""
    m = {}
    ts = [r["res"][mode] for r in runs if r["truth"]["truth"]]
    m["first"] = frac(s["first"] for s in ts)
    m["all"] = frac(s["all"] for s in ts)
    m["cover"] = frac(c for s in ts for c in s["cover"])
    m["heldout"] = frac(s["heldout"] for s in ts)
    m["fd"] = frac(r["res"][mode]["fd"] for r in runs if "fd" in r["res"][mode])
    m["honest"] = frac(r["res"][mode]["honest"] for r in runs if "honest" in r["res"][mode])
    return m


COLS = [("first", "first named"), ("all", "all named"), ("cover", "coverage"),
        ("heldout", "held-out gain"), ("fd", "false disc."), ("honest", "honest")]


def header(title, modes=None, targets=None):
    modes, targets = modes or MODES, targets or TARGETS
    print("\n" + title)
    w = 10 * len(modes)
    line = "%-34s" % ""
    for _, lab in COLS:
        line += " | %-*s" % (w, lab)
    print(line)
    line = "%-34s" % "target"
    for key, _ in COLS:
        t = targets.get(key)
        line += " | %-*s" % (w, "%s %.2f" % t if t else "")
    print(line)
    line = "%-34s" % "group (runs)"
    for _ in COLS:
        line += " | " + " ".join("%-9s" % m for m, _ in modes)
    print(line)


def row(label, runs, modes=None):
    modes = modes or MODES
    if not runs:
        return
    ms = {mode: metrics(runs, mode) for mode, _ in modes}
    line = "%-34s" % ("%s (%d)" % (label, len(runs)))
    for key, _ in COLS:
        line += " | " + " ".join("%-9s" % cell(*ms[mode][key]).split()[0] if ms[mode][key][1] else "%-9s" % "-"
                                 for mode, _ in modes)
    print(line)


def row_counts(label, runs, modes=None):
    """The same row with counts (k/n) for every mode."""
    modes = modes or MODES
    if not runs:
        return
    ms = {mode: metrics(runs, mode) for mode, _ in modes}
    line = "%-34s" % ("  counts, %s" % label)
    for key, _ in COLS:
        line += " | " + " ".join("%-9s" % ("%d/%d" % ms[mode][key] if ms[mode][key][1] else "-")
                                 for mode, _ in modes)
    print(line)


def passes(m, targets=None):
    ok = True
    for key, (op, t) in (targets or TARGETS).items():
        k, n = m[key]
        if n == 0:
            continue
        v = k / n
        ok &= v >= t if op == ">=" else v <= t
    return ok


def group_by(runs, key):
    out = {}
    for r in runs:
        out.setdefault(key(r), []).append(r)
    return out


def print_tables(runs):
    ident = [r for r in runs if r["truth"]["identifiable"]]
    nonid = [r for r in runs if not r["truth"]["identifiable"]]
    header("== Generated cases: %d runs (%d seeds); hidden-term metrics over draws identifiable by design "
           "(true-GLS |z| >= 8, competitor clearly worse); values: %s"
           % (len(runs), SEEDS, " | ".join(m for m, _ in MODES)))
    row("OVERALL", ident)
    row_counts("OVERALL", ident)
    for fam, rs in sorted(group_by(ident, lambda r: r["truth"]["family"]).items()):
        row("family " + fam, rs)
    for title, key in (("case", "case"), ("noise", "noise"), ("length (rows)", "rows"),
                       ("clock", "clock"), ("rig", "rig")):
        print("-- per " + title)
        for c, rs in sorted(group_by(ident, lambda r, k=key: r["truth"][k]).items()):
            row(str(c), rs)
    print("-- draws NOT identifiable by design (the concealment limit of 0.3 sd per sample forbids "
          "|z| >= 8): not counted above")
    row("not identifiable", nonid)
    for c, rs in sorted(group_by(nonid, lambda r: r["truth"]["rows"]).items()):
        row("  rows %s" % c, rs)
    for mode, _ in MODES:
        m = metrics(ident, mode)
        print("verdict (%s): %s" % (mode, "PASS" if passes(m) else "FAIL"))
    errs = sum(1 for r in runs for mode, _ in MODES if r["res"][mode]["rc"] != 0)
    if errs:
        print("discover exited non-zero in %d runs (counted as misses)" % errs)


# ---------------------------------------------------------------- real recordings

def real_recordings():
    print("\n== Real recordings")
    ff = os.path.join(DATA, "freefall-drag", "csv")
    simgen = os.path.join(os.path.dirname(FOLDEST), "..", "examples", "freefall_sim")
    lines = []
    if not os.path.isfile(os.path.join(ff, "fall_1.csv")) or not os.path.exists(simgen):
        print("free-fall drops: no recordings at %s (set FOLDEST_DATA) or no %s: SKIPPED" % (ff, simgen))
    else:
        simdir = os.path.join(OUT, "freefall")
        r = subprocess.run([simgen, ff, simdir], capture_output=True, text=True)
        cmd = shlex.split(r.stdout.strip().splitlines()[-1])[2:]
        pairs, rest, i = [], [], 0
        while i < len(cmd):
            if cmd[i] == "--real":
                pairs.append((cmd[i + 1], cmd[i + 3]))
                i += 4
            else:
                rest.append(cmd[i])
                i += 1
        print("acceptance: quadratic_drag named (bias may come first), k = -coefficient in "
              "[0.010, 0.030] 1/m, no further term")
        print("%-22s %-9s %-8s %-52s" % ("recording", "mode", "result", "named (coefficient)"))
        jobs = [("fall_%d" % (n + 1), ["--real", a, "--sim", b]) for n, (a, b) in enumerate(pairs)]
        jobs.append(("all %d drops together" % len(pairs), [x for a, b in pairs for x in ("--real", a, "--sim", b)]))
        for name, pr in jobs:
            for mode, extra in MODES:
                rc, js, _ = discover(["discover"] + pr + rest + extra)
                found = js.get("discovered", []) if js else []
                names = [d["name"] for d in found if d["name"] != "bias"]
                q = next((d for d in found if d["name"] == "quadratic_drag"), None)
                ok = rc == 0 and names == ["quadratic_drag"] and 0.010 <= -q["coefficient"] <= 0.030
                desc = ", ".join("%s (%.4g)" % (d["name"], d["coefficient"]) for d in found) or \
                    (js or {}).get("verdict", "exit %d" % rc)
                print("%-22s %-9s %-8s %s" % (name, mode, "pass" if ok else "FAIL", desc))
                lines.append(ok)
    sph = [("qmc5883l", ["--sphere", os.path.join(DATA, "qmc5883l_tomisuarez", "filtered_raw_data.csv")],
            ["axis_gain", "cross_axis"]),
           ("ck_explorer", ["--sphere", os.path.join(DATA, "ck_explorer_accmag", "acc_mag_log.csv"),
                            "--columns", "mx,my,mz"], ["cross_axis", "axis_gain"]),
           ("x-IMU3", ["--sphere", os.path.join(DATA, "ximu3_fusion", "sensor_data.csv"), "--columns",
                       "Magnetometer X,Magnetometer Y,Magnetometer Z"], None)]
    print("%-22s %-9s %-8s %s" % ("sphere recording", "expected", "result", "named / verdict"))
    for name, args, want in sph:
        if not os.path.isfile(args[1]):
            print("%-22s SKIPPED: no %s" % (name, args[1]))
            continue
        rc, js, _ = discover(["discover"] + args)
        got = [d["name"] for d in js.get("discovered", [])] if js else []
        if want is None:
            ok = rc == 1 and js is not None and js.get("verdict") == "refused"
            exp = "refused"
            desc = (js or {}).get("verdict", "exit %d" % rc)
        else:
            ok = rc == 0 and got == want
            exp = " then ".join(want)
            desc = ", ".join(got) or (js or {}).get("verdict", "exit %d" % rc)
        print("%-22s %-9s %-8s %s" % (name, exp[:9], "pass" if ok else "FAIL", desc))
        lines.append(ok)
    if lines:
        print("real recordings: %d of %d pass" % (sum(lines), len(lines)))


# ---------------------------------------------------------------- dynamics (output error)

def dyn_modes():
    """("order", as generated) and ("additive", the --order K pair removed);
    the additive one alone when the command does not know --order."""
    if "--order" in discover_help():
        return [("order", None), ("additive", "drop")], True
    return [("additive", "drop")], False


def drop_order(args):
    out, i = [], 0
    while i < len(args):
        if args[i] == "--order":
            i += 2
        elif args[i].startswith("--order="):
            i += 1
        else:
            out.append(args[i])
            i += 1
    return out


def one_dyn_case(case, seed, modes):
    d = os.path.join(OUT, "dyn.%s.%d" % (case, seed))
    args, truth, gen_sec = generate(GEN_DYN, case, seed, d)
    res = {}
    for mode, how in modes:
        a = drop_order(args) if how == "drop" else args
        rc, js, sec = discover(a)
        res[mode] = score(truth, js, rc)
        res[mode]["seconds"] = sec
        if js is not None:
            res[mode]["found"] = [{k: x.get(k) for k in ("name", "coefficient", "interval95")}
                                  for x in js.get("discovered", [])]
    if not KEEP:
        shutil.rmtree(d, ignore_errors=True)
    return {"truth": truth, "args": args, "res": res, "gen_seconds": gen_sec}


def print_dyn_tables(runs, modes, has_order):
    ident = [r for r in runs if r["truth"]["identifiable"]]
    nonid = [r for r in runs if not r["truth"]["identifiable"]]
    note = "" if has_order else " -- `foldest discover` has no --order yet: ADDITIVE COLUMN ONLY"
    header("== Dynamics (output error, gen_dyn): %d runs (%d seeds); hidden-term metrics over draws "
           "identifiable by design (true-GLS |z| >= 8 on the output signature with an offset, "
           "competitor clearly worse); values: %s%s"
           % (len(runs), SEEDS, " | ".join(m for m, _ in modes), note), modes, DYN_TARGETS)
    row("OVERALL", ident, modes)
    row_counts("OVERALL", ident, modes)
    for fam, rs in sorted(group_by(ident, lambda r: r["truth"]["family"]).items()):
        row("family " + fam, rs, modes)
    for title, key in (("case", "case"), ("rig", "rig"), ("noise", "noise"), ("length (rows)", "rows"),
                       ("clock", "clock")):
        print("-- per " + title)
        for c, rs in sorted(group_by(ident, lambda r, k=key: r["truth"][k]).items()):
            row(str(c), rs, modes)
    print("-- draws NOT identifiable by design (|z| >= 8 and the competitor gap not reached at a "
          "parting of 10 sds): not counted above")
    row("not identifiable", nonid, modes)
    for c, rs in sorted(group_by(nonid, lambda r: r["truth"]["case"]).items()):
        row("  " + c, rs, modes)
    for mode, _ in modes:
        m = metrics(ident, mode)
        secs = [r["res"][mode]["seconds"] for r in runs]
        print("verdict (%s): %s; discover %.2f s a run on average, %.2f s at most"
              % (mode, "PASS" if passes(m, DYN_TARGETS) else "FAIL", sum(secs) / len(secs), max(secs)))
    gs = [r["gen_seconds"] for r in runs]
    print("gen_dyn: %.2f s a case on average, %.2f s at most" % (sum(gs) / len(gs), max(gs)))
    errs = sum(1 for r in runs for mode, _ in modes if r["res"][mode]["rc"] != 0)
    if errs:
        print("discover exited non-zero in %d runs (counted as misses)" % errs)


def dynamics():
    try:
        os.nice(10)   # the machine is shared
    except OSError:
        pass
    modes, has_order = dyn_modes()
    cases = [l.split()[0] for l in subprocess.run([GEN_DYN, "--list"], capture_output=True, text=True,
                                                  check=True).stdout.splitlines()]
    tasks = [(c, s) for s in range(SEED0, SEED0 + SEEDS) for c in cases]
    print("\nfoldest discover dynamics acceptance: %d cases x %d seeds, modes: %s, %d workers"
          % (len(cases), SEEDS, ", ".join(m for m, _ in modes), JOBS))
    t0 = time.time()
    runs = []
    with ThreadPoolExecutor(max_workers=JOBS) as ex:
        futs = [ex.submit(one_dyn_case, c, s, modes) for c, s in tasks]
        for i, f in enumerate(futs):
            runs.append(f.result())
            sys.stderr.write("\r[accept dynamics] %d/%d cases done (%.0f s)   "
                             % (i + 1, len(tasks), time.time() - t0))
            sys.stderr.flush()
    sys.stderr.write("\n")
    print_dyn_tables(runs, modes, has_order)
    print("dynamics: %.0f s" % (time.time() - t0))
    return runs


def save(key, runs):
    path = os.path.join(OUT, "results.json")
    data = {}
    try:
        with open(path) as f:
            old = json.load(f)
        data = old if isinstance(old, dict) else {"static": old}
    except (OSError, ValueError):
        pass
    data[key] = runs
    with open(path, "w") as f:
        json.dump(data, f)


def user_terms_table():
    """The outside_cogging cases with and without the right --term (user_terms.py)."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import user_terms
    user_terms.user_term_cases(FOLDEST, GEN, OUT, SEEDS, KEEP, MODES)


def main():
    os.makedirs(OUT, exist_ok=True)
    if "--dynamics" in sys.argv[1:]:
        save("dynamics", dynamics())
        print("\nper-run results: %s (key dynamics)" % os.path.join(OUT, "results.json"))
        return
    cases = [l.split()[0] for l in subprocess.run([GEN, "--list"], capture_output=True, text=True,
                                                  check=True).stdout.splitlines()]
    tasks = [(c, s) for s in range(SEED0, SEED0 + SEEDS) for c in cases]
    print("foldest discover acceptance: %d cases x %d seeds, modes: %s, %d workers"
          % (len(cases), SEEDS, ", ".join(m if not e else " ".join(e) for m, e in MODES), JOBS))
    t0 = time.time()
    runs = []
    with ThreadPoolExecutor(max_workers=JOBS) as ex:
        futs = [ex.submit(one_case, c, s) for c, s in tasks]
        for i, f in enumerate(futs):
            runs.append(f.result())
            sys.stderr.write("\r[accept] %d/%d cases done (%.0f s)   " % (i + 1, len(tasks), time.time() - t0))
            sys.stderr.flush()
    sys.stderr.write("\n")
    save("static", runs)
    print_tables(runs)
    real_recordings()
    user_terms_table()
    if "--static" in sys.argv[1:]:
        print("\nper-run results: %s (key static); %.0f s"
              % (os.path.join(OUT, "results.json"), time.time() - t0))
        return
    save("dynamics", dynamics())
    print("\nper-run results: %s (keys static, dynamics); %.0f s"
          % (os.path.join(OUT, "results.json"), time.time() - t0))


if __name__ == "__main__":
    main()
