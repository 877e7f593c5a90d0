// BRDF comparisons of CUReT samples (paper §5.3, Tables 3–4): one sample with the paper's
// Oren–Nayar parameters where Table 3 gives them, or every sample of the database in parallel.
#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "roughscope/brdf/comparison.hpp"
#include "roughscope/brdf/curet.hpp"
#include "roughscope/core/errors.hpp"

namespace roughscope {

Comparison compare_curet_sample(const CuretDatabase& db, int sample,
                                const ComparisonOptions& options) {
    const BrdfTable table = db.sample_table(sample);  // throws for an unknown sample
    ComparisonOptions o = options;
    if (!o.oren_nayar) {
        if (const auto on = paper_oren_nayar_params(sample)) {
            o.oren_nayar = on;
            o.oren_nayar_source = "the paper's Table 3, from the CUReT database";
        }
    }
    Comparison c = compare_brdf(table, o);
    c.sample = sample;
    const std::string_view name = curet_sample_name(sample);
    if (!name.empty()) c.name = std::string(name);
    return c;
}

std::vector<Comparison> compare_curet_all(const CuretDatabase& db, const ComparisonOptions& options,
                                          int threads) {
    validate(options);
    if (threads < 0)
        throw InvalidArgument("threads = " + std::to_string(threads) + " must be >= 0");
    const std::size_t n = db.samples.size();
    std::vector<Comparison> out(n);
    std::size_t workers = threads > 0 ? static_cast<std::size_t>(threads)
                                      : std::max(1u, std::thread::hardware_concurrency());
    workers = std::max<std::size_t>(1, std::min(workers, n));
    // Samples in parallel, each comparison on one thread; one worker: `threads` for the
    // comparison itself unless its options set their own.
    ComparisonOptions sample_options = options;
    if (workers > 1)
        sample_options.threads = 1;
    else if (threads > 0 && sample_options.threads == 0)
        sample_options.threads = static_cast<std::size_t>(threads);
    std::atomic<std::size_t> next{0};
    std::exception_ptr error;
    std::mutex error_mutex;
    auto work = [&] {
        while (true) {
            const std::size_t k = next.fetch_add(1);
            if (k >= n) return;
            try {
                out[k] = compare_curet_sample(db, db.samples[k], sample_options);
            } catch (...) {
                std::lock_guard<std::mutex> lock(error_mutex);
                if (!error) error = std::current_exception();
                next.store(n);
            }
        }
    };
    if (workers == 1) {
        work();
    } else {
        std::vector<std::thread> pool;
        for (std::size_t t = 0; t < workers; ++t) pool.emplace_back(work);
        for (std::thread& t : pool) t.join();
    }
    if (error) std::rethrow_exception(error);
    return out;
}

}  // namespace roughscope
