// Internal: the zero-padded real FFT of one line of heights (FFTW3), used by the row and column
// autocorrelations (acf.cpp). One RowFft owns its plans and aligned buffers (RAII); plans are
// made with FFTW_ESTIMATE, so results are reproducible from run to run.
#pragma once

#include <cstddef>
#include <mutex>

#include <fftw3.h>

namespace roughscope::surface::detail {

// FFTW's planner is not thread-safe: plans are created and destroyed under this lock.
inline std::mutex& fft_rows_planner_mutex() {
    static std::mutex mutex;
    return mutex;
}

// Smallest n' ≥ n of the form 2^a 3^b 5^c (sizes FFTW transforms fastest).
inline std::size_t fft_friendly_size(std::size_t n) {
    if (n <= 1) return 1;
    for (std::size_t m = n;; ++m) {
        std::size_t r = m;
        for (std::size_t p : {2U, 3U, 5U})
            while (r % p == 0) r /= p;
        if (r == 1) return m;
    }
}

// A real buffer of nfft points, its half spectrum of nfft/2 + 1 points, and the forward (r2c)
// and backward (c2r, unnormalised: a round trip multiplies by nfft) plans between them.
class RowFft {
  public:
    explicit RowFft(std::size_t nfft) : nfft_(nfft) {
        real_ = fftw_alloc_real(nfft_);
        spectrum_ = fftw_alloc_complex(nfft_ / 2 + 1);
        const std::lock_guard<std::mutex> lock(fft_rows_planner_mutex());
        const int n = static_cast<int>(nfft_);
        forward_ = fftw_plan_dft_r2c_1d(n, real_, spectrum_, FFTW_ESTIMATE);
        backward_ = fftw_plan_dft_c2r_1d(n, spectrum_, real_, FFTW_ESTIMATE);
    }
    ~RowFft() {
        {
            const std::lock_guard<std::mutex> lock(fft_rows_planner_mutex());
            fftw_destroy_plan(forward_);
            fftw_destroy_plan(backward_);
        }
        fftw_free(real_);
        fftw_free(spectrum_);
    }
    RowFft(const RowFft&) = delete;
    RowFft& operator=(const RowFft&) = delete;
    RowFft(RowFft&&) = delete;
    RowFft& operator=(RowFft&&) = delete;

    std::size_t nfft() const { return nfft_; }
    std::size_t spectrum_size() const { return nfft_ / 2 + 1; }
    double* real() { return real_; }
    fftw_complex* spectrum() { return spectrum_; }
    void forward() { fftw_execute(forward_); }
    void backward() { fftw_execute(backward_); }  // c2r destroys the spectrum (FFTW)

    // real[j] ← nfft · Σ_k real[k] real[k + j] for j < nfft/2 (the input must be zero-padded to
    // at least twice its length − 1, so the circular correlation has no wrap-around).
    void autocorrelate_in_place() {
        forward();
        const std::size_t ns = spectrum_size();
        for (std::size_t k = 0; k < ns; ++k) {
            const double re = spectrum_[k][0];
            const double im = spectrum_[k][1];
            spectrum_[k][0] = re * re + im * im;
            spectrum_[k][1] = 0.0;
        }
        backward();
    }

  private:
    std::size_t nfft_;
    double* real_ = nullptr;
    fftw_complex* spectrum_ = nullptr;
    fftw_plan forward_ = nullptr;
    fftw_plan backward_ = nullptr;
};

}  // namespace roughscope::surface::detail
