#!/usr/bin/env python3
"""Convergence of the Kirchhoff Monte Carlo (docs/simulation.md, "Convergence"): the simulated
diffuse power over the exact series against the grid spacing dx/T, the patch side L/T (both
layouts) and the number of realisations. Prints Markdown tables.

    PYTHONPATH=build/python /usr/bin/python3 scripts/simulation_convergence.py
"""

import roughscope as rs

LAMBDA = 0.5
GEOM = (30.0, 0.0, 0.0)  # θi, θs, φs: T·v_xy = 2π at T = 1 µm, λ = 0.5 µm


def ratio(correlation, sigma, **options):
    doc = rs.simulate_scatter(*GEOM, correlation=correlation, sigma_um=sigma, T_um=1.0,
                              wavelength_um=LAMBDA, seed=7, **options)
    r = doc["results"][0]
    return r, r["diffuse"] / r["series_diffuse"], r["diffuse_stderr"] / r["series_diffuse"]


def row(cells):
    print("| " + " | ".join(cells) + " |")


def main():
    print("### Grid spacing (L = 12 T, 200 realisations, lattice-aligned)\n")
    row(["correlation", "g", "dx/T", "dx/λ", "n", "simulated / series"])
    row(["---"] * 6)
    for correlation, sigma in [("gaussian", 0.12), ("exponential", 0.12), ("exponential", 0.03)]:
        for dx in [0.5, 0.25, 0.125, 0.0625, 0.03125]:
            n = int(round(12 / dx))
            r, q, e = ratio(correlation, sigma, n=n, dx_um=dx, realisations=200)
            row([correlation, f"{r['g']:.2f}", f"{r['dx_um']:.4f}", f"{r['dx_um'] / LAMBDA:.3f}",
                 str(r["n"]), f"{q:.3f} ± {e:.3f}"])
        r, q, e = ratio(correlation, sigma, realisations=200)
        row([correlation, f"{r['g']:.2f}", f"{r['dx_um']:.4f} (chosen)",
             f"{r['dx_um'] / LAMBDA:.3f}", str(r["n"]), f"{q:.3f} ± {e:.3f}"])
    print("\n### Patch side (spacing chosen, 200 realisations)\n")
    row(["correlation", "g", "L/T", "layout", "simulated / series"])
    row(["---"] * 5)
    for correlation, sigma in [("gaussian", 0.06), ("exponential", 0.06)]:
        for L in [2, 4, 8, 16]:
            for layout in ["lattice_aligned", "fixed"]:
                r, q, e = ratio(correlation, sigma, patch_over_T=L, layout=layout,
                                realisations=200)
                row([correlation, f"{r['g']:.2f}", f"{r['patch_um']:.2f}", layout,
                     f"{q:.3f} ± {e:.3f}"])
    print("\n### Realisations (gaussian, g ≈ 2, grid chosen)\n")
    row(["realisations", "relative standard error", "× √R"])
    row(["---"] * 3)
    for R in [25, 100, 400, 1600]:
        r, q, e = ratio("gaussian", 0.06, realisations=R)
        row([str(R), f"{e:.4f}", f"{e * R ** 0.5:.2f}"])


if __name__ == "__main__":
    main()
