#!/usr/bin/env bash
# Regenerates docs/editor.png, a real screenshot of the Colophony editor: the plugin's editor
# in nice-plug's standalone wrapper (examples/editor_standalone.rs, which bows cello D3 from
# the start so the live views move), on a virtual X server (Xvfb, Mesa's software OpenGL),
# with the dummy audio backend.
#
#   scripts/editor-screenshot.sh [OUT.png]        (default docs/editor.png)
#
# Installs what it needs with apt-get if missing (as root, or through sudo): pkg-config,
# libasound2-dev and libjack-jackd2-dev (the standalone wrapper links ALSA and JACK), xvfb,
# x11-apps (xwd), netpbm (xwdtopnm, pnmcut, pnmtopng) and Mesa's OpenGL drivers.
# Environment: COLOPHONY_DEMO_NOTE (MIDI note, default 50), COLOPHONY_DEMO_SET (parameters,
# `id=value;...`, default the thermal model so the shot shows its views; set it empty for
# the defaults), SETTLE_S (seconds between opening the window and the screenshot, default 6).
set -euo pipefail

cd "$(dirname "$0")/.."
out=${1:-docs/editor.png}
settle=${SETTLE_S:-6}
# The window's default size (EditorSize::DEFAULT in src/editor/mod.rs).
width=880
height=760

packages=(pkg-config libasound2-dev libjack-jackd2-dev xvfb xauth x11-apps netpbm
    libgl1 libgl1-mesa-dri libx11-xcb1 libxcursor1 libxrandr2 libxi6)
missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
    echo "installing: ${missing[*]}"
    sudo_cmd=()
    [[ $(id -u) -eq 0 ]] || sudo_cmd=(sudo)
    "${sudo_cmd[@]}" apt-get update -qq
    DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

cargo build --features standalone --example editor_standalone
app=target/debug/examples/editor_standalone

# A screen larger than the window, so the pointer (Xvfb puts it at the centre) is not over
# the editor; the window opens at the top-left corner (no window manager).
display=:${EDITOR_SCREENSHOT_DISPLAY:-97}
Xvfb "$display" -screen 0 1920x1400x24 -nolisten tcp >/dev/null 2>&1 &
xvfb_pid=$!
app_pid=
cleanup() {
    [[ -n $app_pid ]] && kill "$app_pid" 2>/dev/null || true
    kill "$xvfb_pid" 2>/dev/null || true
}
trap cleanup EXIT
sleep 1.5

export COLOPHONY_DEMO_SET=${COLOPHONY_DEMO_SET-friction_model=Thermal (paper B)}
DISPLAY=$display LIBGL_ALWAYS_SOFTWARE=1 "$app" --backend dummy >/dev/null 2>&1 &
app_pid=$!
sleep "$settle"
kill -0 "$app_pid" 2>/dev/null || { echo "the standalone editor exited early" >&2; exit 1; }

mkdir -p "$(dirname "$out")"
DISPLAY=$display xwd -root -silent | xwdtopnm 2>/dev/null \
    | pnmcut -left 0 -top 0 -width "$width" -height "$height" | pnmtopng >"$out"
echo "wrote $out"
