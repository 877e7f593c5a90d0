// The roughness map's cells into its layers (map_evaluator.cpp), and the passes over the rows of
// the two captures that feed it (map_passes.cpp). Private to the maps topic.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "maps/map_internal.hpp"
#include "roughscope/estimation/estimation.hpp"
#include "roughscope/maps/maps.hpp"

namespace roughscope::image::detail {

// Evaluates cells into the layers of the map (one copy per thread: its own hints and counts).
class Evaluator {
  public:
    // Builds the tables of a flat sample (shared by the threads' copies, read only) and sets the
    // map's method.
    Evaluator(const std::vector<MapCapture>& captures, const MapOptions& o, RoughnessMap& map);

    // A flat sample's pixel (the layers' cells already NaN / no class): the two tables at the
    // ratio E1/E2, the error through their slopes.
    void evaluate_flat(std::size_t index, double ratio, double sd_lr);

    // A flat sample without σ (σ/T and its error, the class; the other correlation's σ/T and
    // error and E1/E2 where their layers are made): a row of pixels from `begin`, every cell
    // written once (no fill first).
    bool fast_flat() const { return flat_ && !o_.sigma_um; }
    // Returns the row's class sums.
    ClassSums evaluate_flat_row(std::size_t begin, std::size_t count, const double* ratio,
                                const double* var_log_ratio, const double* state);

    bool flat() const { return flat_; }
    // A flat sample's σ/T table of correlation c (null where it was not built).
    const RatioInverseTable* sigma_over_T_table(Correlation c) const {
        return c == Correlation::Gaussian ? table_g_.get() : table_e_.get();
    }

    // Any cell (tile, or a pixel of a map with σ or a normal map) into every layer.
    void evaluate(std::size_t index, const Cell& cell);

    // σ known: the class by g and T from the diffuse term valid at the cell's g (Eq. 3, i.e.
    // Eq. 15, for a slightly rough cell; the exact series otherwise).
    void estimate_T(std::size_t index, double lr, double sd_lr,
                    const std::optional<Geometry>& geom1, const std::optional<Geometry>& geom2);

    Counts& counts() { return counts_; }
    std::optional<RoughnessClass> flat_g_class() const { return flat_g_class_; }

  private:
    // The two-geometry solver (normal map), with d(σ/T)/d ln r = σ/T / (d ln M/d ln(σ/T)).
    std::optional<Estimate> solve(double lr, double sd_lr, const Geometry& g1, const Geometry& g2,
                                  Correlation c) const;

    const MapCapture& c1_;
    const MapCapture& c2_;
    const MapOptions& o_;
    RoughnessMap& map_;
    TwoGeometryOptions model_;
    bool flat_ = true;
    std::shared_ptr<const RatioInverseTable> table_g_, table_e_, table_t_, table_t2_;
    double sigma_step_ = 0.0;
    std::optional<RoughnessClass> flat_g_class_;
    std::size_t hint_g_ = 0, hint_e_ = 0, hint_t_ = 0, hint_t2_ = 0;
    Counts counts_;
    // A row's σ/T and slopes (primary, other correlation), and its class as a double
    // (evaluate_flat_row).
    std::vector<double> xp_, sp_, xo_, so_, klass_;
};

// ---------------------------------------------------------------------------------------------
// The passes over the rows (map_passes.cpp), each over a band of rows of the map [begin, end)
// on one thread: the cells' region (cell_region, −1: none or more than one) and each row's class
// sums (row_classes, added in row order afterwards, so the means do not depend on the bands).

// Tiles: one pass over the rows, the sums of each tile of a row of tiles.
void tile_map(const std::vector<MapCapture>& captures, const MapOptions& o, Evaluator& ev,
              RoughnessMap& map, std::vector<std::int32_t>& cell_region,
              std::vector<ClassSums>& row_classes, std::size_t ty_begin, std::size_t ty_end);

// Per pixel: the pixel's ratio, the noise from the (2R + 1)² neighbourhood.
void pixel_map(const std::vector<MapCapture>& captures, const MapOptions& o, Evaluator& ev,
               RoughnessMap& map, std::vector<std::int32_t>& cell_region,
               std::vector<ClassSums>& row_classes, std::size_t r_begin, std::size_t r_end);

// The first touch of every cell of rows [r_begin, r_end) of the map: NaN, no class (the
// layers are allocated without a fill; each band's thread writes its own).
void clear_rows(RoughnessMap& map, std::size_t r_begin, std::size_t r_end);

}  // namespace roughscope::image::detail
