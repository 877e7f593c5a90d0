"""roughscope.sweep: grids of simulate_scatter runs, serial, in local processes and on dask.

The independent facts: the serial run (one simulate_scatter call per point in this process) is
the reference that the process pool and a two-worker dask LocalCluster must reproduce exactly
(==, every key of every result); the seed rule is SplitMix64's, whose first output from state 0 is
the published 0xE220A8397B1DCDAF; a bad point is refused with the same message that
simulate_scatter itself gives, before any point runs.

dask.distributed (Debian's python3-distributed) is a declared dependency: it is imported
unconditionally, so a missing package fails these tests instead of skipping them.
"""

import os
import pathlib
import socket
import time

import distributed
import numpy as np
import pytest

import roughscope as rs
from roughscope import sweep

# Small and fast: 2 correlations x 2 sigma x 3 geometries = 12 points of 10 realisations on
# patches of 2 T (n = 8 .. 40).
GRID = dict(sigma_um=[0.05, 0.1], T_um=1.0, wavelength_um=0.5,
            correlation=["gaussian", "exponential"],
            geometries=[(30, 0, 0), (45, 20, 90), (10, 10, 0)], realisations=10, patch_over_T=2,
            seed=7)


@pytest.fixture(scope="module")
def points():
    return sweep.grid(**GRID)


@pytest.fixture(scope="module")
def serial(points):
    return sweep.run_sweep(points, processes=1)


@pytest.fixture(scope="module")
def cluster():
    """Two worker processes of one thread; they import roughscope through PYTHONPATH."""
    package_parent = str(pathlib.Path(rs.__file__).resolve().parents[1])
    old = os.environ.get("PYTHONPATH")
    os.environ["PYTHONPATH"] = os.pathsep.join([package_parent] + ([old] if old else []))
    try:
        with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                      dashboard_address=None) as local_cluster:
            yield local_cluster
    finally:
        if old is None:
            del os.environ["PYTHONPATH"]
        else:
            os.environ["PYTHONPATH"] = old


def unused_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


# --- the grid and its seeds --------------------------------------------------------------------

def test_seed_rule_is_splitmix64():
    # SplitMix64 from state 0: first output 0xE220A8397B1DCDAF (Vigna's reference generator).
    assert sweep._mix64(0) == 0xE220A8397B1DCDAF
    assert sweep.point_seed(7, 3) == sweep._mix64((sweep._mix64(7) + 3) % 2**64)
    assert sweep.point_seed(2**64 - 1, 2**64 - 1) < 2**64
    with pytest.raises(rs.InvalidArgument, match="base_seed = -1"):
        sweep.point_seed(-1, 0)
    with pytest.raises(TypeError, match="index"):
        sweep.point_seed(1, 1.0)


def test_grid_is_the_product_in_the_documented_order(points):
    assert len(points) == 2 * 2 * 3
    assert all(list(p) == list(sweep.POINT_KEYS) for p in points)
    # correlation varies slowest, the geometry fastest.
    assert [p["correlation"] for p in points] == ["gaussian"] * 6 + ["exponential"] * 6
    assert [p["sigma_um"] for p in points[:6]] == [0.05] * 3 + [0.1] * 3
    assert [(p["theta_i_deg"], p["theta_s_deg"], p["phi_s_deg"]) for p in points[:3]] == \
        GRID["geometries"]
    assert [p["seed"] for p in points] == [sweep.point_seed(7, k) for k in range(12)]


def test_every_point_has_its_own_seed_and_its_own_surfaces(points, serial):
    seeds = [p["seed"] for p in points]
    assert len(set(seeds)) == len(seeds)
    assert all(0 <= s < 2**64 for s in seeds) and max(seeds) >= 2**63  # the whole 64-bit range
    # Same parameters, different seeds: different surfaces, different estimates.
    same = sweep.grid(**dict(GRID, sigma_um=0.05, correlation="gaussian",
                             geometries=[(30, 0, 0)] * 3))
    diffuse = [r["results"][0]["diffuse"] for r in sweep.run_sweep(same, processes=1)]
    assert len(set(diffuse)) == 3
    # The seed of the point, not its place in the sweep, makes the numbers.
    assert serial[4]["results"] == sweep.run_sweep([points[4]], processes=1)[0]["results"]


def test_grid_from_three_angle_lists():
    pts = sweep.grid(sigma_um=0.05, T_um=1.0, theta_i_deg=[10, 20], theta_s_deg=0,
                     phi_s_deg=[0, 90, 180])
    assert [(p["theta_i_deg"], p["phi_s_deg"]) for p in pts] == \
        [(10, 0), (10, 90), (10, 180), (20, 0), (20, 90), (20, 180)]
    with pytest.raises(rs.InvalidArgument, match="not both"):
        sweep.grid(sigma_um=0.05, T_um=1.0, geometries=[(0, 0, 0)], theta_i_deg=[10])
    with pytest.raises(rs.InvalidArgument, match="all three"):
        sweep.grid(sigma_um=0.05, T_um=1.0, theta_i_deg=[10])
    with pytest.raises(rs.InvalidArgument, match=r"geometries\[1\]"):
        sweep.grid(sigma_um=0.05, T_um=1.0, geometries=[(0, 0, 0), (1, 2)])
    with pytest.raises(rs.InvalidArgument, match="sigma_um is an empty list"):
        sweep.grid(sigma_um=[], T_um=1.0, geometries=[(0, 0, 0)])


# --- serial, processes, dask: the same numbers in the same order -------------------------------

def test_serial_results_are_in_input_order_and_match_simulate_scatter(points, serial):
    assert len(serial) == len(points)
    for point, result in zip(points, serial):
        assert result["point"] == point
        (row,) = result["results"]
        assert (row["theta_i_deg"], row["theta_s_deg"], row["phi_s_deg"]) == \
            (point["theta_i_deg"], point["theta_s_deg"], point["phi_s_deg"])
        assert result["options"]["seed"] == point["seed"]
        assert result["options"]["correlation"] == point["correlation"]
    # One point by hand through simulate_scatter (threads do not change the numbers).
    p = points[7]
    doc = rs.simulate_scatter(p["theta_i_deg"], p["theta_s_deg"], p["phi_s_deg"], threads=2,
                              **{k: v for k, v in p.items() if k in sweep.OPTION_KEYS})
    assert doc["results"] == serial[7]["results"]


def test_process_pool_gives_the_serial_results(points, serial):
    calls = []
    results = sweep.run_sweep(points, processes=2, progress=lambda d, t: calls.append((d, t)))
    assert results == serial
    assert calls == [(k, len(points)) for k in range(1, len(points) + 1)]


def test_dask_cluster_gives_the_serial_results(points, serial, cluster):
    # Reversed: the results follow the order of the points given, whatever the completion order.
    order = list(range(len(points)))[::-1]
    with distributed.Client(cluster, set_as_default=False) as client:
        results = sweep.run_sweep([points[i] for i in order], scheduler=client)
        assert results == [serial[i] for i in order]
        assert len(client.scheduler_info()["workers"]) == 2
    # By address: run_sweep opens (and closes) its own client.
    calls = []
    results = sweep.run_sweep(points, scheduler=cluster.scheduler_address,
                              progress=lambda d, t: calls.append(d))
    assert results == serial
    assert calls == list(range(1, len(points) + 1))


def test_to_arrays(serial, points):
    arrays = sweep.to_arrays(serial)
    assert arrays["diffuse"].shape == (len(points),)
    assert arrays["diffuse"].tolist() == [r["results"][0]["diffuse"] for r in serial]
    assert arrays["seed"].dtype == np.uint64
    assert arrays["seed"].tolist() == [p["seed"] for p in points]
    assert arrays["correlation"].tolist() == [p["correlation"] for p in points]
    assert arrays["n"].dtype == np.int64 and (arrays["n"] >= 8).all()
    # The closed form next to the estimate: g = sigma^2 v_z^2 scales with sigma^2.
    assert arrays["g"][3] / arrays["g"][0] == pytest.approx((0.1 / 0.05) ** 2, rel=1e-12)
    with pytest.raises(rs.InvalidArgument, match=r"results\[0\]"):
        sweep.to_arrays([{"results": []}])


# --- failures: before anything runs ------------------------------------------------------------

def bad_points(points, index, **changes):
    out = [dict(p) for p in points]
    out[index].update(changes)
    return out


@pytest.mark.parametrize("change,error,message", [
    (dict(sigma_um=-1.0), rs.InvalidArgument, "sweep point 4: .*sigma"),
    (dict(realisations=1), rs.InvalidArgument, "sweep point 4: .*realisations = 1"),
    (dict(correlation="lorentzian"), rs.InvalidArgument, "sweep point 4: .*lorentzian"),
    (dict(theta_i_deg=95.0), rs.InvalidArgument, "sweep point 4: .*theta_i"),
    (dict(theta_i_deg=[10, 20]), TypeError, "sweep point 4: theta_i_deg"),
    (dict(threads=2), rs.InvalidArgument, "sweep point 4: key 'threads'.*run_sweep sets it"),
    (dict(sigma=0.1), rs.InvalidArgument, "sweep point 4: key 'sigma' is not a point key"),
    (dict(seed=2**64), rs.InvalidArgument, "sweep point 4: .*seed"),
    # Only the grid at the geometry shows this one: dx beyond the Nyquist limit pi/|v_xy|.
    (dict(dx_um=0.5, patch_over_T=None), rs.InvalidArgument, "sweep point 4: .*Nyquist"),
])
def test_a_bad_point_fails_before_anything_runs(points, change, error, message):
    pts = bad_points(points, 4, **change)
    calls = []
    for where in (dict(processes=1), dict(processes=2),
                  dict(scheduler=f"tcp://127.0.0.1:{unused_port()}")):
        with pytest.raises(error, match=message):
            sweep.run_sweep(pts, progress=lambda d, t: calls.append(d), **where)
    assert calls == []  # not one point ran (and the unreachable scheduler was never asked)


def test_the_refusal_is_simulate_scatters_own(points):
    p = dict(points[1], dx_um=0.5, patch_over_T=None)  # theta_s = 20, phi_s = 90: too coarse
    with pytest.raises(rs.InvalidArgument) as direct:
        rs.simulate_scatter(p.pop("theta_i_deg"), p.pop("theta_s_deg"), p.pop("phi_s_deg"), **p)
    with pytest.raises(rs.InvalidArgument) as swept:
        sweep.run_sweep(bad_points(points, 1, dx_um=0.5, patch_over_T=None), processes=1)
    assert str(swept.value) == f"sweep point 1: {direct.value}"


def test_check_simulate_scatter_accepts_what_runs_and_refuses_what_does_not():
    good = dict(sigma_um=0.05, T_um=1.0, wavelength_um=0.5, realisations=10)
    plans = rs.check_simulate_scatter([30, 45, 10], [0, 0, 10], [0, 0, 0], **good)
    fixed = rs.check_simulate_scatter(30, 0, 0, layout="fixed", **good)
    # The grid announced is the grid the run reports.
    for plan, result in zip(plans + fixed,
                            rs.simulate_scatter([30, 45, 10], [0, 0, 10], [0, 0, 0], **good)
                            ["results"] + rs.simulate_scatter(30, 0, 0, layout="fixed",
                                                              **good)["results"]):
        assert {k: plan[k] for k in ("n", "dx_um", "layout", "lattice_index")} == \
            {k: result[k] for k in ("n", "dx_um", "layout", "lattice_index")}
    assert [p["generated_n"] for p in plans] == [p["n"] for p in plans]
    assert fixed[0]["generated_n"] == 2 * fixed[0]["n"]  # the fixed patch is cut from 2n x 2n
    # A grid that needs more than 4096 points per side: refused by both, nothing generated.
    huge = dict(good, correlation="exponential", sigma_um=30.0, patch_over_T=1e4)
    for f in (rs.check_simulate_scatter, rs.simulate_scatter):
        with pytest.raises(rs.InvalidArgument, match="4096"):
            f(30, 0, 0, **huge)


def test_points_must_be_a_list_of_dicts(points):
    with pytest.raises(TypeError, match="list of dicts"):
        sweep.run_sweep(points[0])
    with pytest.raises(TypeError, match="sweep point 1 is a tuple"):
        sweep.run_sweep([points[0], (30, 0, 0)])
    with pytest.raises(rs.InvalidArgument, match="sweep point 0: key 'phi_s_deg' is missing"):
        sweep.run_sweep([{"theta_i_deg": 30, "theta_s_deg": 0, "sigma_um": 0.05}])


@pytest.mark.parametrize("kwargs,error,message", [
    (dict(processes=0), rs.InvalidArgument, r"processes = 0 .*\[1, 4096\]"),
    (dict(processes=2.0), TypeError, "processes"),
    (dict(threads=-1), rs.InvalidArgument, r"threads = -1 .*\[0, 1024\]"),
    (dict(connect_timeout_s=0), rs.InvalidArgument, "connect_timeout_s"),
    (dict(progress="yes"), TypeError, "progress"),
    (dict(scheduler=42), TypeError, "scheduler"),
])
def test_bad_run_options(points, kwargs, error, message):
    with pytest.raises(error, match=message):
        sweep.run_sweep(points[:2], **kwargs)


def test_an_unreachable_scheduler_is_named_within_the_timeout(points):
    address = f"tcp://127.0.0.1:{unused_port()}"
    start = time.monotonic()
    with pytest.raises(ConnectionError) as info:
        sweep.run_sweep(points[:2], scheduler=address, connect_timeout_s=1)
    assert address in str(info.value)
    assert "dask scheduler" in str(info.value)
    assert time.monotonic() - start < 30


# --- interruption ------------------------------------------------------------------------------

def interrupt_after_first(done, total):
    raise KeyboardInterrupt


@pytest.mark.parametrize("where", ["serial", "processes"])
def test_ctrl_c_stops_the_sweep_and_is_reraised(points, where):
    many = sweep.grid(**dict(GRID, realisations=50))
    with pytest.raises(KeyboardInterrupt):
        sweep.run_sweep(many, processes=1 if where == "serial" else 2,
                        progress=interrupt_after_first)


def test_ctrl_c_cancels_the_pending_dask_tasks(cluster):
    many = sweep.grid(**dict(GRID, realisations=200, seed=11))
    with distributed.Client(cluster, set_as_default=False) as client:
        # `info` keeps the traceback, and with it run_sweep's futures, alive: the tasks leave the
        # scheduler only because run_sweep cancelled them.
        with pytest.raises(KeyboardInterrupt) as info:
            sweep.run_sweep(many, scheduler=client, progress=interrupt_after_first)
        assert info.tb is not None
        deadline = time.monotonic() + 20
        left = None
        while time.monotonic() < deadline:
            left = client.run_on_scheduler(lambda dask_scheduler: len(dask_scheduler.tasks))
            if left == 0:
                break
            time.sleep(0.1)
        assert left == 0, f"{left} tasks still on the scheduler after the interrupt"


# --- simulate_scatter options the sweeps rely on -----------------------------------------------

def test_simulate_scatter_takes_seeds_over_the_whole_64_bit_range():
    small = dict(sigma_um=0.05, T_um=1.0, wavelength_um=0.5, realisations=10, n=16)
    diffuse = {}
    for seed in (2**63 - 1, 2**63, 2**64 - 1):
        doc = rs.simulate_scatter(30, 0, 0, seed=seed, **small)
        assert doc["options"]["seed"] == seed
        diffuse[seed] = doc["results"][0]["diffuse"]
    assert len(set(diffuse.values())) == 3  # 2^63 is not folded onto 2^63 - 1 or 0
    assert rs.simulate_scatter(30, 0, 0, seed=np.uint64(2**64 - 1), **small)["results"][0][
        "diffuse"] == diffuse[2**64 - 1]
    for seed in (2**64, -1):
        with pytest.raises(rs.InvalidArgument, match="seed"):
            rs.simulate_scatter(30, 0, 0, seed=seed, **small)


@pytest.mark.parametrize("key,value", [("realisations", 4.0), ("seed", 1.5), ("threads", True),
                                       ("n", 16.0), ("sigma_um", "0.05"), ("sigma_um", None)])
def test_simulate_scatter_option_types(key, value):
    options = dict(sigma_um=0.05, T_um=1.0, wavelength_um=0.5, realisations=10)
    options[key] = value
    for f in (rs.simulate_scatter, rs.check_simulate_scatter):
        with pytest.raises(TypeError, match=key):
            f(30, 0, 0, **options)
