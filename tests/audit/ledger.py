# SPDX-License-Identifier: MIT
"""What the audits share: the file of pairs explained by hand, and the
tally of pairs against the tests that account for them.

A ledger file has one pair a line, `first second reason` (blank lines and
lines starting with # skipped).  A pair is accounted for by a test (found),
by the ledger (explained), or not at all (a gap); a ledger entry for a pair
a test now accounts for, or for a pair that no longer exists, is stale and
fails the audit as a gap does."""


def load_explained(path, form):
    """{(first, second): (line number, reason)} from the ledger at `path`,
    or None after printing the first line not of the form `form`."""
    explained = {}
    name = path.rsplit("/", 1)[-1]
    with open(path, encoding="utf-8") as f:
        for lineno, line in enumerate(f, 1):
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            parts = line.split(None, 2)
            if len(parts) < 3:
                print("%s:%d: want `%s`" % (name, lineno, form))
                return None
            explained[(parts[0], parts[1])] = (lineno, parts[2])
    return explained


def tally(pairs, found, explained, path, labels, gap, verbose):
    """Sort the pairs (first, second) into found, explained and gaps.
    `labels` names the found kind and a column width for -v (("tested", 34));
    `gap(pair)` is a gap's message.  Returns (found, explained, gaps, stale
    entries of the ledger at `path` for pairs a test accounts for)."""
    word, width = labels
    name = path.rsplit("/", 1)[-1]
    n_found, n_explained, gaps, stale = 0, 0, [], []
    for p in pairs:
        if p in found:
            n_found += 1
            if p in explained:
                stale.append("%s:%d: %s %s is %s now (%s)"
                             % (name, explained[p][0], p[0], p[1], word, found[p]))
            elif verbose:
                print("%-9s %-*s %-16s %s" % (word, width, p[0], p[1], found[p]))
        elif p in explained:
            n_explained += 1
            if verbose:
                print("explained %-*s %-16s %s" % (width, p[0], p[1], explained[p][1]))
        else:
            gaps.append(gap(p))
    return n_found, n_explained, gaps, stale
