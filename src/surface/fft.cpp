// Internal FFTW3 helper (fft.hpp).
#include "fft.hpp"

#include <cassert>
#include <cstring>
#include <mutex>
#include <new>

#include <fftw3.h>

#include "roughscope/core/memory.hpp"

namespace roughscope::surface::fft {

namespace {

fftw_plan as_plan(void* p) { return static_cast<fftw_plan>(p); }

}  // namespace

// FFTW's planner and fftw_destroy_plan share global state: one lock for both.
std::mutex& planner_mutex() {
    static std::mutex m;
    return m;
}

std::size_t good_size(std::size_t minimum) {
    for (std::size_t n = minimum < 1 ? 1 : minimum;; ++n) {
        std::size_t m = n;
        for (const std::size_t p : {2U, 3U, 5U, 7U}) {
            while (m % p == 0) {
                m /= p;
            }
        }
        if (m == 1) {
            return n;
        }
    }
}

RealToComplex::RealToComplex(std::size_t rows, std::size_t cols, Layout layout)
    : rows_(rows), cols_(cols) {
    assert(rows >= 1 && cols >= 1);
    const std::size_t doubles = rows * 2 * spectrum_cols();
    data_ = static_cast<double*>(fftw_malloc(doubles * sizeof(double)));
    if (data_ == nullptr) {
        throw std::bad_alloc();
    }
    advise_huge_pages(data_, doubles * sizeof(double));  // before FFTW's planner touches it
    plan(layout);
}

RealToComplex::RealToComplex(std::size_t rows, std::size_t cols, Layout layout, double* external)
    : rows_(rows), cols_(cols), data_(external), owned_(false) {
    assert(rows >= 1 && cols >= 1 && external != nullptr);
    plan(layout);
}

void RealToComplex::plan(Layout layout) {
    auto* spectrum = reinterpret_cast<fftw_complex*>(data_);
    const int n_rows = static_cast<int>(rows_);
    const int n_cols = static_cast<int>(cols_);
    const unsigned flags = FFTW_ESTIMATE;
    const std::lock_guard<std::mutex> lock(planner_mutex());
    if (layout == Layout::plane) {
        forward_plan_ = fftw_plan_dft_r2c_2d(n_rows, n_cols, data_, spectrum, flags);
        backward_plan_ = fftw_plan_dft_c2r_2d(n_rows, n_cols, spectrum, data_, flags);
    } else {
        const int real_stride = 2 * static_cast<int>(spectrum_cols());
        const int complex_stride = static_cast<int>(spectrum_cols());
        forward_plan_ = fftw_plan_many_dft_r2c(1, &n_cols, n_rows, data_, nullptr, 1, real_stride,
                                               spectrum, nullptr, 1, complex_stride, flags);
        backward_plan_ =
            fftw_plan_many_dft_c2r(1, &n_cols, n_rows, spectrum, nullptr, 1, complex_stride, data_,
                                   nullptr, 1, real_stride, flags);
    }
    if (forward_plan_ == nullptr || backward_plan_ == nullptr) {
        if (forward_plan_ != nullptr) {
            fftw_destroy_plan(as_plan(forward_plan_));
        }
        if (backward_plan_ != nullptr) {
            fftw_destroy_plan(as_plan(backward_plan_));
        }
        if (owned_) {
            fftw_free(data_);
        }
        throw std::bad_alloc();
    }
}

RealToComplex::~RealToComplex() {
    {
        const std::lock_guard<std::mutex> lock(planner_mutex());
        fftw_destroy_plan(as_plan(forward_plan_));
        fftw_destroy_plan(as_plan(backward_plan_));
    }
    if (owned_) {
        fftw_free(data_);
    }
}

std::complex<double>* RealToComplex::spectrum_row(std::size_t r) {
    // FFTW guarantees fftw_complex and std::complex<double> share their layout.
    return reinterpret_cast<std::complex<double>*>(data_) + r * spectrum_cols();
}

const std::complex<double>* RealToComplex::spectrum_row(std::size_t r) const {
    return reinterpret_cast<const std::complex<double>*>(data_) + r * spectrum_cols();
}

void RealToComplex::fill_zero() {
    std::memset(data_, 0, rows_ * 2 * spectrum_cols() * sizeof(double));
}

void RealToComplex::forward() { fftw_execute(as_plan(forward_plan_)); }

void RealToComplex::backward() { fftw_execute(as_plan(backward_plan_)); }

ComplexPlane::ComplexPlane(std::size_t rows, std::size_t cols) : rows_(rows), cols_(cols) {
    assert(rows >= 1 && cols >= 1);
    auto* buffer = static_cast<fftw_complex*>(fftw_malloc(rows * cols * sizeof(fftw_complex)));
    if (buffer == nullptr) {
        throw std::bad_alloc();
    }
    data_ = reinterpret_cast<std::complex<double>*>(buffer);
    {
        const std::lock_guard<std::mutex> lock(planner_mutex());
        plan_ = fftw_plan_dft_2d(static_cast<int>(rows), static_cast<int>(cols), buffer, buffer,
                                 FFTW_FORWARD, FFTW_ESTIMATE);
    }
    if (plan_ == nullptr) {
        fftw_free(buffer);
        throw std::bad_alloc();
    }
}

ComplexPlane::ComplexPlane(std::size_t rows, std::size_t cols, std::complex<double>* external)
    : rows_(rows), cols_(cols), data_(external), owned_(false) {
    assert(rows >= 1 && cols >= 1 && external != nullptr);
    auto* buffer = reinterpret_cast<fftw_complex*>(external);
    {
        const std::lock_guard<std::mutex> lock(planner_mutex());
        plan_ = fftw_plan_dft_2d(static_cast<int>(rows), static_cast<int>(cols), buffer, buffer,
                                 FFTW_FORWARD, FFTW_ESTIMATE);
    }
    if (plan_ == nullptr) {
        throw std::bad_alloc();
    }
}

ComplexPlane::~ComplexPlane() {
    {
        const std::lock_guard<std::mutex> lock(planner_mutex());
        fftw_destroy_plan(as_plan(plan_));
    }
    if (owned_) {
        fftw_free(data_);
    }
}

void ComplexPlane::forward() { fftw_execute(as_plan(plan_)); }

}  // namespace roughscope::surface::fft
