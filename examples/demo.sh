#!/bin/sh
# make demo: run every example and show what it prints.
B=${1:-build}
for e in "$B"/examples/*; do
  [ -x "$e" ] || continue
  echo "== $(basename "$e")"
  "$e" || exit 1
  echo
done
