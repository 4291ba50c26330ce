#!/usr/bin/env python3
"""Writes assets/demos/midi/pachelbel-ground-keyswitch.mid: J. Pachelbel's canon in D, the
ground bass (public domain) on the double bass, played twice: pizzicato (keyswitch C#0),
then arco (keyswitch C0). Standard MIDI file, format 0, 480 ticks a beat, 60 bpm."""
import struct, sys

GROUND = [38, 33, 35, 30, 31, 26 + 12, 31, 33]  # D2 A1 B1 F#1 G1 D2 G1 A1
TPB = 480

def vlq(n):
    out = [n & 0x7F]
    n >>= 7
    while n:
        out.insert(0, (n & 0x7F) | 0x80)
        n >>= 7
    return bytes(out)

events = []  # (tick, bytes)
events.append((0, b"\xff\x51\x03" + (1_000_000).to_bytes(3, "big")))
t = 0
for keyswitch, length, velocity in [(13, 0.9, 100), (12, 0.98, 90)]:
    events.append((t, bytes([0x90, keyswitch, 100])))
    events.append((t + 10, bytes([0x80, keyswitch, 0])))
    t += 20
    for note in GROUND:
        events.append((t, bytes([0x90, note, velocity])))
        events.append((t + int(length * TPB) - 20, bytes([0x80, note, 0])))
        t += TPB
    t += TPB - 20
events.sort(key=lambda e: (e[0], e[1][0] != 0x80))
track = b""
last = 0
for tick, data in events:
    track += vlq(tick - last) + data
    last = tick
track += b"\x00\xff\x2f\x00"
smf = b"MThd" + struct.pack(">IHHH", 6, 0, 1, TPB) + b"MTrk" + struct.pack(">I", len(track)) + track
open(sys.argv[1] if len(sys.argv) > 1 else "assets/demos/midi/pachelbel-ground-keyswitch.mid", "wb").write(smf)
