"""Writes the demo phrases (assets/demos/midi/*.mid): short public-domain melodies, one
track each, legato (each note ends where the next begins). Needs mido (the round trip's
venv has it: target/host-roundtrip-venv/bin/python scripts/demo_phrases.py)."""
import os

import mido

OUT = os.path.join(os.path.dirname(__file__), "..", "assets", "demos", "midi")
TPB = 480

# (MIDI note, beats); 0 is a rest.
PHRASES = {
    # J. S. Bach, cello suite no. 1 in G, BWV 1007, prelude, bars 1-4 (sixteenths).
    "bach-bwv1007-prelude": (66, 0.25, 80, [
        43, 50, 59, 57, 59, 50, 59, 50, 43, 50, 59, 57, 59, 50, 59, 50,
        43, 52, 60, 59, 60, 52, 60, 52, 43, 52, 60, 59, 60, 52, 60, 52,
        43, 54, 60, 59, 60, 54, 60, 54, 43, 54, 60, 59, 60, 54, 60, 54,
        43, 55, 59, 57, 59, 55, 59, 55, 43, 55, 59, 57, 59, 55, 59, 54,
    ]),
    # Minuet in G, BWV Anh. 114 (Christian Petzold, from the Notebook for Anna Magdalena
    # Bach), bars 1-8, for the violin.
    "petzold-minuet-in-g": (108, None, 90, [
        (74, 1), (67, 0.5), (69, 0.5), (71, 0.5), (72, 0.5),
        (74, 1), (67, 1), (67, 1),
        (76, 1), (72, 0.5), (74, 0.5), (76, 0.5), (78, 0.5),
        (79, 1), (67, 1), (67, 1),
        (72, 1), (74, 0.5), (72, 0.5), (71, 0.5), (69, 0.5),
        (71, 1), (72, 0.5), (71, 0.5), (69, 0.5), (67, 0.5),
        (66, 1), (67, 0.5), (69, 0.5), (71, 0.5), (67, 0.5),
        (69, 3),
    ]),
    # L. van Beethoven, symphony no. 9, op. 125, finale, the "Ode to Joy" theme, in D for
    # the viola.
    "beethoven-ode-to-joy": (112, None, 85, [
        (66, 1), (66, 1), (67, 1), (69, 1), (69, 1), (67, 1), (66, 1), (64, 1),
        (62, 1), (62, 1), (64, 1), (66, 1), (66, 1.5), (64, 0.5), (64, 2),
        (66, 1), (66, 1), (67, 1), (69, 1), (69, 1), (67, 1), (66, 1), (64, 1),
        (62, 1), (62, 1), (64, 1), (66, 1), (64, 1.5), (62, 0.5), (62, 2),
    ]),
    # G. F. Handel, Sarabande from the keyboard suite in D minor, HWV 437, bars 1-8,
    # the melody an octave down for the cello: the friction models' phrase (slow, with a
    # leap and a long note to hear each law's attack and sustain).
    "handel-sarabande": (72, None, 90, [
        (50, 1), (50, 1.5), (52, 0.5), (53, 1), (53, 1), (52, 1.5), (50, 0.5),
        (49, 1), (45, 2), (57, 1), (57, 1.5), (55, 0.5), (53, 1), (52, 2),
    ]),
}


def write(name, tempo_bpm, step, velocity, notes):
    mid = mido.MidiFile(ticks_per_beat=TPB)
    track = mido.MidiTrack()
    mid.tracks.append(track)
    track.append(mido.MetaMessage("set_tempo", tempo=mido.bpm2tempo(tempo_bpm), time=0))
    track.append(mido.MetaMessage("track_name", name=name, time=0))
    if step is not None:
        notes = [(n, step) for n in notes]
    pending = 0
    for key, beats in notes:
        ticks = round(beats * TPB)
        if key == 0:
            pending += ticks
            continue
        track.append(mido.Message("note_on", note=key, velocity=velocity, time=pending))
        track.append(mido.Message("note_off", note=key, velocity=0, time=ticks))
        pending = 0
    track.append(mido.MetaMessage("end_of_track", time=TPB))
    mid.save(os.path.join(OUT, name + ".mid"))
    seconds = sum(b for _, b in notes) * 60.0 / tempo_bpm
    print(f"{name}.mid: {len(notes)} notes, {seconds:.1f} s")


for name, (tempo, step, velocity, notes) in PHRASES.items():
    write(name, tempo, step, velocity, notes)
