#!/usr/bin/env bash
# The VST3 load benchmark (scripts/vst3_load_time.py) in the round trip's pedalboard venv.
set -euo pipefail
cd "$(dirname "$0")/.."
bundle=target/bundled/Colophony.vst3
[ -e "$bundle" ] || { echo "load time: $bundle missing (run cargo xtask demo)"; exit 1; }
venv=target/host-roundtrip-venv
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
"$venv/bin/python" -m pip install -q --disable-pip-version-check "pedalboard==0.9.26"
"$venv/bin/python" scripts/vst3_load_time.py "$bundle"
