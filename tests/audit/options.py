#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Every option of every command is used by a test that runs that command.

The options are read from the tables the parser itself reads: each
command calls `fe_cli_options("NAME", TABLE, ...)` in src/cli/*.c with a
`fe_cli_option TABLE[]` of its own, and fe_cli_options adds the table of
the options every command takes (the `fe_cli_option` table of the file
that defines fe_cli_options, passed to no command) and the short forms of
its getopt_long string (-h for --help, -V for --version).  Each command of
the command table (`fe_cli_command fe_cli_commands[]`) must have a table.

A (command, option) pair is used when a test of tests/*.c runs the
command with the option: a command line in which the option (`--opt`,
`--opt=value`, or its short form) follows the command's name before any
`|`, `;`, `&&`, `||` or `--`.  A command line is

  - a string literal that begins with the command's name ("stats --json")
    and is an element of an initialiser (a table of cases, an argv array
    such as {"synth", "--effect", "drift", ...}, whose elements are read as
    one line, a variable's value) or an argument of a function that runs
    commands (fe_test_run, popen, system, execv, a test helper that calls
    one of them) or of snprintf;
  - or such an argument in which the name follows a conversion, which is
    where the tests put FE_TEST_CLI: "%s discover --real %s ...",
    "cat %2$s | %1$s calibrate ...".

A conversion of such a format is replaced by its argument when that is a
string the test names: a literal, a variable initialised or assigned a
literal (`roles`), the choices of a `?:` between literals, an element of a
table (`args[a]`, `commands[_i % N]`) or a field of its rows (`c->args`
with `c = &cases[_i]`: the table's structure gives the field's position).
Other arguments (paths, numbers) stay as they are.  Options are named in
full: an abbreviation (--mod) tests the abbreviation, not the option.
Comments are ignored; so are strings passed to anything else (messages,
ck_assert_msg), and a command's name that follows neither the start of a
string nor a conversion (`foldest stats` in a message).

A pair no test can use is listed in tests/audit/options_explained.txt as
`command --option reason`.  The script prints its figures and exits 1 on a
pair neither used nor explained, on an explanation of a pair that is not an
option or is now used, and when it cannot find the tables.  Run from the
top of the tree: python3 tests/audit/options.py [-v]; -v prints each pair
and the test (file: function or table) and command line that uses it.
"""

import glob
import itertools
import re
import sys

import ledger

LEDGER = "tests/audit/options_explained.txt"

CLI = "\0CLI"           # the value of FE_TEST_CLI in an expanded format
CONV = re.compile(r"%(?:%|(\d+\$)?[-+ #0']*(\*|\d+)?(?:\.(?:\*|\d+))?"
                  r"(?:hh|h|ll|l|L|z|j|t)?([diouxXeEfFgGaAcspn]))")
CONV_WORD = re.compile(r"^%%?(?:\d+\$)?s$")   # a conversion standing as one word
STOP = {"|", "||", "&&", ";", "--"}
RUNNERS = {"fe_test_run", "popen", "system", "execv", "execvp", "execve", "execl",
           "execlp", "posix_spawn", "posix_spawnp"}
BUILDERS = {"snprintf", "sprintf"}

ESCAPES = {"n": "\n", "t": "\t", "r": "\r", "\\": "\\", '"': '"', "'": "'", "0": "\0",
           "a": "\a", "b": "\b", "f": "\f", "v": "\v", "?": "?"}


def unescape(body):
    """A string literal's text, its escapes decoded."""
    def one(m):
        e = m.group(1)
        if e[0] == "x":
            return chr(int(e[1:], 16))
        if e[0].isdigit():
            return chr(int(e, 8))
        return ESCAPES.get(e, e)
    return re.sub(r"\\(x[0-9A-Fa-f]+|[0-7]{1,3}|.)", one, body)


TOKEN = re.compile(r'''
    (?P<ws>\s+)
  | (?P<comment>/\*.*?\*/|//[^\n]*)
  | (?P<str>(?:u8|[uUL])?"(?:\\.|[^"\\\n])*")
  | (?P<chr>'(?:\\.|[^'\\\n])*')
  | (?P<id>[A-Za-z_]\w*)
  | (?P<num>\.?\d(?:[eEpP][-+]|[\w.])*)
  | (?P<punct>->|\+\+|--|<<=|>>=|<<|>>|<=|>=|==|!=|&&|\|\||[-+*/%&|^!=<>]=|\.\.\.|.)
''', re.S | re.X)


def lex(text):
    """C tokens as (kind, text), adjacent string literals joined and
    decoded; kind is 'str', 'chr', 'id', 'num' or 'punct'."""
    out = []
    for m in TOKEN.finditer(text):
        kind = m.lastgroup
        if kind in ("ws", "comment"):
            continue
        t = m.group(kind)
        if kind == "str":
            t = unescape(t[t.index('"') + 1:-1])
            if out and out[-1][0] == "str":
                out[-1] = ("str", out[-1][1] + t)
                continue
        out.append((kind, t))
    return out


def split_source(text):
    """The macro definitions (name, tokens of the body) and the tokens of
    the rest, preprocessor lines removed."""
    macros, rest, pos = [], [], 0
    text = re.sub(r"/\*.*?\*/", lambda m: re.sub(r"[^\n]", " ", m.group(0)), text, flags=re.S)
    for m in re.finditer(r"(?m)^[ \t]*#(?:[^\n\\]|\\.)*(?:\\\n(?:[^\n\\]|\\.)*)*$", text):
        rest.append(text[pos:m.start()])
        pos = m.end()
        d = re.match(r"[ \t]*#\s*define\s+(\w+)(\([^)]*\))?(.*)", m.group(0), re.S)
        if d:
            macros.append((d.group(1), lex(d.group(3).replace("\\\n", " "))))
    rest.append(text[pos:])
    return macros, lex("".join(rest))


def top_level(tokens):
    """Split tokens into top-level items: a function's definition ends at
    the '}' that closes its body, anything else at its ';'."""
    items, depth, start, i, body = [], 0, 0, 0, False
    while i < len(tokens):
        t = tokens[i][1] if tokens[i][0] == "punct" else None
        if t == "{":
            if depth == 0:
                body = i > 0 and tokens[i - 1] == ("punct", ")")
            depth += 1
        elif t == "}":
            depth -= 1
            if depth == 0 and body:
                items.append(tokens[start:i + 1])
                start = i + 1
        elif t == ";" and depth == 0:
            items.append(tokens[start:i + 1])
            start = i + 1
        i += 1
    if start < len(tokens):
        items.append(tokens[start:])
    return [it for it in (strip_end_test(it) for it in items) if it]


def strip_end_test(item):
    while item and item[0] == ("id", "END_TEST"):
        item = item[1:]
    return item


def matching(tokens, i):
    """Index of the bracket that closes tokens[i]."""
    depth = 0
    for j in range(i, len(tokens)):
        if tokens[j][0] != "punct":
            continue
        if tokens[j][1] in ("(", "[", "{"):
            depth += 1
        elif tokens[j][1] in (")", "]", "}"):
            depth -= 1
            if depth == 0:
                return j
    return len(tokens) - 1


def split_on(tokens, sep):
    """Split on `sep` outside brackets."""
    out, depth, start = [], 0, 0
    for i, (kind, t) in enumerate(tokens):
        if kind == "punct" and t in "([{":
            depth += 1
        elif kind == "punct" and t in ")]}":
            depth -= 1
        elif kind == "punct" and t == sep and depth == 0:
            out.append(tokens[start:i])
            start = i + 1
    out.append(tokens[start:])
    return [x for x in out if x]


def split_commas(tokens):
    return split_on(tokens, ",")


def item_name(item):
    """A test's name (START_TEST(name)), a function's, or a declaration's."""
    if item[:2] == [("id", "START_TEST"), ("punct", "(")]:
        return item[2][1]
    depth = 0
    last = None
    for i, (kind, t) in enumerate(item):
        if kind == "id":
            last = t
        elif t == "(" and depth == 0 and last is not None:
            j = matching(item, i)
            if j + 1 < len(item) and item[j + 1] == ("punct", "{"):
                return last             # a function
        if t in ("=", "[", "{", ";") and last is not None:
            return last
        if t in "([{":
            depth += 1
        elif t in ")]}":
            depth -= 1
    return last or "?"


# ------------------------------------------------------------------ the options


def parser_options():
    """{command: {option: takes_value}}, and {short: option}."""
    tables, calls, common, shorts, commands = {}, [], None, None, []
    for path in sorted(glob.glob("src/cli/*.c") + glob.glob("src/cli/*.h")):
        text = open(path, encoding="utf-8").read()
        for m in re.finditer(r"\bfe_cli_option\s+(\w+)\s*\[\s*\]\s*=\s*\{(.*?)\};", text, re.S):
            rows = re.findall(r'\{\s*"(-[^"]*)"\s*,\s*(\d+)\s*\}', m.group(2))
            tables[(path, m.group(1))] = {o: int(v) for o, v in rows}
        for m in re.finditer(r'\bfe_cli_options\s*\(\s*"(\w+)"\s*,\s*(\w+)\s*,', text):
            calls.append((path, m.group(1), m.group(2)))
        if re.search(r"(?m)^int\s+fe_cli_options\s*\(", text):
            common = path
            g = re.search(r'\bgetopt_long\s*\([^,]*,[^,]*,\s*"([^"]*)"', text)
            shorts = g.group(1).replace(":", "") if g else None
        for m in re.finditer(r"\bfe_cli_command\s+fe_cli_commands\s*\[\s*\]\s*=\s*\{(.*?)\};",
                             text, re.S):
            commands += re.findall(r'\{\s*"(\w+)"\s*,', m.group(1))
    problems = []
    if shorts is None:
        problems.append("src/cli: cannot find the getopt_long call of fe_cli_options")
    used = {(p, t) for p, _, t in calls}
    common_tables = [k for k in tables if k[0] == common and k not in used]
    if common is None or len(common_tables) != 1:
        problems.append("src/cli: cannot find the table of the options every command takes "
                        "(the fe_cli_option table of the file defining fe_cli_options)")
        return {}, {}, problems
    everyone = tables[common_tables[0]]
    options = {}
    for path, cmd, table in calls:
        if (path, table) not in tables:
            problems.append("%s: fe_cli_options(\"%s\", %s, ...): no fe_cli_option %s[] "
                            "in that file" % (path, cmd, table, table))
            continue
        options[cmd] = dict(tables[(path, table)])
        options[cmd].update(everyone)
    if not commands:
        problems.append("src/cli: cannot find the command table fe_cli_commands[]")
    for cmd in commands:
        if cmd not in options:
            problems.append("src/cli: command %s: no fe_cli_options call names its table" % cmd)
    short = {}
    for letter in shorts or "":
        names = [o for o in everyone if o[2:3] == letter.lower()]
        if len(names) != 1:
            problems.append("%s: short option -%s: not one option of %s begins with '%s'"
                            % (common, letter, common_tables[0][1], letter.lower()))
        else:
            short["-" + letter] = names[0]
    return {c: o for c, o in options.items() if c in commands}, short, problems


# ------------------------------------------------------------------ the tests


def fields_of(tokens):
    """The field names of a structure's body, in order."""
    fields = []
    for decl in split_on(tokens, ";"):
        for part in split_on(decl, ","):
            ids = []
            for kind, t in part:
                if (kind, t) == ("punct", "["):
                    break
                if kind == "id":
                    ids.append(t)
            if ids:
                fields.append(ids[-1])
    return fields


def literals(expr):
    """The strings an expression of literals (or a ?: between them) can be;
    none for a call."""
    if expr and expr[0][0] == "id" and any(tok == ("punct", "(") for tok in expr[1:]):
        return []
    return [t for k, t in expr if k == "str"]


def argv_line(parts):
    """An argv array's elements as one command line: literals as they
    are, anything else a conversion, up to NULL."""
    words = []
    for p in parts:
        if p == [("id", "NULL")]:
            break
        words.append(p[0][1] if len(p) == 1 and p[0][0] == "str" else "%s")
    return " ".join(words)


def expression_at(tokens, i):
    """The expression from tokens[i] to the next ',' or ';' outside brackets."""
    depth = 0
    for j in range(i, len(tokens)):
        kind, t = tokens[j]
        if kind != "punct":
            continue
        if t in "([{":
            depth += 1
        elif t in ")]}":
            if depth == 0:
                return tokens[i:j]
            depth -= 1
        elif t in ",;" and depth == 0:
            return tokens[i:j]
    return tokens[i:]


def find_tables(it, structs, into):
    """NAME[...] = {...} in an item: {NAME: (fields, elements)}, fields the
    structure of its rows (None for a table of strings or of argv arrays)."""
    for i in range(len(it) - 1):
        if it[i][0] != "id" or it[i + 1] != ("punct", "["):
            continue
        j = i + 1
        while j < len(it) and it[j] == ("punct", "["):
            j = matching(it, j) + 1
        if not (j + 1 < len(it) and it[j] == ("punct", "=") and it[j + 1] == ("punct", "{")):
            continue
        fields, k = None, i - 1
        while k >= 0 and (it[k][0] == "id" or it[k] in (("punct", "*"), ("punct", "}"))):
            if it[k] == ("punct", "}"):             # struct { ... } NAME[]
                k0 = k
                while k0 >= 0 and it[k0] != ("punct", "{"):
                    k0 -= 1
                if k0 > 0 and it[k0 - 1] == ("id", "struct"):
                    fields = fields_of(it[k0 + 1:k])
                break
            if it[k] == ("id", "struct") and k + 1 < i:
                fields = structs.get(it[k + 1][1], [])
                break
            k -= 1
        into[it[i][1]] = (fields, split_commas(it[j + 2:matching(it, j + 1)]))


class Unit:
    """A file of tests: its items (top-level definitions and macros), the
    structures and tables it defines, the variables it declares at file
    scope and the command lines built into them."""

    def __init__(self, path):
        self.path = path
        macros, tokens = split_source(open(path, encoding="utf-8").read())
        self.items = [(item_name(it), it) for it in top_level(tokens)]
        self.items += [(name, body) for name, body in macros if body]
        self.structs, self.tables, self.globals, self.built = {}, {}, set(), {}
        for _, it in self.items:
            for i in range(len(it) - 2):
                if it[i] == ("id", "struct") and it[i + 1][0] == "id" \
                        and it[i + 2] == ("punct", "{"):
                    self.structs[it[i + 1][1]] = fields_of(it[i + 3:matching(it, i + 2)])
        for name, it in self.items:
            find_tables(it, self.structs, self.tables)
            if it[-1] == ("punct", ";") and ("punct", "(") not in it:
                self.globals.add(name)

    def table(self, name, local):
        return local.get(name) or self.tables.get(name)

    def field_values(self, table, field, local):
        """The strings a field of a table of structures holds."""
        tab = self.table(table, local)
        if tab is None or not tab[0] or field not in tab[0]:
            return None
        out = []
        for row in tab[1]:
            if row[0] != ("punct", "{"):
                continue
            for n, part in enumerate(split_commas(row[1:matching(row, 0)])):
                if part[0] == ("punct", ".") and len(part) > 3:     # .field = value
                    if part[1][1] == field:
                        out += literals(part[3:])
                elif n < len(tab[0]) and tab[0][n] == field:
                    out += literals(part)
        return out

    def elements(self, table, local):
        """The strings of a table of strings; an argv array's as one line."""
        tab = self.table(table, local)
        if tab is None or tab[0]:
            return None
        out = []
        for el in tab[1]:
            if el[0] == ("punct", "{"):
                out.append(argv_line(split_commas(el[1:matching(el, 0)])))
            else:
                out += literals(el)
        return out


class Block:
    """One item of a test file, with what its variables can hold: literals
    assigned to them, FE_TEST_CLI, the row of a table they point at, and
    the command lines snprintf builds into them."""

    def __init__(self, unit, name, tokens):
        self.unit, self.name, self.tokens = unit, name, tokens
        self.tables, self.values, self.rows = {}, {}, {}
        find_tables(tokens, unit.structs, self.tables)
        for i in range(1, len(tokens) - 1):
            if tokens[i] != ("punct", "=") or tokens[i - 1][0] != "id":
                continue
            var, expr = tokens[i - 1][1], expression_at(tokens, i + 1)
            if expr == [("id", "FE_TEST_CLI")]:
                self.add(var, [CLI])
            elif len(expr) > 2 and expr[0] == ("punct", "&") and expr[1][0] == "id" \
                    and expr[2] == ("punct", "["):
                self.rows[var] = expr[1][1]         # c = &cases[_i]
            elif len(expr) > 1 and expr[0][0] == "id" and expr[1] == ("punct", "+") \
                    or len(expr) == 1 and self.unit.table(expr[0][1], self.tables):
                self.rows[var] = expr[0][1]         # c = cases + k, c = cases
            else:
                self.add(var, self.resolve(expr) or [])

    def add(self, var, values):
        have = self.values.setdefault(var, [])
        for v in values:
            if v not in have and len(have) < 512:
                have.append(v)

    def build(self):
        """Follow the snprintf calls, in order, into their variables."""
        for i in range(len(self.tokens) - 1):
            if self.tokens[i][0] != "id" or self.tokens[i][1] not in BUILDERS \
                    or self.tokens[i + 1] != ("punct", "("):
                continue
            args = split_commas(self.tokens[i + 2:matching(self.tokens, i + 1)])
            at = 2 if self.tokens[i][1] == "snprintf" else 1
            if len(args) <= at or len(args[0]) != 1 or args[0][0][0] != "id" \
                    or len(args[at]) != 1 or args[at][0][0] != "str":
                continue
            lines = expand(args[at][0][1], args[at + 1:], self)
            var = args[0][0][1]
            self.add(var, lines)
            if var in self.unit.globals:
                have = self.unit.built.setdefault(var, [])
                have += [v for v in lines if v not in have]

    def resolve(self, expr):
        """The strings an argument can be, or None when the test does not say."""
        if len(expr) > 3 and expr[0] == ("punct", "(") and expr[1] in (("id", "char"),
                                                                      ("id", "const")):
            expr = expr[matching(expr, 0) + 1:]     # a cast
        if expr == [("id", "FE_TEST_CLI")]:
            return [CLI]
        if len(expr) == 1 and expr[0][0] == "id":
            v = expr[0][1]
            return self.values.get(v) or self.unit.built.get(v)
        if len(expr) == 3 and expr[0][0] == "id" and expr[1][1] in ("->", ".") \
                and expr[2][0] == "id" and expr[0][1] in self.rows:
            return self.unit.field_values(self.rows[expr[0][1]], expr[2][1], self.tables)
        if len(expr) >= 4 and expr[0][0] == "id" and expr[1] == ("punct", "["):
            j = matching(expr, 1)
            if j == len(expr) - 1:
                return self.unit.elements(expr[0][1], self.tables)
            if j == len(expr) - 3 and expr[j + 1][1] == "." and expr[j + 2][0] == "id":
                return self.unit.field_values(expr[0][1], expr[j + 2][1], self.tables)
        return literals(expr) or None


def runners(unit):
    """The library's functions that run a command, and the file's functions
    that call one of them."""
    found = set(RUNNERS)
    calls = {name: {t for k, t in it if k == "id"} for name, it in unit.items}
    changed = True
    while changed:
        changed = False
        for name, ids in calls.items():
            if name not in found and ids & found:
                found.add(name)
                changed = True
    return found


def names_options(text):
    """Does a value say something of a command line: a command's name
    first, or a word that begins with '-'?"""
    words = text.split()
    return bool(words) and (words[0] in COMMANDS or any(w.startswith("-") for w in words))


def expand(fmt, args, block):
    """The command lines a format can give: each conversion whose argument
    names a command or an option is replaced by each value it can take;
    FE_TEST_CLI and the other arguments (paths, numbers) stay conversions."""
    pieces, pos, seq = [], 0, 0
    for m in CONV.finditer(fmt):
        pieces.append([fmt[pos:m.start()]])
        pos = m.end()
        if m.group(0) == "%%":
            pieces.append(["%%"])
            continue
        if m.group(2) == "*":
            seq += 1
        if m.group(1):
            n = int(m.group(1)[:-1]) - 1
        else:
            n, seq = seq, seq + 1
        vals = block.resolve(args[n]) if n < len(args) else None
        if vals and CLI not in vals and any(names_options(v) for v in vals):
            pieces.append(sorted(set(vals)))
        else:
            pieces.append(["%s" if vals and CLI in vals else m.group(0)])
    pieces.append([fmt[pos:]])
    return ["".join(c) for c in itertools.islice(itertools.product(*pieces), 512)]


COMMANDS = set()


def uses(line, options, short):
    """(command, option, shown) for each option that follows a command's
    name, the name first in the line or after a conversion; shown is the
    command line from the name to the option's value."""
    words = line.split()
    out = []
    for i, w in enumerate(words):
        if w not in options or not (i == 0 or CONV_WORD.match(words[i - 1])):
            continue
        for j in range(i + 1, len(words)):
            v = words[j]
            if v in STOP or v.endswith(";"):
                break
            name = short.get(v, v.split("=", 1)[0] if v.startswith("--") else None)
            if name in options[w]:
                shown = words[i:j + 2]
                if len(" ".join(shown)) > 90:
                    shown = [w, "..."] + words[j:j + 2]
                out.append((w, name, " ".join(shown)))
    return out


def initialisers(tokens):
    """(contents, rows) for each brace group that is an initialiser: after
    '=', inside another initialiser, or a macro's body; rows is true for
    the initialiser of a structure or of a table of structures."""
    out = []

    def walk(i, end):
        while i < end:
            if tokens[i] == ("punct", "{"):
                j = matching(tokens, i)
                if i == 0 or tokens[i - 1] == ("punct", "="):
                    k = i - 1
                    while k > 0 and tokens[k - 1] not in (("punct", ";"), ("punct", "{"),
                                                          ("punct", "}")):
                        k -= 1
                    collect(i, j, ("id", "struct") in tokens[k:i])
                else:
                    walk(i + 1, j)
                i = j + 1
            else:
                i += 1

    def collect(i, j, rows):
        out.append((tokens[i + 1:j], rows))
        k = i + 1
        while k < j:
            if tokens[k] == ("punct", "{"):
                m = matching(tokens, k)
                collect(k, m, rows)
                k = m + 1
            else:
                k += 1

    walk(0, len(tokens))
    return out


def coverage(options, short):
    """{(command, option): 'file: item: command line'} for each pair a test uses."""
    found = {}

    def note(line, where):
        for cmd, opt, shown in uses(line, options, short):
            found.setdefault((cmd, opt), "%s: %s" % (where, shown))

    for path in sorted(glob.glob("tests/*.c")):
        unit = Unit(path)
        run = runners(unit) | BUILDERS
        blocks = [Block(unit, name, tokens) for name, tokens in unit.items]
        for _ in range(2):      # a global built in one function, read in another
            for b in blocks:
                b.build()
        for b in blocks:
            where, tokens = "%s: %s" % (path, b.name), b.tokens
            # Initialisers: tables of command lines, argv arrays, variables.
            for i, (kind, t) in enumerate(tokens):
                if kind == "str" and i > 0 and tokens[i - 1] == ("punct", "="):
                    note(t, where)
            for group, rows in initialisers(tokens):
                if rows:
                    continue    # a structure's fields: read where a test uses them
                parts = split_commas(group)
                for p in parts:
                    if len(p) == 1 and p[0][0] == "str":
                        note(p[0][1], where)
                if parts and len(parts[0]) == 1 and parts[0][0][0] == "str" \
                        and parts[0][0][1] in options:
                    note(argv_line(parts), where)
            # Calls of what runs a command or builds one.
            for i in range(len(tokens) - 1):
                if tokens[i][0] != "id" or tokens[i][1] not in run \
                        or tokens[i + 1] != ("punct", "("):
                    continue
                args = split_commas(tokens[i + 2:matching(tokens, i + 1)])
                for k, a in enumerate(args):
                    if len(a) == 1 and a[0][0] == "str":
                        for line in expand(a[0][1], args[k + 1:], b):
                            note(line, where)
                    elif tokens[i][1] not in BUILDERS:
                        for line in b.resolve(a) or ():
                            note(line, where)
    return found


def main():
    verbose = "-v" in sys.argv[1:]
    options, short, problems = parser_options()
    COMMANDS.update(options)
    found = coverage(options, short) if options else {}
    explained = ledger.load_explained(LEDGER, "command --option reason")
    if explained is None:
        return 1
    pairs = sorted((c, o) for c in options for o in options[c])
    n_used, n_explained, gaps, stale = ledger.tally(
        pairs, found, explained, LEDGER, ("used", 10),
        lambda p: "foldest %s %s: no test runs the command with the option" % p, verbose)
    for (c, o), (lineno, _) in sorted(explained.items()):
        if o not in options.get(c, {}):
            stale.append("options_explained.txt:%d: %s %s is not an option of the command"
                         % (lineno, c, o))
    print("options: %d commands, %d (command, option) pairs: %d used by a test, "
          "%d explained, %d gaps" % (len(options), len(pairs), n_used, n_explained, len(gaps)))
    for line in problems + gaps + stale:
        print(line)
    return 1 if problems or gaps or stale else 0


if __name__ == "__main__":
    sys.exit(main())
