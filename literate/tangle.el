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
(require 'seq)
(require 'subr-x)

(defvar fe--literate-dir (file-name-directory (or load-file-name buffer-file-name))
  "The directory of this file, where book.css lives too.")

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

;; The book: index.org first, then the chapters in the order its list of
;; chapters links them; a page the index does not link comes last.  Every
;; page has the same bar above and below: previous chapter, the contents
;; (index.html#chapters), next chapter; and the stylesheet book.css.

(defun fe--org-title (file)
  "The #+TITLE of FILE, or its base name."
  (with-temp-buffer
    (insert-file-contents file)
    (if (re-search-forward "^#\\+TITLE:[ \t]*\\(.*\\)$" nil t)
        (string-trim (match-string 1))
      (file-name-base file))))

(defun fe--reading-order (files)
  "FILES ordered as the book reads them: index.org, then its links."
  (let* ((index (seq-find (lambda (f) (string= (file-name-base f) "index")) files))
         (order (and index (list index))))
    (when index
      (with-temp-buffer
        (insert-file-contents index)
        (while (re-search-forward "\\[\\[file:\\([^]]+\\)\\.org\\]" nil t)
          (let* ((base (file-name-base (match-string 1)))
                 (f (seq-find (lambda (g) (string= (file-name-base g) base)) files)))
            (when (and f (not (member f order)))
              (setq order (append order (list f))))))))
    (dolist (f files)
      (unless (member f order)
        (message "Weave: %s is not linked from index.org; it comes last" f)
        (setq order (append order (list f)))))
    order))

(defun fe--nav (prev next)
  "The navigation bar between PREV and NEXT, each (FILE . TITLE) or nil."
  (let ((link (lambda (page rel arrow)
                (if page
                    (format "<a class=\"%s\" rel=\"%s\" href=\"%s.html\">%s</a>" rel rel
                            (file-name-base (car page))
                            (if (string= rel "prev")
                                (concat arrow " " (org-html-encode-plain-text (cdr page)))
                              (concat (org-html-encode-plain-text (cdr page)) " " arrow)))
                  (format "<span class=\"%s\"></span>" rel)))))
    (concat "<nav class=\"book-nav\">"
            (funcall link prev "prev" "&larr;")
            "<a class=\"contents\" href=\"index.html#chapters\">Contents</a>"
            (funcall link next "next" "&rarr;")
            "</nav>")))

(defun fe-weave ()
  "Weave the .org files named after the output directory into HTML there,
as a book (see `fe--reading-order').  MathJax is read from Debian's local
copy and the stylesheet is copied beside the pages, so the book is offline."
  (let* ((outdir (file-name-as-directory (expand-file-name (pop command-line-args-left))))
         (files (mapcar #'expand-file-name command-line-args-left))
         (order (fe--reading-order files))
         (pages (mapcar (lambda (f) (cons f (fe--org-title f))) order))
         (css (expand-file-name "book.css" fe--literate-dir)))
    (copy-file css (concat outdir "book.css") t)
    (setq org-html-mathjax-options
          '((path "file:///usr/share/javascript/mathjax/MathJax.js?config=TeX-AMS_HTML")
            (scale "100") (align "center") (font "TeX") (linebreaks "false")
            (autonumber "AMS") (indent "0em") (multlinewidth "85%")
            (tagindent ".8em") (tagside "right")))
    (setq org-html-doctype "html5"
          org-html-html5-fancy t
          org-html-head-include-default-style nil
          org-html-head "<link rel=\"stylesheet\" href=\"book.css\">")
    (let ((prev nil) (rest pages))
      (while rest
        (let* ((page (car rest)) (next (cadr rest)) (file (car page))
               (nav (fe--nav prev next)))
          ;; The root element says when MathJax has typeset the page (or that
          ;; the page has no mathematics), so that make check-doc reads it then.
          (setq org-html-head-extra
                (concat "<script>window.addEventListener('load', function () {\n"
                        "  function done() { document.documentElement.setAttribute('data-mathjax', 'done'); }\n"
                        "  if (window.MathJax && MathJax.Hub) MathJax.Hub.Register.StartupHook('End', done); else done();\n"
                        "});</script>"
                        (if prev (format "\n<link rel=\"prev\" href=\"%s.html\">" (file-name-base (car prev))) "")
                        (if next (format "\n<link rel=\"next\" href=\"%s.html\">" (file-name-base (car next))) "")
                        "\n<link rel=\"contents\" href=\"index.html#chapters\">")
                org-html-preamble (lambda (_info) nav)
                org-html-postamble (lambda (_info) nav))
          (with-current-buffer (find-file-noselect file)
            (let ((out (concat outdir (file-name-base file) ".html")))
              (org-export-to-file 'html out)
              (message "Wove %s -> %s" (file-relative-name file) out)))
          (setq prev page rest (cdr rest)))))
    (setq command-line-args-left nil)))
