"""Strict types at the Python boundary (docs/python.md, "Types").

Every public callable of ``roughscope`` and ``roughscope._core`` is enumerated by introspection
and must have a known-good call in ``GOOD_CALLS`` (a new public function without one fails
``test_every_public_callable_has_a_known_good_call``, so the coverage cannot silently shrink).
From each good call, every numeric argument is replaced in turn by each non-real value (bool,
NumPy bool, str, bytes, complex, complex arrays, datetime64, timedelta64, object arrays, None where
a number is required): the call must raise TypeError whose message names the argument. Also: an
impossible broadcast raises MemoryError before allocating, and every error the module raises for
a bad *value* is a ValueError subclass (roughscope.Error).
"""

import inspect
import re
import tempfile

import numpy as np
import pytest

import roughscope as rs
from roughscope import _core

from conftest import CURET_DIR


class Lobes(list):
    """Marks the Lafortune lobes (a list of dicts) as a numeric argument."""


# Geometries of the good calls: four directions, the first two with the viewer on the normal.
TI = np.array([20.0, 50.0, 30.0, 40.0])
PI = np.array([0.0, 0.0, 10.0, 200.0])
TS = np.array([0.0, 0.0, 25.0, 35.0])
PS = np.array([0.0, 0.0, 30.0, 170.0])
BRIGHTNESS = rs.very_rough_brightness(TI, TS, PS, 0.4)
_CSV = tempfile.NamedTemporaryFile("w", suffix=".csv", delete=False)
_CSV.write("theta_i,phi_i,theta_s,phi_s,value\n"
           + "".join(f"{a},{b},{c},{d},{v}\n" for a, b, c, d, v in
                     zip(TI, PI, TS, (PS + PI + 180.0) % 360.0, BRIGHTNESS / np.cos(np.radians(TI)))))
_CSV.close()
TABLE_CSV = _CSV.name
HEIGHTS = np.random.default_rng(1).normal(size=(16, 16))
_HEIGHT_DIR = tempfile.mkdtemp(prefix="roughscope-inputs-")
HEIGHT_FILE = _HEIGHT_DIR + "/h.x3p"
rs.write_height_map(HEIGHTS, 1.0, 1.0, HEIGHT_FILE)
# Two small 16-bit captures (30°, 45°) and their capture file, for the image functions.
for _k, _theta in enumerate((30.0, 45.0)):
    _core.write_capture(_HEIGHT_DIR, "png", f"cap{_k}", width=24, height=24, theta_i_deg=_theta,
                        bits=16, sigma_over_T=0.3, keep_geometry=False, seed=5 + _k)
CAPTURE_FILE = _HEIGHT_DIR + "/capture-file.json"
with open(CAPTURE_FILE, "w", encoding="utf-8") as _f:
    _f.write('{"response": "linear", "black_level_dn": 64, "roi": {"rect": [4, 4, 16, 16]}, '
             '"captures": [{"image": "cap0.png", "theta_i_deg": 30, "exposure_s": 1}, '
             '{"image": "cap1.png", "theta_i_deg": 45, "exposure_s": 1}]}')
IMAGE_VALUES = np.random.default_rng(2).uniform(0.2, 0.3, size=(3, 12, 12))
IMAGE_MASK = np.ones((12, 12), dtype=bool)
# A mirror sphere of circle (16, 16, 12) with its highlight up and right of the centre.
_YY, _XX = np.mgrid[0:32, 0:32] + 0.5
MIRROR_SPHERE = np.where((_XX - 16) ** 2 + (_YY - 16) ** 2 < 144,
                         0.02 + 0.9 * np.exp(-((_XX - 18) ** 2 + (_YY - 14) ** 2) / 2.0), 0.005)
# Four grey images of a Lambertian ramp under four lights, for photometric_stereo.
PS_LIGHTS = np.array([[0.5, 0.0, 0.75 ** 0.5], [0.0, 0.5, 0.75 ** 0.5], [-0.5, 0.0, 0.75 ** 0.5],
                      [0.0, -0.5, 0.75 ** 0.5]])
PS_IMAGES = [0.5 * np.clip(np.full((8, 8), 0.2) * L[0] + L[2], 0, None) for L in PS_LIGHTS]
LOBES = Lobes([{"Cx": -1.0, "Cy": -1.0, "Cz": 1.0, "n": 10.0, "albedo": 0.5}])
COMPARISON_OPTIONS = dict(theta1_deg=20.0, theta2_deg=50.0, pair=(1, 2), on_sigma_rad=0.2,
                          on_albedo=0.5, fits=False)

# name -> list of (args, kwargs): calls that succeed. Functions of CuretDatabase are under
# "CuretDatabase.<method>" and called on the loaded database.
GOOD_CALLS = {
    "acf_model": [((TI, 2.0), dict(correlation="gaussian"))],
    "brdf_compare_arrays": [((TI, PI, TS, PS, BRIGHTNESS),
                             dict(weight=np.ones(4), **COMPARISON_OPTIONS))],
    "brdf_compare_csv": [((TABLE_CSV,), COMPARISON_OPTIONS)],
    "brdf_read_csv": [((TABLE_CSV,), {})],
    # The image as read_image's dict (a str would be a path: a DataError, not a TypeError).
    "calibrate_light": [(({"values": MIRROR_SPHERE[None]},),
                         dict(circle=(16.0, 16.0, 12.0), view=(0.0, 0.0, 1.0),
                              circle_uncertainty_px=0.5, gamma=2.2))],
    "caron_theta_K_deg": [((0.5,), {})],
    "caron_xi_K": [((0.5,), {})],
    "coherent_power": [((0.9, 0.5), {})],
    "compare_correlations": [((TI, TS, PS, BRIGHTNESS),
                              dict(weight=np.ones(4), wavelength_um=0.555, loss_scale=0.05))],
    "comparison_error_measures": [(([1.0, 0.5, 0.2], [1.0, 0.6, 0.1]),
                                   dict(weights=[1.0, 1.0, 2.0]))],
    "format_uncertain": [((0.29991, 0.00025), dict(digits=4))],
    "correlation_length_from_ratio": [((1.5, 0.05, 10.0, 40.0), dict(wavelength_um=0.555))],
    "correlation_length_two_geometries": [((1.5, 0.05, 10.0, 0.0, 0.0, 40.0, 0.0, 0.0),
                                           dict(wavelength_um=0.555))],
    "curet_data_dir": [((), {})],
    "curet_find_directory": [((), {})],
    "curet_load": [((), {})],
    "curet_paper_oren_nayar": [((25,), {})],
    "curet_sample_name": [((25,), {})],
    "deg_to_rad": [((30.0,), {})],
    "diffuse_power_exponential_series": [((0.8, 10.0, 1e4, 2.0, 0.01), {})],
    "diffuse_power_gaussian_series": [((0.8, 10.0, 1e4, 2.0, 0.01), {})],
    "diffuse_power_quadrature": [(("gaussian", 0.8, 10.0, 1e4, 2.0, 0.01), {})],
    "diffuse_power_slightly_rough_exponential": [((0.8, 10.0, 1e4, 0.1, 0.01), {})],
    "diffuse_power_slightly_rough_gaussian": [((0.8, 10.0, 1e4, 0.1, 0.01), {})],
    "diffuse_power_very_rough_exponential": [((0.8, 2.0, 10.0, 1e4, 100.0, 0.01), {})],
    "diffuse_power_very_rough_exponential_series_limit": [((0.8, 10.0, 1e4, 50.0, 0.01), {})],
    "diffuse_power_very_rough_gaussian": [((0.8, 2.0, 10.0, 1e4, 100.0, 0.01), {})],
    "estimate_correlation_length": [((1.5, 0.05, 10.0, 40.0),
                                     dict(sigma_um_stderr=0.001, wavelength_um=0.555, noise=0.01,
                                          theta_s1_deg=0.0, phi_s1_deg=0.0, theta_s2_deg=0.0,
                                          phi_s2_deg=0.0))],
    "estimate_sigma_specular": [((), dict(R_spec=0.5, theta_deg=10.0, wavelength_um=0.555,
                                          R0=1.0, noise=0.01)),
                                ((), dict(E_tot=2.0, E_dif=1.0, theta_deg=10.0))],
    "estimate_slope": [((1.5, 10.0, 40.0),
                        dict(noise=0.01, sigma_um=2.0, wavelength_um=0.555, theta_s1_deg=0.0,
                             phi_s1_deg=0.0, theta_s2_deg=0.0, phi_s2_deg=0.0))],
    "exponential_series_sum": [((2.0, 0.5), {})],
    "find_shared": [(("reference",), {})],
    "fit_roughness": [((TI, TS, PS, BRIGHTNESS),
                       dict(weight=np.ones(4), wavelength_um=0.555, loss_scale=0.05,
                            initial_sigma_over_T=0.5, sigma_over_T_bounds=(0.01, 10.0),
                            max_iterations=50))],
    "gaussian_series_sum": [((2.0, 0.5), {})],
    "generate_surface": [((), dict(sigma_um=1.0, T_um=4.0, nx=32, ny=16, dx_um=1.0, dy_um=0.5,
                                   seed=2))],
    "geometric_factor_beckmann": [((TI, TS, PS), {})],
    "geometric_factor_squared": [(("vh", TI, TS, PS), {})],
    "geometry_from_two_azimuths": [((TI, PI, TS, PS), {})],
    "geometry_from_vectors": [(([0.0, 0.0, 1.0], [0.5, 0.0, 0.866025403784], [0.0, 0.0, 1.0]),
                               dict(unit_tolerance=1e-6))],
    "lafortune_brdf": [((TI, TS, PS, LOBES), dict(rho_d=0.1))],
    "lafortune_diffuse_brightness": [((TI, TS, PS, 2.0), {})],
    "lambert_brightness": [((TI,), {})],
    "mean_scattered_power": [((TI, TS, PS, 0.1, 2.0),
                              dict(wavelength_um=0.555, patch_x_um=500.0, patch_y_um=500.0,
                                   auto_tolerance=1e-8))],
    "oren_nayar_qualitative_radiance": [((TI, TS, PS, 0.3), dict(albedo=0.8))],
    "oren_nayar_radiance": [((TI, TS, PS, 0.3), dict(albedo=0.8))],
    "paper_tables_path": [((), {})],
    "predict_brightness": [((TI, TS, PS), dict(sigma_um=0.1, T_um=2.0, wavelength_um=0.555))],
    "rad_to_deg": [((0.5,), {})],
    "check_simulate_scatter": [((TI, TS, PS), dict(sigma_um=0.05, T_um=1.0, wavelength_um=0.5,
                                                   n=16, realisations=10, seed=2))],
    "read_height_map": [((HEIGHT_FILE,), dict(dx_um=1.0, dy_um=1.0, z_scale_um=1.0))],
    "ratio_range_correlation_length": [((0.05, 10.0, 40.0), dict(wavelength_um=0.555))],
    "ratio_range_exponential": [((10.0, 40.0), {})],
    "ratio_range_gaussian": [((10.0, 40.0), {})],
    "recompute_paper_tables": [(("PAPER_TABLES",), {})],
    "retro_beckmann_exponential_very_rough": [((30.0, 0.5), {})],
    "retro_beckmann_gaussian_very_rough": [((30.0, 0.5), {})],
    "retro_vh_exponential_very_rough": [((30.0, 0.5), {})],
    "retro_vh_gaussian_slightly_rough": [((30.0, 0.05, 2.0), dict(wavelength_um=0.555))],
    "retro_vh_gaussian_very_rough": [((30.0, 0.5), {})],
    "rms_slope": [((0.5,), {})],
    "roughness_class": [((2.0,), {})],
    "roughness_g": [((TI, TS, 0.1), dict(wavelength_um=0.555))],
    "scattering_vector": [((TI, TS, PS), dict(wavelength_um=0.555))],
    "shared_data_required": [((), {})],
    "shared_dir_candidates": [((), {})],
    "shared_search_description": [(("data/curet",), {})],
    "srgb_encode": [(([0.0, 0.002, 0.5, 1.0],), {})],
    "sigma_from_specular": [((0.5, 10.0), dict(wavelength_um=0.555, R0=1.0))],
    "photometric_stereo": [((PS_IMAGES, PS_LIGHTS),
                            dict(light_intensities=[1.0, 1.0, 1.0, 1.0], shadow_fraction=0.05,
                                 highlight_fraction=0.1, gamma=2.2, threads=1))],
    "plan_capture": [((0.5,), dict(sigma_over_T_max=0.6, noise_rel=0.002, fill=0.8,
                                   theta_min_deg=20.0, theta_max_deg=60.0, theta_step_deg=10.0,
                                   min_difference_deg=5.0, range_points=2, top=3))],
    "read_image": [((_HEIGHT_DIR + "/cap0.png",), dict(response="gamma", gamma=2.2,
                                                         black_level_dn=64.0))],
    "region_mask": [(({"circle": [6.0, 6.0, 4.0]}, 12, 12), {})],
    "region_statistics": [((IMAGE_VALUES, IMAGE_MASK), dict(tile_size_px=4,
                                                            max_excluded_fraction=0.5))],
    "measure": [((CAPTURE_FILE,), {})],
    "render_capture": [((), dict(scene="sphere", width=9, height=7, theta_i_deg=30.0,
                                 theta_v_deg=10.0, sigma_over_T=0.3, T_um=5.0, bits=12, gain=0.25,
                                 black_level=64.0, read_noise_e=2.0, vignetting=0.1, seed=3))],
    "write_capture": [((_HEIGHT_DIR,), dict(width=5, height=4, theta_i_deg=20.0,
                                            electrons_per_unit_s=1000.0, seed=2))],
    "sigma_over_T_exponential": [((1.5, 10.0, 40.0), {})],
    "sigma_over_T_gaussian": [((1.5, 10.0, 40.0), {})],
    "sigma_over_T_two_geometries": [((1.5, 10.0, 0.0, 0.0, 40.0, 0.0, 0.0), {})],
    "specular_amplitude_rho0": [((0.01, 0.02), dict(patch_x_um=500.0, patch_y_um=500.0))],
    "specular_reflectance_from_brightness": [((2.0, 1.0), {})],
    "scattering_integral_at": [((HEIGHTS, 1.0, 0.1, 0.2, -3.0), dict(dy_um=1.0))],
    "scattering_integral_lattice": [((HEIGHTS, 1.0, -3.0), dict(dy_um=1.0))],
    "simulate_scatter": [((TI, TS, PS), dict(sigma_um=0.05, T_um=1.0, wavelength_um=0.5, n=16,
                                             realisations=10, seed=2))],
    "surface_statistics": [((HEIGHTS, 1.0, 1.0), dict(cutoff_um=8.0))],
    "very_rough_brightness": [((TI, TS, PS, 0.4), {})],
    "write_height_map": [((HEIGHTS, 1.0, 1.0, _HEIGHT_DIR + "/w.x3p"), dict(z_scale_um=1.0))],
    "CuretDatabase.compare": [((25,), dict(theta1_deg=45.0, theta2_deg=67.5, pair=(81, 112),
                                           on_sigma_rad=0.2, on_albedo=0.5, max_overflow=1.0,
                                           fits=False, series=False))],
    "CuretDatabase.compare_all": [((), dict(fits=False, max_overflow=1.0, threads=1,
                                            format="csv"))],
    "CuretDatabase.sample_table": [((25,), {})],
}

NEEDS_CURET = {"curet_find_directory", "curet_load"}
NEEDS_PAPER_TABLES = {"recompute_paper_tables"}

# Non-real values and what they stand for.
BAD_VALUES = {
    "bool": True,
    "numpy_bool": np.bool_(False),
    "numpy_bool_array": np.array([True, False]),
    "str": "1.5",
    "bytes": b"1.5",
    "complex": 1.0 + 2.0j,
    "complex_array": np.array([1.0 + 2.0j, 3.0 + 0.0j]),
    "datetime64": np.datetime64("2020-01-01"),
    "timedelta64": np.timedelta64(5, "s"),
    "datetime64_array": np.array(["2020-01-01", "2021-01-01"], dtype="datetime64[D]"),
    "object_array": np.array([1.0, 2.0], dtype=object),
    "none": None,
}


def public_callables():
    """Every public function of roughscope and roughscope._core, and CuretDatabase's methods."""
    names = set()
    for module in (rs, _core):
        for name in dir(module):
            obj = getattr(module, name)
            if name.startswith("_") or inspect.isclass(obj) or inspect.ismodule(obj):
                continue
            if callable(obj):
                names.add(name)
    for name, member in vars(_core.CuretDatabase).items():
        if not name.startswith("_") and callable(member):
            names.add(f"CuretDatabase.{name}")
    return sorted(names)


def is_numeric(value):
    if isinstance(value, Lobes):
        return True
    if isinstance(value, bool) or isinstance(value, str):
        return False
    if isinstance(value, (int, float)):
        return True
    if isinstance(value, np.ndarray):
        return value.dtype.kind in "iuf"
    if isinstance(value, (list, tuple)) and value:
        return all(is_numeric(v) for v in value)
    return False


def none_is_accepted(function, name):
    """Whether the argument's default is None (None then means "not given", not a bad number)."""
    try:
        parameter = inspect.signature(function).parameters.get(name)
        if parameter is not None:
            return parameter.default is None
    except (TypeError, ValueError):
        pass
    doc = (function.__doc__ or "").split("\n")[0]
    return re.search(rf"\b{re.escape(name)}: [^,=)]+ = None\b", doc) is not None


@pytest.fixture(scope="module")
def curet_db():
    if CURET_DIR is None:
        return None
    return rs.curet_load(str(CURET_DIR))


def resolve(name, curet_db, request):
    if name.startswith("CuretDatabase.") or name in NEEDS_CURET:
        if curet_db is None:
            request.getfixturevalue("curet_dir")  # skips (or fails) with the reason
    if name.startswith("CuretDatabase."):
        return getattr(curet_db, name.split(".", 1)[1])
    return getattr(rs, name, None) or getattr(_core, name)


def materialise(name, args, request):
    if name in NEEDS_PAPER_TABLES:
        import json
        with open(request.getfixturevalue("paper_tables_path"), encoding="utf-8") as f:
            return (json.load(f),) + tuple(args[1:])
    return args


def numeric_cases():
    """(function name, call index, argument (position or keyword), bad value name)."""
    cases = []
    for name, calls in sorted(GOOD_CALLS.items()):
        for k, (args, kwargs) in enumerate(calls):
            arguments = [(i, v) for i, v in enumerate(args)] + sorted(kwargs.items())
            for where, value in arguments:
                if not is_numeric(value):
                    continue
                for bad in BAD_VALUES:
                    cases.append(pytest.param(name, k, where, bad,
                                              id=f"{name}[{k}]-{where}-{bad}"))
    return cases


def argument_name(function, name, where):
    """The Python name of a positional argument (from the signature), or the keyword itself."""
    if isinstance(where, str):
        return where
    try:
        return list(inspect.signature(function).parameters)[where]
    except (TypeError, ValueError):
        doc = (function.__doc__ or "").split("\n")[0]
        inner = doc[doc.index("(") + 1:]
        names = re.findall(r"(?:^|, )(?:\*, )?(\w+):", inner)
        return [n for n in names if n != "self"][where]


# ---------------------------------------------------------------------------------------------

def test_every_public_callable_has_a_known_good_call():
    missing = [n for n in public_callables() if n not in GOOD_CALLS]
    assert not missing, (f"public callables without a known-good call in GOOD_CALLS of "
                         f"{__file__}: {missing}; add one so that their numeric arguments are "
                         f"tested")
    stale = [n for n in GOOD_CALLS if n not in public_callables()]
    assert not stale, f"GOOD_CALLS lists names that are not public callables: {stale}"


@pytest.mark.parametrize("name", sorted(GOOD_CALLS))
def test_known_good_calls_succeed(name, curet_db, request):
    function = resolve(name, curet_db, request)
    for args, kwargs in GOOD_CALLS[name]:
        function(*materialise(name, args, request), **kwargs)


@pytest.mark.parametrize("name,k,where,bad", numeric_cases())
def test_non_real_input_raises_type_error_naming_the_argument(name, k, where, bad, curet_db,
                                                              request):
    function = resolve(name, curet_db, request)
    args, kwargs = GOOD_CALLS[name][k]
    args = list(materialise(name, args, request))
    arg_name = argument_name(function, name, where)
    if bad == "none" and none_is_accepted(function, arg_name):
        pytest.skip(f"{arg_name}=None means 'not given' for {name}")
    value = BAD_VALUES[bad]
    if isinstance(where, str):
        kwargs = dict(kwargs, **{where: value})
    else:
        args[where] = value
    with pytest.raises(TypeError) as info:
        function(*args, **kwargs)
    message = str(info.value)
    assert arg_name in message, f"the TypeError does not name {arg_name}: {message}"
    assert "incompatible function arguments" not in message, message
    assert "real number" in message or "integer" in message or "measurement numbers" in message \
        or "unsupported type" in message, message


def test_the_imaginary_part_is_never_dropped():
    # Before: complex arrays were cast to float silently (the imaginary part lost).
    with pytest.raises(TypeError, match="theta_i_deg"):
        rs.lambert_brightness(np.array([10.0 + 5.0j]))
    with pytest.raises(TypeError, match="ratio"):
        rs.sigma_over_T_gaussian(np.array([1.5 + 0.1j]), 10.0, 40.0)


def test_real_inputs_of_every_kind_are_accepted():
    expected = rs.lambert_brightness(30.0)
    for value in (30, 30.0, np.float32(30.0), np.int16(30), np.uint8(30), np.array(30.0),
                  np.array([30], dtype=np.int64), [30.0], (30,)):
        out = rs.lambert_brightness(value)
        assert np.allclose(out, expected), value


def test_a_float64_array_is_not_copied_into_a_type_check():
    # The fast path: a C-contiguous float64 array goes straight to the kernel.
    x = np.linspace(0.0, 80.0, 1000)
    out = rs.lambert_brightness(x)
    assert out.dtype == np.float64 and out.shape == x.shape
    assert np.allclose(out, np.cos(np.radians(x)), rtol=1e-14, atol=0.0)


# ---------------------------------------------------------------------------------------------
# Impossible allocations

@pytest.mark.parametrize("call", [
    lambda a, b: rs.very_rough_brightness(a, b, 0.0, 0.5),
    lambda a, b: rs.lambert_brightness(a + b),
    lambda a, b: rs.sigma_over_T_gaussian(1.5, a + 10.0, b + 40.0),
    lambda a, b: rs.sigma_over_T_gaussian(1.5 + 0.0 * a, 10.0, b + 40.0),
], ids=["core-broadcast", "numpy-then-core", "estimation-numpy", "estimation-broadcast"])
def test_an_impossible_broadcast_is_a_memory_error_before_allocating(call):
    # (100000, 1) with (1, 100000): 1e10 float64 values, 75 GiB for one result array.
    a = np.zeros((100000, 1))
    b = np.zeros((1, 100000))
    try:
        call(a, b)
    except MemoryError as e:
        assert "GiB" in str(e) or str(e) == "" or "memory" in str(e).lower(), str(e)
    else:  # pragma: no cover
        pytest.fail("no MemoryError")


def test_the_broadcast_memory_error_names_the_shape():
    with pytest.raises(MemoryError, match=r"\(100000, 100000\).*GiB"):
        rs.very_rough_brightness(np.zeros((100000, 1)), np.zeros((1, 100000)), 0.0, 0.5)
    with pytest.raises(MemoryError, match=r"\(100000, 100000\).*GiB"):
        rs.sigma_over_T_gaussian(1.5, np.zeros((100000, 1)) + 10.0, np.zeros((1, 100000)) + 40.0)


# ---------------------------------------------------------------------------------------------
# Error hierarchy: every library error is a ValueError

def test_error_classes_are_value_errors():
    assert issubclass(rs.Error, ValueError)
    for cls in (rs.InvalidArgument, rs.NoSolution, rs.DataError):
        assert issubclass(cls, rs.Error)
    assert rs.Error.__module__ == "roughscope"


def test_a_malformed_lafortune_lobe_is_a_value_error():
    for lobes in ([{"Cx": [1.0, 2.0]}],                      # an array where a number goes
                  [{"Cx": -1.0, "speed": 2.0}],             # an unknown key
                  [[1.0, 2.0, 3.0]],                        # a row that is not (Cx, Cy, Cz, n, albedo)
                  [{"Cx": -1.0}, [1.0, 2.0, 3.0, 4.0, 5.0]],  # dicts and rows mixed
                  np.zeros((2, 4))):
        with pytest.raises(ValueError) as info:
            rs.lafortune_brdf(30.0, 30.0, 0.0, lobes)
        assert isinstance(info.value, rs.Error), type(info.value)
        assert "lobes" in str(info.value)
    with pytest.raises(TypeError, match=r"lobes\[0\]\['n'\]"):
        rs.lafortune_brdf(30.0, 30.0, 0.0, [{"n": "ten"}])
    with pytest.raises(TypeError, match=r"lobes\[0\]\['Cx'\]"):  # one dict is one lobe
        rs.lafortune_brdf(30.0, 30.0, 0.0, {"Cx": "x"})
    one = {"Cx": -1.0, "Cy": -1.0, "Cz": 1.0, "n": 10.0, "albedo": 0.5}
    assert rs.lafortune_brdf(30.0, 30.0, 0.0, one) == rs.lafortune_brdf(30.0, 30.0, 0.0, [one])


BAD_REAL_VALUES = {"nan": float("nan"), "inf": float("inf"), "-inf": float("-inf"),
                   "huge": 1e308, "-huge": -1e308, "negative": -1.0, "zero": 0.0,
                   "tiny": 1e-320}


def value_cases():
    cases = []
    for name, calls in sorted(GOOD_CALLS.items()):
        if name.startswith("CuretDatabase.compare_all"):
            continue  # 61 samples per call: covered by compare
        if name == "diffuse_power_quadrature":
            continue  # its domain outside g <~ 1e3 is checked by the quadrature's own tests
        args, kwargs = calls[0]
        arguments = [(i, v) for i, v in enumerate(args)] + sorted(kwargs.items())
        for where, value in arguments:
            if not is_numeric(value) or isinstance(value, Lobes):
                continue
            for bad in BAD_REAL_VALUES:
                cases.append(pytest.param(name, where, bad, id=f"{name}-{where}-{bad}"))
    return cases


@pytest.mark.parametrize("name,where,bad", value_cases())
def test_every_error_for_a_bad_value_is_a_value_error(name, where, bad, curet_db, request):
    function = resolve(name, curet_db, request)
    args, kwargs = GOOD_CALLS[name][0]
    args = list(materialise(name, args, request))
    value = BAD_REAL_VALUES[bad]
    original = kwargs[where] if isinstance(where, str) else args[where]
    if isinstance(original, (list, tuple)) or (isinstance(original, np.ndarray)
                                               and original.ndim > 0):
        value = np.full(np.shape(original), value)
    if isinstance(original, (int, np.integer)) and not isinstance(original, bool) \
            and not np.isfinite(value if np.ndim(value) == 0 else value.flat[0]):
        pytest.skip("an integer argument cannot be non-finite")
    if isinstance(where, str):
        kwargs = dict(kwargs, **{where: value})
    else:
        args[where] = value
    try:
        function(*args, **kwargs)
    except ValueError as e:
        assert isinstance(e, rs.Error), f"{type(e).__name__} is not a roughscope.Error: {e}"
        assert str(e), "empty message"
    except TypeError as e:
        # An integer argument given a float is a type error, not a value error.
        assert isinstance(original, (int, tuple)) and "integer" in str(e), str(e)
