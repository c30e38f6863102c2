#!/bin/sh
# docs.sh -- the documents generated from the technique registry (make docs):
# docs/techniques.md is `shadowlab list --markdown`; README.md's block between
# the BEGIN and END marker lines is `shadowlab list --readme` (the technique
# table and the shared map parameters). Usage: scripts/docs.sh [--check]
# SHADOWLAB [ROOT]. ROOT (default: this checkout) holds README.md and docs/.
# --check writes nothing: it exits 1 naming each file that is out of date.
set -eu
check=0
if [ "${1:-}" = "--check" ]; then check=1; shift; fi
[ $# -ge 1 ] || { echo "usage: scripts/docs.sh [--check] SHADOWLAB [ROOT]" >&2; exit 2; }
SL=$1
ROOT=${2:-$(cd "$(dirname "$0")/.." && pwd)}
BEGIN='<!-- BEGIN generated from the technique registry by `make docs` (scripts/docs.sh): do not edit -->'
END='<!-- END generated -->'
TMP=$(mktemp -d /tmp/shadowlab-docs-XXXXXX)
trap 'rm -rf "$TMP"' EXIT

# README.md with its block replaced by the file $2; fails unless the markers
# appear exactly once each, BEGIN first.
splice() {
    awk -v begin="$BEGIN" -v end="$END" -v block="$2" '
        $0 == begin { nb++; print; while ((getline line < block) > 0) print line; skip = 1; next }
        $0 == end { ne++; if (!skip) bad = 1; skip = 0 }
        !skip { print }
        END { if (nb != 1 || ne != 1 || bad || skip) exit 1 }' "$1"
}

"$SL" list --markdown >"$TMP/techniques.md"
"$SL" list --readme >"$TMP/block.md"
if ! splice "$ROOT/README.md" "$TMP/block.md" >"$TMP/README.md"; then
    echo "docs.sh: $ROOT/README.md needs exactly one pair of marker lines:" >&2
    echo "  $BEGIN" >&2
    echo "  $END" >&2
    exit 1
fi

stale=0
for f in docs/techniques.md README.md; do
    new="$TMP/$(basename "$f")"
    if cmp -s "$new" "$ROOT/$f"; then continue; fi
    if [ "$check" -eq 1 ]; then
        echo "docs.sh: $ROOT/$f is out of date with the registry: run make docs" >&2
        stale=1
    else
        cp "$new" "$ROOT/$f.tmp$$" && mv "$ROOT/$f.tmp$$" "$ROOT/$f"
        echo "docs.sh: wrote $ROOT/$f"
    fi
done
exit "$stale"
