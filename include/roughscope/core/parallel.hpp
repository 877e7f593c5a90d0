// Fixed-band parallel loops whose result does not depend on the number of threads: the work is
// cut into bands that do not depend on it, each band writes only its own output, and the caller
// combines the bands' outputs in band order.
#pragma once

#include <algorithm>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

namespace roughscope {

// The worker threads for an options' `threads` (0 = all cores), at most `bands` (and ≥ 1).
inline std::size_t worker_threads(std::size_t threads, std::size_t bands) {
    if (threads == 0) threads = std::max(1U, std::thread::hardware_concurrency());
    return std::clamp<std::size_t>(threads, 1, std::max<std::size_t>(1, bands));
}

// Runs work(band) for every band in [0, bands), band b on thread b mod threads (the calling
// thread is one of them); rethrows the first thread's exception once every thread has ended.
template <class F>
void run_bands(std::size_t bands, std::size_t threads, F&& work) {
    threads = worker_threads(threads, bands);
    std::vector<std::exception_ptr> errors(threads);
    const auto run = [&](std::size_t t) {
        try {
            for (std::size_t b = t; b < bands; b += threads) work(b);
        } catch (...) {
            errors[t] = std::current_exception();
        }
    };
    {
        std::vector<std::jthread> workers;
        workers.reserve(threads);
        for (std::size_t t = 1; t < threads; ++t) workers.emplace_back(run, t);
        run(0);
    }
    for (const std::exception_ptr& e : errors)
        if (e) std::rethrow_exception(e);
}

}  // namespace roughscope
