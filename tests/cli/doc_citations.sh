#!/usr/bin/env bash
# Every docs/*.md that the code, tests, tools and scripts cite exists in the repository.
#   usage: doc_citations.sh SOURCE_DIR
set -euo pipefail
cd "$1"
missing=0
for f in $(grep -rhoE 'docs/[A-Za-z0-9_./-]+\.md' src tests tools scripts | sort -u); do
  if [ ! -f "$f" ]; then
    echo "MISSING: $f, cited in: $(grep -rlF "$f" src tests tools scripts | tr '\n' ' ')"
    missing=$((missing + 1))
  fi
done
[ "$missing" -eq 0 ] && echo "ok: every cited doc exists"
