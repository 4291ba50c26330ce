"""The VST3 load benchmark: Colophony.vst3 loaded in pedalboard (JUCE's VST3 host) and its
parameters listed, in five fresh processes (a host loads a plugin once per project, cold).
Prints each run, the best and the spread. Run by scripts/vst3-load-time.sh."""
import subprocess
import sys

BUNDLE = sys.argv[1] if len(sys.argv) > 1 else "target/bundled/Colophony.vst3"
ONE = """
import sys, time, pedalboard
t0 = time.perf_counter(); p = pedalboard.load_plugin(sys.argv[1]); t1 = time.perf_counter()
n = len(p.parameters); t2 = time.perf_counter()
print(t1 - t0, t2 - t1, n, len(p._parameters))
"""
runs = []
for _ in range(5):
    out = subprocess.run([sys.executable, "-c", ONE, BUNDLE], check=True, capture_output=True, text=True)
    load, listing, listed, declared = out.stdout.split()
    runs.append((float(load), float(listing)))
    print(f"load {float(load):.3f} s, listing {float(listing):.3f} s ({listed} listed of {declared} declared)")
totals = sorted(l + p for l, p in runs)
print(f"load + listing: best {totals[0]:.3f} s, worst {totals[-1]:.3f} s over {len(totals)} processes")
