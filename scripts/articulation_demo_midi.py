#!/usr/bin/env python3
"""Writes the articulation demos' MIDI files into assets/demos/midi/ (standard MIDI files,
format 0, 480 ticks a beat, 60 bpm), each switching articulation by keyswitch (C0 arco,
C#0 pizzicato, D0 tremolo, D#0 spiccato, E0 col legno, F0 sautillé, F#0 harmonics, G0 col legno tratto):

- pachelbel-ground-keyswitch.mid: J. Pachelbel's canon in D, the ground bass (public
  domain) on the double bass, played twice: pizzicato, then arco;
- cello-tremolo-keyswitch.mid: a cello line in half notes under tremolo;
- violin-spiccato-keyswitch.mid: a violin scale in sixteenths, spiccato, then the same
  notes arco (keyswitch C0);
- viola-col-legno-keyswitch.mid: a viola ostinato in eighths struck col legno, growing
  louder, then its last bar arco (keyswitch C0);
- violin-sautille-keyswitch.mid: a violin figure of broken chords, twelve separate notes
  a second (a stroke each, the sautillé's default rate), then its first bar arco;
- violin-harmonics-keyswitch.mid: a slow violin line in harmonics (natural ones on the
  open strings, artificial ones between), then the same line arco an octave lower;
- cello-col-legno-tratto-keyswitch.mid: a cello line in half notes drawn with the stick
  (col legno tratto), then the same line with the hair (keyswitch C0)."""
import struct
import sys
from pathlib import Path

TPB = 480


def vlq(n):
    out = [n & 0x7F]
    n >>= 7
    while n:
        out.insert(0, (n & 0x7F) | 0x80)
        n >>= 7
    return bytes(out)


def write(path, events):
    events = [(0, b"\xff\x51\x03" + (1_000_000).to_bytes(3, "big"))] + events
    events.sort(key=lambda e: (e[0], e[1][0] != 0x80))
    track, last = b"", 0
    for tick, data in events:
        track += vlq(tick - last) + data
        last = tick
    track += b"\x00\xff\x2f\x00"
    header = b"MThd" + struct.pack(">IHHH", 6, 0, 1, TPB)
    path.write_bytes(header + b"MTrk" + struct.pack(">I", len(track)) + track)


def keyswitch(t, key):
    return [(t, bytes([0x90, key, 100])), (t + 10, bytes([0x80, key, 0]))]


def notes(t, pitches, beats, held, velocity):
    events = []
    for note in pitches:
        events.append((t, bytes([0x90, note, velocity])))
        events.append((t + int(held * beats * TPB) - 20, bytes([0x80, note, 0])))
        t += int(beats * TPB)
    return events, t


out = Path(sys.argv[1] if len(sys.argv) > 1 else "assets/demos/midi")
GROUND = [38, 33, 35, 30, 31, 38, 31, 33]  # D2 A1 B1 F#1 G1 D2 G1 A1
events, t = keyswitch(0, 13), 20
part, t = notes(t, GROUND, 1, 0.9, 100)
events += part + keyswitch(t + TPB - 20, 12)
part, t = notes(t + TPB, GROUND, 1, 0.98, 90)
write(out / "pachelbel-ground-keyswitch.mid", events + part)
part, _ = notes(20, [50, 53, 57, 55, 53, 52, 50], 2, 0.97, 96)
write(out / "cello-tremolo-keyswitch.mid", keyswitch(0, 14) + part)
SCALE = [67, 69, 71, 72, 74, 76, 78, 79, 78, 76, 74, 72, 71, 69, 67]
part, t = notes(20, SCALE, 0.25, 0.6, 100)
events = keyswitch(0, 15) + part + keyswitch(t + TPB // 2, 12)
part, _ = notes(t + TPB, SCALE, 0.25, 0.95, 100)
write(out / "violin-spiccato-keyswitch.mid", events + part)
OSTINATO = [55, 55, 55, 62, 55, 55, 62, 60] * 2 + [55, 55, 55, 62, 63, 62, 60, 58]
events, t = keyswitch(0, 16), 20
for i, note in enumerate(OSTINATO):
    part, t = notes(t, [note], 0.5, 0.5, 50 + 3 * i)
    events += part
events += keyswitch(t + TPB // 2, 12)
part, _ = notes(t + TPB, OSTINATO[-8:], 0.5, 0.95, 100)
write(out / "viola-col-legno-keyswitch.mid", events + part)
FIGURE = [67, 71, 74, 79, 74, 71] * 2 + [67, 72, 76, 79, 76, 72] * 2 + [66, 69, 74, 78, 74, 69] * 2 + [67, 71, 74, 79, 83, 79]
events, t = keyswitch(0, 17), 20
part, t = notes(t, FIGURE, 1 / 12, 0.8, 100)
events += part + keyswitch(t + TPB // 2, 12)
part, _ = notes(t + TPB, FIGURE[:12], 1 / 12, 0.8, 100)
write(out / "violin-sautille-keyswitch.mid", events + part)
LINE = [88, 95, 100, 93, 86, 81, 84, 88, 79, 86, 91]
events, t = keyswitch(0, 18), 20
part, t = notes(t, LINE, 1, 0.95, 90)
events += part + keyswitch(t + TPB // 2, 12)
part, _ = notes(t + TPB, [n - 12 for n in LINE], 1, 0.95, 90)
write(out / "violin-harmonics-keyswitch.mid", events + part)
TRATTO = [50, 53, 57, 55, 53, 52, 50]
events, t = keyswitch(0, 19), 20
part, t = notes(t, TRATTO, 2, 0.97, 96)
events += part + keyswitch(t + TPB // 2, 12)
part, _ = notes(t + TPB, TRATTO, 2, 0.97, 96)
write(out / "cello-col-legno-tratto-keyswitch.mid", events + part)
