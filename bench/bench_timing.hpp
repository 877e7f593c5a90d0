// The benchmarks' one timer for ratio counters: the best of `repeats` wall-clock runs of `body`
// (seconds). A benchmark that reports "time_vs_<baseline>" times itself and its baseline with it
// in the same run, so machine load cancels in the ratio.
#pragma once

#include <algorithm>
#include <chrono>

namespace roughscope::bench {

template <class F>
double seconds_of(F&& body, int repeats) {
    double best = 1e300;
    for (int k = 0; k < repeats; ++k) {
        const auto t0 = std::chrono::steady_clock::now();
        body();
        const std::chrono::duration<double> dt = std::chrono::steady_clock::now() - t0;
        best = std::min(best, dt.count());
    }
    return best;
}

}  // namespace roughscope::bench
