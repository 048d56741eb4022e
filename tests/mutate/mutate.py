#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Mutation testing of the library (make mutate).

Generates single-point mutants of src/*.c from the code itself (no list of
mutants is written by hand), builds each one into the plain test binary and
runs the fast suites that exercise its module; a mutant is

  killed      a suite failed, crashed or ran out of time,
  survived    every suite passed,
  stillborn   it did not compile or link (counted apart, not as killed),
  identical   its object code equals the original's (the compiler proved it
              equivalent; counted apart, like stillborn ones),
  not run     it survived, but its line is in code compiled only for
              processors with AVX-512 (inside `#if defined(FE__LANES_X86)`,
              the eight-lane kernels and their dispatch) and this processor
              lacks avx512f (/proc/cpuinfo): no test here can run it
              (counted apart, like stillborn ones).

The kill rate is killed / (killed + survived), per module and overall, and
the survivors are listed with file:line and the change.  Python 3 standard
library only.  Usage: see `--help`, the Makefile's `mutate` target and
tests/mutate/README.md.
"""
import argparse
import json
import os
import random
import re
import shlex
import signal
import subprocess
import sys
import tempfile
import time

# ---------------------------------------------------------------- tokens
TOKEN = re.compile(r"""
    (?P<comment>/\*.*?\*/|//[^\n]*)
  | (?P<pp>^[ \t]*\#(?:[^\n\\]|\\.)*)
  | (?P<string>"(?:\\.|[^"\\\n])*"|'(?:\\.|[^'\\\n])*')
  | (?P<number>0[xX][0-9a-fA-F]+[uUlL]*
              |(?:\d+\.\d*|\.\d+|\d+)(?:[eE][+-]?\d+)?[uUlLfF]*)
  | (?P<ident>[A-Za-z_]\w*)
  | (?P<op>>>=|<<=|->|\+\+|--|<<|>>|<=|>=|==|!=|&&|\|\||\+=|-=|\*=|/=|%=|&=|\|=|\^=
          |[-+*/%<>=!&|^~?:;,.(){}\[\]])
  | (?P<space>\s+)
""", re.X | re.S | re.M)

TYPE_WORDS = {"void", "char", "short", "int", "long", "float", "double", "signed", "unsigned",
              "const", "volatile", "restrict", "struct", "union", "enum", "_Bool", "bool"}
KEYWORDS = {"return", "case", "sizeof", "if", "else", "while", "for", "do", "switch", "goto",
            "break", "continue", "default", "static", "typedef", "extern", "inline"}


class Tok:
    __slots__ = ("kind", "text", "start", "end", "line")

    def __init__(self, kind, text, start, end, line):
        self.kind, self.text, self.start, self.end, self.line = kind, text, start, end, line


def tokenize(src):
    """The significant tokens of a C file (no comments, strings kept as one
    token, preprocessor lines dropped), each with its offset and line."""
    toks, pos, line = [], 0, 1
    while pos < len(src):
        m = TOKEN.match(src, pos)
        if m is None:  # a character the lexer does not know: skip it
            pos += 1
            continue
        kind, text = m.lastgroup, m.group()
        if kind not in ("comment", "space", "pp"):
            toks.append(Tok(kind, text, m.start(), m.end(), line))
        line += text.count("\n")
        pos = m.end()
    return toks


def type_names(paths):
    """Names declared as types in the headers and sources (typedefs, struct
    tags), so that `fe_meanvar *a` is not read as a product."""
    names = set()
    for p in paths:
        with open(p, encoding="utf-8") as f:
            s = f.read()
        names.update(re.findall(r"\}\s*(\w+)\s*;", s))
        names.update(re.findall(r"typedef\s+[^;{()]*?\b(\w+)\s*;", s))
        names.update(re.findall(r"typedef\s+[^;{]*?\(\s*\*\s*(\w+)\s*\)", s))
        names.update(re.findall(r"\b(?:struct|union|enum)\s+(\w+)", s))
    return names


# ---------------------------------------------------------------- mutants
def is_type(t, types):
    return t.kind == "ident" and (t.text in TYPE_WORDS or t.text in types or t.text.endswith("_t"))


def is_operand_end(t, types):
    """Does token t end an operand (so that the next operator is binary)?"""
    if t is None:
        return False
    if t.kind == "number" or t.text in (")", "]"):
        return True
    if t.kind == "ident":
        return t.text not in KEYWORDS and t.text not in TYPE_WORDS and t.text not in types \
            and not t.text.endswith("_t")
    return False


def is_operand_start(t):
    return t is not None and (t.kind in ("number", "ident") or t.text in ("(",))


SWAP = {"+": "-", "-": "+", "*": "/", "/": "*", "<": "<=", "<=": "<", ">": ">=", ">=": ">",
        "==": "!=", "!=": "==", "&&": "||", "||": "&&", "+=": "-=", "-=": "+=", "*=": "/=",
        "/=": "*=", "++": "--", "--": "++"}


def number_variants(text):
    """Replacements of a literal: 0 <-> 1, and n +- 1 for other integers;
    x + 1 for a floating literal other than 0 and 1."""
    m = re.match(r"(0[xX][0-9a-fA-F]+|[\d.]+(?:[eE][+-]?\d+)?)(\w*)$", text)
    if m is None:
        return []
    body, suffix = m.group(1), m.group(2)
    if body.lower().startswith("0x"):
        v = int(body, 16)
        return [hex(v + 1) + suffix] + ([hex(v - 1) + suffix] if v > 0 else [])
    if re.fullmatch(r"\d+", body) and "f" not in suffix.lower():
        v = int(body)
        if v == 0:
            return ["1" + suffix]
        if v == 1:
            return ["0" + suffix, "2" + suffix]
        return [str(v + 1) + suffix, str(v - 1) + suffix]
    v = float(body)
    if v == 0.0:
        return ["1.0" + suffix]
    if v == 1.0:
        return ["0.0" + suffix, "2.0" + suffix]
    return [repr(v + 1.0) + suffix]


def matching(toks, i):
    """Index of the parenthesis closing toks[i] == '('."""
    depth = 0
    for j in range(i, len(toks)):
        if toks[j].text == "(":
            depth += 1
        elif toks[j].text == ")":
            depth -= 1
            if depth == 0:
                return j
    return None


def candidates(src, types):
    """Every single-point mutant of one source: (kind, start, end,
    replacement, line, description), in the order of the file."""
    toks = tokenize(src)
    out = []

    def add(kind, a, b, new, line, desc):
        out.append((kind, a, b, new, line, desc))

    depth_brace, in_decl = 0, False
    for i, t in enumerate(toks):
        prev = toks[i - 1] if i > 0 else None
        nxt = toks[i + 1] if i + 1 < len(toks) else None
        if t.text == "{":
            depth_brace += 1
        elif t.text == "}":
            depth_brace -= 1
        if t.text in (";", "{", "}"):
            in_decl = False
        elif prev is None or prev.text in (";", "{", "}"):
            in_decl = is_type(t, types) or t.text == "static"
        if depth_brace == 0:
            continue  # only code inside functions and initialisers
        # operators
        if t.kind == "op" and t.text in SWAP:
            binary = is_operand_end(prev, types)
            if t.text in ("+", "-", "*", "/") and not binary:
                if t.text == "-" and is_operand_start(nxt):
                    add("sign", t.start, t.end, "", t.line, "unary '-' deleted")
                continue
            add("operator", t.start, t.end, SWAP[t.text], t.line,
                "'%s' -> '%s'" % (t.text, SWAP[t.text]))
            # drop a literal factor: `2.0 * x` -> `x`, `x * 0.5` -> `x`, `x / 2` -> `x`
            if t.text in ("*", "/") and nxt is not None and nxt.kind == "number":
                after = toks[i + 2] if i + 2 < len(toks) else None
                if after is None or after.text not in ("(", "[", "->", "."):
                    add("factor", t.start, nxt.end, "", t.line,
                        "factor '%s %s' dropped" % (t.text, nxt.text))
            if t.text == "*" and prev.kind == "number":
                before = toks[i - 2] if i >= 2 else None
                if before is None or not is_operand_end(before, types):
                    add("factor", prev.start, t.end, "", t.line,
                        "factor '%s *' dropped" % prev.text)
        elif t.kind == "op" and t.text == "!" and nxt is not None and nxt.text != "=":
            add("check", t.start, t.end, "", t.line, "'!' deleted")
        elif t.kind == "number":
            if prev is not None and prev.text == "[" and i >= 3 and toks[i - 2].kind == "ident" \
                    and (is_type(toks[i - 3], types) or
                         (in_decl and toks[i - 3].text in (",", "*"))):
                continue  # an array's dimension in a declaration
            for v in number_variants(t.text):
                add("constant", t.start, t.end, v, t.line, "%s -> %s" % (t.text, v))
        elif t.text == "return" and nxt is not None and nxt.kind == "ident" \
                and nxt.text.startswith("FE_E") and i + 2 < len(toks) and toks[i + 2].text == ";":
            add("check", t.start, toks[i + 2].end, ";", t.line,
                "'return %s;' deleted" % nxt.text)
        elif t.text == "if" and nxt is not None and nxt.text == "(":
            j = matching(toks, i + 1)
            if j is None:
                continue
            a, b = toks[i + 2].start, toks[j - 1].end
            for forced in ("0", "1"):
                add("check", a, b, forced, t.line, "'if (...)' forced to %s" % forced)
    return out


def wide_lines(src):
    """Lines inside `#if defined(FE__LANES_X86)` ... its `#endif`: the
    eight-lane (AVX-512) kernels and the branches that call them."""
    out, depth, inside = set(), 0, 0
    for n, ln in enumerate(src.splitlines(), 1):
        t = ln.strip()
        if t.startswith("#if"):
            depth += 1
            if inside == 0 and re.match(r"#if\s+defined\s*\(\s*FE__LANES_X86\s*\)\s*$", t):
                inside = depth
        elif t.startswith("#endif"):
            if depth == inside:
                inside = 0
            depth -= 1
        elif inside:
            out.add(n)
    return out


def cpu_has_wide():
    """Whether this processor runs AVX-512 code (avx512f in /proc/cpuinfo);
    True when that cannot be read, so that nothing is set apart."""
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for ln in f:
                if ln.startswith("flags"):
                    return "avx512f" in ln.split()
    except OSError:
        pass
    return True


def functions_defined(src):
    """Public functions a source defines (names fe_..., not fe__...)."""
    return set(re.findall(r"^(?!static)[A-Za-z_][\w \t\*]*?\b(fe_[a-z0-9][a-z0-9_]*)\s*\([^;]*$",
                          src, re.M))


# ---------------------------------------------------------------- sampling
def quotas(sizes, n, floor):
    """n mutants over the modules in proportion to their sizes (largest
    remainders), at least `floor` each when n allows it."""
    total = sum(sizes.values())
    raw = {m: n * s / total for m, s in sizes.items()}
    q = {m: int(r) for m, r in raw.items()}
    for m in sorted(raw, key=lambda m: (-(raw[m] - q[m]), m))[: n - sum(q.values())]:
        q[m] += 1
    if n >= floor * len(sizes):
        for m in sorted(q):
            while q[m] < floor:
                big = max(q, key=lambda k: (q[k], k))
                q[big] -= 1
                q[m] += 1
    return q


# ---------------------------------------------------------------- running
def descendants(pid):
    """Every process below pid (Check runs each test in a process group of
    its own, so killing the group of the runner does not reach them)."""
    children = {}
    for d in os.listdir("/proc"):
        if d.isdigit():
            try:
                with open("/proc/%s/stat" % d) as f:
                    ppid = int(f.read().rsplit(")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                continue
            children.setdefault(ppid, []).append(int(d))
    out, todo = [], [pid]
    while todo:
        for c in children.get(todo.pop(), []):
            out.append(c)
            todo.append(c)
    return out


def run(cmd, timeout=None, env=None, cwd=None):
    """Run cmd in its own session; returns (status, output, seconds);
    status None means it and everything it started were killed after
    `timeout` seconds.  The output goes through a file: a pipe would stay
    open in a grandchild."""
    t0 = time.monotonic()
    with tempfile.TemporaryFile() as log:
        p = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, env=env, cwd=cwd,
                             start_new_session=True)
        try:
            status = p.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            status = None
            for victim in [p.pid] + descendants(p.pid):
                try:
                    os.kill(victim, signal.SIGKILL)
                except ProcessLookupError:
                    pass
            p.wait()
        if status is not None:  # a test child left running by its runner
            for victim in descendants(p.pid):
                try:
                    os.kill(victim, signal.SIGKILL)
                except ProcessLookupError:
                    pass
        log.seek(0)
        out = log.read().decode(errors="replace")
    return status, out, time.monotonic() - t0


def sh(cmd):
    status, out, _ = run(cmd)
    if status != 0:
        sys.stderr.write(out)
        sys.exit("mutate: failed: %s" % " ".join(cmd))


def stripped(obj, dst):
    """The object without debugging sections (for the identity test)."""
    sh(["objcopy", "--strip-debug", "--remove-section=.comment", obj, dst])
    with open(dst, "rb") as f:
        return f.read()


def occurrence(text, line):
    """Which occurrence of its text (stripped) line `line` of `text` is:
    1 for the first line of the file that reads so, 2 for the second..."""
    all_lines = text.splitlines()
    want = all_lines[line - 1].strip()
    return sum(1 for ln in all_lines[:line] if ln.strip() == want)


def load_explained(path):
    """The survivors explained in literate/guarantees.org, as listed in
    `path`: blocks of three lines, `module | change | verdict` or
    `module | change | verdict | n` (verdict equivalent or accepted; n: the
    n-th line of the file with that text, 1 when left out), the mutated
    source line as the report prints it (stripped), and the reason in one
    line; blank lines and lines starting with # between blocks.  Keyed by
    (module, change, line, n), so an entry holds while that line's text
    does not change, whatever its number or the mutant's id; every mutant
    of that kind on that line is meant (a line with two zeros has two
    mutants 0 -> 1)."""
    out = {}
    if not path or not os.path.exists(path):
        return out
    with open(path, encoding="utf-8") as f:
        lines = [ln.rstrip("\n") for ln in f if ln.strip() and not ln.startswith("#")]
    if len(lines) % 3:
        sys.exit("mutate: %s: entries are three lines each" % path)
    for i in range(0, len(lines), 3):
        head = [h.strip() for h in lines[i].split(" | ")]
        if len(head) not in (3, 4) or head[2] not in ("equivalent", "accepted") \
                or (len(head) == 4 and not head[3].isdigit()):
            sys.exit("mutate: %s: bad entry: %s" % (path, lines[i]))
        n = int(head[3]) if len(head) == 4 else 1
        out[(head[0], head[1], lines[i + 1].strip(), n)] = head[2]
    return out


# Two checks of UBSan, trapping (no run-time library to link): an index
# out of an array's bounds, and a null pointer passed where the function is
# declared to take none (memcpy(dst, NULL, 0) is undefined, as make check's
# UBSan build reports).
BOUNDS = ["-fsanitize=bounds,nonnull-attribute", "-fsanitize-undefined-trap-on-error"]


def report(results, mods, seed, secs, excluded, a, B):
    # The report.  A survivor listed in the explained file is marked
    # equivalent or accepted; the raw kill rate counts every survivor, the
    # last column leaves out the documented equivalent ones.
    explained = load_explained(a.explained)
    for x in results:
        x["explained"] = ""
        if x["verdict"] == "survived":
            e = explained.get((x["module"], x["change"], x["line"], x.get("occurrence", 1)))
            if e is not None:
                x["explained"] = e
    rows, tot = [], {"killed": 0, "survived": 0, "stillborn": 0, "identical": 0, "not run": 0,
                     "equivalent": 0}
    for m in mods:
        r = [x for x in results if x["module"] == m]
        if not r:
            continue
        c = {v: sum(1 for x in r if x["verdict"] == v) for v in tot}
        c["equivalent"] = sum(1 for x in r if x["explained"] == "equivalent")
        for v in tot:
            tot[v] += c[v]
        rows.append((m, len(r), c))

    def rate(c, less=0):
        d = c["killed"] + c["survived"] - less
        return "%5.1f %%" % (100.0 * c["killed"] / d) if d else "    -  "

    lines_out = ["", "module      mutants  killed  survived  stillborn  identical  not run   kill rate"
                 "   equivalent   without them"]
    for m, nm, c in rows:
        lines_out.append("%-10s %8d %7d %9d %10d %10d %8d   %s   %10d   %s" % (
            m, nm, c["killed"], c["survived"], c["stillborn"], c["identical"], c["not run"],
            rate(c), c["equivalent"], rate(c, c["equivalent"])))
    lines_out.append("%-10s %8d %7d %9d %10d %10d %8d   %s   %10d   %s" % (
        "overall", len(results), tot["killed"], tot["survived"], tot["stillborn"],
        tot["identical"], tot["not run"], rate(tot), tot["equivalent"],
        rate(tot, tot["equivalent"])))
    lines_out.append("(seed %d, %d mutants in %.0f s; excluded: %s; kill rate = killed / (killed"
                     " + survived); equivalent: survivors documented as such in %s)" % (
                         seed, len(results), secs, ", ".join(sorted(excluded)) or "none",
                         a.explained))
    surv = [x for x in results if x["verdict"] == "survived"]
    if surv:
        lines_out += ["", "surviving mutants (explained: %s):" % a.explained]
        for x in surv:
            lines_out.append("  %-10s %-22s %-34s %-12s | %s" % (
                x["id"], x["where"], x["change"], x["explained"] or "UNEXPLAINED", x["line"]))
    notrun = [x for x in results if x["verdict"] == "not run"]
    if notrun:
        lines_out += ["", "not run here (AVX-512 code; this processor lacks avx512f):"]
        for x in notrun:
            lines_out.append("  %-10s %-22s %-34s | %s" % (x["id"], x["where"], x["change"], x["line"]))
    text = "\n".join(lines_out) + "\n"
    print(text, end="")
    with open(os.path.join(B, "report.txt"), "w") as h:
        h.write(text)
    with open(os.path.join(B, "results.json"), "w") as h:
        json.dump(results, h, indent=1)
    return tot


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--mutants", type=int, default=0,
                    help="how many (0: the full set, --full of them)")
    ap.add_argument("--full", type=int, default=200, help="size of the full set")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--floor", type=int, default=4, help="at least this many per module")
    ap.add_argument("--exclude", default="", help="modules left out, comma-separated")
    ap.add_argument("--skip-suites", default="hostile,discover_cli",
                    help="suites never run for a mutant (slow; command-level)")
    ap.add_argument("--ids", default="", help="run only these mutant ids (module:number,...)")
    ap.add_argument("--list", action="store_true", help="print the mutants, run nothing")
    ap.add_argument("--report", action="store_true",
                    help="print the report of the last run again (results.json), with the "
                         "explained file as it is now; run nothing")
    ap.add_argument("--min-rate", type=float, default=0.0,
                    help="exit 1 when the overall kill rate is below this (percent)")
    ap.add_argument("--explained", default="tests/mutate/explained.txt",
                    help="survivors explained as equivalent or accepted (see load_explained)")
    ap.add_argument("--build", default="build")
    ap.add_argument("--cc", default="cc")
    ap.add_argument("--cflags", default="-std=c11 -Wall -Wextra -pedantic -O2 -g")
    ap.add_argument("--ext-cflags", default="")
    ap.add_argument("--ext-libs", default="-lm -pthread")
    ap.add_argument("--check-cflags", default="")
    ap.add_argument("--check-libs", default="-lcheck")
    a = ap.parse_args()

    excluded = {m for m in a.exclude.split(",") if m}
    skip_suites = {s for s in a.skip_suites.split(",") if s}
    mods = sorted(f[:-2] for f in os.listdir("src") if f.endswith(".c") and f[:-2] not in excluded)
    headers = ["include/foldest/" + h for h in os.listdir("include/foldest")] + \
        ["src/" + h for h in os.listdir("src") if h.endswith(".h")]
    types = type_names(headers + ["src/%s.c" % m for m in mods])

    # Every candidate of every module, then the sample.
    src, cands, lines = {}, {}, {}
    for m in mods:
        with open("src/%s.c" % m, encoding="utf-8") as f:
            src[m] = f.read()
        cands[m] = candidates(src[m], types)
        lines[m] = sum(1 for ln in src[m].splitlines()
                       if ln.strip() and not ln.lstrip().startswith(("/*", "*", "//")))
    wide = {m: wide_lines(src[m]) for m in mods}
    wide_here = cpu_has_wide()
    rng = random.Random(a.seed)
    chosen = []
    if a.ids:
        for ident in a.ids.split(","):
            m, k = ident.split(":")
            chosen.append((m, int(k)))
    elif a.mutants:
        # A sample: each mutant's module drawn in proportion to its size.
        pool = {m: list(range(len(cands[m]))) for m in mods}
        for _ in range(a.mutants):
            live = [m for m in mods if pool[m]]
            m = rng.choices(live, weights=[lines[k] for k in live])[0]
            chosen.append((m, pool[m].pop(rng.randrange(len(pool[m])))))
    else:
        q = quotas(lines, a.full, a.floor)
        for m in mods:
            chosen += [(m, k) for k in sorted(rng.sample(range(len(cands[m])),
                                                         min(q[m], len(cands[m]))))]
    chosen.sort()

    def describe(m, k):
        kind, s, e, new, line, desc = cands[m][k]
        return "src/%s.c:%d" % (m, line), desc

    if a.report:
        B = os.path.join(a.build, "mutate")
        with open(os.path.join(B, "results.json")) as h:
            results = json.load(h)
        with open(os.path.join(B, "run.json")) as h:
            run_meta = json.load(h)
        report(results, sorted({x["module"] for x in results}), run_meta["seed"],
               run_meta["secs"], set(run_meta["excluded"]), a, B)
        return 0

    if a.list:
        for m, k in chosen:
            where, desc = describe(m, k)
            print("%s:%d  %-22s %s" % (m, k, where, desc))
        return 0

    # Which suites exercise a module: its own, then every suite whose test
    # file calls one of its public functions, then the command's suites when
    # the command calls one.
    tests = sorted(f for f in os.listdir("tests") if f.startswith("check_") and f.endswith(".c"))
    test_text = {}
    for f in tests:
        with open("tests/" + f, encoding="utf-8") as h:
            test_text[f[6:-2]] = h.read()
    cli_text = ""
    for f in sorted(os.listdir("src/cli")):
        with open("src/cli/" + f, encoding="utf-8") as h:
            cli_text += h.read()
    cli_suites = {s for s, t in test_text.items() if "FE_TEST_CLI" in t}

    def suites_of(m):
        names = functions_defined(src[m])
        pat = re.compile(r"\b(?:%s)\b" % "|".join(sorted(names))) if names else None
        found = [s for s, t in test_text.items() if s == m or (pat and pat.search(t))]
        if pat and pat.search(cli_text):
            found += [s for s in cli_suites if s not in found]
        return [s for s in found if s not in skip_suites]

    # Build: test objects once (cached), the command's objects and the
    # library's pristine objects from make; per mutant one object and links.
    B = os.path.join(a.build, "mutate")
    os.makedirs(os.path.join(B, "tests"), exist_ok=True)
    cli_bin = os.path.abspath(os.path.join(B, "foldest"))
    tflags = shlex.split(a.cflags) + ["-DFE_TEST_CLI=\"%s\"" % cli_bin, "-Iinclude", "-Itests",
                                      "-I" + os.path.join(a.build, "tests")] + \
        shlex.split(a.check_cflags)
    stamp = os.path.join(B, "tests", "flags")
    old = open(stamp).read() if os.path.exists(stamp) else ""
    test_objs = []
    for f in ["main.c"] + tests:
        o = os.path.join(B, "tests", f[:-2] + ".o")
        deps = ["tests/" + f, "tests/testutil.h", os.path.join(a.build, "tests", "suites.h")]
        if old != " ".join(tflags) or not os.path.exists(o) or \
                any(os.path.getmtime(d) > os.path.getmtime(o) for d in deps):
            print("mutate: compiling tests/%s" % f, flush=True)
            sh([a.cc] + tflags + ["-c", "tests/" + f, "-o", o])
        test_objs.append(o)
    with open(stamp, "w") as h:
        h.write(" ".join(tflags))
    lib_objs = {m: os.path.join(a.build, "obj", m + ".o")
                for m in sorted(f[:-2] for f in os.listdir("src") if f.endswith(".c"))}
    cli_objs = [os.path.join(a.build, "obj", "cli", f[:-2] + ".o")
                for f in sorted(os.listdir("src/cli")) if f.endswith(".c")]
    libs = shlex.split(a.check_libs) + shlex.split(a.ext_libs)
    cflags = [f for f in shlex.split(a.cflags) if f != "-Werror"] + \
        ["-fPIC", "-Iinclude", "-Isrc"] + shlex.split(a.ext_cflags)
    test_bin = os.path.join(B, "check_foldest")

    def link(objs):
        s1, out1, _ = run([a.cc, "-o", test_bin] + test_objs + objs + libs)
        if s1 != 0:
            return out1
        s2, out2, _ = run([a.cc, "-o", cli_bin] + cli_objs + objs + libs)
        return None if s2 == 0 else out2

    env = dict(os.environ, FE_TEST_QUICK="1", OPENBLAS_NUM_THREADS="1")

    def run_suite(s, timeout):
        return run([os.path.abspath(test_bin)], timeout=timeout, env=dict(env, CK_RUN_SUITE=s))

    # The unmutated build must pass every suite a mutant will run; its times
    # set the time limits.
    need = sorted({s for m, _ in chosen for s in suites_of(m)})
    err = link(list(lib_objs.values()))
    if err:
        sys.exit("mutate: the unmutated build does not link:\n" + err)
    base = {}
    for s in need:
        status, out, secs = run_suite(s, 600)
        if status != 0:
            sys.stderr.write(out[-3000:])
            sys.exit("mutate: suite %s fails without any mutant; fix that first" % s)
        base[s] = secs
    print("mutate: %d mutants, seed %d; unmutated suites pass (%s)" % (
        len(chosen), a.seed, ", ".join("%s %.1fs" % (s, base[s]) for s in need)), flush=True)

    pristine = {}
    results = []
    t_start = time.monotonic()
    for n, (m, k) in enumerate(chosen, 1):
        kind, s0, e0, new, line, desc = cands[m][k]
        where = "src/%s.c:%d" % (m, line)
        text = src[m][:s0] + new + src[m][e0:]
        mdir = os.path.join(B, "src")
        os.makedirs(mdir, exist_ok=True)
        msrc, mobj = os.path.join(mdir, m + ".c"), os.path.join(mdir, m + ".o")
        with open(msrc, "w", encoding="utf-8") as h:
            # #line keeps the compiler's messages pointing at src/.
            h.write('#line 1 "src/%s.c"\n' % m + text)
        # A file with lane kernels (lanes.h) has a four-lane kernel that
        # this processor may never run: a mutant that survives the build
        # as it is is built again with FE_NO_CLONES (four lanes only).  A
        # mutant that still survives is built once more with the bounds and
        # nonnull checks of UBSan (a trap, no run-time library): an index
        # one past an array, or a null pointer given to memcpy, which the
        # plain build lets through silently and `make check`'s sanitizer
        # build reports, then fails the suite that reaches it.
        variants = [[]] + ([["-DFE_NO_CLONES"]] if '#include "lanes.h"' in src[m] else []) + \
            [BOUNDS]
        verdict, by, ran = None, "", False
        for vi, extra in enumerate(variants):
            key = (m, vi)
            if extra == BOUNDS and not ran:
                continue                # identical in the plain build: not run
            if key not in pristine:
                pobj = os.path.join(B, "pristine%d.o" % vi)
                if vi == 0:
                    pobj = lib_objs[m]
                else:
                    sh([a.cc] + cflags + extra + ["-c", "src/%s.c" % m, "-o", pobj])
                pristine[key] = stripped(pobj, os.path.join(B, "pristine.o"))
                if extra == BOUNDS:
                    # The unmutated module with these checks must pass its
                    # suites too, or this build proves nothing.
                    bad = link([pobj if x == m else o for x, o in lib_objs.items()])
                    for s in ([] if bad else suites_of(m)):
                        if run_suite(s, max(10.0, 10 * base[s]))[0] != 0:
                            bad = s
                            break
                    if bad:
                        print("mutate: %s with the UBSan checks fails %s unmutated; that build "
                              "is not used" % (m, bad), flush=True)
                        pristine[key] = None
            if pristine[key] is None:
                continue
            status, out, _ = run([a.cc] + cflags + extra + ["-c", msrc, "-o", mobj], timeout=300)
            if status != 0 and vi == 0:
                verdict = "stillborn"
                break
            if status != 0 or stripped(mobj, os.path.join(B, "mutant.o")) == pristine[key]:
                continue
            if link([mobj if x == m else o for x, o in lib_objs.items()]):
                if vi == 0:
                    verdict = "stillborn"
                    break
                continue
            ran = True
            for s in sorted(suites_of(m), key=lambda s: (s != m, base[s], s)):
                status, out, secs = run_suite(s, max(10.0, 10 * base[s]))
                if status != 0:
                    verdict = "killed"
                    by = s + (" (timeout)" if status is None else "") + \
                        (" (UBSan checks)" if extra == BOUNDS else
                         " " + " ".join(extra) if extra else "")
                    break
            if verdict == "killed":
                break
        if verdict is None:
            verdict = "survived" if ran else "identical"
            if verdict == "survived" and not wide_here and line in wide[m]:
                verdict = "not run"
        results.append(dict(id="%s:%d" % (m, k), module=m, where=where, kind=kind, change=desc,
                            verdict=verdict, by=by,
                            line=src[m].splitlines()[line - 1].strip(),
                            occurrence=occurrence(src[m], line)))
        print("[%d/%d] %-8s %-22s %-34s %s %s" % (n, len(chosen), results[-1]["id"], where, desc,
                                                 verdict, by), flush=True)

    secs = time.monotonic() - t_start
    with open(os.path.join(B, "run.json"), "w") as h:
        json.dump(dict(seed=a.seed, secs=secs, excluded=sorted(excluded)), h)
    tot = report(results, mods, a.seed, secs, excluded, a, B)
    d = tot["killed"] + tot["survived"]
    if d and 100.0 * tot["killed"] / d < a.min_rate:
        print("mutate: kill rate below %.0f %%" % a.min_rate)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
