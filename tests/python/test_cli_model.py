"""Tests of the command-line front end: `roughscope --version/--help` and `roughscope model`.

Every numeric check compares the CLI output with a value computed here independently from the
paper's equations (Ragheb & Hancock 2007, Eq. 1-10) with Python's math module, never with the
library itself. Every success test is paired with bad-input tests asserting the exit code and a
one-line message naming the flag.

The CLI is found through the environment variable ROUGHSCOPE_CLI (ctest sets it); when run by
hand the fallback is build/bin/roughscope in the repository.
"""

import csv
import json
import math
import re
import subprocess

import pytest

from conftest import REPO_ROOT as REPO
from conftest import cli_path

NAN_RE = re.compile(r"\b(nan|inf|infinity)\b", re.IGNORECASE)

# Exit codes documented in docs/cli.md.
EXIT_USAGE, EXIT_NO_SOLUTION, EXIT_DATA = 2, 3, 4


def run(*args, check=True):
    """Runs the CLI; returns the CompletedProcess. With check, asserts exit 0."""
    proc = subprocess.run([cli_path(), *map(str, args)], capture_output=True, text=True,
                          timeout=120)
    assert not NAN_RE.search(proc.stdout), f"NaN/inf printed: {proc.stdout!r}"
    if check:
        assert proc.returncode == 0, f"exit {proc.returncode}: {proc.stderr}"
        assert proc.stderr == "", proc.stderr
    return proc


def run_json(*args):
    return json.loads(run(*args, "--json").stdout)


def assert_usage_error(proc, *needles, code=EXIT_USAGE):
    """One line 'roughscope: error: ...' on stderr naming every needle; nothing on stdout."""
    assert proc.returncode == code, (proc.returncode, proc.stderr)
    lines = proc.stderr.strip("\n").split("\n")
    assert len(lines) == 1, f"expected one line, got: {proc.stderr!r}"
    assert lines[0].startswith("roughscope: error: "), lines[0]
    for needle in needles:
        assert needle in lines[0], f"{needle!r} not in {lines[0]!r}"
    assert proc.stdout == ""


def rel_close(a, b, rel=1e-8):
    return math.isclose(a, b, rel_tol=rel, abs_tol=0.0)


# -------------------------------------------------------------------------------------------
# Independent formulas (paper §3), angles in degrees, lengths in micrometres.

def q_vector(ti_deg, ts_deg, ps_deg):
    """Scattering vector / k (§3.1): (sin ti - sin ts cos ps, -sin ts sin ps, -(cos ti + cos ts))."""
    ti, ts, ps = map(math.radians, (ti_deg, ts_deg, ps_deg))
    return (math.sin(ti) - math.sin(ts) * math.cos(ps), -math.sin(ts) * math.sin(ps),
            -(math.cos(ti) + math.cos(ts)))


def f_beckmann(ti_deg, ts_deg, ps_deg):
    """Eq. 6."""
    ti, ts, ps = map(math.radians, (ti_deg, ts_deg, ps_deg))
    return ((1 + math.cos(ti) * math.cos(ts) - math.sin(ti) * math.sin(ts) * math.cos(ps))
            / (math.cos(ti) * (math.cos(ti) + math.cos(ts))))


def gaussian_series_diffuse(F2, sigma, T, lam, area, ti, ts, ps):
    """Eq. 2 summed term by term (g moderate, so plain summation is accurate)."""
    k = 2 * math.pi / lam
    qx, qy, qz = q_vector(ti, ts, ps)
    g = sigma ** 2 * (k * qz) ** 2
    vxy2 = k ** 2 * (qx ** 2 + qy ** 2)
    total, term = 0.0, 1.0
    for n in range(1, 400):
        term *= g / n  # g^n / n!
        total += term / n * math.exp(-T ** 2 * vxy2 / (4 * n))
    return math.pi * T ** 2 / area * F2 * math.exp(-g) * total, g


# -------------------------------------------------------------------------------------------
# Top level

def project_version():
    text = (REPO / "CMakeLists.txt").read_text()
    m = re.search(r"project\(\s*roughscope\s+VERSION\s+([0-9.]+)", text)
    assert m, "project VERSION not found in CMakeLists.txt"
    return m.group(1)


def test_version_matches_project_version():
    proc = run("--version")
    assert proc.stdout.strip() == f"roughscope {project_version()}"


def test_help_lists_subcommands_and_model_help_lists_flags():
    top = run("--help").stdout
    assert "model" in top and "--version" in top
    model = run("model", "--help").stdout
    for flag in ("--theta-i", "--retro", "--sigma-over-T", "--csv", "--json", "--factor"):
        assert flag in model


def test_no_subcommand_is_a_usage_error():
    proc = run(check=False)
    assert_usage_error(proc, "subcommand")


def test_unknown_flag_is_one_line_usage_error_without_help_dump():
    proc = run("model", "--retro", "30", "--sigma-over-T", "0.5", "--bogus-flag", check=False)
    assert_usage_error(proc, "--bogus-flag")
    proc = run("frobnicate", check=False)
    assert_usage_error(proc, "frobnicate")


# -------------------------------------------------------------------------------------------
# Very-rough forms from sigma/T (Eq. 4, 5 and the retro forms Eq. 7-10)

@pytest.mark.parametrize("theta", [0.0, 10.0, 30.0, 60.0, 80.0])
@pytest.mark.parametrize("m", [0.2, 0.5, 1.8])
def test_retro_vh_gaussian_equals_eq9(theta, m):
    """Eq. 4 at L = V with F_VH: F²/q_z² exp(-q_xy²/(4m²q_z²)) with q_z² = 4cos²θ,
    q_xy² = 4sin²θ, F² = cos θ, which is Eq. 9 / 4: exp(-tan²θ/(4m²))/(4 cos θ)."""
    out = run_json("model", "--retro", theta, "--sigma-over-T", m, "--factor", "vh",
                   "--correlation", "gaussian")
    c, s = math.cos(math.radians(theta)), math.sin(math.radians(theta))
    shape = c / (4 * c * c) * math.exp(-(4 * s * s) / (4 * m * m * 4 * c * c))
    eq9 = math.exp(-math.tan(math.radians(theta)) ** 2 / (4 * m * m)) / c
    assert rel_close(shape, eq9 / 4, 1e-12)  # the Eq. 9 <-> Eq. 4 constant relation
    assert rel_close(out["brightness"], eq9 / 4)
    assert out["regime"] == "very_rough"
    assert out["g"] is None and out["coherent"] is None and out["total"] is None
    assert out["roughness_class"] is None
    # A closed form (Eq. 4) is exact: method closed_form, error bound the number 0 (not a bool).
    assert out["method"] == "closed_form"
    assert type(out["relative_error_bound"]) in (int, float) and out["relative_error_bound"] == 0
    assert out["scale"] == "relative"
    assert out["theta_i_deg"] == theta and out["theta_s_deg"] == theta
    assert out["phi_s_deg"] == 180
    assert out["sigma_over_T"] == m and out["sigma_um"] is None and out["T_um"] is None
    # §3.5: Caron's angle of RMS slope, θK = 90° − atan(√2 σ/T).
    assert rel_close(out["caron_theta_K_deg"], 90 - math.degrees(math.atan(math.sqrt(2) * m)))


@pytest.mark.parametrize("theta", [5.0, 45.0, 75.0])
def test_retro_vh_exponential_equals_eq10(theta):
    m = 0.7
    out = run_json("model", "--retro", theta, "--sigma-over-T", m, "--correlation",
                   "exponential")
    t = math.tan(math.radians(theta))
    eq10 = 1 / (math.cos(math.radians(theta)) * (1 + t * t / (m * m)) ** 1.5)
    assert rel_close(out["brightness"], eq10 / 4)
    assert out["caron_theta_K_deg"] is None  # Caron's θK assumes Gaussian correlation


@pytest.mark.parametrize("theta", [20.0, 50.0])
def test_retro_beckmann_factor_equals_eq7(theta):
    """F_Beck(θ, θ, π) = 1/cos²θ turns the 1/cos θ of Eq. 9 into the 1/cos⁶θ of Eq. 7."""
    m = 0.4
    out = run_json("model", "--retro", theta, "--sigma-over-T", m, "--factor", "beckmann")
    c = math.cos(math.radians(theta))
    eq7 = math.exp(-math.tan(math.radians(theta)) ** 2 / (4 * m * m)) / c ** 6
    assert rel_close(out["brightness"], eq7 / 4)
    assert out["factor"] == "beckmann"


def test_intensity_radiometry_divides_by_cos_theta_s():
    args = ("model", "--theta-i", 30, "--theta-s", 50, "--phi-s", 20, "--sigma-over-T", 0.6)
    radiance = run_json(*args)["brightness"]
    intensity = run_json(*args, "--radiometry", "intensity")["brightness"]
    assert rel_close(intensity, radiance / math.cos(math.radians(50)))


def test_very_rough_general_geometry_against_eq4_shape():
    ti, ts, ps, m = 35.0, 55.0, 120.0, 0.3
    out = run_json("model", "--theta-i", ti, "--theta-s", ts, "--phi-s", ps,
                   "--sigma-over-T", m, "--factor", "ogilvy")
    qx, qy, qz = q_vector(ti, ts, ps)
    F2 = (f_beckmann(ti, ts, ps) * math.cos(math.radians(ti))) ** 2
    shape = F2 / qz ** 2 * math.exp(-(qx ** 2 + qy ** 2) / (4 * m * m * qz ** 2))
    assert rel_close(out["brightness"], shape)
    assert rel_close(out["diffuse"], shape)


def test_sigma_over_T_rejects_regimes_that_need_sigma_and_T():
    for regime in ("series", "slightly-rough"):
        proc = run("model", "--retro", 30, "--sigma-over-T", 0.5, "--regime", regime,
                   check=False)
        assert_usage_error(proc, "--regime", "--sigma")


# -------------------------------------------------------------------------------------------
# Full model from sigma and T (Eq. 1-4)

def test_full_model_slightly_rough_matches_eq1_and_eq2():
    sigma, T, lam, ti, ts, ps = 0.03, 0.8, 0.555, 20.0, 35.0, 40.0
    out = run_json("model", "--theta-i", ti, "--theta-s", ts, "--phi-s", ps, "--sigma", sigma,
                   "--T", T, "--regime", "series")
    area = 4 * 500.0 * 500.0
    diffuse, g = gaussian_series_diffuse(math.cos(math.radians(ti)), sigma, T, lam, area,
                                         ti, ts, ps)
    k = 2 * math.pi / lam
    qx, qy, qz = q_vector(ti, ts, ps)

    def sinc(x):
        return 1.0 if x == 0 else math.sin(x) / x

    coherent = (sinc(k * qx * 500) * sinc(k * qy * 500)) ** 2 * math.exp(-g)
    assert rel_close(out["g"], sigma ** 2 * (k * qz) ** 2)  # g = σ² v_z²
    assert rel_close(out["diffuse"], diffuse, 1e-8)
    assert math.isclose(out["coherent"], coherent, rel_tol=1e-6, abs_tol=1e-300)
    assert rel_close(out["total"], out["coherent"] + out["diffuse"], 1e-8)
    assert rel_close(out["brightness"], out["total"], 1e-9)  # radiance interpretation
    assert out["regime"] == "series"
    assert out["roughness_class"] == ("slightly_rough" if g < 0.1 else "moderately_rough")
    assert out["scale"] == "absolute"
    assert rel_close(out["sigma_over_T"], sigma / T)


def test_specular_coherent_term_is_exp_minus_g():
    sigma, theta, lam = 0.02, 14.0, 0.555
    out = run_json("model", "--specular", theta, "--sigma", sigma, "--T", 1.0)
    g = (sigma * 2 * (2 * math.pi / lam) * math.cos(math.radians(theta))) ** 2
    assert rel_close(out["g"], g)
    assert rel_close(out["coherent"], math.exp(-g))  # ρ0 = 1 in the specular direction
    assert out["phi_s_deg"] == 0


def test_very_rough_regime_is_eq4_and_close_to_series():
    sigma, T, lam, ti, ts, ps = 3.0, 6.0, 0.555, 30.0, 20.0, 150.0
    base = ("model", "--theta-i", ti, "--theta-s", ts, "--phi-s", ps, "--sigma", sigma,
            "--T", T)
    vr = run_json(*base, "--regime", "very-rough")  # '-' accepted for '_'
    vr2 = run_json(*base, "--regime", "very_rough")
    assert vr == vr2
    assert vr["regime"] == "very_rough" and vr["roughness_class"] == "very_rough"
    k, area = 2 * math.pi / lam, 4 * 500.0 * 500.0
    qx, qy, qz = q_vector(ti, ts, ps)
    vz2, vxy2 = (k * qz) ** 2, k ** 2 * (qx ** 2 + qy ** 2)
    eq4 = (math.pi * T ** 2 / (area * sigma ** 2) * math.cos(math.radians(ti)) / vz2
           * math.exp(-T ** 2 * vxy2 / (4 * sigma ** 2 * vz2)))
    assert rel_close(vr["diffuse"], eq4)
    series = run_json(*base, "--regime", "series")
    assert series["regime"] == "series"
    assert math.isclose(series["diffuse"], eq4, rel_tol=0.01)  # g ≈ 1e4: Eq. 4 is its limit


def test_auto_regime_reports_the_regime_used():
    out = run_json("model", "--retro", 30, "--sigma", 1.0, "--T", 2.0)
    assert out["regime"] in ("series", "slightly_rough", "very_rough", "very_rough_series_limit")
    assert out["regime"] != "auto"


def test_human_output_has_named_lines():
    text = run("model", "--retro", 30, "--sigma-over-T", 0.5).stdout
    lines = dict(line.split(None, 1) for line in text.strip().splitlines())
    c = math.cos(math.radians(30))
    assert rel_close(float(lines["brightness"]),
                     math.exp(-math.tan(math.radians(30)) ** 2 / (4 * 0.25)) / c / 4, 1e-9)
    assert lines["g"].strip() == "unknown"
    assert lines["regime"].strip() == "very_rough"


# -------------------------------------------------------------------------------------------
# Other geometry inputs

def test_vectors_give_the_same_result_as_angles():
    t = math.radians(30)
    light = f"{2 * math.sin(t)!r},0,{2 * math.cos(t)!r}"  # not unit: normalised by the CLI
    by_vec = run_json("model", "--light", light, "--view", light, "--sigma-over-T", 0.5)
    by_retro = run_json("model", "--retro", 30, "--sigma-over-T", 0.5)
    assert by_vec["visible"] is True
    assert rel_close(by_vec["brightness"], by_retro["brightness"], 1e-8)
    assert math.isclose(by_vec["phi_s_deg"], 180, abs_tol=1e-6)


def test_tilted_normal_rotates_the_frame():
    """Rotating N, L and V together leaves the brightness unchanged."""
    a = math.radians(25)

    def rot(x, z):  # rotation about the y axis
        return f"{x * math.cos(a) + z * math.sin(a)!r},0,{-x * math.sin(a) + z * math.cos(a)!r}"

    ti, ts = math.radians(40), math.radians(10)
    L = (-math.sin(ti), math.cos(ti))
    V = (math.sin(ts), math.cos(ts))  # specular plane, φs = 0
    out = run_json("model", "--normal", rot(0, 1), "--light", rot(*L), "--view", rot(*V),
                   "--model", "lambert")
    assert rel_close(out["brightness"], math.cos(ti), 1e-8)
    assert math.isclose(out["theta_i_deg"], 40, abs_tol=1e-6)
    assert math.isclose(out["theta_s_deg"], 10, abs_tol=1e-6)


def test_light_below_horizon_is_zero_and_not_visible():
    out = run_json("model", "--light", "0.5,0,-0.5", "--view", "0,0,1", "--sigma-over-T", 0.5)
    assert out["visible"] is False
    assert out["brightness"] == 0
    assert out["theta_i_deg"] > 90


def test_curet_frame_with_equal_directions_is_retro():
    by_curet = run_json("model", "--curet-frame", "30,45,30,45", "--sigma-over-T", 0.5)
    by_retro = run_json("model", "--retro", 30, "--sigma-over-T", 0.5)
    assert math.isclose(by_curet["phi_s_deg"], 180, abs_tol=1e-9)
    assert rel_close(by_curet["brightness"], by_retro["brightness"], 1e-9)


# -------------------------------------------------------------------------------------------
# Comparison models

def test_lambert_is_cos_theta_i():
    assert rel_close(run_json("model", "--model", "lambert", "--normal-view", 60)["brightness"],
                     0.5, 1e-9)


@pytest.mark.parametrize("model", ["oren-nayar", "oren-nayar-qualitative", "Oren_Nayar"])
def test_oren_nayar_with_zero_slope_is_lambert(model):
    out = run_json("model", "--model", model, "--on-sigma", 0, "--albedo", 0.8, "--theta-i", 40,
                   "--theta-s", 20, "--phi-s", 90)
    assert rel_close(out["brightness"], 0.8 / math.pi * math.cos(math.radians(40)), 1e-9)
    # the library's name scheme: any case, '-' == '_'; printed with '-' as on the command line
    assert out["model"] == model.lower().replace("_", "-")


def test_oren_nayar_rough_brightens_retro_relative_to_lambert():
    """Oren-Nayar's backscatter: rough facets look brighter towards the source than Lambert."""
    out = run_json("model", "--model", "oren-nayar", "--on-sigma", 0.5, "--retro", 60)
    assert out["brightness"] > math.cos(math.radians(60)) / math.pi


def test_lafortune_diffuse_lobe():
    ti, ts, n = 30.0, 50.0, 2.0
    out = run_json("model", "--model", "lafortune", "--n", n, "--theta-i", ti, "--theta-s", ts,
                   "--phi-s", 70)
    ci, cs = math.cos(math.radians(ti)), math.cos(math.radians(ts))
    assert rel_close(out["brightness"], (ci * cs) ** n * ci, 1e-9)


def test_lafortune_extra_lobe_adds():
    ti, ts, ps = 30.0, 30.0, 0.0  # specular direction: Lx Vx = -sin² θ, so Cx = -1 peaks
    base = ("model", "--model", "lafortune", "--theta-i", ti, "--theta-s", ts, "--phi-s", ps)
    lobe_only = run_json(*base, "--lobe", "-1,-1,1,10,0.5")["brightness"]
    s, c = math.sin(math.radians(ti)), math.cos(math.radians(ti))
    assert rel_close(lobe_only, 0.5 * (s * s + c * c) ** 10 * c, 1e-9)


# -------------------------------------------------------------------------------------------
# CSV input and output

def write(path, text):
    path.write_text(text)
    return path


def test_csv_round_trip_with_per_row_overrides(tmp_path):
    src = write(tmp_path / "in.csv",
                "# retro geometries\n"
                "theta_i, theta_s, phi_s, sigma_over_T\n"
                "0, 0, 180, \n"
                "\n"
                "30, 30, 180, 0.9\n"
                "60, 60, 180,\n")
    out = tmp_path / "out.csv"
    proc = run("model", "--csv", src, "--sigma-over-T", 0.5, "--output", out)
    assert proc.stdout == ""
    rows = list(csv.DictReader(out.open()))
    assert [float(r["theta_i_deg"]) for r in rows] == [0, 30, 60]
    for row, m in zip(rows, (0.5, 0.9, 0.5)):
        theta = math.radians(float(row["theta_i_deg"]))
        eq9 = math.exp(-math.tan(theta) ** 2 / (4 * m * m)) / math.cos(theta)
        assert rel_close(float(row["brightness"]), eq9 / 4, 1e-9)
        assert rel_close(float(row["sigma_over_T"]), m)
        assert row["g"] == ""  # unknown
    # Same file as JSON on stdout.
    arr = json.loads(run("model", "--csv", src, "--sigma-over-T", 0.5, "--json").stdout)
    assert len(arr) == 3
    # CSV has 10 significant digits; JSON the full (round-trip) double.
    assert all(rel_close(a["brightness"], float(r["brightness"]), 1e-9) for a, r in zip(arr, rows))


@pytest.mark.parametrize("model", [
    ("--sigma", "1", "--T", "2"),
    ("--sigma-over-T", "0.5"),
    ("--model", "lafortune", "--lobe", "-1,-1,1,10,0.5"),  # nested lobes: the slow path
])
def test_csv_json_stream_is_each_rows_dump(tmp_path, model):
    """`model --csv --json` streams its array without the records in memory; each element has
    the bytes the single-geometry command's `--json` document has (serialize::dump), indented
    one level: numbers as the same shortest text, keys in the same order."""
    geometries = [("30", "40", "180"), ("12.5", "33.3", "90"), ("0.1", "89.9", "359.9"),
                  ("1e-5", "45", "0"), ("0", "0", "0"), ("89.99999999999999", "1.5e-7", "271.25"),
                  # repeated numbers (the writer's cache), azimuths made into others (the echo
                  # of the geometry's, not the typed one), 16-17 digit angles
                  ("30", "40", "180"), ("45", "45", "-180"), ("45", "45", "720"),
                  ("29.999999999999996", "0.30000000000000004", "123.45678901234567")]
    src = write(tmp_path / "in.csv",
                "theta_i,theta_s,phi_s\n" + "".join(",".join(g) + "\n" for g in geometries))
    streamed = run("model", "--csv", src, *model, "--json").stdout
    singles = [run("model", "--theta-i", ti, "--theta-s", ts, "--phi-s", ps, *model,
                   "--json").stdout for ti, ts, ps in geometries]
    elements = ["\n".join("  " + line for line in s.rstrip("\n").split("\n")) for s in singles]
    assert streamed == "[\n" + ",\n".join(elements) + "\n]\n"


def test_csv_per_row_sigma_and_T(tmp_path):
    src = write(tmp_path / "in.csv", "theta_i,theta_s,phi_s,sigma_um,T_um\n14,14,0,0.02,1\n")
    arr = json.loads(run("model", "--csv", src, "--json").stdout)
    g = (0.02 * 2 * (2 * math.pi / 0.555) * math.cos(math.radians(14))) ** 2
    assert rel_close(arr[0]["g"], g)


@pytest.mark.parametrize("content, line, needle", [
    ("theta_i,theta_s,phi_s\n10,10,180\n20,abc,180\n", 3, "theta_s"),
    ("theta_i,theta_s,phi_s\n10,10,180\n# c\n20,20,nan\n", 4, "phi_s"),
    ("theta_i,theta_s,phi_s\n10,10,180\n20,20\n", 3, "expected 3 fields"),
    ("theta_i,theta_s,phi_s\n95,10,180\n", 2, "theta_i"),
])
def test_csv_malformed_row_names_the_line_and_writes_nothing(tmp_path, content, line, needle):
    src = write(tmp_path / "in.csv", content)
    out = tmp_path / "out.csv"
    proc = run("model", "--csv", src, "--sigma-over-T", 0.5, "--output", out, check=False)
    assert_usage_error(proc, f"{src}:{line}:", needle, code=EXIT_DATA)
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in.csv"]  # no temporary left


def test_csv_missing_column_lists_found_and_required(tmp_path):
    src = write(tmp_path / "in.csv", "theta_i,theta_v,phi_s\n10,10,180\n")
    proc = run("model", "--csv", src, "--sigma-over-T", 0.5, check=False)
    assert_usage_error(proc, "theta_s", "theta_v", "required", code=EXIT_DATA)


def test_csv_missing_file_and_row_roughness(tmp_path):
    proc = run("model", "--csv", tmp_path / "nope.csv", "--sigma-over-T", 0.5, check=False)
    assert_usage_error(proc, "nope.csv", code=EXIT_DATA)
    src = write(tmp_path / "in.csv", "theta_i,theta_s,phi_s,sigma_um\n10,10,180,1\n")
    proc = run("model", "--csv", src, check=False)  # sigma_um without T_um
    assert_usage_error(proc, ":2:", "T_um", code=EXIT_DATA)


def test_output_is_atomic_and_bad_directory_fails(tmp_path):
    out = tmp_path / "r.json"
    run("model", "--retro", 30, "--sigma-over-T", 0.5, "--json", "--output", out)
    assert json.loads(out.read_text())["regime"] == "very_rough"
    bad = tmp_path / "missing-dir" / "r.json"
    proc = run("model", "--retro", 30, "--sigma-over-T", 0.5, "--output", bad, check=False)
    assert_usage_error(proc, "missing-dir", code=EXIT_DATA)
    assert not bad.parent.exists()


def test_no_nan_over_a_grid_of_extreme_geometries(tmp_path):
    """Grazing angles, tiny and huge σ/T, both correlations: finite, non-negative results."""
    rows = ["theta_i,theta_s,phi_s"]
    for ti in (0, 1, 45, 89, 89.999):
        for ts in (0, 30, 89.999):
            for ps in (0, 90, 180, -180, 720):
                rows.append(f"{ti},{ts},{ps}")
    src = write(tmp_path / "grid.csv", "\n".join(rows) + "\n")
    for extra in (("--sigma-over-T", 1e-3), ("--sigma-over-T", 50),
                  ("--sigma-over-T", 0.3, "--correlation", "exponential", "--factor", "kirchhoff"),
                  ("--sigma", 0.01, "--T", 0.5), ("--sigma", 20, "--T", 1),
                  ("--sigma", 0.5, "--T", 2, "--correlation", "exponential"),
                  ("--sigma", 0.5, "--T", 2, "--correlation", "exponential",
                   "--regime", "very_rough_series_limit")):
        arr = json.loads(run("model", "--csv", src, "--json", *extra).stdout)
        assert len(arr) == len(rows) - 1
        for rec in arr:
            assert math.isfinite(rec["brightness"]) and rec["brightness"] >= 0, (extra, rec)


# -------------------------------------------------------------------------------------------
# Bad input: one line naming the flag, exit code 2, nothing on stdout

RETRO = ("--retro", "30")
SOT = ("--sigma-over-T", "0.5")


@pytest.mark.parametrize("args, needles", [
    (("--theta-i", "90", "--theta-s", "0", "--phi-s", "0", *SOT), ("--theta-i", "[0, 90)")),
    (("--theta-i", "-1", "--theta-s", "0", "--phi-s", "0", *SOT), ("--theta-i", "[0, 90)")),
    (("--theta-i", "nan", "--theta-s", "0", "--phi-s", "0", *SOT), ("--theta-i", "NaN")),
    (("--theta-i", "10", "--theta-s", "0", "--phi-s", "inf", *SOT), ("--phi-s",)),
    (("--theta-i", "10", "--theta-s", "0", *SOT), ("--phi-s",)),
    (("--retro", "abc", *SOT), ("--retro", "not a number")),
    (("--specular", "90", *SOT), ("--specular",)),
    ((*RETRO, "--sigma", "-1", "--T", "1"), ("--sigma", "> 0")),
    ((*RETRO, "--sigma", "0", "--T", "1"), ("--sigma", "> 0")),
    ((*RETRO, "--sigma", "1", "--T", "nan"), ("--T",)),
    ((*RETRO, "--sigma", "1"), ("--T",)),
    ((*RETRO,), ("--sigma",)),
    ((*RETRO, *SOT, "--sigma", "1"), ("--sigma-over-T", "--sigma")),
    ((*RETRO, "--sigma-over-T", "-0.5"), ("--sigma-over-T", "> 0")),
    ((*RETRO, *SOT, "--correlation", "lorentzian"), ("--correlation", "gaussian")),
    ((*RETRO, *SOT, "--factor", "foo"), ("--factor", "vh")),
    ((*RETRO, *SOT, "--regime", "medium"), ("--regime", "very_rough")),
    ((*RETRO, *SOT, "--radiometry", "flux"), ("--radiometry", "radiance")),
    ((*RETRO, *SOT, "--model", "phong"), ("--model", "phong", "bk, lambert, oren_nayar")),
    ((*RETRO, "--sigma", "1", "--T", "1", "--wavelength", "0"), ("--wavelength",)),
    ((*RETRO, "--sigma", "1", "--T", "1", "--patch-x", "-5"), ("--patch-x",)),
    ((*RETRO, *SOT, "--theta-i", "10"), ("--retro", "--theta-i")),
    (("--light", "1,2", "--view", "0,0,1", *SOT), ("--light", "3")),
    (("--light", "0,0,0", "--view", "0,0,1", *SOT), ("--light", "zero")),
    (("--light", "0,0,1", *SOT), ("--view",)),
    (("--curet-frame", "95,0,0,0", *SOT), ("--curet-frame", "[0, 90)")),
    (("--curet-frame", "10,0,0", *SOT), ("--curet-frame", "4")),
    ((*SOT,), ("geometry",)),
    ((*RETRO, *SOT, "--on-sigma", "0.3"), ("--on-sigma", "oren-nayar")),
    ((*RETRO, "--model", "oren-nayar"), ("--on-sigma",)),
    ((*RETRO, "--model", "oren-nayar", "--on-sigma", "0.3", "--albedo", "2"), ("--albedo",)),
    ((*RETRO, "--model", "lambert", *SOT), ("--sigma-over-T", "bk")),
    ((*RETRO, "--model", "lafortune"), ("--n",)),
    ((*RETRO, "--model", "lafortune", "--lobe", "0,0,1,-2,1"), ("--lobe", "> 0")),
])
def test_bad_input_names_the_flag(args, needles):
    proc = run("model", *args, check=False)
    assert_usage_error(proc, *needles)
