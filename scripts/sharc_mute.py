#!/usr/bin/env python3
"""The muted minus the open long-term spectrum of SHARC's violin, viola, cello and double
bass (docs/articulations.md, "Measured mute"), by the timbre benchmark's method: each
note's harmonic power normalised to its total within the bands from the lowest open
string's third-octave band to 5 kHz, averaged over the notes both sets hold.

Usage: python3 scripts/sharc_mute.py SHARC.xml
SHARC.xml is tools/sharc.xml of github.com/anton-k/sharc-timbre (commit 14be260)."""
import math
import re
import sys

xml = open(sys.argv[1]).read()


def instrument(ident):
    body = re.search(r'<instrument id="%s"[^>]*>(.*?)</instrument>' % ident, xml, re.S).group(1)
    notes = {}
    for n in re.finditer(r'<note pitch="[^"]+" seq="\d+" keyNum="(\d+)" fundHz="([\d.]+)"[^>]*>(.*?)</note>', body, re.S):
        amps = {int(a.group(1)): float(a.group(2)) for a in re.finditer(r'<a n="(\d+)" p="[^"]*">([\d.eE+-]+)</a>', n.group(3))}
        notes[int(n.group(1))] = (float(n.group(2)), amps)
    return notes


def spectrum(notes, keys, low, high=37):
    power = [0.0] * (high - low + 1)
    for k in keys:
        f0, amps = notes[k]
        note = [0.0] * len(power)
        for h, a in amps.items():
            band = round(10 * math.log10(h * f0))
            if low <= band <= high:
                note[band - low] += a * a
        total = sum(note)
        for i, p in enumerate(note):
            power[i] += p / total / len(keys)
    return [10 * math.log10(max(p, 1e-12)) for p in power]


for open_id, muted_id, low in [("violin_vibrato", "violin_muted_vibrato", 23), ("viola_vibrato", "viola_muted_vibrato", 21),
                               ("cello_vibrato", "cello_muted_vibrato", 18), ("CB", "CB_muted", 16)]:
    o, m = instrument(open_id), instrument(muted_id)
    keys = sorted(set(o) & set(m))
    diff = [b - a for a, b in zip(spectrum(o, keys, low), spectrum(m, keys, low))]
    print(f"{open_id:16} {len(keys)} notes, bands from {10 ** (low / 10):.0f} Hz:", " ".join(f"{d:+.0f}" for d in diff))
