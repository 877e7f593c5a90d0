"""The surface functions of the Python module: NumPy arrays in and out, the statistics dict equal
to the CLI's JSON (one serializer), the prediction against the model functions, and errors
(TypeError for non-real input, ValueError subclasses for bad values)."""

import json
import math
import subprocess

import numpy as np
import pytest

import roughscope as rs
from conftest import cli_path


def test_generate_surface_shape_seed_and_truth():
    z = rs.generate_surface(sigma_um=0.5, T_um=8.0, nx=256, ny=128, dx_um=1.0, seed=4)
    assert isinstance(z, np.ndarray) and z.dtype == np.float64 and z.shape == (128, 256)
    assert np.array_equal(z, rs.generate_surface(sigma_um=0.5, T_um=8.0, nx=256, ny=128,
                                                 dx_um=1.0, seed=4))
    assert not np.array_equal(z, rs.generate_surface(sigma_um=0.5, T_um=8.0, nx=256, ny=128,
                                                     dx_um=1.0, seed=5))
    stats = rs.surface_statistics(z, 1.0)
    assert abs(stats["sigma_um"] - 0.5) < 0.06
    assert abs(stats["T_um"] - 8.0) < 1.2


def test_generate_surface_rejects():
    with pytest.raises(ValueError, match="sigma"):
        rs.generate_surface(sigma_um=-1.0, nx=8, ny=8)
    with pytest.raises(ValueError, match="nx"):
        rs.generate_surface(nx=0, ny=8)
    with pytest.raises(TypeError, match="nx"):
        rs.generate_surface(nx=8.0, ny=8)


@pytest.mark.parametrize("ext", ["x3p", "gsf"])
def test_write_read_round_trip_keeps_missing_points(tmp_path, ext):
    z = rs.generate_surface(nx=20, ny=10, seed=2).astype(np.float32).astype(np.float64)
    z[3, 4] = np.nan
    path = tmp_path / f"h.{ext}"
    rs.write_height_map(z, 0.5, 0.25, str(path))
    d = rs.read_height_map(str(path))
    assert d["heights_um"].shape == (10, 20)
    assert (d["nx"], d["ny"], d["dx_um"], d["dy_um"]) == (20, 10, 0.5, 0.25)
    assert d["format"] == ext and d["missing"] == 1
    assert np.isnan(d["heights_um"][3, 4])
    assert d["heights_um"].tobytes() == z.tobytes()


def test_write_height_map_rejects(tmp_path):
    with pytest.raises(ValueError, match="dimensions"):
        rs.write_height_map(np.zeros((2, 2, 2)), 1.0, 1.0, str(tmp_path / "a.x3p"))
    with pytest.raises(ValueError):
        rs.write_height_map(np.zeros((4, 4)), -1.0, 1.0, str(tmp_path / "b.x3p"))
    with pytest.raises(TypeError, match="heights_um"):
        rs.write_height_map(np.zeros((4, 4), complex), 1.0, 1.0, str(tmp_path / "c.x3p"))
    assert not list(tmp_path.iterdir())


def test_read_height_map_rejects(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # a short name in the message
    with pytest.raises(rs.DataError, match="none.x3p"):
        rs.read_height_map("none.x3p")
    with pytest.raises(TypeError, match="dx_um"):
        rs.read_height_map(str(tmp_path / "none.x3p"), dx_um="1")


def test_statistics_dict_equals_the_cli_json(tmp_path):
    path = tmp_path / "s.x3p"
    z = rs.generate_surface(sigma_um=0.3, T_um=5.0, nx=128, ny=64, dx_um=0.5, seed=9)
    rs.write_height_map(z, 0.5, 0.5, str(path))
    for options, flags in (({}, []),
                           (dict(level="line", cutoff_um=20.0, acf="biased"),
                            ["--level", "line", "--cutoff-um", "20", "--acf", "biased"])):
        cli = json.loads(subprocess.run([cli_path(), "surface", "stats", str(path), "--json",
                                         *flags], capture_output=True, text=True,
                                        check=True).stdout)
        assert cli.pop("roughscope_version") == rs.__version__  # the CLI's documents carry it
        py = rs.surface_statistics(rs.read_height_map(str(path))["heights_um"], 0.5, 0.5,
                                   **options)
        assert list(py) == list(cli)
        assert py["file"] is None and py["format"] is None
        for key in cli:
            if key not in ("file", "format"):
                assert py[key] == cli[key], key


def test_statistics_profile_and_curves():
    z = rs.generate_surface(nx=2048, ny=1, T_um=4.0, seed=3)
    assert z.shape == (1, 2048)
    stats = rs.surface_statistics(z[0], 1.0, curves=True)
    assert stats["ny"] == 1 and stats["T_y_um"] is None
    acf = stats["curves"]["acf_x"]
    assert acf["acf"][0] == pytest.approx(1.0)
    assert len(acf["lag_um"]) == len(acf["acf"]) > 10


def test_statistics_rejects():
    z = rs.generate_surface(nx=32, ny=32)
    with pytest.raises(ValueError, match="order"):
        rs.surface_statistics(z, 1.0, order=2)  # needs level='polynomial'
    with pytest.raises(ValueError, match="order"):
        rs.surface_statistics(z, 1.0, level="polynomial", order=4)
    with pytest.raises(ValueError):
        rs.surface_statistics(z, 1.0, level="sideways")
    with pytest.raises(ValueError):
        rs.surface_statistics(np.full((4, 4), np.nan), 1.0)
    with pytest.raises(TypeError, match="heights_um"):
        rs.surface_statistics(z.astype(object), 1.0)


def test_predict_brightness_given_and_from_statistics():
    ti, ts, ps = np.array([10.0, 30.0, 50.0]), 0.0, 0.0
    d = rs.predict_brightness(ti, ts, ps, sigma_um=0.1, T_um=2.0)
    ref = rs.mean_scattered_power(ti, ts, ps, 0.1, 2.0)
    assert [p["brightness"] for p in d["points"]] == list(ref["brightness"])
    assert d["g_normal"] == pytest.approx((4 * math.pi * 0.1 / 0.555) ** 2, rel=1e-12)
    assert d["theta_K_deg"] == pytest.approx(rs.caron_theta_K_deg(0.05), rel=1e-12)
    vr = rs.very_rough_brightness(ti, ts, ps, 0.05)
    assert [p["very_rough_brightness"] for p in d["points"]] == pytest.approx(list(vr),
                                                                             rel=1e-15)
    stats = {"sigma_um": 0.1, "T_um": 2.0, "T_fit_gaussian_um": None,
             "T_fit_exponential_um": None, "correlation": "exponential"}
    e = rs.predict_brightness(ti, ts, ps, statistics=stats)
    assert e["correlation"] == "exponential" and e["T_source"] == "T_um"
    assert e["source"] == "statistics"


def test_predict_brightness_rejects():
    with pytest.raises(ValueError, match="sigma_um"):
        rs.predict_brightness(10.0, 0.0, 0.0, T_um=2.0)
    with pytest.raises(ValueError, match="not both"):
        rs.predict_brightness(10.0, 0.0, 0.0, sigma_um=1.0, T_um=2.0,
                              statistics={"sigma_um": 1.0, "T_um": 2.0})
    with pytest.raises(ValueError, match="theta_i"):
        rs.predict_brightness(95.0, 0.0, 0.0, sigma_um=1.0, T_um=2.0)
    with pytest.raises(ValueError, match="broadcast"):
        rs.predict_brightness([1.0, 2.0], [1.0, 2.0, 3.0], 0.0, sigma_um=1.0, T_um=2.0)
    with pytest.raises(TypeError, match="statistics"):
        rs.predict_brightness(10.0, 0.0, 0.0, statistics=[1.0])


def test_figure_from_python(tmp_path):
    pytest.importorskip("matplotlib")
    from roughscope import surface_figures

    z = rs.generate_surface(nx=64, ny=64, T_um=4.0, seed=1)
    doc = surface_figures.document(z, 1.0)
    out = surface_figures.stats_figure(doc, tmp_path / "f.png")
    assert open(out, "rb").read(8) == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(ValueError, match="curves"):
        surface_figures.stats_figure(rs.surface_statistics(z, 1.0), tmp_path / "g.png")
    assert not (tmp_path / "g.png").exists()
