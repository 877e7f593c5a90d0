"""Every numeric flag of every subcommand, at the extremes of the double range.

For each subcommand, base commands that work are run with one numeric flag replaced (or added)
by an extreme value: ±0, the smallest subnormal, tiny and huge normal numbers, the largest
double, and their negatives (integers: 0, ±1, the int32 limits and beyond). The contract of the
command-line tool (docs/cli.md):
  * the exit code is 0 (a result), 2 (invalid value: the one-line message names the flag) or 3
    (no solution), never 1 ("internal error") and never a crash or a hang;
  * stdout never contains NaN or infinity (an unavailable quantity is printed as "unknown" /
    JSON null with a reason), and no message prints NaN or infinity either.
The flags are read from each subcommand's --help, so a new numeric flag is swept automatically.
Failures are collected per subcommand and reported together.
"""

import concurrent.futures
import math
import os
import re
import subprocess

import pytest

from conftest import REPO_ROOT, cli_path

# Drives the CLI: also run against the sanitizer build (`make sanitize`, DEVELOPERS.md).
pytestmark = pytest.mark.cli

NAN_RE = re.compile(r"\b(nan|inf|infinity)\b", re.IGNORECASE)
# "  --sigma FLOAT:> 0   ..." / "  --max-iterations INT:INT in [1 - 100000]" / "--pair INT x 2"
# / "  --nx UINT:INT in [8,4096]" (unsigned options are swept as integers)
FLAG_RE = re.compile(r"^\s+(?:-\w,)?(--[\w-]+) U?(FLOAT|INT)\b( x (\d+))?", re.MULTILINE)

EXTREMES = ["0", "-0", "5e-324", "1e-320", "1e-300", "1e-8", "1e8", "1e300",
            "1.7976931348623157e308"]
NEGATIVES = ["-" + v for v in EXTREMES[2:]]
INT_EXTREMES = ["0", "-1", "1", "2147483647", "2147483648", "-2147483649", "1e8"]
if os.environ.get("ROUGHSCOPE_SANITIZED") == "1":
    # Under ASan + UBSan (`make sanitize`) the point is memory and undefined-behaviour errors on
    # the extreme paths, which one value per end of the range reaches; the release run sweeps
    # every value above for the exit-code and NaN contract. Keeps the sanitizer run in budget.
    EXTREMES = ["0", "5e-324", "1e-300", "1.7976931348623157e308"]
    NEGATIVES = ["-1e-300", "-1.7976931348623157e308"]
    INT_EXTREMES = ["0", "-1", "2147483648"]


def numeric_flags(*subcommand):
    """{flag: (kind, count)} for the numeric options (FLOAT or INT in --help) of a subcommand."""
    proc = subprocess.run([cli_path(), *subcommand, "--help"], capture_output=True, text=True,
                          timeout=60, check=True)
    return {m.group(1): (m.group(2), int(m.group(4) or 1)) for m in FLAG_RE.finditer(proc.stdout)}


def with_flag(base, flag, values):
    """`base` with `flag` set to `values` (replaced when present, appended otherwise)."""
    args = list(base)
    if flag in args:
        i = args.index(flag)
        args[i + 1:i + 1 + len(values)] = values
    else:
        args += [flag, *values]
    return args


# Flags whose messages name the quantity as the library spells it.
QUANTITY_NAMES = {
    "--e-tot": ["E_tot"], "--e-dif": ["E_dif"], "--r-spec": ["R_spec"], "--r0": ["R0"],
    "--ratio": ["E1/E2"], "--e1": ["E1"], "--e2": ["E2"],
    "--initial-sigma-over-T": ["initial sigma/T"], "--initial-sigma": ["initial sigma"],
    "--initial-T": ["initial T"], "--sigma-over-T": ["sigma_over_T", "sigma/T"],
    "--on-sigma": ["oren_nayar sigma"], "--on-albedo": ["albedo"], "--pair": ["measurement"],
    "--sigma-um": ["sigma ="], "--T-um": ["T ="],
}


def names_flag(message, flag):
    """Whether an error message names the flag (as --flag, its name with '_' or '-', or the
    quantity it sets), case-insensitively."""
    name = flag.lstrip("-")
    names = [flag, name, name.replace("-", "_")] + QUANTITY_NAMES.get(flag, [])
    return any(s.lower() in message.lower() for s in names)


def check(job):
    """Runs one command; returns a failure description or None."""
    flag, args = job
    cmd = "roughscope " + " ".join(args)
    try:
        proc = subprocess.run([cli_path(), *args], capture_output=True, text=True, timeout=60)
    except subprocess.TimeoutExpired:
        return f"timeout (60 s): {cmd}"
    if proc.returncode not in (0, 2, 3):
        return f"exit {proc.returncode}: {cmd}: {proc.stderr.strip()}"
    if NAN_RE.search(proc.stdout):
        return f"NaN/inf printed ({NAN_RE.search(proc.stdout).group(0)}): {cmd}"
    if proc.returncode != 0:
        lines = proc.stderr.strip().splitlines()
        if len(lines) != 1 or not lines[0].startswith("roughscope: error: "):
            return f"not one error line: {cmd}: {proc.stderr!r}"
        if NAN_RE.search(lines[0]):
            return f"NaN/inf in the message: {cmd}: {lines[0]}"
        if proc.returncode == 2 and not names_flag(lines[0], flag):
            return f"exit 2 without naming {flag}: {cmd}: {lines[0]}"
    return None


def sweep(subcommand, bases):
    """Every base × every numeric flag of `subcommand` × every extreme value; asserts none
    fails and returns the number of (base, flag) pairs swept (independent of how many extreme
    values are tried, which the sanitizer run reduces)."""
    flags = numeric_flags(*subcommand)
    assert flags, f"no numeric flag found in {' '.join(subcommand)} --help"
    jobs = []
    for base in bases:
        base_proc = subprocess.run([cli_path(), *subcommand, *base], capture_output=True,
                                   text=True, timeout=60)
        assert base_proc.returncode == 0, f"base command fails: {base}: {base_proc.stderr}"
        for flag, (kind, count) in flags.items():
            for value in INT_EXTREMES if kind == "INT" else EXTREMES + NEGATIVES:
                # multi-valued flags (--pair I J): the extreme in each position
                for pos in range(count):
                    current = base[base.index(flag) + 1:][:count] if flag in base else ["1"] * count
                    values = list(current)
                    values[pos] = value
                    jobs.append((flag, [*subcommand, *with_flag(base, flag, values)]))
    workers = max(2, min(4, os.cpu_count() or 1))
    with concurrent.futures.ThreadPoolExecutor(workers) as pool:
        failures = [f for f in pool.map(check, jobs) if f]
    assert not failures, f"{len(failures)} of {len(jobs)} runs failed:\n" + "\n".join(failures)
    return len(bases) * len(flags)


GEOMETRY = ["--theta-i", "30", "--theta-s", "20", "--phi-s", "45"]


@pytest.mark.parametrize("base", [
    [*GEOMETRY, "--sigma", "0.1", "--T", "1", "--json"],
    [*GEOMETRY, "--sigma", "2", "--T", "4", "--correlation", "exponential"],
    [*GEOMETRY, "--sigma", "0.1", "--T", "1", "--regime", "very_rough", "--factor", "kirchhoff"],
    [*GEOMETRY, "--sigma-over-T", "0.3", "--json"],
    [*GEOMETRY, "--sigma-over-T", "0.3", "--correlation", "exponential", "--factor", "beckmann",
     "--radiometry", "intensity"],
    ["--retro", "30", "--sigma", "0.1", "--T", "1", "--regime", "series"],
    ["--specular", "10", "--sigma", "0.1", "--T", "1", "--correlation", "exponential",
     "--regime", "very_rough_series_limit"],
    ["--normal-view", "40", "--sigma", "1", "--T", "3", "--regime", "slightly_rough"],
    ["--model", "oren-nayar", *GEOMETRY, "--on-sigma", "0.3", "--albedo", "0.5", "--json"],
    ["--model", "oren-nayar-qualitative", *GEOMETRY, "--on-sigma", "0.3", "--albedo", "0.5"],
    ["--model", "lafortune", *GEOMETRY, "--n", "2", "--rho-d", "0.1", "--json"],
    ["--model", "lambert", *GEOMETRY],
], ids=lambda b: "_".join(a.lstrip("-") for a in b[:4]))
def test_model_flags_at_the_extremes(base):
    assert sweep(["model"], [base]) >= 12  # 16 numeric flags


@pytest.mark.parametrize("subcommand,bases", [
    ("specular", [["--r-spec", "0.5", "--theta", "10", "--noise", "0.01", "--json"],
                  ["--e-tot", "2", "--e-dif", "1", "--theta", "10", "--r0", "0.9"]]),
    ("correlation-length", [
        ["--sigma", "0.094", "--ratio", "1.043", "--theta1", "30", "--theta2", "45",
         "--sigma-stderr", "0.001", "--noise", "0.01"],
        ["--sigma", "0.05", "--e1", "1.1", "--e2", "1", "--theta1", "30", "--theta2", "45",
         "--theta-s1", "10", "--phi-s1", "90", "--theta-s2", "20", "--phi-s2", "0",
         "--regime", "series", "--correlation", "exponential", "--json"]]),
    ("slope", [
        ["--ratio", "1.880176", "--theta1", "45", "--theta2", "67.5", "--noise", "0.01"],
        ["--e1", "130", "--e2", "110", "--theta1", "30", "--theta2", "45", "--theta-s1", "20",
         "--phi-s1", "90", "--sigma", "1", "--json"]]),
])
def test_estimate_flags_at_the_extremes(subcommand, bases):
    assert sweep(["estimate", subcommand], bases) >= 12  # (base, flag) pairs: 14 to 26


@pytest.fixture(scope="module")
def measurement_files(tmp_path_factory):
    """A fit measurement table and a BRDF table (two-point pair 1,2 viewed along the normal)."""
    folder = tmp_path_factory.mktemp("extreme_flags")
    fit = folder / "fit.csv"
    rows = [(ti, 0, 30, ps, math.cos(math.radians(ti)) * (1 + 0.1 * ps / 180))
            for ti in (10, 20, 30, 40, 50, 60) for ps in (0, 90, 180)]
    fit.write_text("theta_i,phi_i,theta_s,phi_s,brightness\n"
                   + "".join(",".join(map(str, r)) + "\n" for r in rows))
    table = folder / "table.csv"
    rows = [(ti, 0, 0, 0, 0.3 * math.cos(math.radians(ti))) for ti in (30, 45, 10, 20, 50, 60)]
    rows += [(ti, 180, ts, ps, 0.2) for ti in (20, 40) for ts in (10, 30) for ps in (0, 90)]
    table.write_text("theta_i,phi_i,theta_s,phi_s,value\n"
                     + "".join(",".join(map(str, r)) + "\n" for r in rows))
    return fit, table


def test_fit_flags_at_the_extremes(measurement_files):
    fit, _ = measurement_files
    assert sweep(["estimate", "fit"], [
        ["--measurements", str(fit), "--correlation", "gaussian", "--json"],
        ["--measurements", str(fit), "--model", "slightly_rough", "--correlation", "gaussian",
         "--initial-sigma", "0.1", "--initial-T", "1", "--loss", "huber"],
    ]) >= 10  # 2 bases x 6 numeric flags


def test_curet_table_flags_at_the_extremes(measurement_files):
    _, table = measurement_files
    assert sweep(["curet"], [
        ["--table", str(table), "--pair", "1", "2", "--json"],
        ["--table", str(table), "--pair", "1", "2", "--on-sigma", "0.2", "--on-albedo", "0.5",
         "--no-fits"],
    ]) >= 12  # 2 bases x 8 numeric flags


@pytest.fixture(scope="module")
def height_file(tmp_path_factory):
    """A 32 × 24 generated height map as CSV (heights in µm, spacings in its header)."""
    path = tmp_path_factory.mktemp("surface") / "map.csv"
    subprocess.run([cli_path(), "surface", "generate", "--correlation", "gaussian",
                    "--sigma-um", "0.5", "--T-um", "4", "--nx", "32", "--ny", "24",
                    "--dx-um", "1", "--seed", "3", "--out", str(path)],
                   check=True, capture_output=True, timeout=60)
    return path


def test_surface_flags_at_the_extremes(height_file, tmp_path):
    out = tmp_path / "generated.gsf"
    runs = sweep(["surface", "stats"], [
        [str(height_file), "--json"],
        [str(height_file), "--level", "polynomial", "--order", "2", "--cutoff-um", "8"],
    ])
    runs += sweep(["surface", "generate"], [
        ["--correlation", "exponential", "--sigma-um", "0.5", "--T-um", "4", "--nx", "16",
         "--ny", "8", "--dx-um", "1", "--seed", "1", "--out", str(out)],
    ])
    runs += sweep(["surface", "predict"], [
        ["--sigma-um", "0.5", "--T-um", "4", "--correlation", "gaussian", "--theta-i", "30",
         "--theta-s", "20", "--phi-s", "45", "--json"],
        [str(height_file), "--theta-i", "30", "--theta-s", "20", "--phi-s", "45",
         "--wavelength-um", "0.5"],
    ])
    assert runs >= 25  # (base, flag) pairs: 10 + 5 + 20


def test_simulate_scatter_flags_at_the_extremes(tmp_path):
    # A small fixed grid keeps every accepted extreme fast (the grid is what costs).
    runs = sweep(["simulate", "scatter"], [
        ["--sigma-um", "0.05", "--T-um", "1", "--theta-i", "30", "--theta-s", "10", "--phi-s",
         "45", "--nx", "16", "--realisations", "10", "--json"],
        ["--sigma-um", "0.05", "--T-um", "1", "--correlation", "exponential", "--theta-i", "20",
         "--theta-s", "20", "--phi-s", "0", "--nx", "16", "--dx-um", "0.2", "--realisations",
         "10", "--layout", "fixed"],
    ])
    assert runs >= 20  # 2 bases x 11 numeric flags


def test_calibrate_light_flags_at_the_extremes():
    image = str(REPO_ROOT / "docs" / "examples" / "mirror-sphere.png")
    assert sweep(["calibrate", "light"], [
        [image, "--sphere", "64,64,56"],
        [image, "--sphere", "64,64,56", "--circle-uncertainty", "0", "--json"],
    ]) >= 2


def test_plan_flags_at_the_extremes():
    assert sweep(["plan"], [
        ["--sigma-over-T", "0.5", "--theta-step", "10", "--method", "first_order"],
        ["--sigma-over-T", "0.5", "--sigma-over-T-max", "0.8", "--range-points", "2",
         "--exposure", "common", "--theta-step", "10", "--method", "first_order", "--json"],
    ]) >= 2
