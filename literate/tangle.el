;;; tangle.el --- pinned settings for tangling and weaving foldest  -*- lexical-binding: t -*-
;; SPDX-License-Identifier: MIT
;;
;; Used as: emacs --batch -Q -l literate/tangle.el -f fe-tangle FILE.org...
;;      and: emacs --batch -Q -l literate/tangle.el -f fe-weave OUTDIR FILE.org...
;; Every setting that changes what Org writes is fixed here, so that the
;; tangled sources are the same on every machine with Org 9.5 or later.

(require 'org)
(require 'ob-tangle)
(require 'ox-html)

(setq org-src-preserve-indentation t        ; blocks are written flush-left
      org-babel-tangle-use-relative-file-links t
      org-confirm-babel-evaluate nil
      org-export-use-babel nil              ; weaving runs no code
      org-html-validation-link nil
      org-html-htmlize-output-type nil      ; no htmlize package needed
      make-backup-files nil
      org-id-track-globally nil)

(defun fe-tangle ()
  "Tangle every .org file named on the command line."
  (dolist (file command-line-args-left)
    (org-babel-tangle-file file))
  (setq command-line-args-left nil))

(defun fe-weave ()
  "Weave the .org files named after the output directory into HTML there.
MathJax is read from Debian's local copy, so the pages render offline."
  (let ((outdir (file-name-as-directory (expand-file-name (pop command-line-args-left)))))
    (setq org-html-mathjax-options
          '((path "file:///usr/share/javascript/mathjax/MathJax.js?config=TeX-AMS_HTML")
            (scale "100") (align "center") (font "TeX") (linebreaks "false")
            (autonumber "AMS") (indent "0em") (multlinewidth "85%")
            (tagindent ".8em") (tagside "right")))
    ;; The root element says when MathJax has typeset the page (or that the
    ;; page has no mathematics), so that make check-doc reads the page then.
    (setq org-html-head-extra
          (concat "<script>window.addEventListener('load', function () {\n"
                  "  function done() { document.documentElement.setAttribute('data-mathjax', 'done'); }\n"
                  "  if (window.MathJax && MathJax.Hub) MathJax.Hub.Register.StartupHook('End', done); else done();\n"
                  "});</script>"))
    (dolist (file command-line-args-left)
      (with-current-buffer (find-file-noselect file)
        (let ((out (concat outdir (file-name-base file) ".html")))
          (org-export-to-file 'html out)
          (message "Wove %s -> %s" file out))))
    (setq command-line-args-left nil)))
