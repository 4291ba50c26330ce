#!/usr/bin/env bash
# Renders every sound demo listed in assets/demos/demos.txt into assets/demos/ with the
# release renderer: `colophony render ARGS --out assets/demos/FILE`, one line each.
# lab/tests/demos.rs checks that each command still gives the same length, level and pitch.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -p colophony-lab --bin colophony
grep -v '^#' assets/demos/demos.txt | while IFS='|' read -r file args _; do
    file=$(echo "$file" | xargs)
    echo "colophony render $args --out assets/demos/$file"
    # shellcheck disable=SC2086
    target/release/colophony render $args --out "assets/demos/$file"
done
