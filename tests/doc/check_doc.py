#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Open every woven page in headless Chromium, as a reader would, and fail
when the mathematics did not render.

Used as: python3 tests/doc/check_doc.py build/doc

Each page is loaded from disk (file://, no network, no display) with
`chromium --headless --no-sandbox --dump-dom`.  The pages mark their root
element with data-mathjax="done" once MathJax has typeset them (a hook that
literate/tangle.el writes into every page), so the check knows MathJax ran
to the end instead of guessing a delay.  In the rendered document, outside
<pre>, <code>, <script> and <style> and outside MathJax's own output, the
text must hold no raw TeX: no \\begin, \\end, \\mathsf, \\frac, \\[, \\], \\(,
\\) nor any other backslash command; and no MathJax error may be shown
(merror, noError, "Math Processing Error", or an undefined macro, which
MathJax typesets as its name in red).  Every image must have loaded (the
figures make doc draws into figures/: a page that names one that is not
there fails).  The index of the public API
(api.html) must list every public name of the headers (no "api-missing").  One line per failing page,
then "N passed, N failed".  Standard library only.
"""
import html
import html.parser
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

BUDGET_MS = 120000   # virtual time; unused time is skipped once the page is idle
TIMEOUT_S = 100      # real time for the whole book
RAW_TEX = re.compile(r"\\(?:[A-Za-z]+|\[|\]|\(|\))")
SKIP = {"script", "style", "pre", "code", "head", "title"}
VOID = {"area", "base", "br", "col", "embed", "hr", "img", "input", "link",
        "meta", "source", "track", "wbr"}
ERROR_CLASSES = {"merror", "noError", "MathJax_Error"}


class Rendered(html.parser.HTMLParser):
    """The text a reader sees outside code and outside typeset maths, and the
    MathJax errors shown anywhere."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.stack = []          # (tag, hides text, is an error, is typeset maths)
        self.hidden = 0
        self.maths = 0
        self.math_text = []
        self.text = []
        self.errors = []
        self.done = False
        self.in_error = 0

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "html" and a.get("data-mathjax") == "done":
            self.done = True
        if tag in VOID:
            return
        classes = set((a.get("class") or "").split())
        hides = tag in SKIP or any(c.startswith("MathJax") for c in classes)
        is_error = bool(classes & ERROR_CLASSES)
        is_maths = "MathJax" in classes or "MathJax_Display" in classes
        self.stack.append((tag, hides, is_error, is_maths))
        self.hidden += hides
        self.maths += is_maths
        if is_error:
            self.in_error += 1
            self.errors.append("")

    def handle_endtag(self, tag):
        if tag in VOID:
            return
        while self.stack:
            t, hides, is_error, is_maths = self.stack.pop()
            self.hidden -= hides
            self.maths -= is_maths
            self.in_error -= is_error
            if t == tag:
                break

    def handle_data(self, data):
        if self.in_error:
            self.errors[-1] += data
        if not self.hidden:
            self.text.append(data)
        elif self.maths:
            self.math_text.append(data)
        if "Math Processing Error" in data:
            self.errors.append("Math Processing Error")


HARNESS = """<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>check-doc</title></head><body>
<script>
var pages = %s, left = pages.length, frames = [];
pages.forEach(function (url, i) {
  var f = document.createElement('iframe');
  f.style.width = '1000px'; f.style.height = '700px';
  f.src = url; document.body.appendChild(f); frames.push(f);
});
function poll() {
  frames.forEach(function (f, i) {
    if (!f || document.getElementById('page-' + i)) return;
    var d = null;
    try { d = f.contentDocument; } catch (e) {}
    if (d && d.documentElement && d.documentElement.getAttribute('data-mathjax') === 'done') {
      Array.prototype.forEach.call(d.images, function (img) {
        if (!img.complete || img.naturalWidth === 0) img.setAttribute('data-broken', 'yes');
      });
      var t = document.createElement('textarea');
      t.id = 'page-' + i; t.textContent = d.documentElement.outerHTML;
      document.body.appendChild(t); f.remove(); frames[i] = null; left--;
    }
  });
  if (left > 0) setTimeout(poll, 100);
  else document.documentElement.setAttribute('data-all', 'done');
}
setTimeout(poll, 100);
</script></body></html>
"""


def render_all(chromium, pages):
    """Open every page in one headless Chromium (one iframe each, so the
    browser starts once), and return {page: rendered DOM or None}."""
    tmp = tempfile.mkdtemp(prefix="check-doc-")
    try:
        harness = os.path.join(tmp, "harness.html")
        urls = ["file://" + os.path.abspath(p) for p in pages]
        with open(harness, "w", encoding="utf-8") as f:
            f.write(HARNESS % json.dumps(urls))
        out = subprocess.run(
            [chromium, "--headless", "--no-sandbox", "--disable-gpu",
             "--no-first-run", "--disable-extensions", "--disable-web-security",
             "--allow-file-access-from-files", "--user-data-dir=" + os.path.join(tmp, "profile"),
             "--virtual-time-budget=%d" % BUDGET_MS, "--dump-dom", "file://" + harness],
            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
            timeout=TIMEOUT_S, check=False)
        dom = out.stdout.decode("utf-8", "replace")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    found = {}
    for m in re.finditer(r'<textarea id="page-(\d+)">(.*?)</textarea>', dom, re.S):
        found[pages[int(m.group(1))]] = html.unescape(m.group(2))
    return {p: found.get(p) for p in pages}


def check(dom):
    """A list of problems of one rendered page, empty when it reads well."""
    if dom is None:
        return ["MathJax did not finish typesetting (or the page did not load)"]
    r = Rendered()
    r.feed(dom)
    problems = []
    if 'class="api-missing"' in dom:
        problems.append("the API index misses names the headers declare (see the page)")
    if not r.done:
        problems.append("MathJax did not finish typesetting")
    for m in re.finditer(r'<img\b[^>]*\bdata-broken="yes"[^>]*>', dom):
        src = re.search(r'\bsrc="([^"]*)"', m.group(0))
        problems.append("image did not load: " + (src.group(1) if src else m.group(0)[:80]))
    for e in r.errors:
        problems.append("MathJax error: " + " ".join(e.split())[:120])
    for m in re.finditer(r"\\[A-Za-z]+", "".join(r.math_text)):
        problems.append("MathJax shows an undefined macro: " + m.group(0))
    text = re.sub(r"\s+", " ", "".join(r.text))
    for m in RAW_TEX.finditer(text):
        ctx = text[max(0, m.start() - 40):m.end() + 40]
        problems.append("raw TeX %s in: ...%s..." % (m.group(0), ctx))
    return problems


def main(argv):
    if len(argv) < 2:
        sys.stderr.write("usage: check_doc.py DOCDIR\n")
        return 2
    docdir = argv[1]
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if not chromium:
        sys.stderr.write("check-doc: chromium is not installed (make deps installs it)\n")
        return 2
    pages = sorted(os.path.join(docdir, f) for f in os.listdir(docdir) if f.endswith(".html"))
    if not pages:
        sys.stderr.write("check-doc: no .html in %s (run make doc)\n" % docdir)
        return 2
    failed = 0
    try:
        rendered = render_all(chromium, pages)
    except subprocess.TimeoutExpired:
        sys.stderr.write("check-doc: Chromium did not finish within %d s\n" % TIMEOUT_S)
        return 1
    for page in pages:
        problems = check(rendered[page])
        if problems:
            failed += 1
            print("check-doc: %s: %d problem(s)" % (page, len(problems)))
            for p in problems:
                print("  " + p)
    print("check-doc: %d pages opened in headless Chromium after MathJax" % len(pages))
    print("check-doc: %d passed, %d failed" % (len(pages) - failed, failed))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
