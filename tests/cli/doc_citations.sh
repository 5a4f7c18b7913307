#!/usr/bin/env bash
# Every docs/*.md that the code, tests, tools and scripts cite exists in the repository.
#   usage: doc_citations.sh SOURCE_DIR
set -euo pipefail
cd "$1"
# The project's own files only: not what npm installed under tools/ (node_modules), not binaries.
search=(grep -rI --exclude-dir=node_modules)
missing=0
for f in $("${search[@]}" -hoE 'docs/[A-Za-z0-9_./-]+\.md' src tests tools scripts | sort -u); do
  if [ ! -f "$f" ]; then
    echo "MISSING: $f, cited in: $("${search[@]}" -lF "$f" src tests tools scripts | tr '\n' ' ')"
    missing=$((missing + 1))
  fi
done
[ "$missing" -eq 0 ] && echo "ok: every cited doc exists"
