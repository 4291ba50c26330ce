#!/usr/bin/env bash
# clap-validator on the bundled Colophony.clap (what plugin users run before installing).
#
#   scripts/validate.sh            validate (every test must pass)
#   scripts/validate.sh fuzz N     also fuzz for N seconds (by hand; not in CI)
#
# The validator is built from its source (MIT, by Robbert van der Helm), found at
# $CLAP_VALIDATOR_SRC or ../shared/tools/clap-validator; its dependencies come from
# crates.io. Without the source the script says so and exits 0 (CI then has nothing to
# run it with). The bundle must exist: `cargo xtask demo` (or `cargo xtask bundle
# colophony --release`) writes it.
set -euo pipefail
cd "$(dirname "$0")/.."
src="${CLAP_VALIDATOR_SRC:-../shared/tools/clap-validator}"
if [ ! -f "$src/Cargo.toml" ]; then
    echo "clap-validator: no source at $src (set CLAP_VALIDATOR_SRC); skipped"
    exit 0
fi
bundle=target/bundled/Colophony.clap
[ -e "$bundle" ] || { echo "clap-validator: $bundle missing (run cargo xtask demo)"; exit 1; }
cargo build --release --manifest-path "$src/Cargo.toml" --target-dir target/clap-validator
validator=target/clap-validator/release/clap-validator
# It writes its reports under TMPDIR.
export TMPDIR="${TMPDIR:-/tmp}/colophony-clap-validator"
mkdir -p "$TMPDIR"
out=$("$validator" validate --hide-output "$bundle" 2>&1 | sed 's/\x1b\[[0-9;]*m//g')
echo "$out" | tail -1
summary=$(echo "$out" | grep -E '^[0-9]+ tests run' || true)
failed=$(echo "$summary" | sed -nE 's/.* ([0-9]+) failed.*/\1/p')
if [ -z "$summary" ] || [ "${failed:-1}" != "0" ]; then
    echo "$out" | grep -E 'FAILED' -B3 || true
    echo "clap-validator: validation failed"
    exit 1
fi
if [ "${1:-}" = "fuzz" ]; then
    "$validator" fuzz --duration "${2:-600}s" "$bundle" 2>&1 | sed 's/\x1b\[[0-9;]*m//g' | tail -5
fi
