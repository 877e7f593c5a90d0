// The benchmarks' one timer for ratio counters: the best of `repeats` wall-clock runs of `body`
// (seconds). A benchmark that reports "time_vs_<baseline>" times itself and its baseline with it
// in the same run, so machine load cancels in the ratio.
#pragma once

#include <algorithm>
#include <chrono>
#include <utility>

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

// Two bodies timed alternately (a, b, a, b, …), `repeats` runs each: the best of each
// (seconds). Their ratio then holds when the machine's load drifts during the run, as it does on
// shared virtual machines.
template <class F, class G>
std::pair<double, double> seconds_of_interleaved(F&& a, G&& b, int repeats) {
    double best_a = 1e300, best_b = 1e300;
    for (int k = 0; k < repeats; ++k) {
        best_a = std::min(best_a, seconds_of(a, 1));
        best_b = std::min(best_b, seconds_of(b, 1));
    }
    return {best_a, best_b};
}

}  // namespace roughscope::bench
