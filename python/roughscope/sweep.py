"""Sweeps of Monte Carlo scattering simulations: a grid of simulate_scatter runs in parallel.

A sweep is a list of *points*, plain dicts, each one call of :func:`roughscope.simulate_scatter`
at one geometry: the angles ``theta_i_deg``, ``theta_s_deg``, ``phi_s_deg`` (degrees) and the
simulation options (``correlation``, ``sigma_um``, ``T_um``, ``wavelength_um``, ``factor``,
``n``, ``dx_um``, ``patch_over_T``, ``realisations``, ``seed``, ``layout``).

* :func:`grid` builds the points from the Cartesian product of lists of values, each with its own
  seed derived from a base seed and the point's index (:func:`point_seed`).
* :func:`run_sweep` validates every point, then runs them in local processes (the default),
  serially in this process (``processes=1``) or on a dask.distributed cluster
  (``scheduler="tcp://host:port"`` or a ``distributed.Client``), and returns the results in the
  input order. The numbers depend only on the points (their seeds), not on where, in which order
  or with how many threads they run: the three ways give identical results.
* :func:`to_arrays` turns the results into NumPy arrays.

docs/simulation-sweeps.md has the seed rule, the choice between local and cluster, and examples.
"""

from __future__ import annotations

import itertools
import numbers
import os
import sys
from collections.abc import Mapping, Sequence

import numpy as np

from . import _core

__all__ = ["grid", "point_seed", "validate_points", "run_sweep", "to_arrays", "POINT_KEYS",
           "OPTION_KEYS", "ANGLE_KEYS"]

#: The angles of a point (degrees; the paper's frame, docs/conventions.md).
ANGLE_KEYS = ("theta_i_deg", "theta_s_deg", "phi_s_deg")
#: The simulate_scatter options a point may carry (docs/simulation.md, "Options").
OPTION_KEYS = ("correlation", "sigma_um", "T_um", "wavelength_um", "factor", "n", "dx_um",
               "patch_over_T", "realisations", "seed", "layout")
#: Every key a point may have, in the order of the points that grid() builds.
POINT_KEYS = OPTION_KEYS + ANGLE_KEYS

_MASK64 = (1 << 64) - 1
_GOLDEN_GAMMA = 0x9E3779B97F4A7C15


def _mix64(x: int) -> int:
    """SplitMix64's step and finaliser (the library's seed mixer, simulation/kirchhoff.cpp)."""
    x = (x + _GOLDEN_GAMMA) & _MASK64
    x = ((x ^ (x >> 30)) * 0xBF58476D1CE4E5B9) & _MASK64
    x = ((x ^ (x >> 27)) * 0x94D049BB133111EB) & _MASK64
    return x ^ (x >> 31)


def point_seed(base_seed: int, index: int) -> int:
    """The seed of point ``index`` of a grid with ``base_seed``: h(h(base_seed) + index) mod 2^64.

    h is SplitMix64's step and finaliser, the mixer that simulate_scatter applies to its own seed
    per geometry and realisation. h is a bijection of the 64-bit integers, so the points of one
    grid (indices 0 .. 2^64 - 1) always get distinct seeds; the seed depends only on the base seed
    and the index, never on where or when the point runs.
    """
    for name, value in (("base_seed", base_seed), ("index", index)):
        if isinstance(value, bool) or not isinstance(value, numbers.Integral):
            raise TypeError(f"{name} must be an int, not {type(value).__name__}")
        if not 0 <= int(value) <= _MASK64:
            raise _core.InvalidArgument(
                f"{name} = {int(value)} is out of range: it must be an integer in [0, 2^64 - 1]")
    return _mix64((_mix64(int(base_seed)) + int(index)) & _MASK64)


def _as_list(name, value):
    """A scalar (number, string, None) as a one-element list; a list or tuple as a list."""
    if isinstance(value, (str, bytes)) or value is None or not isinstance(value, (Sequence,
                                                                                   np.ndarray)):
        return [value]
    values = list(value.tolist() if isinstance(value, np.ndarray) else value)
    if not values:
        raise _core.InvalidArgument(f"grid: {name} is an empty list: give at least one value")
    return values


def grid(*, sigma_um, T_um, correlation="gaussian", wavelength_um=0.555, geometries=None,
         theta_i_deg=None, theta_s_deg=None, phi_s_deg=None, realisations=100, factor="beckmann",
         layout="lattice_aligned", n=None, dx_um=None, patch_over_T=None, seed=1):
    """The points of the Cartesian product of the given values, each with its own seed.

    Every argument but ``seed`` takes one value or a list of values. The geometries are either
    ``geometries``, a list of ``(theta_i_deg, theta_s_deg, phi_s_deg)`` tuples, or the product of
    the three angle lists ``theta_i_deg``, ``theta_s_deg``, ``phi_s_deg`` (not both). The product
    runs over correlation, sigma_um, T_um, wavelength_um, factor, layout, n, dx_um, patch_over_T,
    realisations and then the geometries, the last varying fastest. Point k (0-based, in that
    order) gets ``seed = point_seed(seed, k)``. Returns a list of dicts with the keys
    ``POINT_KEYS`` (None for "chosen" n, dx_um, patch_over_T), ready for :func:`run_sweep`.
    Values are checked when the sweep runs (:func:`validate_points`).
    """
    angle_lists = (theta_i_deg, theta_s_deg, phi_s_deg)
    if geometries is not None:
        if any(a is not None for a in angle_lists):
            raise _core.InvalidArgument(
                "grid: give either geometries or theta_i_deg/theta_s_deg/phi_s_deg, not both")
        geoms = _as_list("geometries", geometries)
        if len(geoms) == 3 and all(isinstance(a, numbers.Real) for a in geoms):
            geoms = [tuple(geoms)]  # one geometry given as a bare (θi, θs, φs)
        for k, geom in enumerate(geoms):
            if not isinstance(geom, (Sequence, np.ndarray)) or isinstance(geom, str) \
                    or len(geom) != 3:
                raise _core.InvalidArgument(
                    f"grid: geometries[{k}] = {geom!r} is not a (theta_i_deg, theta_s_deg, "
                    f"phi_s_deg) triple")
        geoms = [tuple(g) for g in geoms]
    else:
        if any(a is None for a in angle_lists):
            raise _core.InvalidArgument(
                "grid: give geometries, or all three of theta_i_deg, theta_s_deg and phi_s_deg")
        geoms = list(itertools.product(*(_as_list(name, a) for name, a in
                                         zip(ANGLE_KEYS, angle_lists))))
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral):
        raise TypeError(f"grid: seed must be an int (the base seed), not {type(seed).__name__}")
    axes = [("correlation", correlation), ("sigma_um", sigma_um), ("T_um", T_um),
            ("wavelength_um", wavelength_um), ("factor", factor), ("layout", layout), ("n", n),
            ("dx_um", dx_um), ("patch_over_T", patch_over_T), ("realisations", realisations)]
    names = [name for name, _ in axes]
    lists = [_as_list(name, value) for name, value in axes]
    points = []
    for k, (values, geom) in enumerate(
            (v, g) for v in itertools.product(*lists) for g in geoms):
        options = dict(zip(names, values))
        point = {key: options[key] for key in OPTION_KEYS if key != "seed"}
        point["seed"] = point_seed(seed, k)
        point.update(zip(ANGLE_KEYS, geom))
        points.append({key: point[key] for key in POINT_KEYS})
    return points


def _is_real_scalar(value):
    return (isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))) or (
        isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf")


def validate_points(points):
    """Checks every point before anything runs; returns the points as a list of dicts.

    Raises roughscope.InvalidArgument (a ValueError) or TypeError naming the point's index and
    the key: a point that is not a dict, an unknown key, a missing angle, an angle that is not
    one real number, and every value simulate_scatter would refuse (the options, the geometry,
    the grid chosen or given there: roughscope.check_simulate_scatter, which generates nothing).
    """
    return _validate(points)[0]


def _validate(points):
    """validate_points, and the relative cost of each point (realisations × N² log N, N the side
    of the surface generated per realisation)."""
    if isinstance(points, Mapping) or not isinstance(points, (Sequence, np.ndarray)):
        raise TypeError("points must be a list of dicts (one per simulation), e.g. from grid()")
    checked, costs = [], []
    for i, point in enumerate(points):
        if not isinstance(point, Mapping):
            raise TypeError(f"sweep point {i} is a {type(point).__name__}, not a dict")
        unknown = [key for key in point if key not in POINT_KEYS]
        if unknown:
            reserved = {"threads": "run_sweep sets it", "progress": "give it to run_sweep"}
            why = reserved.get(str(unknown[0]), f"valid keys: {', '.join(POINT_KEYS)}")
            raise _core.InvalidArgument(f"sweep point {i}: key {unknown[0]!r} is not a point "
                                        f"key ({why})")
        for key in ANGLE_KEYS:
            if key not in point:
                raise _core.InvalidArgument(f"sweep point {i}: key {key!r} is missing (every "
                                            f"point needs {', '.join(ANGLE_KEYS)})")
            if not _is_real_scalar(point[key]):
                raise TypeError(f"sweep point {i}: {key} = {point[key]!r} must be one real "
                                f"number (one geometry per point)")
        point = dict(point)
        options = {key: value for key, value in point.items() if key not in ANGLE_KEYS}
        try:
            (plan,) = _core.check_simulate_scatter(*(point[key] for key in ANGLE_KEYS), **options)
        except (_core.Error, TypeError) as exc:
            raise type(exc)(f"sweep point {i}: {exc}") from exc
        side = plan["generated_n"]
        costs.append(int(options.get("realisations", 100)) * side * side * np.log2(side))
        checked.append(point)
    return checked, costs


def _run_point(point, threads):
    """One task: simulate_scatter at the point, as {"point", "options", "results"}."""
    options = {key: value for key, value in point.items() if key not in ANGLE_KEYS}
    doc = _core.simulate_scatter(*(point[key] for key in ANGLE_KEYS), threads=threads, **options)
    return {"point": dict(point), "options": doc["options"], "results": doc["results"]}


class _Progress:
    """Reports (done, total) to a callable, or on stderr when it is a terminal."""

    def __init__(self, progress, total):
        if progress is not None and not callable(progress):
            raise TypeError("progress must be a callable (done, total) or None")
        self.callback = progress
        self.total = total
        self.on_terminal = progress is None and total > 0 and sys.stderr is not None and \
            hasattr(sys.stderr, "isatty") and sys.stderr.isatty()

    def __call__(self, done):
        if self.callback is not None:
            self.callback(done, self.total)
        elif self.on_terminal:
            end = "\n" if done == self.total else ""
            sys.stderr.write(f"\rroughscope sweep: {done}/{self.total} points{end}")
            sys.stderr.flush()


def _check_count(name, value):
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an int or None, not {type(value).__name__}")
    return int(value)


def run_sweep(points, *, scheduler=None, processes=None, progress=None, threads=None,
              connect_timeout_s=5.0):
    """Runs simulate_scatter at every point; returns the results in the order of ``points``.

    Each result is the point's simulate_scatter document with the point added:
    ``{"point": {...}, "options": {...}, "results": [{...}]}`` (one geometry per point; the keys of
    docs/simulation.md). Every point is validated first (:func:`validate_points`): a bad grid
    raises before anything runs.

    Where the points run:

    * ``scheduler=None`` (default): ``processes`` local worker processes (default
      ``os.cpu_count()``, at most one per point) of a concurrent.futures.ProcessPoolExecutor
      (start method forkserver: a script that calls run_sweep needs the usual
      ``if __name__ == "__main__":`` guard); ``processes=1`` runs them one after the other in this
      process.
    * ``scheduler="tcp://host:port"``: on that dask.distributed cluster (a Client is opened with a
      ``connect_timeout_s`` timeout and closed at the end; an unreachable address raises
      ConnectionError naming it). ``scheduler=<distributed.Client>``: on that client's cluster.
      The workers must be able to import roughscope.

    ``threads``: simulate_scatter's threads per point; default 1 in worker processes and on a
    cluster, 0 (all cores) when run in this process. The numbers do not depend on it.
    ``progress``: a callable(done, total) called as points complete, or None for a line on stderr
    when it is a terminal. Ctrl-C (KeyboardInterrupt) cancels the points not yet run and is
    re-raised; an exception from a point cancels the rest and is raised with a note naming the
    point.
    """
    points, costs = _validate(points)
    # The most expensive points start first: the last to finish is then a short one.
    order = sorted(range(len(points)), key=lambda i: -costs[i])
    if processes is not None:
        processes = _check_count("processes", processes)
        if not 1 <= processes <= 4096:
            raise _core.InvalidArgument(
                f"processes = {processes} is out of range: it must be an integer in [1, 4096]")
    if threads is not None:
        threads = _check_count("threads", threads)
        if not 0 <= threads <= 1024:
            raise _core.InvalidArgument(
                f"threads = {threads} is out of range: it must be an integer in [0, 1024]")
    if not (isinstance(connect_timeout_s, numbers.Real) and 0 < connect_timeout_s <= 3600):
        raise _core.InvalidArgument(f"connect_timeout_s = {connect_timeout_s!r} is out of range: "
                                    f"it must be a number of seconds in (0, 3600]")
    report = _Progress(progress, len(points))
    if scheduler is not None:
        return _run_on_dask(points, order, scheduler, report, 1 if threads is None else threads,
                            connect_timeout_s)
    if processes is None:
        processes = os.cpu_count() or 1
    processes = min(processes, max(len(points), 1))
    if processes == 1:
        return _run_serial(points, report, 0 if threads is None else threads)
    return _run_processes(points, order, processes, report, 1 if threads is None else threads)


def _with_note(exc, i, point):
    exc.add_note(f"in sweep point {i}: {point}")
    return exc


def _run_serial(points, report, threads):
    results = []
    for i, point in enumerate(points):
        try:
            results.append(_run_point(point, threads))
        except KeyboardInterrupt:
            raise
        except Exception as exc:
            raise _with_note(exc, i, point)
        report(i + 1)
    return results


def _run_processes(points, order, processes, report, threads):
    import concurrent.futures
    import multiprocessing

    methods = multiprocessing.get_all_start_methods()
    context = multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")
    results = [None] * len(points)
    executor = concurrent.futures.ProcessPoolExecutor(max_workers=processes, mp_context=context)
    futures = {}
    try:
        futures = {executor.submit(_run_point, points[i], threads): i for i in order}
        done = 0
        for future in concurrent.futures.as_completed(futures):
            i = futures[future]
            try:
                results[i] = future.result()
            except Exception as exc:
                raise _with_note(exc, i, points[i])
            done += 1
            report(done)
    except BaseException:
        for future in futures:
            future.cancel()
        executor.shutdown(wait=False, cancel_futures=True)
        raise
    executor.shutdown(wait=True)
    return results


def _connect(address, timeout_s):
    try:
        import distributed
    except ImportError as exc:  # a declared dependency (python3-distributed)
        raise ImportError(f"a sweep on a dask scheduler needs dask.distributed (Debian package "
                          f"python3-distributed): {exc}") from exc
    if not isinstance(address, str):
        raise TypeError(f"scheduler must be an address 'tcp://host:port' or a "
                        f"distributed.Client, not {type(address).__name__}")
    try:
        return distributed.Client(address, timeout=f"{timeout_s}s", set_as_default=False)
    except (OSError, TimeoutError) as exc:
        raise ConnectionError(f"cannot reach the dask scheduler at {address} within {timeout_s} s "
                              f"({type(exc).__name__}: {exc})") from exc


def _run_on_dask(points, order, scheduler, report, threads, timeout_s):
    own_client = not (hasattr(scheduler, "map") and hasattr(scheduler, "gather"))
    client = _connect(scheduler, timeout_s) if own_client else scheduler
    import distributed

    submitted = []
    try:
        # Submitted most expensive first (the scheduler starts tasks in submission order); the
        # results are gathered back into the input order.
        submitted = client.map(_run_point, [points[i] for i in order], threads=threads)
        futures = [None] * len(points)
        for i, future in zip(order, submitted):
            futures[i] = future
        index = {future.key: i for i, future in zip(order, submitted)}
        done = 0
        for future in distributed.as_completed(submitted, loop=client.loop):
            if future.status == "error":
                i = index[future.key]
                try:
                    future.result()
                except Exception as exc:
                    raise _with_note(exc, i, points[i])
            done += 1
            report(done)
        return client.gather(futures)
    except BaseException:
        if submitted:
            client.cancel(submitted)
        raise
    finally:
        if own_client:
            client.close()


#: Result keys that to_arrays returns as float arrays (None → NaN) and as int arrays.
_FLOAT_KEYS = ("theta_i_deg", "theta_s_deg", "phi_s_deg", "g", "T_vxy", "F2", "diffuse",
               "diffuse_stderr", "coherent", "coherent_stderr", "series_diffuse",
               "series_coherent", "diffuse_deviation", "dx_um", "patch_um", "area_um2")
_INT_KEYS = ("n", "realisations", "lattice_index")


def to_arrays(results):
    """The results of run_sweep as a dict of 1-D NumPy arrays, one entry per point, in order.

    Float arrays (None → NaN) for the result keys theta_i_deg … area_um2 (diffuse,
    diffuse_stderr, coherent, series_diffuse, g, ...), int64 for n, realisations, lattice_index,
    str for layout; and from the options each point ran with: sigma_um, T_um, wavelength_um
    (float), correlation, factor (str), seed (uint64).
    """
    rows = []
    for i, result in enumerate(results):
        try:
            (row,) = result["results"]
            options = result["options"]
        except (KeyError, TypeError, ValueError) as exc:
            raise _core.InvalidArgument(f"to_arrays: results[{i}] is not a run_sweep result of "
                                        f"one geometry") from exc
        rows.append((options, row))

    def column(source, key, dtype):
        values = [(o if source == "options" else r)[key] for o, r in rows]
        if dtype is float:
            return np.array([np.nan if v is None else v for v in values], dtype=float)
        return np.array(values, dtype=dtype)

    out = {key: column("result", key, float) for key in _FLOAT_KEYS}
    out.update({key: column("result", key, np.int64) for key in _INT_KEYS})
    out["layout"] = column("result", "layout", str)
    for key in ("sigma_um", "T_um", "wavelength_um"):
        out[key] = column("options", key, float)
    for key in ("correlation", "factor"):
        out[key] = column("options", key, str)
    out["seed"] = column("options", "seed", np.uint64)
    return out
