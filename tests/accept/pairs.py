# SPDX-License-Identifier: MIT
"""One generated recording/simulation pair, for run.py and user_terms.py."""
import json
import os
import shlex
import subprocess
import time


def generate(gen, case, seed, out_dir):
    """Run generator `gen` for `case` and `seed` into out_dir: the foldest
    arguments it prints, its truth.json, and the seconds it took."""
    t0 = time.time()
    g = subprocess.run([gen, "--case", case, "--seed", str(seed), "--out", out_dir],
                       capture_output=True, text=True)
    seconds = time.time() - t0
    if g.returncode != 0:
        raise RuntimeError("%s %s %d: %s" % (os.path.basename(gen), case, seed, g.stderr))
    with open(os.path.join(out_dir, "truth.json")) as f:
        truth = json.load(f)
    return shlex.split(g.stdout.strip()), truth, seconds
