#!/usr/bin/env bash
# CI: docs/architecture.md names every module file of src/ by its path relative to src/
# (`glint/mixture/patch.rs`, `lib.rs`; a `dir/mod.rs` may also be named as `dir/`). A name counts
# where it is not part of a longer path (`src/` in front is allowed): `math.rs` is not named by
# `glint/math.rs`, `ndf/` is not named by `ndf/ggx.rs`.
# Prints the files the document misses and exits 1 if any (or if the document is absent).
# Usage: bash tools/check_architecture.sh [DOC [SRC_DIR]]   (defaults: docs/architecture.md src)
set -euo pipefail
cd "$(dirname "$0")/.."
doc=${1:-docs/architecture.md}
src=${2:-src}
src=${src%/}

if [[ ! -f $doc ]]; then
    echo "check_architecture: $doc does not exist; it must name every module file of $src/" >&2
    exit 1
fi
if [[ ! -d $src ]]; then
    echo "check_architecture: $src is not a directory" >&2
    exit 1
fi

# An extended regex for a path named on its own: not inside a longer path or word.
named() {
    local esc=${1//./\\.}
    printf '(^|[^A-Za-z0-9_./-])(src/)?%s([^A-Za-z0-9_/-]|$)' "$esc"
}

files=0
missing=()
while IFS= read -r file; do
    rel=${file#"$src"/}
    files=$((files + 1))
    pattern=$(named "$rel")
    if [[ $rel == */mod.rs ]]; then
        pattern="$pattern|$(named "${rel%mod.rs}")"
    fi
    if ! grep -Eq -- "$pattern" "$doc"; then
        missing+=("$rel")
    fi
done < <(find "$src" -type f -name '*.rs' | LC_ALL=C sort)

if ((${#missing[@]})); then
    echo "check_architecture: $doc does not name ${#missing[@]} of the $files module files of $src/:" >&2
    printf '  %s\n' "${missing[@]}" >&2
    exit 1
fi
echo "check_architecture: $doc names all $files module files of $src/"
