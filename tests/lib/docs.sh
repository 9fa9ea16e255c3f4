#!/bin/sh
# SPDX-License-Identifier: MIT
# Splices the output of doc_table (the tables generated from lib/'s metadata)
# between the markers of each document: `doc_table NAME` for docs/NAME.md
# (protocol: the field and enum tables; rtde: the RTDE variable table).
#   docs.sh DOC_TABLE DOC...            rewrite each DOC in place (make docs)
#   docs.sh DOC_TABLE DOC... --check    fail if a DOC differs (make check-docs)
set -u
gen=$1; shift
mode=
for a in "$@"; do [ "$a" = --check ] && mode=--check; done
. "$(dirname "$0")/../lib.sh"
begin='<!-- BEGIN GENERATED TABLES: make docs -->'
end='<!-- END GENERATED TABLES -->'
tmp=; table=
trap 'rm -f "$tmp" "$table"' EXIT

for doc in "$@"; do
  [ "$doc" = --check ] && continue
  tmp="$doc.tmp.$$"; table="$doc.table.$$"
  name=$(basename "$doc" .md)
  if ! "$gen" "$name" > "$table"; then fail "doc_table $name failed"; continue; fi
  if [ "$(grep -cxF "$begin" "$doc")" != 1 ] || [ "$(grep -cxF "$end" "$doc")" != 1 ]; then
    fail "$doc must hold the lines '$begin' and '$end' once each"
    continue
  fi
  awk -v b="$begin" -v e="$end" -v t="$table" '
    $0 == b { print; while ((getline l < t) > 0) print l; skip = 1; next }
    $0 == e { skip = 0 }
    !skip { print }' "$doc" > "$tmp"
  if [ "$mode" = --check ]; then
    if cmp -s "$doc" "$tmp"; then
      ok "$doc tables match lib/'s tables"
    else
      diff -u "$doc" "$tmp" | head -n 40
      fail "$doc tables differ from lib/'s metadata: run make docs"
    fi
    # Every row lib/ generates (a field, an RTDE name or family) is in the document.
    missing=0
    while IFS= read -r row; do
      case $row in '| `'*) grep -qxF -- "$row" "$doc" || { fail "$doc lacks the row: $row"; missing=1; } ;; esac
    done < "$table"
    [ $missing = 0 ] && ok "every row of lib/'s table appears in $doc"
    rm -f "$tmp" "$table"
  else
    mv "$tmp" "$doc"; rm -f "$table"
    echo "docs: updated the tables in $doc"
  fi
done
[ "$mode" = --check ] && { finish; exit $?; }
[ "$FAILED" = 0 ]
