// Internal FFTW3 helper of the surface topic (not installed): an RAII in-place real-to-complex
// transform of a rows × cols array of doubles, either as one 2-D transform or as `rows`
// independent 1-D transforms along the rows.
//
// FFTW's planner (and plan destruction) is not thread-safe, so every plan is made and destroyed
// under one process-wide mutex; executing a plan is thread-safe. Plans use FFTW_ESTIMATE: no
// timing measurements, so the same sizes give the same plan, and the same input the same bits, on
// every run of the same build on the same machine (FFTW's SIMD code paths may round differently on
// another processor or FFTW version). Transforms are unnormalised (FFTW's convention): forward then
// backward multiplies by the number of points transformed.
#pragma once

#include <complex>
#include <cstddef>
#include <mutex>

namespace roughscope::surface::fft {

// The one lock around FFTW's planner and fftw_destroy_plan for every FFT of the library.
std::mutex& planner_mutex();

// The smallest n ≥ minimum whose prime factors are all 2, 3, 5 or 7 (a fast FFTW size).
std::size_t good_size(std::size_t minimum);

enum class Layout {
    plane,  // one 2-D transform of the rows × cols array
    rows,   // rows independent 1-D transforms of length cols
};

class RealToComplex {
  public:
    // Allocates the (aligned) buffer and plans the forward and backward transforms; the buffer
    // starts uninitialised (fill_zero() clears it). Throws std::bad_alloc when the buffer cannot
    // be allocated.
    RealToComplex(std::size_t rows, std::size_t cols, Layout layout);
    // The same on the caller's array of rows·2·(cols/2 + 1) doubles (not owned: it must outlive
    // the transform; FFTW picks codelets for its alignment, so give it 32-byte alignment for the
    // fastest ones).
    RealToComplex(std::size_t rows, std::size_t cols, Layout layout, double* external);
    ~RealToComplex();
    RealToComplex(const RealToComplex&) = delete;
    RealToComplex& operator=(const RealToComplex&) = delete;
    RealToComplex(RealToComplex&&) = delete;
    RealToComplex& operator=(RealToComplex&&) = delete;

    std::size_t rows() const { return rows_; }
    std::size_t cols() const { return cols_; }
    // Complex columns of the half spectrum: cols/2 + 1 (frequencies 0..cols/2 along the rows).
    std::size_t spectrum_cols() const { return cols_ / 2 + 1; }
    // Row r of the real array (cols values; the row stride is 2·spectrum_cols() doubles).
    double* real_row(std::size_t r) { return data_ + r * 2 * spectrum_cols(); }
    const double* real_row(std::size_t r) const { return data_ + r * 2 * spectrum_cols(); }
    // Row r of the half spectrum (spectrum_cols() values), valid after forward().
    std::complex<double>* spectrum_row(std::size_t r);
    const std::complex<double>* spectrum_row(std::size_t r) const;

    void fill_zero();
    void forward();   // real → half spectrum, in place
    void backward();  // half spectrum (Hermitian) → real, in place, unnormalised

  private:
    void plan(Layout layout);  // makes both plans on data_; frees an owned buffer on failure

    std::size_t rows_;
    std::size_t cols_;
    double* data_ = nullptr;
    bool owned_ = true;
    void* forward_plan_ = nullptr;
    void* backward_plan_ = nullptr;
};

// An in-place complex-to-complex 2-D transform of a rows × cols array (row-major), forward
// (e^{−i…}, FFTW_FORWARD) only. Used by the Kirchhoff simulation (simulation topic), which
// includes this internal header through the library's private include path.
class ComplexPlane {
  public:
    ComplexPlane(std::size_t rows, std::size_t cols);  // std::bad_alloc when it cannot allocate
    // The same on the caller's array of rows·cols values (not owned; it must outlive the plane).
    // FFTW picks codelets for the array's alignment.
    ComplexPlane(std::size_t rows, std::size_t cols, std::complex<double>* external);
    ~ComplexPlane();
    ComplexPlane(const ComplexPlane&) = delete;
    ComplexPlane& operator=(const ComplexPlane&) = delete;
    ComplexPlane(ComplexPlane&&) = delete;
    ComplexPlane& operator=(ComplexPlane&&) = delete;

    std::size_t rows() const { return rows_; }
    std::size_t cols() const { return cols_; }
    std::complex<double>* data() { return data_; }
    const std::complex<double>* data() const { return data_; }
    void forward();  // in place, unnormalised

  private:
    std::size_t rows_;
    std::size_t cols_;
    std::complex<double>* data_ = nullptr;
    bool owned_ = true;
    void* plan_ = nullptr;
};

}  // namespace roughscope::surface::fft
