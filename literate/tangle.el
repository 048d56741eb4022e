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
(require 'xml)

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

;; Fragments as pbrt shows them.  Every code block of the woven page
;; starts with a line naming its fragment and the file it tangles into, and
;; carries an anchor; a noweb reference <<name>> is a link to the fragment
;; of that name; a fragment used by others says which ("Used in ...").
;; Blocks tangled into include/ also feed the index of the public API.

(defvar fe--uses nil "Fragment name -> list of (LABEL . ANCHOR) of the blocks using it, this page.")
(defvar fe--anchors nil "Fragment name -> anchor, this page.")
(defvar fe--block-count 0 "Code blocks exported so far, this page.")
(defvar fe--page nil "The base name of the page being woven.")
(defvar fe--api nil "List of (NAME KIND PAGE ANCHOR FRAGMENT) for the public API index.")

(defun fe--slug (name)
  (concat "frag-" (string-trim (replace-regexp-in-string "[^a-z0-9]+" "-" (downcase name)) "-" "-")))

(defun fe--tangle-file (params)
  "The file a block with header arguments PARAMS tangles into, relative to
the project's root, or nil."
  (let ((tangle (cdr (assq :tangle (org-babel-parse-header-arguments (or params ""))))))
    (and tangle (not (member tangle '("no" "yes")))
         (replace-regexp-in-string "\\`\\(\\.\\./\\)+" "" tangle))))

(defun fe--collect-fragments ()
  "Read the current buffer's code blocks: their anchors and who uses whom."
  (setq fe--uses (make-hash-table :test 'equal)
        fe--anchors (make-hash-table :test 'equal)
        fe--block-count 0)
  (let ((n 0))
    (org-element-map (org-element-parse-buffer) 'src-block
      (lambda (b)
        (setq n (1+ n))
        (let* ((name (org-element-property :name b))
               (anchor (if name (fe--slug name) (format "block-%d" n)))
               (label (or name (fe--tangle-file (org-element-property :parameters b))))
               (body (org-element-property :value b))
               (start 0))
          (when (and name (not (gethash name fe--anchors)))
            (puthash name anchor fe--anchors))
          (while (string-match "<<\\([^<>\n]+?\\)>>" body start)
            (let ((used (match-string 1 body))
                  (user (cons (or label "an unnamed block") anchor)))
              (unless (member user (gethash used fe--uses))
                (puthash used (append (gethash used fe--uses) (list user)) fe--uses)))
            (setq start (match-end 0))))))))

(defun fe--api-names (body)
  "The public names a header block BODY declares: (NAME . KIND)."
  (let ((code (replace-regexp-in-string "/\\*\\(?:.\\|\n\\)*?\\*/" "" body))
        (found nil))
    (dolist (rule '(("^[ \t]*#[ \t]*define[ \t]+\\(FE_[A-Za-z0-9_]+\\)" . "macro")
                    ("typedef[^;{]*?(\\*[ \t]*\\(fe_[a-z0-9_]+\\))" . "type")
                    ("}[ \t]*\\(fe_[a-z0-9_]+\\)[ \t]*;" . "type")
                    ("^typedef[^;{(]*[ \t*]\\(fe_[a-z0-9_]+\\)[ \t]*;" . "type")
                    ("^[ \t]*\\(?:typedef[ \t]+\\)?\\(?:struct\\|enum\\|union\\)[ \t]+\\(fe_[a-z0-9_]+\\)[ \t]*{" . "type")
                    ("^\\(?:[A-Za-z_][A-Za-z0-9_]*[ \t*]+\\)+\\(fe_[a-z0-9_]+\\)[ \t]*(" . "function")))
      (let ((start 0))
        (while (string-match (car rule) code start)
          (let ((name (match-string 1 code)))
            (unless (or (assoc name found) (string-prefix-p "fe__" (downcase name))
                        (string-match-p "\\`return\\b" (match-string 0 code)))
              (push (cons name (cdr rule)) found)))
          (setq start (match-end 0)))))
    ;; The constants of an enumeration: the name that starts each item.
    (let ((start 0))
      (while (string-match "enum[ \t\n]*[A-Za-z0-9_]*[ \t\n]*{\\([^}]*\\)}" code start)
        (let ((body (match-string 1 code)))
          (setq start (match-end 0))          ; before split-string moves the match data
          (dolist (item (split-string body ","))
            (when (string-match "\\`[ \t\n]*\\(FE_[A-Z0-9_]+\\)" item)
              (let ((name (match-string 1 item)))
                (unless (assoc name found) (push (cons name "constant") found))))))))
    (nreverse found)))

(defun fe--src-block (src-block contents info)
  "A code block as pbrt shows it: its fragment name, its file, its uses."
  (setq fe--block-count (1+ fe--block-count))
  (let* ((html (org-html-src-block src-block contents info))
         (name (org-element-property :name src-block))
         (file (fe--tangle-file (org-element-property :parameters src-block)))
         (anchor (if name (fe--slug name) (format "block-%d" fe--block-count)))
         (uses (and name (gethash name fe--uses))))
    ;; Noweb references become links to their fragment.
    (setq html (replace-regexp-in-string
                "&lt;&lt;\\([^&<>\n]+?\\)&gt;&gt;"
                (lambda (m)
                  (let* ((ref (match-string 1 m))
                         (target (gethash (xml-substitute-special ref) fe--anchors)))
                    (if target
                        (format "<a class=\"noweb-ref\" href=\"#%s\">&lt;&lt;%s&gt;&gt;</a>" target ref)
                      m)))
                html t t))
    (when (and file (string-prefix-p "include/" file))
      (dolist (n (fe--api-names (org-element-property :value src-block)))
        (push (list (car n) (cdr n) fe--page anchor (or name file)) fe--api)))
    (concat
     (format "<div class=\"fragment-head\" id=\"%s\">" anchor)
     (if name (format "<span class=\"fragment-name\">&lang;%s&rang;</span>"
                      (org-html-encode-plain-text name)) "")
     (if file (format "<span class=\"fragment-file\">&rarr; <code>%s</code></span>" file) "")
     "</div>\n"
     html
     (if uses
         (concat "<div class=\"fragment-uses\">Used in "
                 (mapconcat (lambda (u)
                              (format "<a href=\"#%s\">&lang;%s&rang;</a>" (cdr u)
                                      (org-html-encode-plain-text (car u))))
                            uses ", ")
                 ".</div>\n")
       ""))))

(org-export-define-derived-backend 'fe-html 'html
  :translate-alist '((src-block . fe--src-block)))

;; The index of the public API: every fe_/FE_ name the headers in include/
;; declare, linked to the block that declares it.  The names are read from
;; the blocks as they are woven, then compared with the tangled headers
;; themselves; a name found in a header but in no block is listed apart
;; (class api-missing), and make check-doc fails on it.

(defconst fe--api-page '("api" . "Index of the public API")
  "The page the index of the public API is written to, and its title.")

(defun fe--header-names ()
  "Every public name in include/foldest.h and include/foldest/*.h: each
fe_ or FE_ word outside comments, less the private ones (fe__... and FE__..., and a
macro's locals, which end in _)."
  (let* ((root (expand-file-name ".." fe--literate-dir))
         (headers (cons (expand-file-name "include/foldest.h" root)
                        (directory-files (expand-file-name "include/foldest" root) t "\\.h\\'")))
         (names nil))
    (dolist (h headers)
      (when (file-exists-p h)
        (let ((code (replace-regexp-in-string
                     "/\\*\\(?:.\\|\n\\)*?\\*/" ""
                     (with-temp-buffer (insert-file-contents h) (buffer-string))))
              (start 0))
          (while (string-match "\\_<\\(?:fe_[a-z0-9_]+\\|FE_[A-Z0-9_]+\\)\\_>" code start)
            (let ((name (match-string 0 code)))
              (unless (or (member name names) (string-prefix-p "fe__" (downcase name))
                          (string-suffix-p "_" name))
                (push name names)))
            (setq start (match-end 0))))))
    names))

(defun fe--write-api-page (outdir head nav titles)
  "Write the index of the public API to OUTDIR, with HEAD and NAV.
TITLES maps a page's base name to its title."
  (let ((entries nil) (missing nil))
    (dolist (e (reverse fe--api))
      (unless (assoc (car e) entries) (push e entries)))
    (setq entries (sort entries (lambda (a b) (string< (downcase (car a)) (downcase (car b))))))
    (dolist (n (fe--header-names))
      (unless (assoc n entries) (push n missing)))
    (with-temp-file (concat outdir (car fe--api-page) ".html")
      (insert "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
              "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
              "<title>" (cdr fe--api-page) "</title>\n" head "\n</head>\n<body>\n"
              "<div id=\"preamble\" class=\"status\">" nav "</div>\n"
              "<div id=\"content\" class=\"content\">\n<h1 class=\"title\">" (cdr fe--api-page) "</h1>\n"
              (format "<p>The %d public names of <code>include/foldest.h</code> and "
                      (length entries))
              "<code>include/foldest/*.h</code>: functions, types, macros and the "
              "constants of their enumerations, each linked to the block of the chapter "
              "that declares it; the paragraphs before that block explain it.</p>\n")
      (when missing
        (insert "<p class=\"api-missing\">Declared in a header but found in no block: "
                (mapconcat (lambda (n) (format "<code>%s</code>" n)) (sort missing #'string<) ", ")
                ".</p>\n")
        (message "Weave: the API index misses %s" (mapconcat #'identity missing " ")))
      (insert "<table class=\"api-index\">\n<thead><tr><th>Name</th><th>Kind</th>"
              "<th>Chapter</th><th>Fragment</th></tr></thead>\n<tbody>\n")
      (dolist (e entries)
        (let ((name (nth 0 e)) (kind (nth 1 e)) (page (nth 2 e)) (anchor (nth 3 e)) (frag (nth 4 e)))
          (insert (format "<tr id=\"%s\"><td><a href=\"%s.html#%s\"><code>%s</code></a></td><td>%s</td><td><a href=\"%s.html\">%s</a></td><td>%s</td></tr>\n"
                          name page anchor name kind page
                          (org-html-encode-plain-text (or (cdr (assoc page titles)) page))
                          (org-html-encode-plain-text frag)))))
      (insert "</tbody>\n</table>\n</div>\n<div id=\"postamble\" class=\"status\">" nav
              "</div>\n</body>\n</html>\n"))
    (message "Wove the API index (%d names) -> %s%s.html" (length entries) outdir (car fe--api-page))))

(defun fe-weave ()
  "Weave the .org files named after the output directory into HTML there,
as a book (see `fe--reading-order').  MathJax is read from Debian's local
copy and the stylesheet is copied beside the pages, so the book is offline."
  (let* ((outdir (file-name-as-directory (expand-file-name (pop command-line-args-left))))
         (files (mapcar #'expand-file-name command-line-args-left))
         (order (fe--reading-order files))
         (pages (append (mapcar (lambda (f) (cons f (fe--org-title f))) order)
                        (list fe--api-page)))
         (titles (mapcar (lambda (p) (cons (file-name-base (car p)) (cdr p))) pages))
         (css (expand-file-name "book.css" fe--literate-dir))
         (cwd default-directory))
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
    (setq fe--api nil)
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
          (if (eq page fe--api-page)
              (fe--write-api-page outdir (concat org-html-head "\n" org-html-head-extra) nav titles)
            (with-current-buffer (find-file-noselect file)
              (fe--collect-fragments)
              (setq fe--page (file-name-base file))
              (let ((out (concat outdir (file-name-base file) ".html")))
                (org-export-to-file 'fe-html out)
                (message "Wove %s -> %s" (file-relative-name file cwd) out))))
          (setq prev page rest (cdr rest)))))
    (setq command-line-args-left nil)))
