// Renders STK's stk::Bowed for `colophony bench precision` and `colophony bench peers`
// (the benches compile it with g++ -O2 against libstk-dev).
// Usage: stk_bowed SECONDS RATE_HZ FREQ_HZ OUT.f32 [RUNS]
// Renders RUNS times (default 3) from a fresh instrument, prints the fastest render time in
// seconds (the sample loop only) and writes the last render as raw native-endian f32. On
// standard error it prints the fastest stretch of 16384 samples' time a sample,
// `floor_ns_per_sample X`: a floor other load on the machine cannot raise (lab/src/timing.rs).
#include <stk/Bowed.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

int main(int argc, char** argv) {
    if (argc != 5 && argc != 6) {
        std::fprintf(stderr, "usage: %s SECONDS RATE_HZ FREQ_HZ OUT.f32 [RUNS]\n", argv[0]);
        return 2;
    }
    const int runs = argc == 6 ? std::max(1, std::atoi(argv[5])) : 3;
    const double seconds = std::atof(argv[1]);
    const double rate = std::atof(argv[2]);
    const double freq = std::atof(argv[3]);
    stk::Stk::setSampleRate(rate);
    std::vector<float> out(static_cast<size_t>(seconds * rate));
    const size_t stretch = 16384;
    double best = 1e300;
    double floor = 1e300;
    for (int run = 0; run < runs; ++run) {
        stk::Bowed bowed(50.0);
        bowed.setVibrato(0.0);
        const auto start = std::chrono::steady_clock::now();
        // STK's own defaults: amplitude 0.8 sets the bow velocity envelope; bow pressure
        // and position stay at the constructor's values.
        bowed.noteOn(freq, 0.8);
        auto stretch_start = start;
        for (size_t i = 0; i < out.size(); ++i) {
            out[i] = static_cast<float>(bowed.tick());
            if ((i + 1) % stretch == 0) {
                const auto now = std::chrono::steady_clock::now();
                const std::chrono::duration<double> took = now - stretch_start;
                floor = std::min(floor, took.count() / stretch);
                stretch_start = now;
            }
        }
        const std::chrono::duration<double> took = std::chrono::steady_clock::now() - start;
        best = std::min(best, took.count());
    }
    std::FILE* f = std::fopen(argv[4], "wb");
    if (!f || std::fwrite(out.data(), sizeof(float), out.size(), f) != out.size()) {
        std::fprintf(stderr, "cannot write %s\n", argv[4]);
        return 1;
    }
    std::fclose(f);
    std::printf("%.9f\n", best);
    if (floor < 1e300) std::fprintf(stderr, "floor_ns_per_sample %.3f\n", floor * 1e9);
    return 0;
}
