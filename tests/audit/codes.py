#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Every documented error code of every public function is produced by a test.

The contract comment in front of each public function in include/foldest/*.h
names the codes it returns (FE_EINVAL, FE_ESIZE, ...).  For each pair
(function, code) this script looks in tests/*.c for one test statement that
calls the function and names the code, such as

    ck_assert_int_eq(fe_kalman_init(&k, 2, 1, mem, 3), FE_ESIZE);

Comments and string literals in the tests are ignored.  Two indirections
are followed, inside one test (one braced top-level definition) only:

  - a function pointer: `upd = fast ? fe_kalman_update_fast :
    fe_kalman_update;` makes a call `upd(...)` a call of both;
  - a table: a statement that passes `fe_x` to a helper together with a
    table whose initialiser names the code, such as
    `check_numbers(fe_csv_number, cases, n)`, counts for every code of
    `cases`.

A pair no input can produce is listed in tests/audit/codes_explained.txt as
`function CODE reason`.  The script prints what it checked and exits 1 on
any pair neither tested nor explained, and on an explanation that names a
pair which is no longer documented or is now tested (so the list stays
true).  Run from the top of the tree: python3 tests/audit/codes.py [-v].
"""

import glob
import os
import re
import sys

import ledger

LEDGER = "tests/audit/codes_explained.txt"

CODE = re.compile(r"\bFE_E[A-Z]+\b")
IDENT = re.compile(r"[A-Za-z_]\w*")


def strip_strings(text):
    """Blank out string and character literals, keeping line structure."""
    return re.sub(r'"(?:\\.|[^"\\\n])*"|\'(?:\\.|[^\'\\\n])*\'', '""', text)


def strip_comments(text):
    text = re.sub(r"/\*.*?\*/", lambda m: "\n" * m.group(0).count("\n"),
                  text, flags=re.S)
    return re.sub(r"//[^\n]*", "", text)


def top_level_items(text):
    """Split a C file (preprocessor lines removed) into the items at brace
    depth 0: ('comment', text) and ('code', text), a code item ending at a
    ';' or a '}' that returns to depth 0.  Comments inside braces belong to
    the code item they are in."""
    text = re.sub(r"(?ms)^#ifdef __cplusplus$.*?^#endif$", "", text)
    text = re.sub(r"(?m)^\s*#.*(?:\\\n.*)*$", "", text)
    items, i, depth, start = [], 0, 0, 0
    n = len(text)
    while i < n:
        if text.startswith("/*", i):
            j = text.index("*/", i + 2) + 2
            if depth == 0:
                if text[start:i].strip():
                    items.append(("code", text[start:i]))
                items.append(("comment", text[i + 2:j - 2]))
                start = j
            i = j
            continue
        c = text[i]
        if c == '"':
            i = re.compile(r'"(?:\\.|[^"\\])*"').match(text, i).end()
            continue
        if c == "{":
            depth += 1
        elif c == "}":
            depth -= 1
            if depth == 0:
                # a struct or enum definition goes on to its ';'
                k = i + 1
                m = re.compile(r"\s*\w*\s*;").match(text, k)
                end = m.end() if m else k
                items.append(("code", text[start:end]))
                start = i = end
                continue
        elif c == ";" and depth == 0:
            items.append(("code", text[start:i + 1]))
            start = i + 1
        i += 1
    if text[start:].strip():
        items.append(("code", text[start:]))
    return items


PROTO = re.compile(r"^\s*(?:extern\s+)?[\w\s\*]*?\b(fe_\w+)\s*\(", re.S)


def contracts(header):
    """(function, comment) for each function declared in a header.  A
    function's contract is the comment right before it; prototypes that
    follow one another with no comment between share the first one's.
    Org link comments ([[file:...]], '... ends here') are not contracts."""
    out = []
    last_comment = None
    for kind, text in top_level_items(open(header, encoding="utf-8").read()):
        if kind == "comment":
            t = text.strip()
            if not (t.startswith("[[file:") or t.endswith("ends here")):
                last_comment = text
            continue
        m = PROTO.match(text)
        if (m and text.rstrip().endswith(";") and "{" not in text
                and not text.lstrip().startswith("typedef")):
            out.append((m.group(1), last_comment or ""))
        else:
            last_comment = None
    return out


def statements(body):
    """Split a function body on ';' outside parentheses."""
    out, depth, start = [], 0, 0
    for i, c in enumerate(body):
        if c == "(":
            depth += 1
        elif c == ")":
            depth -= 1
        elif c == ";" and depth == 0:
            out.append(body[start:i])
            start = i + 1
    out.append(body[start:])
    return out


def test_blocks(path):
    text = strip_comments(strip_strings(open(path, encoding="utf-8").read()))
    text = re.sub(r"\bEND_TEST\b", "", text)
    return [t for kind, t in top_level_items(text) if kind == "code" and "{" in t]


def wrappers(blocks, publics):
    """{helper: {fe_x}} for each static helper in a test file that returns
    the status of a public function (`return fe_x(...)`, or `rc =
    fe_x(...)` and later `return rc`), or that takes an `int` status and
    asserts fe_x's against it in one statement (`static void fails_at(...,
    int rc, ...)` with `ck_assert_int_eq(fe_x(...), rc)`)."""
    out = {}
    for block in blocks:
        head = re.match(r"\s*static\s+int\s+(\w+)\s*\(", block)
        if not head:
            continue
        fns = {f for f in re.findall(r"\breturn\s+(fe_\w+)\s*\(", block) if f in publics}
        for var, f in re.findall(r"\b(\w+)\s*=\s*(fe_\w+)\s*\(", block):
            if f in publics and re.search(r"\breturn\s+%s\s*;" % var, block):
                fns.add(f)
        if fns:
            out[head.group(1)] = fns
    for block in blocks:
        head = re.match(r"\s*static\s+void\s+(\w+)\s*\(([^)]*)\)", block)
        if not head:
            continue
        ints = re.findall(r"\bint\s+(\w+)\s*(?:,|$)", head.group(2))
        fns = set()
        for st in statements(block[head.end():]):
            words = set(IDENT.findall(st))
            if words & set(ints):
                fns |= {f for f in re.findall(r"\b(fe_\w+)\s*\(", st) if f in publics}
        if fns:
            out[head.group(1)] = fns
    return out


def coverage(publics):
    """{(function, code): 'file: statement'} for every pair some test produces."""
    found = {}
    call = re.compile(r"\b(\w+)\s*\(")
    for path in sorted(glob.glob("tests/*.c")):
        blocks = test_blocks(path)
        wrap = wrappers(blocks, publics)
        for block in blocks:
            stmts = statements(block)
            alias, tables = dict(wrap), {}
            for st in stmts:
                m = re.search(r"(\w+)\s*\)?\s*(?:\([^()]*\))?\s*=\s*([^=][^;]*)$", st, re.S)
                if m:
                    refs = [f for f in IDENT.findall(m.group(2)) if f in publics]
                    bare = [f for f in refs if not re.search(r"\b%s\s*\(" % f, m.group(2))]
                    if bare:
                        alias[m.group(1)] = bare
                t = re.search(r"(\w+)\s*\[\s*\w*\s*\]\s*=\s*\{", st)
                if t:
                    tables[t.group(1)] = set(CODE.findall(st))
            kept = None  # (variable, functions) of `rc = fe_x(...)`
            for st in stmts:
                called = set()
                for name in call.findall(st):
                    if name in publics:
                        called.add(name)
                    called.update(alias.get(name, ()))
                codes = set(CODE.findall(st))
                words = set(IDENT.findall(st))
                if kept and kept[0] in words:
                    called |= kept[1]
                passed = {f for f in words if f in publics} - called
                tabled = set()
                for name in words & tables.keys():
                    tabled |= tables[name]
                where = "%s: %s" % (path, " ".join(st.split())[:110])
                for f in called:
                    for c in codes:
                        found.setdefault((f, c), where)
                for f in passed | called:
                    for c in tabled:
                        found.setdefault((f, c), where)
                m = re.match(r"[\s{}]*(?:int\s+)?(\w+)\s*=\s*(\w+)\s*\(", st)
                fns = set()
                if m:
                    fns = {m.group(2)} & publics | set(alias.get(m.group(2), ()))
                kept = (m.group(1), fns) if fns else None
    return found


def main():
    verbose = "-v" in sys.argv[1:]
    pairs = []
    publics = set()
    for h in sorted(glob.glob("include/foldest/*.h")):
        for fn, comment in contracts(h):
            publics.add(fn)
            for c in sorted(set(CODE.findall(comment))):
                pairs.append((os.path.basename(h), fn, c))
    found = coverage(publics)
    explained = ledger.load_explained(LEDGER, "function CODE reason")
    if explained is None:
        return 1
    where = {(fn, c): h for h, fn, c in pairs}
    documented = set(where)
    n_tested, n_explained, gaps, stale = ledger.tally(
        [(fn, c) for _, fn, c in pairs], found, explained, LEDGER, ("tested", 34),
        lambda p: "%s: %s %s: no test statement calls the one and names the other"
                  % (where[p], p[0], p[1]), verbose)
    for (fn, c), (lineno, _) in sorted(explained.items()):
        if (fn, c) not in documented:
            stale.append("codes_explained.txt:%d: %s %s is not documented in any header"
                         % (lineno, fn, c))
    print("codes: %d public functions, %d documented (function, code) pairs: "
          "%d produced by a test, %d explained, %d gaps"
          % (len(publics), len(pairs), n_tested, n_explained, len(gaps)))
    for line in gaps + stale:
        print(line)
    return 1 if gaps or stale else 0


if __name__ == "__main__":
    sys.exit(main())
