#!/usr/bin/env bash
# The DAW round trip: Colophony.vst3 rendered by a third-party VST3 host, Spotify's
# pedalboard (JUCE's VST3 hosting, installed from PyPI into target/host-roundtrip-venv),
# with a MIDI part and bow-velocity automation at 44.1, 48 and 96 kHz. The checks are in
# scripts/host_roundtrip.py; any failed check fails the script.
#
# The bundle must exist: `cargo xtask demo` (or `cargo xtask bundle colophony --release`)
# writes it. Without python3, or when PyPI cannot be reached, the script says so and
# exits 0 (CI then has no host to run); CI runs it after the tests.
set -euo pipefail
cd "$(dirname "$0")/.."
bundle=target/bundled/Colophony.vst3
[ -e "$bundle" ] || { echo "host round trip: $bundle missing (run cargo xtask demo)"; exit 1; }
command -v python3 >/dev/null || { echo "host round trip: no python3; skipped"; exit 0; }
venv=target/host-roundtrip-venv
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
if ! "$venv/bin/python" -m pip install -q --disable-pip-version-check \
    "pedalboard==0.9.26" "mido==1.3.3" "numpy>=1.26,<3"; then
    echo "host round trip: could not install pedalboard from PyPI; skipped"
    exit 0
fi
"$venv/bin/python" scripts/host_roundtrip.py "$bundle"
