#!/bin/sh
# SPDX-License-Identifier: MIT
# Splices the output of doc_table (the field and enum tables generated from
# lib/'s metadata) between the markers of docs/protocol.md.
#   docs.sh DOC_TABLE DOC            rewrite DOC in place (make docs)
#   docs.sh DOC_TABLE DOC --check    fail if DOC differs (make check-docs)
set -u
gen=$1; doc=$2; mode=${3:-}
. "$(dirname "$0")/../lib.sh"
begin='<!-- BEGIN GENERATED TABLES: make docs -->'
end='<!-- END GENERATED TABLES -->'
tmp="$doc.tmp.$$"
table="$doc.table.$$"
trap 'rm -f "$tmp" "$table"' EXIT

if ! "$gen" > "$table"; then fail "doc_table failed"; finish; exit 1; fi
if [ "$(grep -cxF "$begin" "$doc")" != 1 ] || [ "$(grep -cxF "$end" "$doc")" != 1 ]; then
  fail "$doc must hold the lines '$begin' and '$end' once each"
  finish; exit 1
fi
awk -v b="$begin" -v e="$end" -v t="$table" '
  $0 == b { print; while ((getline l < t) > 0) print l; skip = 1; next }
  $0 == e { skip = 0 }
  !skip { print }' "$doc" > "$tmp"
if [ "$mode" = --check ]; then
  if cmp -s "$doc" "$tmp"; then
    ok "$doc tables match lib/'s field table"
  else
    diff -u "$doc" "$tmp" | head -n 40
    fail "$doc tables differ from lib/'s metadata: run make docs"
  fi
  # Every field the library knows is in the document.
  for name in $(sed -n 's/^| `\([a-z0-9_]*\)` | [0-9]* |.*/\1/p' "$table"); do
    grep -q "^| \`$name\` |" "$doc" || fail "$doc lacks field $name"
  done
  ok "every field of lib/ appears in $doc"
  finish
else
  mv "$tmp" "$doc"
  echo "docs: updated the tables in $doc"
fi
